//! The wireframe view (CGFS ch. 6-7): the shaded frame with every triangle
//! edge drawn over it, visible or not, as one-pixel lines.
//!
//! Edges are projected with the camera, clipped to the near plane in camera
//! space and to the image in image space, their end points rounded to the
//! pixels that hold them, and drawn by one of two line algorithms
//! (`--lines`): the floating-point DDA (CGFS's `Interpolate`: the minor
//! coordinate grows by the slope at each step of the major one, and is
//! rounded), or the integer-only Bresenham (an error term in integers
//! decides when the minor coordinate steps). Both hit both end points
//! exactly and differ by at most one pixel at any step.
//!
//! The lines are drawn on the finished frame in image space, the same for
//! every renderer: ray casters and rasterizers show the same wireframe.

use crate::math::{Radiance, Vec3};
use crate::named::named_enum;
use crate::scene::{CameraView, Scene};

named_enum! {
    /// How the wireframe view draws its lines.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum LineAlgorithm ("line algorithm") {
        /// DDA with a floating-point slope (CGFS ch. 6).
        #[default]
        Float = "float",
        /// Bresenham: integer additions and comparisons only.
        Integer = "integer",
    }
}

/// The colour of the lines (radiance, shown with the scene's exposure).
pub const LINE_COLOR: Radiance = Vec3::new(1.0, 0.9, 0.2);

/// Visits the pixels of the line from `a` to `b` (both included) by the
/// floating-point DDA: one pixel per step along the longer axis.
pub fn line_float(a: (i32, i32), b: (i32, i32), mut plot: impl FnMut(i32, i32)) {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    if dx == 0 && dy == 0 {
        plot(a.0, a.1);
        return;
    }
    // f64: the slope's rounding error, added up over thousands of steps,
    // stays far below half a pixel, so the last pixel is the end point.
    if dx.abs() >= dy.abs() {
        let (a, b) = if dx < 0 { (b, a) } else { (a, b) };
        let slope = (b.1 - a.1) as f64 / (b.0 - a.0) as f64;
        let mut y = a.1 as f64;
        for x in a.0..=b.0 {
            plot(x, y.round() as i32);
            y += slope;
        }
    } else {
        let (a, b) = if dy < 0 { (b, a) } else { (a, b) };
        let slope = (b.0 - a.0) as f64 / (b.1 - a.1) as f64;
        let mut x = a.0 as f64;
        for y in a.1..=b.1 {
            plot(x.round() as i32, y);
            x += slope;
        }
    }
}

/// Visits the pixels of the line from `a` to `b` (both included) by
/// Bresenham's algorithm, in integers only.
pub fn line_integer(a: (i32, i32), b: (i32, i32), mut plot: impl FnMut(i32, i32)) {
    let (dx, dy) = ((b.0 - a.0).abs(), -(b.1 - a.1).abs());
    let (sx, sy) = (if a.0 < b.0 { 1 } else { -1 }, if a.1 < b.1 { 1 } else { -1 });
    // err = dx + dy tracks how far the true line is from the pixel centre
    // (scaled by 2 dx dy): it decides, each step, which axes advance.
    let mut err = dx + dy;
    let (mut x, mut y) = a;
    loop {
        plot(x, y);
        if (x, y) == b {
            return;
        }
        let e2 = 2 * err;
        if e2 >= dy {
            err += dy;
            x += sx;
        }
        if e2 <= dx {
            err += dx;
            y += sy;
        }
    }
}

/// Draws the line from `a` to `b` with `algorithm`.
pub fn draw_line(algorithm: LineAlgorithm, a: (i32, i32), b: (i32, i32), plot: impl FnMut(i32, i32)) {
    match algorithm {
        LineAlgorithm::Float => line_float(a, b, plot),
        LineAlgorithm::Integer => line_integer(a, b, plot),
    }
}

/// Clips the segment `p0`-`p1` (image positions) to the image rectangle
/// [0, w] x [0, h] (Liang-Barsky); `None` when nothing of it is inside.
fn clip_to_image(p0: [f64; 2], p1: [f64; 2], w: f64, h: f64) -> Option<([f64; 2], [f64; 2])> {
    let d = [p1[0] - p0[0], p1[1] - p0[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-d[0], p0[0]), (d[0], w - p0[0]), (-d[1], p0[1]), (d[1], h - p0[1])] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then(|| ([p0[0] + t0 * d[0], p0[1] + t0 * d[1]], [p0[0] + t1 * d[0], p0[1] + t1 * d[1]]))
}

/// The pixels of the image edge `a`-`b` (world space) crosses: clipped to the
/// near plane and the image, end points rounded down to their pixels.
/// `None` when the edge is not in view.
pub fn edge_end_pixels(view: &CameraView, a: Vec3, b: Vec3) -> Option<((i32, i32), (i32, i32))> {
    let (mut c0, mut c1) = (view.to_camera(a), view.to_camera(b));
    let (d0, d1) = (-c0.z, -c1.z);
    if !(d0.is_finite() && d1.is_finite()) || (d0 < view.near && d1 < view.near) {
        return None;
    }
    // Depth is linear along the segment in camera space.
    if d0 < view.near {
        c0 = c0 + (c1 - c0) * ((view.near - d0) / (d1 - d0));
    } else if d1 < view.near {
        c1 = c1 + (c0 - c1) * ((view.near - d1) / (d0 - d1));
    }
    // Keep the clipped point on the plane whatever the rounding.
    for c in [&mut c0, &mut c1] {
        c.z = c.z.min(-view.near);
    }
    let (p0, p1) = (view.project_camera(c0), view.project_camera(c1));
    let (w, h) = (view.width as f64, view.height as f64);
    let (q0, q1) = clip_to_image([p0.x as f64, p0.y as f64], [p1.x as f64, p1.y as f64], w, h)?;
    let pixel = |q: [f64; 2]| ((q[0].floor() as i32).clamp(0, view.width as i32 - 1), (q[1].floor() as i32).clamp(0, view.height as i32 - 1));
    Some((pixel(q0), pixel(q1)))
}

/// Which pixels of a `view.width` x `view.height` image (row-major) the
/// wireframe of every triangle of `scene` covers.
pub fn line_mask(scene: &Scene, view: &CameraView, algorithm: LineAlgorithm) -> Vec<bool> {
    let (w, h) = (view.width as i32, view.height as i32);
    let mut mask = vec![false; view.width as usize * view.height as usize];
    if w == 0 || h == 0 {
        return mask;
    }
    for t in &scene.triangles {
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            if let Some((p, q)) = edge_end_pixels(view, t.v[a], t.v[b]) {
                draw_line(algorithm, p, q, |x, y| {
                    if (0..w).contains(&x) && (0..h).contains(&y) {
                        mask[(x + y * w) as usize] = true;
                    }
                });
            }
        }
    }
    mask
}

/// Paints the pixels of `mask` in the line colour.
pub fn draw_over(pixels: &mut [Radiance], mask: &[bool]) {
    for (p, on) in pixels.iter_mut().zip(mask) {
        if *on {
            *p = LINE_COLOR;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixels(algorithm: LineAlgorithm, a: (i32, i32), b: (i32, i32)) -> Vec<(i32, i32)> {
        let mut out = Vec::new();
        draw_line(algorithm, a, b, |x, y| out.push((x, y)));
        out
    }

    /// Lines in every octant, steep and shallow, short and long, and degenerate.
    fn test_lines() -> Vec<((i32, i32), (i32, i32))> {
        let mut v = vec![((0, 0), (0, 0)), ((3, 4), (3, 4)), ((0, 0), (10, 0)), ((0, 0), (0, -7)), ((5, 5), (-5, -5)), ((0, 0), (1000, 1)), ((2, 900), (1, 0))];
        for (dx, dy) in [(7, 3), (3, 7), (-7, 3), (-3, 7), (7, -3), (3, -7), (-7, -3), (-3, -7), (13, 13), (100, 37), (-251, 97), (1, 2), (2, 1)] {
            v.push(((10, 20), (10 + dx, 20 + dy)));
        }
        v
    }

    #[test]
    fn both_algorithms_hit_the_end_points_and_step_one_pixel() {
        for (a, b) in test_lines() {
            for alg in LineAlgorithm::ALL {
                let p = pixels(alg, a, b);
                assert!(p.contains(&a) && p.contains(&b), "{alg:?} {a:?}->{b:?}: {p:?}");
                // One pixel per step of the major axis: as many pixels as the
                // longer extent plus one, each a neighbour of the one before.
                let n = (b.0 - a.0).abs().max((b.1 - a.1).abs()) as usize + 1;
                assert_eq!(p.len(), n, "{alg:?} {a:?}->{b:?}");
                for s in p.windows(2) {
                    assert!((s[1].0 - s[0].0).abs() <= 1 && (s[1].1 - s[0].1).abs() <= 1, "{alg:?} {a:?}->{b:?}: gap");
                }
            }
        }
    }

    #[test]
    fn the_two_algorithms_agree_within_one_pixel_per_step() {
        for (a, b) in test_lines() {
            let mut f = pixels(LineAlgorithm::Float, a, b);
            let mut i = pixels(LineAlgorithm::Integer, a, b);
            // Both visit one pixel per major-axis coordinate: pair them by it.
            let major_x = (b.0 - a.0).abs() >= (b.1 - a.1).abs();
            let key = |p: &(i32, i32)| if major_x { (p.0, p.1) } else { (p.1, p.0) };
            f.sort_by_key(key);
            i.sort_by_key(key);
            assert_eq!(f.len(), i.len());
            for (pf, pi) in f.iter().zip(&i) {
                let (mf, mi) = (key(pf), key(pi));
                assert_eq!(mf.0, mi.0, "{a:?}->{b:?}");
                assert!((mf.1 - mi.1).abs() <= 1, "{a:?}->{b:?}: {pf:?} vs {pi:?}");
            }
        }
    }

    #[test]
    fn axis_aligned_lines_cover_exactly_their_pixels() {
        // A horizontal line from (2, 5) to (9, 5): the 8 pixels x = 2..=9 of row 5.
        let row: Vec<_> = (2..=9).map(|x| (x, 5)).collect();
        let col: Vec<_> = (1..=4).map(|y| (3, y)).collect();
        for alg in LineAlgorithm::ALL {
            let mut p = pixels(alg, (2, 5), (9, 5));
            p.sort();
            assert_eq!(p, row, "{alg:?}");
            let mut c = pixels(alg, (3, 4), (3, 1));
            c.sort();
            assert_eq!(c, col, "{alg:?}");
            // The diagonal: (0,0), (1,1), (2,2), (3,3).
            let mut d = pixels(alg, (3, 3), (0, 0));
            d.sort();
            assert_eq!(d, vec![(0, 0), (1, 1), (2, 2), (3, 3)], "{alg:?}");
        }
    }

    #[test]
    fn clipping_to_the_image() {
        // A segment from outside the left edge to inside: starts on x = 0.
        let (a, b) = clip_to_image([-10.0, 5.0], [10.0, 5.0], 20.0, 10.0).unwrap();
        assert_eq!((a, b), ([0.0, 5.0], [10.0, 5.0]));
        assert!(clip_to_image([-10.0, -5.0], [-1.0, 20.0], 20.0, 10.0).is_none());
        let (a, b) = clip_to_image([-5.0, -5.0], [25.0, 25.0], 20.0, 10.0).unwrap();
        assert_eq!((a, b), ([0.0, 0.0], [10.0, 10.0]));
    }
}
