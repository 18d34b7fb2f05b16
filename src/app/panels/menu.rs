//! The top bar: File (open, built-in scenes, reload, export), View (panels,
//! debug view), the renderer and debug-view combo boxes, zoom and the
//! vertex overlay.

use eframe::egui;
use crate::app::PinholeApp;
use crate::render::debug::View;
use crate::scene::builtin;

pub fn show(app: &mut PinholeApp, ui: &mut egui::Ui) {
    egui::Panel::top("menu-bar").show(ui, |ui| {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open… (Ctrl+O)").clicked() {
                    app.open_dialog.open = true;
                    ui.close();
                }
                ui.menu_button("Built-in scenes", |ui| {
                    for name in builtin::names() {
                        if ui.button(name).clicked() {
                            app.open(name.to_string());
                            ui.close();
                        }
                    }
                });
                if ui.button("Reload").clicked() {
                    let arg = app.scene_arg.clone();
                    app.open(arg);
                    ui.close();
                }
                ui.separator();
                if ui.button("Export image… (Ctrl+S)").clicked() {
                    app.export.open_with(&app.scene.name, &app.renderer);
                    ui.close();
                }
                ui.separator();
                if ui.button("Quit").clicked() {
                    ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
                }
            });
            ui.menu_button("View", |ui| {
                ui.checkbox(&mut app.panels.side, "Side panel");
                ui.separator();
                for v in View::ALL {
                    ui.radio_value(&mut app.settings.view, v, v.name());
                }
            });
            ui.separator();
            renderer_combo(app, ui);
            view_combo(app, ui);
            ui.separator();
            zoom_controls(app, ui);
            ui.checkbox(&mut app.inspect.vertices, "vertices")
                .on_hover_text("every projected triangle vertex as a dot (CGPP 15.6.2)");
            ui.separator();
            ui.label(format!("scene: {}", app.scene.name));
        });
    });
}

/// Every debug view (`View::ALL`, so views the core adds appear here); V and
/// shift+V step through them.
pub fn view_combo(app: &mut PinholeApp, ui: &mut egui::Ui) {
    egui::ComboBox::from_label("debug view").selected_text(app.settings.view.name()).height(800.0).show_ui(ui, |ui| {
        for v in View::ALL {
            ui.selectable_value(&mut app.settings.view, v, v.name());
        }
    })
    .response
    .on_hover_text("V / shift+V: next / previous view");
}

/// Image zoom (also ctrl+wheel over the image; right drag pans when zoomed).
fn zoom_controls(app: &mut PinholeApp, ui: &mut egui::Ui) {
    let l = ui.label("zoom");
    let mut z = app.inspect.zoom;
    let r = ui.add(egui::DragValue::new(&mut z).range(1.0..=crate::app::inspect::MAX_ZOOM).speed(0.05).suffix("×").max_decimals(1)).labelled_by(l.id);
    if r.changed() {
        app.inspect.zoom_about(z, egui::Vec2::ZERO);
    }
    r.on_hover_text("ctrl+wheel over the image zooms about the cursor; right drag pans");
    if ui.add_enabled(app.inspect.zoom != 1.0, egui::Button::new("fit")).clicked() {
        app.inspect.zoom_about(1.0, egui::Vec2::ZERO);
    }
}

/// Every registered renderer; number keys 1..9 pick the same list.
pub fn renderer_combo(app: &mut PinholeApp, ui: &mut egui::Ui) {
    egui::ComboBox::from_label("Renderer").selected_text(app.renderer.clone()).show_ui(ui, |ui| {
        for (i, name) in app.renderer_names.clone().into_iter().enumerate() {
            ui.selectable_value(&mut app.renderer, name.to_string(), name)
                .on_hover_text(format!("key {}", i + 1));
        }
    });
}
