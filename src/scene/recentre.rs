//! Camera-relative rendering: moving the whole scene so that the camera sits
//! at the origin, as real-time engines do before rendering worlds whose
//! coordinates are large. Far from the origin an f32 resolves only coarse
//! steps (0.008 at 100,000), so hit points computed there miss their surfaces
//! by more than any ray bump; near the origin the same scene is exact again.

use crate::scene::{Light, Scene};
use crate::math::Vec3;

/// Translates every triangle, sphere, point light and the camera by minus
/// the camera's eye. Directional lights and everything else are unchanged;
/// the image is the same up to rounding, which is what it cures.
pub fn recentre_at_camera(scene: &mut Scene) {
    let origin = scene.camera.eye;
    translate_scene(scene, -origin);
}

fn translate_scene(scene: &mut Scene, by: Vec3) {
    scene.triangles.map_positions(|v| v + by);
    for s in &mut scene.spheres {
        s.center += by;
    }
    for l in &mut scene.lights {
        if let Light::Point { position, .. } = l {
            *position += by;
        }
    }
    scene.camera.eye += by;
    scene.camera.target += by;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_camera_moves_to_the_origin_and_the_scene_with_it() {
        let mut s = crate::scene::builtin::load_builtin("triangle-ground").unwrap().unwrap();
        s.camera.eye = Vec3::new(1.0, 2.0, 3.0);
        let before = s.clone();
        recentre_at_camera(&mut s);
        assert_eq!(s.camera.eye, Vec3::ZERO);
        assert_eq!(s.camera.target, before.camera.target - Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(s.triangles.at(0).v[1], before.triangles.at(0).v[1] - Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(s.triangles.at(0).n, before.triangles.at(0).n, "normals do not move");
        match (&s.lights[0], &before.lights[0]) {
            (Light::Point { position: a, .. }, Light::Point { position: b, .. }) => assert_eq!(*a, *b - Vec3::new(1.0, 2.0, 3.0)),
            _ => panic!("triangle-ground has a point light"),
        }
    }
}
