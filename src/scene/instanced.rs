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

use crate::math::Vec3;
use crate::scene::placement::Placement;
use crate::scene::{InstanceInfo, Scene, Triangle};
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
    /// Per mesh, its triangles' vertex colours (per corner) when its file
    /// gives them: every copy of the mesh shows them.
    pub colours: Vec<Option<Arc<Vec<[Vec3; 3]>>>>,
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

    /// The vertex colours of triangle `local` of copy `inst`, in the corner
    /// order of `world` (a mirroring placement swaps corners 1 and 2);
    /// `None` when its mesh has none.
    #[inline]
    pub fn world_colours(&self, inst: &LayerInstance, local: usize) -> Option<[Vec3; 3]> {
        let mut c = *self.colours.get(inst.mesh as usize)?.as_ref()?.get(local)?;
        if inst.placement.flips() {
            c.swap(1, 2);
        }
        Some(c)
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

/// Copies bound for the two-level layer, gathered while objects are added:
/// their virtual indices come after every flattened triangle.
#[derive(Default)]
pub struct Layered {
    pub flattened: usize,
    /// Per object: its id, its placed mesh and its copies.
    pub objects: Vec<(u32, Arc<Vec<Triangle>>, Vec<MeshCopy>)>,
    /// Per entry of `objects` (missing at the end: none), its mesh's
    /// vertex colours per triangle.
    pub colours: Vec<Option<Arc<Vec<[Vec3; 3]>>>>,
}

/// One placed copy of a mesh object's triangles.
pub struct MeshCopy {
    /// The copy's own placement, applied after the object's (`None`: the object itself).
    pub placement: Option<Placement>,
    /// The copy's material, or the object's when `None` (then the MTL's).
    pub material: Option<u32>,
    /// Index in the object's `instances` list, `None` for an object without one.
    pub index: Option<u32>,
}

/// Places the copies gathered in `layered` after every flattened triangle.
pub fn build_layer(scene: &mut Scene, layered: Layered) -> Result<(), String> {
    if layered.objects.is_empty() {
        return Ok(());
    }
    let mut layer = InstanceLayer::default();
    let mut base = scene.triangles.len() as u64;
    let mut colours = layered.colours.into_iter();
    for (object, mesh, copies) in layered.objects {
        let (center, radius) = bounding_sphere(&mesh);
        let mesh_index = layer.meshes.len() as u32;
        let len = mesh.len() as u64;
        layer.meshes.push(mesh);
        layer.colours.push(colours.next().flatten());
        for copy in copies {
            let placement = copy.placement.unwrap_or_else(|| Placement::new(Vec3::ZERO, Vec3::ZERO, Vec3::ONE));
            if base + len >= 1 << 30 {
                return Err(format!("{}: the copies hold more than 2^30 triangles, the most a primitive id can name", scene.name));
            }
            let m = placement.matrix();
            let stretch = m.x_axis.truncate().length().max(m.y_axis.truncate().length()).max(m.z_axis.truncate().length());
            let c = m.transform_point3(center);
            let r = radius * stretch * (1.0 + 1e-5) + 1e-6 * c.abs().max_element();
            let range = base as usize..(base + len) as usize;
            scene.instances.push(InstanceInfo { object, index: copy.index.unwrap_or(0), triangles: range, center: c, radius: r });
            layer.instances.push(LayerInstance { mesh: mesh_index, placement, material: copy.material, base: base as u32 });
            base += len;
        }
    }
    scene.layer = Some(Arc::new(layer));
    Ok(())
}

/// The centre of the bounding box of `tris` and the distance to its farthest vertex.
pub fn bounding_sphere(tris: &[Triangle]) -> (Vec3, f32) {
    let info = InstanceInfo::new(0, 0, 0..0, tris.iter().cloned());
    (info.center, info.radius)
}

