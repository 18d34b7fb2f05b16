//! The egui viewer: a live framebuffer of the selected renderer
//! with camera, light, material and shading panels, navigation and export.
//! Rendering runs on `worker`; `state` holds what the user edits; `panels`
//! and `viewport` draw it.

use eframe::egui;
mod access;
pub mod compare_lab;
pub mod export;
pub mod gallery;
pub mod inspect;
pub mod legend;
pub mod overlay;
pub mod open_dialog;
pub mod panels;
pub mod reference_view;
pub mod region_stats;
pub mod settings_store;
pub mod split_view;
pub mod state;
pub mod viewed;
pub mod viewport;
pub mod worker;

pub use state::PinholeApp;

use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// `--screenshot`: wait for the full-quality frame, capture the window, exit.
pub struct ScreenshotState {
    pub path: PathBuf,
    /// UI frames drawn since the complete image reached the texture.
    pub frames_shown: u32,
    pub requested: bool,
    pub started: Instant,
    pub result: Arc<Mutex<Option<Result<(), String>>>>,
}

/// Frame-pacing measurement, `PINHOLE_BENCH_UI=SECONDS[:still][:SPP]`:
/// repaints continuously (orbiting the camera a little each frame like a
/// drag, unless `still`), then prints UI frames per second and frame gaps.
pub struct UiBench {
    pub started: Instant,
    pub seconds: f32,
    pub orbit: bool,
    pub spp: Option<u32>,
    gaps_ms: Vec<f32>,
    last: Option<Instant>,
    pub done: bool,
    pub reported: bool,
}

impl UiBench {
    pub fn parse(spec: &str) -> Option<UiBench> {
        let mut parts = spec.split(':');
        let seconds = parts.next()?.parse::<f32>().ok()?;
        let mut bench = UiBench { started: Instant::now(), seconds, orbit: true, spp: None, gaps_ms: Vec::new(), last: None, done: false, reported: false };
        for p in parts {
            if p == "still" {
                bench.orbit = false;
            } else if let Ok(n) = p.parse() {
                bench.spp = Some(n);
            }
        }
        Some(bench)
    }

    fn frame(&mut self, camera: &mut crate::scene::Camera) -> bool {
        let now = Instant::now();
        // The first second is window start-up, not pacing.
        if self.started.elapsed().as_secs_f32() < 1.0 {
            self.last = Some(now);
            return false;
        }
        if let Some(l) = self.last {
            self.gaps_ms.push((now - l).as_secs_f32() * 1e3);
        }
        self.last = Some(now);
        if self.orbit {
            crate::scene::camera::control::orbit(camera, 3.0, 0.0);
        }
        if !self.done && self.started.elapsed().as_secs_f32() >= self.seconds + 1.0 {
            self.done = true;
            let mut g = self.gaps_ms.clone();
            g.sort_by(f32::total_cmp);
            let total: f32 = g.iter().sum();
            let pct = |q: f32| g.get(((g.len() as f32 - 1.0) * q) as usize).copied().unwrap_or(0.0);
            println!(
                "ui-bench ({}): {} frames in {:.2} s = {:.1} fps; frame gap median {:.1} ms, p95 {:.1} ms, max {:.1} ms",
                if self.orbit { "orbiting" } else { "still" },
                g.len(),
                total / 1e3,
                g.len() as f32 / (total / 1e3),
                pct(0.5),
                pct(0.95),
                pct(1.0)
            );
        }
        self.orbit
    }
}

/// Called at the end of every frame: drives `--screenshot` and the UI bench.
fn screenshot_frame(app: &mut PinholeApp, ctx: &egui::Context) {
    if app.bench.as_ref().is_some_and(|b| b.done) && app.screenshot.is_none() {
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }
    if app.screenshot.is_none() {
        return;
    }
    let generation = app.generation;
    let shown = app.shown_version;
    let ready = !app.loading()
        && app.with_output(|o| o.idle && o.complete && o.generation == generation && o.version == shown)
        && !app.bench.as_ref().is_some_and(|b| !b.done)
        && !app.inspect.waiting(generation)
        && !app.compare.running()
        && app.split.idle();
    let viewport_rect = app.viewport_rect;
    let Some(shot) = app.screenshot.as_mut() else { return };
    ctx.request_repaint_after(Duration::from_millis(30));
    if shot.result.lock().unwrap().is_some() {
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        return;
    }
    if shot.requested {
        return;
    }
    if shot.started.elapsed() > Duration::from_secs(600) {
        *shot.result.lock().unwrap() = Some(Err("--screenshot: the frame did not finish within 10 minutes".into()));
        return;
    }
    if !ready {
        shot.frames_shown = 0;
        return;
    }
    shot.frames_shown += 1;
    if shot.frames_shown < 3 {
        return;
    }
    shot.requested = true;
    if let Some(r) = viewport_rect {
        let ppp = ctx.pixels_per_point();
        println!(
            "viewport={},{},{},{}",
            (r.min.x * ppp).round(),
            (r.min.y * ppp).round(),
            (r.width() * ppp).round(),
            (r.height() * ppp).round()
        );
    }
    let path = shot.path.clone();
    let result = shot.result.clone();
    let ctx2 = ctx.clone();
    ctx.request_screenshot(move |image| {
        let rgb: Vec<u8> = image.pixels.iter().flat_map(|c| [c.r(), c.g(), c.b()]).collect();
        let r = crate::image_io::encode_png(image.size[0] as u32, image.size[1] as u32, &rgb)
            .and_then(|bytes| crate::image_io::write_atomic(&path, &bytes));
        *result.lock().unwrap() = Some(r);
        ctx2.request_repaint();
    });
}

/// Applies the environment's overrides for scripts and tests
/// (`env_overrides`, where each is documented) to the viewer.
fn apply_env_overrides(app: &mut PinholeApp, env: &crate::env_overrides::ViewerOverrides) {
    if let Some(name) = env.renderer {
        app.settings.renderer = name.to_string();
    }
    // B keeps the settings as they are here, before the overrides below.
    if let Some(name) = env.split {
        let mut b = app.settings.clone();
        b.renderer = name.to_string();
        app.split.set_b(b);
    }
    if let Some(v) = env.view {
        app.settings.render.view = v;
    }
    if let Some(g) = env.gamma {
        app.settings.render.display.gamma = if g { crate::display::Gamma::Srgb } else { crate::display::Gamma::Off };
    }
    if let Some(m) = env.gi {
        app.settings.render.gi.mode = m;
    }
    if let Some(n) = env.spp {
        app.settings.render.spp = n;
    }
    if let Some((x, y)) = env.select {
        app.select_pixel(x, y);
    }
    if let Some(z) = env.zoom {
        app.inspect.zoom = z.clamp(1.0, inspect::MAX_ZOOM);
        app.inspect.center_on_selection = true;
    }
    if let Some(name) = &env.gallery {
        app.open_gallery_case(name, false);
    }
    if env.compare {
        app.compare.open = true;
        app.start_compare();
    }
    if let Some(v) = env.vertices {
        app.inspect.vertices = v;
    }
    if let Some(p) = env.panels {
        let panels = &mut app.settings.panels;
        (panels.side, panels.camera, panels.lights, panels.materials, panels.shading) = (p.side, p.camera, p.lights, p.materials, p.shading);
    }
}

/// The eframe wrapper: storage, and the root `ui`.
struct EframeApp(PinholeApp);

impl eframe::App for EframeApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.0.ui(ui);
    }

    /// Screenshots and benchmarks neither keep nor leave panel sizes behind.
    fn persist_egui_memory(&self) -> bool {
        self.0.persist
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.0.persist {
            self.0.own_settings().save(storage);
        }
    }
}

/// Opens the viewer on `scene` (a built-in name, `.toml` or `.obj`; `None`:
/// the scene of the last run, else the default scene). With `screenshot`,
/// waits for the full-quality frame, saves a screenshot of the whole window
/// there and exits.
pub fn run(scene: Option<String>, screenshot: Option<PathBuf>) -> Result<(), String> {
    use crate::scene::{builtin, load};
    // An explicit scene that does not load is an error before any window opens.
    let explicit = match &scene {
        Some(arg) => Some((load::load_scene(arg)?, arg.clone())),
        None => None,
    };
    let shot_result = Arc::new(Mutex::new(None));
    let env = crate::env_overrides::ViewerOverrides::from_env();
    let bench = env.bench_ui.as_deref().and_then(UiBench::parse);
    let batch = screenshot.is_some() || bench.is_some();

    // In --screenshot mode the window fits the image 1:1 beside the side panel.
    let size = match &explicit {
        Some((s, _)) if batch => [s.render.width as f32 + 460.0, s.render.height as f32 + 120.0],
        _ => [1280.0, 800.0],
    };
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("pinhole")
            .with_inner_size(size)
            .with_drag_and_drop(true),
        persist_window: !batch,
        ..Default::default()
    };
    let shot_state = screenshot.map(|path| ScreenshotState {
        path,
        frames_shown: 0,
        requested: false,
        started: Instant::now(),
        result: shot_result.clone(),
    });
    let wanted_shot = shot_state.is_some();
    eframe::run_native(
        "pinhole",
        options,
        Box::new(move |cc| {
            let saved = if batch { None } else { settings_store::ViewerSettings::load(cc.storage) };
            if batch {
                // Panel sizes and open sections from interactive runs would
                // make screenshots depend on the machine's history.
                cc.egui_ctx.memory_mut(|m| *m = egui::Memory::default());
            }
            let (scene, arg) = match explicit {
                Some(x) => x,
                None => {
                    let remembered = saved.as_ref().and_then(|p| p.scene.clone());
                    match remembered.and_then(|a| load::load_scene(&a).ok().map(|s| (s, a))) {
                        Some(x) => x,
                        None => {
                            let name = builtin::DEFAULT_SCENE.to_string();
                            match load::load_scene(&name) {
                                Ok(s) => (s, name),
                                Err(e) => return Err(e.into()),
                            }
                        }
                    }
                }
            };
            let mut app = PinholeApp::new(scene, arg, saved.as_ref());
            app.persist = !batch;
            if batch {
                app.settings.res_scale = 1.0;
            }
            apply_env_overrides(&mut app, &env);
            app.screenshot = shot_state;
            app.bench = bench;
            if let Some(n) = app.bench.as_ref().and_then(|b| b.spp) {
                app.settings.render.spp = n;
            }
            Ok(Box::new(EframeApp(app)))
        }),
    )
    .map_err(|e| format!("cannot open the viewer window: {e}"))?;
    match shot_result.lock().unwrap().take() {
        Some(r) => r,
        None if wanted_shot => Err("--screenshot: the window closed before the screenshot was taken".into()),
        None => Ok(()),
    }
}
