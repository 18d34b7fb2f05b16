//! Direct light from lights that have extent: emissive surfaces (area
//! lights) and the environment. Unlike point and directional lights, whose
//! light arrives from one direction (`lighting::direct_light` sums them
//! exactly), these are estimated by sampling: `RenderSettings::light_samples`
//! points per light and shading point, stratified, each with a shadow ray.
//!
//! Light sampling alone is noisy where the BSDF is sharp and the light
//! large (a glossy highlight of a sky), and BSDF sampling alone where the
//! light is small; multiple importance sampling (Veach's power heuristic)
//! weights each strategy's samples by how well it samples them, and the sum
//! is never much worse than the better of the two. The BSDF strategy is the
//! path's own bounce with `--gi path` (its hit is weighted by `arrival_weight`),
//! and one extra sampled ray elsewhere.

use crate::math::{Radiance, Vec3};
use crate::render::inspect::pixel_record::{Recorder, SampledLight, SampledLightKind};
use crate::render::transport::bsdf::bsdf;
use crate::render::transport::bsdf_sampling::{bsdf_pdf, sample_bsdf};
use crate::render::transport::gi::GiMode;
use crate::render::transport::arrival::{power_heuristic, Arrival};
use crate::render::transport::incidence::Incidence;
use crate::render::transport::shading::Shading;
use crate::render::{SceneQuery, ShadowMode};
use crate::scene::emitters::emitted;
use crate::scene::material::PointLobes;
use crate::scene::{Material, SurfaceHit};

/// Whether the BSDF strategy is taken at all: with MIS on, and alone when
/// there are no light samples (`light_samples` 0, for comparison).
#[inline]
fn bsdf_strategy_on(settings: &crate::render::RenderSettings) -> bool {
    settings.mis || settings.light_samples == 0
}

/// Whether a path continues from a surface at `depth`, so that its own
/// bounce is the BSDF strategy there (`--gi path`).
#[inline]
fn path_continues<Q, R>(sh: &Shading<Q, R>, depth: u32) -> bool {
    let settings = sh.settings;
    settings.gi.mode == GiMode::Path && depth < settings.gi.max_path_depth()
}

/// Whether light samples at a surface at `depth` compete with a BSDF
/// strategy (and are weighted against it): with MIS on, where a path's
/// bounce or an extra BSDF-sampled ray is taken.
#[inline]
fn bsdf_strategy<Q, R>(sh: &Shading<Q, R>, depth: u32) -> bool {
    let settings = sh.settings;
    bsdf_strategy_on(settings) && (settings.gi.mode != GiMode::Path || path_continues(sh, depth))
}

/// The part of the radiance an emitter at `hit` sends towards `w_o` that
/// counts, given how the ray arrived (`PathState::arrival`).
pub fn emitted_seen<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, w_o: Vec3) -> Radiance {
    let Shading { scene, settings, .. } = *sh;
    let le = emitted(scene, hit, w_o);
    if le == Vec3::ZERO {
        return Vec3::ZERO;
    }
    match sh.path.arrival {
        Arrival::Direct => le,
        Arrival::Gathered => Vec3::ZERO,
        Arrival::Bsdf { pdf, from } => {
            if !bsdf_strategy_on(settings) {
                return Vec3::ZERO;
            }
            let light_pdf = settings.light_samples as f32 * scene.emitters.pdf(scene, from, hit);
            le * power_heuristic(pdf, light_pdf)
        }
    }
}

/// The part of what a ray that hits nothing sees (the environment or the
/// background) that counts, given how it arrived.
pub fn miss_seen<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, dir: Vec3) -> Radiance {
    let Shading { scene, settings, .. } = *sh;
    let l = scene.miss_radiance(dir);
    let Some(light) = scene.environment.as_ref().and_then(|e| e.light.as_ref()) else {
        return l;
    };
    match sh.path.arrival {
        Arrival::Direct => l,
        Arrival::Gathered => Vec3::ZERO,
        Arrival::Bsdf { pdf, .. } => {
            if !bsdf_strategy_on(settings) {
                return Vec3::ZERO;
            }
            l * power_heuristic(pdf, settings.light_samples as f32 * light.pdf(dir))
        }
    }
}

/// Direct light at `hit` from the area lights and the environment, seen
/// from `w_o`: their light samples, and (MIS on, outside `--gi path`) one
/// BSDF-sampled ray. With `light_samples` 0 the BSDF-sampled ray (or the
/// path's bounce) alone finds these lights: the strategy MIS is measured
/// against. Zero where the surface reflects nothing but by delta
/// lobes, or the scene has no such lights.
pub fn sampled_direct<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, material: &Material, lobes: PointLobes, w_o: Vec3, depth: u32) -> Radiance {
    let Shading { scene, settings, .. } = *sh;
    if !scene.has_sampled_lights() || (lobes.albedo == Vec3::ZERO && !material.has_glossy()) {
        return Vec3::ZERO;
    }
    let n = hit.shading_normal;
    let frame = crate::render::transport::bsdf::ShadingFrame::at(scene, hit, material);
    let count = settings.light_samples;
    let mis = bsdf_strategy(sh, depth);
    let mut l_o = Vec3::ZERO;
    let emitters = &scene.emitters;
    if !emitters.is_empty() && count > 0 {
        // Volumes give the hard shadow of each area light's centre, and maps
        // (filtered or not) one visibility for the whole light: asked once
        // per light and surface (kept on the stack for the first few
        // lights, asked again for the rest), and multiplying every sample
        // of that light.
        let mut whole_light = [None::<f32>; 8];
        for k in 0..count {
            let u_choose = (k as f32 + sh.path.rng.next_f32()) / count as f32;
            let u = sh.path.rng.next_2d();
            let Some(s) = emitters.sample(scene, hit.position, u_choose.min(0.999_999_94), u) else { continue };
            let cos = n.dot(s.w_i);
            if cos <= 0.0 || s.w_i.dot(hit.geometric_normal) <= 0.0 || s.radiance == Vec3::ZERO {
                continue;
            }
            let f = bsdf(material, lobes, frame, s.w_i, w_o);
            if f == Vec3::ZERO {
                continue;
            }
            let visibility = match settings.shadows {
                ShadowMode::None => 1.0,
                ShadowMode::Ray => unblocked(sh, hit, s.w_i, s.distance) as u8 as f32,
                ShadowMode::Map | ShadowMode::Volume => {
                    let light = s.light as usize;
                    match whole_light.get(light).copied().flatten() {
                        Some(v) => v,
                        None => {
                            let v = light_visibility(sh, hit, light);
                            if let Some(slot) = whole_light.get_mut(light) {
                                *slot = Some(v);
                            }
                            v
                        }
                    }
                }
            };
            let visible = visibility > 0.0;
            let weight = if mis { power_heuristic(count as f32 * s.pdf, bsdf_pdf(material, lobes, frame, w_o, s.w_i)) } else { 1.0 };
            let contribution = if visible { s.radiance * f * (cos * weight * visibility / (s.pdf * count as f32)) } else { Vec3::ZERO };
            l_o += contribution;
            if R::ENABLED {
                sh.rec.sampled_light(SampledLight { kind: SampledLightKind::Area(s.light), point: Some(s.point), w_i: s.w_i, pdf: s.pdf, mis_weight: weight, visible, contribution });
            }
        }
    }
    if let Some((env, light)) = scene.environment.as_ref().and_then(|e| Some((e, e.light.as_deref()?))).filter(|_| count > 0) {
        for _ in 0..count {
            let u = sh.path.rng.next_2d();
            let Some((uv, w_i, pdf)) = light.sample_uv(u) else { continue };
            let cos = n.dot(w_i);
            if cos <= 0.0 || w_i.dot(hit.geometric_normal) <= 0.0 {
                continue;
            }
            let f = bsdf(material, lobes, frame, w_i, w_o);
            let radiance = env.radiance_at(uv);
            if f == Vec3::ZERO || radiance == Vec3::ZERO {
                continue;
            }
            let visible = settings.shadows == ShadowMode::None || unblocked(sh, hit, w_i, f32::INFINITY);
            let weight = if mis { power_heuristic(count as f32 * pdf, bsdf_pdf(material, lobes, frame, w_o, w_i)) } else { 1.0 };
            let contribution = if visible { radiance * f * (cos * weight / (pdf * count as f32)) } else { Vec3::ZERO };
            l_o += contribution;
            if R::ENABLED {
                sh.rec.sampled_light(SampledLight { kind: SampledLightKind::Environment, point: None, w_i, pdf, mis_weight: weight, visible, contribution });
            }
        }
    }
    // The BSDF strategy's own ray, where no path bounce stands for it: with
    // MIS outside path tracing, and with no light samples wherever the path
    // does not go on (its last vertex, or no path at all).
    let extra_bsdf_ray = if count == 0 { !path_continues(sh, depth) } else { mis && settings.gi.mode != GiMode::Path };
    if extra_bsdf_ray {
        l_o += bsdf_sampled(sh, hit, material, lobes, w_o, count);
    }
    l_o
}

/// MIS's BSDF strategy outside path tracing: one direction sampled from
/// the BSDF, and the light it finds on an emitter or in the environment,
/// weighted against the light strategy's `count` samples.
fn bsdf_sampled<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, material: &Material, lobes: PointLobes, w_o: Vec3, count: u32) -> Radiance {
    let Shading { scene, query, settings, .. } = *sh;
    let choice = sh.path.rng.next_f32();
    let u = sh.path.rng.next_2d();
    let frame = crate::render::transport::bsdf::ShadingFrame::at(scene, hit, material);
    let Some(s) = sample_bsdf(material, lobes, frame, w_o, choice, u) else { return Vec3::ZERO };
    if s.w_i.dot(hit.geometric_normal) <= 0.0 {
        return Vec3::ZERO;
    }
    let ray = hit.spawn_ray_front(s.w_i, settings.shadow_bump);
    sh.counts.secondary += 1;
    sh.rec.ray(&ray, f32::INFINITY, 1);
    let found = query.closest(&ray, f32::INFINITY, false, sh.counts, sh.rec);
    sh.rec.closest(found.as_ref());
    let (radiance, light_pdf, kind, point) = match &found {
        Some(h) => {
            let le = emitted(scene, h, -s.w_i);
            let pdf = if le == Vec3::ZERO { 0.0 } else { scene.emitters.pdf(scene, hit.position, h) };
            (le, pdf, SampledLightKind::BsdfHit, Some(h.position))
        }
        None => match scene.environment.as_ref().and_then(|e| e.light.as_ref()) {
            Some(light) => (scene.miss_radiance(s.w_i), light.pdf(s.w_i), SampledLightKind::BsdfHit, None),
            None => (Vec3::ZERO, 0.0, SampledLightKind::BsdfHit, None),
        },
    };
    let weight = power_heuristic(s.pdf, count as f32 * light_pdf);
    let contribution = radiance * s.weight * weight;
    sh.rec.shaded(1, contribution);
    if R::ENABLED {
        sh.rec.sampled_light(SampledLight { kind, point, w_i: s.w_i, pdf: s.pdf, mis_weight: weight, visible: radiance != Vec3::ZERO, contribution });
    }
    contribution
}

/// The fraction of area light `light` that `hit` sees, as the shadow
/// approximations answer it: the light's shadow map (filtered as
/// `RenderSettings::shadow_filter` says), or else one shadow ray to the
/// light's centre (the hard shadow a volume or an unfiltered map of a point
/// there gives).
fn light_visibility<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, light: usize) -> f32 {
    let Shading { scene, query, settings, .. } = *sh;
    if settings.shadows == ShadowMode::Map {
        if let Some(v) = query.shadow_maps().and_then(|maps| maps.area_light_visibility(scene, light, hit, settings)) {
            return v;
        }
    }
    let to = scene.emitters.lights[light].centre - hit.position;
    let d = to.length();
    (d > 0.0 && unblocked(sh, hit, to / d, d)) as u8 as f32
}

/// Whether nothing blocks the way from `hit` along unit `w_i` for
/// `distance` (a shadow ray, counted and recorded).
fn unblocked<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, w_i: Vec3, distance: f32) -> bool {
    let Shading { scene, query, settings, .. } = *sh;
    let incidence = Incidence { w_i, distance, incident: Vec3::ONE, cos_theta: 1.0 };
    let (ray, t_max) = incidence.shadow_ray(scene, hit, settings.shadow_bump, settings.terminator_lift);
    // Stop short of the emitter's own surface, where rounding could find it.
    let t_max = if t_max.is_finite() { t_max * (1.0 - 1e-4) } else { t_max };
    sh.counts.shadow += 1;
    sh.rec.in_shadow_ray(true);
    sh.rec.ray(&ray, t_max, 1);
    let blocked = query.occluder(&ray, t_max, sh.counts, sh.rec).is_some();
    sh.rec.in_shadow_ray(false);
    !blocked
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_heuristic_by_hand() {
        assert_eq!(power_heuristic(1.0, 0.0), 1.0);
        assert_eq!(power_heuristic(0.0, 1.0), 0.0);
        assert!((power_heuristic(1.0, 2.0) - 0.2).abs() < 1e-7);
        assert!((power_heuristic(3.0, 1.0) + power_heuristic(1.0, 3.0) - 1.0).abs() < 1e-7);
        assert_eq!(power_heuristic(f32::INFINITY, 5.0), 1.0);
    }
}
