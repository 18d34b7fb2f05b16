//! The reference ray caster (CGPP listings 15.13 to 15.20): every ray is
//! tested against every primitive, in scene order. It stays in the program as
//! the thing every faster method is checked against.

use super::intersect::{intersect_sphere, intersect_triangle};
use super::{cast_pass, cast_pixel};
use crate::math::{Radiance, Ray};
use crate::render::trace::{PixelTrace, PrimitiveTest, Recorder};
use crate::render::{PassJob, PreparedScene, RayCounts, Renderer, SceneQuery};
use crate::scene::{PrimitiveKind, SurfaceHit};

pub struct BruteForce;

impl Renderer for BruteForce {
    fn name(&self) -> &'static str {
        "raytrace:brute"
    }

    fn description(&self) -> &'static str {
        "the reference ray caster: every pixel tests every primitive in scene order (CGPP 15.4)"
    }

    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
        cast_pass(job, &BruteQuery(job.prepared), out)
    }

    fn trace_pixel(&self, job: &PassJob, x: u32, y: u32, rec: &mut PixelTrace) -> Option<Radiance> {
        Some(cast_pixel(job, &BruteQuery(job.prepared), x, y, &mut RayCounts::default(), rec))
    }
}

/// Closest-hit and shadow queries by testing every primitive.
pub struct BruteQuery<'a>(pub &'a PreparedScene);

impl SceneQuery for BruteQuery<'_> {
    fn closest<R: Recorder>(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<SurfaceHit> {
        let prepared = self.0;
        let mut best_t = t_max;
        let mut best: Option<(PrimitiveKind, u32, f32, f32)> = None;
        for (i, tri) in prepared.edges.iter().enumerate() {
            counts.tests += 1;
            let outcome = intersect_triangle(ray, tri, best_t);
            if R::ENABLED {
                rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Triangle, index: i as u32, outcome });
            }
            if let Ok((t, b1, b2)) = outcome {
                best_t = t;
                best = Some((PrimitiveKind::Triangle, i as u32, b1, b2));
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
                best = Some((PrimitiveKind::Sphere, i as u32, 0.0, 0.0));
            }
        }
        best.map(|(kind, i, b1, b2)| make_hit(prepared, kind, i, best_t, b1, b2, ray))
    }

    fn occluder<R: Recorder>(&self, ray: &Ray, t_max: f32, counts: &mut RayCounts, rec: &mut R) -> Option<(PrimitiveKind, u32, f32)> {
        let prepared = self.0;
        for (i, tri) in prepared.edges.iter().enumerate() {
            counts.tests += 1;
            let outcome = intersect_triangle(ray, tri, t_max);
            if R::ENABLED {
                rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Triangle, index: i as u32, outcome });
            }
            if let Ok((t, _, _)) = outcome {
                return Some((PrimitiveKind::Triangle, i as u32, t));
            }
        }
        for (i, s) in prepared.scene.spheres.iter().enumerate() {
            counts.tests += 1;
            let outcome = intersect_sphere(ray, s, t_max, false);
            if R::ENABLED {
                rec.primitive_test(PrimitiveTest { kind: PrimitiveKind::Sphere, index: i as u32, outcome: outcome.map(|t| (t, 0.0, 0.0)) });
            }
            if let Ok(t) = outcome {
                return Some((PrimitiveKind::Sphere, i as u32, t));
            }
        }
        None
    }
}

/// The `SurfaceHit` for a primitive found at `t` with barycentrics `(b1, b2)`.
pub fn make_hit(prepared: &PreparedScene, kind: PrimitiveKind, index: u32, t: f32, b1: f32, b2: f32, ray: &Ray) -> SurfaceHit {
    match kind {
        PrimitiveKind::Triangle => prepared.scene.triangle_hit(index, glam::Vec3::new(1.0 - b1 - b2, b1, b2), t, ray),
        PrimitiveKind::Sphere => prepared.scene.sphere_hit(index, t, ray),
    }
}
