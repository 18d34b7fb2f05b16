//! `shade()` for eight samples at once, as frames use it: the ray caster
//! hands over a row of its packet's tile, the rasterizers a run of visible
//! samples. Direct light runs eight lanes wide (`lighting::direct_light` on
//! `f32x8`, at the best SIMD level the CPU has), or sixteen for two batches
//! lit by direct light alone (`shade_batch_pair`). Frames hand path-traced
//! samples on to a `path_batch::PathPool` (`path_batch::start_paths`); everything else that
//! follows rays one sample at a time (ambient occlusion, photon gathers,
//! mirrors and glass) is `shade()`'s own one-sample code, called per lane in
//! the same order. So each lane's value is bit for bit the value `shade()`
//! gives that sample alone, which is what pixel replays run.

use crate::render::transport::lighting;
use crate::render::transport::lighting::{DiffuseLanes, FresnelLanes, IncidenceLanes, LightVisibility, SurfaceLanes};
use crate::render::inspect::pixel_record::NoRecord;
use crate::render::transport::shade;
use crate::render::transport::incidence::Incidence;
use crate::render::transport::shading::Shading;
use crate::render::inspect::debug::View;
use crate::render::transport::gi::{GiMode, PathState};
use crate::render::{Interpolation, PassJob, RayCounts, SceneQuery, ShadowMode};
use crate::math::lanes::{mask_bits, mask_from_bits, simd_level, Lane, V3};
use crate::math::{Radiance, Ray, Vec2, Vec3};
use crate::scene::hit_lanes::{EyeSamples, Floats, HitLanes, TriangleHitInput};
use crate::scene::{CameraView, Light, PrimitiveKind, Scene, SurfaceHit};
use crate::scene::material::{DiffuseModel, Fresnel, GlossyModel, PointLobes};
use fearless_simd::{dispatch, f32x16, f32x8, Simd, SimdCombine, SimdFrom};

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

/// Whether a rasterizer resolves `job`'s visible samples through batches:
/// shading that `batchable` takes, or a debug view that colours only what
/// is hit (`debug::miss_color`), which then colours each batch's records.
pub fn resolved_in_batches(job: &PassJob) -> bool {
    batchable(job) || crate::render::inspect::debug::miss_color(job.settings.view).is_some()
}

/// The interpolation a batch of `job`'s samples is built with: the
/// shading's in the shaded view; debug views colour the hit as the eye ray
/// found it (`Scene::triangle_hit`'s record, which Phong's is).
pub fn build_interpolation(job: &PassJob) -> Interpolation {
    if job.settings.view == View::Shaded { job.settings.interpolation } else { Interpolation::Phong }
}

/// Up to eight samples that see a surface, with where their results go.
pub struct Batch {
    pub(crate) len: usize,
    /// The surfaces as `shade()` is handed them (flat shading's normal
    /// applied), in lanes.
    pub(crate) hits: HitLanes,
    /// Unit directions towards the eye, in lanes.
    pub(crate) w_o: [Floats; 3],
    pub(crate) pixels: [u32; LANES],
    /// Each lane's sample index among its pixel's (its pass): with the
    /// pixel, the key of its random numbers.
    pub(crate) samples: [u32; LANES],
    /// The caller's index for each lane's result.
    pub slots: [usize; LANES],
    /// Eye samples pushed but not built yet, and their lanes.
    pub(crate) pending: EyeSamples,
    pending_lanes: [usize; LANES],
    /// Ray casters' triangle hits pushed but not built yet, and their lanes.
    pending_rays: [TriangleHitInput; LANES],
    pending_ray_lanes: [usize; LANES],
    pub(crate) pending_ray_count: usize,
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
            hits: HitLanes::new(),
            w_o: [[0.0; LANES], [0.0; LANES], [1.0; LANES]],
            pixels: [0; LANES],
            samples: [0; LANES],
            slots: [0; LANES],
            pending: EyeSamples::default(),
            pending_lanes: [0; LANES],
            pending_rays: [TriangleHitInput::default(); LANES],
            pending_ray_lanes: [0; LANES],
            pending_ray_count: 0,
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
        self.pending.len = 0;
        self.pending_ray_count = 0;
    }

    /// Sample `i`'s surface as `shade()` is handed it (debug views colour
    /// it; shading assembles records from `hits` itself).
    pub fn hit(&self, i: usize) -> SurfaceHit {
        self.hits.get(i)
    }

    /// `push` of the hit `Scene::triangle_hit` builds from `input` (a ray
    /// caster's hit, `input.dir` its ray's direction). The record is built
    /// later, with the batch's other pending hits, eight at a time
    /// (`build_pending`, before shading).
    #[inline]
    pub fn push_ray_triangle(&mut self, input: TriangleHitInput, pixel: u32, sample: u32, slot: usize) {
        let i = self.len;
        self.pending_rays[self.pending_ray_count] = input;
        self.pending_ray_lanes[self.pending_ray_count] = i;
        self.pending_ray_count += 1;
        (self.w_o[0][i], self.w_o[1][i], self.w_o[2][i]) = (-input.dir.x, -input.dir.y, -input.dir.z);
        self.pixels[i] = pixel;
        self.samples[i] = sample;
        self.slots[i] = slot;
        self.len += 1;
    }

    /// Eight `push_ray_triangle`s at once into an empty batch, their
    /// records built at once (`Scene::triangle_hits_of_rays`): lane k is
    /// the hit on triangle `index[k]` with weights `b1[k]`, `b2[k]`, `t[k]`
    /// along a ray towards `dir`, for sample `samples[k]` of pixel
    /// `pixels[k]`, meant for `slots[k]`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn fill_ray_triangles(&mut self, scene: &Scene, interpolation: Interpolation, index: &[u32; LANES], bary: (&Floats, &Floats), t: &Floats, dir: &[Floats; 3], pixels: [u32; LANES], samples: [u32; LANES], slots: [usize; LANES]) {
        assert!(self.len == 0, "fill_ray_triangles into a batch that holds samples");
        place_built(&mut self.hits, LANES, &IN_ORDER, interpolation, |out| scene.triangle_hits_of_rays(index, bary, t, dir, out));
        self.w_o = dir.map(|a| a.map(|d| -d));
        (self.pixels, self.samples, self.slots) = (pixels, samples, slots);
        self.len = LANES;
    }

    /// `push` of the hit a rasterizer's eye sample at image position `p`
    /// sees on triangle `index` with weights b1 and b2: the record
    /// `Scene::triangle_hit` gives for the sample's eye ray, with `t` the
    /// hit's distance along it. The record is built later, with the
    /// batch's other pending samples, eight at a time (`build_pending`,
    /// before shading).
    #[inline]
    pub fn push_eye_triangle(&mut self, index: u32, (b1, b2): (f32, f32), p: Vec2, pixel: u32, sample: u32, slot: usize) {
        let i = self.len;
        self.pending_lanes[self.pending.len] = i;
        self.pending.push(index, b1, b2, p);
        self.pixels[i] = pixel;
        self.samples[i] = sample;
        self.slots[i] = slot;
        self.len += 1;
    }

    /// Eight `push_eye_triangle`s at once into an empty batch: lane k is
    /// the sample of `samples` lane k, of pixel index `pixels[k]`, meant
    /// for `slots[k]`; `sample` is the pass's sample index.
    #[inline]
    pub fn fill_eye_triangles(&mut self, samples: &EyeSamples, pixels: &[u32; LANES], sample: u32, slots: &[usize; LANES]) {
        assert!(self.len == 0 && samples.len == LANES, "fill_eye_triangles needs an empty batch and eight samples");
        let pending = &mut self.pending;
        copy_lanes(&mut pending.index, &samples.index);
        for (to, from) in [(&mut pending.b1, &samples.b1), (&mut pending.b2, &samples.b2), (&mut pending.px, &samples.px), (&mut pending.py, &samples.py)] {
            copy_lanes(to, from);
        }
        pending.len = samples.len;
        self.pending_lanes = IN_ORDER;
        copy_lanes(&mut self.pixels, pixels);
        copy_lanes(&mut self.slots, slots);
        self.samples = [sample; LANES];
        self.len = LANES;
    }

    /// Eight `push_eye_triangle`s at once into an empty batch, for eight
    /// neighbouring samples of one row: lane k sees triangle `index[k]`
    /// with weights `bary[k]`, at column `x + k` of image row `y` (the
    /// pass's sample offset `offset` added, as `PassJob::sample_position`
    /// does), of pixel index `pixel + k`, meant for `slot + k`; `sample` is
    /// the pass's sample index. Every field is computed and stored lanes
    /// wide: nothing is written one lane at a time and read back.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn fill_eye_row(&mut self, index: &[u32; LANES], bary: &[[f32; 2]; LANES], (x, y): (u32, u32), offset: Vec2, pixel: u32, sample: u32, slot: usize) {
        assert!(self.len == 0, "fill_eye_row needs an empty batch");
        let pending = &mut self.pending;
        pending.index = *index;
        pending.b1 = bary.map(|b| b[0]);
        pending.b2 = bary.map(|b| b[1]);
        pending.px = std::array::from_fn(|k| x.wrapping_add(k as u32) as f32 + offset.x);
        pending.py = [y as f32 + offset.y; LANES];
        pending.len = LANES;
        self.pending_lanes = IN_ORDER;
        self.pixels = std::array::from_fn(|k| pixel.wrapping_add(k as u32));
        self.slots = std::array::from_fn(|k| slot + k);
        self.samples = [sample; LANES];
        self.len = LANES;
    }

    /// Builds the records `push_eye_triangle` left pending, as `push` hands
    /// them to `shade()` with `interpolation`; `view` makes the eye rays.
    pub fn build_pending(&mut self, scene: &Scene, view: &CameraView, interpolation: Interpolation) {
        self.build_pending_rays(scene, interpolation);
        let n = self.pending.len;
        if n == 0 {
            return;
        }
        let mut dirs = [[0.0; LANES]; 3];
        let lanes = &self.pending_lanes[..n];
        let pending = &self.pending;
        if place_built(&mut self.hits, self.len, lanes, interpolation, |out| scene.triangle_eye_hits(view, pending, out, &mut dirs)) {
            for a in 0..3 {
                self.w_o[a] = dirs[a].map(|d| -d);
            }
        } else {
            for (k, &i) in lanes.iter().enumerate() {
                for a in 0..3 {
                    self.w_o[a][i] = -dirs[a][k];
                }
            }
        }
        self.pending.len = 0;
    }

    /// The shadow rays `shade()` casts from the batch's surfaces towards
    /// `light` (with `ShadowMode::Ray`: `Incidence::of`, `illuminates` and
    /// `shadow_ray`, eight lanes at a time), each handed to `put` with its
    /// lane and far end: what the packets trace ahead of shading.
    #[inline]
    pub fn shadow_rays(&self, scene: &Scene, light: &Light, bump: f32, lift: bool, put: impl FnMut(usize, Ray, f32)) {
        shadow_rays_of(scene, &self.hits, self.len, light, bump, lift, put);
    }

    /// The part of `build_pending` for `push_ray_triangle`'s hits.
    fn build_pending_rays(&mut self, scene: &Scene, interpolation: Interpolation) {
        let n = self.pending_ray_count;
        if n == 0 {
            return;
        }
        let inputs = &self.pending_rays[..n];
        place_built(&mut self.hits, self.len, &self.pending_ray_lanes[..n], interpolation, |out| scene.triangle_hits(inputs, out));
        self.pending_ray_count = 0;
    }

    /// Adds the sample of pixel index `pixel` (the random numbers' key)
    /// whose eye ray along `dir` sees `hit`, its result meant for `slot`.
    /// The batch must not be full.
    #[inline]
    pub fn push(&mut self, interpolation: Interpolation, hit: &SurfaceHit, dir: Vec3, pixel: u32, sample: u32, slot: usize) {
        let i = self.len;
        match interpolation {
            Interpolation::Flat => self.hits.set(i, &SurfaceHit { shading_normal: hit.geometric_normal, ..*hit }),
            _ => self.hits.set(i, hit),
        }
        (self.w_o[0][i], self.w_o[1][i], self.w_o[2][i]) = (-dir.x, -dir.y, -dir.z);
        self.pixels[i] = pixel;
        self.samples[i] = sample;
        self.slots[i] = slot;
        self.len += 1;
    }
}

/// Copies eight lanes that were just written one at a time, a lane at a
/// time. Copied as a whole (as the compiler otherwise does, with vector
/// loads or a call to memcpy), each wide load would span several of those
/// recent narrow stores, which the processor cannot forward to it: it waits
/// until they reach the cache. The volatile reads keep the loads one lane
/// wide.
#[inline(always)]
fn copy_lanes<T: Copy>(to: &mut [T; LANES], from: &[T; LANES]) {
    for (to, from) in to.iter_mut().zip(from) {
        // SAFETY: `from` is a valid reference to an initialised `T`.
        *to = unsafe { std::ptr::read_volatile(from) };
    }
}

/// Puts surfaces that `build` makes in its lanes `0..lanes.len()` into
/// lanes `lanes` of `hits` (a batch of `len` samples): built in place when
/// they are all of the batch's lanes, in order (the common case), else built
/// aside and copied lane by lane. Flat interpolation then shades them with
/// the geometric normal, as `Batch::push` does. True when built in place
/// (lane k of what `build` made is lane k of the batch).
#[inline(always)]
fn place_built(hits: &mut HitLanes, len: usize, lanes: &[usize], interpolation: Interpolation, build: impl FnOnce(&mut HitLanes)) -> bool {
    let flat = interpolation == Interpolation::Flat;
    if lanes.len() == len {
        debug_assert!(lanes.iter().enumerate().all(|(k, &i)| k == i), "pending lanes are pushed in order");
        build(hits);
        if flat {
            hits.shading_normal = hits.geometric_normal;
        }
        return true;
    }
    let mut built = HitLanes::new();
    build(&mut built);
    for (k, &i) in lanes.iter().enumerate() {
        hits.copy_lane(i, &built, k);
        if flat {
            for a in 0..3 {
                hits.shading_normal[a][i] = hits.geometric_normal[a][i];
            }
        }
    }
    false
}

/// Shades the batch's samples (depth 0, the eye's surfaces) and returns
/// their radiance in lane order. `blocked`, when given, holds per light the
/// lanes whose shadow ray towards it is blocked, traced ahead (a packet),
/// for every lane the light illuminates; otherwise shadow rays are cast
/// here.
pub fn shade_batch<Q: SceneQuery>(job: &PassJob, query: &Q, batch: &Batch, blocked: Option<&[u8]>, counts: &mut RayCounts) -> [Radiance; LANES] {
    assert!(batch.pending.len == 0 && batch.pending_ray_count == 0, "shade_batch on a batch with hits not built (`build_pending`)");
    let scene = &job.prepared.scene;
    let settings = job.settings;
    let n = batch.len;
    let hits = &batch.hits;
    let path = |i: usize| PathState::new(batch.pixels[i], batch.samples[i], settings.spp, &settings.gi, job.photons);
    // Without ambient occlusion or traced light, direct light draws no
    // random numbers: one lane's state serves them all there, and the
    // lanes that go on (mirror, glass) start theirs below, as fresh as
    // they would be.
    let draws = settings.gi.mode != GiMode::None || scene.has_sampled_lights();
    let mut paths: Option<[PathState; LANES]> = draws.then(|| std::array::from_fn(path));
    let (lobes, direct) = match paths.as_mut() {
        Some(paths) => direct_in_lanes(job, query, hits, &batch.w_o, n, paths, &IN_ORDER, blocked, counts),
        None => direct_in_lanes(job, query, hits, &batch.w_o, n, &mut [path(0)], &[0; LANES], blocked, counts),
    };
    // A batch of one material (the common case) asks once whether anything
    // comes after direct light (lanes past `n` are dropped by the callers).
    if n > 0 && hits.material[1..n].iter().all(|&m| m == hits.material[0]) && !shade::adds_after_direct(scene, settings, &scene.materials[hits.material[0] as usize]) {
        return direct;
    }
    let mut paths = paths.unwrap_or_else(|| std::array::from_fn(path));
    let mut out = [Radiance::ZERO; LANES];
    for i in 0..n {
        let material = &scene.materials[hits.material[i] as usize];
        if !shade::adds_after_direct(scene, settings, material) {
            out[i] = direct[i];
            continue;
        }
        let hit = hits.get(i);
        let w_o = Vec3::new(batch.w_o[0][i], batch.w_o[1][i], batch.w_o[2][i]);
        let mut sh = Shading { scene, query, settings, path: &mut paths[i], counts: &mut *counts, rec: &mut NoRecord };
        out[i] = shade::after_direct(&mut sh, &hit, material, lobes[i], w_o, 0, direct[i]);
    }
    out
}

/// Lane i's path is path i.
pub const IN_ORDER: [usize; LANES] = [0, 1, 2, 3, 4, 5, 6, 7];

/// What `shade()` computes before `after_direct` for the surfaces in lanes
/// `0..n` of `hits`, seen along the unit directions `w_o`: each one's
/// albedo, and its ambient term plus direct light (eight lanes wide).
/// Lane i's sample follows path `paths[path_of[i]]` (the ambient term may
/// draw from its random numbers). `blocked` as in `shade_batch`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn direct_in_lanes<Q: SceneQuery>(
    job: &PassJob,
    query: &Q,
    hits: &HitLanes,
    w_o: &[Floats; 3],
    n: usize,
    paths: &mut [PathState],
    path_of: &[usize; LANES],
    blocked: Option<&[u8]>,
    counts: &mut RayCounts,
) -> ([PointLobes; LANES], [Radiance; LANES]) {
    let scene = &job.prepared.scene;
    let settings = job.settings;
    // Lanes past `n` repeat lane 0's geometry (so their arithmetic stays
    // tame); their results are dropped. A full batch is read in place.
    let padded;
    let geometry = if n == LANES {
        Geometry { position: &hits.position, normal: &hits.shading_normal, w_o, tangent: ward_tangents(scene, hits, n) }
    } else {
        let pad = |v: &[Floats; 3]| v.map(|c| std::array::from_fn(|i| if i < n { c[i] } else { c[0] }));
        padded = [pad(&hits.position), pad(&hits.shading_normal), pad(w_o)];
        Geometry { position: &padded[0], normal: &padded[1], w_o: &padded[2], tangent: ward_tangents(scene, hits, n) }
    };
    let mut lobes = [PointLobes { albedo: Vec3::ZERO, glossy: Vec3::ZERO, roughness: 1.0 }; LANES];
    let first = &scene.materials[hits.material[0] as usize];
    let materials = if n > 0 && !first.varies_over_surface() && !scene.has_vertex_colours() && settings.gi.mode != GiMode::Ao && hits.material[1..n].iter().all(|&m| m == hits.material[0]) {
        // One untextured material (the common batch): its albedo, lobes and
        // ambient term are the same in every lane, worked out once and
        // splatted, rather than written lane by lane and loaded back.
        let l = shade::lobes_at(first, Vec2::ZERO, &hits.diff[0], Vec3::ONE, settings);
        let mut sh = Shading { scene, query, settings, path: &mut paths[path_of[0]], counts: &mut *counts, rec: &mut NoRecord };
        let ambient = shade::ambient_term(&mut sh, || hits.get(0), l.albedo);
        lobes = [l; LANES];
        MaterialLanes::Uniform { albedo: l.albedo, diffuse: first.diffuse_model, glossy: l.glossy, sharpness: first.sharpness, model: lighting::model_lane(first.glossy_model), roughness: lighting::roughness_u(first, l.roughness), roughness_v: lighting::roughness_v(first), fresnel: first.fresnel, ambient }
    } else {
        // Lanes past `n` get a black material.
        let (mut albedo_lanes, mut glossy, mut sharpness, mut ambient_lanes) = ([[0.0; LANES]; 3], [[0.0; LANES]; 3], [1.0; LANES], [[0.0; LANES]; 3]);
        let (mut model, mut roughness, mut roughness_v, mut fresnel) = ([0.0; LANES], [1.0; LANES], [1.0; LANES], FresnelSoa::default());
        let mut diffuse = [[0.0; LANES]; 2];
        for i in 0..n {
            let material = &scene.materials[hits.material[i] as usize];
            let b = Vec3::new(hits.barycentric[0][i], hits.barycentric[1][i], hits.barycentric[2][i]);
            let tint = scene.vertex_colour(hits.kind[i], hits.primitive[i], b);
            lobes[i] = shade::lobes_at(material, Vec2::new(hits.uv[0][i], hits.uv[1][i]), &hits.diff[i], tint, settings);
            let l = lobes[i];
            let mut sh = Shading { scene, query, settings, path: &mut paths[path_of[i]], counts: &mut *counts, rec: &mut NoRecord };
            let ambient = shade::ambient_term(&mut sh, || hits.get(i), l.albedo);
            for (a, (v, g)) in [(l.albedo.x, l.glossy.x), (l.albedo.y, l.glossy.y), (l.albedo.z, l.glossy.z)].into_iter().enumerate() {
                albedo_lanes[a][i] = v;
                glossy[a][i] = g;
            }
            (ambient_lanes[0][i], ambient_lanes[1][i], ambient_lanes[2][i]) = (ambient.x, ambient.y, ambient.z);
            sharpness[i] = material.sharpness;
            model[i] = lighting::model_lane(material.glossy_model);
            roughness[i] = lighting::roughness_u(material, l.roughness);
            roughness_v[i] = lighting::roughness_v(material);
            fresnel.set(i, material.fresnel);
            (diffuse[0][i], diffuse[1][i]) = (lighting::diffuse_lane(material.diffuse_model), material.diffuse_model.parameter());
        }
        MaterialLanes::PerLane { albedo: albedo_lanes, diffuse, glossy, sharpness, model, roughness, roughness_v, fresnel, ambient: ambient_lanes }
    };
    let mut visibility = BatchVisibility { job, query, hits, live: ((1u32 << n) - 1) as u8, blocked, counts: &mut *counts };
    let direct = dispatch!(simd_level(), simd => direct_light8(simd, job, &geometry, &materials, &mut visibility));
    (lobes, direct)
}

/// The tangents of lanes `0..n` of `hits` whose material has Ward's lobe,
/// as `ShadingFrame::at` gives them to one-sample shading; zero in the
/// other lanes (and nothing is looked up when no lane has that lobe).
fn ward_tangents(scene: &Scene, hits: &HitLanes, n: usize) -> [Floats; 3] {
    let mut out = [[0.0; LANES]; 3];
    let ward = |i: usize| scene.materials[hits.material[i] as usize].glossy_model == GlossyModel::Ward;
    if !(0..n).any(ward) {
        return out;
    }
    for i in (0..n).filter(|&i| ward(i)) {
        let t = crate::scene::tangents::tangent_at(scene, &hits.get(i));
        (out[0][i], out[1][i], out[2][i]) = (t.x, t.y, t.z);
    }
    out
}

/// Where the surfaces of a batch are and which way they face and are seen,
/// one array per coordinate.
struct Geometry<'a> {
    position: &'a [Floats; 3],
    normal: &'a [Floats; 3],
    w_o: &'a [Floats; 3],
    /// The surfaces' tangents where their lobe is Ward's (which alone
    /// reads them), zero elsewhere.
    tangent: [Floats; 3],
}

/// A batch's material values as `direct_light8` loads them.
enum MaterialLanes {
    /// The same in every lane (one material without a texture).
    /// `model` is the glossy model's `lighting::model_lane` code.
    Uniform { albedo: Vec3, diffuse: DiffuseModel, glossy: Vec3, sharpness: f32, model: f32, roughness: f32, roughness_v: f32, fresnel: Fresnel, ambient: Radiance },
    /// One array per coordinate (lanes may have different glossy models).
    PerLane { albedo: [Floats; 3], diffuse: [Floats; 2], glossy: [Floats; 3], sharpness: Floats, model: Floats, roughness: Floats, roughness_v: Floats, fresnel: FresnelSoa, ambient: [Floats; 3] },
}

/// Lanes' Fresnel terms, one array per value (`lighting::FresnelLanes`).
#[derive(Default)]
struct FresnelSoa {
    model: Floats,
    eta: [Floats; 3],
    k: [Floats; 3],
}

impl FresnelSoa {
    fn set(&mut self, i: usize, fresnel: Fresnel) {
        self.model[i] = lighting::fresnel_lane(fresnel);
        if let Fresnel::Conductor { eta, k } = fresnel {
            for a in 0..3 {
                (self.eta[a][i], self.k[a][i]) = (eta[a], k[a]);
            }
        }
    }

    #[inline(always)]
    fn load<S: Simd>(&self, simd: S) -> FresnelLanes<f32x8<S>> {
        FresnelLanes { model: f32x8::simd_from(simd, self.model), eta: V3::from_soa(simd, &self.eta), k: V3::from_soa(simd, &self.k) }
    }
}

#[inline(always)]
fn direct_light8<S: Simd, Q: SceneQuery>(simd: S, job: &PassJob, geometry: &Geometry, materials: &MaterialLanes, visibility: &mut BatchVisibility<Q>) -> [Radiance; LANES] {
    let like = <f32x8<S> as fearless_simd::SimdBase<S>>::splat(simd, 0.0);
    let (albedo, diffuse, glossy, sharpness, glossy_model, (roughness, roughness_v), fresnel, start) = match materials {
        MaterialLanes::Uniform { albedo, diffuse, glossy, sharpness, model, roughness, roughness_v, fresnel, ambient } => (
            V3::splat(like, *albedo),
            DiffuseLanes::splat(like, *diffuse),
            V3::splat(like, *glossy),
            like.splat(*sharpness),
            like.splat(*model),
            (like.splat(*roughness), like.splat(*roughness_v)),
            FresnelLanes::splat(like, *fresnel),
            V3::splat(like, *ambient),
        ),
        MaterialLanes::PerLane { albedo, diffuse, glossy, sharpness, model, roughness, roughness_v, fresnel, ambient } => (
            V3::from_soa(simd, albedo),
            DiffuseLanes { model: f32x8::simd_from(simd, diffuse[0]), param: f32x8::simd_from(simd, diffuse[1]) },
            V3::from_soa(simd, glossy),
            f32x8::simd_from(simd, *sharpness),
            f32x8::simd_from(simd, *model),
            (f32x8::simd_from(simd, *roughness), f32x8::simd_from(simd, *roughness_v)),
            fresnel.load(simd),
            V3::from_soa(simd, ambient),
        ),
    };
    let surface = SurfaceLanes {
        position: V3::from_soa(simd, geometry.position),
        normal: V3::from_soa(simd, geometry.normal),
        w_o: V3::from_soa(simd, geometry.w_o),
        albedo,
        diffuse,
        glossy,
        sharpness,
        glossy_model,
        roughness,
        roughness_v,
        tangent: V3::from_soa(simd, &geometry.tangent),
        fresnel,
    };
    lighting::direct_light(&job.prepared.scene.lights, job.prepared.scene.render.lighting, &surface, start, visibility).scatter()
}

/// Colours each of `batches` (hits built) in a debug view that colours
/// only what is hit (`resolved_in_batches`), handing lane j of batch b's
/// colour to `put(batch, j, colour)` as `shade_batches` hands its values,
/// and empties them: each record's colour, as `resolve_sample` gives it.
pub fn colour_batches(job: &PassJob, batches: &mut [Batch], mut put: impl FnMut(&Batch, usize, Radiance)) {
    for batch in batches.iter_mut() {
        for j in 0..batch.len() {
            put(batch, j, crate::render::inspect::debug::surface_color(job.settings.view, job.view, &batch.hit(j)));
        }
        batch.clear();
    }
}

/// Shades each of `batches` (hits built) with `shade_batch`, two at a time
/// through `shade_batch_pair` where a pair qualifies, handing lane j of
/// batch b's value to `put(batch, j, value)`, and empties them. With
/// shadows traced ahead, `unpack(b, batch, bits)` writes batch b's blocked
/// lanes per light into `bits` (`bits` holds one buffer for each batch of
/// a pair); without, the lanes' shadow rays are cast in shading.
pub fn shade_batches<Q: SceneQuery>(
    job: &PassJob,
    query: &Q,
    batches: &mut [Batch],
    unpack: Option<impl Fn(usize, &Batch, &mut [u8])>,
    bits: [&mut Vec<u8>; 2],
    counts: &mut RayCounts,
    mut put: impl FnMut(&Batch, usize, Radiance),
) {
    let [first, second] = bits;
    let mut pair_values = [[Radiance::ZERO; LANES]; 2];
    let mut b = 0;
    while b < batches.len() {
        if let Some(unpack) = &unpack {
            unpack(b, &batches[b], first);
        }
        if b + 1 < batches.len() {
            if let Some(unpack) = &unpack {
                unpack(b + 1, &batches[b + 1], second);
            }
            let blocked = [&first[..], &second[..]].map(|bits| unpack.is_some().then_some(bits));
            if shade_batch_pair(job, query, [&batches[b], &batches[b + 1]], blocked, counts, &mut pair_values) {
                for (batch, values) in batches[b..b + 2].iter_mut().zip(&pair_values) {
                    for (j, &value) in values.iter().enumerate() {
                        put(batch, j, value);
                    }
                    batch.clear();
                }
                b += 2;
                continue;
            }
        }
        let batch = &mut batches[b];
        let values = shade_batch(job, query, batch, unpack.is_some().then_some(&first[..]), counts);
        for (j, &value) in values.iter().enumerate().take(batch.len()) {
            put(batch, j, value);
        }
        batch.clear();
        b += 1;
    }
}

/// `shade_batch` for two full batches at once, where direct light and the
/// constant ambient term are all there is to it and one untextured
/// material covers all sixteen lanes: `lighting::direct_light` runs over
/// `f32x16` (one AVX-512 register, or two AVX2 halves). Each lane goes
/// through the same operations as in `shade_batch`, so the values are the
/// same bits; what changes is that the two batches' chains of square
/// roots, divisions and the glossy lobe's power run side by side, where
/// one batch alone leaves the CPU waiting on each step. `blocked` as in
/// `shade_batch`, per batch. The values go into `out` (batch by batch,
/// lane by lane; written in place rather than returned, which cost two
/// copies whose wide loads waited on the lanes' narrow stores). False when
/// the pair does not qualify: the caller then shades each batch alone.
pub fn shade_batch_pair<Q: SceneQuery>(job: &PassJob, query: &Q, pair: [&Batch; 2], blocked: [Option<&[u8]>; 2], counts: &mut RayCounts, out: &mut [[Radiance; LANES]; 2]) -> bool {
    let settings = job.settings;
    let traced = match blocked {
        [Some(_), Some(_)] => true,
        [None, None] => false,
        _ => return false,
    };
    // Without traced shadows, `BatchVisibility` casts the rays one lane at
    // a time: those pairs are left to it.
    if settings.gi.mode != GiMode::None || (!traced && settings.shadows != ShadowMode::None) {
        return false;
    }
    let [a, b] = pair;
    if !(a.is_full() && b.is_full()) {
        return false;
    }
    assert!(a.pending.len == 0 && a.pending_ray_count == 0 && b.pending.len == 0 && b.pending_ray_count == 0, "shade_batch_pair on a batch with hits not built (`build_pending`)");
    let scene = &job.prepared.scene;
    let index = a.hits.material[0];
    if !a.hits.material.iter().chain(&b.hits.material).all(|&m| m == index) {
        return false;
    }
    let material = &scene.materials[index as usize];
    // Ward's lobe needs each lane's tangent, which pairs do not carry.
    if material.varies_over_surface() || !!scene.has_vertex_colours() || material.glossy_model == GlossyModel::Ward || shade::adds_after_direct(scene, settings, material) {
        return false;
    }
    // `direct_in_lanes`' one-material case, for each batch: the albedo
    // and ambient term are worked out from lane 0 and must agree.
    let mut uniform = |batch: &Batch| {
        let albedo = shade::lobes_at(material, Vec2::ZERO, &batch.hits.diff[0], Vec3::ONE, settings).albedo;
        let mut path = PathState::new(batch.pixels[0], batch.samples[0], settings.spp, &settings.gi, job.photons);
        let mut sh = Shading { scene, query, settings, path: &mut path, counts: &mut *counts, rec: &mut NoRecord };
        (albedo, shade::ambient_term(&mut sh, || batch.hits.get(0), albedo))
    };
    let ((albedo, ambient), other) = (uniform(a), uniform(b));
    if (albedo, ambient) != other {
        return false;
    }
    let materials = MaterialLanes::Uniform { albedo, diffuse: material.diffuse_model, glossy: material.glossy, sharpness: material.sharpness, model: lighting::model_lane(material.glossy_model), roughness: lighting::roughness_u(material, material.roughness), roughness_v: lighting::roughness_v(material), fresnel: material.fresnel, ambient };
    let mut visibility = PairVisibility { shadows: settings.shadows, blocked, counts };
    dispatch!(simd_level(), simd => direct_light16(simd, job, pair, &materials, &mut visibility, out));
    true
}

/// `direct_light8` over the sixteen lanes of two full batches (`a`'s in
/// lanes 0-7, `b`'s in 8-15), one material in all of them, into `out`.
#[inline(always)]
fn direct_light16<S: Simd, V: LightVisibility<f32x16<S>>>(simd: S, job: &PassJob, [a, b]: [&Batch; 2], materials: &MaterialLanes, visibility: &mut V, out: &mut [[Radiance; LANES]; 2]) {
    let like = <f32x16<S> as fearless_simd::SimdBase<S>>::splat(simd, 0.0);
    let MaterialLanes::Uniform { albedo, diffuse, glossy, sharpness, model, roughness, roughness_v, fresnel, ambient } = materials else {
        unreachable!("pairs are one material")
    };
    let surface = SurfaceLanes {
        position: join_lanes(simd, &a.hits.position, &b.hits.position),
        normal: join_lanes(simd, &a.hits.shading_normal, &b.hits.shading_normal),
        w_o: join_lanes(simd, &a.w_o, &b.w_o),
        albedo: V3::splat(like, *albedo),
        diffuse: DiffuseLanes::splat(like, *diffuse),
        glossy: V3::splat(like, *glossy),
        sharpness: like.splat(*sharpness),
        glossy_model: like.splat(*model),
        roughness: like.splat(*roughness),
        roughness_v: like.splat(*roughness_v),
        tangent: V3::splat(like, Vec3::ZERO),
        fresnel: FresnelLanes::splat(like, *fresnel),
    };
    let l_o = lighting::direct_light(&job.prepared.scene.lights, job.prepared.scene.render.lighting, &surface, V3::splat(like, *ambient), visibility);
    let (x, y, z): ([f32; 16], [f32; 16], [f32; 16]) = (l_o.x.into(), l_o.y.into(), l_o.z.into());
    // A plain loop: `array::map` over `from_fn` was left as a call that
    // passed the lanes through the stack several times.
    for i in 0..LANES {
        out[0][i] = Vec3::new(x[i], y[i], z[i]);
        out[1][i] = Vec3::new(x[LANES + i], y[LANES + i], z[LANES + i]);
    }
}

/// Sixteen lanes of 3-vectors: `low`'s eight, then `high`'s. (A function,
/// not a closure: a closure would be compiled apart from the SIMD level
/// `dispatch` compiles its caller for.)
#[inline(always)]
fn join_lanes<S: Simd>(simd: S, low: &[Floats; 3], high: &[Floats; 3]) -> V3<f32x16<S>> {
    let (low, high) = (V3::from_soa(simd, low), V3::from_soa(simd, high));
    V3::new(low.x.combine(high.x), low.y.combine(high.y), low.z.combine(high.z))
}

/// Visibility for `shade_batch_pair`: `BatchVisibility`'s answers (no
/// shadows, or the packets' blocked lanes) over sixteen lanes.
struct PairVisibility<'b> {
    shadows: ShadowMode,
    blocked: [Option<&'b [u8]>; 2],
    counts: &'b mut RayCounts,
}

impl<S: Simd> LightVisibility<f32x16<S>> for PairVisibility<'_> {
    #[inline(always)]
    fn visible(&mut self, light: usize, inc: &IncidenceLanes<f32x16<S>>, lit: fearless_simd::mask32x16<S>) -> fearless_simd::mask32x16<S> {
        let simd = inc.cos_theta.simd;
        let all = fearless_simd::SimdMask::from_bitmask(simd, 0xffff);
        if self.shadows == ShadowMode::None {
            return all;
        }
        let [Some(a), Some(b)] = self.blocked else {
            return all;
        };
        self.counts.shadow += (fearless_simd::SimdMask::to_bitmask(lit) & 0xffff).count_ones() as u64;
        fearless_simd::SimdMask::from_bitmask(simd, !(a[light] as u64 | (b[light] as u64) << LANES) & 0xffff)
    }
}

/// `Batch::shadow_rays` for the surfaces in lanes `0..len` of `hits`.
#[inline]
pub fn shadow_rays_of(scene: &Scene, hits: &HitLanes, len: usize, light: &Light, bump: f32, lift: bool, mut put: impl FnMut(usize, Ray, f32)) {
    if len == 0 {
        return;
    }
    // The rays are handed out inside the dispatched code: returned from
    // it, their 256 bytes went through a call to memcpy that read back
    // the lanes just stored.
    dispatch!(simd_level(), simd => {
        let inc = lighting::incidence(light, V3::from_soa(simd, &hits.position), V3::from_soa(simd, &hits.shading_normal));
        let rays = ShadowRays::new(hits, &inc, bump, lift);
        let mut m = mask_bits(inc.illuminates()) & ((1u32 << len) - 1) as u8;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            // Each case hands its ray over on its own: joined, the two
            // became one ray in memory, written a float at a time and read
            // back at once, which waits for the writes to reach the cache.
            if rays.lifted & 1 << i != 0 {
                let (ray, t_max) = rays.lifted_ray(scene, hits, i);
                put(i, ray, t_max);
            } else {
                put(i, rays.plain_ray(i), rays.t_max[i]);
            }
        }
    })
}

/// Visibility for a batch: the packet's answers when it traced them, else
/// `shade()`'s shadow ray per lit lane (the same ray: `Incidence` made from
/// the same lane arithmetic).
struct BatchVisibility<'b, 'j, Q> {
    job: &'b PassJob<'j>,
    query: &'b Q,
    hits: &'b HitLanes,
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
        let settings = self.job.settings;
        let rays = ShadowRays::new(self.hits, inc, settings.shadow_bump, settings.terminator_lift);
        let visible = self.cast_shadow_rays(&rays, mask_bits(lit) & self.live);
        mask_from_bits(simd, visible)
    }
}

impl<Q: SceneQuery> BatchVisibility<'_, '_, Q> {
    /// Casts the shadow rays of the lanes in `lit`; the lanes whose light
    /// arrives unblocked.
    #[inline(never)]
    fn cast_shadow_rays(&mut self, rays: &ShadowRays, lit: u8) -> u8 {
        // One choice of SIMD level for the lanes' rays, whose walks are
        // then compiled into the loop (`occluder_at`).
        dispatch!(simd_level(), simd => self.cast_shadow_rays_at(simd, rays, lit))
    }

    #[inline(always)]
    fn cast_shadow_rays_at<S: Simd>(&mut self, simd: S, rays: &ShadowRays, lit: u8) -> u8 {
        let scene = &self.job.prepared.scene;
        let mut visible = 0u8;
        let mut m = lit;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            let (ray, t_max) = rays.get(scene, self.hits, i);
            self.counts.shadow += 1;
            if self.query.occluder_at(simd, &ray, t_max, self.counts).is_none() {
                visible |= 1 << i;
            }
        }
        visible
    }
}

/// The shadow rays of a batch's surfaces towards one light, worked out
/// eight at a time with `Incidence::shadow_ray`'s arithmetic: the origin
/// bumped along the direction, the far end short of the light. Where the
/// origin is lifted off a triangle (`shadow_origin`), the lane is left to
/// `Incidence::shadow_ray` itself.
struct ShadowRays {
    origin: [Floats; 3],
    w_i: [Floats; 3],
    distance: Floats,
    t_max: Floats,
    bump: f32,
    /// Lanes whose origin `shadow_origin` lifts.
    lifted: u8,
}

impl ShadowRays {
    #[inline(always)]
    fn new<S: Simd>(hits: &HitLanes, inc: &IncidenceLanes<f32x8<S>>, bump: f32, lift: bool) -> ShadowRays {
        let simd = inc.distance.simd;
        let position = V3::from_soa(simd, &hits.position);
        let bump_lanes = inc.distance.splat(bump);
        let mut lifted = 0;
        if lift {
            let mut triangles = 0u8;
            for (i, kind) in hits.kind.iter().enumerate() {
                triangles |= ((*kind == PrimitiveKind::Triangle) as u8) << i;
            }
            let facing = V3::from_soa(simd, &hits.geometric_normal).dot(inc.w_i).gt(bump_lanes.splat(0.0));
            lifted = triangles & !mask_bits(facing);
        }
        ShadowRays {
            origin: (position + inc.w_i.scale(bump_lanes)).to_soa(),
            w_i: inc.w_i.to_soa(),
            distance: inc.distance.into(),
            t_max: (inc.distance - bump_lanes).into(),
            bump,
            lifted,
        }
    }

    /// Lane `i`'s ray and far end, as `Incidence::shadow_ray` gives them
    /// for surface `i` of `hits`.
    #[inline]
    fn get(&self, scene: &Scene, hits: &HitLanes, i: usize) -> (Ray, f32) {
        if self.lifted & 1 << i != 0 {
            return self.lifted_ray(scene, hits, i);
        }
        (self.plain_ray(i), self.t_max[i])
    }

    /// Lane `i`'s ray (its far end is `t_max[i]`), as
    /// `Incidence::shadow_ray` gives it for surface `i` of `hits` when the
    /// lane is not `lifted`.
    #[inline(always)]
    fn plain_ray(&self, i: usize) -> Ray {
        let lane = |a: &[Floats; 3]| Vec3::new(a[0][i], a[1][i], a[2][i]);
        Ray::new(lane(&self.origin), lane(&self.w_i))
    }

    /// Lane `i`'s ray and far end when the lane is `lifted` (rare).
    #[inline(never)]
    fn lifted_ray(&self, scene: &Scene, hits: &HitLanes, i: usize) -> (Ray, f32) {
        let lane = |a: &[Floats; 3]| Vec3::new(a[0][i], a[1][i], a[2][i]);
        // Only the direction and distance matter to `shadow_ray`.
        let incidence = Incidence { w_i: lane(&self.w_i), distance: self.distance[i], incident: Vec3::ZERO, cos_theta: 0.0 };
        incidence.shadow_ray(scene, &hits.get(i), self.bump, true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::inspect::pixel_record::NoRecord;
    use crate::render::accel::bvh::BvhQuery;
    use crate::render::{PreparedScene, RenderSettings};
    use crate::scene::builtin;
    use std::sync::atomic::AtomicBool;

    /// A row of eight samples put in at once holds, field by field, what
    /// eight `push_eye_triangle`s of the same samples leave: the positions
    /// `PassJob::sample_position` gives, consecutive pixels and slots.
    #[test]
    fn a_row_of_eye_samples_fills_a_batch_as_eight_pushes_do() {
        let prepared = PreparedScene::new(builtin::load_builtin("teapot").unwrap().unwrap());
        let view = prepared.scene.camera.view(100, 40);
        let settings = RenderSettings::for_scene(&prepared.scene);
        let cancel = AtomicBool::new(false);
        let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: glam::Vec2::new(0.3, 0.85), sample: 5, photons: None, active: None, rows: 0..40, cancel: &cancel, keep_non_finite: false };
        let index = [7, 3, 3, 90, 1, 0, 44, 12];
        let bary: [[f32; 2]; LANES] = std::array::from_fn(|k| [0.1 * k as f32, 0.35 - 0.03 * k as f32]);
        let (x, y, slot) = (61u32, 17u32, 977usize);
        let mut pushed = Batch::new();
        for k in 0..LANES {
            let xk = x + k as u32;
            pushed.push_eye_triangle(index[k], (bary[k][0], bary[k][1]), job.sample_position(xk, y), job.pixel_index(xk, y), job.sample, slot + k);
        }
        let mut filled = Batch::new();
        filled.fill_eye_row(&index, &bary, (x, y), job.offset, job.pixel_index(x, y), job.sample, slot);
        let (a, b) = (&pushed.pending, &filled.pending);
        assert_eq!((a.len, a.index), (b.len, b.index));
        for (from_pushes, from_row) in [(a.b1, b.b1), (a.b2, b.b2), (a.px, b.px), (a.py, b.py)] {
            assert_eq!(from_pushes.map(f32::to_bits), from_row.map(f32::to_bits));
        }
        assert_eq!((pushed.len, pushed.pending_lanes, pushed.pixels, pushed.samples, pushed.slots), (filled.len, filled.pending_lanes, filled.pixels, filled.samples, filled.slots));
    }

    /// Every built-in scene (glossy, mirror, glass, several lights) as a
    /// 29x19 pass under the shadings the batch tests cover: Phong normals
    /// with shadow rays, flat normals without, and ambient occlusion's
    /// random rays. `check` gets the scene's name, the pass and its query.
    fn for_each_shading_case(mut check: impl FnMut(&str, &PassJob, &BvhQuery)) {
        for (name, lobes) in builtin::names().iter().flat_map(|name| [(name, false), (name, true)]) {
            let mut scene = builtin::load_builtin(name).unwrap().unwrap();
            if lobes {
                with_every_glossy_model(&mut scene);
            }
            let name = &format!("{name}{}", if lobes { " (every glossy model)" } else { "" });
            let prepared = PreparedScene::new(scene);
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
                let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: glam::Vec2::splat(0.5), sample: 0, photons: None, active: None, rows: 0..h, cancel: &cancel, keep_non_finite: false };
                check(name, &job, &query);
            }
        }
    }

    /// `scene` with a glossy lobe on every material, the models taken in
    /// turn (GGX, Beckmann, Phong, Blinn-Phong) with varied roughness and
    /// sharpness, and the diffuse models and Fresnel terms in turns of
    /// their own: batches then hold one model, or several side by side.
    fn with_every_glossy_model(scene: &mut crate::scene::Scene) {
        use crate::scene::material::{DiffuseModel, Fresnel, GlossyModel};
        let models = [GlossyModel::Ggx, GlossyModel::Beckmann, GlossyModel::Phong, GlossyModel::BlinnPhong, GlossyModel::Ward];
        let diffuse = [DiffuseModel::OrenNayar { sigma: 0.4 }, DiffuseModel::Lambert, DiffuseModel::Minnaert { darkening: 0.6 }, DiffuseModel::Toon { bands: 3 }, DiffuseModel::OrenNayar { sigma: 0.0 }];
        let fresnel = [Fresnel::Schlick, Fresnel::None, Fresnel::Conductor { eta: Vec3::new(0.2, 0.9, 1.1), k: Vec3::new(3.9, 2.4, 2.2) }];
        for (k, m) in scene.materials.iter_mut().enumerate() {
            m.diffuse_model = diffuse[k % diffuse.len()];
            m.fresnel = fresnel[k % fresnel.len()];
            m.glossy_model = models[k % models.len()];
            m.roughness = 0.05 + 0.15 * (k % 5) as f32;
            m.roughness_uv = crate::math::Vec2::new(m.roughness, 0.1 + 0.1 * (k % 3) as f32);
            m.sharpness = 3.0 + 20.0 * k as f32;
            if m.glossy == Vec3::ZERO {
                m.glossy = Vec3::new(0.3, 0.5, 0.4);
            }
        }
    }

    /// The surfaces a pass's eye rays see, in scan order: each sample's
    /// hit, eye ray direction and pixel index, with `shade()`'s one-wide
    /// value for it (what pixel replays run).
    fn seen_samples(job: &PassJob, query: &BvhQuery) -> Vec<(SurfaceHit, Vec3, u32, Radiance)> {
        let (w, h) = (job.view.width, job.view.height);
        let mut seen = Vec::new();
        for (x, y) in (0..h).flat_map(|y| (0..w).map(move |x| (x, y))) {
            let p = job.sample_position(x, y);
            let ray = job.view.eye_ray(p.x, p.y);
            let Some(hit) = query.closest(&ray, job.view.far_t(p.x, p.y), false, &mut RayCounts::default(), &mut NoRecord) else { continue };
            let pixel = job.pixel_index(x, y);
            let one = crate::render::resolve_sample(job, query, &ray, Some(&hit), pixel, &mut RayCounts::default(), &mut NoRecord);
            seen.push((hit, ray.dir, pixel, one));
        }
        seen
    }

    /// Eight (or fewer) samples shaded together give each sample's
    /// one-wide `shade()` value bit for bit: on every built-in scene (glossy,
    /// mirror, glass, several lights), with flat and Phong normals, with and
    /// without shadow rays, and with ambient occlusion's random rays; and
    /// with every glossy model (GGX and Beckmann lanes among them, counted).
    #[test]
    fn batches_equal_one_sample_shading() {
        use crate::scene::material::GlossyModel;
        let mut compared = 0;
        let mut lit_by_model = [0usize; 5];
        for_each_shading_case(|name, job, query| {
            assert!(batchable(job));
            let settings = job.settings;
            let mut batch = Batch::new();
            let mut expected = Vec::new();
            let mut check = |batch: &mut Batch, expected: &mut Vec<Radiance>| {
                let got = shade_batch(job, query, batch, None, &mut RayCounts::default());
                for j in 0..batch.len() {
                    assert_eq!(got[j].to_array().map(f32::to_bits), expected[j].to_array().map(f32::to_bits), "{name} {:?} {:?} {:?} lane {j} of {}", settings.interpolation, settings.shadows, settings.gi.mode, batch.len());
                }
                compared += batch.len();
                batch.clear();
                expected.clear();
            };
            for (hit, dir, pixel, one) in seen_samples(job, query) {
                let material = &job.prepared.scene.materials[hit.material as usize];
                if material.has_glossy() && one != Radiance::ZERO {
                    lit_by_model[lighting::model_lane(material.glossy_model) as usize] += 1;
                }
                batch.push(settings.interpolation, &hit, dir, pixel, job.sample, 0);
                expected.push(one);
                // Odd-sized batches too: flush after five when the pixel index says so.
                if batch.is_full() || (pixel % 7 == 0 && batch.len() == 5) {
                    check(&mut batch, &mut expected);
                }
            }
            if !batch.is_empty() {
                check(&mut batch, &mut expected);
            }
        });
        assert!(compared > 3000, "only {compared} samples compared");
        for model in [GlossyModel::Ggx, GlossyModel::Beckmann, GlossyModel::Phong, GlossyModel::BlinnPhong, GlossyModel::Ward] {
            let seen = lit_by_model[lighting::model_lane(model) as usize];
            assert!(seen > 200, "only {seen} lit glossy samples of {model:?} compared");
        }
    }

    /// Two full batches shaded together (`shade_batch_pair`, sixteen lanes)
    /// give each sample's one-wide `shade()` value bit for bit, with and
    /// without shadow rays (traced ahead as packets, as frames do), flat
    /// and Phong; and pairs that need more than direct light (mirrors,
    /// glass, textures, ambient occlusion) are refused, not shaded wrong.
    #[test]
    fn batch_pairs_equal_one_sample_shading() {
        use crate::render::accel::packet::Packet;
use crate::render::transport::shadow_packets::shadow_packets;
        let (mut paired, mut refused) = (0, 0);
        let mut pk = Packet::new();
        for_each_shading_case(|name, job, query| {
            let settings = job.settings;
            let traced = settings.shadows == ShadowMode::Ray;
            let (mut batches, mut expected) = ([Batch::new(), Batch::new()], Vec::new());
            for (hit, dir, pixel, one) in seen_samples(job, query) {
                expected.push(one);
                let b = usize::from(batches[0].is_full());
                batches[b].push(settings.interpolation, &hit, dir, pixel, job.sample, 0);
                if !batches[1].is_full() {
                    continue;
                }
                let mut queue_blocked = vec![0u64; job.prepared.scene.lights.len()];
                if traced {
                    shadow_packets(query, settings, &batches, |b, j| LANES * b + j, &mut pk, &mut queue_blocked, &mut RayCounts::default());
                }
                let bits: [Vec<u8>; 2] = [0, 1].map(|b| queue_blocked.iter().map(|q| (q >> (LANES * b)) as u8).collect());
                let blocked = [&bits[0], &bits[1]].map(|v| traced.then_some(&v[..]));
                let mut got = [[Radiance::NAN; LANES]; 2];
                if shade_batch_pair(job, query, [&batches[0], &batches[1]], blocked, &mut RayCounts::default(), &mut got) {
                    for (k, (got, want)) in got.iter().flatten().zip(&expected).enumerate() {
                        assert_eq!(got.to_array().map(f32::to_bits), want.to_array().map(f32::to_bits), "{name} {:?} {:?} {:?} lane {k} of 16", settings.interpolation, settings.shadows, settings.gi.mode);
                    }
                    paired += 1;
                } else {
                    refused += 1;
                }
                batches.iter_mut().for_each(Batch::clear);
                expected.clear();
            }
        });
        assert!(paired > 50 && refused > 20, "{paired} pairs shaded, {refused} refused");
    }

    /// Eight ray hits filled into a batch at once (`fill_ray_triangles`,
    /// what the ray caster does for a packet's group of eight triangle
    /// hits) make the records and the shading that eight
    /// `push_ray_triangle`s make: on every built-in scene, flat and Phong.
    #[test]
    fn filled_batches_equal_pushed_ones() {
        let mut compared = 0;
        for name in builtin::names() {
            let prepared = PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap());
            let query = BvhQuery::new(&prepared);
            let scene = &prepared.scene;
            let (w, h) = (29u32, 19u32);
            let view = scene.camera.view(w, h);
            let cancel = AtomicBool::new(false);
            for interpolation in [Interpolation::Phong, Interpolation::Flat] {
                let settings = RenderSettings { interpolation, ..RenderSettings::for_scene(scene) };
                let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: glam::Vec2::new(0.25, 0.75), sample: 3, photons: None, active: None, rows: 0..h, cancel: &cancel, keep_non_finite: false };
                let mut hits = Vec::new();
                for (x, y) in (0..h).flat_map(|y| (0..w).map(move |x| (x, y))) {
                    let p = job.sample_position(x, y);
                    let ray = view.eye_ray(p.x, p.y);
                    match query.closest(&ray, view.far_t(p.x, p.y), false, &mut RayCounts::default(), &mut NoRecord) {
                        Some(hit) if hit.kind == PrimitiveKind::Triangle => hits.push((hit, ray, job.pixel_index(x, y))),
                        _ => continue,
                    }
                }
                for eight in hits.chunks_exact(LANES) {
                    let mut pushed = Batch::new();
                    for (slot, (hit, ray, pixel)) in eight.iter().enumerate() {
                        pushed.push_ray_triangle(TriangleHitInput::new(hit.primitive, (hit.barycentric.y, hit.barycentric.z), hit.t, ray.dir), *pixel, job.sample, slot);
                    }
                    pushed.build_pending(scene, &view, interpolation);
                    let index = std::array::from_fn(|k| eight[k].0.primitive);
                    let (b1, b2): (Floats, Floats) = (std::array::from_fn(|k| eight[k].0.barycentric.y), std::array::from_fn(|k| eight[k].0.barycentric.z));
                    let t = std::array::from_fn(|k| eight[k].0.t);
                    let dir = std::array::from_fn(|a| std::array::from_fn(|k| eight[k].1.dir[a]));
                    let mut filled = Batch::new();
                    filled.fill_ray_triangles(scene, interpolation, &index, (&b1, &b2), &t, &dir, std::array::from_fn(|k| eight[k].2), [job.sample; LANES], IN_ORDER);
                    assert_eq!((filled.len(), filled.slots, filled.pixels), (pushed.len(), pushed.slots, pushed.pixels));
                    for k in 0..LANES {
                        let (a, b) = (filled.hit(k), pushed.hit(k));
                        assert_eq!(format!("{a:?}"), format!("{b:?}"), "{name} {interpolation:?} lane {k}");
                        assert_eq!(filled.w_o.map(|c| c[k].to_bits()), pushed.w_o.map(|c| c[k].to_bits()));
                    }
                    let (a, b) = (shade_batch(&job, &query, &filled, None, &mut RayCounts::default()), shade_batch(&job, &query, &pushed, None, &mut RayCounts::default()));
                    assert_eq!(a.map(|v| v.to_array().map(f32::to_bits)), b.map(|v| v.to_array().map(f32::to_bits)), "{name} {interpolation:?}");
                    compared += LANES;
                }
            }
        }
        assert!(compared > 2000, "only {compared} samples compared");
    }
}
