//! A small in-app "Open scene" dialog: a path field and a listing of the
//! current directory (folders, .toml and .obj files), built on std::fs.

use eframe::egui;
use std::path::{Path, PathBuf};

pub struct OpenDialog {
    pub open: bool,
    pub dir: PathBuf,
    pub path: String,
}

impl OpenDialog {
    pub fn new() -> OpenDialog {
        let dir = std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."));
        OpenDialog { open: false, path: String::new(), dir }
    }

    /// Draws the dialog; returns the file the user chose.
    pub fn show(&mut self, ctx: &egui::Context) -> Option<String> {
        if !self.open {
            return None;
        }
        let mut chosen = None;
        let mut open = true;
        egui::Window::new("Open scene").open(&mut open).collapsible(false).default_size([460.0, 400.0]).show(ctx, |ui| {
            ui.horizontal(|ui| {
                let l = ui.label("path");
                let r = ui.add(egui::TextEdit::singleline(&mut self.path).desired_width(300.0)).labelled_by(l.id);
                let enter = r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                if (ui.button("Open").clicked() || enter) && !self.path.is_empty() {
                    let p = PathBuf::from(&self.path);
                    if p.is_dir() {
                        self.dir = p;
                    } else {
                        chosen = Some(self.path.clone());
                    }
                }
            });
            ui.horizontal(|ui| {
                if ui.button("Up").clicked() {
                    if let Some(parent) = self.dir.parent() {
                        self.dir = parent.to_path_buf();
                    }
                }
                ui.label(self.dir.display().to_string());
            });
            ui.separator();
            egui::ScrollArea::vertical().max_height(300.0).show(ui, |ui| match list_dir(&self.dir) {
                Ok(entries) => {
                    for (path, is_dir) in entries {
                        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                        let label = if is_dir { format!("{name}/") } else { name };
                        let r = ui.selectable_label(self.path == path.to_string_lossy(), label);
                        if r.clicked() {
                            self.path = path.to_string_lossy().into_owned();
                        }
                        if r.double_clicked() || (r.clicked() && is_dir) {
                            if is_dir {
                                self.dir = path.clone();
                            } else {
                                chosen = Some(path.to_string_lossy().into_owned());
                            }
                        }
                    }
                }
                Err(e) => {
                    ui.colored_label(egui::Color32::LIGHT_RED, e);
                }
            });
        });
        if chosen.is_some() {
            open = false;
        }
        self.open = open;
        chosen
    }
}

impl Default for OpenDialog {
    fn default() -> Self {
        Self::new()
    }
}

/// Folders first, then scene, mesh and glTF files (.toml, .obj, .ply, .gltf, .glb), each sorted by name; hidden entries skipped.
pub fn list_dir(dir: &Path) -> Result<Vec<(PathBuf, bool)>, String> {
    let rd = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut out: Vec<(PathBuf, bool)> = rd
        .filter_map(|e| e.ok())
        .map(|e| (e.path(), e.path().is_dir()))
        .filter(|(p, is_dir)| {
            let hidden = p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.'));
            let ext = p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
            !hidden && (*is_dir || matches!(ext.as_deref(), Some("toml" | "obj" | "ply" | "gltf" | "glb")))
        })
        .collect();
    out.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    Ok(out)
}
