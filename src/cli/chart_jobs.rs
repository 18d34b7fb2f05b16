//! A chart split into jobs: `chart --plan DIR` writes one `pinhole render`
//! line per configuration (a `--tile 0/1` part: the whole frame, with its
//! settings and timing in the file's header) and one per sample range of a
//! path-traced reference; `chart --from DIR` reads their results back,
//! checks each was rendered as planned, merges the reference and measures
//! every configuration against it, as `chart` measures in one process.
//!
//! The reference is rendered in the same sample ranges either way
//! (`chart::reference::reference_ranges`), so a chart from a plan has the
//! same errors as one measured in one process, to the bit. Its times are
//! each job's `render_ms`: one frame on whatever machine ran it, shadow
//! maps and photon maps built during the frame included.

use super::plan_lines::{self, render_option_args};
use super::render_opts::RenderOpts;
use super::{check_render_job, Loaded};
use crate::chart::reference::{self, Reference, ReferenceSource};
use crate::chart::{glossy_models, Configuration, Measurement};
use crate::part_file::PartFile;
use crate::render::{RenderSettings, DEFAULT_RAYTRACE};
use std::path::{Path, PathBuf};

/// Where the job of sample range `k` of the reference writes.
fn reference_file(dir: &Path, k: usize) -> PathBuf {
    dir.join(format!("reference-{k:03}.exr"))
}

/// Where the job of configuration `i` writes.
fn config_file(dir: &Path, i: usize) -> PathBuf {
    dir.join(format!("config-{i:03}.exr"))
}

fn text(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// The sample ranges the plan renders the reference in (none for a file).
fn reference_jobs(source: &ReferenceSource) -> Vec<std::ops::Range<u32>> {
    match source {
        ReferenceSource::PathTraced { spp } => reference::reference_ranges(*spp),
        ReferenceSource::File(_) => Vec::new(),
    }
}

/// `chart --plan DIR`: the job lines, each checked to render what the
/// chart would measure, and the line that assembles them.
/// `--camera` and `--threads` are passed on to every job as given.
pub fn plan(dir: &Path, scene_arg: &str, opts: &RenderOpts, l: &Loaded, configs: &[Configuration], source: &ReferenceSource) -> Result<(), String> {
    let (program, scene) = (plan_lines::program()?, plan_lines::scene_for_jobs(scene_arg));
    let camera = opts.camera.as_deref();
    let threads: Vec<String> = opts.threads.map(|n| vec!["--threads".to_string(), n.to_string()]).unwrap_or_default();
    let abs = plan_lines::absolute(dir)?;
    let (w, h) = (l.settings.width, l.settings.height);
    let render = |out: PathBuf| vec![program.clone(), "render".to_string(), scene.clone(), "-o".to_string(), text(&out)];
    let mut jobs = Vec::new();
    if let ReferenceSource::File(f) = source {
        // Checked now rather than after the jobs have run.
        reference::load_reference_file(f, w, h)?;
    }
    if let ReferenceSource::PathTraced { spp } = *source {
        let settings = reference::path_settings(&l.prepared, w, h, spp);
        for (k, range) in reference_jobs(source).into_iter().enumerate() {
            let mut argv = render(reference_file(&abs, k));
            argv.extend(render_option_args(DEFAULT_RAYTRACE, &settings, camera, l.glossy_model));
            argv.extend(["--sample-range".to_string(), format!("{}..{}", range.start, range.end)]);
            argv.extend(threads.iter().cloned());
            check_render_job(&argv, &l.prepared.scene, &plan_lines::renderer_name(DEFAULT_RAYTRACE)?, &settings, "the reference")?;
            jobs.push(argv);
        }
    }
    for (i, c) in configs.iter().enumerate() {
        let model = c.glossy_model.map(glossy_models::name).or(l.glossy_model);
        let mut argv = render(config_file(&abs, i));
        argv.extend(render_option_args(&c.renderer, &c.settings, camera, model));
        argv.extend(["--tile".to_string(), "0/1".to_string()]);
        argv.extend(threads.iter().cloned());
        check_render_job(&argv, &c.scene(&l.prepared.scene), &plan_lines::renderer_name(&c.renderer)?, &c.settings, &c.label)?;
        jobs.push(argv);
    }
    plan_lines::write_plan(dir, &jobs, &plan_lines::assemble_command(dir)?)
}

/// The results of a plan's jobs, read from its folder.
pub struct Planned {
    dir: PathBuf,
    /// How many job lines render the reference (they come first).
    reference_lines: usize,
    width: u32,
    height: u32,
    reference_settings: Option<RenderSettings>,
    source: ReferenceSource,
    /// The glossy model `--glossy-model` switched the scene to.
    glossy_model: Option<&'static str>,
}

impl Planned {
    pub fn new(dir: &Path, l: &Loaded, source: &ReferenceSource) -> Result<Planned, String> {
        if !dir.join(plan_lines::JOBS_FILE).is_file() {
            return Err(format!("{}: no {} there; write a plan with --plan first", dir.display(), plan_lines::JOBS_FILE));
        }
        let (w, h) = (l.settings.width, l.settings.height);
        let reference_settings = match source {
            ReferenceSource::PathTraced { spp } => Some(reference::path_settings(&l.prepared, w, h, *spp)),
            ReferenceSource::File(_) => None,
        };
        Ok(Planned {
            dir: dir.to_path_buf(),
            reference_lines: reference_jobs(source).len(),
            width: w,
            height: h,
            reference_settings,
            source: source.clone(),
            glossy_model: l.glossy_model,
        })
    }

    /// A job's result, refused in one sentence when it is missing (naming
    /// the job's line) or not a part.
    fn read(&self, path: &Path, line: usize) -> Result<(PathBuf, PartFile), String> {
        if !path.exists() {
            return Err(format!("{}: missing; run line {line} of {} first", path.display(), self.dir.join(plan_lines::JOBS_FILE).display()));
        }
        crate::part_file::read(path).map(|f| (path.to_path_buf(), f))
    }

    /// Refuses a result rendered otherwise than planned (another plan's, or
    /// a plan made with other options than these).
    fn check(&self, (path, part): &(PathBuf, PartFile), renderer: &str, settings: &RenderSettings, glossy_model: Option<&str>, what: &str) -> Result<(), String> {
        let r = &part.record;
        let planned = serde_json::to_value(settings).map_err(|e| e.to_string())?;
        let renderer = plan_lines::renderer_name(renderer)?;
        if r.renderer != renderer || r.settings != planned || r.stats.get("glossy_model").and_then(|v| v.as_str()) != glossy_model {
            return Err(format!(
                "{}: not rendered as this chart plans {what} (renderer, settings or glossy model differ); give --from the scene and options the plan was made with",
                path.display()
            ));
        }
        Ok(())
    }

    /// The reference merged from its sample ranges' parts; `None` when it
    /// is a file (loaded as `chart` loads it).
    pub fn reference(&self) -> Result<Option<Reference>, String> {
        let Some(settings) = &self.reference_settings else { return Ok(None) };
        let mut parts = Vec::new();
        for k in 0..self.reference_lines {
            let part = self.read(&reference_file(&self.dir, k), k + 1)?;
            self.check(&part, DEFAULT_RAYTRACE, settings, self.glossy_model, "the reference")?;
            parts.push(part);
        }
        let merged = crate::part_merge::merge(&parts)?;
        Ok(Some(Reference { pixels: merged.pixels, width: self.width, height: self.height, name: format!("{}, from {} jobs", self.source.describe(), parts.len()) }))
    }

    /// Configuration `i`'s row: its job's image against `truth`, timed by
    /// the job's own `render_ms`.
    pub fn measurement(&self, i: usize, c: &Configuration, truth: &Reference) -> Result<Measurement, String> {
        let part = self.read(&config_file(&self.dir, i), self.reference_lines + i + 1)?;
        let model = c.glossy_model.map(glossy_models::name).or(self.glossy_model);
        self.check(&part, &c.renderer, &c.settings, model, &format!("configuration {}", c.label))?;
        let r = &part.1.record;
        if r.region != [0, 0, self.width, self.height] || !r.holds_final_values() {
            return Err(format!("{}: holds only part of the frame; its job renders all of it (--tile 0/1)", part.0.display()));
        }
        let ms = r.stats.get("render_ms").and_then(|v| v.as_f64()).unwrap_or(f64::NAN);
        Measurement::of_image(c, ms, &part.1.pixels, truth)
    }
}
