//! Which cameras a renderer draws. The ray casters make each eye ray from
//! the camera itself (`PassJob::eye_ray`), so they draw every projection
//! and the thin lens. A rasterizer projects a triangle's corners and fills
//! the triangle between them: it draws the projections that keep straight
//! lines straight, through one centre (perspective) or along parallel rays
//! (orthographic), and refuses the rest in one sentence.

use crate::scene::camera::Projection;
use crate::scene::Camera;

/// Why `renderer`, which rasterizes triangles between their projected
/// corners, cannot draw `camera`; `Ok` for a pinhole or orthographic camera.
pub fn check_rasterized(renderer: &str, camera: &Camera) -> Result<(), String> {
    if !camera.projection.keeps_lines_straight() {
        return Err(format!(
            "{renderer} cannot draw [camera] projection = \"{}\": a rasterizer fills each triangle between its projected corners, which needs straight lines to stay straight, and this projection bends them; use raytrace:bvh or raytrace:brute",
            camera.projection.name()
        ));
    }
    if camera.aperture > 0.0 {
        return Err(format!(
            "{renderer} cannot draw [camera] aperture = {}: it projects every point through a single centre, so it has no lens to blur out of focus with; use raytrace:bvh or raytrace:brute, or aperture = 0",
            camera.aperture
        ));
    }
    Ok(())
}

/// `check_rasterized` for a rasterizer that orders surfaces by which side
/// of each other's planes the eye point lies on (the painter's algorithm),
/// which parallel rays, coming from no point, do not give it.
pub fn check_rasterized_from_a_point(renderer: &str, camera: &Camera) -> Result<(), String> {
    if let Projection::Orthographic { .. } = camera.projection {
        return Err(format!(
            "{renderer} does not draw [camera] projection = \"orthographic\": its draw order asks which side of a triangle's plane the eye point lies on, and parallel rays leave from no point; use rasterize:fixed, raytrace:bvh or raytrace:brute"
        ));
    }
    check_rasterized(renderer, camera)
}
