//! The truth a chart measures error against: an EXR the user names
//! (`--reference`), else the scene's `[render] reference`, else a
//! many-sample path-traced image, which includes the bounced light that every
//! direct-lighting method leaves out. Path-traced references take long, so
//! they are cached on disk under a hash of the scene and the image settings.

use crate::math::Radiance;
use crate::render::transport::gi::GiMode;
use crate::render::{self, PreparedScene, RenderSettings, ShadowMode};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU32};

/// Samples per pixel of a path-traced reference.
pub const PATH_REFERENCE_SPP: u32 = 256;

/// A path-traced reference renders as sample ranges of at most this many
/// samples, added in order and divided once, whether in one process or as
/// the jobs of `chart --plan` merged by `chart --from`: the same additions
/// in the same order give both the same bits.
pub const SAMPLES_PER_RANGE: u32 = 32;

/// The sample ranges a path-traced reference of `spp` samples renders in.
pub fn reference_ranges(spp: u32) -> Vec<std::ops::Range<u32>> {
    let spp = spp.max(1);
    let n = spp.div_ceil(SAMPLES_PER_RANGE);
    (0..n).map(|i| render::FramePart::band_rows(i, n, spp)).collect()
}

/// Renders `settings` as `reference_ranges` says: each range's sums, added
/// range by range, divided by the samples once (as `pinhole merge` adds
/// the ranges' parts). `None` when cancelled.
fn render_in_ranges(renderer: &dyn render::Renderer, prepared: &PreparedScene, settings: &RenderSettings, cancel: &AtomicBool, passes_done: Option<&AtomicU32>) -> Option<Vec<Radiance>> {
    let ranges = reference_ranges(settings.spp);
    if ranges.len() == 1 {
        return render::render_frame(renderer, prepared, settings, cancel, passes_done).map(|f| f.pixels);
    }
    let mut sum: Option<Vec<Radiance>> = None;
    for passes in ranges {
        let part = render::FramePart { passes, ..render::FramePart::whole(settings) };
        let options = render::FrameOptions { passes_done, part: Some(part), ..render::FrameOptions::default() };
        let frame = render::render_frame_with(renderer, prepared, settings, cancel, options)?;
        match &mut sum {
            None => sum = Some(frame.pixels),
            Some(s) => s.iter_mut().zip(&frame.pixels).for_each(|(a, b)| *a += *b),
        }
    }
    let spp = settings.spp.max(1);
    Some(sum?.into_iter().map(|v| render::frame::final_value(v, spp)).collect())
}

/// The reference's own seed: its noise must not be the noise of the path
/// configurations it judges (they use the scene's seed), or their error
/// would look smaller than it is.
const REFERENCE_SEED: u64 = 0x7e57_5eed_0f_7247;

#[derive(Clone, Debug)]
pub struct Reference {
    pub pixels: Vec<Radiance>,
    pub width: u32,
    pub height: u32,
    /// What it is, for the chart's title: the file name, or "path tracing, 256 spp".
    pub name: String,
}

/// Where the reference comes from, before any work is done.
#[derive(Clone, Debug, PartialEq)]
pub enum ReferenceSource {
    File(PathBuf),
    PathTraced { spp: u32 },
}

impl ReferenceSource {
    /// `explicit` (the command line's `--reference`), else the scene's, else path tracing.
    pub fn choose(explicit: Option<&Path>, prepared: &PreparedScene, spp: u32) -> ReferenceSource {
        match explicit.map(Path::to_path_buf).or_else(|| prepared.scene.render.reference.clone()) {
            Some(f) => ReferenceSource::File(f),
            None => ReferenceSource::PathTraced { spp },
        }
    }

    pub fn describe(&self) -> String {
        match self {
            ReferenceSource::File(f) => f.display().to_string(),
            ReferenceSource::PathTraced { spp } => format!("path tracing, {spp} spp"),
        }
    }
}

/// The settings a path-traced reference of `width` x `height` renders with.
pub fn path_settings(prepared: &PreparedScene, width: u32, height: u32, spp: u32) -> RenderSettings {
    let mut s = RenderSettings { width, height, spp, ..RenderSettings::for_scene(&prepared.scene) };
    s.shadows = ShadowMode::Ray;
    s.gi.mode = GiMode::Path;
    s.gi.bounces = None;
    s.gi.seed = REFERENCE_SEED;
    s
}

/// Loads or renders the reference for images of `width` x `height`.
/// A path-traced one is read from `cache_dir` when there (and written there
/// after rendering). `passes_done` counts the passes of a render in progress;
/// `None` is returned when `cancel` stops it.
pub fn load_reference(
    source: &ReferenceSource,
    prepared: &PreparedScene,
    width: u32,
    height: u32,
    cache_dir: Option<&Path>,
    cancel: &AtomicBool,
    passes_done: Option<&AtomicU32>,
) -> Result<Option<Reference>, String> {
    match source {
        ReferenceSource::File(path) => {
            let img = load_reference_file(path, width, height)?;
            Ok(Some(Reference { pixels: img.pixels, width, height, name: source.describe() }))
        }
        ReferenceSource::PathTraced { spp } => {
            let settings = path_settings(prepared, width, height, *spp);
            let cached = cache_dir.map(|d| d.join(format!("reference-{:016x}.exr", cache_key(prepared, &settings))));
            if let Some(img) = cached.as_deref().and_then(|p| crate::image_io::load_image(p).ok()) {
                if (img.width, img.height) == (width, height) {
                    return Ok(Some(Reference { pixels: img.pixels, width, height, name: format!("{} (cached)", source.describe()) }));
                }
            }
            let renderer = render::renderer_by_name(render::DEFAULT_RAYTRACE)?;
            let Some(pixels) = render_in_ranges(renderer.as_ref(), prepared, &settings, cancel, passes_done) else {
                return Ok(None);
            };
            if let Some(p) = &cached {
                // A cache that cannot be written only costs time next run.
                let saved = p.parent().map_or(Ok(()), |d| std::fs::create_dir_all(d).map_err(|e| e.to_string()))
                    .and_then(|_| crate::image_io::save_image(p, width, height, &pixels, 1.0));
                if let Err(e) = saved {
                    eprintln!("pinhole: cannot cache the reference in {}: {e}", p.display());
                }
            }
            Ok(Some(Reference { pixels, width, height, name: source.describe() }))
        }
    }
}

/// Reads a reference image and checks that error against it means
/// something: its size is the measured images' size, and its pixels are
/// finite, non-negative and not all black (relative error divides by it).
pub fn load_reference_file(path: &Path, width: u32, height: u32) -> Result<crate::image_io::LinearImage, String> {
    let img = crate::image_io::load_image(path)?;
    if (img.width, img.height) != (width, height) {
        return Err(format!(
            "the reference {} is {}x{} but the images measured are {width}x{height}; render at its size (--width {} --height {})",
            path.display(),
            img.width,
            img.height,
            img.width,
            img.height
        ));
    }
    let bad = img.pixels.iter().filter(|p| !p.is_finite()).count();
    if bad > 0 {
        return Err(format!("the reference {} has {bad} pixels that are not finite numbers; error against it means nothing", path.display()));
    }
    let negative = img.pixels.iter().filter(|p| p.min_element() < 0.0).count();
    if negative > 0 {
        return Err(format!("the reference {} has {negative} pixels with negative values; radiance is never negative", path.display()));
    }
    if img.pixels.iter().all(|p| p.max_element() <= 0.0) {
        return Err(format!("the reference {} is black everywhere; relative error against it is undefined", path.display()));
    }
    Ok(img)
}

/// Where path-traced references are kept: `PINHOLE_CACHE_DIR`, else the
/// platform's cache folder (`$XDG_CACHE_HOME/pinhole`, `~/.cache/pinhole`).
pub fn default_cache_dir() -> Option<PathBuf> {
    let env = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty()).map(PathBuf::from);
    crate::env_overrides::cache_dir()
        .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("pinhole")))
        .or_else(|| env("HOME").map(|d| d.join(".cache").join("pinhole")))
}

/// A hash of everything the reference image depends on: the scene's content
/// (streamed through its `Debug` form, textures included) and the settings.
/// FNV-1a, so the key is the same from one build to the next.
pub fn cache_key(prepared: &PreparedScene, settings: &RenderSettings) -> u64 {
    struct Fnv(u64);
    impl std::fmt::Write for Fnv {
        fn write_str(&mut self, s: &str) -> std::fmt::Result {
            for b in s.bytes() {
                self.0 = (self.0 ^ b as u64).wrapping_mul(0x100_0000_01b3);
            }
            Ok(())
        }
    }
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    let s = &prepared.scene;
    // References rendered in one piece, before the sample ranges, round differently.
    let _ = write!(h, "ranges of {SAMPLES_PER_RANGE}");
    let _ = write!(h, "{:?}{:?}{:?}{:?}{:?}{:?}", s.camera, s.render, s.lights, s.materials, s.spheres, settings);
    for t in &s.triangles {
        let _ = write!(h, "{t:?}");
    }
    h.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prepared(name: &str) -> PreparedScene {
        PreparedScene::new(crate::scene::builtin::load_builtin(name).unwrap().unwrap())
    }

    #[test]
    fn references_split_into_ranges_of_at_most_32_samples_covering_all() {
        assert_eq!(reference_ranges(1), vec![0..1]);
        assert_eq!(reference_ranges(32), vec![0..32]);
        assert_eq!(reference_ranges(40), vec![0..20, 20..40]);
        let r = reference_ranges(256);
        assert_eq!(r.len(), 8);
        assert!(r.windows(2).all(|w| w[0].end == w[1].start) && r[0].start == 0 && r[7].end == 256);
        assert!(r.iter().all(|x| x.len() == 32));
    }

    #[test]
    fn the_cache_key_changes_with_the_scene_and_the_settings() {
        let p = prepared("spheres");
        let s = path_settings(&p, 32, 20, 4);
        assert_eq!(cache_key(&p, &s), cache_key(&p, &s.clone()));
        assert_ne!(cache_key(&p, &s), cache_key(&p, &RenderSettings { spp: 8, ..s.clone() }));
        let mut moved = crate::scene::builtin::load_builtin("spheres").unwrap().unwrap();
        moved.lights[0] = match moved.lights[0].clone() {
            crate::scene::Light::Point { position, power } => crate::scene::Light::Point { position: position + glam::Vec3::X, power },
            crate::scene::Light::Directional { direction, irradiance } => crate::scene::Light::Directional { direction, irradiance: irradiance * 2.0 },
        };
        assert_ne!(cache_key(&p, &s), cache_key(&PreparedScene::new(moved), &s));
    }

    #[test]
    fn a_path_traced_reference_is_cached_and_read_back() {
        let dir = std::env::temp_dir().join(format!("pinhole-ref-cache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let p = prepared("spheres");
        let source = ReferenceSource::PathTraced { spp: 2 };
        let cancel = AtomicBool::new(false);
        let first = load_reference(&source, &p, 24, 16, Some(&dir), &cancel, None).unwrap().unwrap();
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        let second = load_reference(&source, &p, 24, 16, Some(&dir), &cancel, None).unwrap().unwrap();
        assert!(second.name.ends_with("(cached)"), "{}", second.name);
        assert_eq!(first.pixels, second.pixels);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_reference_file_of_another_size_is_refused_with_both_sizes() {
        let dir = std::env::temp_dir().join(format!("pinhole-ref-size-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("r.exr");
        crate::image_io::save_image(&f, 8, 4, &vec![glam::Vec3::ONE; 32], 1.0).unwrap();
        let p = prepared("spheres");
        let e = load_reference(&ReferenceSource::File(f.clone()), &p, 16, 8, None, &AtomicBool::new(false), None).unwrap_err();
        assert!(e.contains("8x4") && e.contains("16x8"), "{e}");
        let mut nan = vec![glam::Vec3::ONE; 32];
        nan[5] = glam::Vec3::NAN;
        crate::image_io::save_image(&f, 8, 4, &nan, 1.0).unwrap();
        let e = load_reference(&ReferenceSource::File(f), &p, 8, 4, None, &AtomicBool::new(false), None).unwrap_err();
        assert!(e.contains("1 pixels that are not finite"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
