//! Direct light, written once over a lane type (`math::lanes`): how each
//! light arrives at a surface point, the BSDF (CGPP listing 15.19) and their
//! sum over the lights. `shade()` runs it one sample wide, and a frame's
//! batches (`shade_batch`) eight wide, through the same code: the pixel a
//! replay shows is the pixel the frame computed, bit for bit.
//!
//! Visibility is not decided here: a [`LightVisibility`] answers it per light
//! (shadow rays, maps, volumes, or a packet's answers), because how it is
//! known differs between callers while the arithmetic must not.

use crate::math::lanes::{exp2, pow, Lane, V3};
use crate::render::transport::microfacet;
use crate::scene::material::{DiffuseModel, Fresnel, GlossyModel};
use crate::scene::{Light, Lighting};
use std::f32::consts::PI;

/// What the BSDF and the lights need of a surface, per lane.
#[derive(Clone, Copy)]
pub struct SurfaceLanes<L: Lane> {
    pub position: V3<L>,
    /// Unit shading normal.
    pub normal: V3<L>,
    /// Unit direction towards the viewer.
    pub w_o: V3<L>,
    /// Diffuse albedo k_L (texture applied).
    pub albedo: V3<L>,
    /// The diffuse lobe's model and parameter.
    pub diffuse: DiffuseLanes<L>,
    /// The glossy lobe's weight k_G, and the Blinn-Phong and Phong lobes'
    /// sharpness s.
    pub glossy: V3<L>,
    pub sharpness: L,
    /// The glossy lobe's model, as `model_lane` codes it (lanes may differ).
    pub glossy_model: L,
    /// The microfacet lobes' alpha, and Ward's alpha along u.
    pub roughness: L,
    /// Ward's alpha along v.
    pub roughness_v: L,
    /// The surface's tangent (the direction of growing u), not necessarily
    /// unit or orthogonal to the normal; zero where there is none. Only
    /// Ward's lobe reads it.
    pub tangent: V3<L>,
    /// The glossy lobe's Fresnel term.
    pub fresnel: FresnelLanes<L>,
}

/// A diffuse lobe per lane: its model (`diffuse_lane`'s code) and that
/// model's parameter (`DiffuseModel::parameter`).
#[derive(Clone, Copy)]
pub struct DiffuseLanes<L: Lane> {
    pub model: L,
    pub param: L,
}

impl<L: Lane> DiffuseLanes<L> {
    /// `model` in every lane.
    #[inline(always)]
    pub fn splat(like: L, model: DiffuseModel) -> Self {
        DiffuseLanes { model: like.splat(diffuse_lane(model)), param: like.splat(model.parameter()) }
    }
}

/// `model` as the number `DiffuseLanes::model` holds (Lambert is 0, the
/// others above it).
#[inline(always)]
pub fn diffuse_lane(model: DiffuseModel) -> f32 {
    match model {
        DiffuseModel::Lambert => 0.0,
        DiffuseModel::OrenNayar { .. } => 1.0,
        DiffuseModel::Minnaert { .. } => 2.0,
        DiffuseModel::Toon { .. } => 3.0,
    }
}

/// A glossy lobe's Fresnel term per lane: which one (`fresnel_lane`'s
/// code) and, for a conductor, its complex index of refraction `eta + i k`.
#[derive(Clone, Copy)]
pub struct FresnelLanes<L: Lane> {
    pub model: L,
    pub eta: V3<L>,
    pub k: V3<L>,
}

impl<L: Lane> FresnelLanes<L> {
    /// `fresnel` in every lane.
    #[inline(always)]
    pub fn splat(like: L, fresnel: Fresnel) -> Self {
        let (eta, k) = match fresnel {
            Fresnel::Conductor { eta, k } => (eta, k),
            _ => (glam::Vec3::ZERO, glam::Vec3::ZERO),
        };
        FresnelLanes { model: like.splat(fresnel_lane(fresnel)), eta: V3::splat(like, eta), k: V3::splat(like, k) }
    }
}

/// `fresnel` as the number `FresnelLanes::model` holds.
#[inline(always)]
pub fn fresnel_lane(fresnel: Fresnel) -> f32 {
    match fresnel {
        Fresnel::None => 0.0,
        Fresnel::Schlick => 1.0,
        Fresnel::Conductor { .. } => 2.0,
    }
}

/// `model` as the number `SurfaceLanes::glossy_model` holds.
#[inline(always)]
pub fn model_lane(model: GlossyModel) -> f32 {
    match model {
        GlossyModel::BlinnPhong => 0.0,
        GlossyModel::Phong => 1.0,
        GlossyModel::Ggx => 2.0,
        GlossyModel::Beckmann => 3.0,
        GlossyModel::Ward => 4.0,
    }
}

/// The alpha `SurfaceLanes::roughness` holds for `material` at a point of
/// microfacet alpha `alpha`: Ward's alpha along u for its lobe, else `alpha`.
#[inline(always)]
pub fn roughness_u(material: &crate::scene::Material, alpha: f32) -> f32 {
    if material.glossy_model == GlossyModel::Ward { material.roughness_uv.x } else { alpha }
}

/// The alpha `SurfaceLanes::roughness_v` holds: Ward's alpha along v.
#[inline(always)]
pub fn roughness_v(material: &crate::scene::Material) -> f32 {
    material.roughness_uv.y
}

/// How one light arrives at a surface point, per lane, before visibility.
#[derive(Clone, Copy)]
pub struct IncidenceLanes<L: Lane> {
    /// Unit direction towards the light.
    pub w_i: V3<L>,
    /// Distance to the light (infinite for directional lights).
    pub distance: L,
    /// Incident radiance (point, CGPP 15.4.5: power / (4 pi d^2)) or
    /// irradiance (directional).
    pub incident: V3<L>,
    /// `w_i . n` with the shading normal.
    pub cos_theta: L,
    /// False where a point light sits exactly at the point: it has no
    /// direction there and contributes nothing (the other fields are then
    /// meaningless).
    pub exists: L::Mask,
}

impl<L: Lane> IncidenceLanes<L> {
    /// Where the light reaches the surface's lit side with some radiance:
    /// only there can it contribute, and only there is visibility asked.
    #[inline(always)]
    pub fn illuminates(&self) -> L::Mask {
        let zero = self.cos_theta.splat(0.0);
        self.exists & !(self.cos_theta.le(zero) | self.incident.is_zero())
    }
}

/// Light `light` at points `p` with unit shading normals `n`.
#[inline(always)]
pub fn incidence<L: Lane>(light: &Light, p: V3<L>, n: V3<L>) -> IncidenceLanes<L> {
    let like = p.x;
    let (w_i, distance, incident, exists) = match *light {
        Light::Point { position, power } => {
            let offset = V3::splat(like, position) - p;
            let d = offset.length();
            let w_i = offset.div(d);
            (w_i, d, V3::splat(like, power).div(like.splat(4.0 * PI) * d * d), d.gt(like.splat(0.0)))
        }
        Light::Directional { direction, irradiance } => {
            let always = like.eq(like) | !like.eq(like);
            (V3::splat(like, -direction), like.splat(f32::INFINITY), V3::splat(like, irradiance), always)
        }
    };
    IncidenceLanes { w_i, distance, incident, cos_theta: w_i.dot(n), exists }
}

/// The BSDF: a diffuse lobe (`diffuse`: Lambertian `k_L / pi` unless the
/// material names another model) plus a glossy lobe, `f = f_d + k_G lobe`,
/// the glossy lobe chosen per lane by `glossy_model`:
///
/// - Blinn-Phong (CGPP listing 15.19): `N(s) max(0, n.h)^s` with `N` from
///   `blinn_phong_normalization`;
/// - Phong: `(s + 2) / (2 pi) max(0, r.w_i)^s`, r the mirror direction of
///   `w_o` about n;
/// - GGX and Beckmann: Mitsuba 3's `roughconductor` without Fresnel,
///   `D(h) G1(w_i) G1(w_o) / (4 cos_i cos_o)` (`microfacet`), zero unless
///   both directions are above the surface.
///
/// The lobe's weight is k_G itself with `fresnel = none`; otherwise it
/// depends on the cosine between the light and the half vector
/// (`glossy_weight`): Schlick's `F0 + (1 - F0)(1 - cos)^5` with F0 = k_G, or
/// k_G times a conductor's exact Fresnel reflectance. For the microfacet
/// lobes that gives Cook-Torrance's `F D G / (4 cos_i cos_o)`.
///
/// The glossy lobe is left out where k_G = 0, and the two power lobes where
/// they cannot matter: `c^s <= exp(-s (1 - c))` since `ln c <= c - 1`, so
/// when that bound is below 1e-9 the lobe adds nothing visible and the
/// power is not computed (in no lane, when no lane needs it). Each model is
/// computed only when some lane has it; each lane takes its own model's
/// value, so a lane's bits do not depend on its neighbours'.
#[inline(always)]
pub fn bsdf<L: Lane>(s: &SurfaceLanes<L>, w_i: V3<L>) -> V3<L> {
    let like = s.sharpness;
    let f = diffuse(s, w_i);
    let glossy = !s.glossy.is_zero();
    if !L::any(glossy) {
        return f;
    }
    let weight = glossy_weight(s, w_i);
    let mut out = f;
    for model in [GlossyModel::BlinnPhong, GlossyModel::Phong, GlossyModel::Ggx, GlossyModel::Beckmann, GlossyModel::Ward] {
        let lanes = glossy & s.glossy_model.eq(like.splat(model_lane(model)));
        if !L::any(lanes) {
            continue;
        }
        let (counted, lobe) = match model {
            GlossyModel::BlinnPhong => {
                let w_h = (w_i + s.w_o).normalize_or_zero();
                power_lobe(lanes, s.sharpness, s.normal.dot(w_h), || blinn_phong_normalization(s.sharpness))
            }
            GlossyModel::Phong => {
                let r = s.normal.scale(like.splat(2.0) * s.normal.dot(s.w_o)) - s.w_o;
                let sharp = s.sharpness;
                power_lobe(lanes, sharp, r.dot(w_i), || (sharp + like.splat(2.0)) * like.splat(0.5 / PI))
            }
            GlossyModel::Ggx | GlossyModel::Beckmann => {
                let (above, lobe) = microfacet_lobe(s, w_i, model == GlossyModel::Ggx);
                (lanes & above, lobe)
            }
            GlossyModel::Ward => {
                let (above, lobe) = ward_lobe(s, w_i);
                (lanes & above, lobe)
            }
        };
        out = V3::select(counted, f + weight.scale(lobe), out);
    }
    out
}

/// The diffuse lobe towards `w_i`, `k_L / pi` times a factor per model,
/// with c_i = n.w_i and c_o = n.w_o:
///
/// - Lambert: 1 (the same bits as `k_L / pi`; nothing else is computed
///   when every lane is Lambertian);
/// - Oren-Nayar (qualitative model): `A + B max(0, cos(phi_i - phi_o))
///   sin(alpha) tan(beta)` with `A = 1 - 0.5 s^2 / (s^2 + 0.33)`,
///   `B = 0.45 s^2 / (s^2 + 0.09)`, alpha and beta the larger and smaller
///   angle to n, computed as `max(0, t_i.t_o) / max(c_i, c_o)` with t the
///   directions' tangential parts; at sigma 0 it is 1 exactly;
/// - Minnaert (normalized so that it reflects at most k_L): `(k + 1) / 2
///   (c_i / c_o)^(k - 1)`, the cosines taken at least 1e-4;
/// - toon: `q(c_i) / c_i`, q rounding `c_i` to the nearest of 0, 1/b, ...,
///   1 (b bands), so that `f c_i` is flat within a band.
#[inline(always)]
fn diffuse<L: Lane>(s: &SurfaceLanes<L>, w_i: V3<L>) -> V3<L> {
    let like = s.sharpness;
    let inv_pi = like.splat(1.0 / PI);
    let (model, param) = (s.diffuse.model, s.diffuse.param);
    let zero = like.splat(0.0);
    if !L::any(model.gt(zero)) {
        return s.albedo.scale(inv_pi);
    }
    let one = like.splat(1.0);
    let n = s.normal;
    let (cos_i, cos_o) = (n.dot(w_i), n.dot(s.w_o));
    let mut factor = inv_pi;
    let oren_nayar = model.eq(like.splat(diffuse_lane(DiffuseModel::OrenNayar { sigma: 0.0 })));
    if L::any(oren_nayar) {
        let s2 = param * param;
        let a = one - like.splat(0.5) * s2 / (s2 + like.splat(0.33));
        let b = like.splat(0.45) * s2 / (s2 + like.splat(0.09));
        let (t_i, t_o) = (w_i - n.scale(cos_i), s.w_o - n.scale(cos_o));
        let t = t_i.dot(t_o).max(zero) / cos_i.max(cos_o).max(like.splat(1e-4));
        factor = L::select(oren_nayar, inv_pi * (a + b * t), factor);
    }
    let minnaert = model.eq(like.splat(diffuse_lane(DiffuseModel::Minnaert { darkening: 0.0 })));
    if L::any(minnaert) {
        let floor = like.splat(1e-4);
        let ratio = cos_i.max(floor) / cos_o.max(floor);
        let m = (param + one) * like.splat(0.5) * pow(ratio, param - one);
        factor = L::select(minnaert, inv_pi * m, factor);
    }
    let toon = model.eq(like.splat(diffuse_lane(DiffuseModel::Toon { bands: 1 })));
    if L::any(toon) {
        let q = ((cos_i.max(zero) * param + like.splat(0.5)).floor() / param).min(one);
        let t = L::select(q.gt(zero), q / cos_i, zero);
        factor = L::select(toon, inv_pi * t, factor);
    }
    s.albedo.scale(factor)
}

/// The glossy lobe's weight towards `w_i`: k_G where there is no Fresnel
/// term (the same bits: nothing is computed when no lane has one),
/// Schlick's approximation with F0 = k_G, or k_G times a conductor's
/// reflectance, at the cosine between `w_i` and the half vector.
#[inline(always)]
fn glossy_weight<L: Lane>(s: &SurfaceLanes<L>, w_i: V3<L>) -> V3<L> {
    let zero = s.sharpness.splat(0.0);
    let model = s.fresnel.model;
    let schlick = model.eq(zero.splat(fresnel_lane(Fresnel::Schlick)));
    let conductor = model.eq(zero.splat(fresnel_lane(Fresnel::Conductor { eta: glam::Vec3::ZERO, k: glam::Vec3::ZERO })));
    if !L::any(schlick | conductor) {
        return s.glossy;
    }
    let h = (w_i + s.w_o).normalize_or_zero();
    let c = w_i.dot(h).max(zero).min(zero.splat(1.0));
    let mut weight = s.glossy;
    if L::any(schlick) {
        let m = zero.splat(1.0) - c;
        let m5 = m * m * m * m * m;
        let f0 = s.glossy;
        let one = V3::new(zero.splat(1.0), zero.splat(1.0), zero.splat(1.0));
        weight = V3::select(schlick, f0 + (one - f0).scale(m5), weight);
    }
    if L::any(conductor) {
        let (eta, k) = (s.fresnel.eta, s.fresnel.k);
        let f = V3::new(conductor_fresnel(c, eta.x, k.x), conductor_fresnel(c, eta.y, k.y), conductor_fresnel(c, eta.z, k.z));
        weight = V3::select(conductor, s.glossy * f, weight);
    }
    weight
}

/// The unpolarized Fresnel reflectance of a conductor with complex index
/// of refraction `eta + i k`, lit at the cosine `c` (in [0, 1]) from
/// outside: the mean of the s- and p-polarized reflectances, with
/// `a^2 + b^2 = |n^2 - sin^2|` and `a` the real part of `sqrt(n^2 - sin^2)`.
/// 1 where the expression has no value (a lossless index of 1 at grazing
/// light).
#[inline(always)]
pub fn conductor_fresnel<L: Lane>(c: L, eta: L, k: L) -> L {
    let one = c.splat(1.0);
    let cos2 = c * c;
    let sin2 = one - cos2;
    let t = eta * eta - k * k - sin2;
    let a2b2 = (t * t + c.splat(4.0) * eta * eta * k * k).max(c.splat(0.0)).sqrt();
    let a = ((a2b2 + t) * c.splat(0.5)).max(c.splat(0.0)).sqrt();
    let two_ac = c.splat(2.0) * a * c;
    let r_s = (a2b2 + cos2 - two_ac) / (a2b2 + cos2 + two_ac);
    let (p1, p2) = (a2b2 * cos2 + sin2 * sin2, two_ac * sin2);
    let r_p = r_s * (p1 - p2) / (p1 + p2);
    let f = (r_s + r_p) * c.splat(0.5);
    L::select(f.eq(f), f, one)
}

/// `norm() max(0, c)^s`, and the lanes of `lanes` where it is worth
/// computing (see `bsdf`).
#[inline(always)]
fn power_lobe<L: Lane>(lanes: L::Mask, sharp: L, c: L, norm: impl FnOnce() -> L) -> (L::Mask, L) {
    let c = c.max(c.splat(0.0));
    let needed = lanes & (sharp * (c.splat(1.0) - c)).lt(c.splat(20.7));
    if !L::any(needed) {
        return (needed, c.splat(0.0));
    }
    (needed, norm() * pow(c, sharp))
}

/// `D(h) G1(w_i) G1(w_o) / (4 cos_i cos_o)` for the GGX (`ggx`) or
/// Beckmann distribution, and where both directions are above the surface.
#[inline(always)]
fn microfacet_lobe<L: Lane>(s: &SurfaceLanes<L>, w_i: V3<L>, ggx: bool) -> (L::Mask, L) {
    let zero = s.roughness.splat(0.0);
    let a = s.roughness;
    let cos_i = s.normal.dot(w_i);
    let cos_o = s.normal.dot(s.w_o);
    let h = (w_i + s.w_o).normalize_or_zero();
    let cos_h = s.normal.dot(h);
    let (i_h, o_h) = (w_i.dot(h), s.w_o.dot(h));
    let (d, g) = if ggx {
        (microfacet::ggx_d(cos_h, a), microfacet::ggx_g1(cos_i, i_h, a) * microfacet::ggx_g1(cos_o, o_h, a))
    } else {
        (microfacet::beckmann_d(cos_h, a), microfacet::beckmann_g1(cos_i, i_h, a) * microfacet::beckmann_g1(cos_o, o_h, a))
    };
    let above = cos_i.gt(zero) & cos_o.gt(zero);
    let lobe = d * g / (zero.splat(4.0) * cos_i * cos_o);
    (above, L::select(above, lobe, zero))
}

/// Ward's anisotropic lobe,
/// `exp(-((h.t / a_u)^2 + (h.b / a_v)^2) / (h.n)^2) / (4 pi a_u a_v sqrt(cos_i cos_o))`
/// with h = w_i + w_o (its length cancels) and (t, b, n) the frame
/// `ward_frame` builds, and where both directions are above the surface.
#[inline(always)]
fn ward_lobe<L: Lane>(s: &SurfaceLanes<L>, w_i: V3<L>) -> (L::Mask, L) {
    let zero = s.roughness.splat(0.0);
    let n = s.normal;
    let (cos_i, cos_o) = (n.dot(w_i), n.dot(s.w_o));
    let above = cos_i.gt(zero) & cos_o.gt(zero);
    let (t, b) = ward_frame(n, s.tangent);
    let h = w_i + s.w_o;
    let (au, av) = (s.roughness, s.roughness_v);
    let (x, y, z) = (h.dot(t) / au, h.dot(b) / av, h.dot(n));
    let e = -((x * x + y * y) / (z * z)) * zero.splat(std::f32::consts::LOG2_E);
    let in_range = e.ge(zero.splat(-126.0));
    let d = exp2(e.max(zero.splat(-126.0))) / (zero.splat(4.0 * PI) * au * av * (cos_i * cos_o).max(zero).sqrt());
    let lobe = L::select(in_range & above, d, zero);
    (above, lobe)
}

/// The unit tangent and bitangent of Ward's frame at unit normal `n`:
/// `tangent` made orthogonal to n, or where that leaves nothing (no
/// tangent, or one along n) a fixed perpendicular, `x cross n` (`y cross n`
/// when n is near x). The bitangent is `n cross t`.
#[inline(always)]
pub fn ward_frame<L: Lane>(n: V3<L>, tangent: V3<L>) -> (V3<L>, V3<L>) {
    let like = n.x;
    let t = (tangent - n.scale(n.dot(tangent))).normalize_or_zero();
    let near_x = n.x.max(-n.x).gt(like.splat(0.9));
    let axis = V3::select(near_x, V3::splat(like, glam::Vec3::Y), V3::splat(like, glam::Vec3::X));
    let t = V3::select(t.is_zero(), axis.cross(n).normalize(), t);
    (t, n.cross(t))
}

/// `N(s) = (s + 2)(s + 4) / (8 pi (2^(-s/2) + s))`: the factor that makes
/// the Blinn-Phong lobe `N(s) (n.h)^s` reflect exactly what arrives when
/// seen along the normal, and less at every other angle (the horizon cuts
/// the lobe off there). The book's `(s + 8) / (8 pi)` approximates it and
/// reflects up to 7.5% more than arrives near s = 8; both tend to `s / (8
/// pi)` as s grows, and at s = 0 both give the Lambertian `1 / pi`.
#[inline(always)]
pub fn blinn_phong_normalization<L: Lane>(s: L) -> L {
    let half = (s * s.splat(-0.5)).max(s.splat(-126.0));
    (s + s.splat(2.0)) * (s + s.splat(4.0)) / (s.splat(8.0 * PI) * (exp2(half) + s))
}

/// A light's intensity under `Lighting::Classic`: its `power` or
/// `irradiance` as given, whatever the distance.
#[inline(always)]
pub fn classic_intensity(light: &Light) -> glam::Vec3 {
    match *light {
        Light::Point { power, .. } => power,
        Light::Directional { irradiance, .. } => irradiance,
    }
}

/// What a surface reflects of a light of intensity 1 towards the viewer
/// under `Lighting::Classic` (Computer Graphics from Scratch, ch. 3): the
/// diffuse lobe's `f_d pi cos_i` (Lambert: `k_L cos_i`, no `1 / pi`) plus
/// the glossy lobe's raw power `k_G c^s`, with c = r.w_i for Phong (r the
/// mirror direction of the viewer; the book's R.V) and c = n.h for
/// Blinn-Phong, neither normalized nor multiplied by the cosine. `cos_i` is
/// `n.w_i`; lights behind the surface are never asked for.
#[inline(always)]
pub fn classic_reflection<L: Lane>(s: &SurfaceLanes<L>, w_i: V3<L>, cos_i: L) -> V3<L> {
    let like = s.sharpness;
    let zero = like.splat(0.0);
    let diffuse = if L::any(s.diffuse.model.gt(zero)) { diffuse(s, w_i).scale(like.splat(PI) * cos_i) } else { s.albedo.scale(cos_i) };
    let glossy = !s.glossy.is_zero();
    if !L::any(glossy) {
        return diffuse;
    }
    let phong = s.glossy_model.eq(like.splat(model_lane(GlossyModel::Phong)));
    let r = s.normal.scale(like.splat(2.0) * s.normal.dot(s.w_o)) - s.w_o;
    let w_h = (w_i + s.w_o).normalize_or_zero();
    let c = L::select(phong, r.dot(w_i), s.normal.dot(w_h));
    let (counted, lobe) = power_lobe(glossy, s.sharpness, c, || like.splat(1.0));
    V3::select(counted, diffuse + glossy_weight(s, w_i).scale(lobe), diffuse)
}

/// Answers, per light, whether it is visible from the surface, and hears
/// what it contributed (for the pixel recorder).
pub trait LightVisibility<L: Lane> {
    /// Visibility of light `light` in the lanes of `lit` (other lanes are ignored).
    fn visible(&mut self, light: usize, incidence: &IncidenceLanes<L>, lit: L::Mask) -> L::Mask;

    /// Light `light`'s BSDF value and contribution, zero where not lit or
    /// not visible; called for every light that exists in some lane.
    #[inline(always)]
    fn reflected(&mut self, _light: usize, _incidence: &IncidenceLanes<L>, _lit: L::Mask, _bsdf: V3<L>, _contribution: V3<L>) {}
}

/// `start` (the ambient or indirect term) plus every light's
/// `incident * f * cos`, in the order of `lights`, where visible. Under
/// `Lighting::Classic` a light's incident value is its intensity at any
/// distance and its term is `classic_reflection` instead.
#[inline(always)]
pub fn direct_light<L: Lane, V: LightVisibility<L>>(lights: &[Light], lighting: Lighting, s: &SurfaceLanes<L>, start: V3<L>, vis: &mut V) -> V3<L> {
    let zero = V3::splat(s.sharpness, glam::Vec3::ZERO);
    let mut l_o = start;
    for (index, light) in lights.iter().enumerate() {
        let mut inc = incidence(light, s.position, s.normal);
        if !L::any(inc.exists) {
            continue;
        }
        if lighting == Lighting::Classic {
            inc.incident = V3::splat(s.sharpness, classic_intensity(light));
        }
        let lit = inc.illuminates();
        if !L::any(lit) {
            vis.reflected(index, &inc, lit, zero, zero);
            continue;
        }
        let visible = vis.visible(index, &inc, lit);
        let (f, contribution) = match lighting {
            Lighting::Physical => {
                let f = bsdf(s, inc.w_i);
                (f, (inc.incident * f).scale(inc.cos_theta))
            }
            Lighting::Classic => {
                let r = classic_reflection(s, inc.w_i, inc.cos_theta);
                // Reported as the factor on the light's intensity.
                (r, inc.incident * r)
            }
        };
        let counted = lit & visible;
        l_o = V3::select(counted, l_o + contribution, l_o);
        vis.reflected(index, &inc, lit, V3::select(lit, f, zero), V3::select(counted, contribution, zero));
    }
    l_o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn surface(model: GlossyModel, glossy: Vec3, w_o: Vec3) -> SurfaceLanes<f32> {
        SurfaceLanes {
            position: Vec3::ZERO.into(),
            normal: Vec3::Z.into(),
            w_o: w_o.into(),
            albedo: Vec3::ZERO.into(),
            diffuse: DiffuseLanes::splat(0.0, DiffuseModel::Lambert),
            glossy: glossy.into(),
            sharpness: 10.0,
            glossy_model: model_lane(model),
            roughness: 0.5,
            roughness_v: 0.5,
            tangent: Vec3::ZERO.into(),
            fresnel: FresnelLanes::splat(0.0, Fresnel::None),
        }
    }

    fn close(got: V3<f32>, want: Vec3) -> bool {
        (Vec3::new(got.x, got.y, got.z) - want).abs().max_element() < 1e-5
    }

    /// GGX at alpha 0.5, n = z, w_o = (0.6, 0, 0.8), w_i = z, worked by hand:
    /// h = (0.6, 0, 1.8) / sqrt(3.6) = (0.316228, 0, 0.948683), cos_h^2 = 0.9;
    /// D = 1 / (pi a^2 (sin_h^2 / a^2 + cos_h^2)^2) = 1 / (pi 0.25 1.3^2) = 0.753396;
    /// G1(w_i) = 1 (along the normal); G1(w_o): tan^2 = 0.36 / 0.64 = 0.5625,
    /// a^2 tan^2 = 0.140625, G1 = 2 / (1 + sqrt(1.140625)) = 2 / 2.068 = 0.967118;
    /// f / k_G = D G / (4 cos_i cos_o) = 0.753396 0.967118 / 3.2 = 0.227695.
    /// Beckmann's `D` there is exp(-(0.1 / 0.9) / 0.25) / (pi 0.25 0.9^2)
    /// = 0.641180 / 0.636173 = 1.007872.
    #[test]
    fn ggx_lobe_has_its_hand_computed_value() {
        let k_g = Vec3::new(0.9, 0.5, 0.2);
        let w_o = Vec3::new(0.6, 0.0, 0.8);
        let f = bsdf(&surface(GlossyModel::Ggx, k_g, w_o), Vec3::Z.into());
        assert!(close(f, k_g * 0.227695), "{f:?}");
        // Below the surface on either side the microfacet lobe is black.
        let f = bsdf(&surface(GlossyModel::Ggx, k_g, w_o), Vec3::new(0.0, 0.6, -0.8).into());
        assert!(close(f, Vec3::ZERO), "{f:?}");
        let f = bsdf(&surface(GlossyModel::Ggx, k_g, Vec3::new(0.6, 0.0, -0.8)), Vec3::Z.into());
        assert!(close(f, Vec3::ZERO), "{f:?}");
        // Beckmann: the same configuration with its D and G1 (the latter 1:
        // b = 1 / sqrt(0.140625) = 2.667 >= 1.6).
        let f = bsdf(&surface(GlossyModel::Beckmann, Vec3::ONE, w_o), Vec3::Z.into());
        assert!(close(f, Vec3::splat(1.007872 / 3.2)), "{f:?}");
    }

    /// Phong at s = 10 with w_o = (0.6, 0, 0.8): r = (-0.6, 0, 0.8), and
    /// towards w_i = z, r.w_i = 0.8: f = 12 / (2 pi) 0.8^10 = 0.205070.
    #[test]
    fn phong_lobe_has_its_hand_computed_value() {
        let f = bsdf(&surface(GlossyModel::Phong, Vec3::ONE, Vec3::new(0.6, 0.0, 0.8)), Vec3::Z.into());
        assert!(close(f, Vec3::splat(0.205070)), "{f:?}");
    }

    /// A conductor's reflectance against the Fresnel equations in complex
    /// arithmetic (f64, written here from the equations, not from the code
    /// under test): with n = eta + i k and w = sqrt(n^2 - sin^2),
    /// r_s = (cos - w) / (cos + w), r_p = (n^2 cos - w) / (n^2 cos + w),
    /// F = (|r_s|^2 + |r_p|^2) / 2.
    #[test]
    fn conductor_fresnel_matches_the_complex_fresnel_equations() {
        type C = (f64, f64);
        let mul = |a: C, b: C| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
        let div = |a: C, b: C| {
            let d = b.0 * b.0 + b.1 * b.1;
            ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
        };
        let sqrt = |a: C| {
            let r = (a.0 * a.0 + a.1 * a.1).sqrt();
            (((r + a.0) / 2.0).sqrt(), ((r - a.0) / 2.0).sqrt().copysign(a.1))
        };
        let norm2 = |a: C| a.0 * a.0 + a.1 * a.1;
        let exact = |c: f64, eta: f64, k: f64| {
            let n2 = mul((eta, k), (eta, k));
            let w = sqrt((n2.0 - (1.0 - c * c), n2.1));
            let r_s = div((c - w.0, -w.1), (c + w.0, w.1));
            let n2c = (n2.0 * c, n2.1 * c);
            let r_p = div((n2c.0 - w.0, n2c.1 - w.1), (n2c.0 + w.0, n2c.1 + w.1));
            (norm2(r_s) + norm2(r_p)) / 2.0
        };
        for (eta, k) in [(0.2f32, 3.9f32), (0.9, 2.4), (1.1, 2.2), (1.5, 0.0), (2.9, 3.1), (0.05, 0.1)] {
            for c in [1.0f32, 0.9, 0.6, 0.3, 0.1, 0.01] {
                let (got, want) = (conductor_fresnel(c, eta, k) as f64, exact(c as f64, eta as f64, k as f64));
                assert!((got - want).abs() < 2e-5, "eta {eta} k {k} cos {c}: {got}, equations {want}");
            }
            // Along the normal: ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2).
            let normal = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
            assert!((conductor_fresnel(1.0f32, eta, k) - normal).abs() < 1e-6);
            // Grazing light is reflected whole.
            assert!((conductor_fresnel(0.0f32, eta, k) - 1.0).abs() < 1e-6);
        }
        assert_eq!(conductor_fresnel(0.0f32, 1.0, 0.0), 1.0);
    }

    /// The glossy weight of each Fresnel term: GGX at the hand-computed
    /// configuration of `ggx_lobe_has_its_hand_computed_value`, where the
    /// light w_i = z makes the cosine with h = (0.316228, 0, 0.948683)
    /// 0.948683: Schlick with F0 = 0.04 gives 0.04 + 0.96 (0.051317)^5 =
    /// 0.040000346; a conductor eta 0.2, k 3.9 gives its Fresnel value
    /// times k_G; none gives k_G.
    #[test]
    fn fresnel_terms_weight_the_glossy_lobe() {
        let w_o = Vec3::new(0.6, 0.0, 0.8);
        let lobe = 0.227695;
        let mut s = surface(GlossyModel::Ggx, Vec3::splat(0.04), w_o);
        s.fresnel = FresnelLanes::splat(0.0, Fresnel::Schlick);
        let f = bsdf(&s, Vec3::Z.into());
        let schlick = 0.04 + 0.96 * (1.0f32 - 0.948683).powi(5);
        assert!(close(f, Vec3::splat(schlick * lobe)), "{f:?}");
        // At grazing incidence Schlick tends to 1 whatever F0 is: w_o and
        // w_i nearly opposite about the normal, nearly along the surface.
        let grazing = Vec3::new(0.999, 0.0, 0.0447).normalize();
        let mut s = surface(GlossyModel::BlinnPhong, Vec3::splat(0.04), grazing);
        s.sharpness = 1.0;
        let w_i: V3<f32> = Vec3::new(-0.999, 0.0, 0.0447).normalize().into();
        let plain = bsdf(&s, w_i).x;
        s.fresnel = FresnelLanes::splat(0.0, Fresnel::Schlick);
        let weighted = bsdf(&s, w_i).x;
        assert!(weighted > 10.0 * plain, "Schlick {weighted}, none {plain}");
        let (eta, k) = (Vec3::new(0.2, 0.9, 1.1), Vec3::new(3.9, 2.4, 2.2));
        let k_g = Vec3::new(1.0, 0.5, 0.25);
        let mut s = surface(GlossyModel::Ggx, k_g, w_o);
        s.fresnel = FresnelLanes::splat(0.0, Fresnel::Conductor { eta, k });
        let f = bsdf(&s, Vec3::Z.into());
        let c = 0.948683f32;
        let want = k_g * Vec3::new(conductor_fresnel(c, eta.x, k.x), conductor_fresnel(c, eta.y, k.y), conductor_fresnel(c, eta.z, k.z)) * lobe;
        assert!(close(f, want), "{f:?} {want}");
        assert!(want.x < k_g.x * lobe && want.x > 0.8 * k_g.x * lobe, "{want}");
    }
}
