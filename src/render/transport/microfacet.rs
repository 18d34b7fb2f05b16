//! The two microfacet distributions of the glossy lobe, isotropic with
//! alpha `a` (not squared), as Mitsuba 3's `MicrofacetDistribution` defines
//! them: the normal distribution `D`, Smith's one-sided shadowing `G1` and
//! its `Lambda` (`G1 = 1 / (1 + Lambda)`), written once over a lane type so
//! that `lighting::bsdf` evaluates them one or many samples wide; and the
//! sampling of microfacet normals the path tracer uses (one sample wide).
//!
//! Directions enter as cosines with the shading normal: `cos_h = n.h` for a
//! microfacet normal h, `cos_v = n.v` and `v_h = v.h` for a direction v.
//! Only exactly rounded lane operations are used (`exp` as `exp2`), so every
//! width computes the same bits.

use crate::math::lanes::{exp2, Lane};
use crate::math::Vec3;
use std::f32::consts::PI;

/// `tan^2` of the angle whose cosine is `c`: `(1 - c^2) / c^2`, never
/// negative (a cosine rounded above one gives 0).
#[inline(always)]
fn tan2<L: Lane>(c: L) -> L {
    let c2 = c * c;
    (c.splat(1.0) - c2).max(c.splat(0.0)) / c2
}

/// Mitsuba's guard on `D`: values whose `D cos_h` is not above 1e-20 (and
/// every microfacet facing away, `cos_h <= 0`) are zero.
#[inline(always)]
fn guarded<L: Lane>(d: L, cos_h: L) -> L {
    L::select((d * cos_h).gt(d.splat(1e-20)), d, d.splat(0.0))
}

/// GGX (Trowbridge-Reitz): `D(h) = 1 / (pi a^2 (tan^2 / a^2 + 1)^2 cos^4)`,
/// computed as Mitsuba does, `1 / (pi a^2 e^2)` with
/// `e = sin^2 / a^2 + cos^2`.
#[inline(always)]
pub fn ggx_d<L: Lane>(cos_h: L, a: L) -> L {
    let c2 = cos_h * cos_h;
    let a2 = a * a;
    let e = (cos_h.splat(1.0) - c2).max(cos_h.splat(0.0)) / a2 + c2;
    guarded(cos_h.splat(1.0) / (cos_h.splat(PI) * a2 * e * e), cos_h)
}

/// Beckmann: `D(h) = exp(-tan^2 / a^2) / (pi a^2 cos^4)`, zero where the
/// exponential is below f32's normal range.
#[inline(always)]
pub fn beckmann_d<L: Lane>(cos_h: L, a: L) -> L {
    let a2 = a * a;
    let x = -(tan2(cos_h) / a2) * cos_h.splat(std::f32::consts::LOG2_E);
    let in_range = x.ge(cos_h.splat(-126.0));
    let c2 = cos_h * cos_h;
    let d = exp2(x.max(cos_h.splat(-126.0))) / (cos_h.splat(PI) * a2 * (c2 * c2));
    guarded(L::select(in_range, d, cos_h.splat(0.0)), cos_h)
}

/// GGX's `Lambda(v) = (sqrt(1 + a^2 tan^2) - 1) / 2`.
#[inline(always)]
pub fn ggx_lambda<L: Lane>(cos_v: L, a: L) -> L {
    let t = a * a * tan2(cos_v);
    ((cos_v.splat(1.0) + t).sqrt() - cos_v.splat(1.0)) * cos_v.splat(0.5)
}

/// Beckmann's `Lambda` in the rational approximation (Walter et al. 2007)
/// whose `1 / (1 + Lambda)` is Mitsuba's `G1`: with
/// `b = 1 / (a tan)`, `(1 - 1.259 b + 0.396 b^2) / (3.535 b + 2.181 b^2)`
/// below b = 1.6 and 0 above (the exact form needs erf).
#[inline(always)]
pub fn beckmann_lambda<L: Lane>(cos_v: L, a: L) -> L {
    let b = cos_v.splat(1.0) / (a * a * tan2(cos_v)).sqrt();
    let lambda = (cos_v.splat(1.0) - cos_v.splat(1.259) * b + cos_v.splat(0.396) * b * b) / (cos_v.splat(3.535) * b + cos_v.splat(2.181) * b * b);
    L::select(b.ge(cos_v.splat(1.6)), cos_v.splat(0.0), lambda)
}

/// Zero where the microfacet's back is seen (`v.h` and `n.v` of opposite
/// signs, or either zero), as Mitsuba's `smith_g1`.
#[inline(always)]
fn facing<L: Lane>(g: L, cos_v: L, v_h: L) -> L {
    L::select((v_h * cos_v).le(g.splat(0.0)), g.splat(0.0), g)
}

/// GGX's `G1(v, h) = 2 / (1 + sqrt(1 + a^2 tan^2))`, Mitsuba's form of
/// `1 / (1 + Lambda)`.
#[inline(always)]
pub fn ggx_g1<L: Lane>(cos_v: L, v_h: L, a: L) -> L {
    let t = a * a * tan2(cos_v);
    facing(cos_v.splat(2.0) / (cos_v.splat(1.0) + (cos_v.splat(1.0) + t).sqrt()), cos_v, v_h)
}

/// Beckmann's `G1(v, h)`: Mitsuba's rational approximation (below 0.35%
/// relative error), `(3.535 b + 2.181 b^2) / (1 + 2.276 b + 2.577 b^2)`
/// with `b = 1 / (a tan)`, and 1 from b = 1.6 on.
#[inline(always)]
pub fn beckmann_g1<L: Lane>(cos_v: L, v_h: L, a: L) -> L {
    let b = cos_v.splat(1.0) / (a * a * tan2(cos_v)).sqrt();
    let b2 = b * b;
    let g = (cos_v.splat(3.535) * b + cos_v.splat(2.181) * b2) / (cos_v.splat(1.0) + cos_v.splat(2.276) * b + cos_v.splat(2.577) * b2);
    facing(L::select(b.ge(cos_v.splat(1.6)), cos_v.splat(1.0), g), cos_v, v_h)
}

/// A GGX microfacet normal seen from `v` (local frame, z the normal,
/// `v.z > 0`), distributed as the visible normals `G1(v) max(0, v.h) D(h) /
/// v.z` (Heitz 2018, "Sampling the GGX Distribution of Visible Normals").
pub fn sample_ggx_visible(v: Vec3, a: f32, u1: f32, u2: f32) -> Vec3 {
    // The view in the hemisphere configuration (alpha stretched to 1).
    let vh = Vec3::new(a * v.x, a * v.y, v.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt() } else { Vec3::X };
    let t2 = vh.cross(t1);
    // A point on the disk, its lower part squeezed onto the projected hemisphere.
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    let p1 = r * phi.cos();
    let p2 = r * phi.sin();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    // Back to the ellipsoid configuration.
    Vec3::new(a * nh.x, a * nh.y, nh.z.max(0.0)).normalize()
}

/// A Beckmann microfacet normal (local frame) with density `D(h) cos_h`:
/// `tan^2 = -a^2 ln(1 - u1)`. Not the visible normals (those need erf and
/// its inverse, as Mitsuba samples them): the estimator stays unbiased,
/// with more variance at grazing views, where samples fall below the
/// surface.
pub fn sample_beckmann(a: f32, u1: f32, u2: f32) -> Vec3 {
    let tan2 = -a * a * (1.0 - u1).ln();
    let cos = 1.0 / (1.0 + tan2).sqrt();
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = 2.0 * PI * u2;
    Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `∫ g(cos_h) dω` over the hemisphere by a midpoint rule in theta
    /// (the distributions are isotropic, so phi gives 2 pi), in f64.
    fn hemisphere_integral(g: impl Fn(f32) -> f32) -> f64 {
        let n = 200_000;
        let d = std::f64::consts::FRAC_PI_2 / n as f64;
        (0..n)
            .map(|i| {
                let theta = (i as f64 + 0.5) * d;
                g(theta.cos() as f32) as f64 * theta.sin() * d * 2.0 * std::f64::consts::PI
            })
            .sum()
    }

    #[test]
    fn distributions_project_to_unit_area() {
        // ∫ D(h) cos_h dω = 1: the microfacets' projected area is the macro surface's.
        for a in [0.05f32, 0.1, 0.2, 0.5, 1.0] {
            let ggx = hemisphere_integral(|c| ggx_d(c, a) * c);
            let beckmann = hemisphere_integral(|c| beckmann_d(c, a) * c);
            assert!((ggx - 1.0).abs() < 2e-3, "GGX alpha {a}: {ggx}");
            assert!((beckmann - 1.0).abs() < 2e-3, "Beckmann alpha {a}: {beckmann}");
        }
        // And the test can fail: D without its pi does not.
        let wrong = hemisphere_integral(|c| ggx_d(c, 0.3f32) * c * PI);
        assert!((wrong - 1.0).abs() > 0.5, "{wrong}");
    }

    #[test]
    fn distributions_match_hand_values() {
        // alpha 0.5, cos_h 0.8 (tan^2 = 0.36 / 0.64 = 0.5625):
        // GGX: 1 / (pi 0.25 (0.36 / 0.25 + 0.64)^2) = 1 / (pi 0.25 2.08^2)
        //      = 1 / (0.785398 * 4.3264) = 1 / 3.397952 = 0.294294.
        // Beckmann: exp(-0.5625 / 0.25) / (pi 0.25 0.8^4)
        //      = exp(-2.25) / (0.785398 * 0.4096) = 0.105399 / 0.321699 = 0.327633.
        assert!((ggx_d(0.8f32, 0.5) - 0.294294).abs() < 1e-5, "{}", ggx_d(0.8f32, 0.5));
        assert!((beckmann_d(0.8f32, 0.5) - 0.327633).abs() < 1e-5, "{}", beckmann_d(0.8f32, 0.5));
        assert_eq!(ggx_d(-0.1f32, 0.5), 0.0);
        assert_eq!(beckmann_d(0.01f32, 0.01), 0.0);
    }

    /// `D` at several angles and alphas against the closed forms in terms
    /// of tan, written here in f64 (the code under test works with sin^2
    /// and cos^2 in f32): GGX `1 / (pi a^2 cos^4 (1 + tan^2 / a^2)^2)`,
    /// Beckmann `exp(-tan^2 / a^2) / (pi a^2 cos^4)`. Along the normal both
    /// are `1 / (pi a^2)`. The closed forms take the angle of the f32
    /// cosine the code gets; the relative tolerance 1e-4 covers f32's
    /// `1 - cos^2` near the normal (sin^2 = 0.0076 at 5 degrees keeps about
    /// five digits) and is far below what a wrong power or factor gives.
    /// Values whose `D cos` is below 1e-20 are zero by `guarded`.
    #[test]
    fn distributions_match_their_closed_forms() {
        let ggx = |theta: f64, a: f64| 1.0 / (std::f64::consts::PI * a * a * theta.cos().powi(4) * (1.0 + theta.tan().powi(2) / (a * a)).powi(2));
        let beckmann = |theta: f64, a: f64| (-theta.tan().powi(2) / (a * a)).exp() / (std::f64::consts::PI * a * a * theta.cos().powi(4));
        for a in [0.1f64, 0.3, 0.8] {
            for degrees in [0.0f64, 5.0, 20.0, 45.0, 70.0] {
                let (c, af) = (degrees.to_radians().cos() as f32, a as f32);
                let theta = (c as f64).acos();
                let (got, want) = (ggx_d(c, af) as f64, ggx(theta, a));
                assert!((got - want).abs() <= 1e-4 * want, "GGX alpha {a} at {degrees} degrees: {got}, closed form {want}");
                let (got, want) = (beckmann_d(c, af) as f64, beckmann(theta, a));
                let flushed = want * (c as f64) < 1e-20 && got == 0.0;
                assert!(flushed || (got - want).abs() <= 1e-4 * want, "Beckmann alpha {a} at {degrees} degrees: {got}, closed form {want}");
            }
            let peak = 1.0 / (std::f64::consts::PI * a * a);
            assert!((ggx_d(1.0f32, a as f32) as f64 - peak).abs() <= 1e-6 * peak);
            assert!((beckmann_d(1.0f32, a as f32) as f64 - peak).abs() <= 1e-6 * peak);
        }
    }

    #[test]
    fn g1_is_one_over_one_plus_lambda() {
        for a in [0.05f32, 0.3, 1.0] {
            for c in [0.05f32, 0.2, 0.5, 0.9, 1.0] {
                let ggx = ggx_g1(c, 1.0, a);
                assert!((ggx - 1.0 / (1.0 + ggx_lambda(c, a))).abs() < 1e-6, "GGX a {a} cos {c}");
                let beckmann = beckmann_g1(c, 1.0, a);
                assert!((beckmann - 1.0 / (1.0 + beckmann_lambda(c, a))).abs() < 1e-5, "Beckmann a {a} cos {c}");
                assert!(ggx > 0.0 && ggx <= 1.0 && beckmann > 0.0 && beckmann <= 1.0);
            }
            // Seen head-on nothing is shadowed; the back of a microfacet is never seen.
            assert_eq!(ggx_g1(1.0f32, 1.0, a), 1.0);
            assert_eq!(beckmann_g1(1.0f32, 1.0, a), 1.0);
            assert_eq!(ggx_g1(0.5f32, -0.1, a), 0.0);
            assert_eq!(beckmann_g1(0.5f32, -0.1, a), 0.0);
        }
        // GGX at alpha 0.5, cos 0.6: tan^2 = 0.64 / 0.36 = 1.777778, a^2 tan^2 = 0.444444,
        // G1 = 2 / (1 + sqrt(1.444444)) = 2 / 2.201850 = 0.908327.
        assert!((ggx_g1(0.6f32, 0.9, 0.5) - 0.908327).abs() < 1e-5);
        // Beckmann at alpha 0.5, cos 0.6: b = 1 / sqrt(0.444444) = 1.5,
        // G1 = (5.3025 + 4.90725) / (1 + 3.414 + 5.79825) = 10.20975 / 10.21225 = 0.999755.
        assert!((beckmann_g1(0.6f32, 0.9, 0.5) - 0.999755).abs() < 1e-5);
    }

    /// The sampled normals' histogram over cos_h against the density each
    /// sampler claims, integrated over the bins.
    fn normals_follow(sample: impl Fn(f32, f32) -> Vec3, density: impl Fn(Vec3) -> f64) {
        use crate::render::transport::sampling::SampleRng;
        let (bins, n) = (20, 200_000);
        let mut observed = vec![0f64; bins];
        let mut r = SampleRng::for_index(31, 0, 1);
        for _ in 0..n {
            let u = r.next_2d();
            let h = sample(u.x, u.y);
            assert!((h.length() - 1.0).abs() < 1e-4 && h.z >= 0.0, "{h}");
            observed[((h.z * bins as f32) as usize).min(bins - 1)] += 1.0 / n as f64;
        }
        // Expected mass per bin: the density over the bin's band of the hemisphere.
        for (b, &o) in observed.iter().enumerate() {
            let (sub_c, sub_phi) = (200, 64);
            let mut e = 0.0;
            for i in 0..sub_c {
                let c = (b as f64 + (i as f64 + 0.5) / sub_c as f64) / bins as f64;
                let s = (1.0 - c * c).sqrt();
                for j in 0..sub_phi {
                    let phi = (j as f64 + 0.5) / sub_phi as f64 * 2.0 * std::f64::consts::PI;
                    let h = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
                    e += density(h) / (sub_c * sub_phi) as f64 / bins as f64 * 2.0 * std::f64::consts::PI;
                }
            }
            assert!((o - e).abs() < 0.004 + 0.03 * e, "bin {b}: sampled {o}, density {e}");
        }
    }

    #[test]
    fn sampled_normals_follow_their_densities() {
        for a in [0.1f32, 0.4, 0.8] {
            normals_follow(|u1, u2| sample_beckmann(a, u1, u2), |h| (beckmann_d(h.z, a) * h.z) as f64);
            for v in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.7, 0.7, 0.14).normalize()] {
                normals_follow(|u1, u2| sample_ggx_visible(v, a, u1, u2), |h| (ggx_g1(v.z, v.dot(h), a) * v.dot(h).max(0.0) * ggx_d(h.z, a) / v.z) as f64);
            }
        }
    }
}
