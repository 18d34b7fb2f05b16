//! The viewer's state and its frame: what is loaded, what is edited, what
//! was last asked of the worker. Every part of the window (menu, side
//! panels, gallery bar, status bar, inspector, viewport, export dialog) gets
//! the slice it reads and edits, and returns what it asks beyond that; this
//! file applies those requests (`apply` for the panels' `Requests`). At the
//! end of each frame a change becomes a render request.

use eframe::egui;
use crate::app::export::ExportDialog;
use crate::app::open_dialog::OpenDialog;
use crate::app::panels::Requests;
use crate::app::settings_store::ViewerSettings;
use crate::app::worker::{Output, Request, SceneParams, Worker};
use crate::render::{self, RenderSettings};
use crate::scene::{builtin, Camera, Scene};
use std::path::PathBuf;
use std::sync::mpsc::{channel, Receiver};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime};

/// The whole viewer. `ui()` draws one frame into any `egui::Ui`, so the
/// window and the egui_kittest harness run the same code.
pub struct PinholeApp {
    /// The scene as loaded (its geometry is what the worker renders).
    pub(crate) scene: Arc<Scene>,
    /// How to load it again (built-in name or path).
    pub(crate) scene_arg: String,
    pub(crate) scene_id: u64,
    /// Camera, lights, materials and `[render]` values as edited.
    pub(crate) params: SceneParams,
    /// The camera the scene file gave, for "reset".
    pub(crate) initial_camera: Camera,
    /// The persisted state: renderer, render knobs, display, panels and the
    /// last scene, in force (a gallery case's or an applied configuration's
    /// knobs included). `own_settings()` is what is saved between runs: this
    /// struct whole, the user's own knobs in place of a gallery case's. The
    /// panels edit it, `effective_settings()` renders with it.
    pub(crate) settings: ViewerSettings,
    pub(crate) renderer_names: Vec<&'static str>,
    pub(crate) worker: Worker,
    /// The last request sent (generation counts every request).
    pub(crate) generation: u64,
    last_sent: Option<Request>,
    /// The camera moved this frame (orbit, pan, fly...): ask for a preview.
    pub(crate) camera_moving: bool,
    pub(crate) texture: Option<egui::TextureHandle>,
    pub(crate) shown_version: u64,
    /// The error views: the frame on show mapped against its reference.
    pub(crate) reference_view: crate::app::reference_view::ReferenceView,
    /// A problem to show in the red bar (the previous scene stays).
    pub(crate) error_bar: Option<String>,
    /// A passing note in the status bar (e.g. "saved x.png").
    pub(crate) message: Option<String>,
    loader: Option<Receiver<(String, Result<Scene, String>)>>,
    watch: Option<(PathBuf, Option<SystemTime>)>,
    last_watch_check: Instant,
    pub(crate) open_dialog: OpenDialog,
    pub(crate) export: ExportDialog,
    pub(crate) screenshot: Option<crate::app::ScreenshotState>,
    /// Where the image was drawn last frame, in points, and its size in pixels.
    pub(crate) viewport_rect: Option<egui::Rect>,
    /// The viewport's focus and the light it drags.
    pub(crate) viewport: crate::app::viewport::ViewportState,
    /// Timestamps of recent UI frames, for the fps read-out.
    frame_times: std::collections::VecDeque<Instant>,
    repaint_ctx: Arc<Mutex<Option<egui::Context>>>,
    /// Whether `save()` writes eframe storage (off for tests and screenshots).
    pub(crate) persist: bool,
    /// `PINHOLE_BENCH_UI`: orbit continuously for this long, print fps, quit.
    pub(crate) bench: Option<crate::app::UiBench>,
    /// Selected pixel and its replay, zoom, overlays (visual debugging).
    pub(crate) inspect: crate::app::inspect::Inspect,
    /// The Compare window's measurements.
    pub(crate) compare: crate::app::compare_lab::CompareLab,
    /// A second configuration shown beside the live one (A|B).
    pub(crate) split: crate::app::split_view::SplitView,
    /// The stress-gallery case on show, whose setting overrides the knobs.
    pub(crate) gallery: Option<crate::app::gallery::GalleryView>,
}

impl PinholeApp {
    /// A viewer on `scene`, with no window (tests build it this way; `run`
    /// wraps it in eframe).
    pub fn new(scene: Scene, scene_arg: String, saved: Option<&ViewerSettings>) -> PinholeApp {
        let repaint_ctx: Arc<Mutex<Option<egui::Context>>> = Arc::new(Mutex::new(None));
        let rc = repaint_ctx.clone();
        let worker = Worker::start(Arc::new(move || {
            if let Some(ctx) = rc.lock().unwrap().as_ref() {
                ctx.request_repaint();
            }
        }));
        let renderer_names = render::renderer_names();
        let (settings, repaired) = saved.cloned().unwrap_or_default().sanitized(&renderer_names);
        let mut app = PinholeApp {
            params: SceneParams::of(&scene),
            initial_camera: scene.camera.clone(),
            scene: Arc::new(Scene::default()),
            scene_arg: String::new(),
            scene_id: 0,
            settings,
            renderer_names,
            worker,
            generation: 0,
            last_sent: None,
            camera_moving: false,
            texture: None,
            shown_version: 0,
            reference_view: Default::default(),
            error_bar: None,
            message: None,
            loader: None,
            watch: None,
            last_watch_check: Instant::now(),
            open_dialog: OpenDialog::new(),
            export: ExportDialog::default(),
            screenshot: None,
            viewport_rect: None,
            viewport: Default::default(),
            frame_times: Default::default(),
            repaint_ctx,
            persist: false,
            bench: None,
            inspect: Default::default(),
            compare: Default::default(),
            split: Default::default(),
            gallery: None,
        };
        app.install_scene(scene, scene_arg);
        if !repaired.is_empty() {
            let notes = app.message.take().into_iter().chain(repaired);
            app.message = Some(notes.collect::<Vec<_>>().join("; "));
        }
        app
    }

    /// A viewer for tests: no storage, default settings.
    pub fn new_for_test(scene: Scene) -> PinholeApp {
        let name = scene.name.clone();
        PinholeApp::new(scene, name, None)
    }

    /// Makes `scene` the one on show; the worker builds its BVH.
    pub fn install_scene(&mut self, scene: Scene, arg: String) {
        self.scene_id += 1;
        self.params = SceneParams::of(&scene);
        self.initial_camera = scene.camera.clone();
        self.settings.reset_scene_knobs();
        self.settings.scene = Some(arg.clone());
        self.message = (!scene.warnings.is_empty()).then(|| scene.warnings.join("; "));
        let path = PathBuf::from(&arg);
        self.watch = (builtin::source(&arg).is_none() && path.exists()).then(|| {
            let mtime = std::fs::metadata(&path).and_then(|m| m.modified()).ok();
            (path, mtime)
        });
        self.scene_arg = arg;
        self.scene = Arc::new(scene);
        self.worker.set_scene(self.scene_id, self.scene.clone());
        self.split.scene_changed();
        self.error_bar = None;
        self.last_sent = None;
    }

    /// Loads a scene in the background; it replaces the current one only if it loads.
    pub fn open(&mut self, arg: String) {
        let (tx, rx) = channel();
        let ctx = self.repaint_ctx.lock().unwrap().clone();
        std::thread::spawn(move || {
            let result = crate::scene::load::load_scene(&arg);
            let _ = tx.send((arg, result));
            if let Some(ctx) = ctx {
                ctx.request_repaint();
            }
        });
        self.loader = Some(rx);
        self.message = Some("loading…".into());
    }

    /// True while a scene is loading in the background.
    pub fn loading(&self) -> bool {
        self.loader.is_some()
    }

    /// Blocks until a background load finished and was applied (tests only).
    pub fn wait_loaded(&mut self, timeout: Duration) -> bool {
        let Some(rx) = self.loader.take() else { return true };
        match rx.recv_timeout(timeout) {
            Ok(r) => {
                self.apply_loaded(r);
                true
            }
            Err(_) => false,
        }
    }

    fn apply_loaded(&mut self, (arg, result): (String, Result<Scene, String>)) {
        self.message = None;
        match result {
            Ok(scene) => {
                // Another scene (or the file reloaded): the gallery case is over.
                self.leave_gallery();
                self.install_scene(scene, arg)
            }
            Err(e) => self.error_bar = Some(e),
        }
    }

    fn poll_loader(&mut self) {
        if let Some(rx) = &self.loader {
            match rx.try_recv() {
                Ok(r) => {
                    self.loader = None;
                    self.apply_loaded(r);
                }
                Err(std::sync::mpsc::TryRecvError::Empty) => {}
                Err(std::sync::mpsc::TryRecvError::Disconnected) => self.loader = None,
            }
        }
    }

    /// Reloads the scene file when it changed on disk (checked twice a second).
    fn poll_watch(&mut self, ctx: &egui::Context) {
        if self.watch.is_none() || self.loader.is_some() {
            return;
        }
        ctx.request_repaint_after(Duration::from_millis(500));
        if self.last_watch_check.elapsed() < Duration::from_millis(450) {
            return;
        }
        self.last_watch_check = Instant::now();
        let Some((path, mtime)) = self.watch.as_mut() else { return };
        let now = std::fs::metadata(&*path).and_then(|m| m.modified()).ok();
        if now != *mtime {
            *mtime = now;
            let arg = self.scene_arg.clone();
            self.open(arg);
        }
    }

    /// The settings the worker renders with: the knobs the panels show, at
    /// the scaled resolution.
    pub fn effective_settings(&self) -> RenderSettings {
        let (width, height) = self.image_size();
        self.settings.render_settings(width, height)
    }

    /// The image size: the scene's, times the resolution scale.
    pub fn image_size(&self) -> (u32, u32) {
        crate::app::panels::camera::scaled_size(self.scene.render.width, self.scene.render.height, self.settings.res_scale)
    }

    /// Sends a request when anything that affects the image changed.
    pub fn sync_worker(&mut self) {
        let settings = self.effective_settings();
        if let Some(last) = &self.last_sent {
            if last.scene_id == self.scene_id
                && last.renderer == self.settings.renderer
                && last.settings == settings
                && last.params.same_as(&self.params)
            {
                return;
            }
        }
        if self.params.camera.validate().is_err() {
            return; // half-typed camera values: keep the last image
        }
        self.generation += 1;
        let req = Request {
            generation: self.generation,
            scene_id: self.scene_id,
            params: self.params.clone(),
            settings,
            renderer: self.settings.renderer.clone(),
            interactive: self.camera_moving,
        };
        self.worker.request(req.clone());
        self.last_sent = Some(req);
    }

    /// Blocks until the worker has finished everything asked so far (tests and
    /// `--screenshot` only). False on timeout.
    pub fn wait_idle(&mut self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        if !self.wait_loaded(timeout) {
            return false;
        }
        self.sync_worker();
        self.sync_split();
        self.worker.wait_idle(self.generation, deadline.saturating_duration_since(Instant::now()))
            && self.split.wait_idle(deadline.saturating_duration_since(Instant::now()))
    }

    /// Hands configuration B the live view's scene, camera and size.
    pub fn sync_split(&mut self) {
        let Some(a) = self.last_sent.clone() else { return };
        let rc = self.repaint_ctx.clone();
        let repaint = std::sync::Arc::new(move || {
            if let Some(ctx) = rc.lock().unwrap().as_ref() {
                ctx.request_repaint();
            }
        });
        self.split.sync(&a, &self.settings, &self.scene, self.scene_id, repaint);
    }

    /// Runs `f` on the worker's latest output under its lock.
    pub fn with_output<T>(&self, f: impl FnOnce(&Output) -> T) -> T {
        f(&self.worker.shared.output.lock().unwrap())
    }

    /// The renderer by index (number keys 1..9).
    pub fn select_renderer(&mut self, index: usize) {
        if let Some(n) = self.renderer_names.get(index) {
            self.settings.renderer = n.to_string();
        }
    }

    pub fn reset_camera(&mut self) {
        self.params.camera = self.initial_camera.clone();
        self.camera_moving = true;
    }

    pub fn frame_all(&mut self) {
        if let Some(b) = self.scene.bounds() {
            let s = self.effective_settings();
            crate::scene::camera::control::frame_all(&mut self.params.camera, b, s.width, s.height);
            self.camera_moving = true;
        }
    }

    /// Carries out what the panels asked for this frame, in one place.
    pub fn apply(&mut self, requests: Requests, ctx: &egui::Context) {
        let Requests { camera_moved, reset_camera, frame_all, open, reload, open_dialog, export, toggle_compare, quit, gallery_case } = requests;
        if let Some(name) = gallery_case {
            self.open_gallery_case(name, false);
        }
        self.camera_moving |= camera_moved;
        if toggle_compare {
            self.compare.open = !self.compare.open;
        }
        if reset_camera {
            self.reset_camera();
        }
        if frame_all {
            self.frame_all();
        }
        if open_dialog {
            self.open_dialog.open = true;
        }
        if export {
            self.export.open_with(&self.scene.name, &self.settings.renderer);
        }
        if let Some(arg) = open.or_else(|| reload.then(|| self.scene_arg.clone())) {
            self.open(arg);
        }
        if quit {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    /// UI frames per second over the last second.
    pub fn ui_fps(&self) -> f32 {
        match (self.frame_times.front(), self.frame_times.back()) {
            (Some(a), Some(b)) if self.frame_times.len() > 1 && b > a => {
                (self.frame_times.len() - 1) as f32 / (*b - *a).as_secs_f32()
            }
            _ => 0.0,
        }
    }

    /// The Compare window and what it asks: measure the scene as edited,
    /// apply a configuration, export the chart.
    fn compare_window(&mut self, ctx: &egui::Context) {
        if !self.compare.open {
            // Closing the window (its button, the C key or the menu) stops the sweep.
            if self.compare.running() {
                self.compare.cancel();
            }
            return;
        }
        let current = crate::chart::describe(&self.settings.renderer, &self.effective_settings());
        let req = crate::app::panels::compare::show(ctx, &mut self.compare, &current);
        if req.measure {
            self.start_compare();
        }
        if let Some(c) = req.apply {
            self.settings.apply_configuration(&c.renderer, &c.settings);
            // The configuration replaces a gallery case's knobs: they are the user's now.
            self.gallery = None;
            self.message = Some(match c.glossy_model {
                // The model sweep's edit is of the materials, not the settings.
                Some(m) => format!("applied {}'s settings; its glossy model is an edit of the materials: choose {} in the Materials panel", c.label, crate::chart::glossy_models::name(m)),
                None => format!("applied {}", c.label),
            });
        }
        if let Some(c) = req.set_b {
            let mut b = self.settings.clone();
            b.apply_configuration(&c.renderer, &c.settings);
            self.split.set_b(b);
        }
        if req.export {
            let title = format!("{}: error against time; reference: {}", self.scene.name, self.compare.progress.lock().unwrap().reference.clone().unwrap_or_default());
            match self.compare.export(&title) {
                Ok(m) => self.message = Some(m),
                Err(e) => self.error_bar = Some(e),
            }
        }
    }

    /// Measures the scene as edited (camera, lights, materials) in the background.
    pub fn start_compare(&mut self) {
        let mut scene = (*self.scene).clone();
        self.params.apply(&mut scene);
        let rc = self.repaint_ctx.clone();
        let repaint = std::sync::Arc::new(move || {
            if let Some(ctx) = rc.lock().unwrap().as_ref() {
                ctx.request_repaint();
            }
        });
        self.compare.start(scene, self.settings.render.gi.seed, None, repaint);
    }

    /// Copies a newly published image into the texture.
    fn update_texture(&mut self, ctx: &egui::Context) {
        if let Some(kind) = self.settings.render.view.error_kind() {
            return self.update_error_texture(ctx, kind);
        }
        self.reference_view.clear();
        let out = self.worker.shared.output.lock().unwrap();
        if out.version == self.shown_version || out.width == 0 {
            return;
        }
        let image = egui::ColorImage::from_rgb([out.width as usize, out.height as usize], &out.rgb8);
        self.shown_version = out.version;
        drop(out);
        self.update_texture_of_a(ctx, image);
    }

    /// An error view: A's frame (rendered shaded) mapped against B or the
    /// scene's reference, again whenever either changes; the shaded image
    /// while there is no reference.
    fn update_error_texture(&mut self, ctx: &egui::Context, kind: crate::display::error_view::ErrorKind) {
        let b_version = if self.split.enabled { self.split.b_version().unwrap_or(0) } else { 0 };
        let out = self.worker.shared.output.lock().unwrap();
        let key = (out.version, b_version, kind);
        if out.width == 0 || self.reference_view.is_current(key) {
            return;
        }
        let b = if b_version > 0 { self.split.b_linear() } else { None };
        let b_label = self.split.b_label(&self.settings);
        let reference = self.scene.render.reference.clone();
        let rgb = self.reference_view.map(
            key,
            (out.width, out.height, &out.linear),
            b,
            &b_label,
            reference.as_deref(),
            &self.settings.render.display,
            self.params.render.exposure,
        );
        let image = egui::ColorImage::from_rgb([out.width as usize, out.height as usize], rgb.as_deref().unwrap_or(&out.rgb8));
        self.shown_version = out.version;
        drop(out);
        self.update_texture_of_a(ctx, image);
    }

    /// B's texture, and the difference and error of B against A.
    fn update_split(&mut self, ctx: &egui::Context) {
        if !self.split.enabled {
            return;
        }
        let out = self.worker.shared.output.lock().unwrap();
        let display = self.settings.render.display;
        self.split.update(ctx, (out.width, out.height, out.version, &out.linear), self.params.render.exposure, &display);
    }

    fn update_texture_of_a(&mut self, ctx: &egui::Context, image: egui::ColorImage) {
        match &mut self.texture {
            Some(t) => t.set(image, egui::TextureOptions::NEAREST),
            None => self.texture = Some(ctx.load_texture("pinhole-frame", image, egui::TextureOptions::NEAREST)),
        }
    }

    /// Keyboard shortcuts that work anywhere (not while typing).
    fn shortcuts(&mut self, ctx: &egui::Context) {
        use egui::{Key, KeyboardShortcut, Modifiers};
        if ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::S))) {
            self.export.open_with(&self.scene.name, &self.settings.renderer);
        }
        if ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::O))) {
            self.open_dialog.open = true;
        }
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let keys = [Key::Num1, Key::Num2, Key::Num3, Key::Num4, Key::Num5, Key::Num6, Key::Num7, Key::Num8, Key::Num9];
        for (i, k) in keys.iter().enumerate() {
            if ctx.input(|inp| inp.key_pressed(*k) && inp.modifiers.is_none()) {
                self.select_renderer(i);
            }
        }
        // B: two configurations side by side (B starts as the live one); X swaps them.
        if ctx.input(|i| i.key_pressed(Key::B) && i.modifiers.is_none()) {
            self.split.toggle(&self.settings);
        }
        if self.split.enabled && ctx.input(|i| i.key_pressed(Key::X) && i.modifiers.is_none()) {
            self.split.swap(&mut self.settings);
        }
        if ctx.input(|i| i.key_pressed(Key::C) && i.modifiers.is_none()) {
            self.compare.open = !self.compare.open;
        }
        if ctx.input(|i| i.key_pressed(Key::F) && i.modifiers.is_none()) {
            self.frame_all();
        }
        if ctx.input(|i| i.key_pressed(Key::Home)) {
            self.reset_camera();
        }
        // V / shift+V: next / previous debug view.
        if let Some(step) = ctx.input(|i| i.key_pressed(Key::V).then_some(if i.modifiers.shift { -1 } else { 1 })) {
            use crate::render::inspect::debug::View;
            let n = View::ALL.len() as i64;
            let at = View::ALL.iter().position(|v| *v == self.settings.render.view).unwrap_or(0) as i64;
            self.settings.render.view = View::ALL[(at + step).rem_euclid(n) as usize];
        }
        // Arrows move the selected pixel (shift: by 10), Esc clears it.
        if let Some((x, y)) = self.inspect.selected {
            let (dx, dy) = ctx.input_mut(|i| {
                let step = if i.modifiers.shift { 10 } else { 1 };
                // NONE matches logically, so shift+arrow counts too.
                let mut count = |k: Key| step * i.count_and_consume_key(Modifiers::NONE, k) as i64;
                (count(Key::ArrowRight) - count(Key::ArrowLeft), count(Key::ArrowDown) - count(Key::ArrowUp))
            });
            if (dx, dy) != (0, 0) {
                self.select_pixel(x as i64 + dx, y as i64 + dy);
            }
            if ctx.input(|i| i.key_pressed(Key::Escape)) {
                self.inspect.clear();
            }
        }
    }

    fn dropped_files(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).collect());
        if let Some(p) = dropped.into_iter().next() {
            self.open(p.to_string_lossy().into_owned());
        }
    }

    /// One frame of the whole viewer.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        {
            let mut rc = self.repaint_ctx.lock().unwrap();
            if rc.is_none() {
                *rc = Some(ctx.clone());
            }
        }
        let now = Instant::now();
        self.frame_times.push_back(now);
        while self.frame_times.front().is_some_and(|t| now.duration_since(*t) > Duration::from_secs(1)) {
            self.frame_times.pop_front();
        }
        self.camera_moving = false;
        self.poll_loader();
        self.poll_watch(&ctx);
        self.dropped_files(&ctx);
        self.shortcuts(&ctx);
        if let Some(b) = &mut self.bench {
            self.camera_moving |= b.frame(&mut self.params.camera);
            let report = b.done && !b.reported;
            b.reported |= b.done;
            if report {
                println!("ui-bench: {}", self.status_line());
            }
            ctx.request_repaint();
        }
        self.update_texture(&ctx);
        self.update_split(&ctx);

        let mut requests = Requests::default();
        requests |= crate::app::panels::menu::show(ui, &mut self.settings, &self.renderer_names, &mut self.inspect, &self.scene.name);
        if self.split.enabled {
            let a_label = crate::chart::describe(&self.settings.renderer, &self.effective_settings());
            let b_label = self.split.b_label(&self.settings);
            let r = crate::app::panels::split_bar::show(ui, &mut self.split, &a_label, &b_label);
            if r.swap {
                self.split.swap(&mut self.settings);
            }
            if r.b_from_a {
                self.split.set_b(self.settings.clone());
            }
            if r.close {
                self.split.enabled = false;
            }
        }
        if let Some(err) = self.error_bar.clone() {
            egui::Panel::top("error-bar")
                .frame(egui::Frame::new().fill(egui::Color32::from_rgb(110, 20, 20)).inner_margin(6.0))
                .show(ui, |ui| {
                    ui.horizontal(|ui| {
                        ui.colored_label(egui::Color32::WHITE, format!("Error: {err}"));
                        if ui.button("Dismiss").clicked() {
                            self.error_bar = None;
                        }
                    });
                });
        }
        let bar = crate::app::gallery::show(ui, self.gallery.as_ref());
        if let Some((name, cured)) = bar.show {
            self.open_gallery_case(name, cured);
        }
        if bar.leave {
            self.leave_gallery();
        }
        let status = crate::app::panels::status::Status {
            line: self.status_line(),
            ui_fps: self.ui_fps(),
            message: self.message.as_deref(),
            notices: self.with_output(|o| o.notices.clone()),
        };
        crate::app::panels::status::show(ui, status);
        if self.settings.panels.side {
            let (admitted, notices) = self.with_output(|o| (o.admitted.clone(), o.notices.clone()));
            egui::Panel::left("side-panel").default_size(300.0).resizable(true).show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    let (width, height) = (self.scene.render.width, self.scene.render.height);
                    let panels = &mut self.settings.panels;
                    let named = &self.scene.named_cameras;
                    requests |= crate::app::panels::camera::show(ui, &mut panels.camera, &mut self.params.camera, &mut self.settings.res_scale, (width, height), named);
                    crate::app::panels::lights::show(ui, &mut panels.lights, &mut self.params.lights, &self.params.camera, &self.scene);
                    crate::app::panels::materials::show(ui, &mut panels.materials, &mut self.params.materials);
                    let in_force = crate::app::panels::shading::InForce { admitted: admitted.as_ref(), notices: &notices };
                    crate::app::panels::shading::show(ui, &mut self.settings, &mut self.params.render, in_force);
                });
            });
        }
        if let Some((x, y)) = self.inspect.selected {
            let generation = self.generation;
            let frame_pixel = self.with_output(|o| {
                (o.complete && o.error.is_none() && o.generation == generation && x < o.width && y < o.height)
                    .then(|| o.linear[(x + y * o.width) as usize])
            });
            let viewed = crate::app::panels::inspector::Viewed {
                generation,
                scene: &self.scene,
                lights: &self.params.lights,
                materials: &self.params.materials,
                renderer: &self.settings.renderer,
                exposure: self.params.render.exposure,
                display: self.settings.render.display,
                frame_pixel,
            };
            crate::app::panels::inspector::show(ui, &mut self.inspect, &viewed);
        }
        let settings = self.effective_settings();
        let viewed = crate::app::viewed::Viewed {
            settings: &settings,
            renderer: &self.settings.renderer,
            exposure: self.params.render.exposure,
            display: self.settings.render.display,
            scene: &self.scene,
            scene_id: self.scene_id,
            generation: self.generation,
            texture: self.texture.as_ref(),
            output: &self.worker.shared.output,
            error: self.reference_view.mapped.as_ref(),
        };
        let edited = crate::app::viewport::Edited {
            camera: &mut self.params.camera,
            lights: &mut self.params.lights,
            inspect: &mut self.inspect,
            split: &mut self.split,
            state: &mut self.viewport,
        };
        let shown = egui::CentralPanel::default()
            .frame(egui::Frame::new().fill(egui::Color32::from_gray(24)))
            .show(ui, |ui| crate::app::viewport::show(ui, &viewed, edited))
            .inner;
        self.camera_moving |= shown.camera_moved;
        self.viewport_rect = shown.image_rect.or(self.viewport_rect);
        self.apply(requests, &ctx);
        if let Some(path) = self.open_dialog.show(&ctx) {
            self.open(path);
        }
        if let Some(path) = crate::app::export::show_dialog(&ctx, &mut self.export) {
            let result = self.with_output(|o| crate::app::export::export(o, &path));
            if let Some(note) = self.export.finish(result) {
                self.message = Some(note);
            }
        }
        self.compare_window(&ctx);

        self.sync_worker();
        self.sync_split();
        self.sync_inspector();
        crate::app::screenshot_frame(self, &ctx);
    }
}
