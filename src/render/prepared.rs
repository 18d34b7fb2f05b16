//! A scene made ready to render: triangle edges for intersection and the BVH.
//! Built once per scene load; every renderer reads it.

use super::raytrace::bvh::Bvh;
use super::raytrace::intersect::TriangleEdges;
use crate::scene::Scene;
use std::time::Instant;

pub struct PreparedScene {
    pub scene: Scene,
    /// Per triangle, in scene order: the data the ray-triangle test reads.
    pub edges: Vec<TriangleEdges>,
    pub bvh: Bvh,
    /// Time to build the BVH, milliseconds.
    pub build_ms: f64,
    /// The last shadow maps built (`--shadows map`), keyed by size and lights;
    /// see `PreparedScene::shadow_maps`.
    pub shadow_cache: super::shadow_map::ShadowMapCache,
    /// The last photon map built (`--gi photons`); see `PreparedScene::photon_map`.
    pub photon_cache: super::photon_map::PhotonMapCache,
    /// The last shadow volumes built (`--shadows volume`), keyed by the
    /// lights; see `PreparedScene::shadow_volumes`.
    pub volume_cache: super::shadow_volume::ShadowVolumeCache,
}

/// Bytes held per scene by its geometry (see `PreparedScene::memory`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryUse {
    /// The scene's triangles and spheres.
    pub scene_bytes: usize,
    /// The BVH: nodes, primitive slots, bounds kept for the debugger.
    pub bvh_bytes: usize,
    /// What `PreparedScene` adds besides the BVH (the triangles' edges).
    pub prepared_bytes: usize,
}

impl MemoryUse {
    pub fn total(&self) -> usize {
        self.scene_bytes + self.bvh_bytes + self.prepared_bytes
    }
}

impl PreparedScene {
    pub fn new(scene: Scene) -> PreparedScene {
        let edges: Vec<TriangleEdges> = scene.triangles.iter().map(TriangleEdges::new).collect();
        let start = Instant::now();
        let bvh = Bvh::build(&scene, &edges);
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        PreparedScene { scene, edges, bvh, build_ms, shadow_cache: Default::default(), photon_cache: Default::default(), volume_cache: Default::default() }
    }

    /// What the scene's geometry and its acceleration structures hold in
    /// memory, counted as length times element size (allocator slack and
    /// the lazily built caches left out).
    pub fn memory(&self) -> MemoryUse {
        use std::mem::size_of_val;
        MemoryUse {
            scene_bytes: size_of_val(&self.scene.triangles[..]) + size_of_val(&self.scene.spheres[..]),
            bvh_bytes: self.bvh.memory_bytes(),
            prepared_bytes: size_of_val(&self.edges[..]),
        }
    }

    /// The photon map for the scene's current lights and materials and the
    /// photon settings `gi`, from the cache or built now.
    pub fn photon_map(&self, gi: &super::gi::GiSettings, bump: f32) -> std::sync::Arc<super::photon_map::PhotonMap> {
        self.photon_cache.get(self, gi, bump)
    }
}
