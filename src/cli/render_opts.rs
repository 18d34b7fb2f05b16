//! The options every rendering subcommand takes (`render`, `bench`,
//! `pixel`, `chart`), and how they are written into `RenderSettings`, the
//! one settings struct: clap reads them as given, `write_into` checks each
//! and sets its field. Their defaults are `RenderSettings::default()`'s,
//! shown by `--help`.

use crate::render::{self, RenderSettings};
use clap::Args;

/// The defaults the options show and start from.
fn defaults() -> RenderSettings {
    RenderSettings::default()
}

/// `--bounces` as written: a number, or `inf` for no limit.
fn bounces_name(bounces: Option<u32>) -> String {
    bounces.map_or("inf".to_string(), |b| b.to_string())
}

#[derive(Args, Clone)]
pub struct RenderOpts {
    /// raytrace | rasterize, or a variant (see `pinhole list`).
    #[arg(long, default_value = "raytrace")]
    pub renderer: String,
    /// glTF: look through the camera of this name (default: its first perspective camera).
    #[arg(long, value_name = "NAME")]
    pub camera: Option<String>,
    #[arg(long)]
    pub width: Option<u32>,
    #[arg(long)]
    pub height: Option<u32>,
    /// Samples per pixel (stratified; 1 = the pixel centre).
    #[arg(long, default_value_t = defaults().spp)]
    pub spp: u32,
    /// shaded | barycentric | raydir | depth | zbuffer | normal | id | uv | cost | diff | shadowmap | wireframe | mip | false-colour |
    /// error | absolute-error | signed-error (against --reference) | nan (see `pinhole list`)
    #[arg(long, default_value_t = defaults().view.name().to_string())]
    pub view: String,
    /// ray | map | volume | none (opengl, which casts no rays, draws ray shadows as maps)
    #[arg(long, default_value_t = defaults().shadows.name().to_string())]
    pub shadows: String,
    /// Rasterizers: interpolate attributes affinely in screen space (no 1/z correction).
    #[arg(long)]
    pub affine: bool,
    /// flat | gouraud | phong | faceted: how shading varies across a triangle (faceted: one value per triangle, lit at its centroid).
    #[arg(long, default_value_t = defaults().interpolation.name().to_string())]
    pub interpolation: String,
    /// Mirror and glass recursion limit: reflected and refracted rays followed
    /// from one eye ray (0: none; the scene's or the default when absent).
    #[arg(long = "max-depth", value_name = "N")]
    pub max_depth: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Shadow-ray start offset along the ray (CGPP's rayBumpEpsilon).
    #[arg(long, value_name = "EPS")]
    pub bump: Option<f32>,
    /// --shadows map: texels per side of each shadow map (per cube face for point lights).
    #[arg(long = "shadow-map-size", value_name = "N")]
    pub shadow_map_size: Option<u32>,
    /// --shadows map: depth bias in texels, slope-scaled (too small: acne; too large: peter-panning).
    #[arg(long = "shadow-bias", value_name = "B")]
    pub shadow_bias: Option<f32>,
    /// --shadows volume: count the volume faces in front of the visible
    /// surface (zpass, wrong with the eye inside a shadow) or behind it (zfail).
    #[arg(long = "shadow-volume", value_name = "zpass|zfail", default_value_t = defaults().shadow_volume.name().to_string())]
    pub shadow_volume: String,
    /// Rasterizers: coverage samples per pixel with one shade per pixel per
    /// primitive: 1 (off), 2, 4 or 8. Ray casters ignore it (use --spp).
    #[arg(long, default_value_t = defaults().msaa, value_name = "N")]
    pub msaa: u32,
    /// Rasterizers: depth pass first, then one shade per pixel (false: forward shading).
    #[arg(long = "early-depth", value_name = "BOOL", default_value_t = defaults().early_depth, action = clap::ArgAction::Set)]
    pub early_depth: bool,
    /// Rasterizers: forward shading, every fragment that passes the depth test
    /// is shaded (the same as --early-depth false).
    #[arg(long)]
    pub forward: bool,
    /// Indirect light: none | ao | photons | path.
    #[arg(long, default_value_t = defaults().gi.mode.name().to_string())]
    pub gi: String,
    /// --gi path: indirect bounces, a number or `inf` (Mitsuba's max_depth = N + 2).
    #[arg(long, default_value_t = bounces_name(defaults().gi.bounces), value_name = "N|inf")]
    pub bounces: String,
    /// --gi ao: hemisphere rays per sample.
    #[arg(long = "ao-samples", value_name = "N")]
    pub ao_samples: Option<u32>,
    /// --gi ao: how far the hemisphere rays look for occluders.
    #[arg(long = "ao-distance", value_name = "D")]
    pub ao_distance: Option<f32>,
    /// --gi photons: photons shot from the lights.
    #[arg(long, value_name = "N")]
    pub photons: Option<u32>,
    /// --gi photons: nearest photons per density estimate.
    #[arg(long = "photon-k", value_name = "K")]
    pub photon_k: Option<u32>,
    /// --gi photons: rays gathered at the first hit (0: read the map there).
    #[arg(long = "final-gather", value_name = "N")]
    pub final_gather: Option<u32>,
    /// Stochastic methods: the image depends on (scene, settings, seed) only.
    #[arg(long, default_value_t = defaults().gi.seed)]
    pub seed: u64,
    /// Adaptive sampling: pixels stop taking samples (of at most --spp) once
    /// their estimated relative error is below TARGET (e.g. 0.05).
    #[arg(long, value_name = "TARGET")]
    pub adaptive: Option<f32>,
    /// Sub-sampling: trace every N-th pixel in x and y (1, 2, 4, 8, 16) and
    /// interpolate the pixels between.
    #[arg(long, default_value_t = defaults().subsample.step, value_name = "N")]
    pub subsample: u32,
    /// --subsample: also trace in full each grid cell whose corners differ in
    /// contrast ((max - min) / (max + min), per channel) by more than C.
    #[arg(long = "subsample-contrast", value_name = "C")]
    pub subsample_contrast: Option<f32>,
    /// Rasterizers fixed, tiled and painter: bits of sub-pixel precision of the snapped vertices, 0 to 8.
    #[arg(long = "subpixel-bits", default_value_t = defaults().subpixel_bits, value_name = "BITS")]
    pub subpixel_bits: u32,
    /// Rasterizers: what the depth buffer stores: f32 | unorm24 | unorm16 | reversed | linear-z.
    #[arg(long = "depth-buffer", default_value_t = defaults().depth_buffer.name().to_string(), value_name = "FORMAT")]
    pub depth_buffer: String,
    /// --view wireframe: the line algorithm, float (DDA) | integer (Bresenham).
    #[arg(long, default_value_t = defaults().lines.name().to_string())]
    pub lines: String,
    /// How textures are read: nearest | bilinear | mipmap-nearest | trilinear (mipmapped) | anisotropic:N (N = 2, 4, 8, 16 taps along the footprint).
    #[arg(long = "texture-filter", default_value_t = defaults().texture_filter.name().to_string(), value_name = "FILTER")]
    pub texture_filter: String,
    /// What mirrors reflect: ray (traced) | env (the environment in the reflected direction, no ray).
    #[arg(long, default_value_t = defaults().reflections.name().to_string(), value_name = "ray|env")]
    pub reflections: String,
    /// Rasterizers: clip triangles at the near plane only, or at every plane of the view volume.
    #[arg(long, default_value_t = defaults().clip.name().to_string(), value_name = "near|frustum")]
    pub clip: String,
    /// Rasterizers: cull copies made by `instances` by their bounding spheres (same image either way).
    #[arg(long = "cull-instances", value_name = "BOOL", default_value_t = defaults().cull_instances, action = clap::ArgAction::Set)]
    pub cull_instances: bool,
    /// Area lights and the environment: shadow rays per light per shading point (0: BSDF sampling alone).
    #[arg(long = "light-samples", default_value_t = defaults().light_samples, value_name = "N")]
    pub light_samples: u32,
    /// Area lights and the environment: combine light and BSDF sampling (on) or sample the lights alone (off).
    #[arg(long, default_value = "on", value_name = "on|off")]
    pub mis: String,
    /// raytrace:bvh: trace rays as packets (on) or one ray at a time (off); the same pixels, another speed.
    #[arg(long, default_value = "on", value_name = "on|off")]
    pub packets: String,
    /// --shadows map: none (hard) | pcf (percentage-closer) | pcss (percentage-closer soft).
    #[arg(long = "shadow-filter", default_value_t = defaults().shadow_filter.name().to_string(), value_name = "none|pcf|pcss")]
    pub shadow_filter: String,
    /// --shadow-filter pcf: the filter's radius in shadow-map texels.
    #[arg(long = "pcf-radius", default_value_t = defaults().pcf_radius, value_name = "R")]
    pub pcf_radius: f32,
    /// Display (PNG and the viewer; EXR stays linear): exposure in stops, the
    /// scale 2^EV multiplies the scene's `[render] exposure`.
    #[arg(long, default_value_t = defaults().display.exposure_ev, value_name = "EV", allow_negative_numbers = true)]
    pub exposure: f32,
    /// Display tone map after the exposure: standard | reinhard | aces | agx | khronos-neutral.
    #[arg(long, default_value_t = defaults().display.tonemap.name().to_string(), value_name = "MAP")]
    pub tonemap: String,
    /// Draw every glossy lobe with this model, its parameter matched to the
    /// lobe's width: blinn-phong | phong | ggx | beckmann | ward (as the chart's model sweep does).
    #[arg(long = "glossy-model", value_name = "MODEL")]
    pub glossy_model: Option<String>,
    /// Display transfer curve: srgb | 2.2 | off.
    #[arg(long, default_value_t = defaults().display.gamma.name().to_string(), value_name = "srgb|2.2|off")]
    pub gamma: String,
}

impl RenderOpts {
    /// Writes every option into `settings`, each checked: the error is one
    /// sentence naming the option. The image size only where `--width` or
    /// `--height` is given (else it stays the scene's).
    pub fn write_into(&self, settings: &mut RenderSettings) -> Result<(), String> {
        let s = settings;
        s.view = render::inspect::debug::View::parse(&self.view)?;
        s.shadows = render::ShadowMode::parse(&self.shadows)?;
        s.interpolation = render::Interpolation::parse(&self.interpolation)?;
        s.texture_filter = crate::scene::texture::TextureFilter::parse(&self.texture_filter).map_err(|e| format!("--texture-filter: {e}"))?;
        s.reflections = render::Reflections::parse(&self.reflections).map_err(|e| format!("--reflections: {e}"))?;
        s.shadow_volume = render::shadow::volume::VolumeMode::parse(&self.shadow_volume).map_err(|e| format!("--shadow-volume: {e}"))?;
        s.light_samples = self.light_samples;
        s.shadow_filter = render::shadow::ShadowFilter::parse(&self.shadow_filter).map_err(|e| format!("--shadow-filter: {e}"))?;
        s.pcf_radius = self.pcf_radius;
        s.display.exposure_ev = self.exposure;
        s.display.tonemap = crate::display::ToneMap::parse(&self.tonemap).map_err(|e| format!("--tonemap: {e}"))?;
        s.display.gamma = crate::display::Gamma::parse(&self.gamma).map_err(|e| format!("--gamma: {e}"))?;
        s.mis = match self.mis.as_str() {
            "on" => true,
            "off" => false,
            other => return Err(format!("--mis {other} is neither on nor off")),
        };
        s.packets = match self.packets.as_str() {
            "on" => true,
            "off" => false,
            other => return Err(format!("--packets {other} is neither on nor off")),
        };
        s.spp = self.spp;
        s.max_depth = self.max_depth.unwrap_or(s.max_depth);
        s.width = self.width.unwrap_or(s.width);
        s.height = self.height.unwrap_or(s.height);
        s.clip = render::raster::clip::ClipMode::parse(&self.clip).map_err(|e| format!("--clip: {e}"))?;
        s.cull_instances = self.cull_instances;
        s.affine = self.affine;
        s.shadow_bump = self.bump.unwrap_or(s.shadow_bump);
        s.shadow_map_size = self.shadow_map_size.unwrap_or(s.shadow_map_size);
        s.shadow_map_bias = self.shadow_bias.unwrap_or(s.shadow_map_bias);
        s.msaa = self.msaa;
        s.early_depth = self.early_depth && !self.forward;
        self.write_gi(&mut s.gi)?;
        s.subpixel_bits = self.subpixel_bits;
        s.depth_buffer = render::raster::depth_format::DepthFormat::parse(&self.depth_buffer).map_err(|e| format!("--depth-buffer: {e}"))?;
        s.lines = render::inspect::wireframe::LineAlgorithm::parse(&self.lines).map_err(|e| format!("--lines: {e}"))?;
        s.adaptive = self.adaptive.or(s.adaptive);
        s.subsample.step = self.subsample;
        if let Some(c) = self.subsample_contrast {
            if self.subsample == 1 {
                return Err("--subsample-contrast refines a sub-sampled frame: give --subsample 2, 4, 8 or 16 too".into());
            }
            s.subsample.contrast = Some(c);
        }
        // Every number's range, as the viewer checks its saved settings.
        render::settings_check::check(s).map_err(|p| p.for_command_line())
    }

    /// `--glossy-model`, checked: a change of the scene's materials rather
    /// than a render setting, applied when the scene is loaded.
    pub fn glossy_model(&self) -> Result<Option<crate::scene::material::GlossyModel>, String> {
        let Some(name) = &self.glossy_model else { return Ok(None) };
        let names: Vec<&str> = crate::scene::material::GlossyModel::NAMES.iter().map(|(n, _)| *n).collect();
        crate::scene::material::GlossyModel::parse(name).map(Some).ok_or_else(|| format!("--glossy-model {name} is not one of {}", names.join(", ")))
    }

    /// The indirect-light options, checked, written into `gi`.
    fn write_gi(&self, gi: &mut render::transport::gi::GiSettings) -> Result<(), String> {
        gi.mode = render::transport::gi::GiMode::parse(&self.gi)?;
        gi.seed = self.seed;
        gi.bounces = match self.bounces.as_str() {
            "inf" => None,
            n => match n.parse::<u32>() {
                Ok(b) if b <= render::transport::gi::MAX_BOUNCES => Some(b),
                _ => return Err(format!("--bounces {n} is neither inf nor a number from 0 to {}", render::transport::gi::MAX_BOUNCES)),
            },
        };
        // Ranges are checked with the other settings' (`settings_check`).
        gi.ao_samples = self.ao_samples.unwrap_or(gi.ao_samples);
        gi.ao_distance = self.ao_distance.unwrap_or(gi.ao_distance);
        gi.photons = self.photons.unwrap_or(gi.photons);
        gi.photon_k = self.photon_k.unwrap_or(gi.photon_k);
        gi.final_gather = self.final_gather.unwrap_or(gi.final_gather);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Line {
        #[command(flatten)]
        opts: RenderOpts,
    }

    fn settings_of(args: &[&str]) -> Result<RenderSettings, String> {
        let line = Line::try_parse_from(std::iter::once("pinhole").chain(args.iter().copied())).map_err(|e| e.to_string())?;
        let scene = crate::scene::builtin::load_builtin("spheres").unwrap().unwrap();
        let mut s = RenderSettings { width: 48, height: 32, ..RenderSettings::for_scene(&scene) };
        line.opts.write_into(&mut s)?;
        Ok(s)
    }

    /// `--max-depth` sets `RenderSettings::max_depth`, the one recursion
    /// limit the renderers and the viewer's slider read, within its bound.
    #[test]
    fn max_depth_sets_the_recursion_limit_and_is_bounded() {
        assert_eq!(settings_of(&[]).unwrap().max_depth, RenderSettings::default().max_depth);
        let (none, four) = (settings_of(&["--max-depth", "0"]).unwrap(), settings_of(&["--max-depth", "4"]).unwrap());
        assert_eq!((none.max_depth, four.max_depth), (0, 4));
        let e = settings_of(&["--max-depth", "17"]).unwrap_err();
        assert!(e.contains("--max-depth 17") && e.contains("16"), "{e}");
    }
}
