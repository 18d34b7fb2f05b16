//! The two-level instance layer: copies made by `instances` lists that are
//! not flattened into `Scene::triangles`, because there would be too many
//! triangles to hold. Each copy refers to a shared mesh (the object's
//! triangles, already placed by the object's own placement) and its own
//! placement. Its triangles have *virtual* indices: copy k covers
//! `base_k .. base_k + mesh length`, all after `Scene::triangles`, so a
//! `PrimitiveId` still names any triangle and the id order (the renderers'
//! tie rule) is the order of the copies. `Scene::triangle` makes the
//! world-space triangle of any index with the very arithmetic flattening
//! uses, so a copy renders as its flattened triangles would.

use crate::scene::placement::Placement;
use crate::scene::Triangle;
use std::sync::Arc;

/// One copy in the layer.
#[derive(Clone, Debug)]
pub struct LayerInstance {
    /// Index into `InstanceLayer::meshes`.
    pub mesh: u32,
    pub placement: Placement,
    /// The copy's material, replacing every triangle's.
    pub material: Option<u32>,
    /// Virtual index of its first triangle.
    pub base: u32,
}

/// The copies held as (shared mesh, placement) pairs.
#[derive(Clone, Debug, Default)]
pub struct InstanceLayer {
    /// Meshes with the object's placement, material, object id and
    /// two-sidedness applied: what every copy of the object starts from.
    pub meshes: Vec<Arc<Vec<Triangle>>>,
    /// In virtual index order.
    pub instances: Vec<LayerInstance>,
}

impl InstanceLayer {
    /// The copy holding virtual triangle `index`, and the index within its mesh.
    #[inline]
    pub fn locate(&self, index: u32) -> Option<(&LayerInstance, usize)> {
        let k = self.instances.partition_point(|i| i.base <= index).checked_sub(1)?;
        let inst = &self.instances[k];
        let local = (index - inst.base) as usize;
        (local < self.meshes[inst.mesh as usize].len()).then_some((inst, local))
    }

    /// Triangle `local` of copy `inst` in world space, as flattening makes it.
    #[inline]
    pub fn world(&self, inst: &LayerInstance, local: usize) -> Triangle {
        let mut t = self.meshes[inst.mesh as usize][local].clone();
        if let Some(m) = inst.material {
            t.material = m;
        }
        inst.placement.apply(t)
    }

    /// Only the vertices of `world`: what intersection tests read.
    #[inline]
    pub fn world_vertices(&self, inst: &LayerInstance, local: usize) -> ([glam::Vec3; 3], bool) {
        let t = &self.meshes[inst.mesh as usize][local];
        (inst.placement.apply_vertices(t.v), t.two_sided)
    }

    /// Triangles in the layer.
    pub fn triangle_count(&self) -> u64 {
        self.instances.iter().map(|i| self.meshes[i.mesh as usize].len() as u64).sum()
    }

    /// Bytes the layer holds: the shared meshes and the copies.
    pub fn memory_bytes(&self) -> usize {
        self.meshes.iter().map(|m| std::mem::size_of_val(&m[..])).sum::<usize>() + std::mem::size_of_val(&self.instances[..])
    }
}
