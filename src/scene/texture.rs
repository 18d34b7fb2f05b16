//! Textures: image files decoded into linear RGB, sampled bilinearly.

use super::assets::read_asset;
use crate::input::{decode_image, InputKind, MAX_VALUE};
use crate::math::{Vec2, Vec3};
use std::path::Path;

/// A linear-RGB texture, sampled bilinearly with wrapping.
#[derive(Debug, PartialEq)]
pub struct Texture {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
}

impl Texture {
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        let (w, h) = (self.width as i64, self.height as i64);
        // v = 0 is the bottom row of the image (OBJ convention).
        let x = uv.x * w as f32 - 0.5;
        let y = (1.0 - uv.y) * h as f32 - 0.5;
        if !(x.is_finite() && y.is_finite()) {
            return Vec3::ZERO;
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let texel = |xi: i64, yi: i64| self.texels[(xi.rem_euclid(w) + yi.rem_euclid(h) * w) as usize];
        let (xi, yi) = (x0 as i64, y0 as i64);
        let top = texel(xi, yi).lerp(texel(xi + 1, yi), fx);
        let bottom = texel(xi, yi + 1).lerp(texel(xi + 1, yi + 1), fx);
        top.lerp(bottom, fy)
    }
}

/// Loads an 8-bit sRGB image (or a float EXR) into a linear texture. A float
/// texel that is NaN, infinite, negative or above `MAX_VALUE` is an error
/// naming the texel: such a value would reach pixels through every sample.
pub fn load_texture(path: &Path) -> Result<Texture, String> {
    let bytes = read_asset(path, InputKind::Image).map_err(|e| format!("cannot read {e}"))?;
    let img = decode_image(&bytes, &path.display().to_string())?;
    drop(bytes);
    let is_float = matches!(img, image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_));
    let rgb = img.into_rgb32f();
    let mut texels = Vec::with_capacity(rgb.width() as usize * rgb.height() as usize);
    for (x, y, p) in rgb.enumerate_pixels() {
        let c = Vec3::new(p[0], p[1], p[2]);
        if is_float {
            if let Some(bad) = c.to_array().into_iter().find(|v| !(v.is_finite() && (0.0..=MAX_VALUE).contains(v))) {
                return Err(format!(
                    "{}: texel ({x}, {y}) is {bad}; texels must be finite numbers from 0 to {MAX_VALUE:e}",
                    path.display()
                ));
            }
            texels.push(c);
        } else {
            texels.push(Vec3::new(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z)));
        }
    }
    Ok(Texture { width: rgb.width(), height: rgb.height(), texels })
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}
