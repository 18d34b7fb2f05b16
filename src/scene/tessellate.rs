//! A sphere drawn as a mesh (`tessellate = N` on a `sphere` object): a
//! latitude-longitude grid of about N triangles, with the analytic
//! sphere's outward normals and uvs at its vertices, so that the exact
//! sphere and its tessellations can be compared (silhouettes, shading,
//! cost) in the A|B view and the chart.

use crate::math::{Vec2, Vec3};
use crate::scene::Triangle;
use std::f32::consts::PI;

/// The fewest triangles a tessellation has (two bands of four slices).
pub const MIN_TRIANGLES: u32 = 8;
/// The most a scene file may ask for.
pub const MAX_TRIANGLES: u32 = 1_000_000;

/// Bands of latitude for about `n` triangles: `s` bands of `2 s` slices
/// make `4 s (s - 1)` triangles (the bands at the poles are fans); the
/// fewest bands that reach `n`.
pub fn bands_for(n: u32) -> u32 {
    let mut s = 2u32;
    while 4 * s as u64 * (s as u64 - 1) < n as u64 {
        s += 1;
    }
    s
}

/// The point of the unit sphere at `(u, v)` of the analytic sphere's
/// mapping (`Scene::sphere_hit`): u around +y, v from the south pole up.
fn unit_point(uv: Vec2) -> Vec3 {
    let phi = (0.5 - uv.x) * 2.0 * PI;
    let lat = (uv.y - 0.5) * PI;
    Vec3::new(phi.cos() * lat.cos(), lat.sin(), phi.sin() * lat.cos())
}

/// The triangles of a sphere at `center` of `radius` tessellated into
/// about `n` triangles (at least `MIN_TRIANGLES`), each facing outwards.
pub fn sphere_triangles(center: Vec3, radius: f32, n: u32, material: u32, object: u32, two_sided: bool) -> Vec<Triangle> {
    let bands = bands_for(n.max(MIN_TRIANGLES));
    let slices = 2 * bands;
    let mut out = Vec::with_capacity(4 * bands as usize * (bands as usize - 1));
    let corner = |i: u32, j: u32| Vec2::new(i as f32 / slices as f32, j as f32 / bands as f32);
    let mut push = |uv: [Vec2; 3]| {
        let dir = uv.map(unit_point);
        let v = dir.map(|d| center + d * radius);
        let mut t = Triangle { v, n: dir, uv, material, object, two_sided };
        // Outwards: the corners' order turns anticlockwise seen from outside.
        if (v[1] - v[0]).cross(v[2] - v[0]).dot(v[0] + v[1] + v[2] - 3.0 * center) < 0.0 {
            t.v.swap(1, 2);
            t.n.swap(1, 2);
            t.uv.swap(1, 2);
        }
        out.push(t);
    };
    for j in 0..bands {
        for i in 0..slices {
            let (a, b, c, d) = (corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1));
            if j > 0 {
                push([a, b, c]);
            }
            if j + 1 < bands {
                push([a, c, d]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_vertices_by_hand() {
        assert_eq!(bands_for(8), 2);
        assert_eq!(bands_for(20), 3); // 24 triangles
        assert_eq!(bands_for(20_000), 72); // 20448
        let tris = sphere_triangles(Vec3::new(1.0, 2.0, 3.0), 2.0, 20, 0, 0, false);
        assert_eq!(tris.len(), 24);
        for t in &tris {
            for k in 0..3 {
                // On the sphere, the normal outward from the centre.
                assert!(((t.v[k] - Vec3::new(1.0, 2.0, 3.0)).length() - 2.0).abs() < 1e-5);
                assert!((t.n[k] - (t.v[k] - Vec3::new(1.0, 2.0, 3.0)) / 2.0).length() < 1e-5);
            }
            // Facing outwards, with some area.
            let g = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
            assert!(g.length() > 1e-6 && g.dot(t.v[0] - Vec3::new(1.0, 2.0, 3.0)) > 0.0);
        }
        // The analytic sphere's uv mapping: u = 0.25 is +z, v = 1 the north pole.
        assert!((unit_point(Vec2::new(0.25, 0.5)) - Vec3::Z).length() < 1e-6);
        assert!((unit_point(Vec2::new(0.3, 1.0)) - Vec3::Y).length() < 1e-6);
    }
}
