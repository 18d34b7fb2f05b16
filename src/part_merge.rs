//! `pinhole merge`: parts of one frame (tiles, sample ranges, or both)
//! assembled into the whole. Parts are checked to come from the same scene,
//! settings, renderer and version, and to cover every pixel's every sample
//! pass exactly once; a tile's pixels are copied as they are, and the
//! sums of a pixel's sample ranges are added in pass order and divided once
//! by the samples per pixel, as the whole frame divides its sum.

use crate::math::Radiance;
use crate::part_file::{PartFile, PartRecord};
use serde_json::json;
use std::path::PathBuf;

/// The assembled frame and the statistics a whole render would write.
pub struct Merged {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Radiance>,
    pub stats: serde_json::Value,
}

/// Counters of the run statistics that add up over parts.
const SUMMED: &[&str] = &[
    "load_ms",
    "build_ms",
    "render_ms",
    "primary_rays",
    "shadow_rays",
    "secondary_rays",
    "bvh_nodes_visited",
    "primitive_tests",
    "samples_tested",
    "samples_covered",
    "fragments_shaded",
    "depth_test_failures",
    "instances_drawn",
    "instances_culled",
];

/// Refuses, naming `b`, a part that does not belong with `a`.
fn check_same(a: &(PathBuf, PartFile), b: &(PathBuf, PartFile)) -> Result<(), String> {
    let (pa, ra) = (a.0.display(), &a.1.record);
    let (pb, rb) = (b.0.display(), &b.1.record);
    if ra.version != rb.version {
        return Err(format!("{pb}: made by pinhole {}, but {pa} by pinhole {}", rb.version, ra.version));
    }
    if ra.scene_hash != rb.scene_hash || ra.scene != rb.scene {
        return Err(format!("{pb}: rendered from another scene (\"{}\", hash {}) than {pa} (\"{}\", hash {})", rb.scene, rb.scene_hash, ra.scene, ra.scene_hash));
    }
    if ra.renderer != rb.renderer {
        return Err(format!("{pb}: rendered by {}, but {pa} by {}", rb.renderer, ra.renderer));
    }
    if ra.settings != rb.settings || (ra.frame_width, ra.frame_height, ra.spp) != (rb.frame_width, rb.frame_height, rb.spp) {
        let differing = differing_keys(&ra.settings, &rb.settings);
        return Err(format!("{pb}: rendered with other settings than {pa} ({})", if differing.is_empty() { "frame size or samples".to_string() } else { differing.join(", ") }));
    }
    Ok(())
}

/// The top-level keys whose values differ between two settings objects.
fn differing_keys(a: &serde_json::Value, b: &serde_json::Value) -> Vec<String> {
    let (Some(a), Some(b)) = (a.as_object(), b.as_object()) else { return Vec::new() };
    let mut keys: Vec<String> = a.keys().chain(b.keys()).filter(|k| a.get(*k) != b.get(*k)).cloned().collect();
    keys.sort();
    keys.dedup();
    keys
}

fn describe_region(r: &PartRecord) -> String {
    format!("columns {}..{}, rows {}..{}", r.region[0], r.region[2], r.region[1], r.region[3])
}

/// Merges `parts` (each with the path it was read from). Refuses, in one
/// sentence naming the offending part, parts that do not belong together,
/// overlap, or leave a gap.
pub fn merge(parts: &[(PathBuf, PartFile)]) -> Result<Merged, String> {
    let first = parts.first().ok_or("merge needs at least one part")?;
    for p in &parts[1..] {
        check_same(first, p)?;
    }
    let base = &first.1.record;
    let (w, h, spp) = (base.frame_width, base.frame_height, base.spp.max(1));
    // Parts grouped by their rectangle; each group's passes must run 0..spp.
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by_key(|&i| (parts[i].1.record.region, parts[i].1.record.passes));
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in order {
        match groups.last_mut() {
            Some(g) if parts[g[0]].1.record.region == parts[i].1.record.region => g.push(i),
            _ => groups.push(vec![i]),
        }
    }
    for g in &groups {
        let mut next = 0;
        for &i in g {
            let (path, r) = (parts[i].0.display(), &parts[i].1.record);
            let [from, to] = r.passes;
            if from < next {
                let before = g.iter().find(|&&j| j != i && parts[j].1.record.passes[1] > from && parts[j].1.record.passes[0] < to).map_or(String::new(), |&j| format!(" those of {}", parts[j].0.display()));
                return Err(format!("{path}: its samples {from}..{to} overlap{before}"));
            }
            if from > next {
                return Err(format!("samples {next}..{from} of {} are in no part (a part is missing before {path})", describe_region(r)));
            }
            next = to;
        }
        if next < spp {
            let last = &parts[*g.last().expect("groups are not empty")];
            return Err(format!("samples {next}..{spp} of {} are in no part (a part is missing after {})", describe_region(&last.1.record), last.0.display()));
        }
    }
    // Each group's rectangle must cover its pixels once over the frame.
    let mut owner: Vec<Option<usize>> = vec![None; w as usize * h as usize];
    for g in &groups {
        let i = g[0];
        let [x0, y0, x1, y1] = parts[i].1.record.region;
        for y in y0..y1 {
            for x in x0..x1 {
                let slot = &mut owner[(x + y * w) as usize];
                if let Some(j) = *slot {
                    return Err(format!("{}: its {} overlap those of {} at pixel ({x}, {y})", parts[i].0.display(), describe_region(&parts[i].1.record), parts[j].0.display()));
                }
                *slot = Some(i);
            }
        }
    }
    if let Some(gap) = owner.iter().position(Option::is_none) {
        let (x, y) = (gap as u32 % w, gap as u32 / w);
        let tiles: Vec<[u32; 2]> = parts.iter().filter_map(|p| p.1.record.tile).collect();
        if tiles.len() == parts.len() && tiles.iter().all(|t| t[1] == tiles[0][1]) {
            let n = tiles[0][1];
            let missing: Vec<String> = (0..n).filter(|i| !tiles.iter().any(|t| t[0] == *i)).map(|i| format!("{i}/{n}")).collect();
            return Err(format!("tile {} is missing: no part covers pixel ({x}, {y})", missing.join(", ")));
        }
        return Err(format!("pixel ({x}, {y}) is in no part: a part is missing"));
    }
    let mut pixels = vec![Radiance::ZERO; w as usize * h as usize];
    for g in &groups {
        let r = &parts[g[0]].1.record;
        let rw = r.width() as usize;
        let value = |k: usize| -> Radiance {
            if g.len() == 1 && r.holds_final_values() {
                return parts[g[0]].1.pixels[k];
            }
            let mut sum = parts[g[0]].1.pixels[k];
            for &i in &g[1..] {
                sum += parts[i].1.pixels[k];
            }
            crate::render::frame::final_value(sum, spp)
        };
        for (k, y) in (r.region[1]..r.region[3]).enumerate() {
            for x in 0..rw {
                pixels[(r.region[0] as usize + x) + y as usize * w as usize] = value(k * rw + x);
            }
        }
    }
    Ok(Merged { width: w, height: h, pixels, stats: merged_stats(parts) })
}

/// The whole render's statistics from its parts': counters and times
/// summed, the peak memory the largest part's, and the wall-clock time
/// from the first part's start to the last one's end.
fn merged_stats(parts: &[(PathBuf, PartFile)]) -> serde_json::Value {
    let base = &parts[0].1.record;
    let mut out = base.stats.clone();
    let num = |p: &PartFile, k: &str| p.record.stats.get(k).and_then(|v| v.as_f64());
    if let Some(o) = out.as_object_mut() {
        for k in SUMMED {
            if o.contains_key(*k) {
                let values: Vec<f64> = parts.iter().filter_map(|p| num(&p.1, k)).collect();
                let total: f64 = values.iter().sum();
                o.insert(k.to_string(), if k.ends_with("_ms") { json!(total) } else { json!(total as u64) });
            }
        }
        let peak = parts.iter().filter_map(|p| num(&p.1, "peak_rss_bytes")).fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))));
        o.insert("peak_rss_bytes".into(), json!(peak.map(|v| v as u64)));
        let start = parts.iter().filter_map(|p| num(&p.1, "started_unix_ms")).fold(f64::INFINITY, f64::min);
        let end = parts.iter().filter_map(|p| num(&p.1, "finished_unix_ms")).fold(f64::NEG_INFINITY, f64::max);
        o.insert("wall_clock_ms".into(), json!((end >= start).then(|| end - start)));
        o.insert("started_unix_ms".into(), json!(start.is_finite().then_some(start)));
        o.insert("finished_unix_ms".into(), json!(end.is_finite().then_some(end)));
        o.insert("width".into(), json!(base.frame_width));
        o.insert("height".into(), json!(base.frame_height));
        o.insert("spp".into(), json!(base.spp));
        o.insert("tile".into(), serde_json::Value::Null);
        o.insert("sample_range".into(), serde_json::Value::Null);
        o.insert("crop".into(), serde_json::Value::Null);
        o.insert("parts".into(), json!(parts.len()));
    }
    out
}
