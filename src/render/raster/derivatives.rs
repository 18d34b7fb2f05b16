//! Analytic screen-space derivatives of a rasterized triangle's
//! perspective-correct attributes: the texture footprint the rasterizers
//! hand to shading.
//!
//! Perspective-correct interpolation rests on two facts: across the image
//! `1/z` is affine, and so is `b_k / z` for each barycentric weight (that is
//! what `ScreenTri::bz` stores per vertex). With `q = 1/z` and
//! `a_k = b_k q` both affine, `b_k = a_k / q` and the quotient rule gives
//! `db_k/dx = (da_k/dx - b_k dq/dx) / q`. Here both affine functions come
//! from the triangle's plane in camera space rather than from its clipped
//! screen vertices, so a triangle cut at the near plane (or reaching behind
//! the eye) has the same derivatives as its uncut self.

use crate::math::Vec3;
use crate::render::differentials::RayDifferential;
use crate::scene::{CameraView, Differentials, Scene};

/// The derivatives at image position `(px, py)` of a sample of triangle
/// `index` with perspective-correct barycentrics `b`.
pub fn screen_differentials(scene: &Scene, view: &CameraView, index: u32, b: Vec3, px: f32, py: f32) -> Differentials {
    let tri = &scene.triangle(index);
    let v = tri.v.map(|p| view.to_camera(p));
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let n = e1.cross(e2);
    let nn = n.dot(n);
    // Camera-space gradients of b1 and b2 within the plane.
    let g1 = e2.cross(n) / nn;
    let g2 = n.cross(e1) / nn;
    // One pixel's step across the image, in camera space.
    let dc_dx = Vec3::new(2.0 * view.half_x / view.width as f32, 0.0, 0.0);
    let dc_dy = Vec3::new(0.0, -2.0 * view.half_y / view.height as f32, 0.0);
    let ((dx1, dx2), (dy1, dy2)) = if !view.is_orthographic() {
        // The plane n.P = d; the point seen along c = (sx, sy, -1) is c / q with q = n.c / d.
        let d = n.dot(v[0]);
        let c = view.camera_dir(px, py);
        let q = n.dot(c) / d;
        // a_k = b_k q = c.g_k - (v0.g_k) q, so da_k = dc.g_k - (v0.g_k) dq.
        let db = |dc: Vec3| {
            let dq = n.dot(dc) / d;
            let db1 = (dc.dot(g1) - (v[0].dot(g1) + b.y) * dq) / q;
            let db2 = (dc.dot(g2) - (v[0].dot(g2) + b.z) * dq) / q;
            (db1, db2)
        };
        (db(dc_dx), db(dc_dy))
    } else {
        // Parallel rays down -z: the ray's start moves by dc, and the point
        // it meets slides along the ray back onto the plane, so the point
        // moves by dc - dir (n.dc / n.dir); b_k is affine in it (g_k).
        let dir = Vec3::NEG_Z;
        let db = |dc: Vec3| {
            let dp = dc - dir * (n.dot(dc) / n.dot(dir));
            (dp.dot(g1), dp.dot(g2))
        };
        (db(dc_dx), db(dc_dy))
    };
    let (w1, w2) = (tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]);
    let (t1, t2) = (tri.uv[1] - tri.uv[0], tri.uv[2] - tri.uv[0]);
    // The eye ray's direction changes as the camera's geometry says.
    let eye = RayDifferential::eye(view, px, py);
    Differentials {
        dp_dx: w1 * dx1 + w2 * dx2,
        dp_dy: w1 * dy1 + w2 * dy2,
        dd_dx: eye.dd_dx,
        dd_dy: eye.dd_dy,
        duv_dx: t1 * dx1 + t2 * dx2,
        duv_dy: t1 * dy1 + t2 * dy2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;
    use crate::render::differentials::with_ray_differentials;
    use crate::scene::{Camera, Triangle};

    /// A ground triangle seen at a slant: the rasterizer's derivatives and
    /// the ray differentials agree.
    #[test]
    fn screen_derivatives_equal_ray_differentials() {
        let mut scene = Scene::default();
        scene.triangles.push(Triangle {
            v: [Vec3::new(-5.0, -1.0, -2.0), Vec3::new(5.0, -1.0, -2.0), Vec3::new(0.0, -1.0, -30.0)],
            n: [Vec3::Y; 3],
            uv: [Vec2::new(0.0, 0.0), Vec2::new(4.0, 0.0), Vec2::new(2.0, 9.0)],
            material: 0,
            object: 0,
            two_sided: false,
        });
        let view = Camera::default().view(320, 200);
        for (px, py) in [(160.5, 150.5), (100.25, 120.75), (190.5, 115.5)] {
            let ray = view.eye_ray(px, py);
            let (t, b1, b2) = crate::render::accel::intersect::intersect_triangle(&ray, &crate::render::accel::intersect::TriangleEdges::new(&scene.triangles.at(0)), f32::INFINITY).unwrap();
            let b = Vec3::new(1.0 - b1 - b2, b1, b2);
            let hit = scene.triangle_hit(0, b, t, &ray);
            let traced = with_ray_differentials(&scene, &RayDifferential::eye(&view, px, py), &ray, hit).diff;
            let raster = screen_differentials(&scene, &view, 0, b, px, py);
            for (a, r) in [(traced.duv_dx, raster.duv_dx), (traced.duv_dy, raster.duv_dy)] {
                assert!((a - r).length() <= 1e-4 * a.length().max(1e-6), "({px}, {py}): {a} vs {r}");
            }
            assert!((traced.dp_dy - raster.dp_dy).length() <= 1e-4 * traced.dp_dy.length());
        }
        // Along parallel rays the footprint is the same at every pixel: a
        // ray one pixel over meets the ground `2 half_y / height` further
        // along y, which the slant (ground seen from above at 45 degrees)
        // stretches by sqrt 2 in depth.
        let ortho = Camera { eye: Vec3::new(0.0, 4.0, 2.0), target: Vec3::new(0.0, -1.0, -3.0), projection: crate::scene::camera::Projection::Orthographic { height: 8.0 }, ..Camera::default() }.view(320, 200);
        for (px, py) in [(160.5, 100.5), (100.25, 80.75)] {
            let ray = ortho.eye_ray(px, py);
            let (t, b1, b2) = crate::render::accel::intersect::intersect_triangle(&ray, &crate::render::accel::intersect::TriangleEdges::new(&scene.triangles.at(0)), f32::INFINITY).unwrap();
            let b = Vec3::new(1.0 - b1 - b2, b1, b2);
            let hit = scene.triangle_hit(0, b, t, &ray);
            let traced = with_ray_differentials(&scene, &RayDifferential::eye(&ortho, px, py), &ray, hit).diff;
            let raster = screen_differentials(&scene, &ortho, 0, b, px, py);
            for (a, r) in [(traced.duv_dx, raster.duv_dx), (traced.duv_dy, raster.duv_dy)] {
                assert!((a - r).length() <= 1e-4 * a.length().max(1e-6), "orthographic ({px}, {py}): {a} vs {r}");
            }
            for (a, r) in [(traced.dp_dx, raster.dp_dx), (traced.dp_dy, raster.dp_dy)] {
                assert!((a - r).length() <= 1e-4 * a.length().max(1e-6), "orthographic ({px}, {py}): {a} vs {r}");
            }
            let step = 8.0 / 200.0;
            assert!((raster.dp_dx - Vec3::new(step, 0.0, 0.0)).length() < 1e-5, "{}", raster.dp_dx);
            assert!((raster.dp_dy - Vec3::new(0.0, 0.0, step * 2f32.sqrt())).length() < 1e-5, "{}", raster.dp_dy);
        }
    }
}
