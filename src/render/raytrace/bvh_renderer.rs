//! The `raytrace:bvh` renderer: frames cast their eye rays, and the shadow
//! rays towards the first light, as packets through the BVH (`packet.rs`);
//! a pixel replay casts the same pixel's rays one at a time (`bvh.rs`).

use crate::render::accel::bvh::BvhQuery;
use crate::render::raytrace::cast_pixel;
use crate::render::raytrace::packet_tiles::{cast_pass_packets, cast_passes_packets};
use crate::math::Radiance;
use crate::render::inspect::pixel_record::PixelTrace;
use crate::render::{PassJob, RayCounts, Renderer};

pub struct BvhRayTracer;

impl Renderer for BvhRayTracer {
    fn name(&self) -> &'static str {
        "raytrace:bvh"
    }

    fn description(&self) -> &'static str {
        "ray casting through a SAH bounding volume hierarchy: same pixels as the reference, far fewer tests"
    }

    /// The copies, by the two-level BVH; shadow maps draw them too.
    fn instance_layer(&self) -> crate::render::layer_support::LayerSupport {
        crate::render::layer_support::LayerSupport::Everything
    }

    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
        if job.prepared.instances.is_some() || !job.settings.packets {
            // Packets walk the one BVH; the two-level layer takes rays one at
            // a time, and so does every frame with `--packets off`.
            return crate::render::raytrace::cast_pass(job, &BvhQuery::new(job.prepared), out);
        }
        cast_pass_packets(job, &BvhQuery::new(job.prepared), out)
    }

    /// A chunk's passes up to `packet::MAX_PASSES` at a time, each pixel's
    /// samples of them in one packet (`cast_passes_packets`), where frames
    /// are shaded in batches; otherwise one after the other.
    fn render_passes(&self, jobs: &[PassJob], out: &mut [Radiance]) -> RayCounts {
        let passes = match jobs.first() {
            Some(job) if job.prepared.instances.is_none() && job.settings.packets => cast_passes_packets(jobs, &BvhQuery::new(job.prepared), out),
            _ => None,
        };
        passes.unwrap_or_else(|| crate::render::render_passes_in_turn(self, jobs, out))
    }

    /// `cast_pass_packets` and `cast_pass` check each band as they finish it.
    fn admits_its_samples(&self) -> bool {
        true
    }

    /// Every eye ray is made from the camera itself (`PassJob::eye_ray`).
    fn check_camera(&self, _camera: &crate::scene::Camera) -> Result<(), String> {
        Ok(())
    }

    fn passes_at_once(&self) -> u32 {
        crate::render::accel::packet::MAX_PASSES as u32
    }

    /// Two rows of packet tiles: chunks small enough for two threads to
    /// share the work evenly, large enough that the per-call set-up
    /// (packets, batches, the path pool) is paid rarely.
    fn chunk_rows(&self) -> Option<u32> {
        Some(2 * crate::render::accel::packet::TILE_H as u32)
    }

    /// The replay runs the frame's code from the eye ray's hit on: the same
    /// `resolve_sample` and `shade()`. It differs from the frame in exactly
    /// two places, both traversals rather than shading: the eye ray is traced
    /// alone instead of in its tile's packet, and so is the shadow ray
    /// towards the first light, which a frame answers from the tile's shadow
    /// packet (`packet::PixelQuery`). A packet carries no recorder (it
    /// serves 64 pixels at once), and the single-ray traversal is the one
    /// whose node visits and primitive tests a record can list. Both give
    /// the same answers: the packet finds each ray's own closest hit, and a
    /// shadow packet finds an occluder exactly when the single ray does
    /// (tested in `packet.rs` and below).
    fn trace_pixel(&self, job: &PassJob, x: u32, y: u32, rec: &mut PixelTrace) -> Option<Radiance> {
        Some(cast_pixel(job, &BvhQuery::new(job.prepared), x, y, &mut RayCounts::default(), rec))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::inspect::debug::View;
    use crate::render::raytrace::brute_renderer::BruteForce;
    use crate::render::{render_frame, Interpolation, PreparedScene, RenderSettings, ShadowMode};
    use crate::scene::builtin;
    use std::sync::atomic::AtomicBool;

    fn load(name: &str) -> PreparedScene {
        PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap())
    }

    fn bits(p: &[Radiance]) -> Vec<[u32; 3]> {
        p.iter().map(|c| c.to_array().map(f32::to_bits)).collect()
    }

    #[test]
    fn frames_match_brute_force_pixel_for_pixel() {
        for name in builtin::names() {
            let prepared = load(name);
            for view in [View::Shaded, View::Depth] {
                let settings = RenderSettings { width: 96, height: 54, shadows: ShadowMode::Ray, view, ..RenderSettings::for_scene(&prepared.scene) };
                let cancel = AtomicBool::new(false);
                let a = render_frame(&BvhRayTracer, &prepared, &settings, &cancel, None).unwrap();
                let b = render_frame(&BruteForce, &prepared, &settings, &cancel, None).unwrap();
                assert!(bits(&a.pixels) == bits(&b.pixels), "{name} {view:?}: images differ");
                assert_eq!((a.counts.primary, a.counts.shadow), (b.counts.primary, b.counts.shadow), "{name}");
                if prepared.edges.len() > 1000 {
                    assert!(a.counts.tests * 20 < b.counts.tests, "{name}: the BVH tests too many primitives");
                }
            }
        }
    }

    /// Shadow rays answered from the tile's packet leave every pixel as the
    /// single-ray caster shades it, whatever the interpolation.
    #[test]
    fn shaded_frames_equal_the_single_ray_frames() {
        for name in builtin::names() {
            let prepared = load(name);
            for interpolation in Interpolation::ALL {
                let settings = RenderSettings { width: 45, height: 29, interpolation, shadows: ShadowMode::Ray, ..RenderSettings::for_scene(&prepared.scene) };
                let cancel = AtomicBool::new(false);
                let a = render_frame(&BvhRayTracer, &prepared, &settings, &cancel, None).unwrap();
                let b = render_frame(&BruteForce, &prepared, &settings, &cancel, None).unwrap();
                assert!(bits(&a.pixels) == bits(&b.pixels), "{name} {interpolation:?}: images differ");
                assert_eq!((a.counts.primary, a.counts.shadow), (b.counts.primary, b.counts.shadow), "{name} {interpolation:?}");
            }
        }
    }
}
