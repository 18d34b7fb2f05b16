//! The Compare window: error against frame time of every method that matters
//! for the scene, on log axes, with the Pareto front. Hovering a point names
//! its configuration; clicking it applies it to the live view.

use crate::app::compare_lab::{CompareLab, LAB_WIDTH};
use crate::chart::{pareto_front, Configuration, ErrorMetric, Measurement};
use eframe::egui;
use egui_plot::{Line, MarkerShape, Plot, PlotPoint, PlotPoints, Points};

/// What the window asks of the viewer.
#[derive(Default)]
pub struct CompareRequests {
    /// Start (or restart) the measurements.
    pub measure: bool,
    /// Apply this configuration to the live view.
    pub apply: Option<Configuration>,
    /// Show this configuration as B beside the live view.
    pub set_b: Option<Configuration>,
    /// Write the chart and the CSV.
    pub export: bool,
}

/// Colours of the groups, in the order they first appear.
const GROUP_COLOURS: [egui::Color32; 6] = [
    egui::Color32::from_rgb(230, 80, 80),
    egui::Color32::from_rgb(80, 190, 90),
    egui::Color32::from_rgb(240, 200, 60),
    egui::Color32::from_rgb(70, 150, 240),
    egui::Color32::from_rgb(200, 110, 230),
    egui::Color32::from_rgb(90, 220, 220),
];

/// Pointer distance (points) within which a marker counts as hovered.
const HOVER_RADIUS: f32 = 10.0;

/// `current`: the live view's configuration label, ringed on the plot.
pub fn show(ctx: &egui::Context, lab: &mut CompareLab, current: &str) -> CompareRequests {
    let mut req = CompareRequests::default();
    let mut open = lab.open;
    egui::Window::new("Compare").open(&mut open).default_size([620.0, 560.0]).show(ctx, |ui| {
        controls(ui, lab, &mut req);
        status(ui, lab);
        let points: Vec<(Configuration, Measurement)> = lab.progress.lock().unwrap().points.clone();
        plot(ui, lab, &points, current, &mut req);
        table(ui, lab.metric, &points, &mut req);
        ui.separator();
        ui.horizontal(|ui| {
            ui.label("export to");
            ui.add(egui::TextEdit::singleline(&mut lab.export_path).desired_width(260.0)).on_hover_text("a .png; the CSV is written beside it");
            if ui.add_enabled(!points.is_empty(), egui::Button::new("Export PNG + CSV")).clicked() {
                req.export = true;
            }
        });
    });
    lab.open = open;
    if !open && lab.running() {
        lab.cancel();
    }
    req
}

fn controls(ui: &mut egui::Ui, lab: &mut CompareLab, req: &mut CompareRequests) {
    ui.horizontal(|ui| {
        if lab.running() {
            if ui.button("Cancel").clicked() {
                lab.cancel();
            }
        } else if ui.button("Measure").on_hover_text(format!("render every configuration at up to {LAB_WIDTH} pixels wide and measure it against the reference")).clicked() {
            req.measure = true;
        }
        ui.label("error");
        egui::ComboBox::from_id_salt("compare-metric")
            .selected_text(lab.metric.axis_name())
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut lab.metric, ErrorMetric::RelRmse, ErrorMetric::RelRmse.axis_name());
                ui.selectable_value(&mut lab.metric, ErrorMetric::Flip, ErrorMetric::Flip.axis_name());
            });
    });
}

fn status(ui: &mut egui::Ui, lab: &CompareLab) {
    let p = lab.progress.lock().unwrap();
    if let Some(e) = &p.error {
        ui.colored_label(egui::Color32::from_rgb(255, 120, 120), e);
    }
    if let Some(r) = &p.reference {
        ui.label(format!("reference: {r}"));
    }
    if lab.running() {
        let fraction = if p.total == 0 {
            lab.reference_passes.load(std::sync::atomic::Ordering::Relaxed) as f32 / lab.reference_spp.max(1) as f32
        } else {
            p.points.len() as f32 / p.total as f32
        };
        ui.add(egui::ProgressBar::new(fraction).text(p.stage.clone()).animate(true));
    } else if p.points.is_empty() && p.error.is_none() {
        ui.label("Measure renders each configuration on a small copy of the view and measures its error against the reference.");
    } else {
        ui.label(&p.stage);
    }
}

fn plot(ui: &mut egui::Ui, lab: &mut CompareLab, points: &[(Configuration, Measurement)], current: &str, req: &mut CompareRequests) {
    let metric = lab.metric;
    let at = |m: &Measurement| PlotPoint::new(m.ms.max(1e-3).log10(), metric.of(m).max(1e-6).log10());
    let measurements: Vec<Measurement> = points.iter().map(|(_, m)| m.clone()).collect();
    let front = pareto_front(&measurements, metric);
    let mut groups: Vec<String> = Vec::new();
    for m in &measurements {
        if !groups.contains(&m.group) {
            groups.push(m.group.clone());
        }
    }
    let hovered_before = lab.hovered;
    let response = Plot::new("compare-plot")
        .height(300.0)
        .legend(egui_plot::Legend::default())
        .x_axis_label("frame time (ms, log)")
        .y_axis_label(format!("{} (log)", metric.axis_name()))
        .x_axis_formatter(|mark, _| power_of_ten(mark.value))
        .y_axis_formatter(|mark, _| power_of_ten(mark.value))
        .label_formatter(|_| None)
        .allow_double_click_reset(true)
        .show(ui, |plot_ui| {
            let front_line: Vec<[f64; 2]> = front.iter().map(|&i| at(&measurements[i])).map(|p| [p.x, p.y]).collect();
            plot_ui.line(Line::new("Pareto front", PlotPoints::from(front_line)).color(egui::Color32::GRAY));
            for (g, name) in groups.iter().enumerate() {
                let pts: Vec<[f64; 2]> = measurements.iter().filter(|m| &m.group == name).map(|m| at(m)).map(|p| [p.x, p.y]).collect();
                plot_ui.points(Points::new(name.clone(), PlotPoints::from(pts)).radius(5.0).filled(true).color(GROUP_COLOURS[g % GROUP_COLOURS.len()]));
            }
            if let Some(i) = measurements.iter().position(|m| m.label == current) {
                let p = at(&measurements[i]);
                plot_ui.points(Points::new("current view", PlotPoints::from(vec![[p.x, p.y]])).radius(9.0).filled(false).shape(MarkerShape::Circle).color(egui::Color32::WHITE));
            }
            // The marker nearest the pointer, in screen space.
            let pointer = plot_ui.response().hover_pos();
            let nearest = pointer.and_then(|pos| {
                measurements
                    .iter()
                    .enumerate()
                    .map(|(i, m)| (i, plot_ui.screen_from_plot(at(m)).distance(pos)))
                    .filter(|(_, d)| *d <= HOVER_RADIUS)
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|(i, _)| i)
            });
            if let Some(i) = nearest {
                let p = at(&measurements[i]);
                plot_ui.points(Points::new("", PlotPoints::from(vec![[p.x, p.y]])).radius(8.0).filled(false).color(egui::Color32::YELLOW));
            }
            (nearest, plot_ui.response().clicked())
        });
    let (nearest, clicked) = response.inner;
    lab.hovered = nearest;
    lab.last_transform = Some(response.transform);
    match nearest.or(hovered_before.filter(|_| clicked)) {
        Some(i) if i < points.len() => {
            let m = &points[i].1;
            ui.label(format!("{}: {:.1} ms, {} {:.4}", m.label, m.ms, metric.axis_name(), metric.of(m)));
            if clicked {
                req.apply = Some(points[i].0.clone());
            }
        }
        _ => {
            ui.weak("hover a point to name it; click to apply it to the view");
        }
    }
}

/// Axis labels of a log axis: the value the exponent stands for.
fn power_of_ten(exponent: f64) -> String {
    let v = 10f64.powf(exponent);
    if v >= 100.0 {
        format!("{v:.0}")
    } else {
        let digits = (1 - v.log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    }
}

/// Every measurement, lowest error first, each with a button that applies it.
fn table(ui: &mut egui::Ui, metric: ErrorMetric, points: &[(Configuration, Measurement)], req: &mut CompareRequests) {
    if points.is_empty() {
        return;
    }
    egui::CollapsingHeader::new("all configurations").show(ui, |ui| {
        let mut order: Vec<usize> = (0..points.len()).collect();
        order.sort_by(|&a, &b| metric.of(&points[a].1).total_cmp(&metric.of(&points[b].1)));
        egui::ScrollArea::vertical().max_height(180.0).show(ui, |ui| {
            egui::Grid::new("compare-table").striped(true).show(ui, |ui| {
                ui.strong("configuration");
                ui.strong("ms");
                ui.strong(metric.axis_name());
                ui.label("");
                ui.end_row();
                for i in order {
                    let (c, m) = &points[i];
                    ui.label(&m.label);
                    ui.label(format!("{:.1}", m.ms));
                    ui.label(format!("{:.4}", metric.of(m)));
                    ui.horizontal(|ui| {
                        if ui.small_button("apply").on_hover_text(format!("render the view as {}", c.label)).clicked() {
                            req.apply = Some(c.clone());
                        }
                        if ui.small_button("as B").on_hover_text("show it beside the view, A|B").clicked() {
                            req.set_b = Some(c.clone());
                        }
                    });
                    ui.end_row();
                }
            });
        });
    });
}
