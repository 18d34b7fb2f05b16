//! Tangent frames for normal maps (Computer Graphics from Scratch ch. 15):
//! the direction in which u grows across each triangle, built from its uvs,
//! then summed over the triangles that share a vertex (same object,
//! position, normal and uv), so that the frame turns smoothly across a mesh
//! as its normals do. A tangent the file gives (`Scene::given_tangents`,
//! a glTF's `TANGENT`) is taken instead, with its handedness.

use crate::scene::{PrimitiveKind, Scene, SurfaceHit};
use crate::math::Vec3;
use glam::Vec4;
use std::collections::HashMap;

/// Per triangle the unit tangent at each corner (xyz) and the handedness
/// of the frame (w = +1 or -1: the bitangent is `w * n x t`). Triangles
/// whose material has neither a normal map nor Ward's anisotropic lobe get
/// zeros.
pub fn build_tangents(scene: &Scene) -> Vec<[Vec4; 3]> {
    let mapped = |m: u32| {
        let m = &scene.materials[m as usize];
        m.normal_map.is_some() || m.glossy_model == crate::scene::material::GlossyModel::Ward
    };
    // The tangent and bitangent of each triangle, from its uv derivatives.
    let per_triangle: Vec<Option<(Vec3, Vec3)>> = scene
        .triangles
        .iter()
        .map(|t| {
            if !mapped(t.material) {
                return None;
            }
            let (e1, e2) = (t.v[1] - t.v[0], t.v[2] - t.v[0]);
            let (d1, d2) = (t.uv[1] - t.uv[0], t.uv[2] - t.uv[0]);
            let det = d1.x * d2.y - d2.x * d1.y;
            if det == 0.0 || !det.is_finite() {
                return None;
            }
            let r = 1.0 / det;
            Some(((e1 * d2.y - e2 * d1.y) * r, (e2 * d1.x - e1 * d2.x) * r))
        })
        .collect();
    let key = |i: usize, k: usize| {
        let t = &scene.triangles.at(i);
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        (t.object, bits(t.v[k]), bits(t.n[k]), t.uv[k].to_array().map(f32::to_bits))
    };
    let mut sums: HashMap<_, (Vec3, Vec3)> = HashMap::new();
    for (i, frame) in per_triangle.iter().enumerate() {
        if let Some((t, b)) = frame {
            for k in 0..3 {
                let e = sums.entry(key(i, k)).or_insert((Vec3::ZERO, Vec3::ZERO));
                e.0 += *t;
                e.1 += *b;
            }
        }
    }
    (0..scene.triangles.len())
        .map(|i| {
            let given = scene.given_tangents.get(i).filter(|_| mapped(scene.triangles.at(i).material));
            if per_triangle[i].is_none() && given.is_none_or(|g| g.contains(&Vec4::ZERO)) {
                return [Vec4::ZERO; 3];
            }
            std::array::from_fn(|k| {
                let n = scene.triangles.at(i).n[k];
                if let Some(g) = given.map(|g| g[k]).filter(|g| *g != Vec4::ZERO) {
                    let t = (g.truncate() - n * n.dot(g.truncate())).normalize_or_zero();
                    return t.extend(if g.w < 0.0 { -1.0 } else { 1.0 });
                }
                let Some(&(t, b)) = sums.get(&key(i, k)) else { return Vec4::ZERO };
                let t = (t - n * n.dot(t)).normalize_or_zero();
                let w = if n.cross(t).dot(b) < 0.0 { -1.0 } else { 1.0 };
                t.extend(w)
            })
        })
        .collect()
}

/// The tangent (xyz) and handedness (w) at `hit`, before orthogonalizing
/// against the shading normal: interpolated on a triangle; on a sphere the
/// direction of growing longitude u, `(o.z, 0, -o.x)` for the outward unit
/// `o` (`Scene::sphere_hit`'s mapping).
pub fn tangent_at(scene: &Scene, hit: &SurfaceHit) -> Vec4 {
    match hit.kind {
        PrimitiveKind::Triangle => match scene.tangents.get(hit.primitive as usize) {
            Some(t) => {
                let b = hit.barycentric;
                (t[0].truncate() * b.x + t[1].truncate() * b.y + t[2].truncate() * b.z).extend(t[0].w)
            }
            None => Vec4::ZERO,
        },
        PrimitiveKind::Sphere => {
            let s = &scene.spheres[hit.primitive as usize];
            let o = (hit.position - s.center) / s.radius;
            Vec3::new(o.z, 0.0, -o.x).extend(1.0)
        }
        // No tangent frame is kept for CSG surfaces: normal maps do not apply.
        PrimitiveKind::Csg => Vec4::ZERO,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;
    use crate::scene::{Material, Texture, Triangle};
    use std::sync::Arc;

    #[test]
    fn tangents_follow_u_and_are_shared_at_vertices() {
        let mut scene = Scene::default();
        let mut m = Material::black();
        m.normal_map = Some(Arc::new(Texture::new(1, 1, vec![Vec3::new(0.5, 0.5, 1.0)])));
        scene.materials.push(m);
        // A unit quad in the xy plane facing +z, u along +x and v along +y,
        // as two triangles; the second one's u runs twice as fast.
        let v = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let uv = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
        let tri = |a: usize, b: usize, c: usize| Triangle { v: [v[a], v[b], v[c]], n: [Vec3::Z; 3], uv: [uv[a], uv[b], uv[c]], material: 0, object: 0, two_sided: false };
        scene.triangles = vec![tri(0, 1, 2), tri(0, 2, 3)].into();
        let t = build_tangents(&scene);
        for corner in t.iter().flatten() {
            assert!((corner.truncate() - Vec3::X).length() < 1e-6 && corner.w == 1.0, "{corner}");
        }
        // Mirrored u: the tangent turns to -x and the frame is left-handed.
        for i in 0..scene.triangles.len() {
            let mut tri = scene.triangles.at(i);
            for uv in &mut tri.uv {
                uv.x = 1.0 - uv.x;
            }
            scene.triangles.set(i, tri);
        }
        let t = build_tangents(&scene);
        assert!((t[0][0].truncate() + Vec3::X).length() < 1e-6 && t[0][0].w == -1.0, "{}", t[0][0]);
    }
}
