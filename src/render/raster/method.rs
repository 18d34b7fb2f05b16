//! The rasterization methods (coverage loops) a rasterizer variant can use,
//! with the names `--renderer` takes.

use crate::named::named_enum;

named_enum! {
    /// The rasterization methods, from the book's first version to the fastest.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    pub enum Method ("rasterizer") {
        Naive = "rasterize:naive",
        BBox = "rasterize:bbox",
        Barycentric = "rasterize:barycentric",
        Incremental = "rasterize:incremental",
        Scanline = "rasterize:scanline",
        Fixed = "rasterize:fixed",
        Tiled = "rasterize:tiled",
        Painter = "rasterize:painter",
    }
}

impl Method {
    /// What the method does, for `pinhole list`.
    pub fn description(self) -> &'static str {
        match self {
            Method::Naive => "every triangle against every pixel with the 3D ray test and a depth buffer (CGPP 15.22)",
            Method::BBox => "the 3D ray test within each triangle's screen bounding box (CGPP 15.23, 15.24)",
            Method::Barycentric => "2D barycentric weights per pixel, perspective-correct (CGPP 15.25-15.28)",
            Method::Incremental => "float edge functions stepped by additions, perspective-correct",
            Method::Scanline => "span filling between the triangle's edges (Computer Graphics from Scratch)",
            Method::Fixed => "8-bit sub-pixel fixed-point edge functions, top-left rule: watertight",
            Method::Tiled => "fixed-point edge functions, 32x32 tiles in parallel, 8x8 block masks: watertight",
            Method::Painter => "the painter's algorithm: no depth buffer, back to front with Newell's tests (CGFS ch. 12)",
        }
    }
}
