//! What the viewer remembers between runs (eframe storage): one struct,
//! `ViewerSettings`, that the viewer edits live and saves and loads whole.
//! Its render knobs are a `RenderSettings`, the very value the worker
//! renders with (at the viewer's image size), so the panels show the
//! settings in force.

use crate::render::RenderSettings;

pub const STORAGE_KEY: &str = "pinhole";

/// The user's choices that outlive a scene: renderer, render knobs, display
/// and panels. `#[serde(default)]`: settings saved by an older version load,
/// missing values taking their defaults; `load` also reads the last
/// release's layout, whose render knobs stood beside the others.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct ViewerSettings {
    /// The scene argument (built-in name or path) last opened.
    pub scene: Option<String>,
    /// Saved as an option, as older versions saved it; empty: the default.
    #[serde(with = "saved_as_option")]
    pub renderer: String,
    /// Every render knob. The image size is the scene's times `res_scale`
    /// (`PinholeApp::effective_settings`); the knobs `reset_scene_knobs`
    /// names go back to their defaults with every scene.
    pub render: RenderSettings,
    /// Image size over the scene's size.
    pub res_scale: f32,
    pub panels: Panels,
    /// Older versions' "gamma" checkbox: `false` meant no transfer curve.
    /// `load` turns it into `render.display.gamma` (the one place that
    /// setting lives now) and it is never saved again.
    #[serde(rename = "gamma", skip_serializing, deserialize_with = "saved_as_bool")]
    legacy_gamma: Option<bool>,
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
            render: RenderSettings::default(),
            res_scale: 1.0,
            panels: Panels::default(),
            legacy_gamma: None,
        }
    }
}

/// The one field that tells a saved file's layout: present since the render
/// knobs became a `RenderSettings` of their own, absent in the last
/// release's files (other fields are ignored when reading this).
#[derive(serde::Deserialize)]
struct SavedLayout {
    #[serde(default)]
    render: Present,
}

/// Whether a field was there, whatever its value.
#[derive(Default)]
struct Present(bool);

impl<'de> serde::Deserialize<'de> for Present {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Present, D::Error> {
        serde::de::IgnoredAny::deserialize(d).map(|_| Present(true))
    }
}

impl ViewerSettings {
    /// Brings loaded values into range: a renderer this build has, every
    /// render setting within the bounds the command line enforces
    /// (`settings_check`; one out of range goes back to its default), spp
    /// at most the viewer's 1024, a resolution scale in 0.1..=2. Returns one
    /// sentence per value repaired.
    pub fn sanitized(mut self, renderer_names: &[&str]) -> (ViewerSettings, Vec<String>) {
        let mut said = Vec::new();
        if !renderer_names.contains(&self.renderer.as_str()) {
            said.push(format!("saved renderer \"{}\" is not in this build; using {}", self.renderer, crate::render::DEFAULT_RAYTRACE));
            self.renderer = crate::render::DEFAULT_RAYTRACE.to_string();
        }
        let (render, repaired) = crate::render::settings_check::repaired(self.render);
        self.render = render;
        said.extend(repaired);
        self.render.spp = self.render.spp.clamp(1, 1024);
        self.res_scale = if self.res_scale.is_finite() { self.res_scale.clamp(0.1, 2.0) } else { 1.0 };
        (self, said)
    }

    /// The knobs that suit one scene (shadow-map size and bias, the
    /// rasterizers' and debugging knobs) back at their defaults: they go
    /// with the scene, not with the user.
    pub fn reset_scene_knobs(&mut self) {
        let d = RenderSettings::default();
        let r = &mut self.render;
        (r.shadow_map_size, r.shadow_map_bias, r.shadow_map_slope_bias) = (d.shadow_map_size, d.shadow_map_bias, d.shadow_map_slope_bias);
        (r.msaa, r.early_depth, r.affine, r.depth_buffer, r.lines, r.clip) = (d.msaa, d.early_depth, d.affine, d.depth_buffer, d.lines, d.clip);
        (r.near_clip, r.terminator_lift, r.cull_instances, r.adaptive) = (d.near_clip, d.terminator_lift, d.cull_instances, d.adaptive);
        r.subpixel_bits = d.subpixel_bits;
    }

    /// The render settings at `width` x `height`: these knobs, that size.
    pub fn render_settings(&self, width: u32, height: u32) -> RenderSettings {
        RenderSettings { width, height, ..self.render.clone() }
    }

    /// Takes `renderer` and every render knob of `settings` (a configuration
    /// measured elsewhere), keeping the view and the display.
    pub fn apply_configuration(&mut self, renderer: &str, settings: &RenderSettings) {
        self.renderer = renderer.to_string();
        self.render = RenderSettings { view: self.render.view, ..settings.clone() };
    }

    /// Takes `other`'s renderer and render knobs, keeping this one's view,
    /// display, panels and scene.
    pub fn take_configuration(&mut self, other: &ViewerSettings) {
        let keep = (self.scene.take(), self.render.view, self.render.display, self.res_scale, self.panels);
        *self = other.clone();
        (self.scene, self.render.view, self.render.display, self.res_scale, self.panels) = keep;
    }

    /// The settings saved in `storage`, in this layout or the last release's
    /// (its render knobs beside the others, no `render`). `None`: nothing
    /// saved, or nothing readable.
    pub fn load(storage: Option<&dyn eframe::Storage>) -> Option<ViewerSettings> {
        let storage = storage?;
        let mut settings: ViewerSettings = eframe::get_value(storage, STORAGE_KEY)?;
        if !eframe::get_value::<SavedLayout>(storage, STORAGE_KEY)?.render.0 {
            // The same text read as a `RenderSettings`: it takes the knobs
            // it has a field for and ignores the rest.
            settings.render = eframe::get_value(storage, STORAGE_KEY)?;
        }
        if settings.legacy_gamma.take() == Some(false) {
            settings.render.display.gamma = crate::display::Gamma::Off;
        }
        Some(settings)
    }

    pub fn save(&self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, STORAGE_KEY, self);
    }
}

/// The old checkbox, saved as a plain `bool`.
fn saved_as_bool<'de, D: serde::Deserializer<'de>>(de: D) -> Result<Option<bool>, D::Error> {
    <bool as serde::Deserialize>::deserialize(de).map(Some)
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
    use crate::render::ShadowMode;

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
        assert_eq!((s.render.spp, s.render.shadows, s.render.display.gamma), (9, ShadowMode::Map, crate::display::Gamma::Off));
        assert_eq!(s.render.max_depth, 4);
        s.save(&mut mem);
        assert_eq!(ViewerSettings::load(Some(&mem)), Some(s));
    }

    #[test]
    fn render_settings_match_the_scene_defaults() {
        let scene = crate::scene::builtin::load_builtin("spheres").unwrap().unwrap();
        let s = ViewerSettings::default().render_settings(scene.render.width, scene.render.height);
        assert_eq!(s, RenderSettings::for_scene(&scene));
    }
}
