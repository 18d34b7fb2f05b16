//! Rasterization: for each triangle, for each pixel it covers (CGPP 15.6).
//!
//! Every variant answers only "which surface does this sample see" and hands
//! the `SurfaceHit` to the shared `resolve_sample`, like the ray casters:
//!
//! - `method`: the variants' names;
//! - `cull`: copies made by `instances` culled whole by their bounding spheres;
//! - `setup`: camera space, back-face culling, near clipping (`clip`), projection;
//! - `rect`: pixel rectangles and sample spans; `subpixel`: the fixed-point grid;
//!   `small`: triangles too small for that grid, by the ray casters' test;
//! - coverage loops, one per file: `naive` and `bbox` (the 3D ray test),
//!   `barycentric`, `incremental`, `scanline`, `fixed`, `tiled`;
//! - `painter`: the painter's algorithm's draw order (no depth buffer);
//! - `depth_format`: what the depth buffer stores (`--depth-buffer`);
//! - `vis_buffer`: depth test, visibility buffer, forward or early-depth shading,
//!   the pixel-history recorder and the cost view's counts;
//! - `msaa`: coverage sample patterns and the one-shade-per-primitive resolve;
//! - `sphere`: analytic spheres through the ray tracer's sphere test;
//! - `csg`: constructive solid geometry: operands scan-converted into an A-buffer
//!   (`abuffer`), each sample's list resolved by the ray casters' interval rule;
//! - `stencil`: the shadow volumes' stencil counts (`--shadows volume`);
//! - `pass`: the parallel regions of a pass; `coverage`: coverage counts for tests.

pub mod abuffer;
pub mod barycentric;
pub mod bbox;
pub mod clip;
pub mod coverage;
pub mod csg;
pub mod cull;
pub mod depth_format;
pub mod derivatives;
pub mod fixed;
pub mod incremental;
pub mod method;
pub mod msaa;
pub mod naive;
pub mod painter;
pub mod pass;
pub mod rect;
pub mod runs;
pub mod scanline;
pub mod setup;
pub mod small;
pub mod sphere;
pub mod stencil;
pub mod subpixel;
pub mod tiled;
pub mod vis_buffer;

/// Rows per band of the band-parallel variants (the pass and the stencil
/// count of shadow volumes cut the image the same way).
pub const BAND_ROWS: u32 = 16;

use crate::render::inspect::pixel_record::PixelTrace;
use crate::render::{PassJob, RayCounts, Renderer};
use crate::math::Radiance;

pub use coverage::coverage_counts;
pub use method::Method;

/// The renderer `--renderer rasterize` names.
/// `fixed`: watertight, and measured a little faster than `tiled` at 1280x720
/// on the bench scenes (per-pixel resolve dominates both; tiling adds bookkeeping).
pub const DEFAULT_RASTERIZE: &str = "rasterize:fixed";

/// One rasterizer variant. Its knobs (early depth, MSAA) are in `RenderSettings`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rasterizer {
    pub method: Method,
}

impl Rasterizer {
    pub fn new(method: Method) -> Rasterizer {
        Rasterizer { method }
    }
}

impl Renderer for Rasterizer {
    fn name(&self) -> &'static str {
        self.method.name()
    }

    fn description(&self) -> &'static str {
        self.method.description()
    }

    /// The copies, each set up whole (and culled whole); shadow maps draw them too.
    fn instance_layer(&self) -> crate::render::layer_support::LayerSupport {
        crate::render::layer_support::LayerSupport::Everything
    }

    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
        pass::render(self.method, job, out)
    }

    /// Each region's resolve (`VisBuffer::resolve_into`) checks the values it
    /// writes as it finishes them.
    fn admits_its_samples(&self) -> bool {
        true
    }

    fn check(&self, scene: &crate::scene::Scene, settings: &crate::render::RenderSettings) -> Result<(), String> {
        if self.method == Method::Painter && !scene.csgs.is_empty() {
            return Err("rasterize:painter cannot draw csg objects (a draw order cannot resolve their intervals); use another rasterizer".into());
        }
        crate::render::accel::csg::check(scene, settings)
    }

    fn check_camera(&self, camera: &crate::scene::Camera) -> Result<(), String> {
        if self.method == Method::Painter {
            return crate::render::camera_support::check_rasterized_from_a_point(self.name(), camera);
        }
        crate::render::camera_support::check_rasterized(self.name(), camera)
    }

    fn trace_pixel(&self, job: &PassJob, x: u32, y: u32, rec: &mut PixelTrace) -> Option<Radiance> {
        Some(pass::replay_pixel(self.method, job, x, y, rec))
    }
}

/// Every variant.
pub fn renderers() -> Vec<Box<dyn Renderer>> {
    Method::ALL.into_iter().map(|m| Box::new(Rasterizer::new(m)) as Box<dyn Renderer>).collect()
}
