//! The indirect-light sweep (`pinhole chart --sweep gi`): each way of
//! computing bounced light as a curve of error against time, so that the
//! methods can be compared where they meet, and a peer renderer's curve
//! (`--peer FILE.csv`) can be laid over them.

use crate::chart::configurations::Configuration;
use crate::chart::measure::{measure, Measurement};
use crate::chart::reference::Reference;
use crate::render::transport::gi::GiMode;
use crate::render::{frame, PreparedScene, RenderSettings, DEFAULT_RAYTRACE};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// The curves: direct light only and ambient occlusion at growing samples,
/// photon maps of growing size, and path tracing at each of `path_spps`.
/// Every configuration is the ray tracer at `base`'s size and seed; the
/// rasterizers give the same images (their first hits are the same).
pub fn gi_configurations(base: &RenderSettings, scene: &crate::scene::Scene, path_spps: &[u32]) -> Vec<Configuration> {
    let plain = crate::chart::configurations::plain_settings(scene, base);
    let with = |f: &dyn Fn(&mut RenderSettings)| {
        let mut s = plain.clone();
        f(&mut s);
        s
    };
    let mut out = Vec::new();
    for spp in [1, 4, 16] {
        out.push(Configuration::new("none", DEFAULT_RAYTRACE, with(&|s| s.spp = spp)));
    }
    if scene.render.ambient.max_element() > 0.0 {
        for (samples, spp) in [(4, 1), (4, 4), (16, 4), (16, 16)] {
            out.push(Configuration::new("ao", DEFAULT_RAYTRACE, with(&|s| {
                s.gi.mode = GiMode::Ao;
                s.gi.ao_samples = samples;
                s.spp = spp;
            })));
        }
    }
    for photons in [2_000, 20_000, 200_000, 1_000_000] {
        out.push(Configuration::new("photons", DEFAULT_RAYTRACE, with(&|s| {
            s.gi.mode = GiMode::Photons;
            s.gi.photons = photons;
            s.spp = 4;
        })));
    }
    for &spp in path_spps {
        out.push(Configuration::new("path", DEFAULT_RAYTRACE, with(&|s| {
            s.gi.mode = GiMode::Path;
            s.spp = spp;
        })));
    }
    out.retain(|c| crate::chart::configurations::accepted(scene, c));
    out
}

/// `measure`, with the photon map's construction counted in the frame time:
/// a peer renderer's time includes everything it does for one image, so
/// the curves compare like with like.
pub fn measure_with_builds(prepared: &PreparedScene, config: &Configuration, reference: &Reference, cancel: &AtomicBool) -> Result<Option<Measurement>, String> {
    let start = Instant::now();
    let built = frame::build_photon_map(prepared, &config.settings).is_some();
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(measure(prepared, config, reference, 3, cancel)?.map(|mut m| {
        if built {
            m.ms += build_ms;
        }
        m
    }))
}

/// One point of a peer's curve, read from `--peer FILE.csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct PeerPoint {
    /// The curve it belongs to ("mitsuba path").
    pub series: String,
    /// The point's own label ("16 spp").
    pub label: String,
    pub ms: f64,
    pub rel_rmse: f64,
}

/// Reads a peer's measurements: a header `series,label,ms,rel_rmse`, then
/// one row per point. Errors name the file, line and field.
pub fn load_peer_csv(path: &Path) -> Result<Vec<PeerPoint>, String> {
    let bytes = crate::input::read_file(path, crate::input::InputKind::Scene)?;
    let text = String::from_utf8(bytes).map_err(|_| format!("{}: not UTF-8 text", path.display()))?;
    parse_peer_csv(&text).map_err(|e| format!("{}:{e}", path.display()))
}

/// `load_peer_csv` on text; errors start with the line number.
pub fn parse_peer_csv(text: &str) -> Result<Vec<PeerPoint>, String> {
    const HEADER: &str = "series,label,ms,rel_rmse";
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    match lines.next() {
        Some((_, h)) if h.trim() == HEADER => {}
        Some((i, h)) => return Err(format!("{}: the header is \"{}\", expected \"{HEADER}\"", i + 1, h.trim())),
        None => return Err(format!("1: empty; expected the header \"{HEADER}\"")),
    }
    let mut points = Vec::new();
    for (i, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != 4 {
            return Err(format!("{}: {} fields, expected 4 ({HEADER})", i + 1, fields.len()));
        }
        let number = |k: usize, name: &str| -> Result<f64, String> {
            fields[k]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or(format!("{}: {name} \"{}\" is not a positive number", i + 1, fields[k]))
        };
        points.push(PeerPoint { series: fields[0].to_string(), label: fields[1].to_string(), ms: number(2, "ms")?, rel_rmse: number(3, "rel_rmse")? });
    }
    if points.is_empty() {
        return Err("2: no rows after the header".into());
    }
    Ok(points)
}

/// The knob that moves a point along its curve, from its label: what
/// follows the renderer, without the `--gi` that names the curve
/// ("raytrace:bvh --spp 16 --gi path" -> "spp 16").
pub fn point_label(label: &str) -> String {
    let knobs: Vec<&str> = label.split(" --").skip(1).filter(|k| !k.starts_with("gi ")).collect();
    if knobs.is_empty() { "spp 1".into() } else { knobs.join(", ") }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peer_csv_reads_rows_and_names_the_line_at_fault() {
        let ok = parse_peer_csv("series,label,ms,rel_rmse\nmitsuba path,16 spp,1145.5,0.375\n\nmitsuba path,64 spp,4000,0.169\n").unwrap();
        assert_eq!(ok.len(), 2);
        assert_eq!(ok[1], PeerPoint { series: "mitsuba path".into(), label: "64 spp".into(), ms: 4000.0, rel_rmse: 0.169 });
        assert!(parse_peer_csv("method,ms\n").unwrap_err().starts_with("1: the header"));
        assert!(parse_peer_csv("").unwrap_err().starts_with("1: empty"));
        assert!(parse_peer_csv("series,label,ms,rel_rmse\n").unwrap_err().starts_with("2: no rows"));
        let e = parse_peer_csv("series,label,ms,rel_rmse\na,b,1,0.5\na,c,NaN,0.5\n").unwrap_err();
        assert!(e.starts_with("3: ms \"NaN\""), "{e}");
        let e = parse_peer_csv("series,label,ms,rel_rmse\na,b,1\n").unwrap_err();
        assert!(e.starts_with("2: 3 fields"), "{e}");
    }

    #[test]
    fn point_labels_keep_the_knob_that_moves_along_the_curve() {
        assert_eq!(point_label("raytrace:bvh --spp 16 --gi path"), "spp 16");
        assert_eq!(point_label("raytrace:bvh --spp 4 --gi photons --photons 20000"), "spp 4, photons 20000");
        assert_eq!(point_label("raytrace:bvh"), "spp 1");
    }

    #[test]
    fn the_sweep_has_a_curve_per_method_and_path_at_each_spp() {
        let scene = crate::scene::builtin::load_builtin("cornell-gi").unwrap().unwrap();
        let base = RenderSettings { width: 20, height: 20, ..RenderSettings::for_scene(&scene) };
        let configs = gi_configurations(&base, &scene, &[1, 4, 16]);
        let in_group = |g: &str| configs.iter().filter(|c| c.group == g).count();
        assert_eq!(in_group("none"), 3);
        assert_eq!(in_group("photons"), 4);
        assert_eq!(in_group("path"), 3);
        assert!(configs.iter().filter(|c| c.group == "path").all(|c| c.settings.gi.mode == GiMode::Path));
        assert!(configs.iter().all(|c| (c.settings.width, c.settings.height) == (20, 20)));
    }
}
