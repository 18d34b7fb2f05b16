//! The per-region buffers of a rasterizer: depth, visibility (which primitive
//! and where on it) and, in forward mode, colour. Every variant writes its
//! fragments here; the depth test, the shading hand-off to `resolve_sample`
//! and the counters live in this one place.
//!
//! Depth keys: smaller is nearer. Variants that cast 3D rays (naive, bbox)
//! store the ray parameter t, exactly as the ray caster compares hits; the
//! others store -1/z, which is affine in image space, or what `--depth-buffer`
//! turns it into (`depth_format`: quantized z/w, reversed z). Ties keep the
//! earlier fragment (strict `<`), so the earlier triangle in scene order
//! wins, as in the brute-force caster.
//!
//! The painter's algorithm (`paint`) keeps no depth test: every fragment
//! overwrites the sample, so the last primitive drawn is the one seen. The
//! keys are still written, for the fragment record.

use crate::render::differentials::{with_ray_differentials, RayDifferential};
use crate::render::raster::depth_format::{DepthEncoding, DepthFormat};
use crate::render::raster::fixed::FixedTri;
use crate::math::lanes::{mask_bits, mask_from_bits, simd_level};
use fearless_simd::{dispatch, f32x8, u32x8, Select, Simd, SimdBase, SimdFrom};
use crate::render::raster::rect::{PixelRect, TestCounter};
use crate::render::raster::setup::ScreenTri;
use crate::math::{streaming, Radiance, Ray, Vec3};
use crate::render::finite::{admit_all, admit_rows_except, admitted};
use std::ops::Range;
use crate::render::inspect::debug::{cost_color, View};
use crate::render::inspect::pixel_record::{CsgABufferRecord, FragmentRecord, NoRecord, PixelTrace, Recorder};
use crate::render::{resolve_counted, resolve_sample, view_miss_without_ray, PassJob, RayCounts, SceneQuery};
use crate::render::ShadeQueue;
use crate::scene::hit_lanes::EyeSamples;
use crate::render::shadow::volume::split_depth;
use crate::render::raster::stencil::{PixelRay, StencilSetup};
use crate::render::accel::csg::{Boundary, SurfaceRef};
use crate::scene::{PrimitiveId, PrimitiveKind, SurfaceHit};

/// What `VisBuffer::csg` holds where no CSG object won.
const NO_BOUNDARY: Boundary = Boundary { t: 0.0, surface: SurfaceRef::Sphere(0), leaf: 0, flipped: false };


/// What a depth key measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthKey {
    /// Ray parameter along the eye ray (starts at far_t, the far plane).
    RayT,
    /// -1 / view depth (starts at -1 / far), or its `--depth-buffer` encoding.
    NegInvZ,
}

/// A `Recorder` that also takes the rasterizer's fragments (pixel history).
/// `NoRecord` ignores them, so frames pay nothing.
pub trait FragmentRecorder: Recorder {
    fn fragment(&mut self, _f: FragmentRecord) {}
    fn csg_abuffer(&mut self, _a: CsgABufferRecord) {}
}

impl FragmentRecorder for NoRecord {}

impl FragmentRecorder for PixelTrace {
    fn fragment(&mut self, f: FragmentRecord) {
        self.fragments.push(f);
    }

    fn csg_abuffer(&mut self, a: CsgABufferRecord) {
        self.csg_abuffers.push(a);
    }
}

/// Samples tested by a coverage loop, with a per-pixel map for the cost view.
pub struct TestCountMap {
    pub total: u64,
    rect: PixelRect,
    per_pixel: Vec<u32>,
}

impl TestCounter for TestCountMap {
    #[inline]
    fn add(&mut self, r: PixelRect) {
        self.total += r.area();
        if !self.per_pixel.is_empty() {
            let stride = self.rect.width() as usize;
            for y in r.y0..r.y1 {
                let row = (y - self.rect.y0) as usize * stride;
                for x in r.x0..r.x1 {
                    self.per_pixel[row + (x - self.rect.x0) as usize] += 1;
                }
            }
        }
    }
}

pub struct VisBuffer<'j, 'a, Q: SceneQuery, R: FragmentRecorder = NoRecord> {
    pub job: &'j PassJob<'a>,
    pub query: &'j Q,
    pub rect: PixelRect,
    stride: usize,
    pub key: DepthKey,
    /// How `NegInvZ` keys are stored (`--depth-buffer`).
    pub enc: DepthEncoding,
    /// The painter's algorithm: no depth test, every fragment overwrites
    /// (`set_painter`).
    paint: bool,
    /// Whether `triangle_row` may do a row eight samples at a time: only the
    /// depth test and the store happen per fragment (early depth, float
    /// keys, perspective interpolation, no painter, no cost view, nothing
    /// recorded). Worked out once per buffer, not per row.
    rows_in_lanes: bool,
    /// Whether some material is cut away where its alpha is low: each
    /// triangle sample is then looked up there, and a cut-away one is
    /// discarded before the depth test, as if not covered.
    cutouts: bool,
    /// Shade every fragment that passes the depth test (forward) instead of
    /// once per pixel after visibility is known (early depth).
    pub forward: bool,
    pub depth: Vec<f32>,
    /// What each sample sees; `PrimitiveId::NONE` where nothing covers it.
    pub id: Vec<PrimitiveId>,
    /// Triangles: perspective-correct (b1, b2) in the scene triangle. Spheres
    /// and CSG objects: (t, 0).
    pub payload: Vec<[f32; 2]>,
    /// CSG objects: the boundary the A-buffer resolved each sample to (where
    /// `id` is a CSG object); empty for scenes without them.
    csg: Vec<Boundary>,
    color: Vec<Radiance>,
    /// Cost view only (else empty): per pixel, fragments depth-tested plus fragments shaded...
    work: Vec<u32>,
    /// ... and samples tested by the coverage loops.
    tests: Vec<u32>,
    pub counts: RayCounts,
    /// The recorder, and the one pixel whose history it takes (replay only).
    pub rec: R,
    focus: (u32, u32),
    /// MSAA coverage sample of this buffer (recorded with its fragments).
    pub sample: Option<u32>,
    /// `--shadows volume`: per pixel, one shadow-volume count per light
    /// (`stencil_lights` of them), filled after the depth pass; empty otherwise.
    stencil: Vec<i32>,
    stencil_lights: usize,
    /// The visible samples waiting to be shaded (`resolve_batched`), and
    /// with `--gi path` their paths: kept with the buffer (empty between
    /// regions) so that its buffers grow once, made at the first region
    /// that shades in batches rather than in every region or tile.
    queue: Option<ShadeQueue<'a>>,
    /// `resolve_batched`'s runs of the output streamed past the cache
    /// (ranges of slots): the rest is admitted once the region is shaded;
    /// kept like `queue`.
    streamed: Vec<Range<usize>>,
}

impl<'j, 'a, Q: SceneQuery> VisBuffer<'j, 'a, Q, NoRecord> {
    pub fn new(job: &'j PassJob<'a>, query: &'j Q, rect: PixelRect, key: DepthKey, forward: bool) -> Self {
        VisBuffer::with_recorder(job, query, rect, key, forward, NoRecord, (u32::MAX, u32::MAX))
    }
}

impl<'j, 'a, Q: SceneQuery, R: FragmentRecorder> VisBuffer<'j, 'a, Q, R> {
    /// A buffer whose recorder `rec` takes the history of pixel `focus`.
    pub fn with_recorder(job: &'j PassJob<'a>, query: &'j Q, rect: PixelRect, key: DepthKey, forward: bool, rec: R, focus: (u32, u32)) -> Self {
        let n = rect.area() as usize;
        let enc = DepthEncoding::for_view(job.settings.depth_buffer, job.view);
        let depth = match key {
            DepthKey::NegInvZ => vec![enc.clear_key(); n],
            DepthKey::RayT => {
                let mut d = Vec::with_capacity(n);
                for y in rect.y0..rect.y1 {
                    for x in rect.x0..rect.x1 {
                        let p = job.sample_position(x, y);
                        d.push(job.view.far_t(p.x, p.y));
                    }
                }
                d
            }
        };
        let cost = job.settings.view == View::Cost;
        let rows_in_lanes = Self::rows_in_lanes_allowed(job, forward, &enc);
        VisBuffer {
            job,
            query,
            rect,
            stride: rect.width() as usize,
            key,
            enc,
            paint: false,
            rows_in_lanes,
            cutouts: job.prepared.scene.has_cutouts(),
            forward,
            depth,
            id: vec![PrimitiveId::NONE; n],
            payload: vec![[0.0; 2]; n],
            csg: if job.prepared.scene.csgs.is_empty() { Vec::new() } else { vec![NO_BOUNDARY; n] },
            color: if forward { vec![Radiance::ZERO; n] } else { Vec::new() },
            work: if cost { vec![0; n] } else { Vec::new() },
            tests: if cost { vec![0; n] } else { Vec::new() },
            counts: RayCounts::default(),
            rec,
            focus,
            sample: None,
            stencil: Vec::new(),
            stencil_lights: 0,
            queue: None,
            streamed: Vec::new(),
        }
    }

    /// Draws with the painter's algorithm (no depth test) or not.
    pub fn set_painter(&mut self, on: bool) {
        self.paint = on;
        self.rows_in_lanes = !on && Self::rows_in_lanes_allowed(self.job, self.forward, &self.enc);
    }

    /// `rows_in_lanes` apart from the painter.
    fn rows_in_lanes_allowed(job: &PassJob, forward: bool, enc: &DepthEncoding) -> bool {
        !R::ENABLED && !job.prepared.scene.has_cutouts() && !forward && job.settings.view != View::Cost && !job.settings.affine && enc.format == DepthFormat::F32
    }

    /// Index of image pixel `(x, y)` in this region's buffers.
    #[inline(always)]
    pub fn index(&self, x: u32, y: u32) -> usize {
        (x - self.rect.x0) as usize + (y - self.rect.y0) as usize * self.stride
    }

    #[inline(always)]
    fn is_focus(&self, x: u32, y: u32) -> bool {
        R::ENABLED && (x, y) == self.focus
    }

    /// The pixel whose history the recorder takes (`None` when nothing is recorded).
    #[inline(always)]
    pub fn focus(&self) -> Option<(u32, u32)> {
        R::ENABLED.then_some(self.focus)
    }

    /// Counts the samples of `r` as tested (loops that test through the buffer).
    #[inline]
    pub fn add_tested(&mut self, r: PixelRect) {
        let mut t = self.begin_tests();
        t.add(r);
        self.end_tests(t);
    }

    /// A counter for a coverage loop that cannot borrow the buffer while it runs.
    #[inline]
    pub fn begin_tests(&mut self) -> TestCountMap {
        TestCountMap { total: 0, rect: self.rect, per_pixel: std::mem::take(&mut self.tests) }
    }

    #[inline]
    pub fn end_tests(&mut self, t: TestCountMap) {
        self.counts.samples_tested += t.total;
        self.tests = t.per_pixel;
    }

    /// The cost view's work at pixel index `i` (see `View::Cost`).
    pub fn work_at(&self, i: usize) -> u32 {
        self.work.get(i).copied().unwrap_or(0) + self.tests.get(i).copied().unwrap_or(0)
    }

    #[inline(always)]
    fn count_work(&mut self, i: usize) {
        if !self.work.is_empty() {
            self.work[i] += 1;
        }
    }

    /// The view depth of a depth key at pixel `(x, y)` (for the record).
    fn view_depth_of_key(&self, key: f32, x: u32, y: u32) -> f32 {
        match self.key {
            DepthKey::NegInvZ => self.enc.view_depth(key),
            DepthKey::RayT => {
                let p = self.job.sample_position(x, y);
                self.job.view.near + key / self.job.view.camera_dir(p.x, p.y).length()
            }
        }
    }

    /// A covered sample of screen triangle `st` with screen-space weights `l`:
    /// depth test on -1/z, then perspective-correct barycentrics on a pass.
    #[inline(always)]
    pub fn triangle_fragment(&mut self, st: &ScreenTri, x: u32, y: u32, l: [f32; 3]) {
        let depth = st.affine_depth_at(l);
        let affine = self.job.settings.affine;
        if self.cut_out(st.tri, || if affine { st.affine_bary_at(l) } else { st.bary_at(l, depth) }) {
            return;
        }
        self.counts.samples_covered += 1;
        let i = self.index(x, y);
        self.count_work(i);
        let key = if self.enc.format == DepthFormat::LinearZ && st.perspective { self.enc.key(1.0 / st.linear_z_at(l)) } else { self.enc.key(depth) };
        let stored = self.depth[i];
        let passed = self.paint || key < stored;
        if passed {
            self.depth[i] = key;
            self.id[i] = PrimitiveId::triangle(st.tri);
            self.payload[i] = if self.job.settings.affine { st.affine_bary_at(l) } else { st.bary_at(l, depth) };
            if self.forward {
                self.shade_now(i, x, y);
            }
        } else {
            self.counts.depth_fails += 1;
        }
        if self.is_focus(x, y) {
            // The 2D weights as weights of the scene triangle's vertices (affine
            // interpolation of the piece's vertex barycentrics).
            let screen = st.affine_weights(l);
            let [b1, b2] = st.bary_at(l, depth);
            self.record(PrimitiveKind::Triangle, st.tri, Some(screen), Vec3::new(1.0 - b1 - b2, b1, b2), key, stored, passed, i, x, y);
        }
    }

    /// The covered samples `bits` (bit k: pixel `x0 + k`) of row `y` of
    /// snapped triangle `ft`: `triangle_fragment` for each, with its
    /// screen-space weights, in order. Where nothing but the depth test and
    /// the visibility store happens (early depth, float keys, perspective
    /// interpolation, no cost view, nothing recorded: most frames), the row
    /// is done eight samples at a time with the same arithmetic
    /// (`triangle_row8`).
    #[inline]
    pub fn triangle_row(&mut self, ft: &FixedTri, x0: u32, y: u32, bits: u8) {
        let i = self.index(x0, y);
        if self.rows_in_lanes && i + 8 <= self.depth.len() && bits.count_ones() > 1 {
            dispatch!(simd_level(), simd => self.triangle_row8(simd, ft, x0, y, bits, i));
            return;
        }
        for x in crate::render::raster::fixed::row_pixels(x0, bits) {
            self.triangle_fragment(&ft.st, x, y, ft.weights(x, y));
        }
    }

    /// `triangle_row` eight samples at a time, from buffer index `i` (pixel
    /// `x0`): `screen_weights`, `affine_depth_at`, the F32 key, the depth test and
    /// `bary_at` in lanes, each with the scalar code's operations in its
    /// order, so every stored value is the one `triangle_fragment` stores.
    #[inline(always)]
    fn triangle_row8<S: Simd>(&mut self, simd: S, ft: &FixedTri, x0: u32, y: u32, bits: u8, i: usize) {
        let st = &ft.st;
        let xs: [f32; 8] = std::array::from_fn(|k| (x0 + k as u32) as f32);
        let qx = f32x8::simd_from(simd, xs) + f32x8::splat(simd, ft.sample_off.x);
        let qy = f32x8::splat(simd, y as f32 + ft.sample_off.y);
        // The scalar fragment's arithmetic, eight samples at a time.
        let l = st.screen_weights_lanes(qx, qy);
        let depth = st.affine_depth_lanes(&l);
        // The F32 key: -1/z, or z itself along parallel rays.
        let key = if self.enc.orthographic { depth } else { -depth };
        let stored = f32x8::from_slice(simd, &self.depth[i..i + 8]);
        let passed = mask_bits(key.simd_lt(stored)) & bits;
        self.counts.samples_covered += bits.count_ones() as u64;
        self.counts.depth_fails += (bits & !passed).count_ones() as u64;
        if passed == 0 {
            return;
        }
        let [b1, b2] = st.bary_lanes(&l, depth);
        // The samples that pass take the new values, the others keep
        // theirs: each buffer's eight entries blended and stored whole, not
        // written one passing sample at a time.
        let m = mask_from_bits(simd, passed);
        self.depth[i..i + 8].copy_from_slice(&<[f32; 8]>::from(m.select(key, stored)));
        let ids: &mut [u32] = bytemuck::cast_slice_mut(&mut self.id[i..i + 8]);
        let id = u32x8::splat(simd, PrimitiveId::triangle(st.tri).bits());
        ids.copy_from_slice(&<[u32; 8]>::from(m.select(id, u32x8::from_slice(simd, ids))));
        // The payload's pairs (b1, b2) of samples 0-3, then of 4-7.
        let payload: &mut [f32] = bytemuck::cast_slice_mut(&mut self.payload[i..i + 8]);
        let pairs = b1.interleave(b2);
        for (half, new) in [pairs.0, pairs.1].into_iter().enumerate() {
            let taken = mask_from_bits(simd, each_bit_twice(passed >> (4 * half)));
            let old = &mut payload[8 * half..8 * half + 8];
            let blended = taken.select(new, f32x8::from_slice(simd, old));
            old.copy_from_slice(&<[f32; 8]>::from(blended));
        }
    }

    /// Whether triangle `tri` is cut away at the sample whose (b1, b2)
    /// `bary` gives (looked up only in scenes with cutouts).
    #[inline(always)]
    fn cut_out(&self, tri: u32, bary: impl FnOnce() -> [f32; 2]) -> bool {
        self.cutouts && {
            let [b1, b2] = bary();
            self.job.prepared.scene.cut_out_at(tri, b1, b2)
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn record(&mut self, kind: PrimitiveKind, primitive: u32, screen: Option<Vec3>, b: Vec3, key: f32, stored: f32, passed: bool, i: usize, x: u32, y: u32) {
        let f = FragmentRecord {
            kind,
            primitive,
            screen_barycentric: screen,
            barycentric: b,
            depth: self.view_depth_of_key(key, x, y),
            stored_depth: self.view_depth_of_key(stored, x, y),
            passed_depth_test: passed,
            shaded: (passed && self.forward).then(|| self.color[i]),
            sample: self.sample,
        };
        self.rec.fragment(f);
    }

    /// A ray-triangle hit of a triangle too small for the sub-pixel grid
    /// (`small.rs`), in a buffer of -1/z keys: depth-tested on the key of the
    /// hit's view depth, keeping the ray test's barycentrics.
    #[inline]
    pub fn small_triangle_fragment(&mut self, x: u32, y: u32, tri: u32, t: f32, b1: f32, b2: f32) {
        if self.cut_out(tri, || [b1, b2]) {
            return;
        }
        self.counts.samples_covered += 1;
        let i = self.index(x, y);
        self.count_work(i);
        let p = self.job.sample_position(x, y);
        let depth = self.job.view.near + t / self.job.view.camera_dir(p.x, p.y).length();
        let key = self.enc.key_at_depth(depth);
        let stored = self.depth[i];
        let passed = self.paint || key < stored;
        if passed {
            self.depth[i] = key;
            self.id[i] = PrimitiveId::triangle(tri);
            self.payload[i] = [b1, b2];
            if self.forward {
                self.shade_now(i, x, y);
            }
        } else {
            self.counts.depth_fails += 1;
        }
        if self.is_focus(x, y) {
            self.record(PrimitiveKind::Triangle, tri, None, Vec3::new(1.0 - b1 - b2, b1, b2), key, stored, passed, i, x, y);
        }
    }

    /// A ray-triangle hit already known to be nearer than the pixel's stored
    /// depth (naive, bbox: the ray test's `t_max`).
    #[inline(always)]
    pub fn ray_fragment(&mut self, x: u32, y: u32, tri: u32, t: f32, b1: f32, b2: f32) {
        if self.cut_out(tri, || [b1, b2]) {
            return;
        }
        self.counts.samples_covered += 1;
        let i = self.index(x, y);
        self.count_work(i);
        let stored = self.depth[i];
        self.depth[i] = t;
        self.id[i] = PrimitiveId::triangle(tri);
        self.payload[i] = [b1, b2];
        if self.forward {
            self.shade_now(i, x, y);
        }
        if self.is_focus(x, y) {
            self.record(PrimitiveKind::Triangle, tri, None, Vec3::new(1.0 - b1 - b2, b1, b2), t, stored, true, i, x, y);
        }
    }

    /// A covered sample of a ray-triangle test that lost the depth test; the
    /// replay re-tests the ray without a bound to record where it hit.
    #[inline(always)]
    pub fn ray_depth_fail(&mut self, x: u32, y: u32, tri: u32, ray: &Ray) {
        self.counts.samples_covered += 1;
        self.counts.depth_fails += 1;
        let i = self.index(x, y);
        self.count_work(i);
        if self.is_focus(x, y) {
            let edges = &self.job.prepared.triangle_edges(tri);
            if let Ok((t, b1, b2)) = crate::render::accel::intersect::intersect_triangle(ray, edges, f32::INFINITY) {
                let stored = self.depth[i];
                self.record(PrimitiveKind::Triangle, tri, None, Vec3::new(1.0 - b1 - b2, b1, b2), t, stored, false, i, x, y);
            }
        }
    }

    /// The eye ray hits sphere `s` at `t`. Against another sphere the two ray
    /// parameters are compared (as the ray caster does); against a triangle the
    /// depth keys. The painter overwrites whatever is there.
    #[inline]
    pub fn sphere_fragment(&mut self, x: u32, y: u32, s: u32, t: f32, key: f32) {
        let (i, stored, nearer) = self.analytic_fragment(x, y, PrimitiveId::sphere(s), t, key, None);
        if self.is_focus(x, y) {
            self.record(PrimitiveKind::Sphere, s, None, Vec3::ZERO, key, stored, nearer, i, x, y);
        }
    }

    /// The A-buffer of CSG object `c` resolved this sample to boundary `b`
    /// (at `b.t` along the eye ray): depth tested as a sphere's fragment is
    /// (ray parameters against spheres and other CSG objects, depth keys
    /// against triangles).
    #[inline]
    pub fn csg_fragment(&mut self, x: u32, y: u32, c: u32, b: Boundary, key: f32) {
        let (i, stored, nearer) = self.analytic_fragment(x, y, PrimitiveId::csg(c), b.t, key, Some(b));
        if self.is_focus(x, y) {
            // The winning surface's barycentrics when it is an operand triangle.
            let bary = match b.surface {
                SurfaceRef::Triangle { b1, b2, .. } => Vec3::new(1.0 - b1 - b2, b1, b2),
                SurfaceRef::Sphere(_) => Vec3::ZERO,
            };
            self.record(PrimitiveKind::Csg, c, None, bary, key, stored, nearer, i, x, y);
        }
    }

    /// The depth test and store that sphere and CSG fragments share, for
    /// surface `id` met at ray parameter `t` with depth key `key` (and, for
    /// a CSG object, the boundary its A-buffer resolved). Returns the
    /// sample's index, the key it held before and whether `id` won.
    #[inline]
    fn analytic_fragment(&mut self, x: u32, y: u32, id: PrimitiveId, t: f32, key: f32, boundary: Option<Boundary>) -> (usize, f32, bool) {
        self.counts.samples_covered += 1;
        let i = self.index(x, y);
        self.count_work(i);
        let cur = self.id[i];
        let stored = self.depth[i];
        let nearer = if cur.is_none() || self.paint {
            true
        } else if cur.is_sphere() || cur.is_csg() {
            t < self.payload[i][0]
        } else {
            key < stored
        };
        if nearer {
            self.depth[i] = key;
            self.id[i] = id;
            self.payload[i] = [t, 0.0];
            if let Some(b) = boundary {
                self.csg[i] = b;
            }
            if self.forward {
                self.shade_now(i, x, y);
            }
        } else {
            self.counts.depth_fails += 1;
        }
        (i, stored, nearer)
    }

    fn shade_now(&mut self, i: usize, x: u32, y: u32) {
        self.counts.fragments_shaded += 1;
        self.count_work(i);
        self.color[i] = self.shade(i, x, y);
    }

    /// The eye ray of pixel `(x, y)`'s sample and the `SurfaceHit` of what
    /// the buffer says it sees.
    fn eye_hit(&self, i: usize, x: u32, y: u32) -> (Ray, Option<SurfaceHit>) {
        let p = self.job.sample_position(x, y);
        let ray = self.job.view.eye_ray(p.x, p.y);
        let id = self.id[i];
        let scene = &self.job.prepared.scene;
        let hit = if id.is_none() {
            None
        } else if id.is_csg() {
            // The boundary the A-buffer resolved, built into a hit as the ray casters build theirs.
            let h = crate::render::accel::csg::surface_hit(scene, id.index(), self.csg[i], &ray);
            // Seen along the eye ray, as in the ray casters: the same differentials.
            if scene.has_textures() {
                let mut h = with_ray_differentials(scene, &RayDifferential::eye(self.job.view, p.x, p.y), &ray, h);
                crate::scene::normal_map::apply(scene, self.job.settings.texture_filter, &mut h);
                Some(h)
            } else {
                Some(h)
            }
        } else if id.is_sphere() {
            let hit = scene.sphere_hit(id.index(), self.payload[i][0], &ray);
            // The sphere is hit by the eye ray, as in the ray casters: the same differentials.
            Some(match scene.has_textures() {
                true => {
                    let mut hit = with_ray_differentials(scene, &RayDifferential::eye(self.job.view, p.x, p.y), &ray, hit);
                    crate::scene::normal_map::apply(scene, self.job.settings.texture_filter, &mut hit);
                    hit
                }
                false => hit,
            })
        } else {
            let (b, t) = self.triangle_b_t(i, &ray);
            let mut hit = scene.triangle_hit(id.index(), b, t, &ray);
            if scene.has_textures() {
                hit.diff = crate::render::raster::derivatives::screen_differentials(scene, self.job.view, id.index(), b, p.x, p.y);
                crate::scene::normal_map::apply(scene, self.job.settings.texture_filter, &mut hit);
            }
            Some(hit)
        };
        (ray, hit)
    }

    /// The barycentric weights and the eye ray's `t` of the triangle sample
    /// `i` sees.
    #[inline]
    fn triangle_b_t(&self, i: usize, ray: &Ray) -> (Vec3, f32) {
        let [b1, b2] = self.payload[i];
        let b = Vec3::new(1.0 - b1 - b2, b1, b2);
        let t = match self.key {
            DepthKey::RayT => self.depth[i],
            DepthKey::NegInvZ => {
                let v = self.job.prepared.scene.triangle_positions(self.id[i].index());
                let pos = v[0] * b.x + v[1] * b.y + v[2] * b.z;
                (pos - ray.origin).dot(ray.dir)
            }
        };
        (b, t)
    }

    /// The far bound of pixel `(x, y)`'s eye ray (for the record).
    fn far_t(&self, x: u32, y: u32) -> f32 {
        let p = self.job.sample_position(x, y);
        self.job.view.far_t(p.x, p.y)
    }

    /// The stencil pass of `--shadows volume`, after the depth pass: every
    /// pixel that sees a surface gets its count per light (`stencil.rs`).
    pub fn count_volumes(&mut self, setup: &StencilSetup) {
        let r = self.rect;
        let mut rays: Vec<PixelRay> = Vec::with_capacity(r.area() as usize);
        let mut i = 0;
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                rays.push(if self.id[i].is_none() {
                    None
                } else {
                    let (ray, hit) = self.eye_hit(i, x, y);
                    hit.map(|h| (ray.origin, ray.dir, split_depth(h.t)))
                });
                i += 1;
            }
        }
        self.stencil_lights = setup.lights;
        self.stencil.clear();
        self.stencil.resize(rays.len() * setup.lights, 0);
        setup.count(r, &rays, &mut self.stencil);
    }

    /// Hands what pixel index `i` sees to the shared shading (recorded for the
    /// focus pixel), with its stencil counts when there are any.
    pub fn shade(&mut self, i: usize, x: u32, y: u32) -> Radiance {
        if !self.job.is_active(x, y) {
            return Radiance::ZERO;
        }
        if self.id[i].is_none() && !self.is_focus(x, y) {
            if let Some(background) = view_miss_without_ray(self.job) {
                return background;
            }
        }
        let (ray, hit) = self.eye_hit(i, x, y);
        let focus = self.is_focus(x, y);
        if focus {
            self.rec.ray(&ray, self.far_t(x, y), 0);
            self.rec.closest(hit.as_ref());
        }
        let pixel = self.job.pixel_index(x, y);
        let l = self.stencil_lights;
        if !self.stencil.is_empty() && hit.is_some() {
            let volume = &self.stencil[i * l..(i + 1) * l];
            return if focus {
                resolve_counted(self.job, self.query, &ray, hit.as_ref(), volume, pixel, &mut self.counts, &mut self.rec)
            } else {
                resolve_counted(self.job, self.query, &ray, hit.as_ref(), volume, pixel, &mut self.counts, &mut NoRecord)
            };
        }
        if focus {
            return resolve_sample(self.job, self.query, &ray, hit.as_ref(), pixel, &mut self.counts, &mut self.rec);
        }
        resolve_sample(self.job, self.query, &ray, hit.as_ref(), pixel, &mut self.counts, &mut NoRecord)
    }

    /// True when the frame shows the cost view instead of shading.
    pub fn cost_view(&self) -> bool {
        self.job.settings.view == View::Cost
    }

    /// The final value of pixel `(x, y)` (index `i`): early-depth mode shades
    /// the visible surface here, forward mode already did; the cost view shows
    /// the work counted at the pixel. Counts one primary sample.
    #[inline]
    pub fn resolve(&mut self, i: usize, x: u32, y: u32) -> Radiance {
        self.counts.primary += 1;
        let id = self.id[i];
        if self.cost_view() {
            if !id.is_none() && !self.forward {
                // The shade early depth would do, counted but not computed.
                self.counts.fragments_shaded += 1;
                self.count_work(i);
            }
            let c = cost_color(self.work_at(i) as f32);
            if self.is_focus(x, y) {
                let (ray, hit) = self.eye_hit(i, x, y);
                self.rec.ray(&ray, self.far_t(x, y), 0);
                self.rec.closest(hit.as_ref());
                self.rec.shaded(0, c);
            }
            return c;
        }
        if self.forward && !id.is_none() {
            self.color[i]
        } else {
            if !id.is_none() {
                self.counts.fragments_shaded += 1;
            }
            self.shade(i, x, y)
        }
    }

    /// Resolves every pixel of the region into rows of `out_stride` pixels of
    /// `out` starting at column `x_offset`: early-depth mode shades each
    /// visible surface once here; forward mode already shaded it. Counts one
    /// primary sample per pixel. Every value written is admitted
    /// (`finite::admitted`) before this returns, while it is in cache.
    pub fn resolve_into(&mut self, out: &mut [Radiance], out_stride: usize, x_offset: usize) -> RayCounts {
        if !self.forward && !self.cost_view() && self.stencil.is_empty() && ShadeQueue::takes(self.job) {
            return self.resolve_batched(out, out_stride, x_offset);
        }
        let r = self.rect;
        let mut i = 0;
        for (row, y) in (r.y0..r.y1).enumerate() {
            let line = &mut out[row * out_stride + x_offset..row * out_stride + x_offset + self.stride];
            for (px, x) in line.iter_mut().zip(r.x0..r.x1) {
                *px = self.resolve(i, x, y);
                i += 1;
            }
            if !self.job.keep_non_finite {
                self.counts.non_finite += admit_all(line);
            }
        }
        std::mem::take(&mut self.counts)
    }

    /// `resolve_into` in early-depth mode, the visible surfaces shaded eight
    /// at a time (`ShadeQueue`); empty, inactive and recorded pixels one by
    /// one, as `resolve` does them.
    fn resolve_batched(&mut self, out: &mut [Radiance], out_stride: usize, x_offset: usize) -> RayCounts {
        let r = self.rect;
        let lights = self.job.prepared.scene.lights.len();
        let mut queue = self.queue.take().unwrap_or_else(|| ShadeQueue::new(lights));
        const LANES: usize = ShadeQueue::LANES;
        let scene = &self.job.prepared.scene;
        // A triangle seen without textures (the common case) has its hit
        // built in the batch (eight at a time), not returned and copied.
        // Its eye ray's parameter comes from the hit's position, as
        // `triangle_b_t` works it out from -1/z keys; ray-parameter keys are
        // that parameter itself, and go through `eye_hit`.
        let plain = !scene.has_textures() && self.key == DepthKey::NegInvZ;
        // What an empty pixel shows when no ray is needed for it (most of a
        // frame): `resolve`'s answer there without its per-pixel checks.
        let background = view_miss_without_ray(self.job);
        // No pixel is recorded or left out by this pass: `ordinary` below
        // holds everywhere, without its per-pixel lookups.
        let all_ordinary = !R::ENABLED && self.job.active.is_none();
        // Counted here, added once at the end (`resolve` counts its own).
        let (mut primary, mut shaded) = (0u64, 0u64);
        // Where that holds and no ray is needed, a row's empty pixels are
        // filled at once, and the loop below visits only the others
        // (`visible`, columns of the row); else it visits every pixel.
        // (Admitted here: streamed past the cache, it is not read back.)
        let fill = if all_ordinary { background.map(admitted) } else { None };
        let mut visible: Vec<u32> = Vec::with_capacity(self.stride);
        // The runs of `out` streamed (not in cache), by row: the rest of
        // each row is admitted at the end.
        let mut streamed = std::mem::take(&mut self.streamed);
        // Plain triangles' samples gathered eight at a time, handed to the
        // queue together (a batch's counters are not touched per sample).
        let mut eight = EyeSamples::default();
        let (mut eight_pixels, mut eight_slots) = ([0u32; LANES], [0usize; LANES]);
        for (row, y) in (r.y0..r.y1).enumerate() {
            let line = row * out_stride + x_offset;
            let start = row * self.stride;
            visible.clear();
            match fill {
                Some(value) => {
                    // Runs of empty pixels, filled at once (streamed past
                    // the cache: nothing reads them while the frame is
                    // drawn), and runs of covered ones, whose plain
                    // triangles go straight into the queue; the loop below
                    // takes the others.
                    let ids = &self.id[start..start + self.stride];
                    let payload = &self.payload[start..start + self.stride];
                    let mut col = 0;
                    while col < ids.len() {
                        let empty_from = col;
                        // Sixteen empty samples at a time, then one by one.
                        while let Some(next) = ids.get(col..col + 16) {
                            if !PrimitiveId::all_none::<16>(next.try_into().unwrap()) {
                                break;
                            }
                            col += 16;
                        }
                        while col < ids.len() && ids[col].is_none() {
                            col += 1;
                        }
                        if streaming::fill(&mut out[line + empty_from..line + col], value) {
                            streamed.push(line + empty_from..line + col);
                        }
                        primary += (col - empty_from) as u64;
                        while col < ids.len() && !ids[col].is_none() {
                            // Eight plain triangle samples in a row, nothing
                            // gathered yet and the queue's batch empty (the
                            // usual case inside a surface): the batch is
                            // filled at once, lanes wide.
                            if plain && eight.len == 0 && col + LANES <= ids.len() && queue.batch_is_empty() {
                                let run: &[PrimitiveId; LANES] = ids[col..col + LANES].try_into().unwrap();
                                if let Some(index) = PrimitiveId::triangle_indices(run) {
                                    let x = r.x0 + col as u32;
                                    let bary = payload[col..col + LANES].try_into().unwrap();
                                    queue.push_eye_row(self.job, self.query, &mut self.counts, out, &index, bary, (x, y), line + col);
                                    primary += LANES as u64;
                                    shaded += LANES as u64;
                                    col += LANES;
                                    continue;
                                }
                            }
                            let id = ids[col];
                            if plain && id.kind() == crate::scene::PrimitiveKind::Triangle {
                                let x = r.x0 + col as u32;
                                primary += 1;
                                shaded += 1;
                                let [b1, b2] = payload[col];
                                let k = eight.len;
                                (eight_pixels[k], eight_slots[k]) = (self.job.pixel_index(x, y), line + col);
                                eight.push(id.index(), b1, b2, self.job.sample_position(x, y));
                                if eight.len == LANES {
                                    queue.push_eye_samples(self.job, self.query, &mut self.counts, out, &mut eight, &eight_pixels, &eight_slots);
                                }
                            } else {
                                visible.push(col as u32);
                            }
                            col += 1;
                        }
                    }
                }
                None => visible.extend(0..self.stride as u32),
            }
            for &col in &visible {
                let (col, x) = (col as usize, r.x0 + col);
                let (i, slot) = (start + col, line + col);
                let id = self.id[i];
                // Neither the recorded pixel nor one this pass leaves out.
                let ordinary = all_ordinary || (!self.is_focus(x, y) && self.job.is_active(x, y));
                if let (true, Some(value)) = (id.is_none() && ordinary, background) {
                    primary += 1;
                    out[slot] = value;
                } else if id.is_none() || !ordinary {
                    out[slot] = self.resolve(i, x, y);
                } else {
                    primary += 1;
                    shaded += 1;
                    if plain && id.kind() == crate::scene::PrimitiveKind::Triangle {
                        let [b1, b2] = self.payload[i];
                        queue.push_eye_triangle(self.job, self.query, &mut self.counts, out, id.index(), (b1, b2), (x, y), slot);
                        continue;
                    }
                    match self.eye_hit(i, x, y) {
                        (ray, Some(hit)) => {
                            queue.push_hit(self.job, self.query, &mut self.counts, out, &hit, ray.dir, (x, y), slot);
                        }
                        (_, None) => out[slot] = self.shade(i, x, y),
                    }
                }
            }
        }
        queue.push_eye_samples(self.job, self.query, &mut self.counts, out, &mut eight, &eight_pixels, &eight_slots);
        queue.finish(self.job, self.query, &mut self.counts, out);
        streaming::fence();
        let rows = (0..r.height() as usize).map(|row| row * out_stride + x_offset..row * out_stride + x_offset + self.stride);
        if !self.job.keep_non_finite {
            self.counts.non_finite += admit_rows_except(out, rows, &streamed);
        }
        streamed.clear();
        self.streamed = streamed;
        self.queue = Some(queue);
        self.counts.primary += primary;
        self.counts.fragments_shaded += shaded;
        std::mem::take(&mut self.counts)
    }

    /// Empties the buffers for another region (the next tile of a row, the
    /// next band of a rayon job). Depth keys must be -1/z (a ray-parameter
    /// buffer is cleared per pixel when made).
    pub fn reset(&mut self, rect: PixelRect) {
        let n = rect.area() as usize;
        assert!(self.key == DepthKey::NegInvZ, "reset of a ray-parameter depth buffer");
        self.rect = rect;
        self.stride = rect.width() as usize;
        self.depth.clear();
        self.depth.resize(n, self.enc.clear_key());
        self.id.clear();
        self.id.resize(n, PrimitiveId::NONE);
        // The payload keeps what the last region left: a sample's payload
        // is read only where its id is set, and both are written together.
        self.payload.resize(n, [0.0; 2]);
        if !self.job.prepared.scene.csgs.is_empty() {
            self.csg.clear();
            self.csg.resize(n, NO_BOUNDARY);
        }
        if self.forward {
            self.color.clear();
            self.color.resize(n, Radiance::ZERO);
        }
        if self.cost_view() {
            for v in [&mut self.work, &mut self.tests] {
                v.clear();
                v.resize(n, 0);
            }
        }
    }
}

/// The low four bits of `bits`, each repeated: bit k goes to bits 2k and
/// 2k + 1 (a mask of four samples' lanes over their payload pairs).
#[inline(always)]
fn each_bit_twice(bits: u8) -> u8 {
    let mut x = bits & 0x0f;
    x = (x | x << 2) & 0x33;
    x = (x | x << 1) & 0x55;
    x | x << 1
}

#[cfg(test)]
mod tests {
    use super::each_bit_twice;

    #[test]
    fn each_of_four_bits_covers_its_pair_of_lanes() {
        assert_eq!(each_bit_twice(0b0000), 0);
        assert_eq!(each_bit_twice(0b0001), 0b0000_0011);
        assert_eq!(each_bit_twice(0b0100), 0b0011_0000);
        assert_eq!(each_bit_twice(0b1010), 0b1100_1100);
        assert_eq!(each_bit_twice(0b1111_0101), 0b0011_0011, "the high four bits are not its");
        for bits in 0..16u8 {
            for k in 0..4 {
                let set = bits >> k & 1;
                assert_eq!((each_bit_twice(bits) >> (2 * k) & 0b11), set * 0b11, "{bits:04b} bit {k}");
            }
        }
    }
}
