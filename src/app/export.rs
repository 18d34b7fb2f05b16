//! Export of the current view (debug views included): PNG exactly as
//! displayed, or EXR with the linear radiance; a suggested name of scene,
//! renderer and time; files are written atomically.

use eframe::egui;
use crate::app::worker::Output;
use crate::image_io;
use std::path::{Path, PathBuf};

#[derive(Default)]
pub struct ExportDialog {
    pub open: bool,
    /// The full path; its extension picks the format.
    pub path: String,
    pub last_error: Option<String>,
}

impl ExportDialog {
    pub fn open_with(&mut self, scene: &str, renderer: &str) {
        let dir = std::env::current_dir().unwrap_or_default();
        self.path = dir.join(format!("{}.png", suggested_stem(scene, renderer, std::time::SystemTime::now()))).to_string_lossy().into_owned();
        self.last_error = None;
        self.open = true;
    }

    /// Takes the outcome of a save the window asked for: closes the window
    /// and returns the note for the status bar, or keeps it open with the error.
    pub fn finish(&mut self, result: Result<String, String>) -> Option<String> {
        match result {
            Ok(note) => {
                self.last_error = None;
                self.open = false;
                Some(note)
            }
            Err(e) => {
                self.last_error = Some(e);
                None
            }
        }
    }
}

/// `scene-renderer-YYYYMMDD-HHMMSS` (UTC), safe as a file name.
pub fn suggested_stem(scene: &str, renderer: &str, time: std::time::SystemTime) -> String {
    let secs = time.duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    let (days, rem) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days as i64);
    let clean = |s: &str| s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect::<String>();
    format!(
        "{}-{}-{y:04}{m:02}{d:02}-{:02}{:02}{:02}",
        clean(scene),
        clean(renderer),
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}

/// Days since 1970-01-01 to (year, month, day) (H. Hinnant's algorithm).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

/// Writes `o`, the image on show: `.png` as displayed (exposure, gamma
/// setting, debug view), `.exr` linear. Returns a note for the status bar.
pub fn export(o: &Output, path: &Path) -> Result<String, String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    if o.width == 0 {
        return Err("nothing rendered yet".to_string());
    }
    // Never over a scene, mesh or texture this session has read.
    crate::file_identity::check_outputs(&[path])?;
    match ext.as_str() {
        "png" => image_io::write_atomic(path, &image_io::encode_png(o.width, o.height, &o.rgb8)?)?,
        "exr" => image_io::save_image(path, o.width, o.height, &o.linear, 1.0)?,
        _ => return Err(format!("{}: choose a .png or .exr name", path.display())),
    }
    Ok(format!("saved {} ({}/{} spp)", path.display(), o.passes, o.spp))
}

/// The export window: path (suggested), PNG or EXR, Save. Edits the
/// dialog's own path; returns the file a Save button asks to write (the
/// viewer writes it and hands the outcome to `ExportDialog::finish`).
pub fn show_dialog(ctx: &egui::Context, dialog: &mut ExportDialog) -> Option<PathBuf> {
    if !dialog.open {
        return None;
    }
    let mut open = true;
    let mut save = None;
    egui::Window::new("Export image").open(&mut open).collapsible(false).show(ctx, |ui| {
        ui.horizontal(|ui| {
            let l = ui.label("file");
            ui.add(egui::TextEdit::singleline(&mut dialog.path).desired_width(380.0)).labelled_by(l.id);
        });
        ui.horizontal(|ui| {
            let p = PathBuf::from(&dialog.path);
            if ui.button("Save PNG (as displayed)").clicked() {
                save = Some(p.with_extension("png"));
            }
            if ui.button("Save EXR (linear)").clicked() {
                save = Some(p.with_extension("exr"));
            }
        });
        if let Some(e) = &dialog.last_error {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
        }
    });
    dialog.open &= open;
    save
}

#[cfg(test)]
mod tests {
    #[test]
    fn stem_names_scene_renderer_and_time() {
        let t = std::time::UNIX_EPOCH + std::time::Duration::from_secs(1_700_000_000);
        assert_eq!(super::suggested_stem("teapot", "raytrace:bvh", t), "teapot-raytrace_bvh-20231114-221320");
    }
}
