//! The admission gate: can this renderer draw this scene with these
//! settings? Every front end (the command line, the viewer's worker, chart
//! and gallery) asks here before a frame starts, so they all give the same
//! answer: the settings the renderer will really use, with one sentence for
//! each thing it draws otherwise than asked, or a refusal in one sentence.
//!
//! What a renderer can do is its own answer (`Renderer::check`,
//! `Renderer::substitutes`, `Renderer::instance_layer`); what no renderer
//! can afford (an image or shadow maps too big for memory) is checked here.

use crate::render::inspect::debug::View;
use crate::render::{layer_support, RenderSettings, Renderer, ShadowMode};
use crate::render::shadow::map as shadow_map;
use crate::render::shadow::ShadowFilter;
use crate::scene::Scene;

/// Settings a renderer accepted.
#[derive(Clone, Debug, PartialEq)]
pub struct Admitted {
    /// What the renderer will draw with: the settings asked for, or what it
    /// substituted for them.
    pub settings: RenderSettings,
    /// One sentence per substitution, saying what changed and why.
    pub notices: Vec<String>,
    /// One sentence per thing the settings, drawn as asked, approximate or
    /// leave without effect (`approximations`): said, but nothing changed.
    pub caveats: Vec<String>,
}

/// Settings a renderer can draw in place of ones it cannot, and the
/// sentence that says so.
#[derive(Clone, Debug, PartialEq)]
pub struct Substitute {
    pub settings: RenderSettings,
    pub notice: String,
}

/// Whether `renderer` draws `scene` with `settings`: `Ok` with the settings
/// it will use (`settings` themselves, or the first of its substitutes that
/// it draws), `Err` with why not. Loads no driver (`Renderer::ready` does).
pub fn admit(renderer: &dyn Renderer, scene: &Scene, settings: &RenderSettings) -> Result<Admitted, String> {
    let mut refusal = match check(renderer, scene, settings) {
        Ok(()) => return Ok(Admitted { settings: settings.clone(), notices: Vec::new(), caveats: approximations(scene, settings) }),
        Err(e) => e,
    };
    for s in renderer.substitutes(settings) {
        match check(renderer, scene, &s.settings) {
            Ok(()) => {
                let caveats = approximations(scene, &s.settings);
                return Ok(Admitted { settings: s.settings, notices: vec![s.notice], caveats });
            }
            // The most lenient substitute's refusal names what really stands in the way.
            Err(e) => refusal = e,
        }
    }
    Err(refusal)
}

/// The gate's second half, once the scene is prepared (its BVH built):
/// budgets that depend on what the scene does to light, measured by
/// tracing a little of it. Today: the photon map's memory.
pub fn admit_prepared(prepared: &crate::render::PreparedScene, settings: &RenderSettings) -> Result<(), String> {
    if settings.gi.mode == crate::render::transport::gi::GiMode::Photons {
        prepared.check_photon_budget(&settings.gi, settings.shadow_bump)?;
    }
    Ok(())
}

/// What admitted settings draw otherwise than the light transport they
/// approximate, and settings that have nothing to act on: one sentence
/// each, so nothing is left out without a word.
fn approximations(scene: &Scene, settings: &RenderSettings) -> Vec<String> {
    let mut notes = Vec::new();
    let area_lights = !scene.emitters.is_empty();
    let sky = scene.environment.as_ref().is_some_and(|e| e.is_light());
    let shaded = settings.view == View::Shaded;
    if shaded && area_lights && settings.shadows == ShadowMode::Volume {
        notes.push("--shadows volume gives each area light the hard shadow of its centre (a volume cannot be soft); --shadows ray, or map with --shadow-filter pcss, draws penumbrae".to_string());
    }
    if shaded && area_lights && settings.shadows == ShadowMode::Map && settings.shadow_filter == ShadowFilter::None {
        notes.push("--shadows map without a filter gives each area light the hard shadow of its centre; --shadow-filter pcf or pcss softens it".to_string());
    }
    if shaded && sky && matches!(settings.shadows, ShadowMode::Map | ShadowMode::Volume) {
        notes.push(format!("--shadows {} holds no shadows of the [environment]; its light samples cast shadow rays", settings.shadows.name()));
    }
    if shaded && matches!(settings.shadows, ShadowMode::Map | ShadowMode::Volume) && scene.has_cutouts() {
        notes.push(format!("--shadows {} casts the shadows of alphaMode MASK surfaces whole, cut-away parts included; --shadows ray passes light through them", settings.shadows.name()));
    }
    let colour_map = matches!(settings.view, View::FalseColour | View::Nan) || settings.view.error_kind().is_some();
    if colour_map && settings.display != crate::display::DisplaySettings::default() {
        notes.push(format!("--view {} holds its colours as linear values, so --exposure, --tonemap and --gamma other than 0, standard and srgb change them (the legend no longer matches)", settings.view.name()));
    }
    if settings.shadow_filter != ShadowFilter::None && (settings.shadows != ShadowMode::Map || !area_lights) {
        notes.push(format!("--shadow-filter {} filters the shadow maps of area lights only, and this render has none; it changes nothing", settings.shadow_filter.name()));
    }
    notes
}

/// Every reason `renderer` cannot draw `scene` with exactly `settings`.
fn check(renderer: &dyn Renderer, scene: &Scene, settings: &RenderSettings) -> Result<(), String> {
    crate::input::check_image_size(settings.width, settings.height).map_err(|e| format!("the image size {e}"))?;
    // Refused before anything is allocated, rather than aborting when it is.
    if settings.shadows == ShadowMode::Map || settings.view == View::Shadowmap {
        shadow_map::check_memory(scene, settings.shadow_map_size)?;
    }
    layer_support::check(renderer, scene, settings)?;
    renderer.check_camera(&scene.camera)?;
    classic_lighting(scene, settings)?;
    renderer.check(scene, settings)
}

/// What no renderer draws under `[render] lighting = "classic"`: traced or
/// mapped indirect light (the book's model has its ambient term instead),
/// lobes the book has no raw form of, and a `reflective` above 1 (it would
/// weigh the local colour by a negative number).
fn classic_lighting(scene: &Scene, settings: &RenderSettings) -> Result<(), String> {
    use crate::render::transport::gi::GiMode;
    use crate::scene::material::GlossyModel;
    if scene.render.lighting != crate::scene::Lighting::Classic {
        return Ok(());
    }
    if matches!(settings.gi.mode, GiMode::Path | GiMode::Photons) {
        return Err(format!("--gi {} traces physical light, which [render] lighting = \"classic\" does not describe; use --gi none or ao", settings.gi.mode.name()));
    }
    let in_use = scene.materials_in_use();
    let mut drawn = scene.materials.iter().zip(in_use).filter(|(_, used)| *used).map(|(m, _)| m);
    if let Some(m) = drawn.clone().find(|m| m.has_glossy() && !matches!(m.glossy_model, GlossyModel::BlinnPhong | GlossyModel::Phong)) {
        let name = GlossyModel::NAMES.iter().find(|(_, g)| *g == m.glossy_model).map_or("?", |(n, _)| n);
        return Err(format!("[render] lighting = \"classic\" has a raw form of the phong and blinn-phong lobes only, not glossy_model \"{name}\" (material \"{}\")", m.name));
    }
    if let Some(m) = drawn.find(|m| m.mirror.max_element() > 1.0) {
        return Err(format!("[render] lighting = \"classic\" reads mirror as the book's reflective, from 0 to 1, and material \"{}\" has mirror {}", m.name, m.mirror));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::renderer_by_name;

    fn scene(name: &str) -> Scene {
        crate::scene::builtin::load_builtin(name).unwrap().unwrap()
    }

    #[test]
    fn settings_a_renderer_draws_pass_through_unchanged() {
        let sc = scene("spheres");
        let settings = RenderSettings { spp: 4, shadows: ShadowMode::Map, shadow_map_size: 256, msaa: 4, ..RenderSettings::for_scene(&sc) };
        for name in ["raytrace:brute", "raytrace:bvh", "rasterize"] {
            let a = admit(renderer_by_name(name).unwrap().as_ref(), &sc, &settings).unwrap();
            assert_eq!(a, Admitted { settings: settings.clone(), notices: Vec::new(), caveats: Vec::new() }, "{name}");
        }
    }

    #[test]
    fn opengl_draws_shadow_maps_for_shadow_rays_and_says_so() {
        let sc = scene("spheres");
        let asked = RenderSettings::for_scene(&sc);
        assert_eq!(asked.shadows, ShadowMode::Ray, "rays are the default");
        let a = admit(renderer_by_name("opengl").unwrap().as_ref(), &sc, &asked).unwrap();
        assert_eq!(a.settings, RenderSettings { shadows: ShadowMode::Map, ..asked.clone() }, "only the shadows change");
        assert_eq!(a.notices, vec!["opengl cannot trace shadow rays; drawing shadow maps instead (--shadows map)".to_string()]);
        // Asked for what it draws, nothing is substituted.
        let none = RenderSettings { shadows: ShadowMode::None, ..asked };
        assert_eq!(admit(renderer_by_name("opengl").unwrap().as_ref(), &sc, &none).unwrap().notices, Vec::<String>::new());
    }

    #[test]
    fn opengl_draws_no_shadows_where_its_maps_cannot_draw_the_scene() {
        // Shadow maps are built from triangles and spheres, not CSG objects.
        let sc = scene("csg");
        let asked = RenderSettings::for_scene(&sc);
        let a = admit(renderer_by_name("opengl").unwrap().as_ref(), &sc, &asked).unwrap();
        assert_eq!(a.settings.shadows, ShadowMode::None);
        assert_eq!(a.notices.len(), 1);
        assert!(a.notices[0].contains("--shadows none") && !a.notices[0].contains('\n'), "{:?}", a.notices);
    }

    #[test]
    fn approximations_of_area_light_shadows_are_said() {
        let sc = scene("soft-shadows");
        let asked = RenderSettings { shadows: ShadowMode::Volume, ..RenderSettings::for_scene(&sc) };
        let a = admit(renderer_by_name("rasterize").unwrap().as_ref(), &sc, &asked).unwrap();
        assert_eq!(a.settings, asked);
        assert!(a.notices.is_empty(), "nothing is substituted: {:?}", a.notices);
        assert_eq!(a.caveats.len(), 1, "{:?}", a.caveats);
        assert!(a.caveats[0].contains("hard shadow of its centre"), "{:?}", a.caveats);
        // Filtered maps say nothing; a filter with ray shadows says it does nothing.
        let pcss = RenderSettings { shadows: ShadowMode::Map, shadow_filter: ShadowFilter::Pcss, ..asked.clone() };
        assert!(admit(renderer_by_name("rasterize").unwrap().as_ref(), &sc, &pcss).unwrap().caveats.is_empty());
        let idle = RenderSettings { shadows: ShadowMode::Ray, shadow_filter: ShadowFilter::Pcf, ..asked };
        let notes = admit(renderer_by_name("raytrace").unwrap().as_ref(), &sc, &idle).unwrap().caveats;
        assert!(notes.len() == 1 && notes[0].contains("changes nothing"), "{notes:?}");
        // OpenGL draws area lights by light sampling alone and shadow maps,
        // and says so in one sentence; without light samples it refuses.
        let gl = renderer_by_name("opengl").unwrap();
        let asked = RenderSettings::for_scene(&sc);
        assert!(asked.mis && asked.shadows == ShadowMode::Ray);
        let a = admit(gl.as_ref(), &sc, &asked).unwrap();
        assert_eq!(a.settings, RenderSettings { shadows: ShadowMode::Map, mis: false, ..asked.clone() });
        assert_eq!(a.notices.len(), 1);
        assert!(a.notices[0].contains("(--shadows map --mis off)") && !a.notices[0].contains('\n'), "{:?}", a.notices);
        let mapped = RenderSettings { shadows: ShadowMode::Map, ..asked.clone() };
        let a = admit(gl.as_ref(), &sc, &mapped).unwrap();
        assert_eq!(a.settings, RenderSettings { mis: false, ..mapped.clone() });
        assert!(a.notices.len() == 1 && a.notices[0].ends_with("light sampling alone (--mis off)"), "{:?}", a.notices);
        let e = admit(gl.as_ref(), &sc, &RenderSettings { light_samples: 0, ..mapped }).unwrap_err();
        assert!(e.contains("--light-samples 0") && !e.contains('\n'), "{e}");
        // Without area lights, --mis stays as asked.
        let spheres = scene("spheres");
        let a = admit(gl.as_ref(), &spheres, &RenderSettings::for_scene(&spheres)).unwrap();
        assert!(a.settings.mis);
    }

    #[test]
    fn opengl_lights_with_the_environment_without_shadows_and_says_so() {
        let sc = scene("sky");
        assert!(sc.environment.as_ref().is_some_and(|e| e.is_light()));
        let gl = renderer_by_name("opengl").unwrap();
        // Asked for maps, it refuses in one sentence.
        let s = RenderSettings { shadows: ShadowMode::Map, mis: false, ..RenderSettings::for_scene(&sc) };
        let e = admit(gl.as_ref(), &sc, &s).unwrap_err();
        assert_eq!(e, "the opengl renderer lights the scene with the [environment] without shadows (it casts no rays, and no shadow map holds the sky's), so with --shadows none only");
        // Asked for rays and MIS (the defaults), it draws no shadows and light sampling alone.
        let asked = RenderSettings::for_scene(&sc);
        let a = admit(gl.as_ref(), &sc, &asked).unwrap();
        assert_eq!(a.settings, RenderSettings { shadows: ShadowMode::None, mis: false, ..asked });
        assert!(a.notices.len() == 1 && a.notices[0].ends_with("(--shadows none --mis off)") && !a.notices[0].contains('\n'), "{:?}", a.notices);
    }

    #[test]
    fn a_refusal_is_one_sentence_naming_what_stands_in_the_way() {
        // CSG objects under shadow volumes: no renderer substitutes.
        let sc = scene("csg");
        let s = RenderSettings { shadows: ShadowMode::Volume, ..RenderSettings::for_scene(&sc) };
        let e = admit(renderer_by_name("rasterize").unwrap().as_ref(), &sc, &s).unwrap_err();
        assert!(e.starts_with("--shadows volume cannot include csg objects") && !e.contains('\n'), "{e}");
        // The shadow-map view needs the maps in memory whatever the shadows: six
        // point lights at 4096 texels per face take 4.5 GiB.
        let mut big = scene("spheres");
        big.lights = vec![big.lights[0].clone(); 6];
        let s = RenderSettings { view: View::Shadowmap, shadow_map_size: shadow_map::MAX_SIZE, ..RenderSettings::for_scene(&big) };
        assert_eq!(s.shadows, ShadowMode::Ray);
        let e = admit(renderer_by_name("raytrace").unwrap().as_ref(), &big, &s).unwrap_err();
        assert!(e.starts_with("shadow maps of 6 lights") && !e.contains('\n'), "{e}");
        // An image too big for memory.
        let s = RenderSettings { width: 100_000, ..RenderSettings::for_scene(&big) };
        let e = admit(renderer_by_name("raytrace").unwrap().as_ref(), &big, &s).unwrap_err();
        assert!(e.starts_with("the image size 100000x"), "{e}");
    }
}

/// What `--aov` layers are for `renderer`: a notice when its own visibility
/// is not the BVH ray caster's, which casts the layers (`render::aov`).
pub fn aov_notice(renderer: &dyn crate::render::Renderer, aovs: &[crate::render::aov::Aov]) -> Option<String> {
    (!aovs.is_empty() && !renderer.name().starts_with("raytrace")).then(|| {
        format!("--aov layers are cast through the BVH at each pixel's first sample; {} finds its own surfaces, which can differ along edges", renderer.name())
    })
}
