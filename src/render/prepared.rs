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
}

impl PreparedScene {
    pub fn new(scene: Scene) -> PreparedScene {
        let edges: Vec<TriangleEdges> = scene.triangles.iter().map(TriangleEdges::new).collect();
        let start = Instant::now();
        let bvh = Bvh::build(&scene, &edges);
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        PreparedScene { scene, edges, bvh, build_ms, shadow_cache: Default::default() }
    }
}
