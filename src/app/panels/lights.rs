//! Lights section: list, add and remove point and directional lights; edit
//! position or direction, and power or irradiance as colour times strength.

use eframe::egui;
use crate::app::panels::{color_edit, section, vec3_edit};
use crate::math::Vec3;
use crate::scene::{Camera, Light, Scene};

/// `camera` places new point lights; `scene`'s size sets their distance and power.
pub fn show(ui: &mut egui::Ui, open: &mut bool, lights: &mut Vec<Light>, camera: &Camera, scene: &Scene) {
    section(ui, "Lights", open, |ui| {
        let mut remove = None;
        for (i, light) in lights.iter_mut().enumerate() {
            ui.push_id(i, |ui| {
                ui.horizontal(|ui| {
                    let kind = match light {
                        Light::Point { .. } => "point",
                        Light::Directional { .. } => "directional",
                    };
                    ui.strong(format!("L{i} {kind}"));
                    if ui.small_button("remove").clicked() {
                        remove = Some(i);
                    }
                });
                match light {
                    Light::Point { position, power } => {
                        vec3_edit(ui, &format!("L{i} position"), position, 0.01);
                        strength_edit(ui, &format!("L{i} power"), power, "W");
                    }
                    Light::Directional { direction, irradiance } => {
                        if vec3_edit(ui, &format!("L{i} direction"), direction, 0.01) && direction.length_squared() < 1e-12 {
                            *direction = Vec3::NEG_Y;
                        }
                        strength_edit(ui, &format!("L{i} irradiance"), irradiance, "W/m²");
                    }
                }
                ui.separator();
            });
        }
        if let Some(i) = remove {
            lights.remove(i);
        }
        ui.horizontal(|ui| {
            let scale = crate::scene::camera::control::scene_scale(scene.bounds());
            if ui.button("+ point").clicked() {
                let c = camera;
                // Above and behind the camera, lighting what it sees.
                let position = c.eye + (c.up.normalize_or(Vec3::Y) * 0.5 - (c.target - c.eye).normalize_or(Vec3::NEG_Z) * 0.2) * scale;
                lights.push(Light::Point { position, power: Vec3::splat(10.0 * scale * scale) });
            }
            if ui.button("+ directional").clicked() {
                lights.push(Light::Directional { direction: Vec3::new(-1.0, -4.0, -4.0).normalize(), irradiance: Vec3::ONE });
            }
        });
    });
}

/// A light quantity as colour (max channel 1) times strength.
fn strength_edit(ui: &mut egui::Ui, label: &str, value: &mut Vec3, unit: &str) {
    let strength = value.max_element().max(0.0);
    let mut color = if strength > 0.0 { *value / strength } else { Vec3::ONE };
    let mut s = strength;
    let mut changed = color_edit(ui, &format!("{label} colour"), &mut color, 1.0);
    ui.horizontal(|ui| {
        let l = ui.label(format!("{label}"));
        changed |= ui
            .add(egui::DragValue::new(&mut s).range(0.0..=1e6).speed((strength * 0.01).max(0.01)).suffix(format!(" {unit}")))
            .labelled_by(l.id)
            .changed();
    });
    if changed {
        *value = color * s;
    }
}
