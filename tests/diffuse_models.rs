//! The diffuse models (Lambert, Oren-Nayar, Minnaert, toon) against their
//! formulas written again here in f64 from angles (not from the code's
//! cosine forms), their limits (Oren-Nayar at sigma 0 is Lambert bit for
//! bit; Minnaert at darkening 1 too), which of them are reciprocal, and
//! their directional albedo (at most k_L at every angle tested).

use pinhole::math::Vec3;
use pinhole::render::transport::bsdf::bsdf;
use pinhole::scene::material::DiffuseModel;
use pinhole::scene::Material;
use std::f64::consts::PI;

fn material(model: DiffuseModel) -> Material {
    let mut m = Material::black();
    m.lambertian = Vec3::new(0.8, 0.5, 0.2);
    m.diffuse_model = model;
    m
}

/// A unit direction at polar angle `theta` and azimuth `phi` about z.
fn dir(theta: f64, phi: f64) -> Vec3 {
    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32)
}

/// The angles of the f32 direction `v` (what the code sees), in f64.
fn angles(v: Vec3) -> (f64, f64) {
    let v = v.as_dvec3();
    ((v.z / v.length()).clamp(-1.0, 1.0).acos(), v.y.atan2(v.x))
}

/// Oren and Nayar's qualitative model: rho / pi (A + B max(0, cos(phi_i -
/// phi_o)) sin(alpha) tan(beta)), alpha = max(theta_i, theta_o),
/// beta = min(theta_i, theta_o).
fn oren_nayar(rho: f64, sigma: f64, w_i: Vec3, w_o: Vec3) -> f64 {
    let ((ti, pi_), (to, po)) = (angles(w_i), angles(w_o));
    let s2 = sigma * sigma;
    let a = 1.0 - 0.5 * s2 / (s2 + 0.33);
    let b = 0.45 * s2 / (s2 + 0.09);
    let (alpha, beta) = (ti.max(to), ti.min(to));
    rho / PI * (a + b * (pi_ - po).cos().max(0.0) * alpha.sin() * beta.tan())
}

/// Minnaert's lobe normalized to reflect at most rho:
/// rho (k + 1) / (2 pi) cos(theta_i)^(k - 1) cos(theta_o)^(1 - k).
fn minnaert(rho: f64, k: f64, w_i: Vec3, w_o: Vec3) -> f64 {
    let (ti, to) = (angles(w_i).0, angles(w_o).0);
    rho * (k + 1.0) / (2.0 * PI) * ti.cos().powf(k - 1.0) * to.cos().powf(1.0 - k)
}

/// Toon with b bands: f cos(theta_i) = rho / pi round(cos(theta_i) b) / b.
fn toon(rho: f64, bands: f64, w_i: Vec3) -> f64 {
    let c = angles(w_i).0.cos();
    rho / PI * (c * bands).round() / bands / c
}

/// Directions above the surface, from near the normal to grazing, at
/// several azimuths.
fn directions() -> Vec<Vec3> {
    let mut out = Vec::new();
    for theta_deg in [0.0f64, 10.0, 30.0, 50.0, 65.0, 80.0, 88.0] {
        for phi_deg in [0.0f64, 40.0, 100.0, 180.0, 250.0] {
            out.push(dir(theta_deg.to_radians(), phi_deg.to_radians()));
        }
    }
    out
}

fn assert_close(got: f32, want: f64, what: &str) {
    assert!(((got as f64) - want).abs() <= 2e-5 * want.abs().max(1e-3), "{what}: {got}, formula {want}");
}

#[test]
fn oren_nayar_matches_its_formula() {
    for sigma in [0.1f32, 0.3, 0.6, 1.2] {
        let m = material(DiffuseModel::OrenNayar { sigma });
        for &w_i in &directions() {
            for &w_o in &directions() {
                let f = bsdf(&m, m.lambertian, Vec3::Z, w_i, w_o);
                for (c, rho) in [(f.x, 0.8), (f.y, 0.5), (f.z, 0.2)] {
                    assert_close(c, oren_nayar(rho, sigma as f64, w_i, w_o), &format!("sigma {sigma} w_i {w_i} w_o {w_o}"));
                }
            }
        }
    }
    // And the test tells sigma 0.3 from 0.33.
    let m = material(DiffuseModel::OrenNayar { sigma: 0.3 });
    let (w_i, w_o) = (dir(1.0, 0.0), dir(1.2, 0.3));
    let f = bsdf(&m, m.lambertian, Vec3::Z, w_i, w_o).x as f64;
    assert!((f - oren_nayar(0.8, 0.33, w_i, w_o)).abs() > 1e-3);
}

#[test]
fn minnaert_matches_its_formula() {
    for k in [0.0f32, 0.3, 0.7, 1.0] {
        let m = material(DiffuseModel::Minnaert { darkening: k });
        for &w_i in &directions() {
            for &w_o in &directions() {
                let f = bsdf(&m, m.lambertian, Vec3::Z, w_i, w_o);
                assert_close(f.y, minnaert(0.5, k as f64, w_i, w_o), &format!("darkening {k} w_i {w_i} w_o {w_o}"));
            }
        }
    }
}

#[test]
fn toon_matches_its_formula() {
    for bands in [1u32, 2, 3, 5] {
        let m = material(DiffuseModel::Toon { bands });
        let mut lit_tones = std::collections::BTreeSet::new();
        for &w_i in &directions() {
            let c = angles(w_i).0.cos();
            // Not within rounding of a band's edge, where either side is right.
            if ((c * bands as f64).fract() - 0.5).abs() < 1e-4 {
                continue;
            }
            let f = bsdf(&m, m.lambertian, Vec3::Z, w_i, dir(0.4, 1.0));
            let want = toon(0.8, bands as f64, w_i);
            assert_close(f.x, want, &format!("bands {bands} w_i {w_i}"));
            lit_tones.insert(((f.x as f64) * c * 1e4).round() as i64);
        }
        // One tone per band plus dark, whatever the viewer's direction.
        assert!(lit_tones.len() <= bands as usize + 1, "bands {bands}: {lit_tones:?}");
    }
}

/// Oren-Nayar at sigma 0 and Minnaert at darkening 1 are Lambert, to the
/// bit, at every pair of directions.
#[test]
fn limits_equal_lambert_bit_for_bit() {
    let lambert = material(DiffuseModel::Lambert);
    for model in [DiffuseModel::OrenNayar { sigma: 0.0 }, DiffuseModel::Minnaert { darkening: 1.0 }] {
        let m = material(model);
        for &w_i in &directions() {
            for &w_o in &directions() {
                let (a, b) = (bsdf(&m, m.lambertian, Vec3::Z, w_i, w_o), bsdf(&lambert, lambert.lambertian, Vec3::Z, w_i, w_o));
                assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits), "{model:?} w_i {w_i} w_o {w_o}");
            }
        }
    }
    // Away from the limit they differ.
    let m = material(DiffuseModel::OrenNayar { sigma: 0.05 });
    let (w_i, w_o) = (dir(1.0, 0.0), dir(1.2, 0.3));
    assert_ne!(bsdf(&m, m.lambertian, Vec3::Z, w_i, w_o), bsdf(&lambert, lambert.lambertian, Vec3::Z, w_i, w_o));
}

/// f(w_i, w_o) = f(w_o, w_i) for Lambert and Oren-Nayar; Minnaert (below
/// darkening 1) and toon are not reciprocal, and the test finds it.
#[test]
fn reciprocity_holds_where_the_model_has_it() {
    let symmetric = |m: &Material| {
        let mut worst = 0.0f32;
        for &a in &directions() {
            for &b in &directions() {
                let (ab, ba) = (bsdf(m, m.lambertian, Vec3::Z, a, b), bsdf(m, m.lambertian, Vec3::Z, b, a));
                worst = worst.max(((ab - ba).abs() / ab.abs().max(Vec3::splat(1e-6))).max_element());
            }
        }
        worst
    };
    for model in [DiffuseModel::Lambert, DiffuseModel::OrenNayar { sigma: 0.3 }, DiffuseModel::OrenNayar { sigma: 1.0 }, DiffuseModel::Minnaert { darkening: 1.0 }] {
        let worst = symmetric(&material(model));
        assert!(worst < 1e-5, "{model:?} is not reciprocal: relative difference {worst}");
    }
    for model in [DiffuseModel::Minnaert { darkening: 0.5 }, DiffuseModel::Toon { bands: 3 }] {
        let worst = symmetric(&material(model));
        assert!(worst > 0.1, "{model:?} was expected not to be reciprocal: relative difference {worst}");
    }
}

/// `∫ f cos dw_i` for a white diffuse lobe seen from `w_o`, by a midpoint
/// rule over the hemisphere.
fn albedo(m: &Material, w_o: Vec3) -> f64 {
    let (n_theta, n_phi) = (1200, 120);
    let (d_theta, d_phi) = (PI / 2.0 / n_theta as f64, 2.0 * PI / n_phi as f64);
    let mut sum = 0.0;
    for i in 0..n_theta {
        let theta = (i as f64 + 0.5) * d_theta;
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) * d_phi;
            let f = bsdf(m, Vec3::ONE, Vec3::Z, dir(theta, phi), w_o).x as f64;
            sum += f * theta.cos() * theta.sin() * d_theta * d_phi;
        }
    }
    sum
}

/// A white lobe's directional albedo is at most 1 (within the quadrature's
/// 2e-3) at every angle of view and parameter tested, with one exception:
/// Oren-Nayar's qualitative model, at small sigma seen near grazing,
/// reflects up to about 1.5% more than arrives (1.0144 at sigma 0.2, 89
/// degrees; the test checks that it does, so the documented figure stays
/// true). Lambert and toon reflect all of it (toon's rounding to the
/// nearest tone keeps the mean), normalized Minnaert `cos_o^(1-k)` of it,
/// Oren-Nayar less as sigma grows.
#[test]
fn directional_albedo_is_at_most_one() {
    for theta_o in [0.0f64, 30.0, 60.0, 80.0, 89.0] {
        let w_o = dir(theta_o.to_radians(), 0.7);
        let c_o = theta_o.to_radians().cos();
        let models = [
            DiffuseModel::Lambert,
            DiffuseModel::OrenNayar { sigma: 0.2 },
            DiffuseModel::OrenNayar { sigma: 0.5 },
            DiffuseModel::OrenNayar { sigma: 1.0 },
            DiffuseModel::OrenNayar { sigma: 1.5 },
            DiffuseModel::Minnaert { darkening: 0.0 },
            DiffuseModel::Minnaert { darkening: 0.5 },
            DiffuseModel::Toon { bands: 1 },
            DiffuseModel::Toon { bands: 4 },
        ];
        for model in models {
            let a = albedo(&material(model), w_o);
            let bound = if matches!(model, DiffuseModel::OrenNayar { .. }) { 1.017 } else { 1.002 };
            assert!(a <= bound, "{model:?} at {theta_o} degrees reflects {a}");
            let expected = match model {
                DiffuseModel::Lambert | DiffuseModel::Toon { .. } => Some(1.0),
                DiffuseModel::Minnaert { darkening } => Some(c_o.powf(1.0 - darkening as f64)),
                DiffuseModel::OrenNayar { .. } => None,
            };
            if let Some(e) = expected {
                assert!((a - e).abs() < 3e-3, "{model:?} at {theta_o} degrees reflects {a}, not {e}");
            } else {
                assert!(a > 0.5, "{model:?} at {theta_o} degrees reflects only {a}");
            }
        }
    }
    let grazing = albedo(&material(DiffuseModel::OrenNayar { sigma: 0.2 }), dir(89f64.to_radians(), 0.7));
    assert!((grazing - 1.0144).abs() < 2e-3, "Oren-Nayar at sigma 0.2, 89 degrees: {grazing}");
}
