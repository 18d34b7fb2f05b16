//! Renderers and what they share: settings, the scene query (closest hit and
//! shadow rays), the sample pattern, statistics and the frame loop.
//!
//! A renderer answers visibility for one sample pass: for every pixel of the
//! requested rows it finds the `SurfaceHit` the sample sees and hands it to
//! `resolve_sample`, which shades it (or draws a debug view).

pub mod accel;
pub mod admit;
pub mod camera_support;
pub mod differentials;
pub mod finite;
pub mod aov;
pub mod frame;
pub mod gi_settings;
pub mod inspect;
pub mod keyed_cache;
pub mod layer_support;
pub mod opengl;
pub mod prepared;
pub mod raster;
pub mod raytrace;
pub mod settings_check;
pub mod shadow;
pub mod transport;

pub use frame::{render_frame, render_frame_with, replay_pixel, FrameOptions, FramePart, FrameResult, PixelReplay};
pub use prepared::PreparedScene;

use crate::math::{Radiance, Ray, Vec2};
use crate::named::named_enum;
use crate::scene::{CameraView, PrimitiveId, PrimitiveKind, SurfaceHit};
use std::ops::Range;
use std::sync::atomic::AtomicBool;
use inspect::pixel_record::Recorder;

named_enum! {
    /// How shadow visibility is resolved.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    pub enum ShadowMode ("shadow mode") {
        None = "none",
        Ray = "ray",
        Map = "map",
        /// Stencil shadow volumes for the surface the eye sees (`shadow_volume`).
        Volume = "volume",
    }
}

named_enum! {
    /// How shading varies across a triangle (Computer Graphics from Scratch, ch. 13).
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum Interpolation ("interpolation") {
        /// One normal per face: the geometric normal everywhere.
        Flat = "flat",
        /// Lighting computed at the three vertices, the radiance interpolated.
        Gouraud = "gouraud",
        /// Normals interpolated and lighting computed per sample.
        #[default]
        Phong = "phong",
        /// One lighting value per triangle: `shade()` at its centroid
        /// (Computer Graphics from Scratch's flat shading).
        Faceted = "faceted",
    }
}

named_enum! {
    /// What a mirror (and a dielectric's Fresnel reflection) reflects.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum Reflections ("reflection mode") {
        /// A traced ray: whatever it hits, shaded.
        #[default]
        Ray = "ray",
        /// The environment (or background) looked up in the reflected
        /// direction, no ray: the rasterizer's environment-map trick, blind
        /// to nearby objects.
        Env = "env",
    }
}

/// Per-render knobs: the one struct every front end (command line, viewer,
/// chart, gallery) fills and renders with. Scene-level values (background,
/// ambient, exposure) stay in `Scene::render`. `#[serde(default)]`: a value
/// saved without a field loads with that field's default (`Default` below,
/// the one place defaults are written).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel (stratified; 1 = the pixel centre).
    pub spp: u32,
    pub shadows: ShadowMode,
    /// CGPP's `rayBumpEpsilon`: how far shadow and secondary rays start off the surface.
    pub shadow_bump: f32,
    /// `--shadows map`: texels per side of each shadow map (per cube face for a point light).
    pub shadow_map_size: u32,
    /// `--shadows map`: depth bias in texels of the map, slope-scaled: a point is
    /// shadowed when it lies farther from the light than the stored depth by more
    /// than `bias * texel size * (1 + tan theta)` (see `shadow_map`).
    pub shadow_map_bias: f32,
    /// `--shadows volume`: count the volume faces in front of the visible
    /// surface (z-pass) or behind it (z-fail).
    pub shadow_volume: shadow::volume::VolumeMode,
    /// Maximum depth of mirror and refraction rays.
    pub max_depth: u32,
    pub view: inspect::debug::View,
    pub interpolation: Interpolation,
    /// Rasterizers: resolve visibility first, then shade once per pixel
    /// (CGPP 15.8.3); false = forward shading of every fragment that passes
    /// the depth test when it arrives. Ray casters ignore it.
    pub early_depth: bool,
    /// Rasterizers: coverage samples per pixel (1 = off; 2, 4 or 8 at the
    /// D3D standard positions), one shade per pixel per primitive. Ray
    /// casters ignore it (they antialias with `spp`).
    pub msaa: u32,
    /// Rasterizers with 2D weights: interpolate attributes affinely in screen
    /// space instead of perspective-correctly, to show the difference (the uv
    /// checker bends). Ray casters and the 3D-ray variants ignore it.
    pub affine: bool,
    /// Indirect light and its knobs.
    pub gi: transport::gi::GiSettings,
    /// Adaptive sampling: after a few passes, only pixels whose estimated
    /// relative error is above this keep taking samples (up to `spp`).
    pub adaptive: Option<f32>,
    /// Sub-sampling: trace a grid of pixels and interpolate the rest
    /// (`frame::subsample`); the shaded view of whole frames only.
    pub subsample: frame::Subsample,
    /// Rasterizers with a depth buffer: what it stores (`raster::depth_format`).
    /// The ray casters, naive, bbox and the painter ignore it.
    pub depth_buffer: raster::depth_format::DepthFormat,
    /// The wireframe view: the line algorithm (float DDA or integer Bresenham).
    pub lines: inspect::wireframe::LineAlgorithm,
    /// Rasterizers: cut triangles at the near plane (CGPP 15.6.3). A debug
    /// knob to show why: false drops every triangle that reaches nearer than
    /// the near plane whole, as a rasterizer without a clipper has to (its
    /// vertices behind the eye would project through infinity), so floors
    /// and walls that pass beside the camera lose their nearest triangles.
    /// Ray casters and `rasterize:naive` ignore it (they test eye rays,
    /// which start on the near plane).
    pub near_clip: bool,
    /// `--shadows map`: scale the bias with the slope of the surface to the
    /// light (see `shadow_map`); false: a constant `shadow_map_bias` texels,
    /// which at grazing light is too little (acne). A debug knob.
    pub shadow_map_slope_bias: bool,
    /// Shadow rays from smooth-normal triangles facing away from the light
    /// leave from the surface the normals imply (`transport::incidence::shadow_origin`,
    /// against the shadow terminator); false: from the hit point, as the book
    /// does, to show the speckles. A debug knob.
    pub terminator_lift: bool,
    /// How textures and normal maps are read.
    pub texture_filter: crate::scene::texture::TextureFilter,
    /// Traced reflections or environment lookups.
    pub reflections: Reflections,
    /// Rasterizers: clip at the near plane only, or at every plane of the
    /// view volume (`raster::clip`). The same image either way.
    pub clip: raster::clip::ClipMode,
    /// Rasterizers and shadow maps: skip copies made by `instances` whose
    /// bounding sphere is outside the view volume (`raster::cull`). The same
    /// image either way; a knob to measure and test that.
    pub cull_instances: bool,
    /// Area lights and the environment: shadow rays per light per shading
    /// point, stratified over the emitter (`transport::sampled_light`);
    /// 0 finds them by BSDF sampling alone, for comparison.
    pub light_samples: u32,
    /// Area lights and the environment: combine light sampling with BSDF
    /// sampling by multiple importance sampling (power heuristic); false:
    /// light sampling alone.
    pub mis: bool,
    /// `raytrace:bvh`: trace frames' rays as packets through the BVH (eye
    /// rays by tile, shadow rays and path bounces together); false: one ray
    /// at a time, as a pixel replay does. The same pixels either way (the
    /// packets answer each ray as it would be answered alone): a switch
    /// that times the optimisation.
    pub packets: bool,
    /// The fixed-point rasterizers (`fixed`, `tiled`, the painter): bits of
    /// sub-pixel precision their vertices are snapped to, 0 to
    /// `raster::subpixel::SUBPIXEL_BITS` (the default, the full grid). Fewer
    /// bits move edges by up to half a coarse step.
    pub subpixel_bits: u32,
    /// `--shadows map`: how the map is read (hard, PCF or PCSS).
    pub shadow_filter: shadow::ShadowFilter,
    /// `--shadow-filter pcf`: the filter's radius in texels of the map.
    pub pcf_radius: f32,
    /// How the image is shown (exposure in stops, tone map, transfer
    /// curve): read by the viewer and 8-bit outputs only, never by a renderer.
    pub display: crate::display::DisplaySettings,
}

/// The most `RenderSettings::light_samples` a front end accepts.
pub const MAX_LIGHT_SAMPLES: u32 = 4096;

impl Default for RenderSettings {
    /// Every knob's default, at the default scene size.
    fn default() -> RenderSettings {
        let size = crate::scene::RenderDefaults::default();
        RenderSettings {
            width: size.width,
            height: size.height,
            spp: 1,
            shadows: ShadowMode::Ray,
            shadow_bump: 1e-4,
            shadow_map_size: shadow::map::DEFAULT_SIZE,
            shadow_map_bias: shadow::map::DEFAULT_BIAS,
            shadow_volume: shadow::volume::VolumeMode::ZFail,
            max_depth: 4,
            view: inspect::debug::View::Shaded,
            interpolation: Interpolation::Phong,
            affine: false,
            early_depth: true,
            msaa: 1,
            gi: transport::gi::GiSettings::default(),
            adaptive: None,
            subsample: frame::Subsample::default(),
            depth_buffer: raster::depth_format::DepthFormat::F32,
            lines: inspect::wireframe::LineAlgorithm::Float,
            near_clip: true,
            shadow_map_slope_bias: true,
            terminator_lift: true,
            texture_filter: crate::scene::texture::TextureFilter::Trilinear,
            reflections: Reflections::Ray,
            clip: raster::clip::ClipMode::Near,
            cull_instances: true,
            light_samples: 1,
            mis: true,
            packets: true,
            subpixel_bits: raster::subpixel::SUBPIXEL_BITS,
            shadow_filter: shadow::ShadowFilter::None,
            pcf_radius: 1.5,
            display: crate::display::DisplaySettings::default(),
        }
    }
}

impl RenderSettings {
    /// The defaults at `scene`'s image size.
    pub fn for_scene(scene: &crate::scene::Scene) -> RenderSettings {
        RenderSettings { width: scene.render.width, height: scene.render.height, ..RenderSettings::default() }
    }
}

/// Counters of rays cast (per frame in the statistics).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub primary: u64,
    pub shadow: u64,
    pub secondary: u64,
    /// BVH nodes visited and primitives tested, by every ray.
    pub nodes: u64,
    pub tests: u64,
    /// Rasterizer: samples tested against triangles, covered, and fragments shaded.
    pub samples_tested: u64,
    pub samples_covered: u64,
    pub fragments_shaded: u64,
    pub depth_fails: u64,
    /// Rasterizer: copies made by `instances` set up, and culled whole.
    pub instances_drawn: u64,
    pub instances_culled: u64,
    /// Samples that came out NaN or infinite and were zeroed before they
    /// reached a pixel (`finite::admit_all`).
    pub non_finite: u64,
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.secondary += o.secondary;
        self.nodes += o.nodes;
        self.tests += o.tests;
        self.samples_tested += o.samples_tested;
        self.samples_covered += o.samples_covered;
        self.fragments_shaded += o.fragments_shaded;
        self.depth_fails += o.depth_fails;
        self.instances_drawn += o.instances_drawn;
        self.instances_culled += o.instances_culled;
        self.non_finite += o.non_finite;
    }
}

/// What blocks a shadow ray: the primitive, and how far along the ray it
/// lies (from a shadow map: how far before the shaded point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Occluder {
    pub kind: PrimitiveKind,
    /// Index into `Scene::triangles` or `Scene::spheres`.
    pub index: u32,
    pub t: f32,
}

impl Occluder {
    #[inline]
    pub fn new(id: PrimitiveId, t: f32) -> Occluder {
        Occluder { kind: id.kind(), index: id.index(), t }
    }
}

/// Closest-hit and any-hit queries against the scene. The brute-force caster
/// and the BVH implement it; `shade()` uses it for shadow and secondary rays.
pub trait SceneQuery: Sync {
    /// The closest surface along `ray` with `0 < t < t_max`. `inside` lets a
    /// refracted ray hit the sphere it travels in from inside.
    fn closest<R: Recorder>(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<SurfaceHit>;
    /// The first surface found along `ray` with `0 < t < t_max`; `None`
    /// when the segment is clear.
    fn occluder<R: Recorder>(&self, ray: &Ray, t_max: f32, counts: &mut RayCounts, rec: &mut R) -> Option<Occluder>;
    /// `closest` (unrecorded) for a ray whose hit is shaded in a batch: a
    /// triangle hit may come back as what its record is built from, so
    /// that the batch builds eight records at once (`Scene::triangle_hits`,
    /// the same records `closest` gives).
    fn closest_for_batch(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts) -> Option<BatchHit> {
        self.closest(ray, t_max, inside, counts, &mut inspect::pixel_record::NoRecord).map(BatchHit::Record)
    }
    /// `closest_for_batch` from code already running at SIMD level `simd`
    /// (inside a `dispatch!` around a loop over many rays): a traversal
    /// written over `Simd` can then be inlined there, instead of choosing
    /// the level and entering its compiled copy once per ray.
    #[inline(always)]
    fn closest_for_batch_at<S: fearless_simd::Simd>(&self, _simd: S, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts) -> Option<BatchHit> {
        self.closest_for_batch(ray, t_max, inside, counts)
    }
    /// `occluder` (unrecorded) from code already running at SIMD level
    /// `simd`, as `closest_for_batch_at` is to `closest_for_batch`.
    #[inline(always)]
    fn occluder_at<S: fearless_simd::Simd>(&self, _simd: S, ray: &Ray, t_max: f32, counts: &mut RayCounts) -> Option<Occluder> {
        self.occluder(ray, t_max, counts, &mut inspect::pixel_record::NoRecord)
    }
    /// The BVH query behind this one where its packets can trace the
    /// rays this query would trace one by one (`transport::shadow_packets`):
    /// the flat tree, no instances or CSG objects. `None` for any other.
    fn bvh_packets(&self) -> Option<&accel::bvh::BvhQuery<'_>> {
        None
    }
    /// Shadow maps to look light visibility up in (`--shadows map`);
    /// `resolve_sample` wraps the query in a `shadow::ApproximateShadows` that has them.
    fn shadow_maps(&self) -> Option<&shadow::map::ShadowMaps> {
        None
    }
    /// The shadow volume count of light `light` at the primary surface
    /// (`--shadows volume`, nonzero = shadow); `resolve_sample` wraps the
    /// query in a `shadow::ApproximateShadows` that has the counts.
    fn volume_count(&self, _light: usize) -> Option<i32> {
        None
    }
}

/// A hit as `SceneQuery::closest_for_batch` finds it.
#[derive(Clone, Copy, Debug)]
pub enum BatchHit {
    /// A triangle's hit, its record not built yet.
    Triangle(crate::scene::hit_lanes::TriangleHitInput),
    /// Any other hit, as its record.
    Record(SurfaceHit),
}

/// One sample pass of a frame: every pixel sampled at the same sub-pixel offset.
pub struct PassJob<'a> {
    pub prepared: &'a PreparedScene,
    pub view: &'a CameraView,
    pub settings: &'a RenderSettings,
    /// Sub-pixel position of this pass's sample in [0, 1)^2 (0.5, 0.5 = centre).
    pub offset: Vec2,
    /// Index of this pass's sample (0-based): with the pixel, it keys the
    /// sample's random numbers.
    pub sample: u32,
    /// `--gi photons`: the photon map, built before the passes.
    pub photons: Option<&'a transport::photon_map::PhotonMap>,
    /// Adaptive sampling: which pixels of `rows` (row-major, `width` per row)
    /// still take samples; the others are left as they are in `out` (but
    /// a renderer that admits its samples blackens a non-finite one there).
    pub active: Option<&'a [bool]>,
    /// Rows to render; `out` holds `width * rows.len()` pixels.
    pub rows: Range<u32>,
    pub cancel: &'a AtomicBool,
    /// The frame looks for non-finite samples itself (the nan view marks
    /// their pixels): a renderer that admits its samples leaves them as
    /// they are for the frame to find, count and zero.
    pub keep_non_finite: bool,
}

impl PassJob<'_> {
    pub fn cancelled(&self) -> bool {
        self.cancel.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Whether pixel `(x, y)` (a row of `rows`) takes a sample in this pass.
    #[inline]
    pub fn is_active(&self, x: u32, y: u32) -> bool {
        self.active.is_none_or(|a| a[((y - self.rows.start) * self.view.width + x) as usize])
    }

    /// The index of pixel `(x, y)` that keys its samples' random numbers.
    #[inline]
    pub fn pixel_index(&self, x: u32, y: u32) -> u32 {
        x.wrapping_add(y.wrapping_mul(self.view.width))
    }

    /// Image position of this pass's sample in pixel `(x, y)`.
    pub fn sample_position(&self, x: u32, y: u32) -> Vec2 {
        Vec2::new(x as f32 + self.offset.x, y as f32 + self.offset.y)
    }

    /// This pass's eye ray in pixel `(x, y)` and the ray parameter of the
    /// far plane: through its `sample_position`, and with a thin lens from
    /// the point of the lens that `lens_sample` draws for the sample.
    #[inline]
    pub fn eye_ray(&self, x: u32, y: u32) -> (Ray, f32) {
        let p = self.sample_position(x, y);
        if self.view.aperture == 0.0 {
            return (self.view.eye_ray(p.x, p.y), self.view.far_t(p.x, p.y));
        }
        self.view.eye_ray_through_lens(p.x, p.y, lens_sample(self.pixel_index(x, y), self.sample, self.settings.gi.seed))
    }
}

/// Where on the unit disk sample `sample` of pixel `pixel` crosses a thin
/// lens: a pure function of (pixel, sample index, seed), on a stream of
/// its own so that it draws nothing from the shading's numbers.
pub fn lens_sample(pixel: u32, sample: u32, seed: u64) -> Vec2 {
    const LENS_STREAM: u64 = 0x1E45_0000_0000_0000;
    let u = transport::sampling::hashed_unit_pair(pixel as u64 | (sample as u64) << 32, seed ^ LENS_STREAM);
    transport::sampling::concentric_disk(u)
}

/// A rendering method: `raytrace:brute`, `raytrace:bvh`, `rasterize:...`.
pub trait Renderer: Sync + Send {
    fn name(&self) -> &'static str;
    fn description(&self) -> &'static str;
    /// Renders `job.rows` of one sample pass into `out` (row-major), in
    /// parallel, and returns what it counted. Result must not depend on the
    /// number of threads.
    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts;

    /// Renders several passes of the same rows, pass k into
    /// `out[k * n..(k + 1) * n]` (n pixels each), as `render_pass` would
    /// one after the other (which is what this default does). A ray caster
    /// may trace a pixel's samples of several passes together.
    fn render_passes(&self, jobs: &[PassJob], out: &mut [Radiance]) -> RayCounts {
        render_passes_in_turn(self, jobs, out)
    }

    /// Whether `render_pass` leaves only finite values in `out`: each band
    /// put through `finite::admit_all` as soon as it is written, while it
    /// is in cache. A one-sample frame then skips its own scan of the pass.
    fn admits_its_samples(&self) -> bool {
        false
    }

    /// The rows of a chunk when a frame of many passes is rendered chunk by
    /// chunk, each chunk's passes in a row (`Accumulator::render_in_chunks`);
    /// `None` for a renderer whose `render_pass` has a cost per call that
    /// does not shrink with its rows (a rasterizer sets up every triangle),
    /// which renders pass by pass.
    fn chunk_rows(&self) -> Option<u32> {
        None
    }

    /// How many passes a chunk hands `render_passes` at once: more than one
    /// only for a renderer that does something with them together.
    fn passes_at_once(&self) -> u32 {
        1
    }

    /// Whether this renderer can draw `scene` with `settings`: one sentence
    /// saying why not (an option it does not support). Asked by
    /// `admit::admit`, with no driver loaded.
    fn check(&self, scene: &crate::scene::Scene, settings: &RenderSettings) -> Result<(), String> {
        accel::csg::check(scene, settings)
    }

    /// Whether this renderer draws through `camera`: one sentence saying
    /// why not. By default a rasterizer's answer (`camera_support`); the
    /// ray casters draw every camera.
    fn check_camera(&self, camera: &crate::scene::Camera) -> Result<(), String> {
        camera_support::check_rasterized(self.name(), camera)
    }

    /// What this renderer draws instead of `settings` when `check` refuses
    /// them but it can draw something close: candidates, best first, each
    /// with the sentence that says what changed. `admit::admit` takes the
    /// first that passes. None (the default): it draws `settings` or refuses.
    fn substitutes(&self, _settings: &RenderSettings) -> Vec<admit::Substitute> {
        Vec::new()
    }

    /// How much of the two-level instance layer (`scene::instanced`) this
    /// renderer draws; `layer_support::check` refuses the rest. None by
    /// default: a renderer that reads `Scene::triangles` alone.
    fn instance_layer(&self) -> layer_support::LayerSupport {
        layer_support::LayerSupport::Nothing
    }

    /// Readies what this renderer needs from outside the process (a
    /// driver) for `settings`, once they are admitted and before a frame
    /// starts: one sentence when it cannot.
    fn ready(&self, _settings: &RenderSettings) -> Result<(), String> {
        Ok(())
    }

    /// Replays pixel `(x, y)` of this pass through the same code path with a
    /// recorder, returning the very value `render_pass` stores there; `None`
    /// when this renderer cannot replay pixels.
    fn trace_pixel(&self, _job: &PassJob, _x: u32, _y: u32, _rec: &mut inspect::pixel_record::PixelTrace) -> Option<Radiance> {
        None
    }
}

/// Every registered renderer, reference first.
pub fn renderers() -> Vec<Box<dyn Renderer>> {
    let mut all: Vec<Box<dyn Renderer>> = vec![Box::new(raytrace::brute_renderer::BruteForce), Box::new(raytrace::bvh_renderer::BvhRayTracer)];
    all.extend(raster::renderers());
    all.push(Box::new(opengl::OpenGl));
    all
}

/// Names accepted by `--renderer`, with the aliases `raytrace` and `rasterize`.
pub fn renderer_names() -> Vec<&'static str> {
    renderers().iter().map(|r| r.name()).collect()
}

pub const DEFAULT_RAYTRACE: &str = "raytrace:bvh";

/// Looks a renderer up by name; `raytrace` and `rasterize` name the defaults.
pub fn renderer_by_name(name: &str) -> Result<Box<dyn Renderer>, String> {
    let wanted = match name {
        "raytrace" => DEFAULT_RAYTRACE,
        "rasterize" => raster::DEFAULT_RASTERIZE,
        other => other,
    };
    renderers()
        .into_iter()
        .find(|r| r.name() == wanted)
        .ok_or_else(|| format!("unknown renderer \"{name}\" (choose from raytrace, rasterize, {})", renderer_names().join(", ")))
}

/// `Renderer::render_passes` as `render_pass` after `render_pass`.
pub fn render_passes_in_turn<R: Renderer + ?Sized>(renderer: &R, jobs: &[PassJob], out: &mut [Radiance]) -> RayCounts {
    let n = (out.len() / jobs.len().max(1)).max(1);
    let mut counts = RayCounts::default();
    for (job, out) in jobs.iter().zip(out.chunks_mut(n)) {
        counts += renderer.render_pass(job, out);
    }
    counts
}

/// What `resolve_sample` returns for a sample that sees nothing, when that
/// does not depend on the ray: the background in the shaded view (an
/// environment depends on the ray's direction: `None`). Lets a
/// rasterizer skip building eye rays for empty pixels (most of a frame).
#[inline]
pub fn miss_without_ray(job: &PassJob) -> Option<Radiance> {
    let scene = &job.prepared.scene;
    (job.settings.view == inspect::debug::View::Shaded && scene.environment.is_none()).then_some(scene.render.background)
}

/// `miss_without_ray`, and in the debug views that colour only what is hit,
/// their colour for a miss (`inspect::debug::miss_color`): what a rasterizer shows
/// at a pixel no primitive covers, without making its eye ray.
pub fn view_miss_without_ray(job: &PassJob) -> Option<Radiance> {
    miss_without_ray(job).or_else(|| inspect::debug::miss_color(job.settings.view))
}

/// The batched hand-off from visibility to shading, beside `resolve_sample`
/// below (the one-sample hand-off): a rasterizer pushes the samples its
/// visibility buffer sees and the queue lights them eight at a time. It is
/// named here so that the hit-making layers never name `transport`.
pub use transport::shade_queue::ShadeQueue;

/// The value one sample contributes, given what it sees: `shade()` for the
/// shaded view, a debug colour otherwise, the background on a miss.
#[inline]
pub fn resolve_sample<Q: SceneQuery, R: Recorder>(job: &PassJob, query: &Q, ray: &Ray, hit: Option<&SurfaceHit>, pixel: u32, counts: &mut RayCounts, rec: &mut R) -> Radiance {
    if job.settings.view == inspect::debug::View::Shadowmap {
        return shadow::map::view_sample(job, ray, rec);
    }
    if job.settings.shadows == ShadowMode::Map && job.settings.view == inspect::debug::View::Shaded && hit.is_some() {
        return shadow::map::with_maps(job.prepared, job.settings, |maps| {
            resolve_with(job, &shadow::ApproximateShadows { inner: query, maps: Some(maps), volume_counts: None }, ray, hit, pixel, counts, rec)
        });
    }
    if job.settings.shadows == ShadowMode::Volume && job.settings.view == inspect::debug::View::Shaded {
        if let Some(h) = hit {
            let volume = shadow::volume::ray_counts(job.prepared, job.settings, ray, h.t);
            return resolve_counted(job, query, ray, hit, &volume, pixel, counts, rec);
        }
    }
    resolve_with(job, query, ray, hit, pixel, counts, rec)
}

/// `resolve_sample` for a sample whose shadow volume counts (one per light)
/// are known already: a rasterizer's stencil (`--shadows volume`).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn resolve_counted<Q: SceneQuery, R: Recorder>(job: &PassJob, query: &Q, ray: &Ray, hit: Option<&SurfaceHit>, volume: &[i32], pixel: u32, counts: &mut RayCounts, rec: &mut R) -> Radiance {
    resolve_with(job, &shadow::ApproximateShadows { inner: query, maps: None, volume_counts: Some(volume) }, ray, hit, pixel, counts, rec)
}

#[inline]
fn resolve_with<Q: SceneQuery, R: Recorder>(job: &PassJob, query: &Q, ray: &Ray, hit: Option<&SurfaceHit>, pixel: u32, counts: &mut RayCounts, rec: &mut R) -> Radiance {
    let scene = &job.prepared.scene;
    match (job.settings.view, hit) {
        (inspect::debug::View::Shaded, Some(h)) => {
            let mut path = transport::gi::PathState::new(pixel, job.sample, job.settings.spp, &job.settings.gi, job.photons);
            let mut sh = transport::shading::Shading { scene, query, settings: job.settings, path: &mut path, counts, rec };
            let shaded = with_shading_hit(job.settings.interpolation, h, |s| transport::shade::shade(&mut sh, s, -ray.dir, 0));
            match (shaded, job.settings.interpolation) {
                (Some(radiance), _) => radiance,
                (None, Interpolation::Faceted) => transport::shade::shade_faceted(&mut sh, h, job.view),
                (None, _) => transport::shade::shade_gouraud(&mut sh, h, job.view),
            }
        }
        (inspect::debug::View::Shaded, None) => {
            let l = scene.miss_radiance(ray.dir);
            rec.shaded(0, l);
            l
        }
        (inspect::debug::View::Mip, hit) => {
            let c = inspect::debug::mip_view(scene, job.settings.texture_filter, hit);
            rec.shaded(0, c);
            c
        }
        (view, hit) => {
            let c = inspect::debug::view_color(view, job.view, ray, hit);
            rec.shaded(0, c);
            c
        }
    }
}

/// Calls `f` with the surface `shade()` is handed for a sample that sees
/// `hit`: the hit itself with Phong interpolation, the hit with its
/// geometric normal as shading normal with flat shading. `None` with
/// Gouraud, which shades the triangle's vertices instead
/// (`transport::shade::shade_gouraud`), and faceted, which shades its
/// centroid (`transport::shade::shade_faceted`). A callback rather than a returned hit, so the
/// Phong case copies nothing.
#[inline(always)]
pub fn with_shading_hit<T>(interpolation: Interpolation, hit: &SurfaceHit, f: impl FnOnce(&SurfaceHit) -> T) -> Option<T> {
    match interpolation {
        Interpolation::Phong => Some(f(hit)),
        Interpolation::Flat => Some(f(&SurfaceHit { shading_normal: hit.geometric_normal, ..*hit })),
        Interpolation::Gouraud | Interpolation::Faceted => None,
    }
}

/// Stratified, jittered sub-pixel positions: one point in each cell of an
/// n x n grid when `spp` is a square, otherwise a Latin hypercube (one cell
/// per row and per column of an spp x spp grid, columns in a fixed
/// shuffle); inside its cell each point is placed by a hash of (sample,
/// spp, seed). The same position serves every pixel of a pass, so both
/// families (and OpenGL, which draws a pass at one offset) see the same
/// points, and the image stays a pure function of (pixel, sample, seed).
/// Jittered rather than at cell centres because centres quantize an edge's
/// coverage to multiples of 1/n: a bias that does not fall as seeds change
/// and that showed as whole rows off along a bright emitter's edge. One
/// sample is the pixel centre.
pub fn sample_offset(index: u32, spp: u32, seed: u64) -> Vec2 {
    let spp = spp.max(1);
    if spp == 1 {
        return Vec2::splat(0.5);
    }
    let jitter = transport::sampling::hashed_unit_pair(index as u64 | (spp as u64) << 32, seed);
    let n = (spp as f32).sqrt().round() as u32;
    if n * n == spp {
        let (i, j) = (index % n, index / n);
        return Vec2::new((i as f32 + jitter.x) / n as f32, (j as f32 + jitter.y) / n as f32);
    }
    // A fixed permutation of the columns: multiply by a number coprime to spp.
    let mut k = (spp as f32 * 0.618_034).round() as u32 | 1;
    while gcd(k, spp) != 1 {
        k += 2;
    }
    let col = (index as u64 * k as u64 % spp as u64) as u32;
    Vec2::new((index as f32 + jitter.x) / spp as f32, (col as f32 + jitter.y) / spp as f32)
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 { a } else { gcd(b, a % b) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sample_is_the_centre() {
        assert_eq!(sample_offset(0, 1, 7), Vec2::splat(0.5));
    }

    #[test]
    fn samples_are_stratified() {
        for spp in [2u32, 3, 4, 5, 8, 9, 16, 64] {
            let pts: Vec<Vec2> = (0..spp).map(|i| sample_offset(i, spp, 3)).collect();
            let n = (spp as f32).sqrt().round() as u32;
            let cells = if n * n == spp { n } else { spp };
            // One sample in each column stratum and in each row stratum.
            let mut cols: Vec<u32> = pts.iter().map(|p| (p.x * cells as f32) as u32).collect();
            let mut rows: Vec<u32> = pts.iter().map(|p| (p.y * cells as f32) as u32).collect();
            cols.sort();
            rows.sort();
            cols.dedup();
            rows.dedup();
            if n * n != spp {
                assert_eq!(cols.len(), spp as usize, "spp {spp}");
                assert_eq!(rows.len(), spp as usize, "spp {spp}");
            } else {
                assert_eq!(cols.len(), n as usize);
                assert_eq!(rows.len(), n as usize);
            }
            assert!(pts.iter().all(|p| p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all()), "spp {spp}: {pts:?}");
        }
    }

    #[test]
    fn jitter_moves_with_the_seed_and_covers_the_cell() {
        // Another seed moves the point within the same cell; over many seeds
        // the points spread over the whole cell, not its centre alone.
        let (a, b) = (sample_offset(5, 16, 1), sample_offset(5, 16, 2));
        assert_ne!(a, b);
        assert_eq!((a * 4.0).floor(), (b * 4.0).floor());
        let inside: Vec<Vec2> = (0..256).map(|seed| sample_offset(5, 16, seed) * 4.0 - (a * 4.0).floor()).collect();
        let (lo, hi) = inside.iter().fold((Vec2::ONE, Vec2::ZERO), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        assert!(lo.max_element() < 0.05 && hi.min_element() > 0.95, "{lo} {hi}");
        assert_eq!(sample_offset(5, 16, 1), a, "a pure function");
    }

    #[test]
    fn settings_saved_before_the_debug_knobs_load_with_them_on() {
        let scene = crate::scene::builtin::load_builtin("one-triangle").unwrap().unwrap();
        let settings = RenderSettings::for_scene(&scene);
        let mut old = serde_json::to_value(&settings).unwrap();
        for key in ["near_clip", "shadow_map_slope_bias", "terminator_lift"] {
            assert_eq!(old[key], true, "{key} is on by default");
            old.as_object_mut().unwrap().remove(key);
        }
        let loaded: RenderSettings = serde_json::from_value(old).unwrap();
        assert_eq!(loaded, settings);
    }

    #[test]
    fn every_name_resolves() {
        for n in renderer_names() {
            assert_eq!(renderer_by_name(n).unwrap().name(), n);
        }
        assert_eq!(renderer_by_name("raytrace").unwrap().name(), DEFAULT_RAYTRACE);
        assert!(renderer_by_name("rasterize").is_ok());
        assert!(renderer_by_name("nope").err().unwrap().contains("raytrace:brute"));
    }
}
