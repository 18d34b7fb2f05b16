//! The display transform: how linear radiance becomes the colour a screen or
//! a PNG shows. Three steps, in this order, each a pure function:
//!
//! 1. a linear scale: the scene's `[render] exposure` times `2^EV` of the
//!    front end's exposure in stops (`--exposure EV`, the viewer's slider);
//! 2. a tone map (`tonemap`): `standard` (clip), `reinhard`, `aces`, `agx`,
//!    `khronos-neutral`, each from [0, inf) into [0, 1];
//! 3. a transfer curve (`transfer`): the sRGB curve, a pure 2.2 power, or none.
//!
//! Only the viewer and 8-bit outputs (PNG, PPM) go through it. The data stays
//! linear: EXR files, metrics, charts and replays never see a tone map.
//! This module reads nothing but `math`; `image_io`, `render` and the viewer
//! call it.

pub mod error_view;
pub mod false_colour;
pub mod histogram;
pub mod tonemap;
pub mod transfer;

use crate::math::Radiance;

pub use tonemap::ToneMap;
pub use transfer::Gamma;

/// The front end's display choices, a part of `RenderSettings`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct DisplaySettings {
    /// Exposure in stops: the display scale is multiplied by `2^exposure_ev`.
    pub exposure_ev: f32,
    pub tonemap: ToneMap,
    pub gamma: Gamma,
}

impl Default for DisplaySettings {
    fn default() -> Self {
        DisplaySettings { exposure_ev: 0.0, tonemap: ToneMap::Standard, gamma: Gamma::Srgb }
    }
}

/// The most stops of exposure either way a front end accepts.
pub const MAX_EXPOSURE_EV: f32 = 64.0;

impl DisplaySettings {
    /// The linear factor applied before the tone map: the scene's exposure
    /// (a plain scale, `[render] exposure`) times `2^EV`.
    pub fn scale(&self, scene_exposure: f32) -> f32 {
        scene_exposure * self.exposure_ev.exp2()
    }

    /// Checks the exposure: one sentence when it is not a finite number of
    /// stops within +-`MAX_EXPOSURE_EV`.
    pub fn check(&self) -> Result<(), String> {
        if self.exposure_ev.is_finite() && self.exposure_ev.abs() <= MAX_EXPOSURE_EV {
            Ok(())
        } else {
            Err(format!("{} is not a number of stops from -{MAX_EXPOSURE_EV} to {MAX_EXPOSURE_EV}", self.exposure_ev))
        }
    }
}

/// One pixel through the whole transform, as values in [0, 1] ready to be
/// quantized. A non-finite or negative channel counts as 0 (NaN never
/// reaches a pixel).
pub fn display_rgb(c: Radiance, scale: f32, tonemap: ToneMap, gamma: Gamma) -> [f32; 3] {
    // A finite value scaled past f32's range is the brightest finite value,
    // so every curve sees a number (and clip maps it to 1).
    let clean = |v: f32| if v.is_finite() { (v * scale).clamp(0.0, f32::MAX) } else { 0.0 };
    let mapped = tonemap.apply([clean(c.x), clean(c.y), clean(c.z)]);
    mapped.map(|v| gamma.encode(if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 }))
}

/// One pixel as 8 bits per channel.
pub fn display_rgb8(c: Radiance, scale: f32, tonemap: ToneMap, gamma: Gamma) -> [u8; 3] {
    display_rgb(c, scale, tonemap, gamma).map(|v| (v * 255.0 + 0.5) as u8)
}

/// A whole image as 8-bit RGB, row-major; rows of pixels in parallel (the
/// viewer encodes every frame it shows).
pub fn image_rgb8(pixels: &[Radiance], scale: f32, tonemap: ToneMap, gamma: Gamma) -> Vec<u8> {
    encode_rgb8(pixels, |c| display_rgb8(c, scale, tonemap, gamma))
}

/// `encode` of every pixel into 8-bit RGB, in parallel chunks, into one
/// buffer (no per-pixel allocation or iterator chain).
pub fn encode_rgb8(pixels: &[Radiance], encode: impl Fn(Radiance) -> [u8; 3] + Sync) -> Vec<u8> {
    use rayon::prelude::*;
    const CHUNK: usize = 4096;
    let mut out = vec![0u8; pixels.len() * 3];
    out.par_chunks_mut(CHUNK * 3).zip(pixels.par_chunks(CHUNK)).for_each(|(out, pixels)| {
        for (o, &c) in out.chunks_exact_mut(3).zip(pixels) {
            o.copy_from_slice(&encode(c));
        }
    });
    out
}
