//! Tone maps: from linear radiance (already scaled by the exposure) in
//! [0, inf) to linear display values in [0, 1]. Each is a published curve,
//! implemented from its formulas:
//!
//! - `standard`: no curve, values above 1 clip (Blender's "Standard");
//! - `reinhard`: `x / (1 + x)` per channel (Reinhard et al. 2002, eq. 3);
//! - `aces`: Stephen Hill's fit of the ACES reference rendering transform and
//!   output transform: a 3x3 matrix into the fit's working space, a rational
//!   curve, a matrix back;
//! - `agx`: the AgX base transform of Blender 4 (Eary Chow's version): linear
//!   sRGB through the combined Rec.2020 + inset matrix, log2 encoding over
//!   16.5 stops around mid grey, the two-sided power sigmoid with its pivot at
//!   mid grey, the 2.4 power back to linear, the outset + Rec.2020-to-sRGB
//!   matrix;
//! - `khronos-neutral`: Khronos PBR Neutral: a small offset that darkens the
//!   toe, identity below a peak of 0.76, then highlight compression towards
//!   1 with desaturation.

use crate::named::named_enum;

named_enum! {
    /// A display tone map.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum ToneMap ("tone map") {
        /// Clip at 1: what the display did before tone maps existed.
        #[default]
        Standard = "standard",
        /// `x / (1 + x)` per channel.
        Reinhard = "reinhard",
        /// The ACES fitted curve (RRT + ODT fit, with its matrices).
        Aces = "aces",
        /// AgX as Blender 4 ships it (base look).
        Agx = "agx",
        /// Khronos PBR Neutral.
        KhronosNeutral = "khronos-neutral",
    }
}

impl ToneMap {
    /// Maps a linear colour with non-negative finite channels to [0, 1]
    /// (callers clamp, the curves may overshoot by rounding).
    pub fn apply(self, c: [f32; 3]) -> [f32; 3] {
        match self {
            ToneMap::Standard => c.map(|v| v.min(1.0)),
            ToneMap::Reinhard => c.map(|v| v / (1.0 + v)),
            ToneMap::Aces => aces_fitted(c),
            ToneMap::Agx => agx(c),
            ToneMap::KhronosNeutral => khronos_neutral(c),
        }
    }
}

type Mat3 = [[f32; 3]; 3];

fn mul(m: &Mat3, c: [f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|r| m[r][0] * c[0] + m[r][1] * c[1] + m[r][2] * c[2])
}

/// Hill's ACES fit: sRGB -> the fit's space (rows), the RRT+ODT rational fit,
/// back to sRGB (rows), clamped.
fn aces_fitted(c: [f32; 3]) -> [f32; 3] {
    const INPUT: Mat3 = [[0.59719, 0.35458, 0.04823], [0.07600, 0.90834, 0.01566], [0.02840, 0.13383, 0.83777]];
    const OUTPUT: Mat3 = [[1.60475, -0.53108, -0.07367], [-0.10208, 1.10813, -0.00605], [-0.00327, -0.07276, 1.07602]];
    let rrt_odt = |v: f32| {
        let a = v * (v + 0.024_578_6) - 0.000_090_537;
        let b = v * (0.983_729 * v + 0.432_951) + 0.238_081;
        a / b
    };
    mul(&OUTPUT, mul(&INPUT, c).map(rrt_odt)).map(|v| v.clamp(0.0, 1.0))
}

/// Blender 4's AgX base transform (see the module comment).
fn agx(c: [f32; 3]) -> [f32; 3] {
    // Linear sRGB -> Rec.2020 -> AgX inset, as one matrix (rows).
    const INSET: Mat3 = [
        [0.544_908_14, 0.373_779_46, 0.081_384_98],
        [0.140_440_06, 0.754_109_6, 0.105_433_585],
        [0.088_827_41, 0.178_877_12, 0.732_25],
    ];
    // AgX outset (inverse) -> Rec.2020 -> linear sRGB, as one matrix (rows).
    const OUTSET: Mat3 = [
        [1.964_551, -0.855_858_45, -0.108_867_11],
        [-0.299_322_43, 1.326_451_1, -0.027_084_02],
        [-0.164_368_34, -0.238_224_64, 1.402_665_3],
    ];
    // log2 of mid grey 0.18 with 10 stops below and 6.5 above.
    const MIN_EV: f32 = -12.473_931;
    const MAX_EV: f32 = 4.026_069;
    // The sigmoid's pivot: mid grey on the log axis (10 / 16.5) and on the
    // display axis (0.18^(1/2.4)).
    const X_PIVOT: f32 = 10.0 / 16.5;
    const Y_PIVOT: f32 = 0.489_437_1;
    let sigmoid = |x: f32| {
        // Slopes (a) and offsets (b = -a * pivot) of the two halves; the
        // curve is y = y_pivot + 2.4 u / (1 + s |a x + b|^1.5)^(1/1.5).
        let (a, b) = if x < X_PIVOT { (-58.337_322, 35.355_953) } else { (46.141_05, -27.964_273) };
        let t = (a * x + b).abs().powf(1.5);
        Y_PIVOT + 2.4 * (x - X_PIVOT) / (1.0 + 0.019_613_087 * t).powf(1.0 / 1.5)
    };
    let inset = mul(&INSET, c.map(|v| v.max(2e-10)));
    let encoded = inset.map(|v| ((v.max(1e-10).log2() - MIN_EV) / (MAX_EV - MIN_EV)).clamp(0.0, 1.0));
    let display = encoded.map(|x| sigmoid(x).max(0.0).powf(2.4));
    mul(&OUTSET, display).map(|v| v.clamp(0.0, 1.0))
}

/// Khronos PBR Neutral (see the module comment).
fn khronos_neutral(c: [f32; 3]) -> [f32; 3] {
    const F90: f32 = 0.04;
    const START: f32 = 0.8 - F90;
    const DESATURATION: f32 = 0.15;
    let x = c[0].min(c[1]).min(c[2]);
    let offset = if x < 2.0 * F90 { x - x * x / (4.0 * F90) } else { F90 };
    let c = c.map(|v| v - offset);
    let peak = c[0].max(c[1]).max(c[2]);
    if peak < START {
        return c;
    }
    let d = 1.0 - START;
    let new_peak = 1.0 - d * d / (peak + d - START);
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.map(|v| v * new_peak / peak * (1.0 - g) + new_peak * g)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(t: ToneMap, v: f32) -> f32 {
        let o = t.apply([v; 3]);
        assert!((o[0] - o[1]).abs() < 2e-4 && (o[1] - o[2]).abs() < 2e-4, "{}: grey {v} stays grey: {o:?}", t.name());
        o[1]
    }

    fn close(a: f32, b: f32, tol: f32) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn standard_and_reinhard_by_hand() {
        assert_eq!(ToneMap::Standard.apply([0.25, 0.5, 3.0]), [0.25, 0.5, 1.0]);
        // 1 / (1 + 1) = 0.5, 3 / 4 = 0.75, 0 stays 0.
        assert_eq!(ToneMap::Reinhard.apply([1.0, 3.0, 0.0]), [0.5, 0.75, 0.0]);
    }

    #[test]
    fn aces_by_hand() {
        // The matrices' rows sum to 1, so grey stays grey and the fit alone
        // decides: at 1, (1.0245786 - 0.000090537) / (0.983729 + 0.432951 + 0.238081)
        // = 1.024488063 / 1.654761 = 0.619115.
        assert!(close(grey(ToneMap::Aces, 1.0), 0.619_115, 2e-4));
        // At 0.18: (0.18 * 0.2045786 - 0.000090537) / (0.18 * (0.983729 * 0.18 + 0.432951) + 0.238081)
        // = 0.105591.
        assert!(close(grey(ToneMap::Aces, 0.18), 0.105_591, 2e-4));
        // Black is black (the fit is slightly negative there and clamps).
        assert_eq!(grey(ToneMap::Aces, 0.0), 0.0);
    }

    #[test]
    fn agx_by_hand() {
        // Mid grey sits on the sigmoid's pivot: 0.18 -> log axis 10/16.5 ->
        // display 0.18^(1/2.4) -> 0.18 linear.
        assert!(close(grey(ToneMap::Agx, 0.18), 0.18, 2e-3));
        // Black reaches the bottom of the log range, where the curve is
        // y_pivot - 2.4 * pivot / (1 + s * 35.355953^1.5)^(2/3) = about 0;
        // 16.5 stops above it 1 is reached, and the output stays below 1.
        assert!(grey(ToneMap::Agx, 0.0) < 1e-3);
        let top = grey(ToneMap::Agx, 1e6);
        assert!(top > 0.95 && top <= 1.0, "{top}");
    }

    #[test]
    fn khronos_neutral_by_hand() {
        // 0.5: offset 0.04, peak 0.46 below 0.76: 0.46.
        assert!(close(grey(ToneMap::KhronosNeutral, 0.5), 0.46, 1e-6));
        // 0.05: offset 0.05 - 0.05^2 / 0.16 = 0.034375 -> 0.015625.
        assert!(close(grey(ToneMap::KhronosNeutral, 0.05), 0.015_625, 1e-6));
        // 2: peak 1.96, new peak 1 - 0.24^2 / (1.96 + 0.24 - 0.76) = 0.96;
        // grey stays at the new peak whatever the desaturation.
        assert!(close(grey(ToneMap::KhronosNeutral, 2.0), 0.96, 1e-5));
        // A colour: (3, 1, 0.5): offset 0.04, peak 2.96, new peak
        // 1 - 0.0576 / 2.44 = 0.976393, g = 1 - 1 / (0.15 * 1.983607 + 1) = 0.229311;
        // red = 2.96 * 0.976393 / 2.96 * (1 - g) + 0.976393 * g = 0.976393,
        // green = 0.96 * 0.329862 * 0.770689 + 0.223898 = 0.467951.
        let o = ToneMap::KhronosNeutral.apply([3.0, 1.0, 0.5]);
        assert!(close(o[0], 0.976_393, 1e-5) && close(o[1], 0.467_951, 1e-4), "{o:?}");
    }

    #[test]
    fn every_tone_map_is_monotonic_and_bounded() {
        for t in ToneMap::ALL {
            let mut last = -1.0f32;
            // Grey from 2^-14 to 2^12 in sixteenth stops.
            for i in 0..=(26 * 16) {
                let v = (i as f32 / 16.0 - 14.0).exp2();
                let o = grey(t, v);
                assert!((0.0..=1.0).contains(&o), "{} at {v}: {o}", t.name());
                assert!(o >= last, "{} falls at {v}: {last} -> {o}", t.name());
                last = o;
            }
            // And per channel: raising one channel never lowers it.
            for base in [[0.1, 0.4, 0.02], [2.0, 0.5, 1.0]] {
                let mut last = -1.0f32;
                for i in 0..200 {
                    let o = t.apply([base[0] * (1.0 + i as f32 * 0.05), base[1], base[2]]);
                    assert!(o[0] >= last - 1e-6, "{} red falls at step {i}", t.name());
                    last = o[0];
                }
            }
        }
    }
}
