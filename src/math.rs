//! Small math vocabulary shared by the whole core: rays, radiance, glam re-exports.

pub mod lanes;
pub mod prefetch;
pub mod streaming;
pub mod rounding;

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

/// A direction with its length brought into the range where squaring it
/// stays a normal f32, by a power of two (exact, so the direction does not
/// change). Vectors already in range come back unchanged, bit for bit;
/// `[0, 1e20, 0]` becomes `[0, 2^0.., 0]` instead of normalizing to zero.
pub fn rescale_direction(v: Vec3) -> Vec3 {
    let m = v.abs().max_element();
    let l2 = v.length_squared();
    if !m.is_finite() || m == 0.0 || (l2.is_finite() && l2 >= 1e-30) {
        return v;
    }
    v * 2f32.powi(-(m.log2().floor() as i32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_and_tiny_directions_keep_their_direction() {
        assert_eq!(rescale_direction(Vec3::new(0.0, 1e20, 0.0)).normalize(), Vec3::Y);
        assert_eq!(rescale_direction(Vec3::new(0.0, -1e20, -1e20)).normalize(), Vec3::new(0.0, -1.0, -1.0).normalize());
        assert_eq!(rescale_direction(Vec3::new(1e-30, 0.0, 0.0)).normalize(), Vec3::X);
        let v = Vec3::new(0.3, -0.7, 2.0);
        assert_eq!(rescale_direction(v), v);
    }
}
