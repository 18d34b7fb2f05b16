//! LDR FLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating
//! Images", HPG 2020): a per-pixel perceptual difference in [0, 1] between two
//! sRGB images as a viewer flipping between them would see it. Colour
//! differences are measured after filtering by the eye's contrast
//! sensitivity; edge and point features that differ amplify them.

use crate::math::Vec3;

/// Pixels per degree of visual angle: a 0.7 m wide 4K monitor seen from 0.7 m.
pub const PIXELS_PER_DEGREE: f32 = 67.02;

/// Mean FLIP error of `test` against `reference`, both sRGB-encoded values in
/// [0, 1], row-major `width` x `height`.
pub fn mean_flip(test: &[Vec3], reference: &[Vec3], width: usize, height: usize) -> f64 {
    let map = flip_map(test, reference, width, height);
    map.iter().map(|&v| v as f64).sum::<f64>() / map.len().max(1) as f64
}

/// The per-pixel FLIP error map.
pub fn flip_map(test: &[Vec3], reference: &[Vec3], width: usize, height: usize) -> Vec<f32> {
    let ppd = PIXELS_PER_DEGREE;
    let ycc_t: Vec<Vec3> = test.iter().map(|&c| xyz_to_ycxcz(linear_rgb_to_xyz(srgb_to_linear(c)))).collect();
    let ycc_r: Vec<Vec3> = reference.iter().map(|&c| xyz_to_ycxcz(linear_rgb_to_xyz(srgb_to_linear(c)))).collect();

    // Colour pipeline: contrast-sensitivity filtering in YCxCz, then Hunt-adjusted L*a*b*.
    let csf = csf_kernels(ppd);
    let filtered = |img: &[Vec3]| -> Vec<Vec3> {
        let f = convolve_separable_per_channel(img, width, height, &csf);
        f.into_iter()
            .map(|c| hunt(xyz_to_lab(linear_rgb_to_xyz(xyz_to_linear_rgb(ycxcz_to_xyz(c)).clamp(Vec3::ZERO, Vec3::ONE)))))
            .collect()
    };
    let lab_t = filtered(&ycc_t);
    let lab_r = filtered(&ycc_r);
    let green = hunt(xyz_to_lab(linear_rgb_to_xyz(Vec3::new(0.0, 1.0, 0.0))));
    let blue = hunt(xyz_to_lab(linear_rgb_to_xyz(Vec3::new(0.0, 0.0, 1.0))));
    let cmax = hyab(green, blue).powf(0.7);

    // Feature pipeline: edges (first derivative) and points (second derivative) of luminance.
    let lum = |img: &[Vec3]| -> Vec<f32> { img.iter().map(|c| (c.x + 16.0) / 116.0).collect() };
    let (lum_t, lum_r) = (lum(&ycc_t), lum(&ycc_r));
    let sigma = 0.5 * 0.082 * ppd;
    let (g, d1, d2) = feature_kernels(sigma);
    let features = |l: &[f32]| -> (Vec<f32>, Vec<f32>) {
        let ex = conv2(l, width, height, &d1, &g);
        let ey = conv2(l, width, height, &g, &d1);
        let px = conv2(l, width, height, &d2, &g);
        let py = conv2(l, width, height, &g, &d2);
        let edges = ex.iter().zip(&ey).map(|(a, b)| (a * a + b * b).sqrt()).collect();
        let points = px.iter().zip(&py).map(|(a, b)| (a * a + b * b).sqrt()).collect();
        (edges, points)
    };
    let (edge_t, point_t) = features(&lum_t);
    let (edge_r, point_r) = features(&lum_r);

    (0..width * height)
        .map(|i| {
            let (pc, pt) = (0.4f32, 0.95f32);
            let d = hyab(lab_t[i], lab_r[i]).powf(0.7);
            let color = if d < pc * cmax { pt / (pc * cmax) * d } else { pt + (d - pc * cmax) / (cmax - pc * cmax) * (1.0 - pt) };
            let feature = ((edge_t[i] - edge_r[i]).abs().max((point_t[i] - point_r[i]).abs()) / std::f32::consts::SQRT_2).powf(0.5);
            color.clamp(0.0, 1.0).powf(1.0 - feature.clamp(0.0, 1.0))
        })
        .collect()
}

fn srgb_to_linear(c: Vec3) -> Vec3 {
    let f = |v: f32| if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) };
    Vec3::new(f(c.x), f(c.y), f(c.z))
}

fn linear_rgb_to_xyz(c: Vec3) -> Vec3 {
    Vec3::new(
        0.412_390_8 * c.x + 0.357_584_33 * c.y + 0.180_480_79 * c.z,
        0.212_639 * c.x + 0.715_168_7 * c.y + 0.072_192_32 * c.z,
        0.019_330_82 * c.x + 0.119_194_78 * c.y + 0.950_532_2 * c.z,
    )
}

fn xyz_to_linear_rgb(c: Vec3) -> Vec3 {
    Vec3::new(
        3.240_97 * c.x - 1.537_383_2 * c.y - 0.498_610_76 * c.z,
        -0.969_243_6 * c.x + 1.875_967_5 * c.y + 0.041_555_06 * c.z,
        0.055_630_08 * c.x - 0.203_976_96 * c.y + 1.056_971_5 * c.z,
    )
}

/// D65 reference white.
const WHITE: Vec3 = Vec3::new(0.950_428_5, 1.0, 1.088_900_4);

fn xyz_to_ycxcz(c: Vec3) -> Vec3 {
    let n = c / WHITE;
    Vec3::new(116.0 * n.y - 16.0, 500.0 * (n.x - n.y), 200.0 * (n.y - n.z))
}

fn ycxcz_to_xyz(c: Vec3) -> Vec3 {
    let y = (c.x + 16.0) / 116.0;
    let x = y + c.y / 500.0;
    let z = y - c.z / 200.0;
    Vec3::new(x, y, z) * WHITE
}

fn xyz_to_lab(c: Vec3) -> Vec3 {
    let f = |t: f32| {
        let delta: f32 = 6.0 / 29.0;
        if t > delta.powi(3) { t.cbrt() } else { t / (3.0 * delta * delta) + 4.0 / 29.0 }
    };
    let n = c / WHITE;
    let (fx, fy, fz) = (f(n.x), f(n.y), f(n.z));
    Vec3::new(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz))
}

/// Hunt effect: chroma appears weaker at low lightness.
fn hunt(lab: Vec3) -> Vec3 {
    Vec3::new(lab.x, 0.01 * lab.x * lab.y, 0.01 * lab.x * lab.z)
}

/// HyAB distance: city-block in lightness, Euclidean in chroma.
fn hyab(a: Vec3, b: Vec3) -> f32 {
    (a.x - b.x).abs() + ((a.y - b.y).powi(2) + (a.z - b.z).powi(2)).sqrt()
}

/// The contrast sensitivity functions of the three opponent channels as
/// normalized 1D Gaussian mixtures (one kernel per channel, applied separably).
fn csf_kernels(ppd: f32) -> [Vec<f32>; 3] {
    // (a1, b1, a2, b2) for achromatic, red-green and blue-yellow.
    let params = [(1.0f32, 0.0047f32, 0.0f32, 1e-5f32), (1.0, 0.0053, 0.0, 1e-5), (34.1, 0.04, 13.5, 0.025)];
    let max_b = 0.04f32;
    let radius = (3.0 * (max_b / (2.0 * std::f32::consts::PI.powi(2))).sqrt() * ppd).ceil() as i32;
    params.map(|(a1, b1, a2, b2)| {
        let pi2 = std::f32::consts::PI.powi(2);
        // The 2D kernel is separable: exp(-pi^2 (x^2 + y^2) / b) = g(x) g(y). For the
        // sum of two Gaussians we approximate with the dominant one's separable
        // form weighted by both amplitudes, which is exact for a2 = 0.
        let mut k: Vec<f32> = (-radius..=radius)
            .map(|i| {
                let x = i as f32 / ppd;
                let g1 = a1 * (std::f32::consts::PI / b1).sqrt() * (-pi2 * x * x / b1).exp();
                let g2 = a2 * (std::f32::consts::PI / b2).sqrt() * (-pi2 * x * x / b2).exp();
                g1 + g2
            })
            .collect();
        let s: f32 = k.iter().sum();
        k.iter_mut().for_each(|v| *v /= s);
        k
    })
}

/// Gaussian, its first and its second derivative, each normalized as FLIP does
/// (the Gaussian to sum 1; the derivatives' positive and negative lobes to 1 and -1).
fn feature_kernels(sigma: f32) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
    let radius = (3.0 * sigma).ceil() as i32;
    let xs: Vec<f32> = (-radius..=radius).map(|i| i as f32).collect();
    let g: Vec<f32> = xs.iter().map(|x| (-x * x / (2.0 * sigma * sigma)).exp()).collect();
    let gs: f32 = g.iter().sum();
    let g: Vec<f32> = g.iter().map(|v| v / gs).collect();
    let d1: Vec<f32> = xs.iter().zip(&g).map(|(x, g)| -x * g).collect();
    let d2: Vec<f32> = xs.iter().zip(&g).map(|(x, g)| (x * x / (sigma * sigma) - 1.0) * g).collect();
    let balance = |k: Vec<f32>| {
        let pos: f32 = k.iter().filter(|v| **v > 0.0).sum();
        let neg: f32 = -k.iter().filter(|v| **v < 0.0).sum::<f32>();
        k.into_iter().map(|v| if v > 0.0 { v / pos } else { v / neg }).collect::<Vec<f32>>()
    };
    (g, balance(d1), balance(d2))
}

/// Separable convolution (kx along rows, ky along columns), clamping at edges.
fn conv2(img: &[f32], w: usize, h: usize, kx: &[f32], ky: &[f32]) -> Vec<f32> {
    let rows = conv1(img, w, h, kx, true);
    conv1(&rows, w, h, ky, false)
}

/// One pass of `conv2`: the kernel along rows (`along_rows`) or along columns.
fn conv1(img: &[f32], w: usize, h: usize, kernel: &[f32], along_rows: bool) -> Vec<f32> {
    let r = (kernel.len() / 2) as isize;
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut s = 0.0;
            for (k, wgt) in kernel.iter().enumerate() {
                let index = if along_rows {
                    (x as isize + k as isize - r).clamp(0, w as isize - 1) as usize + y * w
                } else {
                    x + (y as isize + k as isize - r).clamp(0, h as isize - 1) as usize * w
                };
                s += wgt * img[index];
            }
            out[x + y * w] = s;
        }
    }
    out
}

fn convolve_separable_per_channel(img: &[Vec3], w: usize, h: usize, k: &[Vec<f32>; 3]) -> Vec<Vec3> {
    let chan = |c: usize| -> Vec<f32> { conv2(&img.iter().map(|v| v[c]).collect::<Vec<_>>(), w, h, &k[c], &k[c]) };
    let (a, b, c) = (chan(0), chan(1), chan(2));
    (0..w * h).map(|i| Vec3::new(a[i], b[i], c[i])).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(c: Vec3, n: usize) -> Vec<Vec3> {
        vec![c; n]
    }

    #[test]
    fn identical_images_have_no_error() {
        let img: Vec<Vec3> = (0..32 * 32).map(|i| Vec3::new((i % 7) as f32 / 7.0, (i % 5) as f32 / 5.0, 0.3)).collect();
        assert!(mean_flip(&img, &img, 32, 32) < 1e-6);
    }

    #[test]
    fn green_against_blue_is_the_maximum() {
        // FLIP is normalized so the largest colour difference (green vs blue) maps to 1.
        let e = mean_flip(&flat(Vec3::new(0.0, 1.0, 0.0), 400), &flat(Vec3::new(0.0, 0.0, 1.0), 400), 20, 20);
        assert!((e - 1.0).abs() < 0.02, "{e}");
    }

    #[test]
    fn error_grows_with_difference() {
        let base = flat(Vec3::splat(0.5), 400);
        let small = mean_flip(&flat(Vec3::splat(0.52), 400), &base, 20, 20);
        let large = mean_flip(&flat(Vec3::splat(0.8), 400), &base, 20, 20);
        assert!(0.0 < small && small < large && large < 1.0, "{small} {large}");
    }

    #[test]
    fn a_moved_edge_counts_more_than_its_colour_alone() {
        // A one-pixel shift of a sharp edge: features differ, so error at the edge is high.
        let (w, h) = (40, 8);
        let edge = |at: usize| -> Vec<Vec3> { (0..w * h).map(|i| if i % w < at { Vec3::ZERO } else { Vec3::ONE }).collect() };
        let map = flip_map(&edge(20), &edge(21), w, h);
        let at_edge = map[20 + 4 * w];
        let far = map[5 + 4 * w];
        assert!(at_edge > 0.5 && far < 0.05, "{at_edge} {far}");
    }
}
