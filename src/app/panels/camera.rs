//! Camera section: the file's named cameras (a glTF's), eye, target, up,
//! field of view (x or y), near, far, resolution scale; reset and frame-all.

use eframe::egui;
use crate::app::panels::{section, vec3_edit, Requests};
use crate::scene::{Camera, Fov};

/// `scene_size`: the scene's image size, which `res_scale` scales;
/// `named`: the cameras the scene's file offers, each a button that looks
/// through it.
pub fn show(ui: &mut egui::Ui, open: &mut bool, cam: &mut Camera, res_scale: &mut f32, scene_size: (u32, u32), named: &[(String, Camera)]) -> Requests {
    let mut requests = Requests::default();
    section(ui, "Camera", open, |ui| {
        let mut moved = false;
        if !named.is_empty() {
            ui.horizontal_wrapped(|ui| {
                ui.label("look through");
                for (name, c) in named {
                    if ui.selectable_label(cam == c, name).clicked() {
                        *cam = c.clone();
                        moved = true;
                    }
                }
            });
        }
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
            ui.add(egui::Slider::new(res_scale, 0.1..=2.0).step_by(0.05).suffix("×"));
        });
        let (width, height) = scaled_size(scene_size.0, scene_size.1, *res_scale);
        ui.label(format!("image {width}x{height}"));
        ui.horizontal(|ui| {
            requests.reset_camera = ui.button("Reset (Home)").clicked();
            requests.frame_all = ui.button("Frame all (F)").clicked();
        });
        requests.camera_moved = moved;
        ui.label(egui::RichText::new("orbit: left drag · pan: middle or shift drag · dolly: wheel · fly: WASD/QE").small());
    });
    requests
}

/// `width` x `height` times `scale`, rounded, at least one pixel each way.
pub fn scaled_size(width: u32, height: u32, scale: f32) -> (u32, u32) {
    (((width as f32 * scale).round() as u32).max(1), ((height as f32 * scale).round() as u32).max(1))
}
