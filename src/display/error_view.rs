//! Error views: an image against its reference, pixel by pixel, as colours
//! with a legend whose numbers can be read back from the image.
//!
//! Every view compares Rec. 709 luminances, `d = L(a) - L(b)` for the image
//! `a` and the reference `b`:
//!
//! - **relative** (`--view error`): `|d| / max(L(b), RELATIVE_FLOOR)` on a
//!   log10 scale from `RELATIVE_MIN` to `RELATIVE_MAX` through viridis; the
//!   floor keeps a black reference pixel from dividing by zero;
//! - **absolute** (`--view absolute-error`): `|d|` on a linear scale from 0
//!   to the scale through viridis;
//! - **signed** (`--view signed-error`): `d` on a symmetric scale, red where
//!   the image is brighter than the reference, green where darker, black
//!   where equal; the colour's intensity is `|d| / scale`, sRGB-encoded.
//!
//! The absolute and signed views' scale is the largest `|d|` of the image
//! rounded up to 1, 2 or 5 times a power of ten, so no pixel clips; it is the
//! same whichever image is the reference, which makes the signed view of
//! (a, b) the signed view of (b, a) with red and green exchanged.
//!
//! Like the false-colour view, the mapped image holds linear values whose
//! sRGB encoding is the colour, so the default display shows the legend's
//! colours exactly (within one 8-bit step).

use crate::display::false_colour::{luminance, srgb_to_linear, viridis};
use crate::math::{Radiance, Vec3};

/// Which comparison an error view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    Relative,
    Absolute,
    Signed,
}

/// The relative view divides by the reference's luminance, but never by
/// less than this.
pub const RELATIVE_FLOOR: f32 = 1e-3;
/// The relative view's scale: from 0.1% (and below, the bottom colour) ...
pub const RELATIVE_MIN: f32 = 1e-3;
/// ... to 1000% (and above, the top colour).
pub const RELATIVE_MAX: f32 = 10.0;

/// The scale the absolute and signed views take when the images are equal
/// (every pixel then shows the zero colour whatever the scale).
const EQUAL_SCALE: f32 = 1e-6;

/// One error view fitted to a pair of images: its kind and its scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorMap {
    pub kind: ErrorKind,
    /// Absolute and signed: the error shown at full intensity (and, signed,
    /// its negative at full green). Relative: `RELATIVE_MAX`.
    pub scale: f32,
}

/// The signed luminance difference of a pixel and its reference; 0 where
/// either is not finite (such a pair says nothing about the error).
pub fn signed_difference(a: Radiance, b: Radiance) -> f32 {
    let d = luminance(a) - luminance(b);
    if d.is_finite() { d } else { 0.0 }
}

/// The number `kind` shows for a pixel `a` against its reference `b`.
pub fn error_value(kind: ErrorKind, a: Radiance, b: Radiance) -> f32 {
    let d = signed_difference(a, b);
    match kind {
        ErrorKind::Signed => d,
        ErrorKind::Absolute => d.abs(),
        ErrorKind::Relative => {
            let lb = luminance(b);
            let lb = if lb.is_finite() { lb.max(RELATIVE_FLOOR) } else { RELATIVE_FLOOR };
            d.abs() / lb
        }
    }
}

/// The smallest of 1, 2 and 5 times a power of ten that is at least `x`.
pub fn nice_ceiling(x: f32) -> f32 {
    if !(x.is_finite() && x > 0.0) {
        return EQUAL_SCALE;
    }
    let power = 10f32.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0, 20.0].into_iter().map(|m| m * power).find(|&v| v >= x).unwrap_or(20.0 * power)
}

impl ErrorMap {
    /// The map of `kind` for `mine` against `reference` (the same length).
    pub fn fit(kind: ErrorKind, mine: &[Radiance], reference: &[Radiance]) -> ErrorMap {
        let scale = match kind {
            ErrorKind::Relative => RELATIVE_MAX,
            ErrorKind::Absolute | ErrorKind::Signed => {
                let largest = mine.iter().zip(reference).map(|(&a, &b)| signed_difference(a, b).abs()).fold(0.0f32, f32::max);
                nice_ceiling(largest).max(EQUAL_SCALE)
            }
        };
        ErrorMap { kind, scale }
    }

    /// The display colour (sRGB-encoded, in [0, 1]) of an error `value`.
    pub fn colour(&self, value: f32) -> [f32; 3] {
        let value = if value.is_finite() { value } else { 0.0 };
        match self.kind {
            ErrorKind::Relative => {
                let t = if value > 0.0 { (value / RELATIVE_MIN).log10() / (RELATIVE_MAX / RELATIVE_MIN).log10() } else { 0.0 };
                viridis(t)
            }
            ErrorKind::Absolute => viridis(value / self.scale),
            ErrorKind::Signed => {
                let t = (value.abs() / self.scale).clamp(0.0, 1.0);
                if value > 0.0 { [t, 0.0, 0.0] } else { [0.0, t, 0.0] }
            }
        }
    }

    /// The colour of `value` as 8 bits per channel.
    pub fn colour_rgb8(&self, value: f32) -> [u8; 3] {
        self.colour(value).map(|v| (v * 255.0 + 0.5) as u8)
    }

    /// A pixel `a` against `b` as the linear value the mapped image holds.
    pub fn linear(&self, a: Radiance, b: Radiance) -> Radiance {
        let [r, g, bl] = self.colour(error_value(self.kind, a, b)).map(srgb_to_linear);
        Vec3::new(r, g, bl)
    }

    /// The legend: the values at its ticks with their 8-bit colours, from
    /// the bottom of the scale to its top.
    pub fn legend(&self) -> Vec<(f32, [u8; 3])> {
        let values: Vec<f32> = match self.kind {
            ErrorKind::Relative => vec![RELATIVE_MIN, 1e-2, 1e-1, 1.0, RELATIVE_MAX],
            ErrorKind::Absolute => (0..=4).map(|k| self.scale * k as f32 / 4.0).collect(),
            ErrorKind::Signed => (-4..=4).map(|k| self.scale * k as f32 / 4.0).collect(),
        };
        values.into_iter().map(|v| (v, self.colour_rgb8(v))).collect()
    }

    /// Where on the legend's bar (0 = its left end, 1 = its right end) a
    /// value sits.
    pub fn position(&self, value: f32) -> f32 {
        match self.kind {
            ErrorKind::Relative => ((value.max(RELATIVE_MIN) / RELATIVE_MIN).log10() / (RELATIVE_MAX / RELATIVE_MIN).log10()).clamp(0.0, 1.0),
            ErrorKind::Absolute => (value / self.scale).clamp(0.0, 1.0),
            ErrorKind::Signed => (0.5 + 0.5 * value / self.scale).clamp(0.0, 1.0),
        }
    }

    /// The value at `t` along the legend's bar (the inverse of `position`).
    pub fn value_at(&self, t: f32) -> f32 {
        match self.kind {
            ErrorKind::Relative => RELATIVE_MIN * (RELATIVE_MAX / RELATIVE_MIN).powf(t),
            ErrorKind::Absolute => self.scale * t,
            ErrorKind::Signed => self.scale * (2.0 * t - 1.0),
        }
    }
}

/// `mine` against `reference` (the same size) in the view `kind`: the mapped
/// image, as linear values, and the map with its scale.
pub fn error_image(kind: ErrorKind, mine: &[Radiance], reference: &[Radiance]) -> (Vec<Radiance>, ErrorMap) {
    let map = ErrorMap::fit(kind, mine, reference);
    (mine.iter().zip(reference).map(|(&a, &b)| map.linear(a, b)).collect(), map)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(l: f32) -> Radiance {
        Vec3::splat(l)
    }

    /// Pixels whose differences sit exactly at the legend's tick values map
    /// to the legend's colours for those values (the legend reads the image).
    #[test]
    fn legend_colours_are_what_pixels_of_those_values_show() {
        let reference = vec![grey(0.5); 9];
        let signed_values = [-0.4f32, -0.3, -0.2, -0.1, 0.0, 0.1, 0.2, 0.3, 0.4];
        let mine: Vec<Radiance> = signed_values.iter().map(|d| grey(0.5 + d)).collect();
        for kind in [ErrorKind::Signed, ErrorKind::Absolute] {
            let (image, map) = error_image(kind, &mine, &reference);
            // The largest difference, 0.4 (give or take rounding), rounds up to 0.5.
            assert_eq!(map.scale, 0.5, "{kind:?}");
            for (pixel, (&a, &b)) in image.iter().zip(mine.iter().zip(&reference)) {
                let value = error_value(kind, a, b);
                let shown = crate::display::display_rgb8(*pixel, 1.0, crate::display::ToneMap::Standard, crate::display::Gamma::Srgb);
                let want = map.colour_rgb8(value);
                for k in 0..3 {
                    assert!((shown[k] as i32 - want[k] as i32).abs() <= 1, "{kind:?} {value}: {shown:?} vs {want:?}");
                }
            }
            // The legend's ticks are colours of their values, and a tick at
            // a pixel's value shows the pixel's colour.
            for (v, colour) in map.legend() {
                assert_eq!(colour, map.colour_rgb8(v));
                assert!((map.value_at(map.position(v)) - v).abs() < 1e-5, "{v}");
            }
        }
        let map = ErrorMap::fit(ErrorKind::Signed, &mine, &reference);
        let legend = map.legend();
        assert_eq!(legend.first().unwrap(), &(-0.5, [0, 255, 0]));
        assert_eq!(legend[4], (0.0, [0, 0, 0]));
        assert_eq!(legend.last().unwrap(), &(0.5, [255, 0, 0]));
        // A quarter of the scale shows a quarter of full red, read back by
        // dividing the channel by 255 and multiplying by the scale.
        assert_eq!(map.colour_rgb8(0.125), [64, 0, 0]);
    }

    #[test]
    fn signed_error_is_antisymmetric() {
        let a: Vec<Radiance> = (0..50).map(|i| Vec3::new(i as f32 * 0.03, 0.2, (i % 7) as f32 * 0.1)).collect();
        let b: Vec<Radiance> = (0..50).map(|i| Vec3::new(0.7, (i % 5) as f32 * 0.2, 0.1)).collect();
        let (ab, m_ab) = error_image(ErrorKind::Signed, &a, &b);
        let (ba, m_ba) = error_image(ErrorKind::Signed, &b, &a);
        assert_eq!(m_ab, m_ba);
        for (p, q) in ab.iter().zip(&ba) {
            assert_eq!((p.x, p.y, p.z), (q.y, q.x, q.z));
        }
        assert!(ab.iter().any(|p| p.x > 0.0) && ab.iter().any(|p| p.y > 0.0));
    }

    #[test]
    fn relative_error_divides_by_the_reference() {
        let map = ErrorMap::fit(ErrorKind::Relative, &[], &[]);
        assert!((error_value(ErrorKind::Relative, grey(1.1), grey(1.0)) - 0.1).abs() < 1e-5);
        assert!((error_value(ErrorKind::Relative, grey(0.9), grey(1.0)) - 0.1).abs() < 1e-5);
        // A black reference divides by the floor, not by zero.
        assert!((error_value(ErrorKind::Relative, grey(0.01), grey(0.0)) - 0.01 / RELATIVE_FLOOR).abs() < 1e-3);
        // The scale's decades: 0.1% at the bottom, 1000% at the top.
        assert_eq!(map.colour_rgb8(RELATIVE_MIN), map.colour_rgb8(0.0));
        assert_eq!(map.colour_rgb8(RELATIVE_MAX * 3.0), [0xfd, 0xe7, 0x25]);
        assert_eq!(map.legend().iter().map(|(v, _)| *v).collect::<Vec<_>>(), vec![1e-3, 1e-2, 1e-1, 1.0, 10.0]);
    }

    #[test]
    fn scales_round_up_to_one_two_five() {
        assert_eq!(nice_ceiling(0.37), 0.5);
        assert_eq!(nice_ceiling(1.5), 2.0);
        assert_eq!(nice_ceiling(7.0), 10.0);
        assert_eq!(nice_ceiling(0.0), EQUAL_SCALE);
        assert_eq!(nice_ceiling(f32::NAN), EQUAL_SCALE);
        for x in [1e-5f32, 0.003, 0.1, 0.99, 3.3, 1234.0] {
            assert!(nice_ceiling(x) >= x && nice_ceiling(x) <= 5.0 * x, "{x}");
        }
    }
}
