//! Rasterization: for each triangle, for each pixel it covers (CGPP 15.6).
//!
//! Every variant answers only "which surface does this sample see" and hands
//! the `SurfaceHit` to the shared `resolve_sample`, like the ray casters:
//!
//! - `setup`: camera space, back-face culling, near clipping (`clip`), projection;
//! - coverage loops, one per file: `naive` and `bbox` (the 3D ray test),
//!   `barycentric`, `incremental`, `scanline`, `fixed`, `tiled`;
//! - `vis_buffer`: depth test, visibility buffer, forward or early-depth shading;
//! - `sphere`: analytic spheres through the ray tracer's sphere test;
//! - `pass`: the parallel regions of a pass; `coverage`: coverage counts for tests.

pub mod barycentric;
pub mod bbox;
pub mod clip;
pub mod coverage;
pub mod fixed;
pub mod incremental;
pub mod naive;
pub mod pass;
pub mod scanline;
pub mod setup;
pub mod sphere;
pub mod tiled;
pub mod vis_buffer;

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

/// Knobs shared by every rasterizer variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RasterOptions {
    /// true: resolve visibility first (a visibility buffer of primitive and
    /// barycentrics per pixel), then shade once per pixel. false: forward
    /// shading, every fragment that passes the depth test when it arrives is shaded.
    pub early_depth: bool,
}

impl Default for RasterOptions {
    fn default() -> Self {
        RasterOptions { early_depth: true }
    }
}

/// One rasterizer variant with its options.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rasterizer {
    pub method: Method,
    pub options: RasterOptions,
}

impl Rasterizer {
    pub fn new(method: Method, options: RasterOptions) -> Rasterizer {
        Rasterizer { method, options }
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
        match self.method {
            Method::Naive => naive::render(job, self.options, out),
            Method::BBox => bbox::render(job, self.options, out),
            Method::Tiled => pass::render_tiled(self.options, job, out),
            m => pass::render_bands(m, self.options, job, out),
        }
    }
}

/// Every variant with the given options.
pub fn renderers_with(options: RasterOptions) -> Vec<Box<dyn Renderer>> {
    Method::ALL.into_iter().map(|m| Box::new(Rasterizer::new(m, options)) as Box<dyn Renderer>).collect()
}

/// Every variant with the default options (early depth).
pub fn renderers() -> Vec<Box<dyn Renderer>> {
    renderers_with(RasterOptions::default())
}
