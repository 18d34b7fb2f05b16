//! Constructive solid geometry objects: a tree of boolean operations whose
//! leaves are closed solids (analytic spheres and closed triangle meshes).
//! The leaves' geometry lives in the object itself, never in
//! `Scene::triangles` or `Scene::spheres`, so the BVH and the rasterizers'
//! triangle loops never see it; `render::accel::csg` casts rays at it and
//! `render::raster::csg` scan-converts it into its own A-buffer.

use crate::scene::{Sphere, Triangle};
use crate::math::Vec3;

/// Deepest nesting of operations a scene file may give (the ray test recurses).
pub const MAX_DEPTH: usize = 32;

/// The boolean operation of a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CsgOp {
    Union,
    Intersection,
    /// `a` minus `b`.
    Difference,
}

impl CsgOp {
    pub fn parse(s: &str) -> Option<CsgOp> {
        match s {
            "union" => Some(CsgOp::Union),
            "intersection" => Some(CsgOp::Intersection),
            "difference" => Some(CsgOp::Difference),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            CsgOp::Union => "union",
            CsgOp::Intersection => "intersection",
            CsgOp::Difference => "difference",
        }
    }

    /// Whether a point inside `a` (or not) and inside `b` (or not) is inside the result.
    #[inline]
    pub fn inside(self, a: bool, b: bool) -> bool {
        match self {
            CsgOp::Union => a || b,
            CsgOp::Intersection => a && b,
            CsgOp::Difference => a && !b,
        }
    }
}

/// One node of the tree.
#[derive(Clone, Debug, PartialEq)]
pub enum CsgNode {
    /// `Csg::spheres[i]`.
    Sphere(u32),
    /// A closed mesh: `Csg::triangles[range]`, with its bounds.
    Mesh { first: u32, end: u32, lo: Vec3, hi: Vec3 },
    Op { op: CsgOp, a: Box<CsgNode>, b: Box<CsgNode> },
}

/// One CSG object of the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Csg {
    pub root: CsgNode,
    /// The sphere leaves (`object` is this object's).
    pub spheres: Vec<Sphere>,
    /// The mesh leaves' triangles, each leaf a contiguous range.
    pub triangles: Vec<Triangle>,
    pub object: u32,
    /// World bounds of every leaf (the result lies inside).
    pub lo: Vec3,
    pub hi: Vec3,
}

impl Csg {
    /// A tree over `spheres` and `triangles`, its bounds computed.
    pub fn new(root: CsgNode, spheres: Vec<Sphere>, triangles: Vec<Triangle>, object: u32) -> Csg {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for s in &spheres {
            lo = lo.min(s.center - Vec3::splat(s.radius));
            hi = hi.max(s.center + Vec3::splat(s.radius));
        }
        for t in &triangles {
            for v in t.v {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        Csg { root, spheres, triangles, object, lo, hi }
    }

    /// The bounding sphere of the bounds (rasterizers bound the object on screen with it).
    pub fn bounding_sphere(&self) -> Sphere {
        let center = (self.lo + self.hi) * 0.5;
        Sphere { center, radius: ((self.hi - self.lo) * 0.5).length().max(1e-6), material: 0, object: self.object }
    }
}

/// Whether the triangles form a closed surface: every edge, by its end
/// points' exact positions, is used exactly twice, once in each direction
/// (consistently wound). `Err` says what is wrong in a few words.
pub fn check_closed(triangles: &[Triangle]) -> Result<(), String> {
    use std::collections::HashMap;
    if triangles.is_empty() {
        return Err("it has no triangles".into());
    }
    let key = |v: Vec3| v.to_array().map(|c| (c + 0.0).to_bits());
    let mut edges: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (key(t.v[k]), key(t.v[(k + 1) % 3]));
            if a == b {
                continue;
            }
            // Counted on the undirected edge: +1 one way, -1 the other; the
            // number of uses separately.
            let (lo, hi, sign) = if a < b { (a, b, 1) } else { (b, a, -1) };
            *edges.entry((lo, hi)).or_insert(0) += sign * 1000 + 1;
        }
    }
    let open = edges.values().filter(|&&v| v != 2).count();
    if open > 0 {
        return Err(format!("{open} of its edges are not shared by exactly two consistently wound triangles"));
    }
    Ok(())
}

/// The volume a closed surface encloses, positive when its triangles face
/// outwards (counter-clockwise seen from outside) and negative when the
/// whole solid is wound inside out.
pub fn signed_volume(triangles: &[Triangle]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.v.map(|v| v.as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// Turns an inside-out solid right side out: each triangle's winding is
/// reversed, and vertex normals that then point against their face follow it.
pub fn turn_right_side_out(triangles: &mut [Triangle]) {
    for t in triangles {
        t.v.swap(1, 2);
        t.n.swap(1, 2);
        t.uv.swap(1, 2);
        let face = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
        for n in &mut t.n {
            if n.dot(face) < 0.0 {
                *n = -*n;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;

    fn tri(a: Vec3, b: Vec3, c: Vec3) -> Triangle {
        Triangle { v: [a, b, c], n: [Vec3::Y; 3], uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided: false }
    }

    #[test]
    fn a_tetrahedron_is_closed_and_without_a_face_is_not() {
        let (o, x, y, z) = (Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z);
        let mut t = vec![tri(o, y, x), tri(o, x, z), tri(o, z, y), tri(x, y, z)];
        assert_eq!(check_closed(&t), Ok(()));
        // One face wound the wrong way: its edges run the same way as their neighbours'.
        t[3] = tri(x, z, y);
        assert!(check_closed(&t).is_err());
        t.pop();
        assert!(check_closed(&t).unwrap_err().contains("3 of its edges"));
    }

    #[test]
    fn an_inside_out_solid_has_negative_volume_until_turned() {
        let (o, x, y, z) = (Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z);
        let mut t = vec![tri(o, y, x), tri(o, x, z), tri(o, z, y), tri(x, y, z)];
        assert!((signed_volume(&t) - 1.0 / 6.0).abs() < 1e-9);
        for tr in &mut t {
            tr.v.swap(0, 1);
        }
        assert!((signed_volume(&t) + 1.0 / 6.0).abs() < 1e-9);
        assert_eq!(check_closed(&t), Ok(()), "inside out, it is still closed: the volume is what tells");
        turn_right_side_out(&mut t);
        assert!((signed_volume(&t) - 1.0 / 6.0).abs() < 1e-9);
        for tr in &t {
            let face = (tr.v[1] - tr.v[0]).cross(tr.v[2] - tr.v[0]);
            assert!(tr.n.iter().all(|n| n.dot(face) >= 0.0));
        }
    }
}
