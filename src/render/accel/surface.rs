//! The surface record of a ray's hit on a primitive, as every ray query
//! builds it: triangles and spheres from the scene's own surface records,
//! CSG objects from their intervals (`csg::closest`).

use crate::math::{Ray, Vec2, Vec3};
use crate::render::accel::csg::closest;
use crate::scene::{Differentials, PrimitiveId, PrimitiveKind, Scene, SurfaceHit};

/// The surface record for a ray that hit primitive `id` at parameter `t`;
/// `(b1, b2)` are a triangle hit's barycentric weights of v1 and v2
/// (ignored for spheres). Both ray casters build their hits here.
#[inline]
pub fn primitive_hit(scene: &Scene, id: PrimitiveId, t: f32, b1: f32, b2: f32, ray: &Ray) -> SurfaceHit {
    match id.kind() {
        PrimitiveKind::Triangle => scene.triangle_hit(id.index(), Vec3::new(1.0 - b1 - b2, b1, b2), t, ray),
        PrimitiveKind::Sphere => scene.sphere_hit(id.index(), t, ray),
        // CSG hits are built by `render::accel::csg`, never from an id.
        PrimitiveKind::Csg => closest(scene, id.index(), ray, f32::INFINITY, true).unwrap_or(SurfaceHit {
            position: ray.at(t),
            geometric_normal: -ray.dir,
            shading_normal: -ray.dir,
            barycentric: Vec3::ZERO,
            uv: Vec2::ZERO,
            t,
            kind: PrimitiveKind::Csg,
            primitive: id.index(),
            object: 0,
            material: 0,
            back_face: false,
            diff: Differentials::ZERO,
        }),
    }
}
