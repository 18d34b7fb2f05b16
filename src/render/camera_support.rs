//! Which cameras a renderer draws. The ray casters make each eye ray from
//! the camera itself (`PassJob::eye_ray`), so they draw every projection
//! and the thin lens. A rasterizer projects a triangle's corners and fills
//! the triangle between them, through one centre of projection with
//! perspective division: what it cannot draw, it refuses in one sentence.

use crate::scene::camera::Projection;
use crate::scene::Camera;

/// Why `renderer`, which rasterizes triangles through the pinhole's
/// perspective, cannot draw `camera`; `Ok` for a pinhole camera.
pub fn check_rasterized(renderer: &str, camera: &Camera) -> Result<(), String> {
    match camera.projection {
        Projection::Perspective => {}
        Projection::Orthographic { .. } => {
            return Err(format!(
                "{renderer} does not draw [camera] projection = \"orthographic\": its triangle set-up and depth buffer divide by depth for perspective; use raytrace:bvh or raytrace:brute"
            ))
        }
        p => {
            return Err(format!(
                "{renderer} cannot draw [camera] projection = \"{}\": a rasterizer fills each triangle between its projected corners, which needs straight lines to stay straight, and this projection bends them; use raytrace:bvh or raytrace:brute",
                p.name()
            ))
        }
    }
    if camera.aperture > 0.0 {
        return Err(format!(
            "{renderer} cannot draw [camera] aperture = {}: it projects every point through a single centre, so it has no lens to blur out of focus with; use raytrace:bvh or raytrace:brute, or aperture = 0",
            camera.aperture
        ));
    }
    Ok(())
}
