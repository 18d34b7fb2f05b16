//! `shade()` for eight samples at once, as frames use it: the ray caster
//! hands over a row of its packet's tile, the rasterizers a run of visible
//! samples. Direct light runs eight lanes wide (`lighting::direct_light` on
//! `f32x8`, at the best SIMD level the CPU has); everything that follows
//! rays one sample at a time (ambient occlusion, indirect light, mirrors and
//! glass) is `shade()`'s own one-sample code, called per lane in the same
//! order. So each lane's value is bit for bit the value `shade()` gives that
//! sample alone, which is what pixel replays run.

use super::lighting::{self, IncidenceLanes, LightVisibility, SurfaceLanes};
use super::pixel_record::NoRecord;
use super::shade::{self, Incidence, Shading};
use super::{debug::View, gi::PathState, Interpolation, PassJob, RayCounts, SceneQuery, ShadowMode};
use crate::math::lanes::{mask_bits, mask_from_bits, simd_level, V3};
use crate::math::{Radiance, Vec3};
use crate::scene::hit_lanes::TriangleHitInput;
use crate::scene::{Scene, SurfaceHit};
use fearless_simd::{dispatch, f32x8, Simd, SimdFrom};

/// Samples per batch.
pub const LANES: usize = 8;

/// Whether frames of `job` are shaded in batches. Otherwise (debug views,
/// Gouraud's per-vertex shading, shadow maps and volumes, whose lookups
/// are per sample) every sample goes through `resolve_sample` alone.
pub fn batchable(job: &PassJob) -> bool {
    job.settings.view == View::Shaded
        && matches!(job.settings.interpolation, Interpolation::Phong | Interpolation::Flat)
        && matches!(job.settings.shadows, ShadowMode::Ray | ShadowMode::None)
}

/// What a lane holds before a sample is pushed into it (never shaded).
const UNUSED_HIT: SurfaceHit = SurfaceHit {
    position: Vec3::ZERO,
    geometric_normal: Vec3::Z,
    shading_normal: Vec3::Z,
    barycentric: Vec3::ZERO,
    uv: crate::math::Vec2::ZERO,
    t: 0.0,
    kind: crate::scene::PrimitiveKind::Triangle,
    primitive: 0,
    object: 0,
    material: 0,
    back_face: false,
    diff: crate::scene::Differentials::ZERO,
};

/// Up to eight samples that see a surface, with where their results go.
pub struct Batch {
    len: usize,
    /// The surfaces as `shade()` is handed them (flat shading's normal applied).
    hits: [SurfaceHit; LANES],
    w_o: [Vec3; LANES],
    pixels: [u32; LANES],
    /// The caller's index for each lane's result.
    pub slots: [usize; LANES],
    /// Triangle hits pushed but not built yet: their inputs and lanes.
    pending_inputs: [TriangleHitInput; LANES],
    pending_lanes: [usize; LANES],
    pending: usize,
}

impl Default for Batch {
    fn default() -> Self {
        Self::new()
    }
}

impl Batch {
    pub fn new() -> Batch {
        Batch {
            len: 0,
            hits: [UNUSED_HIT; LANES],
            w_o: [Vec3::ZERO; LANES],
            pixels: [0; LANES],
            slots: [0; LANES],
            pending_inputs: [TriangleHitInput::default(); LANES],
            pending_lanes: [0; LANES],
            pending: 0,
        }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub fn is_full(&self) -> bool {
        self.len == LANES
    }

    pub fn clear(&mut self) {
        self.len = 0;
        self.pending = 0;
    }

    /// `push` of the hit `Scene::triangle_hit` gives for these arguments.
    /// The record is built later, with the batch's other pending triangle
    /// hits, eight at a time (`build_pending`, before shading).
    #[inline]
    pub fn push_triangle(&mut self, index: u32, b: Vec3, t: f32, ray: &crate::math::Ray, pixel: u32, slot: usize) {
        let i = self.len;
        self.pending_inputs[self.pending] = TriangleHitInput { index, b, t, dir: ray.dir };
        self.pending_lanes[self.pending] = i;
        self.pending += 1;
        self.w_o[i] = -ray.dir;
        self.pixels[i] = pixel;
        self.slots[i] = slot;
        self.len += 1;
    }

    /// Builds the records `push_triangle` left pending, as `push` hands
    /// them to `shade()` with `interpolation`.
    pub fn build_pending(&mut self, scene: &Scene, interpolation: Interpolation) {
        let Batch { hits, pending_inputs, pending_lanes, pending, .. } = self;
        scene.triangle_hits(&pending_inputs[..*pending], |k, mut hit| {
            if interpolation == Interpolation::Flat {
                hit.shading_normal = hit.geometric_normal;
            }
            hits[pending_lanes[k]] = hit;
        });
        *pending = 0;
    }

    /// Adds the sample of pixel index `pixel` (the random numbers' key)
    /// whose eye ray along `dir` sees `hit`, its result meant for `slot`.
    /// The batch must not be full.
    #[inline]
    pub fn push(&mut self, interpolation: Interpolation, hit: &SurfaceHit, dir: Vec3, pixel: u32, slot: usize) {
        let i = self.len;
        self.hits[i] = match interpolation {
            Interpolation::Flat => SurfaceHit { shading_normal: hit.geometric_normal, ..*hit },
            _ => *hit,
        };
        self.w_o[i] = -dir;
        self.pixels[i] = pixel;
        self.slots[i] = slot;
        self.len += 1;
    }
}

/// Shades the batch's samples (depth 0, the eye's surfaces) and returns
/// their radiance in lane order. `blocked`, when given, holds per light the
/// lanes whose shadow ray towards it is blocked, traced ahead (a packet),
/// for every lane the light illuminates; otherwise shadow rays are cast
/// here.
pub fn shade_batch<Q: SceneQuery>(job: &PassJob, query: &Q, batch: &Batch, blocked: Option<&[u8]>, counts: &mut RayCounts) -> [Radiance; LANES] {
    assert!(batch.pending == 0, "shade_batch on a batch with hits not built (`build_pending`)");
    let scene = &job.prepared.scene;
    let settings = job.settings;
    let n = batch.len;
    let mut paths: [PathState; LANES] = std::array::from_fn(|i| {
        PathState::new(batch.pixels[i], job.sample, settings.spp, &settings.gi, job.photons)
    });
    let mut ambient = [Vec3::ZERO; LANES];
    let mut albedo = [Vec3::ZERO; LANES];
    let mut glossy = [Vec3::ZERO; LANES];
    let mut sharpness = [1.0f32; LANES];
    // Lanes past `len` repeat lane 0's geometry (so their arithmetic stays
    // tame) with a black material; their results are dropped.
    let mut position = [batch.hits[0].position; LANES];
    let mut normal = [batch.hits[0].shading_normal; LANES];
    let mut w_o = [batch.w_o[0]; LANES];
    for i in 0..n {
        let hit = &batch.hits[i];
        let material = &scene.materials[hit.material as usize];
        albedo[i] = shade::albedo_at(material, hit, settings);
        let mut sh = Shading { scene, query, settings, path: &mut paths[i], counts: &mut *counts, rec: &mut NoRecord };
        ambient[i] = shade::ambient_term(&mut sh, hit, albedo[i]);
        glossy[i] = material.glossy;
        sharpness[i] = material.sharpness;
        position[i] = hit.position;
        normal[i] = hit.shading_normal;
        w_o[i] = batch.w_o[i];
    }
    let inputs = DirectInputs { position, normal, w_o, albedo, glossy, sharpness, ambient };
    let mut visibility = BatchVisibility { job, query, hits: &batch.hits, live: ((1u32 << n) - 1) as u8, blocked, counts: &mut *counts };
    let direct = dispatch!(simd_level(), simd => direct_light8(simd, job, &inputs, &mut visibility));

    let mut out = [Radiance::ZERO; LANES];
    for i in 0..n {
        let hit = &batch.hits[i];
        let material = &scene.materials[hit.material as usize];
        if !shade::adds_after_direct(settings, material) {
            out[i] = direct[i];
            continue;
        }
        let mut sh = Shading { scene, query, settings, path: &mut paths[i], counts: &mut *counts, rec: &mut NoRecord };
        out[i] = shade::after_direct(&mut sh, hit, material, albedo[i], w_o[i], 0, direct[i]);
    }
    out
}

/// The per-lane values `direct_light8` gathers into vectors.
struct DirectInputs {
    position: [Vec3; LANES],
    normal: [Vec3; LANES],
    w_o: [Vec3; LANES],
    albedo: [Vec3; LANES],
    glossy: [Vec3; LANES],
    sharpness: [f32; LANES],
    ambient: [Vec3; LANES],
}

#[inline(always)]
fn direct_light8<S: Simd, Q: SceneQuery>(simd: S, job: &PassJob, inputs: &DirectInputs, visibility: &mut BatchVisibility<Q>) -> [Radiance; LANES] {
    let surface = SurfaceLanes {
        position: V3::gather(simd, &inputs.position),
        normal: V3::gather(simd, &inputs.normal),
        w_o: V3::gather(simd, &inputs.w_o),
        albedo: V3::gather(simd, &inputs.albedo),
        glossy: V3::gather(simd, &inputs.glossy),
        sharpness: f32x8::simd_from(simd, inputs.sharpness),
    };
    let start = V3::gather(simd, &inputs.ambient);
    lighting::direct_light(&job.prepared.scene.lights, &surface, start, visibility).scatter()
}

/// Visibility for a batch: the packet's answers when it traced them, else
/// `shade()`'s shadow ray per lit lane (the same ray: `Incidence` made from
/// the same lane arithmetic).
struct BatchVisibility<'b, 'j, Q> {
    job: &'b PassJob<'j>,
    query: &'b Q,
    hits: &'b [SurfaceHit; LANES],
    /// The lanes that hold samples.
    live: u8,
    blocked: Option<&'b [u8]>,
    counts: &'b mut RayCounts,
}

impl<S: Simd, Q: SceneQuery> LightVisibility<f32x8<S>> for BatchVisibility<'_, '_, Q> {
    #[inline(always)]
    fn visible(&mut self, light: usize, inc: &IncidenceLanes<f32x8<S>>, lit: fearless_simd::mask32x8<S>) -> fearless_simd::mask32x8<S> {
        let simd = inc.cos_theta.simd;
        if self.job.settings.shadows == ShadowMode::None {
            return mask_from_bits(simd, 0xff);
        }
        if let Some(blocked) = self.blocked {
            self.counts.shadow += (mask_bits(lit) & self.live).count_ones() as u64;
            return mask_from_bits(simd, !blocked[light]);
        }
        let visible = self.cast_shadow_rays(inc.w_i.scatter(), inc.distance.into(), inc.incident.scatter(), inc.cos_theta.into(), mask_bits(lit) & self.live);
        mask_from_bits(simd, visible)
    }
}

impl<Q: SceneQuery> BatchVisibility<'_, '_, Q> {
    /// Casts the shadow rays of the lanes in `lit` towards the light that
    /// arrives as given; the lanes it reaches unblocked.
    #[inline(never)]
    fn cast_shadow_rays(&mut self, w_i: [Vec3; LANES], distance: [f32; LANES], incident: [Vec3; LANES], cos_theta: [f32; LANES], lit: u8) -> u8 {
        let settings = self.job.settings;
        let scene = &self.job.prepared.scene;
        let mut visible = 0u8;
        let mut m = lit;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            let incidence = Incidence { w_i: w_i[i], distance: distance[i], incident: incident[i], cos_theta: cos_theta[i] };
            let (ray, t_max) = incidence.shadow_ray(scene, &self.hits[i], settings.shadow_bump, settings.terminator_lift);
            self.counts.shadow += 1;
            if self.query.occluder(&ray, t_max, self.counts, &mut NoRecord).is_none() {
                visible |= 1 << i;
            }
        }
        visible
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::pixel_record::NoRecord;
    use crate::render::raytrace::bvh::BvhQuery;
    use crate::render::gi::GiMode;
    use crate::render::{PreparedScene, RenderSettings};
    use crate::scene::builtin;
    use std::sync::atomic::AtomicBool;

    /// Eight (or fewer) samples shaded together give each sample's
    /// one-wide `shade()` value bit for bit: on every built-in scene (glossy,
    /// mirror, glass, several lights), with flat and Phong normals, with and
    /// without shadow rays, and with ambient occlusion's random rays.
    #[test]
    fn batches_equal_one_sample_shading() {
        let mut compared = 0;
        for name in builtin::names() {
            let prepared = PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap());
            let query = BvhQuery::new(&prepared);
            let (w, h) = (29u32, 19u32);
            let view = prepared.scene.camera.view(w, h);
            let cancel = AtomicBool::new(false);
            for (interpolation, shadows, gi) in [
                (Interpolation::Phong, ShadowMode::Ray, GiMode::None),
                (Interpolation::Flat, ShadowMode::None, GiMode::None),
                (Interpolation::Phong, ShadowMode::Ray, GiMode::Ao),
            ] {
                let mut settings = RenderSettings { interpolation, shadows, ..RenderSettings::for_scene(&prepared.scene) };
                settings.gi.mode = gi;
                let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: glam::Vec2::splat(0.5), sample: 0, photons: None, active: None, rows: 0..h, cancel: &cancel };
                assert!(batchable(&job));
                let mut batch = Batch::new();
                let mut expected = Vec::new();
                let mut check = |batch: &mut Batch, expected: &mut Vec<Radiance>| {
                    let got = shade_batch(&job, &query, batch, None, &mut RayCounts::default());
                    for j in 0..batch.len() {
                        assert_eq!(got[j].to_array().map(f32::to_bits), expected[j].to_array().map(f32::to_bits), "{name} {interpolation:?} {shadows:?} {gi:?} lane {j} of {}", batch.len());
                    }
                    compared += batch.len();
                    batch.clear();
                    expected.clear();
                };
                for (x, y) in (0..h).flat_map(|y| (0..w).map(move |x| (x, y))) {
                    let p = job.sample_position(x, y);
                    let ray = view.eye_ray(p.x, p.y);
                    let Some(hit) = query.closest(&ray, view.far_t(p.x, p.y), false, &mut RayCounts::default(), &mut NoRecord) else { continue };
                    let pixel = job.pixel_index(x, y);
                    let one = crate::render::resolve_sample(&job, &query, &ray, Some(&hit), pixel, &mut RayCounts::default(), &mut NoRecord);
                    batch.push(interpolation, &hit, ray.dir, pixel, 0);
                    expected.push(one);
                    // Odd-sized batches too: flush after five when the pixel index says so.
                    if batch.is_full() || (pixel % 7 == 0 && batch.len() == 5) {
                        check(&mut batch, &mut expected);
                    }
                }
                if !batch.is_empty() {
                    check(&mut batch, &mut expected);
                }
            }
        }
        assert!(compared > 3000, "only {compared} samples compared");
    }
}
