//! The command line: `render`, `bench`, `compare`, `pixel`, `chart`, `gallery`, `list`;
//! without a subcommand it asks `main` to open the viewer. Errors are returned
//! as one sentence; `main` prints them and exits non-zero.

use crate::render;
use crate::render::inspect::debug::View;
use crate::render::{PreparedScene, RayCounts, RenderSettings, ShadowMode};
use crate::scene::Scene;
use clap::{Parser, Subcommand};
use serde_json::json;
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

mod chart_jobs;
mod gallery_jobs;
mod interrupt;
mod part_opts;
mod plan_lines;
mod render_opts;
mod usage_error;
use render_opts::RenderOpts;

#[derive(Parser)]
#[command(name = "pinhole", version, about = "Watch a CPU ray tracer and a CPU rasterizer render the same scene.")]
#[command(args_conflicts_with_subcommands = true)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Scene to open in the viewer: a .toml, a mesh (.obj, .ply), a glTF (.gltf, .glb) or a built-in name.
    scene: Option<String>,
    /// Open the window, wait for the full-quality frame, save a screenshot of the window there, exit.
    #[arg(long, value_name = "OUT.png")]
    screenshot: Option<PathBuf>,
}

#[derive(Subcommand)]
enum Command {
    /// Render once without a window.
    Render {
        scene: String,
        /// Output image: .png (sRGB 8-bit), .exr (linear f32) or .ppm.
        #[arg(short = 'o', long = "output", value_name = "OUT")]
        output: PathBuf,
        #[command(flatten)]
        opts: RenderOpts,
        #[command(flatten)]
        part: part_opts::PartOpts,
        /// The error views' ground truth (linear .exr of the frame's size);
        /// default: the scene's [render] reference.
        #[arg(long, value_name = "FILE.exr")]
        reference: Option<PathBuf>,
        /// Also write these layers of raw values into the output EXR:
        /// depth,normal,albedo,position,uv,id,material (comma-separated).
        #[arg(long, value_name = "LIST")]
        aov: Option<String>,
        /// Write run statistics as JSON (`-` for stdout).
        #[arg(long, value_name = "FILE")]
        stats: Option<String>,
    },
    /// Assemble partial renders (--tile, --sample-range) into the whole frame.
    Merge {
        /// The parts (.exr files written by `render --tile` or `--sample-range`).
        #[arg(required_unless_present = "status", value_name = "PART.exr")]
        parts: Vec<PathBuf>,
        /// The whole frame (.exr).
        #[arg(short = 'o', long = "output", value_name = "OUT", required_unless_present = "status")]
        output: Option<PathBuf>,
        /// Write the whole render's statistics as JSON (`-` for stdout).
        #[arg(long, value_name = "FILE")]
        stats: Option<String>,
        /// Instead of merging: which parts in DIR exist, which tiles are
        /// missing, and about how much rendering is left.
        #[arg(long, value_name = "DIR", conflicts_with_all = ["parts", "output", "stats"])]
        status: Option<PathBuf>,
    },
    /// Render warm frames and print timing statistics as JSON.
    Bench {
        scene: String,
        #[command(flatten)]
        opts: RenderOpts,
        /// Number of timed frames (after one warm-up frame).
        #[arg(long, default_value_t = 5)]
        frames: u32,
        /// Time the viewer's display pass instead of rendering: the display
        /// transform (--exposure, --tonemap, --gamma), false colour and the
        /// log-luminance histogram of one rendered frame, --frames times.
        #[arg(long = "display-pass")]
        display_pass: bool,
    },
    /// The debug record of one pixel, replayed exactly as the renderer computed it.
    Pixel {
        scene: String,
        x: u32,
        y: u32,
        #[command(flatten)]
        opts: RenderOpts,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Error metrics between two images (.exr or .png).
    Compare {
        a: PathBuf,
        b: PathBuf,
        #[arg(long)]
        json: bool,
    },
    /// Speed-versus-accuracy chart: error against frame time of every method
    /// that matters for the scene (or of each renderer as spp grows), + OUT.csv beside it.
    Chart {
        scene: String,
        #[arg(short = 'o', long = "output", value_name = "OUT.png")]
        output: PathBuf,
        /// methods: renderers, samples, shadow maps, interpolation, indirect light;
        /// gi: each method of indirect light as a curve (path at each of --spp-list);
        /// spp: each of --renderers at each of --spp-list.
        #[arg(long, default_value = "methods")]
        sweep: String,
        /// Error on the chart's vertical axis: rel-rmse | flip (the CSV has both).
        #[arg(long, default_value = "rel-rmse")]
        metric: String,
        /// --sweep spp: renderers to compare (comma-separated).
        #[arg(long, default_value = "raytrace,rasterize")]
        renderers: String,
        /// --sweep spp: samples per pixel to sweep (comma-separated).
        #[arg(long = "spp-list", default_value = "1,4,16,64")]
        spp_list: String,
        /// Reference image (linear .exr); default: the scene's [render] reference, else
        /// (methods) a path-traced image at --reference-spp, cached, or (spp) raytrace:bvh.
        #[arg(long)]
        reference: Option<PathBuf>,
        #[arg(long = "reference-spp", default_value_t = 256)]
        reference_spp: u32,
        /// --sweep gi: a peer renderer's curve to draw beside ours, as a CSV with the
        /// header series,label,ms,rel_rmse (scripts/gi_chart.sh measures Mitsuba's).
        #[arg(long, value_name = "FILE.csv")]
        peer: Option<PathBuf>,
        /// Instead of measuring (--sweep methods|gi): write one `pinhole render` command
        /// line per configuration and per sample range of the reference to DIR/jobs.txt,
        /// and the command that assembles their results to DIR/assemble.txt.
        #[arg(long, value_name = "DIR", conflicts_with = "from")]
        plan: Option<PathBuf>,
        /// Assemble the chart from the results of the jobs `--plan DIR` wrote (give
        /// the same scene and options as the plan had).
        #[arg(long, value_name = "DIR")]
        from: Option<PathBuf>,
        #[command(flatten)]
        opts: RenderOpts,
    },
    /// The stress gallery: every case's failing and cured images against its
    /// truth, as DIR/gallery.png (contact sheet) and DIR/gallery.json.
    Gallery {
        #[arg(short = 'o', long = "output", value_name = "DIR")]
        output: PathBuf,
        /// Run only this case (see the names in gallery.json or an error listing them).
        #[arg(long, value_name = "NAME")]
        case: Option<String>,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Also write each case's truth, failing and cured images as linear EXRs
        /// (CASE-truth.exr, CASE-failing.exr, CASE-cured.exr) in DIR.
        #[arg(long)]
        exr: bool,
        /// Instead of measuring: write one command line per case to DIR/jobs.txt and
        /// the command that assembles their results to DIR/assemble.txt.
        #[arg(long, value_name = "DIR", conflicts_with = "from")]
        plan: Option<PathBuf>,
        /// Assemble the gallery from the results of the jobs `--plan DIR` wrote.
        #[arg(long, value_name = "DIR")]
        from: Option<PathBuf>,
    },
    /// List renderers, views and built-in scenes.
    List,
}

/// What is left to do once the command line ran: the viewer is not part of
/// the core, so opening it is the caller's job.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// The command ran to completion.
    Done,
    /// No subcommand: open the viewer on `scene` (`None`: the last run's or
    /// the default scene); with `screenshot`, save a screenshot of the
    /// window there once the full-quality frame is in, and exit.
    OpenViewer { scene: Option<String>, screenshot: Option<PathBuf> },
}

/// The command line's grammar. Negative numbers reach the value parsers,
/// which then name the option and its range, instead of reading as unknown
/// flags. Options' values may start with '-' (`--bump -1e-9` is a value out
/// of range, not an unknown flag `-1`); so may positional numbers.
fn command() -> clap::Command {
    use clap::CommandFactory;
    let hyphens = |a: clap::Arg| if a.get_action().takes_values() && !a.is_positional() { a.allow_hyphen_values(true) } else { a };
    Cli::command().allow_negative_numbers(true).mut_subcommands(|s| s.allow_negative_numbers(true).mut_args(hyphens))
}

/// Parses the arguments and runs the command.
pub fn run() -> Result<Outcome, String> {
    use clap::FromArgMatches;
    let command = command();
    let parsed = command.clone().try_get_matches().and_then(|m| Cli::from_arg_matches(&m));
    let cli = match parsed {
        Ok(c) => c,
        Err(e) if e.use_stderr() => {
            eprintln!("pinhole: {}", usage_error::one_sentence(&e, &command));
            std::process::exit(2);
        }
        Err(e) => {
            // Help and version go to stdout with success.
            let _ = e.print();
            std::process::exit(0);
        }
    };
    if cli.command.is_some() {
        interrupt::install();
    }
    let ran = match cli.command {
        None => return Ok(Outcome::OpenViewer { scene: cli.scene, screenshot: cli.screenshot }),
        Some(Command::Render { scene, output, opts, part, reference, aov, stats }) => cmd_render(&scene, &output, &opts, &part, reference.as_deref(), aov.as_deref(), stats.as_deref()),
        Some(Command::Merge { status: Some(dir), .. }) => crate::part_status::status(&dir).map(|s| print!("{s}")),
        Some(Command::Merge { parts, output: Some(output), stats, status: None }) => cmd_merge(&parts, &output, stats.as_deref()),
        Some(Command::Merge { output: None, .. }) => Err("pinhole merge needs -o OUT.exr (or --status DIR)".into()),
        Some(Command::Bench { scene, opts, frames, display_pass: false }) => cmd_bench(&scene, &opts, frames),
        Some(Command::Bench { scene, opts, frames, display_pass: true }) => cmd_bench_display(&scene, &opts, frames),
        Some(Command::Compare { a, b, json }) => cmd_compare(&a, &b, json),
        Some(Command::Pixel { scene, x, y, opts, json }) => cmd_pixel(&scene, x, y, &opts, json),
        Some(Command::Chart { scene, output, sweep, metric, renderers, spp_list, reference, reference_spp, peer, plan, from, opts }) => {
            let jobs = match (&plan, &from) {
                (Some(dir), _) => Jobs::Plan(dir),
                (_, Some(dir)) => Jobs::From(dir),
                _ => Jobs::Run,
            };
            match sweep.as_str() {
                _ if peer.is_some() && sweep != "gi" => Err("--peer: a peer's curve is drawn on --sweep gi charts only".to_string()),
                "methods" => cmd_chart_methods(&scene, &output, &metric, reference.as_deref(), reference_spp, None, &opts, jobs),
                "gi" => parse_spp_list(&spp_list).and_then(|spps| {
                    cmd_chart_methods(&scene, &output, &metric, reference.as_deref(), reference_spp, Some((&spps, peer.as_deref())), &opts, jobs)
                }),
                "spp" if !matches!(jobs, Jobs::Run) => Err("--plan and --from split --sweep methods and --sweep gi charts; the spp sweep runs in one process".to_string()),
                "spp" => cmd_chart(&scene, &output, &renderers, &spp_list, reference.as_deref(), reference_spp, &opts),
                other => Err(format!("--sweep: \"{other}\" is not one of methods, gi, spp")),
            }
        }
        Some(Command::Gallery { case, plan: Some(dir), .. }) => gallery_jobs::plan(&dir, case.as_deref()),
        Some(Command::Gallery { output, case, exr, from: Some(dir), .. }) => gallery_jobs::assemble(&dir, &output, case.as_deref(), exr),
        Some(Command::Gallery { output, case, threads, exr, .. }) => cmd_gallery(&output, case.as_deref(), threads, exr),
        Some(Command::List) => cmd_list(),
    };
    if interrupt::interrupted() {
        // Said by the handler already; nothing was written.
        std::process::exit(interrupt::EXIT_INTERRUPTED);
    }
    ran.map(|()| Outcome::Done)
}

/// Whether a chart or gallery measures in this process, writes its jobs
/// as command lines (`--plan DIR`), or assembles their results (`--from DIR`).
#[derive(Clone, Copy)]
enum Jobs<'a> {
    Run,
    Plan(&'a Path),
    From(&'a Path),
}

/// A scene loaded and prepared under the requested thread pool, with timings.
struct Loaded {
    /// `--glossy-model`: the model every glossy lobe was switched to.
    glossy_model: Option<&'static str>,
    prepared: PreparedScene,
    settings: RenderSettings,
    renderer: Box<dyn render::Renderer>,
    pool: rayon::ThreadPool,
    load_ms: f64,
}

/// Most frames `bench --frames` times: 10,000 frames of a slow scene are
/// already hours.
const MAX_BENCH_FRAMES: u32 = 10_000;

/// Most worker threads `--threads` starts: more only cost memory and start-up time.
const MAX_THREADS: usize = 256;

/// The worker threads of every subcommand: `--threads` (default: all
/// cores), at least 1 and capped at `MAX_THREADS` with a warning.
fn worker_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, String> {
    if threads == Some(0) {
        return Err("--threads must be at least 1".into());
    }
    let mut threads = threads.unwrap_or(0);
    if threads > MAX_THREADS {
        eprintln!("warning: --threads {threads} is more than {MAX_THREADS}; using {MAX_THREADS}");
        threads = MAX_THREADS;
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| format!("cannot start {threads} worker threads: {e}"))
}

fn load(scene_arg: &str, opts: &RenderOpts) -> Result<Loaded, String> {
    let renderer = render::renderer_by_name(&opts.renderer)?;
    // The options are checked before the scene loads (which can take seconds)
    // and written over the scene's settings once it has.
    opts.write_into(&mut RenderSettings::default())?;
    let glossy_model = opts.glossy_model()?;
    let pool = worker_pool(opts.threads)?;
    let start = Instant::now();
    let mut scene: Scene = crate::scene::load::load_scene_with_camera(scene_arg, opts.camera.as_deref())?;
    if let Some(model) = glossy_model {
        scene = crate::chart::glossy_models::switched(&scene, model);
    }
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let mut settings = RenderSettings::for_scene(&scene);
    opts.write_into(&mut settings)?;
    let admitted = render::admit::admit(renderer.as_ref(), &scene, &settings)?;
    // Said before the renderer loads its driver, which may fail.
    for notice in admitted.notices.iter().chain(&admitted.caveats) {
        eprintln!("note: {notice}");
    }
    renderer.ready(&admitted.settings)?;
    let prepared = pool.install(|| PreparedScene::new(scene));
    pool.install(|| render::admit::admit_prepared(&prepared, &admitted.settings))?;
    Ok(Loaded { glossy_model: glossy_model.map(crate::chart::glossy_models::name), prepared, settings: admitted.settings, renderer, pool, load_ms })
}

fn stats_json(l: &Loaded, render_ms: f64, counts: &RayCounts, spp: u32) -> serde_json::Value {
    let per_frame = |v: u64| v / spp.max(1) as u64 * spp.max(1) as u64;
    let mut j = json!({
        "renderer": l.renderer.name(),
        "scene": l.prepared.scene.name,
        "width": l.settings.width,
        "height": l.settings.height,
        "spp": spp,
        "threads": l.pool.current_num_threads(),
        "triangles": l.prepared.scene.total_triangles(),
        "flattened_triangles": l.prepared.scene.triangles.len(),
        "spheres": l.prepared.scene.spheres.len(),
        "load_ms": l.load_ms,
        "build_ms": l.prepared.build_ms,
        "bvh_depth": l.prepared.bvh.depth(),
        "render_ms": render_ms,
        "primary_rays": per_frame(counts.primary),
        "shadow_rays": counts.shadow,
        "secondary_rays": counts.secondary,
        "bvh_nodes_visited": counts.nodes,
        "primitive_tests": counts.tests,
        "samples_tested": counts.samples_tested,
        "samples_covered": counts.samples_covered,
        "fragments_shaded": counts.fragments_shaded,
        "depth_test_failures": counts.depth_fails,
        "instances": l.prepared.scene.instances.len(),
        "instances_drawn": counts.instances_drawn,
        "instances_culled": counts.instances_culled,
        "clip": l.settings.clip.name(),
        "shadows": l.settings.shadows.name(),
        "view": l.settings.view.name(),
        "interpolation": l.settings.interpolation.name(),
        "early_depth": l.settings.early_depth,
        "msaa": l.settings.msaa,
        "shadow_map_size": l.settings.shadow_map_size,
        "shadow_map_bias": l.settings.shadow_map_bias,
        "shadow_map_ms": (l.settings.shadows == ShadowMode::Map).then(|| l.prepared.shadow_maps(l.settings.shadow_map_size).build_ms),
        "shadow_volume": l.settings.shadow_volume.name(),
        "shadow_volume_ms": (l.settings.shadows == ShadowMode::Volume).then(|| l.prepared.shadow_volumes().build_ms),
        "gi": l.settings.gi.mode.name(),
        "seed": l.settings.gi.seed,
        "photons": (l.settings.gi.mode == render::transport::gi::GiMode::Photons).then(|| l.prepared.photon_map(&l.settings.gi, l.settings.shadow_bump).len()),
        // Samples that came out NaN or infinite, zeroed before any pixel saw them.
        "non_finite_samples": counts.non_finite,
    });
    // The display transform the 8-bit image went through (an EXR is linear).
    j["tonemap"] = json!(l.settings.display.tonemap.name());
    j["exposure_ev"] = json!(l.settings.display.exposure_ev);
    j["gamma"] = json!(l.settings.display.gamma.name());
    j["glossy_model"] = json!(l.glossy_model);
    j
}

/// The reference image an error view compares with: `--reference`, else
/// the scene's `[render] reference`, read at the frame's size and cut to
/// `part` when only a part is rendered. `None` for the other views (a
/// `--reference` they do not read is said in a note).
fn error_reference(l: &Loaded, given: Option<&Path>, part: Option<&render::FramePart>, tiled: bool) -> Result<Option<(PathBuf, Vec<crate::math::Radiance>)>, String> {
    let view = l.settings.view;
    if view.error_kind().is_none() {
        if let Some(path) = given {
            eprintln!("note: --reference {} is read by --view error, absolute-error and signed-error only; this render does not use it", path.display());
        }
        return Ok(None);
    }
    if tiled {
        return Err(format!("--view {} cannot be rendered as --tile parts: its scale spans the whole image (render the tiles shaded, merge them, and compare the result)", view.name()));
    }
    let Some(path) = given.map(Path::to_path_buf).or_else(|| l.prepared.scene.render.reference.clone()) else {
        return Err(format!("--view {} compares with a reference image: give --reference FILE.exr or set [render] reference in the scene", view.name()));
    };
    let image = crate::chart::reference::load_reference_file(&path, l.settings.width, l.settings.height)?;
    let pixels = match part {
        Some(p) => {
            let w = image.width as usize;
            p.y.clone().flat_map(|y| image.pixels[y as usize * w + p.x.start as usize..y as usize * w + p.x.end as usize].iter().copied()).collect()
        }
        None => image.pixels,
    };
    Ok(Some((path, pixels)))
}

fn cmd_render(scene_arg: &str, output: &Path, opts: &RenderOpts, part_opts: &part_opts::PartOpts, reference: Option<&Path>, aov: Option<&str>, stats: Option<&str>) -> Result<(), String> {
    let ext = output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    if !["png", "exr", "ppm"].contains(&ext.as_str()) {
        return Err(format!("{}: unknown image type (use .png, .exr or .ppm)", output.display()));
    }
    let aovs = aov.map(render::aov::parse_list).transpose()?.unwrap_or_default();
    if !aovs.is_empty() && ext != "exr" {
        return Err(format!("--aov writes named layers of an EXR, and {} is not one (use -o OUT.exr)", output.display()));
    }
    if !aovs.is_empty() && part_opts.is_partial() {
        return Err("--aov cannot go with --tile or --sample-range: a part for pinhole merge holds the image alone".into());
    }
    if part_opts.is_partial() && ext != "exr" {
        return Err(format!("{}: a part for pinhole merge (--tile, --sample-range) is written as .exr", output.display()));
    }
    crate::image_io::check_writable(output)?;
    if let Some(dest) = stats.filter(|d| *d != "-") {
        crate::image_io::check_writable(Path::new(dest))?;
    }
    let outputs: Vec<&Path> = std::iter::once(output).chain(stats.filter(|d| *d != "-").map(Path::new)).collect();
    crate::file_identity::check_outputs(&outputs)?;
    let l = load(scene_arg, opts)?;
    let part = part_opts.part(&l.settings)?;
    let truth = error_reference(&l, reference, part.as_ref(), part_opts.tile.is_some())?;
    if let Some(notice) = render::admit::aov_notice(l.renderer.as_ref(), &aovs) {
        eprintln!("note: {notice}");
    }
    // Now that every input is read: none of them may be an output.
    crate::file_identity::check_outputs(&outputs)?;
    let cancel = interrupt::flag();
    let rows_done = AtomicU64::new(0);
    let total_rows = match &part {
        Some(p) => p.height() as u64 * p.passes.len() as u64,
        None => l.settings.height as u64 * l.settings.spp as u64,
    };
    let started_unix_ms = unix_ms();
    let show_progress = std::io::stderr().is_terminal();
    let start = Instant::now();
    let done = AtomicBool::new(false);
    let result = std::thread::scope(|s| {
        s.spawn(|| progress_loop(&rows_done, total_rows, &done, show_progress));
        let bands = if show_progress { 32 } else { 1 };
        let r = l.pool.install(|| {
            render::render_frame_with(l.renderer.as_ref(), &l.prepared, &l.settings, cancel, render::FrameOptions { bands, rows_done: Some(&rows_done), part: part.clone(), ..render::FrameOptions::default() })
        });
        done.store(true, Ordering::Relaxed);
        r
    });
    let render_ms = start.elapsed().as_secs_f64() * 1e3;
    let mut frame = result.ok_or("the render was cancelled")?;
    if let Some(n) = frame.differing_pixels {
        eprintln!("{n} of {} pixels differ from raytrace:brute", frame.pixels.len());
    }
    let mut j = stats_json(&l, render_ms, &frame.counts, l.settings.spp);
    // The error views: the shaded frame against the reference, mapped.
    if let (Some(kind), Some((path, truth))) = (l.settings.view.error_kind(), &truth) {
        let (image, map) = crate::display::error_view::error_image(kind, &frame.pixels, truth);
        frame.pixels = image;
        j["reference"] = json!(path.display().to_string());
        j["error_scale"] = json!(map.scale);
    }
    j["tile"] = json!(part_opts.tile.map(|t| format!("{}/{}", t.index, t.count)));
    j["sample_range"] = json!(part.as_ref().filter(|_| part_opts.sample_range.is_some()).map(|p| format!("{}..{}", p.passes.start, p.passes.end)));
    j["crop"] = json!(part_opts.crop.map(|c| c.0));
    if part_opts.is_partial() {
        let p = part.as_ref().expect("a partial render has a part");
        j["started_unix_ms"] = json!(started_unix_ms);
        j["finished_unix_ms"] = json!(unix_ms());
        j["peak_rss_bytes"] = json!(peak_rss_bytes());
        let record = crate::part_file::PartRecord {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene: l.prepared.scene.name.clone(),
            // A switched glossy model is part of what the parts drew.
            scene_hash: crate::part_file::scene_hash(&scene_identity(&l), &crate::file_identity::inputs_read())?,
            renderer: l.renderer.name().to_string(),
            settings: serde_json::to_value(&l.settings).map_err(|e| e.to_string())?,
            frame_width: l.settings.width,
            frame_height: l.settings.height,
            spp: l.settings.spp.max(1),
            region: [p.x.start, p.y.start, p.x.end, p.y.end],
            passes: [p.passes.start, p.passes.end],
            tile: part_opts.tile.map(|t| [t.index, t.count]),
            stats: j.clone(),
        };
        crate::image_io::write_atomic(output, &crate::part_file::encode(&record, &frame.pixels)?)?;
    } else if !aovs.is_empty() {
        let layers = l.pool.install(|| render::aov::render_aovs(&l.prepared, &l.settings, &aovs, part.as_ref()));
        let channels: Vec<(String, Vec<f32>)> = layers.into_iter().flat_map(|layer| layer.channels).collect();
        crate::image_io::write_atomic(output, &crate::image_io::encode_layered_exr(frame.width, frame.height, &frame.pixels, &channels)?)?;
        j["aov"] = json!(aovs.iter().map(|a| a.name()).collect::<Vec<_>>());
    } else {
        crate::image_io::save_image_displayed(output, frame.width, frame.height, &frame.pixels, l.prepared.scene.render.exposure, &l.settings.display)?;
    }
    if let Some(dest) = stats {
        // After the frame and its image: the run's peak (null where unknown).
        j["peak_rss_bytes"] = json!(peak_rss_bytes());
        write_json(dest, &j)?;
    }
    Ok(())
}

/// What a part's scene hash covers besides the files: the scene's name, and
/// the glossy model `--glossy-model` switched its lobes to.
fn scene_identity(l: &Loaded) -> String {
    match l.glossy_model {
        Some(m) => format!("{} glossy-model {m}", l.prepared.scene.name),
        None => l.prepared.scene.name.clone(),
    }
}

/// Checks that `argv`, a `pinhole render` job line, renders `scene` with
/// `renderer` and exactly `target`: it is parsed and admitted as the job
/// will parse and admit it. `what` names the work in the error.
fn check_render_job(argv: &[String], scene: &Scene, renderer: &str, target: &RenderSettings, what: &str) -> Result<(), String> {
    use clap::FromArgMatches;
    let cmd = command();
    let words = std::iter::once("pinhole".to_string()).chain(argv[1..].iter().cloned());
    let parsed = cmd.clone().try_get_matches_from(words).and_then(|m| Cli::from_arg_matches(&m));
    let cli = parsed.map_err(|e| format!("{what}: its job line does not parse: {}", usage_error::one_sentence(&e, &cmd)))?;
    let Some(Command::Render { opts, .. }) = cli.command else {
        return Err(format!("{what}: its job line is not a pinhole render command"));
    };
    let r = render::renderer_by_name(&opts.renderer)?;
    let mut settings = RenderSettings::for_scene(scene);
    opts.write_into(&mut settings)?;
    let admitted = render::admit::admit(r.as_ref(), scene, &settings)?;
    if r.name() != renderer {
        return Err(format!("{what}: its job line renders with {} instead of {renderer}", r.name()));
    }
    if admitted.settings != *target {
        let keys = plan_lines::differing_settings(&admitted.settings, target);
        return Err(format!("{what} cannot be written as a pinhole render command line: it would render with other {}", keys.join(", ")));
    }
    Ok(())
}

/// Now as milliseconds since the Unix epoch (parts' start and end times,
/// from which a merge tells the wall-clock time of the whole).
fn unix_ms() -> f64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64() * 1e3)
}

fn cmd_merge(paths: &[PathBuf], output: &Path, stats: Option<&str>) -> Result<(), String> {
    if output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() != Some("exr") {
        return Err(format!("{}: the merged frame is written as .exr (linear, like the parts)", output.display()));
    }
    crate::image_io::check_writable(output)?;
    if let Some(dest) = stats.filter(|d| *d != "-") {
        crate::image_io::check_writable(Path::new(dest))?;
    }
    let parts = paths.iter().map(|p| crate::part_file::read(p).map(|f| (p.clone(), f))).collect::<Result<Vec<_>, String>>()?;
    // Every part is read: none of them may be written over.
    let outputs: Vec<&Path> = std::iter::once(output).chain(stats.filter(|d| *d != "-").map(Path::new)).collect();
    crate::file_identity::check_outputs(&outputs)?;
    let merged = crate::part_merge::merge(&parts)?;
    crate::image_io::save_image(output, merged.width, merged.height, &merged.pixels, 1.0)?;
    if let Some(dest) = stats {
        write_json(dest, &merged.stats)?;
    }
    Ok(())
}

/// Reports progress on stderr until `done`: on a terminal, one line
/// redrawn in place; otherwise (a log, a batch job) a line every
/// `LOG_PROGRESS_SECS` once the render has taken that long.
fn progress_loop(rows_done: &AtomicU64, total: u64, done: &AtomicBool, terminal: bool) {
    const LOG_PROGRESS_SECS: f64 = 10.0;
    let start = Instant::now();
    let mut shown = false;
    let mut last_logged = 0.0;
    while !done.load(Ordering::Relaxed) {
        std::thread::sleep(std::time::Duration::from_millis(200));
        let d = rows_done.load(Ordering::Relaxed);
        let secs = start.elapsed().as_secs_f64();
        let eta = secs * (total as f64 / d.max(1) as f64 - 1.0);
        let percent = 100.0 * d as f64 / total as f64;
        if terminal && secs > 0.5 && d > 0 {
            eprint!("\rrendering {percent:5.1}%  {secs:.1} s elapsed, about {eta:.0} s left   ");
            shown = true;
        } else if !terminal && secs - last_logged >= LOG_PROGRESS_SECS {
            last_logged = secs;
            if d > 0 {
                eprintln!("rendering {percent:.1}%, {secs:.0} s elapsed, about {eta:.0} s left");
            } else {
                eprintln!("rendering, {secs:.0} s elapsed (the first pass is not done yet)");
            }
        }
    }
    if shown && terminal {
        eprintln!("\rrendered in {:.1} s{:40}", start.elapsed().as_secs_f64(), "");
    }
}

/// Says every ten seconds how many of `total` passes of `what` are done,
/// until `finished`.
fn report_passes(what: &str, done: &std::sync::atomic::AtomicU32, total: u32, finished: &AtomicBool) {
    let start = Instant::now();
    let mut last = 0.0;
    while !finished.load(Ordering::Relaxed) {
        std::thread::sleep(std::time::Duration::from_millis(200));
        let secs = start.elapsed().as_secs_f64();
        if secs - last >= 10.0 {
            last = secs;
            let d = done.load(Ordering::Relaxed);
            let left = if d > 0 { format!(", about {:.0} s left", secs * (total as f64 / d as f64 - 1.0)) } else { String::new() };
            eprintln!("{what}: {d} of {total} passes, {secs:.0} s elapsed{left}");
        }
    }
}

fn write_json(dest: &str, j: &serde_json::Value) -> Result<(), String> {
    let text = serde_json::to_string_pretty(j).map_err(|e| e.to_string())? + "\n";
    if dest == "-" {
        print_stdout(&text)
    } else {
        crate::image_io::write_atomic(Path::new(dest), text.as_bytes())
    }
}

fn cmd_bench(scene_arg: &str, opts: &RenderOpts, frames: u32) -> Result<(), String> {
    if !(1..=MAX_BENCH_FRAMES).contains(&frames) {
        return Err(format!("--frames {frames} is not between 1 and {MAX_BENCH_FRAMES}"));
    }
    let l = load(scene_arg, opts)?;
    let bench_started = Instant::now();
    let mut last_note = bench_started;
    let cancel = interrupt::flag();
    let mut times = Vec::new();
    let mut first_ms = 0.0;
    let mut counts = RayCounts::default();
    // Each frame renders over the one before's pixels, as a viewer redraws
    // its image (`FrameOptions::spare`).
    let mut spare = Vec::new();
    for i in 0..=frames {
        let start = Instant::now();
        let frame = l
            .pool
            .install(|| render::render_frame_with(l.renderer.as_ref(), &l.prepared, &l.settings, cancel, render::FrameOptions { spare: std::mem::take(&mut spare), ..render::FrameOptions::default() }))
            .ok_or("the render was cancelled")?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        if i > 0 {
            times.push(ms);
            counts = frame.counts;
        } else {
            first_ms = ms;
        }
        spare = frame.pixels;
        // Long benchmarks say how far they are, every few seconds.
        if last_note.elapsed().as_secs_f64() >= 2.0 && i < frames {
            last_note = Instant::now();
            let per_frame = bench_started.elapsed().as_secs_f64() / (i + 1) as f64;
            eprintln!("bench: {i} of {frames} frames, about {:.0} s left", per_frame * (frames - i) as f64);
        }
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let mut j = stats_json(&l, median, &counts, l.settings.spp);
    j["render_ms_min"] = json!(times[0]);
    // The untimed first frame: what one `render` in a fresh process pays.
    j["first_ms"] = json!(first_ms);
    j["frames"] = json!(frames);
    j["primary_rays_per_s"] = json!(counts.primary as f64 / (median / 1e3));
    j["rays_per_s"] = json!((counts.primary + counts.shadow + counts.secondary) as f64 / (median / 1e3));
    // Memory of the geometry, from lengths and element sizes:
    //   "scene_bytes"        triangles and spheres of the scene
    //   "bvh_bytes"          BVH nodes, primitive slots and debugger bounds
    //   "prepared_bytes"     what the prepared scene adds per triangle besides the BVH
    //   "bytes_per_triangle" the three summed, over "triangles" (null without triangles)
    //   "peak_rss_bytes"     the process's peak resident memory (null where unknown)
    let memory = l.prepared.memory();
    let triangles = l.prepared.scene.total_triangles() as usize;
    j["scene_bytes"] = json!(memory.scene_bytes);
    j["bvh_bytes"] = json!(memory.bvh_bytes);
    j["prepared_bytes"] = json!(memory.prepared_bytes);
    j["bytes_per_triangle"] = json!((triangles > 0).then(|| memory.total() as f64 / triangles as f64));
    j["peak_rss_bytes"] = json!(peak_rss_bytes());
    write_json("-", &j)
}

/// `bench --display-pass`: one frame rendered, then its display pass timed
/// `frames` times, each step apart: the display transform to 8 bits, false
/// colour to 8 bits, the log-luminance histogram. Prints the medians (ms).
fn cmd_bench_display(scene_arg: &str, opts: &RenderOpts, frames: u32) -> Result<(), String> {
    if !(1..=MAX_BENCH_FRAMES).contains(&frames) {
        return Err(format!("--frames {frames} is not between 1 and {MAX_BENCH_FRAMES}"));
    }
    let l = load(scene_arg, opts)?;
    let shaded = RenderSettings { view: View::Shaded, ..l.settings.clone() };
    let frame = l.pool.install(|| render::render_frame(l.renderer.as_ref(), &l.prepared, &shaded, interrupt::flag(), None)).ok_or("the render was cancelled")?;
    let d = l.settings.display;
    let scale = d.scale(l.prepared.scene.render.exposure);
    let time = |f: &mut dyn FnMut()| -> f64 {
        let start = Instant::now();
        f();
        start.elapsed().as_secs_f64() * 1e3
    };
    let (mut tonemap, mut false_colour, mut histogram, mut total) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut checksum = 0u64;
    // One untimed round first (caches, page faults), then the timed ones.
    for i in 0..=frames {
        let a = time(&mut || checksum += crate::display::image_rgb8(&frame.pixels, scale, d.tonemap, d.gamma).len() as u64);
        let b = time(&mut || checksum += crate::display::false_colour::image_rgb8(&frame.pixels).len() as u64);
        let c = time(&mut || checksum += crate::display::histogram::log_luminance(&frame.pixels)[0] as u64);
        if i > 0 {
            tonemap.push(a);
            false_colour.push(b);
            histogram.push(c);
            total.push(a + b + c);
        }
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let j = json!({
        "scene": l.prepared.scene.name, "width": frame.width, "height": frame.height, "frames": frames,
        "tonemap": d.tonemap.name(), "gamma": d.gamma.name(), "exposure_ev": d.exposure_ev,
        "display_ms": median(total), "tonemap_ms": median(tonemap), "false_colour_ms": median(false_colour), "histogram_ms": median(histogram),
        "budget_ms": 2.0, "checksum": checksum,
    });
    write_json("-", &j)
}

/// The process's peak resident memory (`VmHWM` of /proc/self/status), where
/// the system reports it.
fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn cmd_pixel(scene_arg: &str, x: u32, y: u32, opts: &RenderOpts, as_json: bool) -> Result<(), String> {
    let l = load(scene_arg, opts)?;
    let replay = render::replay_pixel(l.renderer.as_ref(), &l.prepared, &l.settings, x, y)?;
    let scene = &l.prepared.scene;
    if as_json {
        write_json("-", &crate::render::inspect::pixel_report::to_json(l.renderer.name(), scene, x, y, &replay))
    } else {
        print_stdout(&crate::render::inspect::pixel_report::to_text(l.renderer.name(), scene, x, y, &replay))
    }
}

/// `--spp-list`: comma-separated sample counts.
fn parse_spp_list(list: &str) -> Result<Vec<u32>, String> {
    list.split(',')
        .map(|s| s.trim().parse::<u32>().ok().filter(|&n| (1..=65536).contains(&n)).ok_or(format!("--spp-list: \"{s}\" is not a sample count")))
        .collect()
}

/// `chart --sweep methods`: every configuration of `chart::method_configurations`
/// against the reference, as a scatter with its Pareto front, and the CSV.
/// With `gi = Some((path spps, peer))`, `chart --sweep gi`: the methods of
/// indirect light as curves, a peer's curve beside them, the same CSV.
/// `jobs`: measured here, written as job lines, or assembled from their results.
#[allow(clippy::too_many_arguments)]
fn cmd_chart_methods(scene_arg: &str, output: &Path, metric: &str, reference: Option<&Path>, reference_spp: u32, gi: Option<(&[u32], Option<&Path>)>, opts: &RenderOpts, jobs: Jobs) -> Result<(), String> {
    check_png_output(output)?;
    let peers = match gi.and_then(|(_, peer)| peer) {
        Some(path) => crate::chart::gi_sweep::load_peer_csv(path)?,
        None => Vec::new(),
    };
    let metric = match metric {
        "rel-rmse" | "rmse" => crate::chart::ErrorMetric::RelRmse,
        "flip" => crate::chart::ErrorMetric::Flip,
        other => return Err(format!("--metric: \"{other}\" is not one of rel-rmse, flip")),
    };
    if !(1..=65536).contains(&reference_spp) {
        return Err(format!("--reference-spp {reference_spp} is not between 1 and 65536"));
    }
    // Shadow-map configurations too big for the scene's lights are left out of the sweep.
    let l = load(scene_arg, opts)?;
    check_chart_outputs(output)?;
    let (w, h) = (l.settings.width, l.settings.height);
    if metric == crate::chart::ErrorMetric::Flip && (w * h) as usize > crate::metrics::MAX_FLIP_PIXELS {
        return Err(format!("--metric flip: {w}x{h} is more than the {} pixels FLIP is computed for", crate::metrics::MAX_FLIP_PIXELS));
    }
    let source = crate::chart::ReferenceSource::choose(reference, &l.prepared, reference_spp);
    let configs = match gi {
        Some((spps, _)) => {
            if l.prepared.scene.render.ambient.max_element() <= 0.0 {
                eprintln!("note: the scene has no ambient term, so --gi ao (which dims it) equals --gi none and is left out");
            }
            crate::chart::gi_sweep::gi_configurations(&l.settings, &l.prepared.scene, spps)
        }
        None => crate::chart::method_configurations(&l.prepared.scene, &l.settings),
    };
    let planned = match jobs {
        Jobs::Plan(dir) => return chart_jobs::plan(dir, scene_arg, opts, &l, &configs, &source),
        Jobs::From(dir) => Some(chart_jobs::Planned::new(dir, &l, &source)?),
        Jobs::Run => None,
    };
    let cancel = interrupt::flag();
    let cache = crate::chart::reference::default_cache_dir();
    // A path-traced reference can take minutes: its passes are reported
    // every ten seconds.
    let passes = std::sync::atomic::AtomicU32::new(0);
    let loaded = AtomicBool::new(false);
    let truth = match planned.as_ref().map(chart_jobs::Planned::reference).transpose()?.flatten() {
        Some(r) => r,
        None => std::thread::scope(|s| {
            if let crate::chart::ReferenceSource::PathTraced { spp } = source {
                let (passes, loaded) = (&passes, &loaded);
                s.spawn(move || report_passes("reference", passes, spp, loaded));
            }
            let r = l.pool.install(|| crate::chart::load_reference(&source, &l.prepared, w, h, cache.as_deref(), cancel, Some(&passes)));
            loaded.store(true, Ordering::Relaxed);
            r
        })?
        .ok_or("cancelled")?,
    };
    eprintln!("reference: {}", truth.name);
    check_chart_outputs(output)?;
    let mut points = Vec::new();
    for (i, c) in configs.iter().enumerate() {
        eprintln!("[{}/{}] {}", i + 1, configs.len(), c.label);
        let m = match (&planned, gi) {
            (Some(p), _) => p.measurement(i, c, &truth).map(Some),
            (None, Some(_)) => l.pool.install(|| crate::chart::gi_sweep::measure_with_builds(&l.prepared, c, &truth, cancel)),
            (None, None) => l.pool.install(|| crate::chart::measure(&l.prepared, c, &truth, 3, cancel)),
        };
        points.push(m?.ok_or("cancelled")?);
    }
    let runs_on = match planned {
        Some(_) => "times of the planned jobs".to_string(),
        None => format!("{} threads", l.pool.current_num_threads()),
    };
    let title = format!("{}: error against time, {w}x{h}, {runs_on}; reference: {}", l.prepared.scene.name, truth.name);
    let png = match gi {
        Some(_) => crate::chart::plot::draw_curves_png(&points, &peers, metric, &title, 1100, 700)?,
        None => crate::chart::plot::draw_methods_png(&points, metric, &title, 1100, 700)?,
    };
    let csv_path = output.with_extension("csv");
    let csv = crate::chart::methods_csv(&points);
    crate::image_io::write_all_atomic(&[(output, &png), (&csv_path, csv.as_bytes())])?;
    eprintln!("wrote {} and {}", output.display(), csv_path.display());
    Ok(())
}

/// The chart's PNG name, and that it and the CSV beside it can be written
/// (checked before minutes of measuring).
fn check_png_output(output: &Path) -> Result<(), String> {
    if output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() != Some("png") {
        return Err(format!("{}: the chart is written as .png", output.display()));
    }
    crate::image_io::check_writable(output)?;
    crate::image_io::check_writable(&output.with_extension("csv"))
}

/// Once the scene and reference are read, before measuring: the chart and
/// its CSV are neither inputs nor the same file.
fn check_chart_outputs(output: &Path) -> Result<(), String> {
    crate::file_identity::check_outputs(&[output, &output.with_extension("csv")])
}

fn cmd_chart(scene_arg: &str, output: &Path, renderers: &str, spp_list: &str, reference: Option<&Path>, reference_spp: u32, opts: &RenderOpts) -> Result<(), String> {
    check_png_output(output)?;
    if !(1..=65536).contains(&reference_spp) {
        return Err(format!("--reference-spp {reference_spp} is not between 1 and 65536"));
    }
    let spps = parse_spp_list(spp_list)?;
    let names: Vec<&str> = renderers.split(',').map(str::trim).collect();
    for n in &names {
        render::renderer_by_name(n)?;
    }
    let l = load(scene_arg, opts)?;
    check_chart_outputs(output)?;
    let (w, h) = (l.settings.width, l.settings.height);
    let reference = reference.map(Path::to_path_buf).or_else(|| l.prepared.scene.render.reference.clone());
    let reference_pixels = match reference.as_deref() {
        Some(path) => crate::chart::reference::load_reference_file(path, w, h)?.pixels,
        None => {
            eprintln!("rendering the reference: raytrace:bvh at {reference_spp} spp");
            let r = render::renderer_by_name(render::DEFAULT_RAYTRACE)?;
            let settings = RenderSettings { spp: reference_spp, ..l.settings.clone() };
            l.pool
                .install(|| render::render_frame(r.as_ref(), &l.prepared, &settings, interrupt::flag(), None))
                .ok_or("cancelled")?
                .pixels
        }
    };
    check_chart_outputs(output)?;
    let points = l.pool.install(|| {
        crate::chart::spp_sweep::sweep(&l.prepared, &l.settings, &names, &spps, &reference_pixels, 3, |r, spp| eprintln!("measuring {r} at {spp} spp"), |n| eprintln!("note: {n}"))
    })?;
    let title = format!("{}: error against time, {w}x{h}, {} threads", l.prepared.scene.name, l.pool.current_num_threads());
    let png = crate::chart::plot::draw_spp_png(&points, &title, 900, 600)?;
    let csv_path = output.with_extension("csv");
    let csv = crate::chart::spp_sweep::to_csv(&points);
    crate::image_io::write_all_atomic(&[(output, &png), (&csv_path, csv.as_bytes())])?;
    eprintln!("wrote {} and {}", output.display(), csv_path.display());
    Ok(())
}

fn cmd_compare(a: &Path, b: &Path, as_json: bool) -> Result<(), String> {
    let ia = crate::image_io::load_image(a)?;
    let ib = crate::image_io::load_image(b)?;
    for (img, path) in [(&ia, a), (&ib, b)] {
        let bad = crate::metrics::count_non_finite(&img.pixels);
        if bad > 0 {
            return Err(format!("{}: {bad} pixels are NaN or infinite; compare needs finite images", path.display()));
        }
    }
    if (ia.width, ia.height) != (ib.width, ib.height) {
        return Err(format!(
            "{} is {}x{} but {} is {}x{}; compare needs images of the same size",
            a.display(),
            ia.width,
            ia.height,
            b.display(),
            ib.width,
            ib.height
        ));
    }
    let m = crate::metrics::compare_images(&ia.pixels, &ib.pixels, ia.width as usize, ia.height as usize)?;
    if as_json {
        write_json("-", &serde_json::to_value(m).map_err(|e| e.to_string())?)
    } else {
        let mut t = String::new();
        let _ = writeln!(t, "rmse      {:.6}  ({:.3}% of the mean {:.6} of {})", m.rmse, 100.0 * m.rmse / m.reference_mean.max(1e-12), m.reference_mean, b.display());
        let _ = writeln!(t, "rel_mse   {:.6}", m.rel_mse);
        let _ = writeln!(t, "max_abs   {:.6}", m.max_abs);
        match m.flip {
            Some(f) => writeln!(t, "flip      {f:.6}"),
            None => writeln!(t, "flip      not computed (more than {} pixels)", crate::metrics::MAX_FLIP_PIXELS),
        }
        .ok();
        let _ = writeln!(t, "differing {} of {} pixels", m.differing_pixels, ia.pixels.len());
        print_stdout(&t)
    }
}

/// `pinhole gallery`: every case (or `only`) measured here; with `exr`, its
/// three images kept as EXRs beside the sheet.
fn cmd_gallery(dir: &Path, only: Option<&str>, threads: Option<usize>, exr: bool) -> Result<(), String> {
    let cases = gallery_jobs::cases(only)?;
    let pool = worker_pool(threads)?;
    gallery_jobs::prepare_output(dir)?;
    let start = Instant::now();
    let mut results = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        if interrupt::interrupted() {
            return Err("interrupted".into());
        }
        eprintln!("[{}/{}] {}: {} ...", i + 1, cases.len(), case.name, case.method);
        let t = Instant::now();
        let images = pool.install(|| crate::gallery::render_case(case))?;
        if exr {
            gallery_jobs::write_case_images(dir, case.name, &images)?;
        }
        let r = crate::gallery::judge(case, images)?;
        gallery_jobs::report(&r, t.elapsed().as_secs_f64());
        results.push((r, case.explanation));
    }
    gallery_jobs::write_gallery(dir, &results, start)
}

fn cmd_list() -> Result<(), String> {
    let mut t = String::new();
    let _ = writeln!(t, "renderers:");
    for r in render::renderers() {
        let _ = writeln!(t, "  {:24} {}", r.name(), r.description());
    }
    let _ = writeln!(t, "  {:24} = {}", "raytrace", render::DEFAULT_RAYTRACE);
    let _ = writeln!(t, "  {:24} = {}", "rasterize", render::raster::DEFAULT_RASTERIZE);
    let _ = writeln!(t, "  (rasterizers only: --msaa 2|4|8 coverage samples, one shade per pixel per primitive;");
    let _ = writeln!(t, "   --forward shades every fragment that passes the depth test instead of early depth)");
    let _ = writeln!(t, "views:");
    for v in View::ALL {
        let _ = writeln!(t, "  {}", v.name());
    }
    let _ = writeln!(t, "shadows:\n  none\n  ray\n  map\n  volume");
    let _ = writeln!(t, "shadow volumes (--shadow-volume, with --shadows volume):\n  zpass\n  zfail");
    let _ = writeln!(t, "depth buffers (rasterizers with a depth buffer: --depth-buffer):");
    for f in render::raster::depth_format::DepthFormat::ALL {
        let _ = writeln!(t, "  {:24} {}", f.name(), f.description());
    }
    let _ = writeln!(t, "line algorithms (--view wireframe: --lines):\n  float\n  integer");
    let _ = writeln!(t, "built-in scenes:");
    for s in crate::scene::builtin::names() {
        let _ = writeln!(t, "  {s}");
    }
    let _ = writeln!(t, "large scenes (instanced: raytrace:bvh, rasterize and opengl):");
    for s in crate::scene::builtin::large_names() {
        let _ = writeln!(t, "  {s}");
    }
    let _ = writeln!(t, "stress scenes (pinhole gallery: each provokes one failure):");
    for s in crate::scene::builtin::stress_names() {
        let _ = writeln!(t, "  {s}");
    }
    print_stdout(&t)
}

/// Writes `text` to standard output. A reader that went away (`| head`)
/// ends the program quietly, as Unix tools end; any other failure (a full
/// disk) is an error sentence instead of a panic.
fn print_stdout(text: &str) -> Result<(), String> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(0),
        Err(e) => Err(format!("cannot write to standard output: {e}")),
    }
}
