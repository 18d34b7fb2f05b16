//! Analytic spheres in the rasterizer: never tessellated. Each sphere covers a
//! conservative screen-space box; every sample in it casts its eye ray at the
//! sphere with the ray tracer's own `intersect_sphere`, and the hit is
//! depth-tested against the triangles already drawn.

use crate::render::raster::rect::{sample_span, PixelRect};
use crate::render::raster::vis_buffer::{DepthKey, FragmentRecorder, VisBuffer};
use crate::math::{Vec2, Vec3};
use crate::render::accel::intersect::intersect_sphere;
use crate::render::SceneQuery;
use crate::scene::{CameraView, Sphere};

/// Pixels whose sample may see sphere `s`; the whole image when the sphere
/// reaches the near plane (its projection is then unbounded), `None` when it
/// lies entirely beyond the far plane or off screen.
pub fn sphere_bounds(view: &CameraView, s: &Sphere, off: Vec2) -> Option<PixelRect> {
    let c = view.to_camera(s.center);
    let r = s.radius;
    if -c.z - r >= view.far || -c.z + r <= view.near {
        return None;
    }
    let full = PixelRect::new(0, 0, view.width, view.height);
    if -c.z - r <= view.near {
        return Some(full);
    }
    // The camera-space cube around the sphere lies entirely in front of the
    // eye, so the projection of its 8 corners bounds the sphere's projection.
    let mut lo = Vec2::splat(f32::INFINITY);
    let mut hi = Vec2::splat(f32::NEG_INFINITY);
    for i in 0..8 {
        let corner = c + Vec3::new(
            if i & 1 == 0 { -r } else { r },
            if i & 2 == 0 { -r } else { r },
            if i & 4 == 0 { -r } else { r },
        );
        let p = view.project_camera(corner);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    // One pixel of margin for rounding: the ray test decides coverage.
    let (x0, x1) = sample_span(lo.x - 1.0, hi.x + 1.0, off.x, view.width);
    let (y0, y1) = sample_span(lo.y - 1.0, hi.y + 1.0, off.y, view.height);
    let rect = PixelRect::new(x0, y0, x1, y1);
    (!rect.is_empty()).then_some(rect)
}

/// Bounds of every sphere of the scene for this pass.
pub fn all_sphere_bounds(view: &CameraView, spheres: &[Sphere], off: Vec2) -> Vec<Option<PixelRect>> {
    spheres.iter().map(|s| sphere_bounds(view, s, off)).collect()
}

/// Draws every sphere (in scene order, after the triangles, as the ray caster
/// tests them) into the region of `vb`.
pub fn raster_spheres<Q: SceneQuery, R: FragmentRecorder>(vb: &mut VisBuffer<Q, R>, bounds: &[Option<PixelRect>]) {
    for (si, b) in bounds.iter().enumerate() {
        if let Some(b) = b {
            raster_sphere(vb, si as u32, *b);
        }
    }
}

/// Draws sphere `si`, whose bounds are `bounds`, into the region of `vb`:
/// every sample whose eye ray hits its front surface.
pub fn raster_sphere<Q: SceneQuery, R: FragmentRecorder>(vb: &mut VisBuffer<Q, R>, si: u32, bounds: PixelRect) {
    let job = vb.job;
    let view = job.view;
    let s = &job.prepared.scene.spheres[si as usize];
    let r = bounds.intersect(&vb.rect);
    if r.is_empty() {
        return;
    }
    vb.add_tested(r);
    for y in r.y0..r.y1 {
        for x in r.x0..r.x1 {
            let p = job.sample_position(x, y);
            let ray = view.eye_ray(p.x, p.y);
            let t_max = view.far_t(p.x, p.y);
            if let Ok(t) = intersect_sphere(&ray, s, t_max, false) {
                let key = match vb.key {
                    DepthKey::RayT => t,
                    // The eye ray starts on the near plane: depth = near + t / |d|.
                    DepthKey::NegInvZ => vb.enc.key_at_depth(view.near + t / view.camera_dir(p.x, p.y).length()),
                };
                vb.sphere_fragment(x, y, si, t, key);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Fov};

    #[test]
    fn bounds_contain_the_silhouette() {
        let cam = Camera { fov: Fov::Y(60.0), ..Camera::default() };
        let view = cam.view(200, 100);
        let s = Sphere { center: Vec3::new(0.7, -0.3, -4.0), radius: 0.8, material: 0, object: 0 };
        let b = sphere_bounds(&view, &s, Vec2::splat(0.5)).unwrap();
        // Every pixel whose eye ray hits the sphere lies inside the bounds.
        let mut hits = 0;
        for y in 0..100 {
            for x in 0..200 {
                let r = view.eye_ray(x as f32 + 0.5, y as f32 + 0.5);
                if intersect_sphere(&r, &s, 1e9, false).is_ok() {
                    hits += 1;
                    assert!(x >= b.x0 && x < b.x1 && y >= b.y0 && y < b.y1, "({x}, {y}) outside {b:?}");
                }
            }
        }
        assert!(hits > 100);
        // Behind the camera: nothing; straddling the near plane: everything.
        let behind = Sphere { center: Vec3::new(0.0, 0.0, 5.0), radius: 1.0, material: 0, object: 0 };
        assert_eq!(sphere_bounds(&view, &behind, Vec2::splat(0.5)), None);
        let around = Sphere { center: Vec3::new(0.0, 0.0, -0.5), radius: 1.0, material: 0, object: 0 };
        assert_eq!(sphere_bounds(&view, &around, Vec2::splat(0.5)), Some(PixelRect::new(0, 0, 200, 100)));
    }
}
