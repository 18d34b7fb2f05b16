//! PLACEHOLDER until the SAH BVH lands: delegates to the brute-force query.

use super::brute::BruteQuery;
use super::cast_pass;
use super::intersect::TriangleEdges;
use crate::math::Radiance;
use crate::render::{PassJob, RayCounts, Renderer};
use crate::scene::Scene;

pub struct Bvh;

impl Bvh {
    pub fn build(_scene: &Scene, _edges: &[TriangleEdges]) -> Bvh {
        Bvh
    }
}

pub struct BvhRayTracer;

impl Renderer for BvhRayTracer {
    fn name(&self) -> &'static str {
        "raytrace:bvh"
    }
    fn description(&self) -> &'static str {
        "placeholder"
    }
    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
        cast_pass(job, &BruteQuery(job.prepared), out)
    }
}
