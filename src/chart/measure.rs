//! Measuring configurations: time a frame, compare it with the reference,
//! and find which configurations are worth their time (the Pareto front).

use crate::chart::configurations::Configuration;
use crate::chart::reference::Reference;
use crate::render::{self, PreparedScene};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// A frame slower than this is timed once: repeating it buys little accuracy
/// in the timing and costs the user seconds.
const REPEAT_BELOW_MS: f64 = 300.0;

/// One measured configuration.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Measurement {
    pub label: String,
    pub group: String,
    pub renderer: String,
    /// Best of the timed frames, milliseconds. Shadow maps, shadow volumes
    /// and photon maps are built before the timer starts: like a BVH, they
    /// are built once per scene or light change, not per frame.
    pub ms: f64,
    /// rmse relative to the reference's mean radiance.
    pub rel_rmse: f64,
    /// Mean FLIP of the sRGB-encoded images.
    pub flip: f64,
}

/// Which error the chart plots.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ErrorMetric {
    #[default]
    RelRmse,
    Flip,
}

impl ErrorMetric {
    pub fn of(self, m: &Measurement) -> f64 {
        match self {
            ErrorMetric::RelRmse => m.rel_rmse,
            ErrorMetric::Flip => m.flip,
        }
    }

    pub fn axis_name(self) -> &'static str {
        match self {
            ErrorMetric::RelRmse => "rmse / mean radiance",
            ErrorMetric::Flip => "mean FLIP",
        }
    }
}

/// Renders `config` up to `repeats` times (fast frames only), keeps the best
/// time, and measures the image against `reference`. `None` when cancelled.
pub fn measure(prepared: &PreparedScene, config: &Configuration, reference: &Reference, repeats: u32, cancel: &AtomicBool) -> Result<Option<Measurement>, String> {
    let s = &config.settings;
    if (s.width, s.height) != (reference.width, reference.height) {
        return Err(format!("{} renders {}x{} but the reference is {}x{}", config.label, s.width, s.height, reference.width, reference.height));
    }
    let renderer = render::renderer_by_name(&config.renderer)?;
    // A configuration that edits the scene (the model sweep) draws its own copy.
    let edited;
    let prepared = match config.glossy_model {
        None => prepared,
        Some(_) => {
            edited = PreparedScene::new(config.scene(&prepared.scene).into_owned());
            &edited
        }
    };
    render::frame::build_shadow_maps(prepared, s);
    render::frame::build_photon_map(prepared, s);
    let mut best = f64::INFINITY;
    let mut image = Vec::new();
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let Some(frame) = render::render_frame(renderer.as_ref(), prepared, s, cancel, None) else {
            return Ok(None);
        };
        best = best.min(start.elapsed().as_secs_f64() * 1e3);
        image = frame.pixels;
        if best > REPEAT_BELOW_MS {
            break;
        }
    }
    Measurement::of_image(config, best, &image, reference).map(Some)
}

impl Measurement {
    /// `config`'s row: `image`, rendered in `ms`, against `reference`.
    pub fn of_image(config: &Configuration, ms: f64, image: &[crate::math::Radiance], reference: &Reference) -> Result<Measurement, String> {
        let m = crate::metrics::compare_images(image, &reference.pixels, reference.width as usize, reference.height as usize)?;
        Ok(Measurement {
            label: config.label.clone(),
            group: config.group.to_string(),
            renderer: config.renderer.clone(),
            ms,
            rel_rmse: m.rmse / m.reference_mean.max(1e-12),
            flip: m.flip.unwrap_or(f64::NAN),
        })
    }
}

/// Indices of the measurements no other one beats in both time and error,
/// ordered by time: the configurations worth choosing.
pub fn pareto_front(points: &[Measurement], metric: ErrorMetric) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).filter(|&i| points[i].ms.is_finite() && metric.of(&points[i]).is_finite()).collect();
    order.sort_by(|&a, &b| points[a].ms.total_cmp(&points[b].ms).then(metric.of(&points[a]).total_cmp(&metric.of(&points[b]))));
    let mut front = Vec::new();
    let mut best_error = f64::INFINITY;
    for i in order {
        let e = metric.of(&points[i]);
        if e < best_error {
            best_error = e;
            front.push(i);
        }
    }
    front
}

/// `method,ms,rel_rmse,flip`, one row per measurement.
pub fn methods_csv(points: &[Measurement]) -> String {
    let mut s = String::from("method,ms,rel_rmse,flip\n");
    for p in points {
        let label = if p.label.contains([',', '"']) { format!("\"{}\"", p.label.replace('"', "\"\"")) } else { p.label.clone() };
        s.push_str(&format!("{label},{:.3},{:.6},{:.6}\n", p.ms, p.rel_rmse, p.flip));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(label: &str, ms: f64, err: f64) -> Measurement {
        Measurement { label: label.into(), group: "g".into(), renderer: "r".into(), ms, rel_rmse: err, flip: err * 0.5 }
    }

    #[test]
    fn the_front_keeps_only_points_nothing_beats() {
        let pts = [point("slow-good", 100.0, 0.01), point("fast-bad", 1.0, 0.5), point("dominated", 50.0, 0.6), point("middle", 10.0, 0.1), point("nan", 5.0, f64::NAN)];
        assert_eq!(pareto_front(&pts, ErrorMetric::RelRmse), vec![1, 3, 0]);
        assert_eq!(pareto_front(&pts, ErrorMetric::Flip), vec![1, 3, 0]);
    }

    #[test]
    fn csv_has_the_contract_columns_and_quotes_commas() {
        let csv = methods_csv(&[point("a b", 1.5, 0.25), point("x,y", 2.0, 0.5)]);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "method,ms,rel_rmse,flip");
        assert_eq!(lines[1], "a b,1.500,0.250000,0.125000");
        assert!(lines[2].starts_with("\"x,y\",2.000,"));
    }
}
