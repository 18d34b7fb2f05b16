//! Rasterization: for each triangle, for each pixel it covers.

use super::Renderer;

pub const DEFAULT_RASTERIZE: &str = "rasterize:incremental";

pub fn renderers() -> Vec<Box<dyn Renderer>> {
    vec![]
}
