//! A scene made ready to render: triangle edges for intersection and the BVH.
//! Built once per scene load; every renderer reads it.

use crate::render::accel::bvh::Bvh;
use crate::render::accel::scene_edges::SceneEdges;
use crate::render::accel::intersect::TriangleEdges;
use crate::scene::Scene;
use std::time::Instant;

pub struct PreparedScene {
    pub scene: Scene,
    /// Per triangle, in scene order: the data the ray-triangle test reads
    /// (stored once, in the BVH's primitive slots).
    pub edges: SceneEdges,
    pub bvh: Bvh,
    /// Time to build the BVH, milliseconds.
    pub build_ms: f64,
    /// The last shadow maps built (`--shadows map`), keyed by size and lights;
    /// see `PreparedScene::shadow_maps`.
    pub shadow_cache: crate::render::shadow::map::ShadowMapCache,
    /// The last photon map built (`--gi photons`); see `PreparedScene::photon_map`.
    pub photon_cache: crate::render::transport::photon_map::PhotonMapCache,
    /// The last shadow volumes built (`--shadows volume`), keyed by the
    /// lights; see `PreparedScene::shadow_volumes`.
    pub volume_cache: crate::render::shadow::volume::ShadowVolumeCache,
    /// The two-level layer's BVHs, when the scene has one.
    pub instances: Option<crate::render::accel::instances::InstanceAccel>,
}

/// Bytes held per scene by its geometry (see `PreparedScene::memory`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryUse {
    /// The scene's triangles and spheres, CSG operands' included.
    pub scene_bytes: usize,
    /// The BVH: nodes, primitive slots, bounds kept for the debugger.
    pub bvh_bytes: usize,
    /// What `PreparedScene` adds besides the BVH (where each triangle's
    /// edges sit in the BVH).
    pub prepared_bytes: usize,
}

impl MemoryUse {
    pub fn total(&self) -> usize {
        self.scene_bytes + self.bvh_bytes + self.prepared_bytes
    }
}

impl PreparedScene {
    pub fn new(mut scene: Scene) -> PreparedScene {
        // Scenes made in code (or edited) may hold triangles pushed since
        // loading; a no-op for scenes straight from a file.
        scene.triangles.share_corners();
        scene.refresh_emitters();
        let start = Instant::now();
        let bvh = Bvh::build(&scene, &scene.triangles);
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        let instances = scene.layer.as_ref().map(|l| crate::render::accel::instances::InstanceAccel::build(l));
        let build_ms = if instances.is_some() { start.elapsed().as_secs_f64() * 1e3 } else { build_ms };
        let edges = bvh.edges_in_scene_order();
        PreparedScene {
            scene,
            edges,
            bvh,
            build_ms,
            shadow_cache: Default::default(),
            photon_cache: Default::default(),
            volume_cache: Default::default(),
            instances,
        }
    }

    /// The intersection data of triangle `index`, of the two-level layer too.
    #[inline]
    pub fn triangle_edges(&self, index: u32) -> TriangleEdges {
        if (index as usize) < self.edges.len() {
            self.edges[index as usize]
        } else {
            TriangleEdges::new(&self.scene.triangle(index))
        }
    }

    /// What the scene's geometry and its acceleration structures hold in
    /// memory, counted as length times element size (allocator slack and
    /// the lazily built caches left out).
    pub fn memory(&self) -> MemoryUse {
        use std::mem::size_of_val;
        MemoryUse {
            scene_bytes: self.scene.triangles.memory_bytes()
                + size_of_val(&self.scene.spheres[..])
                + self.scene.layer.as_ref().map_or(0, |l| l.memory_bytes())
                + self.scene.csgs.iter().map(|c| size_of_val(&c.triangles[..]) + size_of_val(&c.spheres[..])).sum::<usize>(),
            bvh_bytes: self.bvh.memory_bytes() + self.instances.as_ref().map_or(0, |a| a.memory_bytes()),
            prepared_bytes: self.edges.memory_bytes(),
        }
    }
}
