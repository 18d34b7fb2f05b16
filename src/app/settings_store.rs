//! What the viewer remembers between runs (eframe storage): last scene,
//! renderer, render settings, display settings and which panels are open.

use crate::render::RenderSettings;

pub const STORAGE_KEY: &str = "pinhole";

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Persisted {
    /// The scene argument (built-in name or path) last opened.
    pub scene: Option<String>,
    pub renderer: Option<String>,
    pub spp: u32,
    pub shadows: crate::render::ShadowMode,
    pub shadow_bump: f32,
    pub max_depth: u32,
    pub view: crate::render::debug::View,
    pub interpolation: crate::render::Interpolation,
    pub res_scale: f32,
    pub gamma: bool,
    pub panels: Panels,
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

impl Default for Persisted {
    fn default() -> Self {
        Persisted {
            scene: None,
            renderer: None,
            spp: 1,
            shadows: crate::render::ShadowMode::Ray,
            shadow_bump: 1e-4,
            max_depth: 4,
            view: crate::render::debug::View::Shaded,
            interpolation: crate::render::Interpolation::Phong,
            res_scale: 1.0,
            gamma: true,
            panels: Panels::default(),
        }
    }
}

impl Persisted {
    /// Applies the remembered knobs to settings made for a scene.
    pub fn apply_to(&self, s: &mut RenderSettings) {
        s.spp = self.spp.clamp(1, 1024);
        s.shadows = self.shadows;
        s.shadow_bump = self.shadow_bump;
        s.max_depth = self.max_depth;
        s.view = self.view;
        s.interpolation = self.interpolation;
    }

    pub fn load(storage: Option<&dyn eframe::Storage>) -> Option<Persisted> {
        storage.and_then(|s| eframe::get_value(s, STORAGE_KEY))
    }

    pub fn save(&self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, STORAGE_KEY, self);
    }
}
