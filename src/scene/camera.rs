//! The pinhole camera: eye rays for pixel positions and the inverse projection.
//!
//! Conventions (CGPP 15.4.1): the camera looks down its local -z, +y is up,
//! pixel (x, y) has its centre at (x + 0.5, y + 0.5) with y growing downwards.
//! Eye rays start on the near plane, so nothing nearer than `near` is seen by
//! the ray tracer, just as the rasterizer's near-plane clip removes it.

pub mod control;
pub mod projection;

pub use projection::Projection;

use crate::math::lanes::{Lane, V3};
use crate::math::{Mat3, Ray, Vec2, Vec3};

/// The field of view a camera may have, in degrees: narrower than this the
/// image plane is smaller than f32 can resolve, wider the projection blows up.
pub const MIN_FOV_DEG: f32 = 0.001;
pub const MAX_FOV_DEG: f32 = 179.9;

/// Which image edges the field of view spans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fov {
    /// Full angle between the left and right image edges, degrees.
    X(f32),
    /// Full angle between the top and bottom image edges, degrees.
    Y(f32),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov: Fov,
    pub near: f32,
    pub far: f32,
    pub projection: Projection,
    /// Thin lens radius in world units (0: a pinhole, everything sharp).
    pub aperture: f32,
    /// Distance along the view axis of the plane in focus (with an aperture).
    pub focus_distance: f32,
}

/// Where the plane in focus lies when a scene gives no `focus_distance`.
pub const DEFAULT_FOCUS_DISTANCE: f32 = 1.0;

impl Default for Camera {
    fn default() -> Self {
        Camera {
            eye: Vec3::ZERO,
            target: Vec3::new(0.0, 0.0, -1.0),
            up: Vec3::Y,
            fov: Fov::Y(60.0),
            near: 0.1,
            far: 100.0,
            projection: Projection::Perspective,
            aperture: 0.0,
            focus_distance: DEFAULT_FOCUS_DISTANCE,
        }
    }
}

impl Camera {
    /// Checks the camera can form an image; the message names the field at fault.
    pub fn validate(&self) -> Result<(), String> {
        use crate::input::MAX_COORDINATE;
        for (name, v) in [("eye", self.eye), ("target", self.target), ("up", self.up)] {
            if !crate::math::is_finite(v) {
                return Err(format!("camera.{name} is not finite"));
            }
        }
        for (name, v) in [("eye", self.eye), ("target", self.target)] {
            if v.abs().max_element() > MAX_COORDINATE {
                return Err(format!("camera.{name} is {v}; coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e}"));
            }
        }
        let forward = self.target - self.eye;
        if forward.length_squared() < 1e-20 {
            return Err("camera.eye and camera.target are the same point".into());
        }
        if forward.normalize().cross(crate::math::rescale_direction(self.up)).length_squared() < 1e-12 {
            return Err("camera.up is parallel to the view direction (or zero)".into());
        }
        let (deg, horizontal) = match self.fov {
            Fov::X(d) => (d, true),
            Fov::Y(d) => (d, false),
        };
        let max = self.projection.max_fov_deg(horizontal);
        if !((MIN_FOV_DEG..=max).contains(&deg)) {
            return Err(format!("camera field of view {deg} is not between {MIN_FOV_DEG} and {max} degrees"));
        }
        if let Projection::Orthographic { height } = self.projection {
            if !(height > 0.0 && height <= 2.0 * MAX_COORDINATE) {
                return Err(format!("camera.height is {height}; an orthographic view must be more than 0 and at most {:e} world units high", 2.0 * MAX_COORDINATE));
            }
        }
        if !(self.aperture >= 0.0 && self.aperture <= MAX_COORDINATE) {
            return Err(format!("camera.aperture is {}; the lens radius must be at least 0 (0 is a pinhole) and at most {MAX_COORDINATE:e}", self.aperture));
        }
        if !(self.focus_distance > 0.0 && self.focus_distance <= MAX_COORDINATE) {
            return Err(format!("camera.focus_distance is {}; the plane in focus must lie more than 0 and at most {MAX_COORDINATE:e} in front of the eye", self.focus_distance));
        }
        if self.aperture > 0.0 && self.projection != Projection::Perspective {
            return Err(format!("camera.aperture is {}, but a thin lens is modelled for the perspective projection only, not \"{}\"", self.aperture, self.projection.name()));
        }
        if !(self.near > 0.0 && self.near < self.far && self.far.is_finite()) {
            return Err(format!(
                "camera.near ({}) and camera.far ({}) must satisfy 0 < near < far",
                self.near, self.far
            ));
        }
        Ok(())
    }

    /// The view for one image size (aspect ratio fixes the other field of view).
    pub fn view(&self, width: u32, height: u32) -> CameraView {
        CameraView::new(self, width, height)
    }
}

/// A camera fixed to one resolution, with everything per-frame precomputed.
#[derive(Clone, Debug)]
pub struct CameraView {
    pub width: u32,
    pub height: u32,
    pub eye: Vec3,
    /// Columns: camera x (right), y (up), z (backwards) in world space.
    pub camera_to_world: Mat3,
    pub world_to_camera: Mat3,
    /// Half extents of the image at distance 1 in front of the eye: tan(fov / 2).
    pub half_x: f32,
    pub half_y: f32,
    pub near: f32,
    pub far: f32,
    /// What `half_x` and `half_y` measure, and how image positions become
    /// directions.
    pub projection: Projection,
    /// Thin lens radius (0: a pinhole) and the distance of the plane in focus.
    pub aperture: f32,
    pub focus_distance: f32,
}

impl CameraView {
    pub fn new(camera: &Camera, width: u32, height: u32) -> CameraView {
        let forward = (camera.target - camera.eye).normalize();
        let right = forward.cross(crate::math::rescale_direction(camera.up)).normalize();
        let up = right.cross(forward);
        let camera_to_world = Mat3::from_cols(right, up, -forward);
        let aspect = width as f32 / height as f32;
        let (half_x, half_y) = match (camera.projection, camera.fov) {
            (Projection::Orthographic { height }, _) => (0.5 * height * aspect, 0.5 * height),
            (p, Fov::X(deg)) => p.half_extents(deg, true, aspect),
            (p, Fov::Y(deg)) => p.half_extents(deg, false, aspect),
        };
        CameraView {
            width,
            height,
            eye: camera.eye,
            camera_to_world,
            world_to_camera: camera_to_world.transpose(),
            half_x,
            half_y,
            near: camera.near,
            far: camera.far,
            projection: camera.projection,
            aperture: camera.aperture,
            focus_distance: camera.focus_distance,
        }
    }

    /// Whether every eye ray leaves the eye itself through a plane image:
    /// perspective with no lens, the camera the ray casters' packets and
    /// their test for empty tiles are written for.
    pub fn is_pinhole(&self) -> bool {
        self.projection == Projection::Perspective && self.aperture == 0.0
    }

    /// Whether the eye rays are parallel (an orthographic camera): depth is
    /// then affine across the image and nothing divides by it.
    pub fn is_orthographic(&self) -> bool {
        matches!(self.projection, Projection::Orthographic { .. })
    }

    /// The image position `(px, py)` in pixels scaled to the half extents.
    #[inline]
    fn scaled(&self, px: f32, py: f32) -> (f32, f32) {
        let sx = (2.0 * px / self.width as f32 - 1.0) * self.half_x;
        let sy = (1.0 - 2.0 * py / self.height as f32) * self.half_y;
        (sx, sy)
    }

    /// Camera-space direction through the image position `(px, py)` in
    /// pixels (pixel centres are at +0.5): for the perspective projection
    /// the point of the image plane at z = -1.
    pub fn camera_dir(&self, px: f32, py: f32) -> Vec3 {
        let (sx, sy) = self.scaled(px, py);
        self.projection.direction(sx, sy)
    }

    /// The eye ray through image position `(px, py)`, starting on the near
    /// plane (the near sphere of a fisheye, the near cylinder of a
    /// panorama; orthographic rays start on the near plane beside the axis).
    pub fn eye_ray(&self, px: f32, py: f32) -> Ray {
        let d = self.camera_dir(px, py);
        let start = match self.projection {
            Projection::Orthographic { .. } => {
                let (sx, sy) = self.scaled(px, py);
                Vec3::new(sx, sy, -self.near)
            }
            _ => d * self.near,
        };
        let origin = self.eye + self.camera_to_world * start;
        Ray::new(origin, (self.camera_to_world * d).normalize())
    }

    /// The ray parameter at which an eye ray through `(px, py)` reaches the far plane.
    pub fn far_t(&self, px: f32, py: f32) -> f32 {
        (self.far - self.near) * self.camera_dir(px, py).length()
    }

    /// The eye ray through `(px, py)` leaving the thin lens at the point
    /// `lens` of the unit disk (scaled by the aperture), with the ray
    /// parameter of the far plane. Every ray through one image position
    /// meets the others on the plane in focus, at the point the pinhole's
    /// ray meets it. With no aperture it is `eye_ray` and `far_t` exactly.
    pub fn eye_ray_through_lens(&self, px: f32, py: f32, lens: Vec2) -> (Ray, f32) {
        if self.aperture == 0.0 {
            return (self.eye_ray(px, py), self.far_t(px, py));
        }
        let focus = self.camera_dir(px, py) * self.focus_distance;
        let on_lens = Vec3::new(lens.x * self.aperture, lens.y * self.aperture, 0.0);
        let d = focus - on_lens;
        // The line leaves the lens (depth 0) and reaches the plane in focus at
        // depth `focus_distance`: depths along it are linear in the parameter.
        let per_depth = 1.0 / self.focus_distance;
        let start = on_lens + d * (self.near * per_depth);
        let ray = Ray::new(self.eye + self.camera_to_world * start, (self.camera_to_world * d).normalize());
        (ray, (self.far - self.near) * per_depth * d.length())
    }

    /// `camera_dir` of the perspective and orthographic projections (the
    /// straight ones a rasterizer draws) for lanes of image positions, with its arithmetic in
    /// the same order (glam's), so a tile's eye rays made eight at a time
    /// are bit for bit the ones `eye_ray` makes for a pixel replay (a test
    /// holds them to it). The one-pixel functions above stay in glam's form,
    /// which the compiler turns into fewer instructions for a single ray.
    #[inline(always)]
    pub fn camera_dir_lanes<L: Lane>(&self, px: L, py: L) -> V3<L> {
        if let Projection::Orthographic { .. } = self.projection {
            return V3::new(px.splat(0.0), px.splat(0.0), px.splat(-1.0));
        }
        let (one, two) = (px.splat(1.0), px.splat(2.0));
        let sx = (two * px / px.splat(self.width as f32) - one) * px.splat(self.half_x);
        let sy = (one - two * py / px.splat(self.height as f32)) * px.splat(self.half_y);
        V3::new(sx, sy, px.splat(-1.0))
    }

    /// `eye_ray` for lanes: origins and unit directions. Orthographic rays
    /// start beside the axis, at the image position on the near plane.
    #[inline(always)]
    pub fn eye_ray_lanes<L: Lane>(&self, px: L, py: L) -> (V3<L>, V3<L>) {
        let d = self.camera_dir_lanes(px, py);
        let start = match self.projection {
            Projection::Orthographic { .. } => {
                let (one, two) = (px.splat(1.0), px.splat(2.0));
                let sx = (two * px / px.splat(self.width as f32) - one) * px.splat(self.half_x);
                let sy = (one - two * py / px.splat(self.height as f32)) * px.splat(self.half_y);
                V3::new(sx, sy, px.splat(-self.near))
            }
            _ => d.scale(px.splat(self.near)),
        };
        let origin = V3::splat(px, self.eye) + self.to_world_lanes(start);
        (origin, self.to_world_lanes(d).normalize())
    }

    /// `far_t` for lanes.
    #[inline(always)]
    pub fn far_t_lanes<L: Lane>(&self, px: L, py: L) -> L {
        px.splat(self.far - self.near) * self.camera_dir_lanes(px, py).length()
    }

    /// `camera_to_world * v` with glam's arithmetic: the columns scaled by
    /// v's components and added left to right.
    #[inline(always)]
    fn to_world_lanes<L: Lane>(&self, v: V3<L>) -> V3<L> {
        let m = &self.camera_to_world;
        V3::splat(v.x, m.x_axis).scale(v.x) + V3::splat(v.y, m.y_axis).scale(v.y) + V3::splat(v.z, m.z_axis).scale(v.z)
    }

    pub fn to_camera(&self, world: Vec3) -> Vec3 {
        self.world_to_camera * (world - self.eye)
    }

    /// Distance along the view axis (camera -z) of a world point.
    pub fn view_depth(&self, world: Vec3) -> f32 {
        -self.to_camera(world).z
    }

    /// Projects a camera-space point with z < 0 to image position (pixels) .
    pub fn project_camera(&self, c: Vec3) -> Vec2 {
        if self.projection == Projection::Perspective {
            let inv = 1.0 / -c.z;
            return Vec2::new(
                (c.x * inv / self.half_x + 1.0) * 0.5 * self.width as f32,
                (1.0 - c.y * inv / self.half_y) * 0.5 * self.height as f32,
            );
        }
        let (sx, sy) = self.projection.image_of(c);
        Vec2::new((sx / self.half_x + 1.0) * 0.5 * self.width as f32, (1.0 - sy / self.half_y) * 0.5 * self.height as f32)
    }

    /// Projects a world point to image position and view depth; `None` when
    /// the point is not beyond the near plane (sphere, cylinder).
    pub fn project(&self, world: Vec3) -> Option<(Vec2, f32)> {
        let c = self.to_camera(world);
        if !self.projection.beyond_near(c, self.near) {
            return None;
        }
        Some((self.project_camera(c), -c.z))
    }

    /// The world point at view depth `depth` seen at image position `(px, py)`.
    pub fn point_at_depth(&self, px: f32, py: f32, depth: f32) -> Vec3 {
        match self.projection {
            Projection::Orthographic { .. } => {
                let (sx, sy) = self.scaled(px, py);
                self.eye + self.camera_to_world * Vec3::new(sx, sy, -depth)
            }
            _ => {
                let d = self.camera_dir(px, py);
                self.eye + self.camera_to_world * (d * (depth / -d.z))
            }
        }
    }

    /// Unit world-space view direction (camera -z).
    pub fn forward(&self) -> Vec3 {
        -self.camera_to_world.z_axis
    }

    /// The world direction (not of unit length) from `p` back towards
    /// the camera along the eye ray that sees it: towards the eye for the
    /// projections through one centre, the camera's backward axis for
    /// parallel rays, whose eye lies at infinity.
    pub fn toward_viewer(&self, p: Vec3) -> Vec3 {
        match self.projection {
            Projection::Orthographic { .. } => self.camera_to_world.z_axis,
            _ => self.eye - p,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn book_camera() -> CameraView {
        // CGPP 15.3.4: at the origin, looking down -z, 90 degree horizontal fov, 800x500.
        let cam = Camera { fov: Fov::X(90.0), near: 0.1, far: 100.0, ..Camera::default() };
        cam.view(800, 500)
    }

    /// Tiles make their eye rays eight at a time (`eye_ray_lanes`), replays
    /// one at a time (`eye_ray`): they must be the same rays, bit for bit,
    /// or a replay would not reproduce its pixel.
    #[test]
    fn eye_rays_in_lanes_are_the_single_rays_bit_for_bit() {
        use fearless_simd::{dispatch, f32x8, SimdFrom};
        let cameras = [
            book_camera(),
            Camera { eye: Vec3::new(0.3, 1.7, -2.9), target: Vec3::new(-0.4, 0.2, 0.5), fov: Fov::Y(37.0), near: 0.013, far: 71.0, ..Camera::default() }.view(641, 359),
            // Parallel rays, which a rasterizer's shading makes in lanes too.
            Camera { eye: Vec3::new(0.3, 1.7, -2.9), target: Vec3::new(-0.4, 0.2, 0.5), projection: Projection::Orthographic { height: 3.1 }, near: 0.013, far: 71.0, ..Camera::default() }.view(641, 359),
        ];
        for view in &cameras {
            let mut state = 0x2545_f491_u32;
            let mut next = move || {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                state as f32 / u32::MAX as f32
            };
            for _ in 0..500 {
                let px: [f32; 8] = std::array::from_fn(|_| next() * view.width as f32);
                let py: [f32; 8] = std::array::from_fn(|_| next() * view.height as f32);
                let (origin, dir, far) = dispatch!(crate::math::lanes::simd_level(), simd => {
                    let (o, d) = view.eye_ray_lanes(f32x8::simd_from(simd, px), f32x8::simd_from(simd, py));
                    let far: [f32; 8] = view.far_t_lanes(f32x8::simd_from(simd, px), f32x8::simd_from(simd, py)).into();
                    (o.scatter(), d.scatter(), far)
                });
                for k in 0..8 {
                    let ray = view.eye_ray(px[k], py[k]);
                    let one = view.eye_ray_lanes(px[k], py[k]);
                    for (a, b) in [(ray.origin, origin[k]), (ray.dir, dir[k]), (ray.origin, Vec3::from(one.0)), (ray.dir, Vec3::from(one.1))] {
                        assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits), "({}, {})", px[k], py[k]);
                    }
                    assert_eq!(view.far_t(px[k], py[k]).to_bits(), far[k].to_bits());
                    assert_eq!(view.camera_dir(px[k], py[k]), Vec3::from(view.camera_dir_lanes(px[k], py[k])));
                }
            }
        }
    }

    #[test]
    fn centre_pixel_ray_looks_down_minus_z() {
        let v = book_camera();
        let r = v.eye_ray(400.0, 250.0);
        assert!((r.dir - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        assert!((r.origin - Vec3::new(0.0, 0.0, -0.1)).length() < 1e-6);
    }

    #[test]
    fn pixel_zero_zero_by_hand() {
        // Pixel (0, 0) centre (0.5, 0.5): s = 2 tan 45 = 2, aspect 500/800.
        // x = (0.5/800 - 0.5) * 2 = -0.99875, y = -(0.5/500 - 0.5) * 2 * 0.625 = 0.62375.
        let v = book_camera();
        let r = v.eye_ray(0.5, 0.5);
        let d = Vec3::new(-0.99875, 0.62375, -1.0);
        assert!((r.dir - d.normalize()).length() < 1e-6, "{:?}", r.dir);
        assert!((r.origin - d * 0.1).length() < 1e-6, "{:?}", r.origin);
    }

    #[test]
    fn last_pixel_is_mirror_of_first() {
        let v = book_camera();
        let a = v.eye_ray(0.5, 0.5).dir;
        let b = v.eye_ray(799.5, 499.5).dir;
        assert!((a + Vec3::new(b.x, b.y, -b.z)).length() < 1e-6);
    }

    #[test]
    fn fov_y_sets_vertical_edges() {
        let cam = Camera { fov: Fov::Y(90.0), ..Camera::default() };
        let v = cam.view(200, 100);
        // Top edge of the image at 45 degrees above the axis.
        let r = v.eye_ray(100.0, 0.0);
        assert!((r.dir.y / -r.dir.z - 1.0).abs() < 1e-6);
        // Horizontal extent follows the 2:1 aspect.
        let r = v.eye_ray(200.0, 50.0);
        assert!((r.dir.x / -r.dir.z - 2.0).abs() < 1e-6);
    }

    #[test]
    fn projection_inverts_eye_ray() {
        let cam = Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(-1.0, 0.5, -2.0),
            up: Vec3::Y,
            fov: Fov::Y(40.0),
            near: 0.05,
            far: 50.0,
            ..Camera::default()
        };
        let v = cam.view(640, 360);
        for &(px, py) in &[(0.5, 0.5), (320.0, 180.0), (600.25, 17.75), (12.0, 359.0)] {
            let r = v.eye_ray(px, py);
            let p = r.at(7.0);
            let (q, depth) = v.project(p).unwrap();
            assert!((q - Vec2::new(px, py)).length() < 2e-3, "{q:?} vs {px},{py}");
            assert!((depth - v.view_depth(p)).abs() < 1e-5);
        }
    }

    #[test]
    fn project_by_hand() {
        // A point on the axis at depth 2 lands at the image centre; a point at
        // x = 2 (the 45 degree edge at depth 2) lands on the right edge.
        let v = book_camera();
        let (q, d) = v.project(Vec3::new(0.0, 0.0, -2.0)).unwrap();
        assert_eq!((q, d), (Vec2::new(400.0, 250.0), 2.0));
        let (q, _) = v.project(Vec3::new(2.0, 0.0, -2.0)).unwrap();
        assert!((q.x - 800.0).abs() < 1e-4);
        assert!(v.project(Vec3::new(0.0, 0.0, -0.05)).is_none());
    }

    #[test]
    fn far_t_reaches_far_plane() {
        let v = book_camera();
        let r = v.eye_ray(10.5, 20.5);
        let p = r.at(v.far_t(10.5, 20.5));
        assert!((v.view_depth(p) - 100.0).abs() < 1e-3);
    }

    #[test]
    fn validate_rejects_bad_cameras() {
        let mut c = Camera::default();
        c.near = 0.0;
        assert!(c.validate().unwrap_err().contains("near"));
        let mut c = Camera::default();
        c.up = Vec3::new(0.0, 0.0, 1.0);
        assert!(c.validate().unwrap_err().contains("up"));
        let mut c = Camera::default();
        c.eye.x = f32::NAN;
        assert!(c.validate().unwrap_err().contains("eye"));
        let mut c = Camera::default();
        c.fov = Fov::Y(1e-45);
        assert!(c.validate().unwrap_err().contains("between 0.001 and 179.9"));
        let mut c = Camera::default();
        c.eye.z = 1e20;
        assert!(c.validate().unwrap_err().contains("between -1e6 and 1e6"));
        // A huge up vector is a direction like any other.
        let mut c = Camera::default();
        c.up = Vec3::new(0.0, 1e20, 0.0);
        assert!(c.validate().is_ok());
        assert_eq!(c.view(8, 6).eye_ray(4.0, 3.0).dir, Camera::default().view(8, 6).eye_ray(4.0, 3.0).dir);
    }
}
