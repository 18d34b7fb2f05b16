//! Image error metrics between a test image and a reference, on linear values.

pub mod flip;

use crate::math::Radiance;

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ErrorMetrics {
    /// Root mean squared error over all pixels and channels.
    pub rmse: f64,
    /// Mean of (a - b)^2 / (b^2 + 0.01): squared error relative to the reference.
    pub rel_mse: f64,
    /// Largest absolute channel difference.
    pub max_abs: f64,
    /// Mean radiance of the reference, to state rmse relative to it.
    pub reference_mean: f64,
    /// Pixels whose largest channel difference exceeds 1e-4 relative.
    pub differing_pixels: u64,
    /// Mean LDR FLIP error of the sRGB-encoded images (exposure 1); computed by `compare_images`.
    pub flip: Option<f64>,
}

/// All metrics, FLIP included, for two images of `width` x `height`.
/// Largest image FLIP is computed for (4 Mi pixels, e.g. 2048 x 2048): its
/// filtered copies would otherwise take gigabytes.
pub const MAX_FLIP_PIXELS: usize = 1 << 22;

/// The metrics of `compare`, with FLIP when the image has at most `MAX_FLIP_PIXELS`.
pub fn compare_images(test: &[Radiance], reference: &[Radiance], width: usize, height: usize) -> Result<ErrorMetrics, String> {
    let mut m = compare(test, reference)?;
    let encode = |img: &[Radiance]| -> Vec<glam::Vec3> {
        img.iter().map(|&c| {
            let p = crate::image_io::display_pixel(c, 1.0, true);
            glam::Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0
        }).collect()
    };
    // FLIP holds a dozen full-size buffers: above the limit it is left out.
    if width * height <= MAX_FLIP_PIXELS {
        m.flip = Some(flip::mean_flip(&encode(test), &encode(reference), width, height));
    }
    Ok(m)
}

/// Compares `test` against `reference` (same size, row-major linear RGB).
pub fn compare(test: &[Radiance], reference: &[Radiance]) -> Result<ErrorMetrics, String> {
    if test.len() != reference.len() {
        return Err(format!("the images differ in size ({} vs {} pixels)", test.len(), reference.len()));
    }
    if test.is_empty() {
        return Err("the images are empty".into());
    }
    // A NaN difference compares false with everything, so it would count as
    // no difference at all: non-finite input is refused instead.
    for (img, which) in [(test, "test"), (reference, "reference")] {
        let bad = count_non_finite(img);
        if bad > 0 {
            return Err(format!("the {which} image has {bad} pixels that are NaN or infinite; error metrics need finite values"));
        }
    }
    let (mut se, mut rel, mut max_abs, mut mean) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut differing = 0u64;
    for (a, b) in test.iter().zip(reference) {
        let mut differs = false;
        for k in 0..3 {
            let (x, y) = (a[k] as f64, b[k] as f64);
            let d = x - y;
            se += d * d;
            rel += d * d / (y * y + 0.01);
            max_abs = max_abs.max(d.abs());
            mean += y;
            if d.abs() > 1e-4 * y.abs().max(x.abs()).max(1e-3) {
                differs = true;
            }
        }
        differing += differs as u64;
    }
    let n = (test.len() * 3) as f64;
    Ok(ErrorMetrics {
        rmse: (se / n).sqrt(),
        rel_mse: rel / n,
        max_abs,
        reference_mean: mean / n,
        differing_pixels: differing,
        flip: None,
    })
}

/// How many pixels have a NaN or infinite channel.
pub fn count_non_finite(img: &[Radiance]) -> usize {
    img.iter().filter(|c| !(c.x.is_finite() && c.y.is_finite() && c.z.is_finite())).count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn non_finite_input_is_refused_not_measured_as_zero() {
        let good = vec![Vec3::ONE; 2];
        let nan = vec![Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ONE];
        assert!(compare(&nan, &good).unwrap_err().contains("test image has 1 pixels"));
        assert!(compare(&good, &[Vec3::ONE, Vec3::splat(f32::INFINITY)]).unwrap_err().contains("reference image"));
    }

    #[test]
    fn flip_is_left_out_above_its_pixel_limit() {
        let (w, h) = (2049, 2048);
        let img = vec![Vec3::splat(0.5); w * h];
        assert!(w * h > MAX_FLIP_PIXELS);
        assert_eq!(compare_images(&img, &img, w, h).unwrap().flip, None);
        assert_eq!(compare_images(&img[..64], &img[..64], 8, 8).unwrap().flip, Some(0.0));
    }

    #[test]
    fn by_hand() {
        let a = vec![Vec3::new(1.0, 1.0, 1.0), Vec3::new(0.0, 0.0, 0.0)];
        let b = vec![Vec3::new(1.0, 1.0, 1.0), Vec3::new(0.0, 0.0, 0.6)];
        let m = compare(&a, &b).unwrap();
        // One channel off by 0.6 of six: mse = 0.36 / 6 = 0.06.
        assert!((m.rmse - 0.06f64.sqrt()).abs() < 1e-6);
        assert!((m.max_abs - 0.6).abs() < 1e-6);
        assert!((m.rel_mse - 0.36 / (0.36 + 0.01) / 6.0).abs() < 1e-6);
        assert_eq!(m.differing_pixels, 1);
        assert!(compare(&a, &b[..1]).is_err());
    }
}
