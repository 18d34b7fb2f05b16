//! The reference renderer: one eye ray per pixel (`cast_pass`) answered by
//! the brute-force query (`accel::brute`), every primitive in scene order.

use crate::math::Radiance;
use crate::render::accel::brute::BruteQuery;
use crate::render::inspect::pixel_record::PixelTrace;
use crate::render::raytrace::{cast_pass, cast_pixel};
use crate::render::{PassJob, RayCounts, Renderer};

pub struct BruteForce;

impl Renderer for BruteForce {
    fn name(&self) -> &'static str {
        "raytrace:brute"
    }

    fn description(&self) -> &'static str {
        "the reference ray caster: every pixel tests every primitive in scene order (CGPP 15.4)"
    }

    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
        cast_pass(job, &BruteQuery(job.prepared), out)
    }

    /// `cast_pass` checks each row as it finishes it.
    fn admits_its_samples(&self) -> bool {
        true
    }

    /// Every eye ray is made from the camera itself (`PassJob::eye_ray`).
    fn check_camera(&self, _camera: &crate::scene::Camera) -> Result<(), String> {
        Ok(())
    }

    fn trace_pixel(&self, job: &PassJob, x: u32, y: u32, rec: &mut PixelTrace) -> Option<Radiance> {
        Some(cast_pixel(job, &BruteQuery(job.prepared), x, y, &mut RayCounts::default(), rec))
    }
}
