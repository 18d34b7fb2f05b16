//! Command lines for planned work (`chart --plan`, `gallery --plan`): each
//! job is one `pinhole` invocation that a shell, a Slurm array task or a
//! Kubernetes pod runs on its own. The lines name the binary that wrote
//! the plan by its full path and every file by an absolute path, so they run
//! from any folder of a machine that sees the same files.
//!
//! A render job's options are written from the `RenderSettings` it must
//! render with, then parsed back as the job will parse them: a setting the
//! command line cannot express is refused when planning, not discovered as
//! a wrong image afterwards.

use crate::render::{self, RenderSettings};
use std::path::{Path, PathBuf};

/// The file of a plan's job lines, one command per line.
pub const JOBS_FILE: &str = "jobs.txt";
/// The file holding the one command that assembles the jobs' results.
pub const ASSEMBLE_FILE: &str = "assemble.txt";

/// `s` as one shell word: as it is when it holds only safe characters,
/// else in single quotes.
pub fn shell_quote(s: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "-_./:=,+@%".contains(c);
    if !s.is_empty() && s.chars().all(safe) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// One line of shell words.
pub fn shell_line(argv: &[String]) -> String {
    argv.iter().map(|a| shell_quote(a)).collect::<Vec<_>>().join(" ")
}

/// The running pinhole binary's full path, for the jobs to call.
pub fn program() -> Result<String, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot tell where the pinhole binary is, to write it into the plan: {e}"))?;
    Ok(exe.to_string_lossy().into_owned())
}

/// The scene argument for a job: a file as an absolute path (jobs run from
/// other folders), a built-in name as it is.
pub fn scene_for_jobs(scene_arg: &str) -> String {
    let p = Path::new(scene_arg);
    match p.exists().then(|| std::fs::canonicalize(p)).and_then(Result::ok) {
        Some(abs) => abs.to_string_lossy().into_owned(),
        None => scene_arg.to_string(),
    }
}

/// An absolute path for a file a job writes or reads.
pub fn absolute(p: &Path) -> Result<PathBuf, String> {
    std::path::absolute(p).map_err(|e| format!("{}: cannot make the path absolute: {e}", p.display()))
}

/// The options that make `pinhole render` draw with `s`: the size, seed and
/// renderer always, every other setting where it differs from the
/// command line's default (`RenderSettings::default()`).
pub fn render_option_args(renderer: &str, s: &RenderSettings, camera: Option<&str>, glossy_model: Option<&str>) -> Vec<String> {
    let d = RenderSettings::default();
    let mut out: Vec<String> = Vec::new();
    let mut opt = |k: &str, v: String| {
        out.push(format!("--{k}"));
        out.push(v);
    };
    opt("renderer", renderer.to_string());
    if let Some(c) = camera {
        opt("camera", c.to_string());
    }
    if let Some(m) = glossy_model {
        opt("glossy-model", m.to_string());
    }
    opt("width", s.width.to_string());
    opt("height", s.height.to_string());
    opt("seed", s.gi.seed.to_string());
    // Floats are written in Rust's shortest form, which parses back to the same bits.
    let f = |v: f32| format!("{v}");
    if s.spp != d.spp {
        opt("spp", s.spp.to_string());
    }
    if s.view != d.view {
        opt("view", s.view.name().to_string());
    }
    if s.shadows != d.shadows {
        opt("shadows", s.shadows.name().to_string());
    }
    if s.interpolation != d.interpolation {
        opt("interpolation", s.interpolation.name().to_string());
    }
    if s.max_depth != d.max_depth {
        opt("max-depth", s.max_depth.to_string());
    }
    if s.shadow_bump != d.shadow_bump {
        opt("bump", f(s.shadow_bump));
    }
    if s.shadow_map_size != d.shadow_map_size {
        opt("shadow-map-size", s.shadow_map_size.to_string());
    }
    if s.shadow_map_bias != d.shadow_map_bias {
        opt("shadow-bias", f(s.shadow_map_bias));
    }
    if s.shadow_volume != d.shadow_volume {
        opt("shadow-volume", s.shadow_volume.name().to_string());
    }
    if s.msaa != d.msaa {
        opt("msaa", s.msaa.to_string());
    }
    if s.early_depth != d.early_depth {
        opt("early-depth", s.early_depth.to_string());
    }
    let (g, dg) = (&s.gi, &d.gi);
    if g.mode != dg.mode {
        opt("gi", g.mode.name().to_string());
    }
    if g.bounces != dg.bounces {
        opt("bounces", g.bounces.map_or("inf".to_string(), |b| b.to_string()));
    }
    if g.ao_samples != dg.ao_samples {
        opt("ao-samples", g.ao_samples.to_string());
    }
    if g.ao_distance != dg.ao_distance {
        opt("ao-distance", f(g.ao_distance));
    }
    if g.photons != dg.photons {
        opt("photons", g.photons.to_string());
    }
    if g.photon_k != dg.photon_k {
        opt("photon-k", g.photon_k.to_string());
    }
    if g.final_gather != dg.final_gather {
        opt("final-gather", g.final_gather.to_string());
    }
    if let Some(a) = s.adaptive {
        opt("adaptive", f(a));
    }
    if s.subsample.step != d.subsample.step {
        opt("subsample", s.subsample.step.to_string());
    }
    if let Some(c) = s.subsample.contrast {
        opt("subsample-contrast", f(c));
    }
    if s.depth_buffer != d.depth_buffer {
        opt("depth-buffer", s.depth_buffer.name().to_string());
    }
    if s.lines != d.lines {
        opt("lines", s.lines.name().to_string());
    }
    if s.texture_filter != d.texture_filter {
        opt("texture-filter", s.texture_filter.name().to_string());
    }
    if s.reflections != d.reflections {
        opt("reflections", s.reflections.name().to_string());
    }
    if s.clip != d.clip {
        opt("clip", s.clip.name().to_string());
    }
    if s.cull_instances != d.cull_instances {
        opt("cull-instances", s.cull_instances.to_string());
    }
    if s.light_samples != d.light_samples {
        opt("light-samples", s.light_samples.to_string());
    }
    if s.mis != d.mis {
        opt("mis", if s.mis { "on" } else { "off" }.to_string());
    }
    if s.packets != d.packets {
        opt("packets", if s.packets { "on" } else { "off" }.to_string());
    }
    if s.subpixel_bits != d.subpixel_bits {
        opt("subpixel-bits", s.subpixel_bits.to_string());
    }
    if s.shadow_filter != d.shadow_filter {
        opt("shadow-filter", s.shadow_filter.name().to_string());
    }
    if s.pcf_radius != d.pcf_radius {
        opt("pcf-radius", f(s.pcf_radius));
    }
    if s.display.exposure_ev != d.display.exposure_ev {
        opt("exposure", f(s.display.exposure_ev));
    }
    if s.display.tonemap != d.display.tonemap {
        opt("tonemap", s.display.tonemap.name().to_string());
    }
    if s.display.gamma != d.display.gamma {
        opt("gamma", s.display.gamma.name().to_string());
    }
    if s.affine {
        out.push("--affine".into());
    }
    out
}

/// The top-level keys whose values differ between two settings, as JSON.
pub fn differing_settings(a: &RenderSettings, b: &RenderSettings) -> Vec<String> {
    let (Ok(a), Ok(b)) = (serde_json::to_value(a), serde_json::to_value(b)) else { return vec!["(unreadable settings)".into()] };
    let (Some(a), Some(b)) = (a.as_object(), b.as_object()) else { return Vec::new() };
    let mut keys: Vec<String> = a.keys().chain(b.keys()).filter(|k| a.get(*k) != b.get(*k)).cloned().collect();
    keys.sort();
    keys.dedup();
    keys
}

/// Writes a plan into `dir` (created; refused when it already holds files,
/// whose stale results `--from` would take for the new ones): `jobs.txt`
/// with one line per job and `assemble.txt` with the command that gathers
/// their results. Says on stderr what was written.
pub fn write_plan(dir: &Path, jobs: &[Vec<String>], assemble: &str) -> Result<(), String> {
    if dir.exists() && !dir.is_dir() {
        return Err(format!("{}: exists and is not a folder", dir.display()));
    }
    if dir.is_dir() && std::fs::read_dir(dir).map_err(|e| format!("{}: cannot list the folder: {e}", dir.display()))?.next().is_some() {
        return Err(format!("{}: the folder is not empty; plan into a new or empty folder (results of another plan there would be taken for this one's)", dir.display()));
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create the folder {}: {e}", dir.display()))?;
    let lines: String = jobs.iter().map(|j| shell_line(j) + "\n").collect();
    crate::image_io::write_atomic(&dir.join(JOBS_FILE), lines.as_bytes())?;
    crate::image_io::write_atomic(&dir.join(ASSEMBLE_FILE), format!("{assemble}\n").as_bytes())?;
    eprintln!("wrote {} jobs to {} and the command that assembles their results to {}", jobs.len(), dir.join(JOBS_FILE).display(), dir.join(ASSEMBLE_FILE).display());
    Ok(())
}

/// This process's command line with `--plan DIR` turned into `--from DIR`
/// (DIR absolute), run from the current folder so that relative paths (the
/// scene, `-o`) mean what they meant here: the command that assembles a plan.
pub fn assemble_command(plan_dir: &Path) -> Result<String, String> {
    let cwd = std::env::current_dir().map_err(|e| format!("cannot tell the current folder: {e}"))?;
    let dir = absolute(plan_dir)?.to_string_lossy().into_owned();
    let mut out = vec![program()?];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--plan" {
            args.next();
            out.extend(["--from".to_string(), dir.clone()]);
        } else if a.starts_with("--plan=") {
            out.extend(["--from".to_string(), dir.clone()]);
        } else {
            out.push(a);
        }
    }
    Ok(format!("cd {} && {}", shell_quote(&cwd.to_string_lossy()), shell_line(&out)))
}

/// The renderer's canonical name (`raytrace` -> `raytrace:bvh`).
pub fn renderer_name(name: &str) -> Result<String, String> {
    Ok(render::renderer_by_name(name)?.name().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_quoted_only_where_a_shell_would_split_them() {
        assert_eq!(shell_quote("--spp"), "--spp");
        assert_eq!(shell_quote("/tmp/a b.exr"), "'/tmp/a b.exr'");
        assert_eq!(shell_quote("it's"), "'it'\\''s'");
        assert_eq!(shell_quote(""), "''");
        assert_eq!(shell_quote("&&"), "'&&'");
    }
}
