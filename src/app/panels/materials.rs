//! Materials section: per material k_L (colour picker), k_G, sharpness on a
//! logarithmic slider (the book's advice), mirror, transmission, ior and
//! emission (a colour and a strength: an emissive material is an area light).

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
                    emission_edit(ui, m);
                    if m.texture.is_some() {
                        ui.label("textured: k_L multiplies the texture");
                    }
                });
            });
        }
    });
}

/// Emission as a colour (its largest channel 1) times a strength, the two
/// things a person sets for a lamp; stored as their product, the radiance.
fn emission_edit(ui: &mut egui::Ui, m: &mut Material) {
    let mut strength = m.emission.max_element();
    let mut colour = if strength > 0.0 { m.emission / strength } else { crate::math::Vec3::ONE };
    let mut changed = color_edit(ui, &format!("{} emission colour", m.name), &mut colour, 1.0);
    ui.horizontal(|ui| {
        let l = ui.label(format!("{} emission strength", m.name));
        changed |= ui.add(egui::Slider::new(&mut strength, 0.0..=1000.0).logarithmic(true).smallest_positive(0.01)).labelled_by(l.id).changed();
    });
    if changed {
        m.emission = colour * strength;
    }
}
