//! `pinhole merge --status DIR`: while the parts of a split render are
//! still being made, which exist, which are missing, and about how much
//! rendering is left, judged from the finished parts' own render times.
//! It reads only the parts' headers (not their pixels) and writes nothing.

use crate::part_file::PartRecord;
use std::path::{Path, PathBuf};

/// What a folder of parts says about the frame they belong to.
#[derive(Debug, PartialEq)]
pub struct PartStatus {
    /// Parts of the frame most of the readable parts belong to.
    pub parts: usize,
    /// Files with the `.exr` ending that are not parts of that frame, each
    /// with the reason.
    pub others: Vec<(PathBuf, String)>,
    /// For tiled renders, the tile indices no part holds, and N.
    pub missing_tiles: Option<(Vec<u32>, u32)>,
    /// The share of the frame's pixel samples that the parts hold.
    pub done: f64,
    /// The rendering time left at the parts' own pace, where it can be told.
    pub remaining_ms: Option<f64>,
}

/// The status of the parts in `dir` (every `*.exr` in it, not below).
pub fn status(dir: &Path) -> Result<PartStatus, String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: cannot list the folder: {e}", dir.display()))?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().and_then(|x| x.to_str()).is_some_and(|x| x.eq_ignore_ascii_case("exr")))
        .collect();
    paths.sort();
    let mut read: Vec<(PathBuf, Result<PartRecord, String>)> = paths.into_iter().map(|p| (p.clone(), crate::part_file::read_record(&p))).collect();
    Ok(summarise(&mut read))
}

/// Whether `b` is a part of the same frame as `a`.
fn same_frame(a: &PartRecord, b: &PartRecord) -> bool {
    a.version == b.version && a.scene_hash == b.scene_hash && a.renderer == b.renderer && a.settings == b.settings
}

fn summarise(read: &mut [(PathBuf, Result<PartRecord, String>)]) -> PartStatus {
    // The frame most parts belong to (a stray part of another render
    // should not make the real ones look foreign).
    let records: Vec<&PartRecord> = read.iter().filter_map(|(_, r)| r.as_ref().ok()).collect();
    let base = records
        .iter()
        .enumerate()
        .max_by_key(|&(i, a)| (records.iter().filter(|b| same_frame(a, b)).count(), std::cmp::Reverse(i)))
        .map(|(_, r)| (*r).clone());
    let mut others = Vec::new();
    let mut mine: Vec<&PartRecord> = Vec::new();
    for (path, r) in read.iter() {
        match (r, &base) {
            (Err(e), _) => others.push((path.clone(), e.clone())),
            (Ok(r), Some(b)) if same_frame(b, r) => mine.push(r),
            (Ok(_), _) => others.push((path.clone(), "a part of another frame (scene, settings, renderer or version)".into())),
        }
    }
    let Some(base) = base else {
        return PartStatus { parts: 0, others, missing_tiles: None, done: 0.0, remaining_ms: None };
    };
    let whole = base.frame_width as f64 * base.frame_height as f64 * base.spp.max(1) as f64;
    let units = |r: &PartRecord| r.width() as f64 * r.height() as f64 * r.passes[1].saturating_sub(r.passes[0]) as f64;
    let held: f64 = mine.iter().map(|r| units(r)).sum();
    // A part counted twice (a part rendered again) would claim more than
    // the whole: the share is capped, and the merge itself refuses overlaps.
    let done = if whole > 0.0 { (held / whole).min(1.0) } else { 0.0 };
    let missing_tiles = base.tile.map(|[_, n]| {
        let have: Vec<u32> = mine.iter().filter_map(|r| r.tile.filter(|t| t[1] == n).map(|t| t[0])).collect();
        ((0..n).filter(|i| !have.contains(i)).collect(), n)
    });
    let spent: f64 = mine.iter().filter_map(|r| r.stats.get("render_ms").and_then(|v| v.as_f64())).sum();
    let remaining_ms = (held > 0.0 && spent > 0.0).then(|| spent / held * (whole - held).max(0.0));
    PartStatus { parts: mine.len(), others, missing_tiles, done, remaining_ms }
}

impl std::fmt::Display for PartStatus {
    /// A few lines for a person watching a split render.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.parts == 0 {
            writeln!(f, "no parts yet")?;
        } else {
            writeln!(f, "{} part{} hold {:.1}% of the frame's samples", self.parts, if self.parts == 1 { "" } else { "s" }, self.done * 100.0)?;
        }
        if let Some((missing, n)) = &self.missing_tiles {
            if missing.is_empty() {
                writeln!(f, "every tile of {n} is there")?;
            } else {
                let list: Vec<String> = missing.iter().map(|i| format!("{i}/{n}")).collect();
                writeln!(f, "missing tiles: {}", list.join(", "))?;
            }
        }
        match self.remaining_ms {
            Some(ms) if self.done < 1.0 => writeln!(f, "about {:.1} s of rendering left, at the finished parts' pace", ms / 1e3)?,
            _ if self.done >= 1.0 => writeln!(f, "complete: ready for pinhole merge")?,
            _ => {}
        }
        for (path, why) in &self.others {
            writeln!(f, "{}: not counted: {why}", path.display())?;
        }
        Ok(())
    }
}
