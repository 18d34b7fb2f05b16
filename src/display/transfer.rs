//! The display's transfer curve: how a value in [0, 1] after the tone map is
//! encoded for an 8-bit image.

use crate::named::named_enum;

named_enum! {
    /// The transfer curve of the display.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum Gamma ("gamma") {
        /// The sRGB curve (IEC 61966-2-1): linear near black, a 1/2.4 power above.
        #[default]
        Srgb = "srgb",
        /// A pure power of 1/2.2.
        Power22 = "2.2",
        /// No curve: linear values quantized as they are.
        Off = "off",
    }
}

impl Gamma {
    /// Encodes a linear value in [0, 1].
    pub fn encode(self, v: f32) -> f32 {
        match self {
            Gamma::Srgb => srgb(v),
            Gamma::Power22 => v.max(0.0).powf(1.0 / 2.2),
            Gamma::Off => v,
        }
    }
}

/// The sRGB transfer function of a linear value in [0, 1].
pub fn srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curves_map_known_values() {
        // sRGB: the linear segment, the 1/2.4 power above it, both ends fixed.
        assert_eq!(Gamma::Srgb.encode(0.0), 0.0);
        assert!((Gamma::Srgb.encode(0.002) - 0.02584).abs() < 1e-6);
        assert!((Gamma::Srgb.encode(0.5) - 0.735_357).abs() < 1e-5);
        assert!((Gamma::Srgb.encode(1.0) - 1.0).abs() < 1e-6);
        // 0.5^(1/2.2) = 0.72974.
        assert!((Gamma::Power22.encode(0.5) - 0.729_740).abs() < 1e-5);
        assert_eq!(Gamma::Power22.encode(1.0), 1.0);
        assert_eq!(Gamma::Off.encode(0.3), 0.3);
    }

    #[test]
    fn curves_are_monotonic() {
        for g in Gamma::ALL {
            let mut last = -1.0;
            for i in 0..=1000 {
                let v = g.encode(i as f32 / 1000.0);
                assert!(v > last, "{} at {i}", g.name());
                last = v;
            }
        }
    }
}
