//! The top bar: File (open, built-in scenes, reload, export), View (panels,
//! debug view), the Compare window, Gallery (the stress cases: a failure and its cure), the renderer and debug-view combo boxes, zoom and the
//! vertex overlay.

use eframe::egui;
use crate::app::panels::Requests;
use crate::app::inspect::Inspect;
use crate::app::settings_store::ViewerSettings;
use crate::render::inspect::debug::View;
use crate::scene::builtin;

/// `settings`: panels, view and renderer; `inspect`: zoom and the vertex overlay.
pub fn show(ui: &mut egui::Ui, settings: &mut ViewerSettings, renderer_names: &[&'static str], inspect: &mut Inspect, scene_name: &str) -> Requests {
    let mut requests = Requests::default();
    egui::Panel::top("menu-bar").show(ui, |ui| {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open… (Ctrl+O)").clicked() {
                    requests.open_dialog = true;
                    ui.close();
                }
                ui.menu_button("Built-in scenes", |ui| {
                    for name in builtin::names() {
                        if ui.button(name).clicked() {
                            requests.open = Some(name.to_string());
                            ui.close();
                        }
                    }
                });
                if ui.button("Reload").clicked() {
                    requests.reload = true;
                    ui.close();
                }
                ui.separator();
                if ui.button("Export image… (Ctrl+S)").clicked() {
                    requests.export = true;
                    ui.close();
                }
                ui.separator();
                if ui.button("Quit").clicked() {
                    requests.quit = true;
                }
            });
            ui.menu_button("View", |ui| {
                ui.checkbox(&mut settings.panels.side, "Side panel");
                ui.separator();
                for v in View::ALL {
                    ui.radio_value(&mut settings.render.view, v, v.name());
                }
            });
            if ui.button("Compare").on_hover_text("C: error against time of every method, against a reference").clicked() {
                requests.toggle_compare = true;
            }
            ui.menu_button("Gallery", |ui| {
                for case in crate::gallery::cases() {
                    if ui.button(case.name).on_hover_text(case.explanation).clicked() {
                        requests.gallery_case = Some(case.name);
                        ui.close();
                    }
                }
            });
            ui.separator();
            renderer_combo(ui, &mut settings.renderer, renderer_names);
            view_combo(ui, &mut settings.render.view);
            ui.separator();
            zoom_controls(ui, inspect);
            ui.checkbox(&mut inspect.vertices, "vertices")
                .on_hover_text("every projected triangle vertex as a dot (CGPP 15.6.2)");
            ui.separator();
            ui.label(format!("scene: {scene_name}"));
        });
    });
    requests
}

/// Every debug view (`View::ALL`, so views the core adds appear here); V and
/// shift+V step through them.
pub fn view_combo(ui: &mut egui::Ui, view: &mut View) {
    egui::ComboBox::from_label("debug view").selected_text(view.name()).height(800.0).show_ui(ui, |ui| {
        for v in View::ALL {
            ui.selectable_value(view, v, v.name());
        }
    })
    .response
    .on_hover_text("V / shift+V: next / previous view");
}

/// Image zoom (also ctrl+wheel over the image; right drag pans when zoomed).
fn zoom_controls(ui: &mut egui::Ui, inspect: &mut Inspect) {
    let l = ui.label("zoom");
    let mut z = inspect.zoom;
    let r = ui.add(egui::DragValue::new(&mut z).range(1.0..=crate::app::inspect::MAX_ZOOM).speed(0.05).suffix("×").max_decimals(1)).labelled_by(l.id);
    if r.changed() {
        inspect.zoom_about(z, egui::Vec2::ZERO);
    }
    r.on_hover_text("ctrl+wheel over the image zooms about the cursor; right drag pans");
    if ui.add_enabled(inspect.zoom != 1.0, egui::Button::new("fit")).clicked() {
        inspect.zoom_about(1.0, egui::Vec2::ZERO);
    }
}

/// Every registered renderer; number keys 1..9 pick the same list.
pub fn renderer_combo(ui: &mut egui::Ui, renderer: &mut String, renderer_names: &[&'static str]) {
    egui::ComboBox::from_label("Renderer").selected_text(renderer.clone()).show_ui(ui, |ui| {
        for (i, name) in renderer_names.iter().enumerate() {
            ui.selectable_value(renderer, name.to_string(), *name)
                .on_hover_text(format!("key {}", i + 1));
        }
    });
}
