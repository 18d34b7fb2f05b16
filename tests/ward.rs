//! Ward's anisotropic lobe against its formula written again here from
//! the half vector's angles in f64, its isotropic limit (alpha_u = alpha_v:
//! the lobe turns with the directions about the normal and ignores the
//! tangent), reciprocity, and the scene file's refusal of a Ward lobe on a
//! mesh without uvs.

use pinhole::math::{Vec2, Vec3};
use pinhole::render::transport::bsdf::{bsdf, ShadingFrame};
use pinhole::scene::material::GlossyModel;
use pinhole::scene::Material;
use std::f64::consts::PI;

fn ward(au: f32, av: f32) -> Material {
    let mut m = Material::black();
    m.glossy = Vec3::ONE;
    m.glossy_model = GlossyModel::Ward;
    m.roughness_uv = Vec2::new(au, av);
    m
}

fn dir(theta: f64, phi: f64) -> Vec3 {
    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32)
}

/// Ward (1992): exp(-tan^2(theta_h) (cos^2(phi_h) / a_u^2 + sin^2(phi_h) /
/// a_v^2)) / (4 pi a_u a_v sqrt(cos_i cos_o)), phi_h the half vector's
/// azimuth from the tangent x (the frame is x, y, z here).
fn formula(au: f64, av: f64, w_i: Vec3, w_o: Vec3) -> f64 {
    let (i, o) = (w_i.as_dvec3(), w_o.as_dvec3());
    let h = (i + o).normalize();
    let theta_h = h.z.acos();
    let phi_h = h.y.atan2(h.x);
    let e = theta_h.tan().powi(2) * (phi_h.cos().powi(2) / (au * au) + phi_h.sin().powi(2) / (av * av));
    (-e).exp() / (4.0 * PI * au * av * (i.z * o.z).sqrt())
}

fn directions() -> Vec<Vec3> {
    let mut out = Vec::new();
    for theta_deg in [0.0f64, 15.0, 35.0, 55.0, 75.0] {
        for phi_deg in [0.0f64, 30.0, 90.0, 160.0, 200.0, 290.0] {
            out.push(dir(theta_deg.to_radians(), phi_deg.to_radians()));
        }
    }
    out
}

#[test]
fn ward_matches_its_formula() {
    let frame = ShadingFrame { n: Vec3::Z, tangent: Vec3::X };
    let mut compared = 0;
    for (au, av) in [(0.1f32, 0.4f32), (0.3, 0.3), (0.5, 0.15)] {
        let m = ward(au, av);
        for &w_i in &directions() {
            for &w_o in &directions() {
                let want = formula(au as f64, av as f64, w_i, w_o);
                let got = bsdf(&m, Vec3::ZERO, frame, w_i, w_o).x as f64;
                if want < 1e-6 {
                    assert!(got < 2e-6, "({au}, {av}) w_i {w_i} w_o {w_o}: {got}, formula {want}");
                    continue;
                }
                assert!((got - want).abs() <= 1e-4 * want, "({au}, {av}) w_i {w_i} w_o {w_o}: {got}, formula {want}");
                compared += 1;
            }
        }
    }
    assert!(compared > 500, "{compared}");
    // The tangent sets the orientation: turned a quarter, alpha_u and alpha_v swap.
    let (w_i, w_o) = (dir(0.5, 0.0), dir(0.4, 2.0));
    let along_x = bsdf(&ward(0.1, 0.4), Vec3::ZERO, ShadingFrame { n: Vec3::Z, tangent: Vec3::Y }, w_i, w_o).x;
    let swapped = bsdf(&ward(0.4, 0.1), Vec3::ZERO, ShadingFrame { n: Vec3::Z, tangent: Vec3::X }, w_i, w_o).x;
    assert!((along_x - swapped).abs() <= 1e-5 * swapped, "{along_x} {swapped}");
    let unturned = bsdf(&ward(0.1, 0.4), Vec3::ZERO, ShadingFrame { n: Vec3::Z, tangent: Vec3::X }, w_i, w_o).x;
    assert!((unturned - swapped).abs() > 0.1 * swapped, "{unturned} {swapped}");
}

/// With alpha_u = alpha_v the lobe is isotropic: the same value for any
/// tangent, and for both directions turned together about the normal; it
/// is then `exp(-tan^2(theta_h) / a^2) / (4 pi a^2 sqrt(cos_i cos_o))`.
#[test]
fn ward_with_equal_alphas_is_isotropic() {
    let m = ward(0.25, 0.25);
    let turn = |v: Vec3, psi: f32| Vec3::new(v.x * psi.cos() - v.y * psi.sin(), v.x * psi.sin() + v.y * psi.cos(), v.z);
    for &w_i in &directions() {
        for &w_o in &directions() {
            let base = bsdf(&m, Vec3::ZERO, ShadingFrame { n: Vec3::Z, tangent: Vec3::X }, w_i, w_o).x;
            for psi in [0.3f32, 1.7, 4.0] {
                let other_tangent = bsdf(&m, Vec3::ZERO, ShadingFrame { n: Vec3::Z, tangent: turn(Vec3::X, psi) }, w_i, w_o).x;
                let turned = bsdf(&m, Vec3::ZERO, ShadingFrame { n: Vec3::Z, tangent: Vec3::X }, turn(w_i, psi), turn(w_o, psi)).x;
                for v in [other_tangent, turned] {
                    assert!((v - base).abs() <= 1e-4 * base.max(1e-3), "w_i {w_i} w_o {w_o} psi {psi}: {v} vs {base}");
                }
            }
            let h = (w_i + w_o).as_dvec3().normalize();
            let tan2 = h.z.acos().tan().powi(2);
            let a = 0.25f64;
            let want = (-tan2 / (a * a)).exp() / (4.0 * PI * a * a * ((w_i.z * w_o.z) as f64).sqrt());
            assert!((base as f64 - want).abs() <= 1e-4 * want.max(1e-3), "w_i {w_i} w_o {w_o}: {base}, closed form {want}");
        }
    }
}

#[test]
fn ward_is_reciprocal() {
    let frame = ShadingFrame { n: Vec3::Z, tangent: Vec3::new(0.6, 0.8, 0.0) };
    let m = ward(0.1, 0.4);
    for &a in &directions() {
        for &b in &directions() {
            let (ab, ba) = (bsdf(&m, Vec3::ZERO, frame, a, b).x, bsdf(&m, Vec3::ZERO, frame, b, a).x);
            assert!((ab - ba).abs() <= 1e-5 * ab.max(1e-3), "{a} {b}: {ab} vs {ba}");
        }
    }
}

/// A Ward lobe on a mesh whose OBJ has no uvs is refused, naming the file,
/// the object and the material; the same mesh with uvs loads.
#[test]
fn ward_on_a_mesh_without_uvs_is_refused() {
    let dir = std::env::temp_dir().join(format!("pinhole-ward-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("plain.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(dir.join("mapped.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n").unwrap();
    let scene = |mesh: &str| {
        format!(
            "[camera]\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n\n[materials.brushed]\nglossy = [0.9, 0.9, 0.9]\nglossy_model = \"ward\"\nroughness_uv = [0.1, 0.4]\n\n[[object]]\ntype = \"mesh\"\nfile = \"{mesh}\"\nmaterial = \"brushed\"\n"
        )
    };
    std::fs::write(dir.join("plain.toml"), scene("plain.obj")).unwrap();
    std::fs::write(dir.join("mapped.toml"), scene("mapped.obj")).unwrap();
    let e = pinhole::scene::file::load_scene_file(&dir.join("plain.toml")).err().expect("a Ward lobe without uvs was accepted");
    for w in ["plain.toml", "object 1", "\"brushed\"", "ward", "uvs"] {
        assert!(e.contains(w), "{e:?} does not name {w}");
    }
    let loaded = pinhole::scene::file::load_scene_file(&dir.join("mapped.toml")).unwrap();
    assert!(!loaded.tangents.is_empty(), "the Ward material's tangents were not built");
    std::fs::remove_dir_all(&dir).ok();
}
