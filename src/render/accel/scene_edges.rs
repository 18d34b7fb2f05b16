//! The triangles' edges in scene order, read through the BVH's slots: what
//! the rasterizers and shading look up by triangle index without a second
//! copy of the edges.

use crate::render::accel::intersect::TriangleEdges;
use crate::scene::PrimitiveId;
use std::sync::Arc;

/// The triangles' edges in scene order: a view of the BVH's primitive
/// slots (which hold the edges in leaf order) through each triangle's slot.
pub struct SceneEdges {
    prims: Arc<Vec<(TriangleEdges, PrimitiveId)>>,
    /// Per triangle, in scene order: its slot in `prims`.
    slot: Vec<u32>,
}

impl SceneEdges {
    /// `slot[i]` must be the slot of triangle `i` in `prims`.
    pub(crate) fn new(prims: Arc<Vec<(TriangleEdges, PrimitiveId)>>, slot: Vec<u32>) -> SceneEdges {
        debug_assert!(slot.iter().enumerate().all(|(i, &s)| prims[s as usize].1 == PrimitiveId::triangle(i as u32)));
        SceneEdges { prims, slot }
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.slot.len()
    }

    pub fn is_empty(&self) -> bool {
        self.slot.is_empty()
    }

    /// Every triangle's edges, in scene order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &TriangleEdges> + '_ {
        self.slot.iter().map(|&s| &self.prims[s as usize].0)
    }

    /// Bytes of the view itself (the edges are the BVH's).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.slot[..])
    }
}

impl std::ops::Index<usize> for SceneEdges {
    type Output = TriangleEdges;
    #[inline]
    fn index(&self, i: usize) -> &TriangleEdges {
        &self.prims[self.slot[i] as usize].0
    }
}
