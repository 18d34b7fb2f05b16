//! What a rasterizer's depth buffer stores per sample (`--depth-buffer`),
//! and how two stored values compare.
//!
//! Every format is turned into one key where smaller means nearer, so the
//! depth test stays one strict `<` (a tie keeps the fragment already there,
//! the LESS test of a GPU: this is where z-fighting comes from when two
//! surfaces quantize to the same value).
//!
//! - `f32`: -1/z as an f32, the key the rasterizers always used. CGFS
//!   (ch. 12) stores 1/z rather than z: 1/z is affine in image space, so it
//!   can be interpolated linearly across a triangle (z cannot), and it
//!   spends its precision near the eye, where surfaces are large on screen.
//! - `unorm24`, `unorm16`: what a GPU's fixed-point buffer stores,
//!   d = f (z - n) / (z (f - n)) in [0, 1] (0 on the near plane, 1 on the
//!   far plane), rounded to 2^24 - 1 or 2^16 - 1 steps. d is 1/z rescaled,
//!   so its steps are packed near the near plane: a small `near` leaves few
//!   steps for distant surfaces.
//! - `reversed`: reversed-z, d' = 1 - d = n (f / z - 1) / (f - n), stored as
//!   an f32 and compared GREATER (nearer is larger). Floats are densest near
//!   0, which d' reaches at the far plane, so float precision and the 1/z
//!   crowding cancel out and distant surfaces keep their separation. The key
//!   is -d', so the shared `<` test is the GREATER test on d'.
//!
//! - `linear-z`: view depth z interpolated linearly in image space (as
//!   the key -1/z), the mistake the f32 format avoids: z along a receding
//!   triangle is not affine in image space, the straight line between its
//!   corners' z lies beyond the surface, so a large receding triangle reads
//!   as farther than it is and what lies just behind it shows through.
//!   Wrong on purpose, for the lesson; spheres keep their exact ray depth.
//!
//! Through an orthographic camera every eye ray is parallel, and the view
//! depth z itself is affine in image space: the buffer then interpolates z,
//! `f32` stores it as it is, and the fixed-point formats store what a GPU's
//! orthographic projection gives, d = (z - n) / (f - n), whose steps are
//! spread evenly from the near plane to the far one (reversed: 1 - d).
//!
//! Only the variants with 2D weights (barycentric, incremental, scanline,
//! fixed, tiled) store depth keys; naive and bbox compare exact ray
//! parameters as the ray casters do, the painter keeps no depth buffer,
//! and the ray casters have none: they all ignore the format.

use crate::named::named_enum;

named_enum! {
    /// The depth buffer's storage format.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum DepthFormat ("depth buffer") {
        /// -1/z as f32 (the default).
        #[default]
        F32 = "f32",
        /// Fixed-point z/w with 24 bits.
        Unorm24 = "unorm24",
        /// Fixed-point z/w with 16 bits.
        Unorm16 = "unorm16",
        /// Reversed z (1 - z/w) as f32, compared GREATER.
        Reversed = "reversed",
        /// View z interpolated linearly in image space (wrong on purpose).
        LinearZ = "linear-z",
    }
}

/// The format with the camera's near and far distances and projection:
/// turns the depth value a rasterizer interpolates (1/z, or z through an
/// orthographic camera: `ScreenTri::affine_depth`) into the key the buffer
/// stores and back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthEncoding {
    pub format: DepthFormat,
    pub near: f32,
    pub far: f32,
    /// Parallel eye rays: the interpolated value is the view depth itself.
    pub orthographic: bool,
}

impl DepthFormat {
    /// What the format is, for `pinhole list`.
    pub fn description(self) -> &'static str {
        match self {
            DepthFormat::F32 => "-1/z as f32 (CGFS stores 1/z), compared LESS",
            DepthFormat::Unorm24 => "GPU z/w in [0,1] with 2^24-1 steps, compared LESS",
            DepthFormat::Unorm16 => "GPU z/w in [0,1] with 2^16-1 steps, compared LESS: z-fights first",
            DepthFormat::Reversed => "reversed z (1 - z/w) as f32, compared GREATER",
            DepthFormat::LinearZ => "z interpolated linearly in image space (wrong on purpose: why 1/z is stored)",
        }
    }

    /// Steps of a fixed-point format (`None` for the float ones).
    pub fn steps(self) -> Option<f64> {
        match self {
            DepthFormat::Unorm24 => Some(((1u32 << 24) - 1) as f64),
            DepthFormat::Unorm16 => Some(((1u32 << 16) - 1) as f64),
            DepthFormat::F32 | DepthFormat::Reversed | DepthFormat::LinearZ => None,
        }
    }
}

impl DepthEncoding {
    /// The encoding for a camera seen through a perspective projection.
    pub fn new(format: DepthFormat, near: f32, far: f32) -> DepthEncoding {
        DepthEncoding { format, near, far, orthographic: false }
    }

    /// The encoding for `view`'s near and far planes and projection.
    pub fn for_view(format: DepthFormat, view: &crate::scene::CameraView) -> DepthEncoding {
        DepthEncoding { format, near: view.near, far: view.far, orthographic: view.is_orthographic() }
    }

    /// The key stored for a fragment whose interpolated depth value is
    /// `value`: 1 / view depth, or the view depth itself when
    /// `orthographic`. Smaller is nearer.
    #[inline(always)]
    pub fn key(&self, value: f32) -> f32 {
        match self.format {
            DepthFormat::F32 | DepthFormat::LinearZ if !self.orthographic => -value,
            _ => self.key_slow(value),
        }
    }

    /// The key stored for a fragment at view depth `z` (a ray test's hit).
    #[inline]
    pub fn key_at_depth(&self, z: f32) -> f32 {
        if self.orthographic {
            self.key(z)
        } else {
            self.key(1.0 / z)
        }
    }

    #[inline(never)]
    fn key_slow(&self, value: f32) -> f32 {
        if self.orthographic {
            return self.linear_key(value);
        }
        let (n, f) = (self.near as f64, self.far as f64);
        let inv_z = value as f64;
        match self.format {
            DepthFormat::F32 | DepthFormat::LinearZ => -inv_z as f32,
            DepthFormat::Reversed => -((n * (f * inv_z - 1.0) / (f - n)) as f32),
            DepthFormat::Unorm24 | DepthFormat::Unorm16 => {
                let steps = self.format.steps().unwrap_or(1.0);
                // d = f (z - n) / (z (f - n)) = f (1 - n / z) / (f - n), clamped
                // to [0, 1] as a GPU clamps, then rounded to the nearest step.
                let d = (f * (1.0 - n * inv_z) / (f - n)).clamp(0.0, 1.0);
                (d * steps).round() as f32
            }
        }
    }

    /// The key of view depth `z` through an orthographic camera: z itself,
    /// or d = (z - n) / (f - n) as the fixed-point and reversed formats
    /// store it.
    fn linear_key(&self, z: f32) -> f32 {
        let (n, f) = (self.near as f64, self.far as f64);
        let d = (z as f64 - n) / (f - n);
        match self.format {
            DepthFormat::F32 | DepthFormat::LinearZ => z,
            DepthFormat::Reversed => -((1.0 - d) as f32),
            DepthFormat::Unorm24 | DepthFormat::Unorm16 => {
                let steps = self.format.steps().unwrap_or(1.0);
                (d.clamp(0.0, 1.0) * steps).round() as f32
            }
        }
    }

    /// The key a buffer is cleared to: that of the far plane (the f32
    /// format's -1/far exactly as the rasterizers always cleared it).
    #[inline]
    pub fn clear_key(&self) -> f32 {
        if self.orthographic {
            return self.linear_key(self.far);
        }
        match self.format {
            DepthFormat::F32 | DepthFormat::LinearZ => -1.0 / self.far,
            DepthFormat::Reversed => 0.0,
            DepthFormat::Unorm24 | DepthFormat::Unorm16 => self.format.steps().unwrap_or(1.0) as f32,
        }
    }

    /// The view depth a key stands for (for the fragment record).
    pub fn view_depth(&self, key: f32) -> f32 {
        let (n, f) = (self.near as f64, self.far as f64);
        if self.orthographic {
            let d = match self.format {
                DepthFormat::F32 | DepthFormat::LinearZ => return key,
                DepthFormat::Reversed => 1.0 + key as f64,
                DepthFormat::Unorm24 | DepthFormat::Unorm16 => key as f64 / self.format.steps().unwrap_or(1.0),
            };
            return (n + d * (f - n)) as f32;
        }
        let inv_z = match self.format {
            DepthFormat::F32 | DepthFormat::LinearZ => return -1.0 / key,
            DepthFormat::Reversed => (-key as f64 * (f - n) / n + 1.0) / f,
            DepthFormat::Unorm24 | DepthFormat::Unorm16 => {
                let d = key as f64 / self.format.steps().unwrap_or(1.0);
                (1.0 - d * (f - n) / f) / n
            }
        };
        (1.0 / inv_z) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_is_the_old_key_bit_for_bit() {
        let e = DepthEncoding::new(DepthFormat::F32, 0.1, 100.0);
        for z in [0.1f32, 0.37, 1.0, 2.5, 99.0] {
            assert_eq!(e.key(1.0 / z).to_bits(), (-(1.0 / z)).to_bits());
        }
        assert_eq!(e.clear_key().to_bits(), (-1.0f32 / 100.0).to_bits());
    }

    #[test]
    fn unorm_by_hand() {
        // n = 1, f = 3: d = 3 (z - 1) / (2 z); z = 1 -> 0, z = 3 -> 1, z = 2 -> 0.75.
        let e = DepthEncoding::new(DepthFormat::Unorm16, 1.0, 3.0);
        assert_eq!(e.key(1.0), 0.0);
        assert_eq!(e.key(1.0 / 3.0), 65535.0);
        assert_eq!(e.clear_key(), 65535.0);
        assert_eq!(e.key(0.5), 49151.0); // 0.75 * 65535 = 49151.25
        assert!((e.view_depth(49151.0) - 2.0).abs() < 1e-3);
        let e24 = DepthEncoding::new(DepthFormat::Unorm24, 1.0, 3.0);
        assert_eq!(e24.key(0.5), 12582911.0); // 0.75 * (2^24 - 1) = 12582911.25
        // Nearer than near clamps to 0, beyond far to the maximum.
        assert_eq!(e.key(2.0), 0.0);
        assert_eq!(e.key(0.1), 65535.0);
    }

    #[test]
    fn unorm16_merges_distant_surfaces_that_f32_and_reversed_separate() {
        // near 0.01, far 1000: two surfaces 0.1 apart at depth 50.
        let (a, b) = (1.0 / 50.0f32, 1.0 / 50.1f32);
        for (format, separated) in [(DepthFormat::F32, true), (DepthFormat::Reversed, true), (DepthFormat::Unorm24, true), (DepthFormat::Unorm16, false)] {
            let e = DepthEncoding::new(format, 0.01, 1000.0);
            assert_eq!(e.key(a) < e.key(b), separated, "{format:?}");
            assert!(e.key(a) <= e.key(b), "{format:?}: nearer never compares farther");
        }
    }

    #[test]
    fn orthographic_keys_are_linear_in_depth() {
        // n = 1, f = 3: d = (z - 1) / 2; z = 2 -> 0.5, evenly spaced steps.
        let mut e = DepthEncoding::new(DepthFormat::Unorm16, 1.0, 3.0);
        e.orthographic = true;
        assert_eq!(e.key(1.0), 0.0);
        assert_eq!(e.key(2.0), 32768.0); // 0.5 * 65535 = 32767.5
        assert_eq!(e.clear_key(), 65535.0);
        assert!((e.view_depth(32768.0) - 2.0).abs() < 1e-4);
        e.format = DepthFormat::Reversed;
        assert_eq!(e.key(2.0), -0.5);
        assert_eq!(e.clear_key(), 0.0);
        assert!((e.view_depth(-0.5) - 2.0).abs() < 1e-6);
        e.format = DepthFormat::F32;
        assert_eq!((e.key(2.5), e.key_at_depth(2.5), e.clear_key(), e.view_depth(2.5)), (2.5, 2.5, 3.0, 2.5));
        for format in [DepthFormat::F32, DepthFormat::Reversed, DepthFormat::Unorm24] {
            e.format = format;
            assert!(e.key(1.5) < e.key(2.5) && e.key(2.5) < e.clear_key(), "{format:?}: nearer is smaller");
        }
    }

    #[test]
    fn reversed_is_one_minus_d() {
        let e = DepthEncoding::new(DepthFormat::Reversed, 1.0, 3.0);
        // n = 1, f = 3: d' = (3 / z - 1) / 2; z = 1 -> 1, z = 3 -> 0, z = 2 -> 0.25.
        assert_eq!(e.key(1.0), -1.0);
        assert_eq!(e.clear_key(), 0.0);
        assert_eq!(e.key(0.5), -0.25);
        assert!((e.view_depth(-0.25) - 2.0).abs() < 1e-5);
    }
}
