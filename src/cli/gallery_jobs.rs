//! The gallery split into jobs: `gallery --plan DIR` writes one line per
//! case, `pinhole gallery --case NAME -o DIR/case-NAME --exr`, which
//! renders the case's truth, failing and cured images and keeps them as
//! linear EXRs; `gallery --from DIR` reads those images back and judges
//! them as `gallery` judges the images it renders (`gallery::judge`), so
//! the JSON is the same and the sheet draws the same pixels.
//!
//! Also the parts `pinhole gallery` itself runs on: the case list, the
//! output folder, the progress line and the two files it writes.

use super::plan_lines;
use crate::gallery::{self, CaseImages, CaseResult, GalleryCase};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Every case, or the one named.
pub fn cases(only: Option<&str>) -> Result<Vec<GalleryCase>, String> {
    Ok(match only {
        Some(name) => vec![gallery::case_by_name(name)?],
        None => gallery::cases(),
    })
}

/// The gallery's folder, created, and its sheet writable.
pub fn prepare_output(dir: &Path) -> Result<(), String> {
    if dir.exists() && !dir.is_dir() {
        return Err(format!("{}: exists and is not a directory", dir.display()));
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create the directory {}: {e}", dir.display()))?;
    crate::image_io::check_writable(&dir.join("gallery.png"))
}

/// The line a measured case prints.
pub fn report(r: &CaseResult, secs: f64) {
    eprintln!(
        "    failing {}: {} wrong px; cured {}: {} wrong px (threshold {}){} in {secs:.1} s",
        r.failing.setting,
        r.failing.wrong_pixels,
        r.cured.setting,
        r.cured.wrong_pixels,
        r.threshold,
        if r.demonstrated() { "" } else { " NOT DEMONSTRATED" },
    );
}

/// DIR/gallery.png and DIR/gallery.json, both or neither.
pub fn write_gallery(dir: &Path, results: &[(CaseResult, &str)], start: Instant) -> Result<(), String> {
    let png = gallery::sheet::draw_png(results)?;
    let json = serde_json::to_value(results.iter().map(|(r, _)| r).collect::<Vec<_>>()).map_err(|e| e.to_string())?;
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n";
    crate::image_io::write_all_atomic(&[(&dir.join("gallery.png"), &png), (&dir.join("gallery.json"), text.as_bytes())])?;
    eprintln!("wrote {} and {} in {:.1} s", dir.join("gallery.png").display(), dir.join("gallery.json").display(), start.elapsed().as_secs_f64());
    Ok(())
}

const KINDS: [&str; 3] = ["truth", "failing", "cured"];

fn image_file(dir: &Path, case: &str, kind: &str) -> PathBuf {
    dir.join(format!("{case}-{kind}.exr"))
}

/// A case's three images as DIR/CASE-truth.exr, -failing.exr, -cured.exr.
pub fn write_case_images(dir: &Path, case: &str, images: &CaseImages) -> Result<(), String> {
    for (kind, pixels) in KINDS.into_iter().zip([&images.truth, &images.failing, &images.cured]) {
        crate::image_io::save_image(&image_file(dir, case, kind), images.width, images.height, pixels, 1.0)?;
    }
    Ok(())
}

/// Where the job of `case` writes its images.
fn job_dir(dir: &Path, case: &str) -> PathBuf {
    dir.join(format!("case-{case}"))
}

/// `gallery --plan DIR`: one line per case.
pub fn plan(dir: &Path, only: Option<&str>) -> Result<(), String> {
    let cases = cases(only)?;
    let (program, abs) = (plan_lines::program()?, plan_lines::absolute(dir)?);
    let jobs: Vec<Vec<String>> = cases
        .iter()
        .map(|c| {
            let out = job_dir(&abs, c.name).to_string_lossy().into_owned();
            vec![program.clone(), "gallery".into(), "--case".into(), c.name.into(), "-o".into(), out, "--exr".into()]
        })
        .collect();
    plan_lines::write_plan(dir, &jobs, &plan_lines::assemble_command(dir)?)
}

/// `gallery --from DIR`: the cases' images read back and judged.
pub fn assemble(from: &Path, output: &Path, only: Option<&str>, exr: bool) -> Result<(), String> {
    let cases = cases(only)?;
    if !from.join(plan_lines::JOBS_FILE).is_file() {
        return Err(format!("{}: no {} there; write a plan with --plan first", from.display(), plan_lines::JOBS_FILE));
    }
    prepare_output(output)?;
    let start = Instant::now();
    let mut results = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        let job = job_dir(from, case.name);
        let mut read = Vec::new();
        for kind in KINDS {
            let path = image_file(&job, case.name, kind);
            if !path.exists() {
                return Err(format!("{}: missing; run line {} of {} first", path.display(), i + 1, from.join(plan_lines::JOBS_FILE).display()));
            }
            read.push(crate::image_io::load_image(&path)?);
        }
        let (w, h) = (read[0].width, read[0].height);
        if read.iter().any(|r| (r.width, r.height) != (w, h)) {
            return Err(format!("{}: the case's three images differ in size", job.display()));
        }
        let mut pixels = read.into_iter().map(|r| r.pixels);
        let (truth, failing, cured) = (pixels.next().unwrap_or_default(), pixels.next().unwrap_or_default(), pixels.next().unwrap_or_default());
        let images = CaseImages { truth, failing, cured, width: w, height: h };
        if exr {
            write_case_images(output, case.name, &images)?;
        }
        eprintln!("[{}/{}] {}: {}", i + 1, cases.len(), case.name, case.method);
        let r = gallery::judge(case, images)?;
        report(&r, 0.0);
        results.push((r, case.explanation));
    }
    write_gallery(output, &results, start)
}
