//! Importance sampling of the BSDF's non-delta lobes for path tracing: the
//! Lambertian lobe by cosine and the glossy lobe by its model (Blinn-Phong
//! by its half vector, Phong about the mirror direction, GGX by its visible
//! normals, Beckmann by `D(h) cos_h`), chosen between in proportion to
//! their albedo. `bsdf()` itself stays the one definition of the reflectance.

use crate::render::transport::sampling::{blinn_phong_half, blinn_phong_pdf, cosine_hemisphere, cosine_hemisphere_lanes, cosine_hemisphere_pdf, cosine_hemisphere_pdf_lanes, from_local, from_local_lanes, luminance, reflect, tangents};
use crate::render::transport::microfacet;
use crate::scene::material::{DiffuseModel, GlossyModel, IntoLobes, PointLobes};
use std::f32::consts::PI;
use crate::math::lanes::{Lane, V3};
use crate::render::transport::bsdf::{bsdf, ShadingFrame};
use crate::math::{Vec2, Vec3};
use crate::scene::Material;

/// A sampled incoming direction with what the estimator needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Unit, pointing away from the surface.
    pub w_i: Vec3,
    /// The density of `w_i` under the lobe mixture (solid angle).
    pub pdf: f32,
    /// `f(w_i, w_o) cos(theta_i) / pdf`: what the radiance arriving along
    /// `w_i` is multiplied by.
    pub weight: Vec3,
}

/// The probability of choosing the Lambertian lobe; the glossy lobe takes the rest.
#[inline]
fn diffuse_probability(material: &Material, lobes: &PointLobes) -> f32 {
    let d = luminance(lobes.albedo).max(0.0);
    let g = if material.has_glossy() { luminance(lobes.glossy).max(0.0) } else { 0.0 };
    if d + g > 0.0 { d / (d + g) } else { 0.0 }
}

/// The density with which `sample_bsdf` returns `w_i` at `frame` (a
/// normal, or a normal and tangent) for a point's `lobes` (or albedo).
pub fn bsdf_pdf(material: &Material, lobes: impl IntoLobes, frame: impl Into<ShadingFrame>, w_o: Vec3, w_i: Vec3) -> f32 {
    let lobes = lobes.into_lobes(material);
    let frame = frame.into();
    let n = frame.n;
    let p_d = diffuse_probability(material, &lobes);
    let mut pdf = p_d * diffuse_pdf(material, n, w_i);
    if material.has_glossy() && p_d < 1.0 {
        pdf += (1.0 - p_d) * glossy_pdf(material, lobes.roughness, frame, w_o, w_i);
    }
    pdf
}

/// Ward's (t, b, n) frame at `frame`, as `lighting::ward_frame` builds it.
fn ward_axes(frame: ShadingFrame) -> (Vec3, Vec3) {
    let (t, b) = crate::render::transport::lighting::ward_frame(V3::from(frame.n), V3::from(frame.tangent));
    (t.into(), b.into())
}

/// The density with which `sample_diffuse` returns `w_i`: Minnaert's
/// lobe by `(k + 1) / (2 pi) cos^k` (its own `cos_i^k` shape, so that its
/// sample weight is bounded), the others by the cosine.
fn diffuse_pdf(material: &Material, n: Vec3, w_i: Vec3) -> f32 {
    match material.diffuse_model {
        DiffuseModel::Minnaert { darkening } => {
            let c = n.dot(w_i);
            if c <= 0.0 {
                return 0.0;
            }
            (darkening + 1.0) / (2.0 * PI) * c.powf(darkening)
        }
        _ => cosine_hemisphere_pdf(n.dot(w_i)),
    }
}

/// An incoming direction from the diffuse lobe alone (see `diffuse_pdf`).
fn sample_diffuse(material: &Material, n: Vec3, u: Vec2) -> Vec3 {
    match material.diffuse_model {
        DiffuseModel::Minnaert { darkening } => from_local(blinn_phong_half(u, darkening), n),
        _ => from_local(cosine_hemisphere(u), n),
    }
}

/// The density with which `sample_glossy` returns `w_i` (over the whole
/// sphere: directions below the surface have density too, and are refused
/// by `sample_bsdf`).
fn glossy_pdf(material: &Material, a: f32, frame: ShadingFrame, w_o: Vec3, w_i: Vec3) -> f32 {
    let n = frame.n;
    match material.glossy_model {
        GlossyModel::BlinnPhong => blinn_phong_pdf(n, w_o, w_i, material.sharpness),
        GlossyModel::Phong => {
            let c = reflect(w_o, n).normalize_or_zero().dot(w_i);
            if c <= 0.0 {
                return 0.0;
            }
            (material.sharpness + 1.0) / (2.0 * PI) * c.powf(material.sharpness)
        }
        GlossyModel::Ggx => {
            // The visible normals' density `G1(w_o) (w_o.h) D(h) / cos_o`
            // over the Jacobian `4 (w_o.h)` of reflection.
            let cos_o = n.dot(w_o);
            let h = (w_i + w_o).normalize_or_zero();
            if cos_o <= 0.0 {
                return 0.0;
            }
            microfacet::ggx_d(n.dot(h), a) * microfacet::ggx_g1(cos_o, w_o.dot(h), a) / (4.0 * cos_o)
        }
        GlossyModel::Beckmann => {
            let h = (w_i + w_o).normalize_or_zero();
            let (cos_h, o_h) = (n.dot(h), w_o.dot(h));
            if cos_h <= 0.0 || o_h <= 0.0 {
                return 0.0;
            }
            microfacet::beckmann_d(cos_h, a) * cos_h / (4.0 * o_h)
        }
        GlossyModel::Ward => {
            // The half vector's density `ward_d(h) cos_h` over the Jacobian.
            let h = (w_i + w_o).normalize_or_zero();
            let (t, b) = ward_axes(frame);
            let local = Vec3::new(h.dot(t), h.dot(b), h.dot(n));
            let o_h = w_o.dot(h);
            if local.z <= 0.0 || o_h <= 0.0 {
                return 0.0;
            }
            ward_half_density(local, material.roughness_uv) / (4.0 * o_h)
        }
    }
}

/// The density `exp(-((x / a_u)^2 + (y / a_v)^2) / z^2) / (pi a_u a_v z^3)`
/// of Ward's sampled half vector `(x, y, z)` (local frame, z > 0), that is
/// its normalized distribution times the cosine.
fn ward_half_density(h: Vec3, alpha: Vec2) -> f32 {
    let (x, y) = (h.x / alpha.x, h.y / alpha.y);
    (-(x * x + y * y) / (h.z * h.z)).exp() / (PI * alpha.x * alpha.y * h.z * h.z * h.z)
}

/// A half vector from `ward_half_density` (local frame): the azimuth with
/// `tan phi = (a_v / a_u) tan(2 pi u2)`, then
/// `tan^2 theta = -ln(1 - u1) / (cos^2 phi / a_u^2 + sin^2 phi / a_v^2)`.
fn sample_ward_half(alpha: Vec2, u: Vec2) -> Vec3 {
    let turn = 2.0 * PI * u.y;
    let phi = (alpha.y * turn.sin()).atan2(alpha.x * turn.cos());
    let (sin_phi, cos_phi) = phi.sin_cos();
    let spread = cos_phi * cos_phi / (alpha.x * alpha.x) + sin_phi * sin_phi / (alpha.y * alpha.y);
    let tan2 = -(1.0 - u.x).ln() / spread;
    let cos = 1.0 / (1.0 + tan2).sqrt();
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    Vec3::new(sin * cos_phi, sin * sin_phi, cos)
}

/// An incoming direction from the glossy lobe alone (not yet normalized,
/// possibly below the surface); `None` where the lobe reflects nothing
/// towards `w_o` (a microfacet lobe seen from below).
fn sample_glossy(material: &Material, a: f32, frame: ShadingFrame, w_o: Vec3, u: Vec2) -> Option<Vec3> {
    let n = frame.n;
    Some(match material.glossy_model {
        GlossyModel::BlinnPhong => reflect(w_o, from_local(blinn_phong_half(u, material.sharpness), n)),
        // The Phong lobe is the Blinn-Phong half vector's distribution laid about r.
        GlossyModel::Phong => from_local(blinn_phong_half(u, material.sharpness), reflect(w_o, n).try_normalize()?),
        GlossyModel::Ggx => {
            let (t, b) = tangents(n);
            let v = Vec3::new(w_o.dot(t), w_o.dot(b), w_o.dot(n));
            if v.z <= 0.0 {
                return None;
            }
            reflect(w_o, from_local(microfacet::sample_ggx_visible(v.normalize(), a, u.x, u.y), n))
        }
        GlossyModel::Beckmann => reflect(w_o, from_local(microfacet::sample_beckmann(a, u.x, u.y), n)),
        GlossyModel::Ward => {
            let (t, b) = ward_axes(frame);
            let h = sample_ward_half(material.roughness_uv, u);
            reflect(w_o, t * h.x + b * h.y + n * h.z)
        }
    })
}

/// Samples an incoming direction at a surface with shading normal `n` seen
/// from `w_o`; `choice` picks the lobe, `u` places the direction. `None` when
/// the material reflects nothing diffusely or glossily, or the sample falls
/// below the surface (that path ends: its light is absorbed). `lobes` are
/// the point's (or its diffuse albedo).
pub fn sample_bsdf(material: &Material, lobes: impl IntoLobes, frame: impl Into<ShadingFrame>, w_o: Vec3, choice: f32, u: Vec2) -> Option<BsdfSample> {
    let lobes = lobes.into_lobes(material);
    let albedo = lobes.albedo;
    let frame = frame.into();
    let n = frame.n;
    let p_d = diffuse_probability(material, &lobes);
    let has_glossy = material.has_glossy() && p_d < 1.0;
    if p_d <= 0.0 && !has_glossy {
        return None;
    }
    if !has_glossy && material.diffuse_model == DiffuseModel::Lambert {
        return sample_lambertian(albedo, n, u);
    }
    let w_i = if choice < p_d || !has_glossy {
        sample_diffuse(material, n, u)
    } else {
        sample_glossy(material, lobes.roughness, frame, w_o, u)?
    };
    if !(n.dot(w_i) > 0.0) {
        return None;
    }
    let w_i = w_i.normalize();
    let cos_i = n.dot(w_i);
    let pdf = bsdf_pdf(material, lobes, frame, w_o, w_i);
    if !(pdf > 0.0 && pdf.is_finite()) {
        return None;
    }
    let weight = bsdf(material, lobes, frame, w_i, w_o) * (cos_i / pdf);
    weight.is_finite().then_some(BsdfSample { w_i, pdf, weight })
}

/// `sample_bsdf` for a purely Lambertian surface: the cosine lobe is the
/// BSDF times cos over its own density, so the weight is the albedo itself
/// (`(albedo / pi) cos / (cos / pi)` exactly, without its rounding).
#[inline]
fn sample_lambertian(albedo: Vec3, n: Vec3, u: Vec2) -> Option<BsdfSample> {
    let (w_i, pdf, usable) = cosine_lobe(V3::from(n), u.x, u.y);
    (usable && albedo.is_finite()).then_some(BsdfSample { w_i: w_i.into(), pdf, weight: albedo })
}

/// The cosine lobe about the unit normal `n` sampled at (`ux`, `uy`), over
/// lanes (path bounces take it eight at a time): the unit direction, its
/// density, and whether it can be used (it leaves above the surface with a
/// positive density).
#[inline(always)]
pub fn cosine_lobe<L: Lane>(n: V3<L>, ux: L, uy: L) -> (V3<L>, L, L::Mask) {
    let w_i = from_local_lanes(cosine_hemisphere_lanes(ux, uy), n);
    let zero = ux.splat(0.0);
    let above = n.dot(w_i).gt(zero);
    let w_i = w_i.normalize();
    let pdf = cosine_hemisphere_pdf_lanes(n.dot(w_i));
    (w_i, pdf, above & pdf.gt(zero))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::transport::sampling::SampleRng;

    /// The midpoint rule over the sphere of directions, `n_theta` x `n_phi`
    /// cells in polar coordinates about the unit axis `about` (put it where
    /// the integrand peaks, so its cells are finest there).
    fn integrate_sphere(n_theta: usize, n_phi: usize, about: Vec3, f: impl Fn(Vec3) -> f64) -> f64 {
        let (d_theta, d_phi) = (std::f64::consts::PI / n_theta as f64, 2.0 * std::f64::consts::PI / n_phi as f64);
        let mut sum = 0.0f64;
        for i in 0..n_theta {
            let theta = (i as f64 + 0.5) * d_theta;
            for j in 0..n_phi {
                let phi = (j as f64 + 0.5) * d_phi;
                let local = Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
                sum += f(from_local(local, about)) * theta.sin() * d_theta * d_phi;
            }
        }
        sum
    }

    /// The Monte Carlo estimate of the directional albedo `∫ f cos dw`.
    fn albedo_estimate(m: &Material, w_o: Vec3, n: usize) -> Vec3 {
        let mut r = SampleRng::for_index(21, 0, 1);
        // Summed in f64: 10^5 f32 additions would drift by more than the test allows.
        let mut sum = glam::DVec3::ZERO;
        for _ in 0..n {
            let choice = r.next_f32();
            if let Some(s) = sample_bsdf(m, m.lambertian, Vec3::Z, w_o, choice, r.next_2d()) {
                sum += s.weight.as_dvec3();
            }
        }
        (sum / n as f64).as_vec3()
    }

    #[test]
    fn lambertian_reflects_its_albedo() {
        let mut m = Material::black();
        m.lambertian = Vec3::new(0.73, 0.4, 0.1);
        for w_o in [Vec3::Z, Vec3::new(0.8, 0.0, 0.6)] {
            let a = albedo_estimate(&m, w_o, 20_000);
            assert!((a - m.lambertian).abs().max_element() < 1e-4, "{a}");
        }
    }

    /// `∫ f cos dw` of the glossy lobe by a midpoint rule over the hemisphere:
    /// an estimate that shares no code with the sampling.
    fn albedo_by_quadrature(m: &Material, w_o: Vec3) -> f32 {
        albedo_by_quadrature_with(m, Vec3::ZERO, w_o)
    }

    /// `∫ f cos dw` of the whole BSDF with diffuse albedo `albedo`.
    fn albedo_by_quadrature_with(m: &Material, albedo: Vec3, w_o: Vec3) -> f32 {
        let (n_theta, n_phi) = (200, 400);
        let (d_theta, d_phi) = (std::f32::consts::FRAC_PI_2 / n_theta as f32, 2.0 * std::f32::consts::PI / n_phi as f32);
        let mut sum = 0.0f64;
        for i in 0..n_theta {
            let theta = (i as f32 + 0.5) * d_theta;
            for j in 0..n_phi {
                let phi = (j as f32 + 0.5) * d_phi;
                let w_i = Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                sum += (bsdf(m, albedo, Vec3::Z, w_i, w_o).x * w_i.z * theta.sin() * d_theta * d_phi) as f64;
            }
        }
        sum as f32
    }

    /// Sampling the glossy lobe estimates its albedo without bias, at every
    /// sharpness and angle, and the lobe never reflects more than arrives:
    /// exactly all of it seen along the normal, less at grazing angles.
    #[test]
    fn blinn_phong_sampling_estimates_the_lobes_albedo() {
        for sharpness in [0.0f32, 1.0, 4.0, 8.0, 16.0, 64.0, 256.0, 2048.0] {
            let mut m = Material::black();
            m.glossy = Vec3::ONE;
            m.sharpness = sharpness;
            for cos_o in [1.0f32, 0.7, 0.3] {
                let w_o = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
                let sampled = albedo_estimate(&m, w_o, 100_000).x;
                let exact = albedo_by_quadrature(&m, w_o);
                assert!((sampled - exact).abs() < 0.02 * exact.max(0.1), "sharpness {sharpness}, cos_o {cos_o}: sampled {sampled}, quadrature {exact}");
                assert!(exact <= 1.002, "sharpness {sharpness}, cos_o {cos_o}: the lobe reflects {exact} (sampled {sampled})");
                if cos_o == 1.0 {
                    assert!(exact > 0.99, "sharpness {sharpness}: seen along the normal the lobe reflects {exact}, not all");
                }
            }
        }
    }

    fn glossy_material(model: GlossyModel, roughness: f32, sharpness: f32) -> Material {
        let mut m = Material::black();
        m.glossy = Vec3::ONE;
        m.glossy_model = model;
        m.roughness = roughness;
        m.sharpness = sharpness;
        m
    }

    /// Sampling the Phong and microfacet lobes estimates their albedo (by
    /// quadrature, sharing no code with the sampling) within 1%, and no
    /// lobe reflects more than arrives. The microfacet lobes lose energy
    /// as they roughen (single scattering, no Fresnel), as Mitsuba's do.
    #[test]
    fn phong_and_microfacet_sampling_estimate_the_lobes_albedo() {
        let cases = [
            (GlossyModel::Ggx, [0.05f32, 0.2, 0.5, 1.0].map(|a| (a, 0.0))),
            (GlossyModel::Beckmann, [0.05f32, 0.2, 0.5, 1.0].map(|a| (a, 0.0))),
            (GlossyModel::Phong, [1.0f32, 10.0, 50.0, 200.0].map(|s| (0.1, s))),
        ];
        for (model, params) in cases {
            for (roughness, sharpness) in params {
                let m = glossy_material(model, roughness, sharpness);
                for cos_o in [1.0f32, 0.7, 0.3] {
                    let w_o = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
                    let sampled = albedo_estimate(&m, w_o, 200_000).x;
                    let exact = albedo_by_quadrature(&m, w_o);
                    let what = format!("{model:?} alpha {roughness} s {sharpness}, cos_o {cos_o}: sampled {sampled}, quadrature {exact}");
                    assert!((sampled - exact).abs() < 0.01 * exact.max(0.1), "{what}");
                    assert!(exact <= 1.002 && exact > 0.2, "{what}");
                }
            }
        }
    }

    /// Each glossy lobe's sampling density integrates to one over the
    /// sphere (directions below the surface included: `sample_bsdf` refuses
    /// those after drawing them), by a midpoint rule; Beckmann's `D cos`
    /// sampling loses the half vectors that face away from `w_o`, so its
    /// integral is one only where there are none of those (seen near the
    /// normal, smooth) and below one otherwise.
    #[test]
    fn glossy_densities_integrate_to_one() {
        let sphere_integral = |m: &Material, w_o: Vec3| integrate_sphere(800, 800, Vec3::Z, |w_i| glossy_pdf(m, m.roughness, Vec3::Z.into(), w_o, w_i) as f64);
        let near_normal = Vec3::new(0.3, 0.1, 0.9).normalize();
        let grazing = Vec3::new(0.95, 0.0, 0.3).normalize();
        for (model, roughness, sharpness) in [(GlossyModel::Ggx, 0.2, 0.0), (GlossyModel::Ggx, 0.7, 0.0), (GlossyModel::Phong, 0.1, 10.0), (GlossyModel::Phong, 0.1, 60.0)] {
            for w_o in [near_normal, grazing] {
                let integral = sphere_integral(&glossy_material(model, roughness, sharpness), w_o);
                assert!((integral - 1.0).abs() < 5e-3, "{model:?} alpha {roughness} s {sharpness} w_o {w_o}: {integral}");
            }
        }
        let beckmann = sphere_integral(&glossy_material(GlossyModel::Beckmann, 0.2, 0.0), near_normal);
        assert!((beckmann - 1.0).abs() < 5e-3, "Beckmann: {beckmann}");
        let beckmann = sphere_integral(&glossy_material(GlossyModel::Beckmann, 0.7, 0.0), grazing);
        assert!(beckmann < 0.99 && beckmann > 0.5, "Beckmann: {beckmann}");
    }

    /// `sample_bsdf`'s directions against `bsdf_pdf` by Pearson's
    /// chi-square test (16 x 32 bins over the hemisphere, p = 1e-4), for
    /// every glossy model alone and mixed with a Lambertian lobe, seen
    /// along the normal and obliquely: the density MIS weighs light samples
    /// with is the one the BSDF strategy draws from. Samples refused below
    /// the surface count as misses, as the density's missing mass does.
    #[test]
    fn sampled_directions_follow_bsdf_pdf() {
        use crate::render::transport::sampling::tests::chi_square;
        let cases = [
            glossy_material(GlossyModel::Ggx, 0.3, 0.0),
            glossy_material(GlossyModel::Ggx, 0.6, 0.0),
            glossy_material(GlossyModel::Beckmann, 0.3, 0.0),
            glossy_material(GlossyModel::Beckmann, 0.6, 0.0),
            glossy_material(GlossyModel::Phong, 0.1, 5.0),
            glossy_material(GlossyModel::Phong, 0.1, 30.0),
            glossy_material(GlossyModel::BlinnPhong, 0.1, 20.0),
        ];
        for glossy_only in cases {
            let mut mixed = glossy_only.clone();
            mixed.lambertian = Vec3::new(0.3, 0.2, 0.1);
            mixed.glossy = Vec3::splat(0.4);
            for m in [glossy_only, mixed] {
                for w_o in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.3, 0.9, 0.3).normalize()] {
                    let mut choices = SampleRng::for_index(23, 0, 2);
                    let (stat, threshold) = chi_square(
                        &mut |u| sample_bsdf(&m, m.lambertian, Vec3::Z, w_o, choices.next_f32(), u).map(|s| s.w_i),
                        &|w_i| bsdf_pdf(&m, m.lambertian, Vec3::Z, w_o, w_i),
                        200_000,
                    );
                    let what = format!("{:?} alpha {} s {} k_L {}, w_o {w_o}", m.glossy_model, m.roughness, m.sharpness, m.lambertian);
                    assert!(stat < threshold, "{what}: chi-square {stat} >= {threshold}");
                }
            }
        }
        // The test tells a lobe from a slightly rougher one: GGX's samples
        // at alpha 0.3 against its density at alpha 0.36.
        let (m, rougher) = (glossy_material(GlossyModel::Ggx, 0.3, 0.0), glossy_material(GlossyModel::Ggx, 0.36, 0.0));
        let w_o = Vec3::new(0.6, 0.0, 0.8);
        let mut choices = SampleRng::for_index(23, 0, 2);
        let (stat, threshold) = chi_square(
            &mut |u| sample_bsdf(&m, Vec3::ZERO, Vec3::Z, w_o, choices.next_f32(), u).map(|s| s.w_i),
            &|w_i| bsdf_pdf(&rougher, Vec3::ZERO, Vec3::Z, w_o, w_i),
            200_000,
        );
        assert!(stat > threshold, "alpha 0.3 passes for 0.36: {stat} < {threshold}");
    }

    /// The diffuse models' sampling: directions against `bsdf_pdf` by the
    /// chi-square test (Minnaert by its own `cos^k` density, the others by
    /// the cosine; alone and beside a GGX lobe), and the sample weights'
    /// mean against the directional albedo by quadrature (`∫ f cos dw`,
    /// sharing no code with the sampling) within 1%.
    #[test]
    fn diffuse_models_sample_their_pdf_and_albedo() {
        use crate::render::transport::sampling::tests::chi_square;
        let models = [DiffuseModel::OrenNayar { sigma: 0.5 }, DiffuseModel::Minnaert { darkening: 0.0 }, DiffuseModel::Minnaert { darkening: 0.6 }, DiffuseModel::Toon { bands: 3 }];
        for model in models {
            let mut alone = Material::black();
            alone.lambertian = Vec3::splat(0.7);
            alone.diffuse_model = model;
            let mut mixed = glossy_material(GlossyModel::Ggx, 0.3, 0.0);
            mixed.glossy = Vec3::splat(0.3);
            mixed.lambertian = Vec3::splat(0.5);
            mixed.diffuse_model = model;
            for m in [alone, mixed] {
                for w_o in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.3, 0.9, 0.3).normalize()] {
                    let mut choices = SampleRng::for_index(24, 0, 2);
                    let (stat, threshold) = chi_square(
                        &mut |u| sample_bsdf(&m, m.lambertian, Vec3::Z, w_o, choices.next_f32(), u).map(|s| s.w_i),
                        &|w_i| bsdf_pdf(&m, m.lambertian, Vec3::Z, w_o, w_i),
                        200_000,
                    );
                    let what = format!("{model:?} k_G {}, w_o {w_o}", m.glossy);
                    assert!(stat < threshold, "{what}: chi-square {stat} >= {threshold}");
                    let sampled = albedo_estimate(&m, w_o, 200_000).x;
                    let exact = albedo_by_quadrature_with(&m, m.lambertian, w_o);
                    assert!((sampled - exact).abs() < 0.01 * exact.max(0.1), "{what}: sampled {sampled}, quadrature {exact}");
                }
            }
        }
        // The test tells Minnaert's density from the cosine's.
        let mut m = Material::black();
        m.lambertian = Vec3::splat(0.7);
        m.diffuse_model = DiffuseModel::Minnaert { darkening: 0.3 };
        let mut lambert = m.clone();
        lambert.diffuse_model = DiffuseModel::Lambert;
        let (stat, threshold) = chi_square(
            &mut |u| sample_bsdf(&m, m.lambertian, Vec3::Z, Vec3::Z, 0.5, u).map(|s| s.w_i),
            &|w_i| bsdf_pdf(&lambert, m.lambertian, Vec3::Z, Vec3::Z, w_i),
            200_000,
        );
        assert!(stat > threshold, "Minnaert's samples pass for the cosine's: {stat} < {threshold}");
    }

    /// Ward's sampling along a tangent frame (a tangent that is not unit
    /// nor orthogonal to n, made so): its directions against `bsdf_pdf` by
    /// the chi-square test, anisotropic and isotropic, alone and beside a
    /// Lambertian lobe; the sample weights' mean against the albedo by
    /// quadrature within 2%; and the test tells alpha (0.1, 0.4) from
    /// (0.4, 0.1), so the frame's orientation is what the pdf says.
    #[test]
    fn ward_samples_its_pdf_along_the_tangent() {
        use crate::render::transport::sampling::tests::chi_square;
        let frame = ShadingFrame { n: Vec3::Z, tangent: Vec3::new(0.8, 0.6, 0.3) };
        let ward = |au: f32, av: f32| {
            let mut m = glossy_material(GlossyModel::Ward, 0.1, 0.0);
            m.roughness_uv = Vec2::new(au, av);
            m
        };
        let chi = |m: &Material, pdf_of: &Material, w_o: Vec3| {
            let mut choices = SampleRng::for_index(25, 0, 2);
            chi_square(
                &mut |u| sample_bsdf(m, m.lambertian, frame, w_o, choices.next_f32(), u).map(|s| s.w_i),
                &|w_i| bsdf_pdf(pdf_of, m.lambertian, frame, w_o, w_i),
                200_000,
            )
        };
        for (au, av) in [(0.1f32, 0.4f32), (0.3, 0.3), (0.5, 0.15)] {
            let alone = ward(au, av);
            let mut mixed = alone.clone();
            mixed.lambertian = Vec3::splat(0.4);
            mixed.glossy = Vec3::splat(0.5);
            for m in [alone, mixed] {
                for w_o in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.3, 0.9, 0.3).normalize()] {
                    let (stat, threshold) = chi(&m, &m, w_o);
                    let what = format!("Ward ({au}, {av}) k_L {}, w_o {w_o}", m.lambertian);
                    assert!(stat < threshold, "{what}: chi-square {stat} >= {threshold}");
                }
            }
            let m = ward(au, av);
            for w_o in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8)] {
                let mut r = SampleRng::for_index(26, 0, 1);
                let n = 200_000;
                let mut sum = 0.0f64;
                for _ in 0..n {
                    let choice = r.next_f32();
                    if let Some(s) = sample_bsdf(&m, Vec3::ZERO, frame, w_o, choice, r.next_2d()) {
                        sum += s.weight.x as f64;
                    }
                }
                let sampled = sum / n as f64;
                let exact = integrate_sphere(400, 800, Vec3::Z, |w_i| if w_i.z > 0.0 { (bsdf(&m, Vec3::ZERO, frame, w_i, w_o).x * w_i.z) as f64 } else { 0.0 });
                assert!((sampled - exact).abs() < 0.02 * exact, "Ward ({au}, {av}) w_o {w_o}: sampled {sampled}, quadrature {exact}");
            }
        }
        let (stat, threshold) = chi(&ward(0.1, 0.4), &ward(0.4, 0.1), Vec3::new(0.6, 0.0, 0.8));
        assert!(stat > threshold, "Ward (0.1, 0.4) passes for (0.4, 0.1): {stat} < {threshold}");
    }

    /// A white furnace for nearly smooth GGX: `∫ f cos dw` over the
    /// hemisphere is at most one (a microfacet lobe without Fresnel only
    /// loses light, to shadowing) and close to one (little is shadowed
    /// when alpha is small: the least here is 0.94, at alpha 0.1 seen at
    /// cos 0.3). The lobe is narrow (about alpha wide about the
    /// mirror direction r), so the midpoint rule runs in polar coordinates
    /// about r with steps of 0.05 degrees, over 20 points across the
    /// narrowest lobe: its error is far below the 1e-3 allowed.
    #[test]
    fn smooth_ggx_reflects_at_most_what_arrives() {
        for alpha in [0.01f32, 0.05, 0.1] {
            let m = glossy_material(GlossyModel::Ggx, alpha, 0.0);
            for cos_o in [1.0f32, 0.7, 0.3] {
                let w_o = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
                let r = reflect(w_o, Vec3::Z).normalize();
                let sum = integrate_sphere(3600, 256, r, |w_i| if w_i.z > 0.0 { (bsdf(&m, Vec3::ZERO, Vec3::Z, w_i, w_o).x * w_i.z) as f64 } else { 0.0 });
                assert!(sum <= 1.001, "alpha {alpha}, cos_o {cos_o}: the lobe reflects {sum}");
                assert!(sum > 0.9, "alpha {alpha}, cos_o {cos_o}: the lobe reflects only {sum}");
            }
        }
    }

    #[test]
    fn pdf_agrees_with_the_sampled_mixture() {
        // The mixture density must integrate to at most one over the hemisphere
        // and to one when no sample can fall below it (w_o along n, diffuse).
        let mut m = Material::black();
        m.lambertian = Vec3::splat(0.5);
        m.glossy = Vec3::splat(0.3);
        m.sharpness = 20.0;
        let w_o = Vec3::new(0.3, 0.1, 0.9).normalize();
        let mut r = SampleRng::for_index(22, 0, 1);
        let n = 200_000;
        let mut integral = 0.0f64;
        for _ in 0..n {
            // Uniform hemisphere: integral of pdf = mean(pdf / (1 / 2 pi)).
            let u = r.next_2d();
            let z = u.x;
            let s = (1.0 - z * z).sqrt();
            let phi = 2.0 * std::f32::consts::PI * u.y;
            let w_i = Vec3::new(s * phi.cos(), s * phi.sin(), z);
            integral += (bsdf_pdf(&m, m.lambertian, Vec3::Z, w_o, w_i) * 2.0 * std::f32::consts::PI) as f64;
        }
        let integral = integral / n as f64;
        assert!(integral <= 1.01 && integral > 0.9, "{integral}");
    }
}
