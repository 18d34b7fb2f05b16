//! Small math vocabulary shared by the whole core: rays, radiance, glam re-exports.

pub use glam::{Mat3, Vec2, Vec3};

/// Linear RGB radiance in W/(m²·sr). Never gamma-encoded inside the core.
pub type Radiance = Vec3;

/// A ray `origin + t * dir`; `dir` is unit length for every ray the renderers cast.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Ray {
        Ray { origin, dir }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Relative luminance of linear RGB (Rec. 709 weights).
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// True when every component is finite.
pub fn is_finite(v: Vec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}
