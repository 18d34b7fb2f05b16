//! The A|B bar, shown while two configurations are side by side: what A and
//! B are, wipe or difference, swap, and the error of B against A over the
//! whole view and over the dragged rectangle.

use crate::app::split_view::{SplitMode, SplitView};
use eframe::egui;

/// What the bar asks of the viewer.
#[derive(Default)]
pub struct SplitRequests {
    pub swap: bool,
    /// B takes the live view's configuration.
    pub b_from_a: bool,
    pub close: bool,
}

pub fn show(ui: &mut egui::Ui, split: &mut SplitView, a_label: &str, b_label: &str) -> SplitRequests {
    let mut req = SplitRequests::default();
    egui::Panel::top("split-bar").show(ui, |ui| {
        ui.horizontal_wrapped(|ui| {
            ui.strong("A");
            ui.label(a_label);
            ui.separator();
            ui.strong("B");
            ui.label(b_label);
            ui.separator();
            ui.radio_value(&mut split.mode, SplitMode::Wipe, "wipe").on_hover_text("drag the divider on the image");
            ui.radio_value(&mut split.mode, SplitMode::Difference, "difference").on_hover_text("B against A: red where B is brighter, blue where darker");
            if ui.button("swap (X)").clicked() {
                req.swap = true;
            }
            if ui.button("B = A").on_hover_text("B takes the live view's configuration; then change A").clicked() {
                req.b_from_a = true;
            }
            ui.separator();
            match split.error {
                Some(e) => {
                    ui.label(format!("rmse/mean {:.4}", e.whole)).on_hover_text("B against A over the whole view");
                    ui.label(format!("{} pixels differ", e.differing));
                    match e.region {
                        Some(r) => {
                            ui.label(format!("region {:.4}", r)).on_hover_text("the same over the dragged rectangle");
                            if ui.small_button("clear region").clicked() {
                                split.region = None;
                            }
                            if let Some(s) = &split.region_stats {
                                ui.end_row();
                                ui.label(region_text(s)).on_hover_text("A's linear values over the dragged rectangle, per channel (r, g, b): population std, numpy's median");
                            }
                        }
                        None => {
                            ui.weak("alt+drag: measure a region");
                        }
                    }
                }
                None => {
                    ui.weak("rendering B…");
                }
            }
            if ui.button("close (B)").clicked() {
                req.close = true;
            }
        });
    });
    req
}

/// The region's statistics as one line: per channel r, g, b.
pub fn region_text(s: &crate::app::region_stats::RegionStats) -> String {
    let [x0, y0, x1, y1] = s.region;
    let each = |f: &dyn Fn(&crate::app::region_stats::ChannelStats) -> f64| -> String {
        s.channels.iter().map(|c| c.map_or("-".to_string(), |c| format!("{:.4}", f(&c)))).collect::<Vec<_>>().join(", ")
    };
    format!(
        "region {x0},{y0}-{x1},{y1} ({} px): mean ({}) median ({}) min ({}) max ({}) std ({}) non-finite {}",
        s.pixels,
        each(&|c| c.mean),
        each(&|c| c.median),
        each(&|c| c.min as f64),
        each(&|c| c.max as f64),
        each(&|c| c.std),
        s.non_finite
    )
}
