//! The configurations a methods chart measures: each approximation that
//! matters for the scene, at a few settings of its knob, plus the samples
//! that buy accuracy with time. Every configuration is a renderer and the
//! `RenderSettings` it renders with, so the viewer can apply one as it is.

use crate::render::transport::gi::GiMode;
use crate::render::inspect::debug;
use crate::render::shadow::map as shadow_map;
use crate::render::{Interpolation, RenderSettings, ShadowMode, DEFAULT_RAYTRACE};
use crate::render::raster::depth_format::DepthFormat;
use crate::render::shadow::volume::VolumeMode;
use crate::render::shadow::ShadowFilter;
use crate::render::raster::DEFAULT_RASTERIZE;
use crate::render::Reflections;
use crate::scene::texture::TextureFilter;
use crate::chart::glossy_models;
use crate::scene::material::GlossyModel;
use crate::scene::Scene;

/// One point of the methods sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Configuration {
    /// What it is, in the words of the command line (`describe`).
    pub label: String,
    /// The family of approximation it belongs to: the chart colours by it.
    pub group: &'static str,
    pub renderer: String,
    pub settings: RenderSettings,
    /// The glossy model every glossy material is drawn with instead of its
    /// own (`glossy_models::switched`): an edit of the scene's materials, not
    /// a render setting, so the model sweep can set models side by side.
    pub glossy_model: Option<GlossyModel>,
}

impl Configuration {
    pub fn new(group: &'static str, renderer: &str, settings: RenderSettings) -> Configuration {
        Configuration { label: describe(renderer, &settings), group, renderer: renderer.to_string(), settings, glossy_model: None }
    }

    /// The configuration drawn with every glossy lobe switched to `model`.
    pub fn with_glossy_model(group: &'static str, renderer: &str, settings: RenderSettings, model: GlossyModel) -> Configuration {
        let label = format!("{} glossy_model {}", describe(renderer, &settings), glossy_models::name(model));
        Configuration { label, group, renderer: renderer.to_string(), settings, glossy_model: Some(model) }
    }

    /// The scene this configuration draws: `scene` itself, or a copy with
    /// its glossy lobes switched.
    pub fn scene<'s>(&self, scene: &'s Scene) -> std::borrow::Cow<'s, Scene> {
        match self.glossy_model {
            None => std::borrow::Cow::Borrowed(scene),
            Some(model) => std::borrow::Cow::Owned(glossy_models::switched(scene, model)),
        }
    }
}

/// The renderer and every knob that differs from the defaults, as the command
/// line would set it: "rasterize:fixed --spp 4 --shadows map --shadow-map-size 256".
/// Commas never appear, so a label is one CSV field.
pub fn describe(renderer: &str, s: &RenderSettings) -> String {
    let mut out = vec![renderer.to_string()];
    let mut knob = |k: &str, v: String| out.push(format!("--{k} {v}"));
    if s.spp != 1 {
        knob("spp", s.spp.to_string());
    }
    if s.msaa > 1 {
        knob("msaa", s.msaa.to_string());
    }
    if s.shadows != ShadowMode::Ray {
        knob("shadows", s.shadows.name().to_string());
    }
    if s.shadows == ShadowMode::Volume && s.shadow_volume != VolumeMode::ZFail {
        knob("shadow-volume", s.shadow_volume.name().to_string());
    }
    if s.shadows == ShadowMode::Map {
        if s.shadow_map_size != shadow_map::DEFAULT_SIZE {
            knob("shadow-map-size", s.shadow_map_size.to_string());
        }
        if s.shadow_map_bias != shadow_map::DEFAULT_BIAS {
            knob("shadow-map-bias", format!("{}", s.shadow_map_bias));
        }
        if s.shadow_filter != ShadowFilter::None {
            knob("shadow-filter", s.shadow_filter.name().to_string());
            if s.shadow_filter == ShadowFilter::Pcf {
                knob("pcf-radius", format!("{}", s.pcf_radius));
            }
        }
    }
    if s.light_samples != 1 {
        knob("light-samples", s.light_samples.to_string());
    }
    if !s.mis {
        knob("mis", "off".to_string());
    }
    if !s.packets {
        knob("packets", "off".to_string());
    }
    if s.subpixel_bits != RenderSettings::default().subpixel_bits {
        knob("subpixel-bits", s.subpixel_bits.to_string());
    }
    if s.depth_buffer != DepthFormat::F32 {
        knob("depth-buffer", s.depth_buffer.name().to_string());
    }
    if s.interpolation != Interpolation::Phong {
        knob("interpolation", s.interpolation.name().to_string());
    }
    if s.texture_filter != TextureFilter::Trilinear {
        knob("texture-filter", s.texture_filter.name().to_string());
    }
    if s.reflections != Reflections::Ray {
        knob("reflections", s.reflections.name().to_string());
    }
    if s.affine {
        out.push("--affine".into());
    }
    if s.subsample.is_on() {
        out.push(format!("--subsample {}", s.subsample.step));
        if let Some(c) = s.subsample.contrast {
            out.push(format!("--subsample-contrast {c}"));
        }
    }
    let gi = &s.gi;
    if gi.mode != GiMode::None {
        let mut knob = |k: &str, v: String| out.push(format!("--{k} {v}"));
        knob("gi", gi.mode.name().to_string());
        match gi.mode {
            GiMode::Ao => knob("ao-samples", gi.ao_samples.to_string()),
            GiMode::Photons => {
                knob("photons", gi.photons.to_string());
                if gi.final_gather > 0 {
                    knob("final-gather", gi.final_gather.to_string());
                }
            }
            GiMode::Path => {
                if let Some(b) = gi.bounces {
                    knob("bounces", b.to_string());
                }
            }
            GiMode::None => {}
        }
    }
    out.join(" ")
}

/// Whether `config`'s renderer draws `scene` with exactly its settings
/// (`render::admit` accepts them with nothing substituted: a substitute
/// would be measured under a label that does not say what was drawn).
pub fn accepted(scene: &Scene, config: &Configuration) -> bool {
    let scene = config.scene(scene);
    crate::render::renderer_by_name(&config.renderer)
        .and_then(|r| crate::render::admit::admit(r.as_ref(), &scene, &config.settings))
        .is_ok_and(|a| a.notices.is_empty() && a.settings == config.settings)
}

/// What every swept configuration starts from: the scene's defaults, the
/// shaded view, at `base`'s image size and seed.
pub fn plain_settings(scene: &Scene, base: &RenderSettings) -> RenderSettings {
    RenderSettings {
        width: base.width,
        height: base.height,
        view: debug::View::Shaded,
        gi: crate::render::transport::gi::GiSettings { seed: base.gi.seed, ..Default::default() },
        ..RenderSettings::for_scene(scene)
    }
}

/// The configurations worth measuring on `scene`, all at `base`'s image size
/// (and seed). Shadow-map settings only when something casts a shadow,
/// interpolation only when the scene has triangles.
pub fn method_configurations(scene: &Scene, base: &RenderSettings) -> Vec<Configuration> {
    let plain = plain_settings(scene, base);
    let with = |f: &dyn Fn(&mut RenderSettings)| {
        let mut s = plain.clone();
        f(&mut s);
        s
    };
    let (ray, raster) = (DEFAULT_RAYTRACE, DEFAULT_RASTERIZE);
    let mut out = Vec::new();
    let mut add = |group, renderer: &str, s: RenderSettings| out.push(Configuration::new(group, renderer, s));

    // Antialiasing: more samples per pixel, or coverage samples.
    for spp in [1, 4, 16] {
        add("samples", ray, with(&|s| s.spp = spp));
    }
    add("samples", raster, plain.clone());
    add("samples", raster, with(&|s| s.msaa = 4));
    // The same image by other visibility algorithms: they differ in time only.
    for variant in ["rasterize:tiled", "rasterize:scanline"] {
        add("samples", variant, plain.clone());
    }
    // The ray caster without its packets: the same image, the time of one
    // ray at a time.
    add("samples", ray, with(&|s| s.packets = false));

    // Fewer rays than pixels: a grid traced and the rest interpolated, and
    // the same with the cells whose corners differ traced in full.
    for contrast in [None, Some(0.3)] {
        add("sub-sampling", ray, with(&|s| s.subsample = crate::render::frame::Subsample { step: 4, contrast }));
    }

    // Lights with extent: light samples per shading point, light sampling
    // alone (MIS off) and BSDF sampling alone (no light samples).
    if scene.has_sampled_lights() {
        for n in [4, 16] {
            add("light sampling", ray, with(&|s| s.light_samples = n));
        }
        for n in [1, 4] {
            add("light sampling", ray, with(&|s| {
                s.light_samples = n;
                s.mis = false;
            }));
        }
        add("light sampling", ray, with(&|s| s.light_samples = 0));
    }

    // Soft shadows of area lights from maps: the three filters at two map
    // sizes (volumes are below with the other shadows).
    if !scene.emitters.is_empty() {
        for size in [512, 2048] {
            for filter in ShadowFilter::ALL {
                add("soft shadows", raster, with(&|s| {
                    s.shadows = ShadowMode::Map;
                    s.shadow_map_size = size;
                    s.shadow_filter = filter;
                }));
            }
        }
    }

    // Shadows: none, traced (above), or looked up in maps of a few sizes and biases.
    let casts_shadows = (!scene.lights.is_empty() || !scene.emitters.is_empty()) && scene.triangles.len() + scene.spheres.len() > 1;
    if casts_shadows {
        add("shadows", raster, with(&|s| s.shadows = ShadowMode::None));
        // Sizes whose maps for all the scene's lights would not fit in
        // memory are refused by `accepted` and left out below.
        for size in [256, 1024, 2048] {
            add("shadows", raster, with(&|s| {
                s.shadows = ShadowMode::Map;
                s.shadow_map_size = size;
            }));
        }
        for mode in [VolumeMode::ZFail, VolumeMode::ZPass] {
            add("shadows", raster, with(&|s| {
                s.shadows = ShadowMode::Volume;
                s.shadow_volume = mode;
            }));
        }
        for bias in [0.1, 8.0] {
            add("shadows", raster, with(&|s| {
                s.shadows = ShadowMode::Map;
                s.shadow_map_bias = bias;
            }));
        }
    }

    // Visibility: depth buffers that store less, and no depth buffer at all.
    for format in [DepthFormat::Unorm16, DepthFormat::Unorm24, DepthFormat::Reversed, DepthFormat::LinearZ] {
        add("visibility", raster, with(&|s| s.depth_buffer = format));
    }
    add("visibility", "rasterize:painter", plain.clone());

    // Shading interpolation across triangles.
    if !scene.triangles.is_empty() {
        for i in [Interpolation::Flat, Interpolation::Gouraud, Interpolation::Faceted] {
            add("interpolation", raster, with(&|s| s.interpolation = i));
        }
    }

    // Textures: read from level 0 only (aliasing), from the nearest level
    // (seams), or anisotropically (sharper than trilinear), at one sample and four.
    if scene.has_textures() {
        for filter in [TextureFilter::Nearest, TextureFilter::Bilinear, TextureFilter::MipmapNearest, TextureFilter::Anisotropic8] {
            for spp in [1, 4] {
                add("textures", ray, with(&|s| {
                    s.texture_filter = filter;
                    s.spp = spp;
                }));
            }
        }
    }
    // Reflections: the environment looked up instead of traced, blind to
    // nearby objects; only where something is a mirror.
    if scene.materials.iter().any(|m| m.mirror != crate::math::Vec3::ZERO) {
        add("reflections", ray, with(&|s| s.reflections = Reflections::Env));
        add("reflections", raster, with(&|s| s.reflections = Reflections::Env));
    }

    // Indirect light: the cheap approximation (it darkens the ambient term,
    // so only where there is one), photons, and paths (the truth's method).
    let has_ambient = scene.render.ambient.max_element() > 0.0;
    for (n, spp) in [(4, 1), (16, 4)].into_iter().filter(|_| has_ambient) {
        add("indirect light", ray, with(&|s| {
            s.gi.mode = GiMode::Ao;
            s.gi.ao_samples = n;
            s.spp = spp;
        }));
    }
    for photons in [20_000, 200_000] {
        add("indirect light", ray, with(&|s| {
            s.gi.mode = GiMode::Photons;
            s.gi.photons = photons;
            s.spp = 4;
        }));
    }
    for spp in [4, 16, 64] {
        add("indirect light", ray, with(&|s| {
            s.gi.mode = GiMode::Path;
            s.spp = spp;
        }));
    }
    add("indirect light", raster, with(&|s| {
        s.gi.mode = GiMode::Path;
        s.spp = 16;
    }));
    // Glossy models side by side: every glossy lobe drawn by each model in
    // turn, its parameter matched to the lobe's width, so each model's cost
    // sits beside its error against the scene's own model's truth.
    if glossy_models::has_glossy(scene) {
        for model in glossy_models::SWEPT {
            out.push(Configuration::with_glossy_model("glossy model", ray, plain.clone(), model));
        }
    }

    // What the scene cannot be drawn with (CSG objects under the painter or
    // shadow maps, the copies' two-level layer under shadow maps, maps too
    // big for memory...) is not measured: its image would be refused, not wrong.
    out.retain(|c| accepted(scene, c));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_model_sweep_lists_every_glossy_model_where_there_is_a_glossy_lobe() {
        let scene = crate::scene::builtin::load_builtin("spheres").unwrap().unwrap();
        let base = RenderSettings { width: 40, height: 30, ..RenderSettings::for_scene(&scene) };
        let configs = method_configurations(&scene, &base);
        let models: Vec<GlossyModel> = configs.iter().filter(|c| c.group == "glossy model").filter_map(|c| c.glossy_model).collect();
        assert_eq!(models, glossy_models::SWEPT.to_vec());
        for c in configs.iter().filter(|c| c.group == "glossy model") {
            let m = c.glossy_model.unwrap();
            assert!(c.label.ends_with(&format!("glossy_model {}", glossy_models::name(m))), "{}", c.label);
            // The edit reaches the scene the configuration draws.
            assert!(c.scene(&scene).materials.iter().filter(|m| m.has_glossy()).all(|g| g.glossy_model == m));
        }
        assert!(configs.iter().filter(|c| c.group != "glossy model").all(|c| c.glossy_model.is_none()));
        // No glossy lobe, no model sweep.
        let mut plain = scene.clone();
        plain.materials.iter_mut().for_each(|m| m.glossy = crate::math::Vec3::ZERO);
        assert!(method_configurations(&plain, &RenderSettings::for_scene(&plain)).iter().all(|c| c.group != "glossy model"));
        // Classic lighting has raw forms of the power lobes only: the sweep keeps those.
        let classic = crate::scene::builtin::load_builtin("cgfs-spheres").unwrap().unwrap();
        let kept: Vec<GlossyModel> = method_configurations(&classic, &RenderSettings::for_scene(&classic)).iter().filter_map(|c| c.glossy_model).collect();
        assert_eq!(kept, vec![GlossyModel::BlinnPhong, GlossyModel::Phong]);
    }

    #[test]
    fn labels_name_the_knobs_that_differ_and_are_unique() {
        let scene = crate::scene::builtin::load_builtin("teapot").unwrap().unwrap();
        let base = RenderSettings { width: 40, height: 30, ..RenderSettings::for_scene(&scene) };
        let configs = method_configurations(&scene, &base);
        assert!(configs.len() >= 12);
        let mut labels: Vec<&str> = configs.iter().map(|c| c.label.as_str()).collect();
        labels.sort();
        labels.dedup();
        assert_eq!(labels.len(), configs.len(), "two configurations share a label");
        assert!(labels.iter().all(|l| !l.contains(',')));
        assert!(configs.iter().all(|c| (c.settings.width, c.settings.height) == (40, 30)));
        let map = configs.iter().find(|c| c.settings.shadow_map_size == 256).unwrap();
        assert_eq!(map.label, "rasterize:fixed --shadows map --shadow-map-size 256");
        let path = configs.iter().find(|c| c.settings.gi.mode == GiMode::Path && c.settings.spp == 64).unwrap();
        assert_eq!(path.label, "raytrace:bvh --spp 64 --gi path");
    }

    #[test]
    fn shadow_maps_that_would_not_fit_in_memory_are_left_out() {
        let mut scene = crate::scene::builtin::load_builtin("spheres").unwrap().unwrap();
        let light = scene.lights[0].clone();
        // 2048^2 texels x 6 faces x 8 bytes = 192 MiB per point light: 6 lights pass 1 GiB.
        scene.lights = vec![light; 6];
        let sizes: Vec<u32> = method_configurations(&scene, &RenderSettings::for_scene(&scene))
            .iter()
            .filter(|c| c.settings.shadows == ShadowMode::Map)
            .map(|c| c.settings.shadow_map_size)
            .collect();
        assert!(sizes.contains(&1024) && !sizes.contains(&2048), "{sizes:?}");
    }

    #[test]
    fn textures_and_env_reflections_are_swept_where_they_matter() {
        let scene = crate::scene::builtin::load_builtin("textures").unwrap().unwrap();
        let configs = method_configurations(&scene, &RenderSettings::for_scene(&scene));
        let labels: Vec<&str> = configs.iter().map(|c| c.label.as_str()).collect();
        assert!(labels.contains(&"raytrace:bvh --texture-filter nearest"), "{labels:?}");
        assert!(labels.contains(&"raytrace:bvh --spp 4 --texture-filter bilinear"), "{labels:?}");
        assert!(labels.contains(&"rasterize:fixed --reflections env"), "{labels:?}");
        let teapot = crate::scene::builtin::load_builtin("teapot").unwrap().unwrap();
        assert!(method_configurations(&teapot, &RenderSettings::for_scene(&teapot)).iter().all(|c| c.group != "textures" && c.group != "reflections"));
    }

    #[test]
    fn configurations_the_scene_refuses_are_left_out() {
        let scene = crate::scene::builtin::load_builtin("csg").unwrap().unwrap();
        let base = RenderSettings::for_scene(&scene);
        let configs = method_configurations(&scene, &base);
        assert!(!configs.is_empty());
        assert!(configs.iter().all(|c| accepted(&scene, c)));
        assert!(!configs.iter().any(|c| c.renderer == "rasterize:painter"), "the painter cannot draw CSG");
        assert!(!configs.iter().any(|c| c.settings.shadows == ShadowMode::Map), "shadow maps are built from triangles and spheres only");
        // On a scene without CSG they are measured.
        let teapot = crate::scene::builtin::load_builtin("teapot").unwrap().unwrap();
        let configs = method_configurations(&teapot, &RenderSettings::for_scene(&teapot));
        assert!(configs.iter().any(|c| c.renderer == "rasterize:painter"));
    }

    #[test]
    fn lights_with_extent_sweep_light_samples_mis_and_shadow_filters() {
        let scene = crate::scene::builtin::load_builtin("soft-shadows").unwrap().unwrap();
        let configs = method_configurations(&scene, &RenderSettings::for_scene(&scene));
        let labels: Vec<&str> = configs.iter().map(|c| c.label.as_str()).collect();
        for expected in [
            "raytrace:bvh --light-samples 16",
            "raytrace:bvh --mis off",
            "raytrace:bvh --light-samples 0",
            "rasterize:fixed --shadows map --shadow-map-size 512",
            "rasterize:fixed --shadows map --shadow-map-size 2048 --shadow-filter pcss",
            "rasterize:fixed --shadows map --shadow-map-size 512 --shadow-filter pcf --pcf-radius 1.5",
            "rasterize:fixed --shadows volume",
        ] {
            assert!(labels.contains(&expected), "{expected} missing from {labels:?}");
        }
        // A scene of point lights sweeps none of it.
        let teapot = crate::scene::builtin::load_builtin("teapot").unwrap().unwrap();
        assert!(method_configurations(&teapot, &RenderSettings::for_scene(&teapot)).iter().all(|c| c.group != "light sampling" && c.group != "soft shadows"));
    }

    #[test]
    fn a_scene_with_one_primitive_sweeps_no_shadow_maps() {
        let scene = crate::scene::builtin::load_builtin("one-triangle").unwrap().unwrap();
        let base = RenderSettings::for_scene(&scene);
        assert!(method_configurations(&scene, &base).iter().all(|c| c.group != "shadows"));
    }
}
