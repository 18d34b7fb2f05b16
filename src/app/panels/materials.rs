//! Materials section: per material k_L (colour picker) with the diffuse
//! model and its parameter, k_G with the glossy model and its parameters
//! (sharpness on a logarithmic slider, the book's advice; roughness; Ward's
//! two alphas) and the Fresnel term, mirror, transmission, ior and emission
//! (a colour and a strength: an emissive material is an area light), and
//! a polar plot of the lobe with its directional albedo (`bsdf_plot`).

use eframe::egui;
use crate::app::panels::{color_edit, section};
use crate::scene::material::{DiffuseModel, Fresnel, GlossyModel, MIN_ROUGHNESS};
use crate::scene::Material;

pub fn show(ui: &mut egui::Ui, open: &mut bool, materials: &mut [Material]) {
    section(ui, "Materials", open, |ui| {
        for (i, m) in materials.iter_mut().enumerate() {
            ui.push_id(i, |ui| {
                egui::CollapsingHeader::new(format!("{}", m.name)).default_open(i < 3).show(ui, |ui| {
                    color_edit(ui, &format!("{} k_L", m.name), &mut m.lambertian, 1.0);
                    diffuse_edit(ui, m);
                    color_edit(ui, &format!("{} k_G", m.name), &mut m.glossy, 1.0);
                    glossy_edit(ui, m);
                    fresnel_edit(ui, m);
                    color_edit(ui, &format!("{} mirror", m.name), &mut m.mirror, 1.0);
                    color_edit(ui, &format!("{} transmission", m.name), &mut m.transmission, 1.0);
                    ui.horizontal(|ui| {
                        let l = ui.label(format!("{} ior", m.name));
                        ui.add(egui::DragValue::new(&mut m.ior).range(1.0..=3.0).speed(0.01)).labelled_by(l.id);
                    });
                    emission_edit(ui, m);
                    crate::app::panels::bsdf_plot::show(ui, m);
                    if m.texture.is_some() {
                        ui.label("textured: k_L multiplies the texture");
                    }
                });
            });
        }
    });
}

/// A labelled slider over `range` for one lobe parameter.
fn parameter(ui: &mut egui::Ui, label: String, value: &mut f32, range: std::ops::RangeInclusive<f32>, logarithmic: bool) {
    ui.horizontal(|ui| {
        let l = ui.label(label);
        ui.add(egui::Slider::new(value, range).logarithmic(logarithmic)).labelled_by(l.id);
    });
}

/// A combo box labelled `label` choosing among `names`; the index chosen.
fn model_choice(ui: &mut egui::Ui, label: String, current: usize, names: &[&str]) -> usize {
    let mut chosen = current;
    egui::ComboBox::from_label(label).selected_text(names[current]).show_ui(ui, |ui| {
        for (i, name) in names.iter().enumerate() {
            ui.selectable_value(&mut chosen, i, *name);
        }
    });
    chosen
}

/// The diffuse model (Lambert, Oren-Nayar, Minnaert, toon) and its parameter.
fn diffuse_edit(ui: &mut egui::Ui, m: &mut Material) {
    let current = DiffuseModel::NAMES.iter().position(|n| *n == m.diffuse_model.name()).unwrap_or(0);
    let chosen = model_choice(ui, format!("{} diffuse model", m.name), current, &DiffuseModel::NAMES);
    if chosen != current {
        m.diffuse_model = match chosen {
            1 => DiffuseModel::OrenNayar { sigma: 0.3 },
            2 => DiffuseModel::Minnaert { darkening: 0.7 },
            3 => DiffuseModel::Toon { bands: 3 },
            _ => DiffuseModel::Lambert,
        };
    }
    match &mut m.diffuse_model {
        DiffuseModel::Lambert => {}
        DiffuseModel::OrenNayar { sigma } => parameter(ui, format!("{} sigma", m.name), sigma, 0.0..=std::f32::consts::FRAC_PI_2, false),
        DiffuseModel::Minnaert { darkening } => parameter(ui, format!("{} darkening", m.name), darkening, 0.0..=1.0, false),
        DiffuseModel::Toon { bands } => {
            ui.horizontal(|ui| {
                let l = ui.label(format!("{} bands", m.name));
                ui.add(egui::Slider::new(bands, 1..=16)).labelled_by(l.id);
            });
        }
    }
}

/// The glossy model and the parameters it reads.
fn glossy_edit(ui: &mut egui::Ui, m: &mut Material) {
    let names: Vec<&str> = GlossyModel::NAMES.iter().map(|(n, _)| *n).collect();
    let current = GlossyModel::NAMES.iter().position(|(_, g)| *g == m.glossy_model).unwrap_or(0);
    let chosen = model_choice(ui, format!("{} glossy model", m.name), current, &names);
    m.glossy_model = GlossyModel::NAMES[chosen].1;
    match m.glossy_model {
        GlossyModel::BlinnPhong | GlossyModel::Phong => parameter(ui, format!("{} sharpness", m.name), &mut m.sharpness, 1.0..=10000.0, true),
        GlossyModel::Ggx | GlossyModel::Beckmann => parameter(ui, format!("{} roughness", m.name), &mut m.roughness, MIN_ROUGHNESS..=1.0, true),
        GlossyModel::Ward => {
            parameter(ui, format!("{} roughness u", m.name), &mut m.roughness_uv.x, MIN_ROUGHNESS..=1.0, true);
            parameter(ui, format!("{} roughness v", m.name), &mut m.roughness_uv.y, MIN_ROUGHNESS..=1.0, true);
        }
    }
}

/// The glossy lobe's Fresnel term, with a conductor's eta and k.
fn fresnel_edit(ui: &mut egui::Ui, m: &mut Material) {
    let current = Fresnel::NAMES.iter().position(|n| *n == m.fresnel.name()).unwrap_or(0);
    let chosen = model_choice(ui, format!("{} fresnel", m.name), current, &Fresnel::NAMES);
    if chosen != current {
        // A new conductor starts as gold (its eta and k at R, G, B).
        m.fresnel = match chosen {
            1 => Fresnel::Schlick,
            2 => Fresnel::Conductor { eta: crate::math::Vec3::new(0.18, 0.42, 1.37), k: crate::math::Vec3::new(3.42, 2.35, 1.77) },
            _ => Fresnel::None,
        };
    }
    if let Fresnel::Conductor { eta, k } = &mut m.fresnel {
        color_edit(ui, &format!("{} eta", m.name), eta, 5.0);
        color_edit(ui, &format!("{} k", m.name), k, 10.0);
    }
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
