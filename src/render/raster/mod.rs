//! Rasterization: for each triangle, for each pixel it covers (CGPP 15.6).
//!
//! Every variant answers only "which surface does this sample see" and hands
//! the `SurfaceHit` to the shared `resolve_sample`, like the ray casters:
//!
//! - `setup`: camera space, back-face culling, near clipping (`clip`), projection;
//! - coverage loops, one per file: `naive` and `bbox` (the 3D ray test),
//!   `barycentric`, `incremental`, `scanline`, `fixed`, `tiled`;
//! - `vis_buffer`: depth test, visibility buffer, forward or early-depth shading,
//!   the pixel-history recorder and the cost view's counts;
//! - `msaa`: coverage sample patterns and the one-shade-per-primitive resolve;
//! - `sphere`: analytic spheres through the ray tracer's sphere test;
//! - `pass`: the parallel regions of a pass; `coverage`: coverage counts for tests.

pub mod barycentric;
pub mod bbox;
pub mod clip;
pub mod coverage;
pub mod fixed;
pub mod incremental;
pub mod msaa;
pub mod naive;
pub mod pass;
pub mod scanline;
pub mod setup;
pub mod sphere;
pub mod tiled;
pub mod vis_buffer;

use super::trace::PixelTrace;
use super::{PassJob, RayCounts, Renderer};
use crate::math::Radiance;

pub use coverage::coverage_counts;

/// The renderer `--renderer rasterize` names.
/// `fixed`: watertight, and measured a little faster than `tiled` at 1280x720
/// on the bench scenes (per-pixel resolve dominates both; tiling adds bookkeeping).
pub const DEFAULT_RASTERIZE: &str = "rasterize:fixed";

/// The rasterization methods, from the book's first version to the fastest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    Naive,
    BBox,
    Barycentric,
    Incremental,
    Scanline,
    Fixed,
    Tiled,
}

impl Method {
    pub const ALL: [Method; 7] = [Method::Naive, Method::BBox, Method::Barycentric, Method::Incremental, Method::Scanline, Method::Fixed, Method::Tiled];

    pub fn name(self) -> &'static str {
        match self {
            Method::Naive => "rasterize:naive",
            Method::BBox => "rasterize:bbox",
            Method::Barycentric => "rasterize:barycentric",
            Method::Incremental => "rasterize:incremental",
            Method::Scanline => "rasterize:scanline",
            Method::Fixed => "rasterize:fixed",
            Method::Tiled => "rasterize:tiled",
        }
    }

    pub fn description(self) -> &'static str {
        match self {
            Method::Naive => "every triangle against every pixel with the 3D ray test and a depth buffer (CGPP 15.22)",
            Method::BBox => "the 3D ray test within each triangle's screen bounding box (CGPP 15.23, 15.24)",
            Method::Barycentric => "2D barycentric weights per pixel, perspective-correct (CGPP 15.25-15.28)",
            Method::Incremental => "float edge functions stepped by additions, perspective-correct",
            Method::Scanline => "span filling between the triangle's edges (Computer Graphics from Scratch)",
            Method::Fixed => "8-bit sub-pixel fixed-point edge functions, top-left rule: watertight",
            Method::Tiled => "fixed-point edge functions, 32x32 tiles in parallel, 8x8 block masks: watertight",
        }
    }

    pub fn parse(name: &str) -> Option<Method> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

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

    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
        pass::render(self.method, job, out)
    }

    fn trace_pixel(&self, job: &PassJob, x: u32, y: u32, rec: &mut PixelTrace) -> Option<Radiance> {
        Some(pass::trace(self.method, job, x, y, rec))
    }
}

/// Every variant.
pub fn renderers() -> Vec<Box<dyn Renderer>> {
    Method::ALL.into_iter().map(|m| Box::new(Rasterizer::new(m)) as Box<dyn Renderer>).collect()
}
