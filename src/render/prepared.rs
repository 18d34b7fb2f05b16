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

impl PreparedScene {
    pub fn new(scene: Scene) -> PreparedScene {
        let edges: Vec<TriangleEdges> = scene.triangles.iter().map(TriangleEdges::new).collect();
        let start = Instant::now();
        let bvh = Bvh::build(&scene, &edges);
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        PreparedScene { scene, edges, bvh, build_ms, shadow_cache: Default::default(), photon_cache: Default::default(), volume_cache: Default::default() }
    }

    /// The photon map for the scene's current lights and materials and the
    /// photon settings `gi`, from the cache or built now.
    pub fn photon_map(&self, gi: &super::gi::GiSettings, bump: f32) -> std::sync::Arc<super::photon_map::PhotonMap> {
        self.photon_cache.get(self, gi, bump)
    }
}
