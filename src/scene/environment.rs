//! The environment: a latitude-longitude image of radiance arriving from
//! infinitely far away, seen by every ray that hits nothing (instead of the
//! flat `background`), and so by mirrors (Computer Graphics from Scratch ch. 15).

use crate::scene::texture::{Texture, Wrap};
use crate::math::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub texture: Arc<Texture>,
    /// Scales the image's values into radiance.
    pub intensity: f32,
}

/// Where unit direction `dir` falls in a latitude-longitude image: u is the
/// longitude, 0.5 looking down -z, growing towards +x (0.75) and round to
/// +z at the seam (0 or 1); v the latitude, 1 straight up (the top row),
/// 0 straight down.
#[inline]
pub fn latlong_uv(dir: Vec3) -> Vec2 {
    let u = 0.5 + dir.x.atan2(-dir.z) * (0.5 / PI);
    let v = 0.5 + dir.y.clamp(-1.0, 1.0).asin() / PI;
    Vec2::new(u, v)
}

impl Environment {
    /// Radiance arriving from direction `dir` (unit, pointing away from
    /// the scene): the image read bilinearly at its finest level, repeating
    /// around the horizon and clamped at the poles.
    #[inline]
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let v = self.texture.levels[0].bilinear_uv(latlong_uv(dir), Wrap::Repeat, Wrap::Clamp) * self.intensity;
        if v.is_finite() { v } else { Vec3::ZERO }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_six_axis_directions_by_hand() {
        // 4 x 4 texels: the top row 100, the bottom row 200, the middle
        // rows 10 * row + column.
        let texels = (0..16)
            .map(|i| {
                let (x, y) = (i % 4, i / 4);
                Vec3::splat(match y {
                    0 => 100.0,
                    3 => 200.0,
                    _ => (10 * y + x) as f32,
                })
            })
            .collect();
        let env = Environment { texture: Arc::new(Texture::new(4, 4, texels)), intensity: 2.0 };
        let at = |d: Vec3| env.radiance(d).x / 2.0;
        // The horizon is v = 0.5, texel row 1.5: rows 1 and 2 equally.
        // -z: u = 0.5, column 1.5 -> (11 + 12 + 21 + 22) / 4.
        assert_eq!(at(-Vec3::Z), 16.5);
        // +x: u = 0.75, column 2.5 -> (12 + 13 + 22 + 23) / 4.
        assert_eq!(at(Vec3::X), 17.5);
        // -x: u = 0.25, column 0.5 -> (10 + 11 + 20 + 21) / 4.
        assert_eq!(at(-Vec3::X), 15.5);
        // +z: u = 1, column 3.5 -> columns 3 and 0 (around the seam).
        assert_eq!(at(Vec3::Z), 16.5);
        // Straight up and down: the top and bottom rows, clamped.
        assert_eq!(at(Vec3::Y), 100.0);
        assert_eq!(at(-Vec3::Y), 200.0);
        assert_eq!(latlong_uv(Vec3::X), Vec2::new(0.75, 0.5));
    }
}
