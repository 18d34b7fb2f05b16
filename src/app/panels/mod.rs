//! The viewer's panels: the menu bar, the status bar and the side-panel
//! sections (camera, lights, materials, shading) and the pixel inspector,
//! one file each. Each gets only the values it reads and, mutably, those it
//! edits; what the menu and the side-panel sections ask of the viewer beyond
//! that comes back as `Requests`, which `PinholeApp::apply` carries out once
//! per frame. The status bar and the inspector ask nothing more.

use eframe::egui;
pub mod bsdf_plot;
pub mod camera;
pub mod compare;
pub mod inspector;
pub mod lights;
pub mod materials;
pub mod menu;
pub mod shading;
pub mod split_bar;
pub mod status;

use crate::math::Vec3;

/// What panels ask the viewer to do this frame, beyond editing their values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Requests {
    /// The camera was edited: render a quick preview first.
    pub camera_moved: bool,
    pub reset_camera: bool,
    pub frame_all: bool,
    /// Load this scene (built-in name or path).
    pub open: Option<String>,
    /// Load the current scene again.
    pub reload: bool,
    pub open_dialog: bool,
    pub export: bool,
    /// Open or close the Compare window.
    pub toggle_compare: bool,
    pub quit: bool,
    /// Open this stress-gallery case with its failing setting.
    pub gallery_case: Option<&'static str>,
}

impl std::ops::BitOrAssign for Requests {
    fn bitor_assign(&mut self, o: Requests) {
        self.camera_moved |= o.camera_moved;
        self.reset_camera |= o.reset_camera;
        self.frame_all |= o.frame_all;
        self.open = o.open.or(self.open.take());
        self.reload |= o.reload;
        self.open_dialog |= o.open_dialog;
        self.export |= o.export;
        self.toggle_compare |= o.toggle_compare;
        self.quit |= o.quit;
        self.gallery_case = o.gallery_case.or(self.gallery_case.take());
    }
}

/// Three labelled drag values for a vector; true when one changed.
pub fn vec3_edit(ui: &mut egui::Ui, label: &str, v: &mut Vec3, speed: f32) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        ui.label(label);
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            changed |= ui
                .add(egui::DragValue::new(&mut v[i]).speed(speed).prefix(format!("{axis} ")).max_decimals(4))
                .accessible_name(format!("{label} {axis}"))
                .changed();
        }
    });
    changed
}

/// A linear colour: picker plus R, G, B drag values (exact numbers matter).
pub fn color_edit(ui: &mut egui::Ui, label: &str, c: &mut Vec3, max: f32) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        ui.label(label);
        let mut rgb = c.to_array();
        if max <= 1.0 {
            if ui.color_edit_button_rgb(&mut rgb).accessible_name(label).changed() {
                *c = Vec3::from_array(rgb);
                changed = true;
            }
        }
        for (i, ch) in ["R", "G", "B"].iter().enumerate() {
            changed |= ui
                .add(egui::DragValue::new(&mut c[i]).speed(0.005 * max).range(0.0..=max).prefix(format!("{ch} ")).max_decimals(3))
                .accessible_name(format!("{label} {ch}"))
                .changed();
        }
    });
    changed
}

/// A collapsing section whose open state lives in `open` (so it persists).
pub fn section(ui: &mut egui::Ui, title: &str, open: &mut bool, body: impl FnOnce(&mut egui::Ui)) {
    let r = egui::CollapsingHeader::new(egui::RichText::new(title).strong()).open(Some(*open)).show(ui, body);
    if r.header_response.clicked() {
        *open = !*open;
    }
}
