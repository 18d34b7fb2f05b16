//! Camera section: eye, target, up, field of view (x or y), near, far,
//! resolution scale; reset and frame-all.

use eframe::egui;
use super::{section, vec3_edit};
use crate::app::PinholeApp;
use crate::scene::Fov;

pub fn show(app: &mut PinholeApp, ui: &mut egui::Ui) {
    let mut open = app.panels.camera;
    section(ui, "Camera", &mut open, |ui| {
        let cam = &mut app.params.camera;
        let mut moved = false;
        moved |= vec3_edit(ui, "eye", &mut cam.eye, 0.01);
        moved |= vec3_edit(ui, "target", &mut cam.target, 0.01);
        vec3_edit(ui, "up", &mut cam.up, 0.01);
        ui.horizontal(|ui| {
            let (mut deg, mut horizontal) = crate::scene::camera::control::fov_parts(cam.fov);
            ui.label("fov");
            let mut c = ui.add(egui::DragValue::new(&mut deg).range(1.0..=179.0).speed(0.2).suffix("°")).changed();
            c |= ui.radio_value(&mut horizontal, false, "y").changed();
            c |= ui.radio_value(&mut horizontal, true, "x").changed();
            if c {
                cam.fov = if horizontal { Fov::X(deg) } else { Fov::Y(deg) };
            }
        });
        ui.horizontal(|ui| {
            ui.label("near");
            let far = cam.far;
            ui.add(egui::DragValue::new(&mut cam.near).range(1e-4..=far * 0.999).speed(0.001).max_decimals(4));
            ui.label("far");
            let near = cam.near;
            ui.add(egui::DragValue::new(&mut cam.far).range(near * 1.001..=1e6).speed(0.1));
        });
        ui.horizontal(|ui| {
            ui.label("resolution");
            ui.add(egui::Slider::new(&mut app.res_scale, 0.1..=2.0).step_by(0.05).suffix("×"));
        });
        let s = app.effective_settings();
        ui.label(format!("image {}x{}", s.width, s.height));
        ui.horizontal(|ui| {
            if ui.button("Reset (Home)").clicked() {
                app.reset_camera();
            }
            if ui.button("Frame all (F)").clicked() {
                app.frame_all();
            }
        });
        if moved {
            app.camera_moving = true;
        }
        ui.label(egui::RichText::new("orbit: left drag · pan: middle or shift drag · dolly: wheel · fly: WASD/QE").small());
    });
    app.panels.camera = open;
}
