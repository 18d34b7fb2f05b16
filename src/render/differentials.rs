//! Ray differentials (Igehy, "Tracing Ray Differentials", 1999): how a ray's
//! origin and direction change from one pixel to the next, carried from the
//! camera to the surface it hits (transfer), and on through mirror
//! reflection. At the hit they give the change of position and uv per pixel:
//! the texture footprint that picks the mip level. The ray casters find
//! their footprints this way; the rasterizers differentiate their
//! perspective-correct interpolation instead (`raster::derivatives`), and
//! both arrive at the same numbers up to rounding.

use crate::math::{Ray, Vec2, Vec3};
use crate::scene::camera::Projection;
use crate::scene::{CameraView, Differentials, PrimitiveKind, Scene, SurfaceHit};

/// d(origin)/dx, d(origin)/dy, d(direction)/dx, d(direction)/dy of a ray,
/// per pixel of the image (x right, y down).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayDifferential {
    pub do_dx: Vec3,
    pub do_dy: Vec3,
    pub dd_dx: Vec3,
    pub dd_dy: Vec3,
}

impl RayDifferential {
    /// The differentials of `CameraView::eye_ray` at image position
    /// `(px, py)`: the unnormalized direction `C (sx, sy, -1)` moves by
    /// `2 half_x / width` along the camera's x per pixel (and `-2 half_y /
    /// height` along y), the origin on the near plane by `near` times that,
    /// and the unit direction by the derivative of normalization.
    /// Orthographic rays move sideways and keep their direction; the
    /// projections that bend lines take the difference between the rays
    /// half a pixel either side.
    pub fn eye(view: &CameraView, px: f32, py: f32) -> RayDifferential {
        let m = view.camera_to_world;
        match view.projection {
            Projection::Perspective => {}
            Projection::Orthographic { .. } => {
                return RayDifferential {
                    do_dx: m * Vec3::new(2.0 * view.half_x / view.width as f32, 0.0, 0.0),
                    do_dy: m * Vec3::new(0.0, -2.0 * view.half_y / view.height as f32, 0.0),
                    dd_dx: Vec3::ZERO,
                    dd_dy: Vec3::ZERO,
                }
            }
            Projection::Fisheye | Projection::Cylindrical => {
                let across = |a: Ray, b: Ray| (b.origin - a.origin, b.dir - a.dir);
                let (do_dx, dd_dx) = across(view.eye_ray(px - 0.5, py), view.eye_ray(px + 0.5, py));
                let (do_dy, dd_dy) = across(view.eye_ray(px, py - 0.5), view.eye_ray(px, py + 0.5));
                return RayDifferential { do_dx, do_dy, dd_dx, dd_dy };
            }
        }
        let d = m * view.camera_dir(px, py);
        let step_x = m * Vec3::new(2.0 * view.half_x / view.width as f32, 0.0, 0.0);
        let step_y = m * Vec3::new(0.0, -2.0 * view.half_y / view.height as f32, 0.0);
        RayDifferential {
            do_dx: step_x * view.near,
            do_dy: step_y * view.near,
            dd_dx: normalized_derivative(d, step_x),
            dd_dy: normalized_derivative(d, step_y),
        }
    }
}

/// The derivative of `d / |d|` when `d` changes by `dd`.
#[inline]
pub fn normalized_derivative(d: Vec3, dd: Vec3) -> Vec3 {
    let l2 = d.length_squared();
    (dd * l2 - d * d.dot(dd)) / (l2 * l2.sqrt())
}

/// Igehy's transfer to a surface with normal `n` at ray parameter `t` of
/// a ray along unit `dir`: the hit point moves by `dO + t dD`, then back
/// along the ray onto the tangent plane. Infinite at grazing incidence
/// (the coarsest texture level).
#[inline]
pub fn transfer(rd: &RayDifferential, dir: Vec3, t: f32, n: Vec3) -> (Vec3, Vec3) {
    let dn = dir.dot(n);
    let onto_plane = |d_o: Vec3, d_d: Vec3| {
        let p = d_o + d_d * t;
        p - dir * (p.dot(n) / dn)
    };
    (onto_plane(rd.do_dx, rd.dd_dx), onto_plane(rd.do_dy, rd.dd_dy))
}

/// The change of the hit's uv when its position moves by `dp` in the
/// surface: through the barycentric gradient on a triangle (Implementor's
/// Guide 2.4.2's edge vectors), through the derivatives of longitude and
/// latitude on a sphere (`Scene::sphere_hit`'s mapping; infinite at the
/// poles).
#[inline]
pub fn uv_change(scene: &Scene, hit: &SurfaceHit, dp: Vec3) -> Vec2 {
    match hit.kind {
        PrimitiveKind::Triangle => {
            let tri = &scene.triangle(hit.primitive);
            let (e1, e2) = (tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]);
            let n = e1.cross(e2);
            let nn = n.dot(n);
            let db1 = dp.dot(e2.cross(n)) / nn;
            let db2 = dp.dot(n.cross(e1)) / nn;
            (tri.uv[1] - tri.uv[0]) * db1 + (tri.uv[2] - tri.uv[0]) * db2
        }
        PrimitiveKind::Sphere => {
            let s = &scene.spheres[hit.primitive as usize];
            let o = (hit.position - s.center) / s.radius;
            let d = dp / s.radius;
            let du = -(o.x * d.z - o.z * d.x) / (o.x * o.x + o.z * o.z) * (0.5 * std::f32::consts::FRAC_1_PI);
            let dv = d.y / ((1.0 - o.y * o.y).max(0.0).sqrt() * std::f32::consts::PI);
            Vec2::new(du, dv)
        }
        // The winning operand surface is not kept in the hit: CSG surfaces
        // read textures at the finest level.
        PrimitiveKind::Csg => Vec2::ZERO,
    }
}

/// `hit` found by a ray whose differentials are `rd`, with its
/// `Differentials` filled in by transfer.
#[inline]
pub fn with_ray_differentials(scene: &Scene, rd: &RayDifferential, ray: &Ray, mut hit: SurfaceHit) -> SurfaceHit {
    let (dp_dx, dp_dy) = transfer(rd, ray.dir, hit.t, hit.geometric_normal);
    hit.diff = Differentials {
        dp_dx,
        dp_dy,
        dd_dx: rd.dd_dx,
        dd_dy: rd.dd_dy,
        duv_dx: uv_change(scene, &hit, dp_dx),
        duv_dy: uv_change(scene, &hit, dp_dy),
    };
    hit
}

/// The differentials of the mirror reflection at `hit` of a ray arriving
/// along unit `d_in`, about unit normal `n` (Igehy eq. 12): `R = D - 2 (D.n) n`
/// changes with `dD` and with the normal's change, zero on a flat triangle
/// and `dp / r` on a sphere. The reflected ray starts where the hit moves.
pub fn reflected(scene: &Scene, hit: &SurfaceHit, d_in: Vec3, n: Vec3) -> RayDifferential {
    let diff = &hit.diff;
    let (dn_dx, dn_dy) = match hit.kind {
        PrimitiveKind::Sphere => {
            let r = scene.spheres[hit.primitive as usize].radius;
            let side = if hit.back_face { -1.0 } else { 1.0 };
            (diff.dp_dx * (side / r), diff.dp_dy * (side / r))
        }
        PrimitiveKind::Triangle | PrimitiveKind::Csg => (Vec3::ZERO, Vec3::ZERO),
    };
    let d_dot_n = d_in.dot(n);
    let reflect = |dd: Vec3, dn: Vec3| dd - 2.0 * (dn * d_dot_n + n * (dd.dot(n) + d_in.dot(dn)));
    RayDifferential { do_dx: diff.dp_dx, do_dy: diff.dp_dy, dd_dx: reflect(diff.dd_dx, dn_dx), dd_dy: reflect(diff.dd_dy, dn_dy) }
}

/// The differentials of a refracted ray at `hit`: the origin moves with the
/// hit, the direction's change is kept as it arrived (a thin-lens
/// simplification of Igehy's refraction: footprints through glass are
/// approximate).
pub fn refracted(hit: &SurfaceHit) -> RayDifferential {
    let diff = &hit.diff;
    RayDifferential { do_dx: diff.dp_dx, do_dy: diff.dp_dy, dd_dx: diff.dd_dx, dd_dy: diff.dd_dy }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Fov};

    /// The book's camera (CGPP 15.3.4): at the origin looking down -z,
    /// 90 degrees across 800 pixels, so the image plane at distance 1 is
    /// 2 wide and one pixel is 1/400 of it.
    fn book_view() -> CameraView {
        Camera { fov: Fov::X(90.0), near: 0.1, far: 100.0, ..Camera::default() }.view(800, 500)
    }

    #[test]
    fn a_ray_differential_through_a_known_pixel() {
        let view = book_view();
        // The centre of the image: d = (0, 0, -1), unit already.
        let rd = RayDifferential::eye(&view, 400.0, 250.0);
        let step = 2.0 / 800.0;
        assert!((rd.dd_dx - Vec3::new(step, 0.0, 0.0)).length() < 1e-9, "{:?}", rd.dd_dx);
        assert!((rd.dd_dy - Vec3::new(0.0, -step, 0.0)).length() < 1e-9, "{:?}", rd.dd_dy);
        assert!((rd.do_dx - Vec3::new(0.1 * step, 0.0, 0.0)).length() < 1e-9);
        // Pixel x = 800 (the right edge), y = 250: d = (1, 0, -1), |d| = sqrt 2.
        // d(d/|d|)/dx = (step (1,0,0) * 2 - d * step) / 2^1.5 = step (1, 0, 1) / 2^1.5.
        let rd = RayDifferential::eye(&view, 800.0, 250.0);
        let want = Vec3::new(1.0, 0.0, 1.0) * (step / 2f32.powf(1.5));
        assert!((rd.dd_dx - want).length() < 1e-8, "{:?} vs {want:?}", rd.dd_dx);
        // The finite difference of the eye rays agrees.
        let (a, b) = (view.eye_ray(799.5, 250.0), view.eye_ray(800.5, 250.0));
        assert!((b.dir - a.dir - rd.dd_dx).length() < 1e-6);

        // Transfer to a wall at z = -10 facing the eye: one pixel there is
        // 10 * 2/800 = 0.025 wide, along x only.
        let rd = RayDifferential::eye(&view, 400.0, 250.0);
        let ray = view.eye_ray(400.0, 250.0);
        let t = 10.0 - 0.1;
        let (dx, dy) = transfer(&rd, ray.dir, t, Vec3::Z);
        assert!((dx - Vec3::new(0.025, 0.0, 0.0)).length() < 1e-7, "{dx:?}");
        assert!((dy - Vec3::new(0.0, -0.025, 0.0)).length() < 1e-7, "{dy:?}");
        // Tilted 60 degrees about y: the footprint stretches by 1 / cos 60 = 2.
        let n = Vec3::new(60f32.to_radians().sin(), 0.0, 60f32.to_radians().cos());
        let (dx, _) = transfer(&rd, ray.dir, t, n);
        assert!((dx.length() - 0.05).abs() < 1e-6, "{dx:?}");
    }

    #[test]
    fn mirror_reflection_of_differentials_by_hand() {
        // A flat mirror keeps the spread: dR = dD - 2 (dD.n) n.
        let mut scene = Scene::default();
        scene.triangles.push(crate::scene::Triangle {
            v: [Vec3::new(-1.0, -1.0, -5.0), Vec3::new(1.0, -1.0, -5.0), Vec3::new(0.0, 1.0, -5.0)],
            n: [Vec3::Z; 3],
            uv: [Vec2::ZERO; 3],
            material: 0,
            object: 0,
            two_sided: false,
        });
        let rd = RayDifferential { do_dx: Vec3::ZERO, do_dy: Vec3::ZERO, dd_dx: Vec3::new(0.01, 0.0, 0.003), dd_dy: Vec3::ZERO };
        let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
        let hit = scene.triangle_hit(0, Vec3::splat(1.0 / 3.0), 5.0, &ray);
        let hit = with_ray_differentials(&scene, &rd, &ray, hit);
        let out = reflected(&scene, &hit, ray.dir, hit.geometric_normal);
        assert!((out.dd_dx - Vec3::new(0.01, 0.0, -0.003)).length() < 1e-7, "{:?}", out.dd_dx);
        assert_eq!(out.do_dx, hit.diff.dp_dx);
    }
}
