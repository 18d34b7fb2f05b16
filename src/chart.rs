//! Speed against accuracy, measured rather than assumed: sweep the samples per
//! pixel of each renderer, time every frame, measure its error against a
//! reference image, and draw the trade-off as a chart (PNG) and a table (CSV).

use crate::math::Radiance;
use crate::render::{self, PreparedScene, RenderSettings};
use plotters::prelude::*;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// One measured frame of the sweep.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SweepPoint {
    pub renderer: String,
    pub spp: u32,
    /// Best of the timed frames, milliseconds.
    pub ms: f64,
    /// rmse relative to the reference's mean radiance.
    pub rel_rmse: f64,
    pub flip: f64,
}

/// Renders each renderer at each spp (`repeats` timed frames, best kept) and
/// measures it against `reference`. `progress` is called before each frame.
pub fn sweep(
    prepared: &PreparedScene,
    base: &RenderSettings,
    renderers: &[&str],
    spps: &[u32],
    reference: &[Radiance],
    repeats: u32,
    mut progress: impl FnMut(&str, u32),
) -> Result<Vec<SweepPoint>, String> {
    let cancel = AtomicBool::new(false);
    let mut points = Vec::new();
    for name in renderers {
        let r = render::renderer_by_name(name)?;
        for &spp in spps {
            progress(r.name(), spp);
            let settings = RenderSettings { spp, ..base.clone() };
            let mut best = f64::INFINITY;
            let mut image = Vec::new();
            for _ in 0..repeats.max(1) {
                let start = Instant::now();
                let f = render::render_frame(r.as_ref(), prepared, &settings, &cancel, None).ok_or("cancelled")?;
                best = best.min(start.elapsed().as_secs_f64() * 1e3);
                image = f.pixels;
            }
            let m = crate::metrics::compare_images(&image, reference, settings.width as usize, settings.height as usize)?;
            points.push(SweepPoint {
                renderer: r.name().to_string(),
                spp,
                ms: best,
                rel_rmse: m.rmse / m.reference_mean.max(1e-12),
                flip: m.flip.unwrap_or(0.0),
            });
        }
    }
    Ok(points)
}

pub fn to_csv(points: &[SweepPoint]) -> String {
    let mut s = String::from("renderer,spp,ms,rel_rmse,flip\n");
    for p in points {
        s.push_str(&format!("{},{},{:.3},{:.6},{:.6}\n", p.renderer, p.spp, p.ms, p.rel_rmse, p.flip));
    }
    s
}

/// Draws error (log) against frame time (log), one line per renderer, each
/// point labelled with its spp. Returns PNG bytes.
pub fn draw_png(points: &[SweepPoint], title: &str, width: u32, height: u32) -> Result<Vec<u8>, String> {
    // Registering twice is harmless; the font is egui's own Ubuntu Light.
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    let mut buf = vec![255u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (xmin, xmax) = bounds(points.iter().map(|p| p.ms));
        let (ymin, ymax) = bounds(points.iter().map(|p| p.rel_rmse.max(1e-6)));
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d((xmin..xmax).log_scale(), (ymin..ymax).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("frame time (ms, log)")
            .y_desc("rmse / mean radiance (log)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
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
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    crate::image_io::encode_png(width, height, &buf)
}

/// A log-axis range around the values, with some room.
fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !(lo.is_finite() && hi > 0.0) {
        return (0.1, 1.0);
    }
    (lo / 1.5, hi * 1.5)
}
