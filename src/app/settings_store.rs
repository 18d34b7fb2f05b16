//! What the viewer remembers between runs (eframe storage): one struct,
//! `ViewerSettings`, that the viewer edits live and saves and loads whole.

use crate::render::inspect::debug::View;
use crate::render::raster::depth_format::DepthFormat;
use crate::render::inspect::wireframe::LineAlgorithm;
use crate::render::shadow::volume::VolumeMode;
use crate::render::shadow::map as shadow_map;
use crate::render::{Interpolation, RenderSettings, ShadowMode};
use crate::scene::Scene;

pub const STORAGE_KEY: &str = "pinhole";

/// The user's choices that outlive a scene: renderer, render knobs, display
/// and panels. `#[serde(default)]`: settings saved by an older version load,
/// missing values taking their defaults. The knobs marked `skip` are not
/// remembered between runs and go back to their defaults with a new scene.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct ViewerSettings {
    /// The scene argument (built-in name or path) last opened.
    pub scene: Option<String>,
    /// Saved as an option, as older versions saved it; empty: the default.
    #[serde(with = "saved_as_option")]
    pub renderer: String,
    pub spp: u32,
    pub shadows: ShadowMode,
    /// `--shadows volume`: z-pass or z-fail counting.
    pub shadow_volume: VolumeMode,
    pub shadow_bump: f32,
    pub max_depth: u32,
    pub view: View,
    pub interpolation: Interpolation,
    /// Indirect light and its knobs.
    pub gi: crate::render::transport::gi::GiSettings,
    /// How textures are read.
    pub texture_filter: crate::scene::texture::TextureFilter,
    /// Traced reflections or environment lookups.
    pub reflections: crate::render::Reflections,
    /// Sub-sampling: a grid traced, the rest interpolated.
    pub subsample: crate::render::frame::Subsample,
    /// Image size over the scene's size.
    pub res_scale: f32,
    /// Encode the image as sRGB for display.
    pub gamma: bool,
    pub panels: Panels,
    #[serde(skip)]
    pub per_scene: SceneKnobs,
}

/// Render knobs that go back to their defaults with every scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneKnobs {
    pub shadow_map_size: u32,
    pub shadow_map_bias: f32,
    pub msaa: u32,
    pub early_depth: bool,
    pub affine: bool,
    /// What the depth buffer stores (rasterizers with one).
    pub depth_buffer: DepthFormat,
    /// The wireframe view's line algorithm.
    pub lines: LineAlgorithm,
    /// The planes rasterizers clip at (the same image either way).
    pub clip: crate::render::raster::clip::ClipMode,
}

impl Default for SceneKnobs {
    fn default() -> Self {
        SceneKnobs { shadow_map_size: shadow_map::DEFAULT_SIZE, shadow_map_bias: shadow_map::DEFAULT_BIAS, msaa: 1, early_depth: true, affine: false, depth_buffer: DepthFormat::F32, lines: LineAlgorithm::Float, clip: Default::default() }
    }
}

/// Which side-panel sections are open.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Panels {
    pub side: bool,
    pub camera: bool,
    pub lights: bool,
    pub materials: bool,
    pub shading: bool,
}

impl Default for Panels {
    fn default() -> Self {
        Panels { side: true, camera: false, lights: true, materials: false, shading: true }
    }
}

impl Default for ViewerSettings {
    fn default() -> Self {
        ViewerSettings {
            scene: None,
            renderer: crate::render::DEFAULT_RAYTRACE.to_string(),
            spp: 1,
            shadows: ShadowMode::Ray,
            shadow_volume: VolumeMode::ZFail,
            shadow_bump: 1e-4,
            max_depth: 4,
            view: View::Shaded,
            interpolation: Interpolation::Phong,
            gi: Default::default(),
            texture_filter: Default::default(),
            reflections: Default::default(),
            subsample: Default::default(),
            res_scale: 1.0,
            gamma: true,
            panels: Panels::default(),
            per_scene: SceneKnobs::default(),
        }
    }
}

impl ViewerSettings {
    /// Brings loaded values into range: a renderer this build has, spp in
    /// 1..=1024, a resolution scale in 0.1..=2.
    pub fn sanitized(mut self, renderer_names: &[&str]) -> ViewerSettings {
        if !renderer_names.contains(&self.renderer.as_str()) {
            self.renderer = crate::render::DEFAULT_RAYTRACE.to_string();
        }
        self.spp = self.spp.clamp(1, 1024);
        self.res_scale = self.res_scale.clamp(0.1, 2.0);
        self
    }

    /// The settings to render `scene` with at `width` x `height`: the scene's
    /// values with these knobs.
    pub fn render_settings(&self, scene: &Scene, width: u32, height: u32) -> RenderSettings {
        let k = &self.per_scene;
        RenderSettings {
            width,
            height,
            spp: self.spp,
            shadows: self.shadows,
            shadow_volume: self.shadow_volume,
            shadow_bump: self.shadow_bump,
            max_depth: self.max_depth,
            view: self.view,
            interpolation: self.interpolation,
            gi: self.gi.clone(),
            texture_filter: self.texture_filter,
            reflections: self.reflections,
            subsample: self.subsample,
            shadow_map_size: k.shadow_map_size,
            shadow_map_bias: k.shadow_map_bias,
            msaa: k.msaa,
            early_depth: k.early_depth,
            affine: k.affine,
            depth_buffer: k.depth_buffer,
            lines: k.lines,
            clip: k.clip,
            ..RenderSettings::for_scene(scene)
        }
    }

    /// Takes the renderer and every render knob of `settings` (a configuration
    /// measured elsewhere), keeping the image size, the view and the display.
    pub fn apply_configuration(&mut self, renderer: &str, settings: &RenderSettings) {
        self.renderer = renderer.to_string();
        self.spp = settings.spp;
        self.shadows = settings.shadows;
        self.shadow_volume = settings.shadow_volume;
        self.shadow_bump = settings.shadow_bump;
        self.max_depth = settings.max_depth;
        self.interpolation = settings.interpolation;
        self.gi = settings.gi.clone();
        self.texture_filter = settings.texture_filter;
        self.reflections = settings.reflections;
        self.subsample = settings.subsample;
        self.per_scene = SceneKnobs {
            shadow_map_size: settings.shadow_map_size,
            shadow_map_bias: settings.shadow_map_bias,
            msaa: settings.msaa,
            early_depth: settings.early_depth,
            affine: settings.affine,
            depth_buffer: settings.depth_buffer,
            lines: settings.lines,
            clip: settings.clip,
        };
    }

    /// Takes `other`'s renderer and render knobs, keeping this one's view,
    /// display, panels and scene.
    pub fn take_configuration(&mut self, other: &ViewerSettings) {
        let keep = (self.scene.take(), self.view, self.res_scale, self.gamma, self.panels);
        *self = other.clone();
        (self.scene, self.view, self.res_scale, self.gamma, self.panels) = keep;
    }

    pub fn load(storage: Option<&dyn eframe::Storage>) -> Option<ViewerSettings> {
        storage.and_then(|s| eframe::get_value(s, STORAGE_KEY))
    }

    pub fn save(&self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, STORAGE_KEY, self);
    }
}

/// A string stored as `Option<String>` (`None` for empty), the form older
/// versions saved the renderer in.
mod saved_as_option {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(s: &str, ser: S) -> Result<S::Ok, S::Error> {
        (!s.is_empty()).then_some(s).serialize(ser)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(de: D) -> Result<String, D::Error> {
        Ok(Option::<String>::deserialize(de)?.unwrap_or_default())
    }
}

/// Settings storage in memory: what the viewer's tests save to and load
/// from instead of the user's settings file.
#[derive(Default)]
pub struct MemoryStorage(pub std::collections::HashMap<String, String>);

impl eframe::Storage for MemoryStorage {
    fn get_string(&self, key: &str) -> Option<String> {
        self.0.get(key).cloned()
    }
    fn set_string(&mut self, key: &str, value: String) {
        self.0.insert(key.into(), value);
    }
    fn remove_string(&mut self, key: &str) {
        self.0.remove(key);
    }
    fn flush(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    type Mem = MemoryStorage;

    #[test]
    fn older_saved_settings_load() {
        // As an older version saved them: a field since dropped, some missing.
        let old = r#"(scene: Some("spheres"), renderer: Some("raytrace:brute"), spp: 9, shadows: map, gamma: false, retired: 3)"#;
        let mut mem = Mem::default();
        eframe::Storage::set_string(&mut mem, STORAGE_KEY, old.into());
        let s = ViewerSettings::load(Some(&mem)).unwrap();
        assert_eq!(s.scene.as_deref(), Some("spheres"));
        assert_eq!(s.renderer, "raytrace:brute");
        assert_eq!((s.spp, s.shadows, s.gamma), (9, ShadowMode::Map, false));
        assert_eq!(s.max_depth, 4);
        s.save(&mut mem);
        assert_eq!(ViewerSettings::load(Some(&mem)), Some(s));
    }

    #[test]
    fn render_settings_match_the_scene_defaults() {
        let scene = crate::scene::builtin::load_builtin("spheres").unwrap().unwrap();
        let s = ViewerSettings::default().render_settings(&scene, scene.render.width, scene.render.height);
        assert_eq!(s, RenderSettings::for_scene(&scene));
    }
}
