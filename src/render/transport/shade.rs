//! The one shading routine (CGPP listing 15.17): every renderer hands a
//! `SurfaceHit` to `shade()`. Lights, shadows, BSDF and secondary rays live
//! here and nowhere else.

use crate::render::transport::bsdf::{surface_lane, DeltaLobes, ShadingFrame};
use crate::render::transport::gi;
use crate::render::transport::gi::GiMode;
use crate::render::transport::lighting;
use crate::render::transport::sampled_light;
use crate::render::transport::arrival::Arrival;
use crate::render::transport::incidence::Incidence;
use crate::render::transport::shading::Shading;
use crate::render::transport::lighting::{IncidenceLanes, LightVisibility};
use crate::render::inspect::pixel_record::{LightSample, Recorder};
use crate::render::differentials::{self, RayDifferential};
use crate::render::{Reflections, RenderSettings, SceneQuery, ShadowMode};
use crate::math::lanes::V3;
use crate::math::{Radiance, Ray, Vec2, Vec3};
use crate::scene::material::PointLobes;
use crate::scene::{Differentials, Lighting, Material, Scene, SurfaceHit};
#[cfg(test)]
use std::f32::consts::PI;


/// Outgoing radiance towards `w_o` (unit, pointing away from the surface) at `hit`.
pub fn shade<Q: SceneQuery, R: Recorder>(
    sh: &mut Shading<Q, R>,
    hit: &SurfaceHit,
    w_o: Vec3,
    depth: u32,
) -> Radiance {
    let Shading { scene, .. } = *sh;
    let material = &scene.materials[hit.material as usize];
    let tint = scene.vertex_colour(hit.kind, hit.primitive, hit.barycentric);
    let lobes = lobes_at(material, hit.uv, &hit.diff, tint, sh.settings);
    let ambient = ambient_term(sh, || *hit, lobes.albedo);
    let surface = surface_lane(material, lobes, hit.position, ShadingFrame::at(scene, hit, material), w_o);
    let mut visibility = ShadowQueries { sh: &mut *sh, hit, depth, pending: PendingShadow::default() };
    let direct: Vec3 = lighting::direct_light(&scene.lights, scene.render.lighting, &surface, ambient.into(), &mut visibility).into();
    after_direct(sh, hit, material, lobes, w_o, depth, direct)
}

/// The lobes `shade()` lights at a hit with texture coordinates `uv`,
/// differentials `diff` and vertex colour `tint`: the material's textures
/// read there with the footprint and the chosen filter.
#[inline]
pub fn lobes_at(material: &Material, uv: Vec2, diff: &Differentials, tint: Vec3, settings: &RenderSettings) -> PointLobes {
    material.lobes_tinted(uv, &diff.footprint(), settings.texture_filter, tint)
}

/// The term `shade()` starts from, before the lights: the constant ambient,
/// dimmed by ambient occlusion with `--gi ao`; zero when indirect light is
/// traced or mapped instead. `hit` gives the surface's record, asked for
/// only where rays leave it (ambient occlusion), so that batches, which
/// keep their surfaces in lanes, assemble no record otherwise. Always
/// inlined: for most frames it is one product, cheaper than the call the
/// compiler sometimes left around it.
#[inline(always)]
pub fn ambient_term<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: impl FnOnce() -> SurfaceHit, albedo: Vec3) -> Radiance {
    let Shading { scene, query, settings, .. } = *sh;
    match settings.gi.mode {
        GiMode::None => albedo * scene.render.ambient,
        // The constant ambient term, dimmed where nearby geometry hides the sky.
        GiMode::Ao if scene.render.ambient != Vec3::ZERO && albedo != Vec3::ZERO => {
            let open = gi::ambient_occlusion(query, &hit(), &settings.gi, settings.shadow_bump, &mut sh.path.rng, sh.counts, sh.rec);
            albedo * scene.render.ambient * open
        }
        // Traced or mapped indirect light replaces the constant.
        GiMode::Ao | GiMode::Photons | GiMode::Path => Vec3::ZERO,
    }
}

/// Whether `after_direct` can add anything to a surface of `material`: a
/// frame without traced or mapped indirect light adds nothing to most
/// surfaces, and its batches skip the call.
#[inline(always)]
pub fn adds_after_direct(scene: &Scene, settings: &RenderSettings, material: &Material) -> bool {
    matches!(settings.gi.mode, GiMode::Path | GiMode::Photons) || material.has_secondary() || material.is_emissive() || scene.has_sampled_lights()
}

/// What `shade()` adds after the point and directional lights, in this
/// order: the surface's own emission, direct light from area lights and
/// the environment, traced or mapped indirect light, then mirror
/// reflection and refraction. `l_o` is the ambient term plus the point and
/// directional lights' light. Under `Lighting::Classic` a mirror blends:
/// what came before it is weighed by `1 - mirror` while the recursion
/// goes on, and kept whole where it stops (`--max-depth`), as the book's
/// tracer returns its local colour there.
#[inline]
pub fn after_direct<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, material: &Material, lobes: PointLobes, w_o: Vec3, depth: u32, mut l_o: Radiance) -> Radiance {
    let Shading { settings, .. } = *sh;
    if material.is_emissive() {
        l_o += sampled_light::emitted_seen(sh, hit, w_o);
    }
    l_o += sampled_light::sampled_direct(sh, hit, material, lobes, w_o, depth);
    match settings.gi.mode {
        GiMode::Path if depth < settings.gi.max_path_depth() => {
            l_o += indirect_path(sh, hit, material, lobes, w_o, depth);
        }
        GiMode::Photons => l_o += indirect_photons(sh, hit, material, lobes, w_o, depth),
        _ => {}
    }

    if material.has_secondary() {
        if settings.gi.mode == GiMode::Path {
            if depth < settings.gi.max_path_depth() {
                l_o += secondary_sampled(sh, hit, material, w_o, depth);
            }
        } else if depth < settings.max_depth {
            if sh.scene.render.lighting == Lighting::Classic {
                // The book's `reflective` r: (1 - r) local + r reflected
                // (`secondary` weighs the reflection by r).
                l_o *= Vec3::ONE - material.mirror;
            }
            l_o += secondary(sh, hit, material, w_o, depth);
        }
    }
    sh.rec.shaded(depth, l_o);
    l_o
}

/// What one light's visibility test found, kept for the recorder.
#[derive(Default)]
struct PendingShadow {
    shadow_ray: Option<(Ray, f32)>,
    blocker: Option<crate::render::Occluder>,
    volume_count: Option<i32>,
}

/// Visibility for one sample as `shade()` asks it: the shadow volume count
/// at the surface the eye sees, a shadow ray, or the light's shadow map;
/// every step recorded.
struct ShadowQueries<'s, 'a, 'p, Q, R> {
    sh: &'s mut Shading<'a, 'p, Q, R>,
    hit: &'s SurfaceHit,
    depth: u32,
    pending: PendingShadow,
}

impl<Q: SceneQuery, R: Recorder> LightVisibility<f32> for ShadowQueries<'_, '_, '_, Q, R> {
    #[inline]
    fn visible(&mut self, index: usize, inc: &IncidenceLanes<f32>, _lit: bool) -> bool {
        let Shading { scene, query, settings, .. } = *self.sh;
        let incidence = Incidence::from_lane(inc);
        let (hit, depth) = (self.hit, self.depth);
        let mut blocker = None;
        // Shadow volumes answer for the surface the eye sees (its stencil
        // count); every other surface falls back to a shadow ray.
        let volume_count = if settings.shadows == ShadowMode::Volume && depth == 0 { query.volume_count(index) } else { None };
        if volume_count.is_none() && matches!(settings.shadows, ShadowMode::Ray | ShadowMode::Volume) {
            let (ray, t_max) = incidence.shadow_ray(scene, hit, settings.shadow_bump, settings.terminator_lift);
            let sh = &mut *self.sh;
            sh.counts.shadow += 1;
            sh.rec.in_shadow_ray(true);
            sh.rec.ray(&ray, t_max, depth + 1);
            blocker = query.occluder(&ray, t_max, sh.counts, sh.rec);
            sh.rec.in_shadow_ray(false);
            self.pending.shadow_ray = Some((ray, t_max));
        } else if settings.shadows == ShadowMode::Map {
            // CGPP 15.6.5: no ray; the light's depth map says whether something
            // nearer to the light covers P (blocker t = how far before P it lies).
            if let Some(maps) = query.shadow_maps() {
                blocker = maps.occluder(scene, index, hit, incidence.w_i, settings.shadow_map_bias, settings.shadow_map_slope_bias, settings.terminator_lift);
            }
        }
        self.pending.blocker = blocker;
        self.pending.volume_count = volume_count;
        !(blocker.is_some() || volume_count.is_some_and(|c| c != 0))
    }

    #[inline]
    fn reflected(&mut self, index: usize, inc: &IncidenceLanes<f32>, _lit: bool, f: V3<f32>, contribution: V3<f32>) {
        let PendingShadow { shadow_ray, blocker, volume_count } = std::mem::take(&mut self.pending);
        if R::ENABLED {
            let Incidence { w_i, distance, incident, cos_theta } = Incidence::from_lane(inc);
            self.sh.rec.light(LightSample { light: index, w_i, distance, incident, cos_theta, shadow_ray, blocker, volume_count, bsdf: f.into(), contribution: contribution.into() });
        }
    }
}

/// Path tracing's indirect term: one direction sampled from the diffuse and
/// glossy lobes, the radiance found along it weighted by `f cos / pdf`.
fn indirect_path<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, material: &Material, lobes: PointLobes, w_o: Vec3, depth: u32) -> Radiance {
    let Shading { settings, .. } = *sh;
    let Some((w_i, weight, pdf)) = gi::sample_bounce(sh.scene, material, lobes, hit, w_o, depth, sh.path, sh.rec) else {
        return Vec3::ZERO;
    };
    let ray = hit.spawn_ray_front(w_i, settings.shadow_bump);
    weight * follow(sh, &ray, depth, false, weight, Arrival::Bsdf { pdf, from: hit.position })
}

/// `radiance_along` with the path's throughput multiplied by `weight` for
/// the rest of the path (Russian roulette reads it) and the ray chosen as
/// `arrival` says, both restored afterwards.
fn follow<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, ray: &Ray, depth: u32, inside: bool, weight: Vec3, arrival: Arrival) -> Radiance {
    let (before, arrived) = (sh.path.throughput, sh.path.arrival);
    sh.path.throughput *= weight;
    sh.path.arrival = arrival;
    let l = radiance_along(sh, ray, None, depth + 1, inside);
    sh.path.throughput = before;
    sh.path.arrival = arrived;
    l
}

/// Photon mapping's indirect term: the map's density estimate at diffuse
/// surfaces, or at the first hit a final gather of sampled rays whose hits
/// read the map.
fn indirect_photons<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, material: &Material, lobes: PointLobes, w_o: Vec3, depth: u32) -> Radiance {
    let Shading { settings, .. } = *sh;
    let Some(map) = sh.path.photons else { return Vec3::ZERO };
    let gather = settings.gi.final_gather;
    if depth == 0 && gather > 0 {
        let mut sum = Vec3::ZERO;
        for _ in 0..gather {
            let choice = sh.path.rng.next_f32();
            let u = sh.path.rng.next_2d();
            if let Some(s) = crate::render::transport::bsdf_sampling::sample_bsdf(material, lobes, ShadingFrame::at(sh.scene, hit, material), w_o, choice, u) {
                if s.w_i.dot(hit.geometric_normal) > 0.0 {
                    let ray = hit.spawn_ray_front(s.w_i, settings.shadow_bump);
                    sum += s.weight * follow(sh, &ray, depth, false, s.weight, Arrival::Gathered);
                }
            }
        }
        return sum / gather as f32;
    }
    if lobes.albedo == Vec3::ZERO && !material.has_glossy() {
        return Vec3::ZERO;
    }
    let l = map.radiance(hit, material, lobes, w_o, settings.gi.photon_k as usize);
    if R::ENABLED {
        sh.rec.photons(l);
    }
    l
}

/// Path tracing's delta lobes: one of mirror reflection and refraction,
/// chosen in proportion to its weight, instead of both.
fn secondary_sampled<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, material: &Material, w_o: Vec3, depth: u32) -> Radiance {
    let Shading { settings, .. } = *sh;
    let DeltaLobes { reflect_dir, reflect_weight, refract } = DeltaLobes::at(hit, material, w_o);
    let refract_weight = refract.map_or(Vec3::ZERO, |r| r.1);
    let (take_reflection, scale) = gi::choose_lobe(reflect_weight, refract_weight, &mut sh.path.rng);
    let (ray, weight, inside) = match refract {
        Some((dir, w)) if !take_reflection => (hit.spawn_ray_back(dir, settings.shadow_bump), w * scale, true),
        _ if reflect_weight != Vec3::ZERO => (hit.spawn_ray_front(reflect_dir, settings.shadow_bump), reflect_weight * scale, false),
        _ => return Vec3::ZERO,
    };
    let Some((survive, _)) = gi::roulette(depth, sh.path.throughput * weight, &mut sh.path.rng) else {
        return Vec3::ZERO;
    };
    let weight = weight * survive;
    weight * follow(sh, &ray, depth, inside, weight, Arrival::Direct)
}


/// Gouraud shading: `shade()` at the triangle's three vertices (each seen
/// from the eye), the results blended with the hit's barycentric weights.
/// Spheres have no vertices and are shaded per sample.
pub fn shade_gouraud<Q: SceneQuery, R: Recorder>(
    sh: &mut Shading<Q, R>,
    hit: &SurfaceHit,
    view: &crate::scene::CameraView,
) -> Radiance {
    let Shading { scene, .. } = *sh;
    if hit.kind != crate::scene::PrimitiveKind::Triangle {
        let w_o = view.toward_viewer(hit.position).normalize_or_zero();
        return shade(sh, hit, w_o, 0);
    }
    let tri = &scene.triangle(hit.primitive);
    let side = if hit.back_face { -1.0 } else { 1.0 };
    let mut l_o = Vec3::ZERO;
    for k in 0..3 {
        let mut b = Vec3::ZERO;
        b[k] = 1.0;
        let vertex = SurfaceHit {
            position: tri.v[k],
            shading_normal: tri.n[k] * side,
            barycentric: b,
            uv: tri.uv[k],
            ..*hit
        };
        let w_o = view.toward_viewer(tri.v[k]).normalize_or_zero();
        l_o += hit.barycentric[k] * shade(sh, &vertex, w_o, 0);
    }
    l_o
}

/// Faceted shading: `shade()` once, at the triangle's centroid (its
/// position, normal and uv there, seen from the eye), for every sample on
/// the triangle, so each triangle shows one value and the mesh's facets
/// and the seams between them show. Spheres have no facets and are shaded
/// per sample.
pub fn shade_faceted<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, view: &crate::scene::CameraView) -> Radiance {
    let Shading { scene, .. } = *sh;
    if hit.kind != crate::scene::PrimitiveKind::Triangle {
        let w_o = view.toward_viewer(hit.position).normalize_or_zero();
        return shade(sh, hit, w_o, 0);
    }
    let tri = &scene.triangle(hit.primitive);
    let side = if hit.back_face { -1.0 } else { 1.0 };
    let third = 1.0 / 3.0;
    let position = (tri.v[0] + tri.v[1] + tri.v[2]) * third;
    let normal = ((tri.n[0] + tri.n[1] + tri.n[2]) * side).normalize_or(hit.geometric_normal);
    let centroid = SurfaceHit {
        position,
        shading_normal: normal,
        barycentric: Vec3::splat(third),
        uv: (tri.uv[0] + tri.uv[1] + tri.uv[2]) * third,
        ..*hit
    };
    let w_o = view.toward_viewer(position).normalize_or_zero();
    shade(sh, &centroid, w_o, 0)
}

/// Perfect mirror reflection and Fresnel-weighted refraction.
fn secondary<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, material: &Material, w_o: Vec3, depth: u32) -> Radiance {
    let Shading { settings, .. } = *sh;
    let DeltaLobes { reflect_dir, reflect_weight, refract } = DeltaLobes::at(hit, material, w_o);
    let mut result = Vec3::ZERO;
    // Delta lobes: the light they find counts whole.
    let arrived = std::mem::take(&mut sh.path.arrival);
    if let Some((dir, weight)) = refract {
        let ray = hit.spawn_ray_back(dir, settings.shadow_bump);
        let rd = differentials::refracted(hit);
        sh.path.arrival = Arrival::Direct;
        result += weight * radiance_along(sh, &ray, Some(&rd), depth + 1, true);
    }
    if reflect_weight != Vec3::ZERO {
        sh.path.arrival = Arrival::Direct;
        result += reflect_weight * reflection(sh, hit, reflect_dir, -w_o, depth);
    }
    sh.path.arrival = arrived;
    result
}

/// What a mirror at `hit` reflects towards the eye along unit `dir`, the
/// ray having arrived along `d_in`: the traced ray's radiance (with its
/// differentials reflected), or with `--reflections env` the environment
/// looked up in `dir`, no ray cast.
fn reflection<Q: SceneQuery, R: Recorder>(sh: &mut Shading<Q, R>, hit: &SurfaceHit, dir: Vec3, d_in: Vec3, depth: u32) -> Radiance {
    let Shading { scene, settings, .. } = *sh;
    match settings.reflections {
        Reflections::Ray => {
            let ray = hit.spawn_ray_front(dir, settings.shadow_bump);
            let rd = differentials::reflected(scene, hit, d_in, hit.geometric_normal);
            radiance_along(sh, &ray, Some(&rd), depth + 1, false)
        }
        Reflections::Env => {
            let l = scene.miss_radiance(dir);
            sh.rec.shaded(depth + 1, l);
            l
        }
    }
}

/// Radiance along a secondary ray: closest hit, then `shade()`; the
/// environment or background on a miss. With differentials `rd` the hit
/// gets its footprint from them; without, the finest texture level.
pub fn radiance_along<Q: SceneQuery, R: Recorder>(
    sh: &mut Shading<Q, R>,
    ray: &Ray,
    rd: Option<&RayDifferential>,
    depth: u32,
    inside: bool,
) -> Radiance {
    let Shading { scene, query, .. } = *sh;
    sh.counts.secondary += 1;
    sh.rec.ray(ray, f32::INFINITY, depth);
    let mut hit = query.closest(ray, f32::INFINITY, inside, sh.counts, sh.rec);
    // Completed in place: the record is large, and copies of it showed up
    // in profiles of path-traced frames.
    if let Some(h) = hit.as_mut() {
        if let Some(rd) = rd.filter(|_| scene.has_textures()) {
            *h = differentials::with_ray_differentials(scene, rd, ray, *h);
        }
        crate::scene::normal_map::apply(scene, sh.settings.texture_filter, h);
    }
    sh.rec.closest(hit.as_ref());
    match &hit {
        Some(h) => shade(sh, h, -ray.dir, depth),
        None => {
            let l = sampled_light::miss_seen(sh, ray.dir);
            sh.rec.shaded(depth, l);
            l
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::transport::bsdf::bsdf;

    #[test]
    fn lambertian_is_albedo_over_pi() {
        let mut m = Material::black();
        m.lambertian = Vec3::new(0.5, 0.25, 1.0);
        let f = bsdf(&m, m.lambertian, Vec3::Z, Vec3::Z, Vec3::X);
        assert!((f - m.lambertian / PI).length() < 1e-7);
    }

    #[test]
    fn blinn_phong_peak_by_hand() {
        // At the mirror direction n.h = 1: f = k_G (s + 2)(s + 4) / (8 pi (2^(-s/2) + s)),
        // and 2^-50 vanishes beside 100.
        let mut m = Material::black();
        m.glossy = Vec3::splat(0.2);
        m.sharpness = 100.0;
        let w = Vec3::new(0.0, 0.6, 0.8);
        let w_o = Vec3::new(0.0, -0.6, 0.8);
        let f = bsdf(&m, Vec3::ZERO, Vec3::Z, w, w_o);
        assert!((f.x - 0.2 * 102.0 * 104.0 / (8.0 * PI * 100.0)).abs() < 1e-5, "{f}");
        // s = 2: 2^-1 = 0.5, so N = 4 * 6 / (8 pi * 2.5).
        m.sharpness = 2.0;
        let f = bsdf(&m, Vec3::ZERO, Vec3::Z, w, w_o);
        assert!((f.x - 0.2 * 24.0 / (8.0 * PI * 2.5)).abs() < 1e-6, "{f}");
    }
}
