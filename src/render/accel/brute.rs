//! The reference ray caster (CGPP listings 15.13 to 15.20): every ray is
//! tested against every primitive, in scene order. It stays in the program as
//! the thing every faster method is checked against. A triangle met where
//! its material is cut away (alpha below the cutoff) is passed through.

use crate::render::accel::intersect::{intersect_sphere, intersect_triangle};
use crate::math::Ray;
use crate::render::inspect::pixel_record::{PrimitiveTest, Recorder};
use crate::render::{Occluder, PreparedScene, RayCounts, SceneQuery};
use crate::scene::{PrimitiveId, PrimitiveKind, SurfaceHit};

/// Closest-hit and shadow queries by testing every primitive.
pub struct BruteQuery<'a>(pub &'a PreparedScene);

impl SceneQuery for BruteQuery<'_> {
    fn closest<R: Recorder>(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<SurfaceHit> {
        let prepared = self.0;
        let cutouts = prepared.scene.has_cutouts();
        let mut best_t = t_max;
        let mut best: Option<(PrimitiveId, f32, f32)> = None;
        for (i, tri) in prepared.edges.iter().enumerate() {
            counts.tests += 1;
            let outcome = intersect_triangle(ray, tri, best_t);
            if R::ENABLED {
                rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Triangle, index: i as u32, outcome });
            }
            if let Ok((t, b1, b2)) = outcome {
                // A cut-away point is no hit: the ray passes through it.
                if cutouts && prepared.scene.cut_out_at(i as u32, b1, b2) {
                    continue;
                }
                best_t = t;
                best = Some((PrimitiveId::triangle(i as u32), b1, b2));
            }
        }
        for (i, s) in prepared.scene.spheres.iter().enumerate() {
            counts.tests += 1;
            let outcome = intersect_sphere(ray, s, best_t, inside);
            if R::ENABLED {
                rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Sphere, index: i as u32, outcome: outcome.map(|t| (t, 0.0, 0.0)) });
            }
            if let Ok(t) = outcome {
                best_t = t;
                best = Some((PrimitiveId::sphere(i as u32), 0.0, 0.0));
            }
        }
        // CSG objects after every primitive, as they come in id order.
        if let Some(h) = crate::render::accel::csg::closest_in_scene(&prepared.scene, ray, best_t, inside, counts) {
            return Some(h);
        }
        best.map(|(id, b1, b2)| crate::render::accel::surface::primitive_hit(&prepared.scene, id, best_t, b1, b2, ray))
    }

    fn occluder<R: Recorder>(&self, ray: &Ray, t_max: f32, counts: &mut RayCounts, rec: &mut R) -> Option<Occluder> {
        let prepared = self.0;
        let cutouts = prepared.scene.has_cutouts();
        for (i, tri) in prepared.edges.iter().enumerate() {
            counts.tests += 1;
            let outcome = intersect_triangle(ray, tri, t_max);
            if R::ENABLED {
                rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Triangle, index: i as u32, outcome });
            }
            if let Ok((t, b1, b2)) = outcome {
                if cutouts && prepared.scene.cut_out_at(i as u32, b1, b2) {
                    continue;
                }
                return Some(Occluder { kind: PrimitiveKind::Triangle, index: i as u32, t });
            }
        }
        for (i, s) in prepared.scene.spheres.iter().enumerate() {
            counts.tests += 1;
            let outcome = intersect_sphere(ray, s, t_max, false);
            if R::ENABLED {
                rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Sphere, index: i as u32, outcome: outcome.map(|t| (t, 0.0, 0.0)) });
            }
            if let Ok(t) = outcome {
                return Some(Occluder { kind: PrimitiveKind::Sphere, index: i as u32, t });
            }
        }
        crate::render::accel::csg::occluder_in_scene(&prepared.scene, ray, t_max, counts)
    }
}
