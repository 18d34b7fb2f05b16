//! Camera section: the file's named cameras (a glTF's), eye, target, up,
//! projection (with the field of view, x or y, or an orthographic height),
//! thin lens, near, far, resolution scale; reset and frame-all.

use eframe::egui;
use crate::app::panels::{section, vec3_edit, Requests};
use crate::scene::camera::Projection;
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
        moved |= projection_edit(ui, cam);
        ui.horizontal(|ui| {
            let (mut deg, mut horizontal) = crate::scene::camera::control::fov_parts(cam.fov);
            ui.label("fov");
            let max = cam.projection.max_fov_deg(horizontal).min(359.0);
            let mut c = ui.add(egui::DragValue::new(&mut deg).range(1.0..=max).speed(0.2).suffix("°")).changed();
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

/// The projection's choice, an orthographic view's height and the thin
/// lens (aperture, focus distance); whether any changed. Only values the
/// camera accepts (`Camera::validate`) can be chosen: a lens is offered
/// with the perspective projection alone.
fn projection_edit(ui: &mut egui::Ui, cam: &mut Camera) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        ui.label("projection");
        let before = cam.projection;
        egui::ComboBox::from_id_salt("camera projection").selected_text(cam.projection.name()).show_ui(ui, |ui| {
            let height = 2.0 * (cam.target - cam.eye).length() * 0.577;
            for p in [Projection::Perspective, Projection::Orthographic { height: height.max(1e-3) }, Projection::Fisheye, Projection::Cylindrical] {
                ui.selectable_value(&mut cam.projection, p, p.name());
            }
        });
        if std::mem::discriminant(&before) == std::mem::discriminant(&cam.projection) {
            cam.projection = before;
        } else {
            changed = true;
            cam.aperture = 0.0;
            let (deg, horizontal) = crate::scene::camera::control::fov_parts(cam.fov);
            if deg > cam.projection.max_fov_deg(horizontal) {
                cam.fov = Fov::Y(60.0);
            }
        }
        if let Projection::Orthographic { height } = &mut cam.projection {
            ui.label("height");
            changed |= ui.add(egui::DragValue::new(height).range(1e-3..=1e6).speed(0.01)).changed();
        }
    });
    if cam.projection == Projection::Perspective {
        ui.horizontal(|ui| {
            ui.label("aperture");
            changed |= ui.add(egui::DragValue::new(&mut cam.aperture).range(0.0..=10.0).speed(0.001).max_decimals(4)).changed();
            ui.label("focus");
            changed |= ui.add(egui::DragValue::new(&mut cam.focus_distance).range(1e-3..=1e6).speed(0.01)).changed();
        });
    }
    changed
}

/// `width` x `height` times `scale`, rounded, at least one pixel each way.
pub fn scaled_size(width: u32, height: u32, scale: f32) -> (u32, u32) {
    (((width as f32 * scale).round() as u32).max(1), ((height as f32 * scale).round() as u32).max(1))
}
