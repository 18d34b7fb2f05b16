//! Materials section: per material k_L (colour picker), k_G, sharpness on a
//! logarithmic slider (the book's advice), mirror, transmission and ior.

use eframe::egui;
use crate::app::panels::{color_edit, section};
use crate::scene::Material;

pub fn show(ui: &mut egui::Ui, open: &mut bool, materials: &mut [Material]) {
    section(ui, "Materials", open, |ui| {
        for (i, m) in materials.iter_mut().enumerate() {
            ui.push_id(i, |ui| {
                egui::CollapsingHeader::new(format!("{}", m.name)).default_open(i < 3).show(ui, |ui| {
                    color_edit(ui, &format!("{} k_L", m.name), &mut m.lambertian, 1.0);
                    color_edit(ui, &format!("{} k_G", m.name), &mut m.glossy, 1.0);
                    ui.horizontal(|ui| {
                        let l = ui.label(format!("{} sharpness", m.name));
                        ui.add(egui::Slider::new(&mut m.sharpness, 1.0..=10000.0).logarithmic(true)).labelled_by(l.id);
                    });
                    color_edit(ui, &format!("{} mirror", m.name), &mut m.mirror, 1.0);
                    color_edit(ui, &format!("{} transmission", m.name), &mut m.transmission, 1.0);
                    ui.horizontal(|ui| {
                        let l = ui.label(format!("{} ior", m.name));
                        ui.add(egui::DragValue::new(&mut m.ior).range(1.0..=3.0).speed(0.01)).labelled_by(l.id);
                    });
                    if m.texture.is_some() {
                        ui.label("textured: k_L multiplies the texture");
                    }
                });
            });
        }
    });
}
