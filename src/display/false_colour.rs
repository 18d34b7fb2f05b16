//! False colour: each pixel's luminance on a log2 scale (stops) through the
//! viridis colour map, so equal ratios of brightness look equally far apart
//! and the map stays readable by luminance alone. The scale spans
//! `MIN_STOP` to `MAX_STOP` stops of linear luminance (stop 0 = luminance 1);
//! values outside take the end colours, black and non-finite pixels the
//! bottom one.

use crate::math::{Radiance, Vec3};

/// The darkest stop the scale tells apart (luminance 2^-10).
pub const MIN_STOP: f32 = -10.0;
/// The brightest stop the scale tells apart (luminance 2^6).
pub const MAX_STOP: f32 = 6.0;

/// Viridis (matplotlib's perceptually uniform map) at nine evenly spaced
/// points, sRGB-encoded as the map is published; linearly interpolated
/// between them.
const VIRIDIS: [[u8; 3]; 9] = [
    [0x44, 0x01, 0x54],
    [0x47, 0x2c, 0x7a],
    [0x3b, 0x51, 0x8b],
    [0x2c, 0x71, 0x8e],
    [0x21, 0x90, 0x8d],
    [0x27, 0xad, 0x81],
    [0x5c, 0xc8, 0x63],
    [0xaa, 0xdc, 0x32],
    [0xfd, 0xe7, 0x25],
];

/// Rec. 709 luminance of a linear colour.
pub fn luminance(c: Radiance) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The stop of a linear colour: log2 of its luminance, `MIN_STOP` for black,
/// negative or non-finite values.
pub fn stop_of(c: Radiance) -> f32 {
    let l = luminance(c);
    if l.is_finite() && l > 0.0 { l.log2().clamp(MIN_STOP, MAX_STOP) } else { MIN_STOP }
}

/// The map's display colour (sRGB-encoded, in [0, 1]) at `t` in [0, 1].
pub fn viridis(t: f32) -> [f32; 3] {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * (VIRIDIS.len() - 1) as f32;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f32;
    [0, 1, 2].map(|k| (VIRIDIS[i][k] as f32 * (1.0 - f) + VIRIDIS[i + 1][k] as f32 * f) / 255.0)
}

/// The display colour (sRGB-encoded) of stop `s`.
pub fn stop_colour(s: f32) -> [f32; 3] {
    viridis((s - MIN_STOP) / (MAX_STOP - MIN_STOP))
}

/// One pixel's false colour, 8 bits, sRGB-encoded (no further curve).
pub fn false_colour_rgb8(c: Radiance) -> [u8; 3] {
    stop_colour(stop_of(c)).map(|v| (v * 255.0 + 0.5) as u8)
}

/// One pixel's false colour as a linear value whose sRGB encoding is the
/// map's colour: what a frame holds in the false-colour view, so the
/// default display (exposure 1, no tone map, sRGB) shows the map exactly.
pub fn false_colour_linear(c: Radiance) -> Radiance {
    let [r, g, b] = stop_colour(stop_of(c)).map(srgb_to_linear);
    Vec3::new(r, g, b)
}

/// The inverse of the sRGB curve.
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}

/// The legend: every whole stop of the scale with its 8-bit colour.
pub fn legend() -> Vec<(i32, [u8; 3])> {
    (MIN_STOP as i32..=MAX_STOP as i32).map(|s| (s, false_colour_rgb8(Vec3::splat((s as f32).exp2())))).collect()
}

/// A whole image in false colour, 8-bit RGB, row-major.
pub fn image_rgb8(pixels: &[Radiance]) -> Vec<u8> {
    crate::display::encode_rgb8(pixels, false_colour_rgb8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legend_stops_are_the_colours_pixels_of_those_stops_get() {
        // An image of grey pixels at each whole stop (luminance 2^s): read
        // back, each pixel's colour is the legend's colour for its stop, and
        // the colours differ from stop to stop (the map never repeats).
        let legend = legend();
        assert_eq!(legend.len(), 17);
        let pixels: Vec<Radiance> = legend.iter().map(|(s, _)| Vec3::splat((*s as f32).exp2())).collect();
        let rgb = image_rgb8(&pixels);
        for (i, (s, colour)) in legend.iter().enumerate() {
            assert_eq!(&rgb[i * 3..i * 3 + 3], colour, "stop {s}");
        }
        // The ends are viridis's published ends; stop -2 is the scale's middle
        // (8 of 16 stops): the 5th of the nine points, #21908d.
        assert_eq!(legend[0].1, [0x44, 0x01, 0x54]);
        assert_eq!(legend[16].1, [0xfd, 0xe7, 0x25]);
        assert_eq!(legend[8], (-2, [0x21, 0x90, 0x8d]));
        // A coloured pixel goes by its luminance: pure green of luminance
        // 0.7152 * 2^k sits at stop k + log2(0.7152).
        let g = stop_of(Vec3::new(0.0, 2.0 / 0.7152, 0.0));
        assert!((g - 1.0).abs() < 1e-5, "{g}");
    }

    #[test]
    fn brighter_is_always_further_along_the_map() {
        // Viridis rises in brightness along its length: the sum of the
        // colour's channels never falls from one sixteenth stop to the next.
        let mut last = -1.0;
        for i in 0..=(16 * 16) {
            let c = stop_colour(MIN_STOP + i as f32 / 16.0);
            let sum = c[0] * 0.2126 + c[1] * 0.7152 + c[2] * 0.0722;
            assert!(sum >= last, "falls at step {i}");
            last = sum;
        }
        assert_eq!(false_colour_rgb8(Vec3::new(f32::NAN, 0.0, 0.0)), false_colour_rgb8(Vec3::ZERO));
    }

    #[test]
    fn the_linear_form_displays_as_the_map() {
        // Through the default display transform, the linear value a frame
        // holds shows the legend's colour within one 8-bit step.
        for (s, colour) in legend() {
            let lin = false_colour_linear(Vec3::splat((s as f32).exp2()));
            let shown = crate::display::display_rgb8(lin, 1.0, crate::display::ToneMap::Standard, crate::display::Gamma::Srgb);
            for k in 0..3 {
                assert!((shown[k] as i32 - colour[k] as i32).abs() <= 1, "stop {s}: {shown:?} vs {colour:?}");
            }
        }
    }
}
