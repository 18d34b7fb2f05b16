//! The scene's CSG objects as the fragment shader evaluates them
//! (`shaders::csg_fragment`): each tree flattened into a postfix program
//! (operands before their operation, `a` before `b`, so the leaves are
//! numbered as `render::accel::csg` numbers them), with the leaves' spheres and
//! triangles in buffers of their own.

use crate::scene::csg::{Csg, CsgNode, CsgOp};

/// Most operand lists the shader's evaluation stack holds at once.
pub const MAX_STACK: usize = 4;

/// The buffers, as floats (integers stored as their bits).
#[derive(Debug, Default, PartialEq)]
pub struct CsgData {
    /// Per object: (first node, node count, 0, 0) as bits, then its
    /// bounds (lo, 0) and (hi, 0).
    pub objects: Vec<f32>,
    /// Per node: (kind, first, end or 0, flipped), as integer bits: kind 0 a
    /// sphere leaf (first: its index in `spheres`), 1 a mesh leaf (its
    /// triangles `first..end` of `triangles`), 2 union, 3 intersection, 4
    /// difference (of the two lists on top of the stack).
    pub nodes: Vec<f32>,
    /// Per sphere: (centre, radius), (material bits, 0, 0, 0).
    pub spheres: Vec<f32>,
    /// Per triangle: (v0, material bits), v1, v2, n0, n1, n2 (each padded
    /// to four), (uv0, uv1), (uv2, 0, 0).
    pub triangles: Vec<f32>,
}

/// How many operand lists evaluating `n` keeps on the stack at once.
fn stack_needed(n: &CsgNode) -> usize {
    match n {
        CsgNode::Op { a, b, .. } => stack_needed(a).max(1 + stack_needed(b)),
        _ => 1,
    }
}

pub fn build(csgs: &[Csg]) -> Result<CsgData, String> {
    let mut d = CsgData::default();
    for (i, csg) in csgs.iter().enumerate() {
        if stack_needed(&csg.root) > MAX_STACK {
            return Err(format!("the opengl renderer evaluates csg trees that keep at most {MAX_STACK} operands pending, not csg object {i}"));
        }
        let first_node = d.nodes.len() / 4;
        let sphere_base = d.spheres.len() / 8;
        let triangle_base = d.triangles.len() / 32;
        for s in &csg.spheres {
            d.spheres.extend_from_slice(&[s.center.x, s.center.y, s.center.z, s.radius, f32::from_bits(s.material), 0.0, 0.0, 0.0]);
        }
        for t in &csg.triangles {
            let v = t.v;
            d.triangles.extend_from_slice(&[v[0].x, v[0].y, v[0].z, f32::from_bits(t.material)]);
            for p in [v[1], v[2], t.n[0], t.n[1], t.n[2]] {
                d.triangles.extend_from_slice(&[p.x, p.y, p.z, 0.0]);
            }
            d.triangles.extend_from_slice(&[t.uv[0].x, t.uv[0].y, t.uv[1].x, t.uv[1].y, t.uv[2].x, t.uv[2].y, 0.0, 0.0]);
        }
        emit(&csg.root, false, sphere_base as u32, triangle_base as u32, &mut d.nodes);
        let count = d.nodes.len() / 4 - first_node;
        let bits = |x: usize| f32::from_bits(x as u32);
        d.objects.extend_from_slice(&[bits(first_node), bits(count), 0.0, 0.0]);
        d.objects.extend_from_slice(&[csg.lo.x, csg.lo.y, csg.lo.z, 0.0, csg.hi.x, csg.hi.y, csg.hi.z, 0.0]);
    }
    // GL refuses empty storage blocks.
    for v in [&mut d.objects, &mut d.nodes, &mut d.spheres, &mut d.triangles] {
        if v.is_empty() {
            v.resize(4, 0.0);
        }
    }
    Ok(d)
}

/// Appends `node`'s postfix program; `flipped` under an odd number of
/// subtractions (`render::accel::csg::node_intervals`).
fn emit(node: &CsgNode, flipped: bool, sphere_base: u32, triangle_base: u32, out: &mut Vec<f32>) {
    let mut push = |kind: u32, a: u32, b: u32, f: bool| out.extend_from_slice(&[kind, a, b, f as u32].map(f32::from_bits));
    match node {
        CsgNode::Sphere(i) => push(0, sphere_base + i, 0, flipped),
        CsgNode::Mesh { first, end, .. } => push(1, triangle_base + first, triangle_base + end, flipped),
        CsgNode::Op { op, a, b } => {
            emit(a, flipped, sphere_base, triangle_base, out);
            emit(b, flipped ^ (*op == CsgOp::Difference), sphere_base, triangle_base, out);
            let kind = match op {
                CsgOp::Union => 2,
                CsgOp::Intersection => 3,
                CsgOp::Difference => 4,
            };
            out.extend_from_slice(&[kind, 0, 0, 0].map(f32::from_bits));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Sphere;
    use glam::Vec3;

    #[test]
    fn a_difference_flips_its_second_operand_and_comes_last() {
        let s = |x: f32| Sphere { center: Vec3::new(x, 0.0, 0.0), radius: 1.0, material: 0, object: 0 };
        let root = CsgNode::Op { op: CsgOp::Difference, a: Box::new(CsgNode::Sphere(0)), b: Box::new(CsgNode::Sphere(1)) };
        let d = build(&[Csg::new(root, vec![s(0.0), s(1.0)], Vec::new(), 0)]).unwrap();
        let nodes: Vec<u32> = d.nodes.iter().map(|x| x.to_bits()).collect();
        assert_eq!(nodes, [0, 0, 0, 0, 0, 1, 0, 1, 4, 0, 0, 0]);
        assert_eq!(d.objects[..2].iter().map(|x| x.to_bits()).collect::<Vec<_>>(), [0, 3]);
    }
}
