//! Charts as PNG (plotters): error against frame time on log axes.

use crate::chart::measure::{ErrorMetric, Measurement};
use crate::chart::spp_sweep::SweepPoint;
use plotters::prelude::*;

/// Registering twice is harmless; the font is egui's own Ubuntu Light.
fn register_font() {
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
}

/// Draws error (log) against frame time (log), one line per renderer, each
/// point labelled with its spp. Returns PNG bytes.
pub fn draw_spp_png(points: &[SweepPoint], title: &str, width: u32, height: u32) -> Result<Vec<u8>, String> {
    let frame = Frame {
        title,
        size: (width, height),
        x: bounds(points.iter().map(|p| p.ms)),
        y: bounds(points.iter().map(|p| p.rel_rmse.max(1e-6))),
        y_desc: "rmse / mean radiance (log)".to_string(),
        legend: SeriesLabelPosition::MiddleRight,
    };
    frame.draw(|chart| {
        let mut names: Vec<&str> = points.iter().map(|p| p.renderer.as_str()).collect();
        names.dedup();
        for (i, name) in names.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            let series: Vec<(f64, f64)> = points.iter().filter(|p| p.renderer == *name).map(|p| (p.ms, p.rel_rmse.max(1e-6))).collect();
            chart
                .draw_series(LineSeries::new(series.clone(), color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(*name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
            chart
                .draw_series(points.iter().filter(|p| p.renderer == *name).map(|p| {
                    EmptyElement::at((p.ms, p.rel_rmse.max(1e-6)))
                        + Circle::new((0, 0), 4, color.filled())
                        + Text::new(format!("{}", p.spp), (6, -14), ("sans-serif", 13))
                }))
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    })
}

/// The log-log chart on a log x axis of frame times.
type LogChart<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// What every chart here shares: a white image of `size`, a title, error
/// (log) against frame time (log) over the ranges `x` and `y`, and a legend.
struct Frame<'t> {
    title: &'t str,
    size: (u32, u32),
    x: (f64, f64),
    y: (f64, f64),
    y_desc: String,
    legend: SeriesLabelPosition,
}

impl Frame<'_> {
    /// Draws the axes, lets `series` add the chart's own series, then the
    /// legend. Returns PNG bytes.
    fn draw(self, series: impl FnOnce(&mut LogChart) -> Result<(), String>) -> Result<Vec<u8>, String> {
        register_font();
        let (width, height) = self.size;
        // Points are labelled to their right: the axis runs on past the
        // last point far enough (on its log scale) to hold a label.
        let x_end = self.x.1 * 3.0;
        let mut buf = vec![255u8; (width * height * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let mut chart = ChartBuilder::on(&root)
                .caption(self.title, ("sans-serif", 20))
                .margin(16)
                .x_label_area_size(44)
                .y_label_area_size(70)
                .build_cartesian_2d((self.x.0..x_end).log_scale(), (self.y.0..self.y.1).log_scale())
                .map_err(|e| e.to_string())?;
            chart
                .configure_mesh()
                .x_desc("frame time (ms, log)")
                .y_desc(self.y_desc)
                .x_label_formatter(&|v| short_number(*v))
                .y_label_formatter(&|v| short_number(*v))
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(|e| e.to_string())?;
            series(&mut chart)?;
            chart
                .configure_series_labels()
                .position(self.legend)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .draw()
                .map_err(|e| e.to_string())?;
            root.present().map_err(|e| e.to_string())?;
        }
        crate::image_io::encode_png(width, height, &buf)
    }
}

/// The names of `points`' groups, in the order they first appear.
fn groups(points: &[Measurement]) -> Vec<&str> {
    let mut groups: Vec<&str> = Vec::new();
    for p in points {
        if !groups.contains(&p.group.as_str()) {
            groups.push(&p.group);
        }
    }
    groups
}

/// Axis numbers with two significant digits (log axes otherwise print
/// rounding noise such as 0.30000000000000004).
fn short_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (1 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

/// A log-axis range around the values, with some room.
fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !(lo.is_finite() && hi > 0.0) {
        return (0.1, 1.0);
    }
    (lo / 1.5, hi * 1.5)
}

/// The methods chart: one dot per configuration, coloured by its group, the
/// Pareto front as a line through the configurations worth choosing, each
/// of those labelled. Returns PNG bytes.
pub fn draw_methods_png(points: &[Measurement], metric: ErrorMetric, title: &str, width: u32, height: u32) -> Result<Vec<u8>, String> {
    let err = |p: &Measurement| metric.of(p).max(1e-6);
    let front = crate::chart::measure::pareto_front(points, metric);
    let frame = Frame {
        title,
        size: (width, height),
        x: bounds(points.iter().map(|p| p.ms)),
        y: bounds(points.iter().map(err)),
        y_desc: format!("{} (log)", metric.axis_name()),
        legend: SeriesLabelPosition::LowerLeft,
    };
    frame.draw(|chart| {
        let front_line: Vec<(f64, f64)> = front.iter().map(|&i| (points[i].ms, err(&points[i]))).collect();
        chart
            .draw_series(LineSeries::new(front_line, BLACK.mix(0.5).stroke_width(1)))
            .map_err(|e| e.to_string())?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5).stroke_width(1)));
        for (gi, group) in groups(points).iter().enumerate() {
            let color = Palette99::pick(gi).to_rgba();
            chart
                .draw_series(points.iter().filter(|p| p.group == *group).map(|p| Circle::new((p.ms, err(p)), 5, color.filled())))
                .map_err(|e| e.to_string())?
                .label(*group)
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, color.filled()));
        }
        chart
            .draw_series(front.iter().enumerate().map(|(k, &i)| {
                // Neighbours on the front often sit close together: their
                // labels step up in turn so they do not overprint.
                let p = &points[i];
                let dy = -6 - 15 * (k % 3) as i32;
                EmptyElement::at((p.ms, err(p))) + Text::new(p.label.clone(), (8, dy), ("sans-serif", 12))
            }))
            .map_err(|e| e.to_string())?;
        Ok(())
    })
}

/// The curves chart (`--sweep gi`): one line per group through its points in
/// the order they were measured, each point labelled with the knob that moves it, and each
/// peer series as a dashed black line with crosses. Returns PNG bytes.
pub fn draw_curves_png(points: &[Measurement], peers: &[crate::chart::gi_sweep::PeerPoint], metric: ErrorMetric, title: &str, width: u32, height: u32) -> Result<Vec<u8>, String> {
    let err = |p: &Measurement| metric.of(p).max(1e-6);
    let frame = Frame {
        title,
        size: (width, height),
        x: bounds(points.iter().map(|p| p.ms).chain(peers.iter().map(|p| p.ms))),
        y: bounds(points.iter().map(err).chain(peers.iter().map(|p| p.rel_rmse.max(1e-6)))),
        y_desc: format!("{} (log)", metric.axis_name()),
        legend: SeriesLabelPosition::UpperRight,
    };
    frame.draw(|chart| {
        for (gi, group) in groups(points).iter().enumerate() {
            let color = Palette99::pick(gi).to_rgba();
            // In the sweep's order, which is the order of the knob (samples,
            // photons): a costlier knob setting is not always slower.
            let curve: Vec<&Measurement> = points.iter().filter(|p| p.group == *group).collect();
            let line: Vec<(f64, f64)> = curve.iter().map(|p| (p.ms, err(p))).collect();
            chart
                .draw_series(LineSeries::new(line, color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(*group)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
            chart
                .draw_series(curve.iter().map(|p| {
                    EmptyElement::at((p.ms, err(p)))
                        + Circle::new((0, 0), 4, color.filled())
                        + Text::new(crate::chart::gi_sweep::point_label(&p.label), (6, -14), ("sans-serif", 12))
                }))
                .map_err(|e| e.to_string())?;
        }
        let mut series: Vec<&str> = Vec::new();
        for p in peers {
            if !series.contains(&p.series.as_str()) {
                series.push(&p.series);
            }
        }
        // Peer values are rmse / mean: they belong on the chart only when it plots that.
        for name in series.iter().filter(|_| metric == ErrorMetric::RelRmse) {
            let curve: Vec<&crate::chart::gi_sweep::PeerPoint> = peers.iter().filter(|p| p.series == *name).collect();
            let line: Vec<(f64, f64)> = curve.iter().map(|p| (p.ms, p.rel_rmse.max(1e-6))).collect();
            chart
                .draw_series(DashedLineSeries::new(line, 8, 5, BLACK.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(*name)
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
            chart
                .draw_series(curve.iter().map(|p| {
                    EmptyElement::at((p.ms, p.rel_rmse.max(1e-6)))
                        + Cross::new((0, 0), 5, BLACK.stroke_width(2))
                        + Text::new(p.label.clone(), (6, 6), ("sans-serif", 12))
                }))
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    })
}
