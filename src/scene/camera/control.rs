//! Camera navigation as plain functions on `Camera`: orbit, pan, dolly, fly
//! and frame-all. The viewer maps mouse and keys onto them.

use crate::scene::camera::{Camera, Fov};
use crate::math::{Mat3, Vec3};

/// Radians of orbit per pixel of drag.
const ORBIT_PER_PIXEL: f32 = 0.005;

/// Rotates the eye about the target: `dx` around the up axis, `dy` up and
/// down, stopping short of the poles so `up` never becomes parallel.
pub fn orbit(cam: &mut Camera, dx: f32, dy: f32) {
    let up = cam.up.normalize_or(Vec3::Y);
    let offset = cam.eye - cam.target;
    let yaw = Mat3::from_axis_angle(up, -dx * ORBIT_PER_PIXEL);
    let mut offset = yaw * offset;
    let right = offset.cross(up).normalize_or(Vec3::X);
    let pitched = Mat3::from_axis_angle(right, -dy * ORBIT_PER_PIXEL) * offset;
    // Keep at least ~1 degree away from the up axis.
    if pitched.normalize_or_zero().dot(up).abs() < 0.9998 {
        offset = pitched;
    }
    cam.eye = cam.target + offset;
}

/// Moves eye and target sideways so the point under the cursor follows it:
/// `dx`, `dy` in pixels of an image `height` pixels high.
pub fn pan(cam: &mut Camera, dx: f32, dy: f32, width: u32, height: u32) {
    let view = cam.view(width.max(1), height.max(1));
    let dist = (cam.target - cam.eye).length();
    let per_pixel = 2.0 * view.half_y * dist / height.max(1) as f32;
    let right = view.camera_to_world.x_axis;
    let up = view.camera_to_world.y_axis;
    let delta = (-right * dx + up * dy) * per_pixel;
    cam.eye += delta;
    cam.target += delta;
}

/// Moves the eye towards the target by a factor per wheel step (`steps` > 0: closer).
pub fn dolly(cam: &mut Camera, steps: f32) {
    let offset = cam.eye - cam.target;
    let factor = 0.9f32.powf(steps).clamp(0.01, 100.0);
    let new = offset * factor;
    if new.length() > cam.near * 1.01 {
        cam.eye = cam.target + new;
    }
}

/// Flies: moves eye and target together along the view (`forward`), right
/// and world-up axes by `distance` per unit of each component of `dir`.
pub fn fly(cam: &mut Camera, dir: Vec3, distance: f32) {
    let forward = (cam.target - cam.eye).normalize_or(Vec3::NEG_Z);
    let right = forward.cross(cam.up).normalize_or(Vec3::X);
    let up = cam.up.normalize_or(Vec3::Y);
    let delta = (right * dir.x + up * dir.y + forward * dir.z) * distance;
    cam.eye += delta;
    cam.target += delta;
}

/// Keeps the view direction and puts the whole bounding box in view.
pub fn frame_all(cam: &mut Camera, bounds: (Vec3, Vec3), width: u32, height: u32) {
    let (lo, hi) = bounds;
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo) * 0.5).length().max(1e-4);
    let forward = (cam.target - cam.eye).normalize_or(Vec3::NEG_Z);
    let view = cam.view(width.max(1), height.max(1));
    let half = view.half_x.min(view.half_y).atan();
    let dist = radius / half.sin().max(1e-3);
    cam.target = center;
    cam.eye = center - forward * dist;
    if cam.far < dist + radius {
        cam.far = (dist + radius) * 1.5;
    }
    if cam.near > (dist - radius).max(0.0) {
        cam.near = ((dist - radius) * 0.5).max(dist * 1e-3);
    }
}

/// A length for fly speed: the scene's size (so WASD feels the same at any scale).
pub fn scene_scale(bounds: Option<(Vec3, Vec3)>) -> f32 {
    bounds.map(|(lo, hi)| (hi - lo).length().max(1e-3)).unwrap_or(1.0)
}

/// The field of view in degrees and whether it is horizontal.
pub fn fov_parts(fov: Fov) -> (f32, bool) {
    match fov {
        Fov::X(d) => (d, true),
        Fov::Y(d) => (d, false),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_keeps_distance_and_target() {
        let mut c = Camera { eye: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, ..Camera::default() };
        orbit(&mut c, 100.0, 40.0);
        assert!((c.eye.length() - 5.0).abs() < 1e-4);
        assert_eq!(c.target, Vec3::ZERO);
        assert!(c.validate().is_ok());
        // Never past the pole.
        orbit(&mut c, 0.0, 10_000.0);
        assert!(c.validate().is_ok());
    }

    #[test]
    fn frame_all_sees_the_box() {
        let mut c = Camera { eye: Vec3::new(0.0, 0.0, 1.0), target: Vec3::ZERO, ..Camera::default() };
        frame_all(&mut c, (Vec3::splat(9.0), Vec3::splat(11.0)), 800, 500);
        let v = c.view(800, 500);
        for corner in [Vec3::splat(9.0), Vec3::splat(11.0), Vec3::new(9.0, 11.0, 9.0)] {
            let (p, _) = v.project(corner).unwrap();
            assert!(p.x >= 0.0 && p.x <= 800.0 && p.y >= 0.0 && p.y <= 500.0, "{p:?}");
        }
    }

    #[test]
    fn pan_moves_both() {
        let mut c = Camera { eye: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, ..Camera::default() };
        pan(&mut c, 10.0, 0.0, 100, 100);
        assert!(c.target.x < 0.0 && (c.eye.x - c.target.x).abs() < 1e-6);
    }
}
