//! The top bar: File (open, built-in scenes, reload, export), View (panels,
//! debug view) and the renderer combo box.

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
            ui.label(format!("scene: {}", app.scene.name));
        });
    });
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
