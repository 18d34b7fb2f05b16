//! The render worker: one thread that owns the `PreparedScene` and drives the
//! core's frame `Accumulator` band by band (a coarse preview first when the
//! frame is slow or the camera moves), sizing the bands to the time a band
//! takes, and publishes each band's running average for the UI. The UI never
//! waits on it: it sends requests over a channel, raises the cancel flag, and
//! reads the latest published image under a short lock.

use crate::math::Radiance;
use crate::render::inspect::debug::View;
use crate::render::frame::Accumulator;
use crate::render::{self, PreparedScene, RayCounts, RenderSettings, Renderer};
use crate::scene::{Camera, Light, Material, RenderDefaults, Scene};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// The editable, geometry-free part of a scene: changing it needs no BVH rebuild.
#[derive(Clone, Debug)]
pub struct SceneParams {
    pub camera: Camera,
    pub render: RenderDefaults,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
}

impl SceneParams {
    pub fn of(scene: &Scene) -> SceneParams {
        SceneParams {
            camera: scene.camera.clone(),
            render: scene.render.clone(),
            lights: scene.lights.clone(),
            materials: scene.materials.clone(),
        }
    }

    /// Copies these values into `scene` (its geometry stays).
    pub fn apply(&self, scene: &mut Scene) {
        scene.camera = self.camera.clone();
        scene.render = self.render.clone();
        scene.lights = self.lights.clone();
        let emission_changed = scene.materials.len() != self.materials.len() || scene.materials.iter().zip(&self.materials).any(|(a, b)| a.emission != b.emission);
        scene.materials = self.materials.clone();
        if emission_changed {
            scene.refresh_emitters();
        }
    }

    /// Equality that ignores textures (never edited; comparing texels every frame is waste).
    pub fn same_as(&self, o: &SceneParams) -> bool {
        self.camera == o.camera
            && self.render == o.render
            && self.lights == o.lights
            && self.materials.len() == o.materials.len()
            && self.materials.iter().zip(&o.materials).all(|(a, b)| a.same_but_texels(b))
    }

    /// Equal except for the display-only values (exposure).
    fn same_but_display(&self, o: &SceneParams) -> bool {
        let mut a = self.clone();
        a.render.exposure = o.render.exposure;
        a.same_as(o)
    }
}

/// What the UI asks the worker to show.
#[derive(Clone, Debug)]
pub struct Request {
    pub generation: u64,
    pub scene_id: u64,
    pub params: SceneParams,
    pub settings: RenderSettings,
    pub renderer: String,
    /// The camera is moving: show a coarse preview first.
    pub interactive: bool,
}

impl Request {
    /// The image on show as displayed: the scene's exposure and the display
    /// settings (stops, tone map, transfer curve).
    pub fn encode(&self, linear: &[Radiance]) -> Vec<u8> {
        let d = &self.settings.display;
        crate::display::image_rgb8(linear, d.scale(self.params.render.exposure), d.tonemap, d.gamma)
    }
}

/// Render settings equal but for the display transform (a change there
/// re-encodes the image on show, it renders nothing).
fn same_but_display(a: &RenderSettings, b: &RenderSettings) -> bool {
    let mut a = a.clone();
    a.display = b.display;
    a == *b
}

/// The inspector asks for one pixel replayed (`render::replay_pixel`) with
/// the values of a render request.
#[derive(Clone, Debug)]
pub struct ReplayRequest {
    /// Counts every replay asked for; the answer carries it back.
    pub id: u64,
    pub scene_id: u64,
    pub params: SceneParams,
    pub settings: RenderSettings,
    pub renderer: String,
    pub x: u32,
    pub y: u32,
}

/// A replayed pixel, or why it could not be replayed.
pub struct ReplayResult {
    pub id: u64,
    pub x: u32,
    pub y: u32,
    pub renderer: String,
    pub result: Result<render::PixelReplay, String>,
    /// Diff view: the same pixel replayed by `raytrace:brute` (both shaded).
    pub reference: Option<Result<render::PixelReplay, String>>,
    /// Time the replay took on the worker, ms.
    pub ms: f64,
}

enum Msg {
    SetScene { id: u64, scene: Arc<Scene> },
    Render(Box<Request>),
    Replay(Box<ReplayRequest>),
    Quit,
}

/// Timings and counters of the frame on show.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    /// Wall time of the last complete full-resolution pass, ms.
    pub pass_ms: f64,
    /// Time from the request to the first image (preview or first band), ms.
    pub first_image_ms: f64,
    /// Time from the request until every sample was done, ms (0 while rendering).
    pub frame_ms: f64,
    /// Counters of the last complete pass.
    pub counts: RayCounts,
    /// BVH build of the scene on show, ms.
    pub build_ms: f64,
    pub triangles: usize,
    /// Estimated noise left in the image (rmse / mean), once two passes are in.
    pub noise: Option<f32>,
}

/// The image the UI shows, as the worker last published it.
pub struct Output {
    pub width: u32,
    pub height: u32,
    /// Display-encoded image (`Request::encode`), RGB8 row-major.
    pub rgb8: Vec<u8>,
    /// Linear radiance: the running average of the samples so far.
    pub linear: Vec<Radiance>,
    /// Bumped on every publish.
    pub version: u64,
    /// The request this image belongs to (0: nothing yet).
    pub generation: u64,
    pub scene_id: u64,
    /// Full-resolution passes completed, out of `spp`.
    pub passes: u32,
    pub spp: u32,
    /// Some rows still show the coarse preview.
    pub preview: bool,
    /// All samples done for `generation`.
    pub complete: bool,
    /// The worker has nothing to do.
    pub idle: bool,
    pub stats: Stats,
    /// What the renderer reported when it failed (a panic message), or why
    /// it refused the request (`render::admit`).
    pub error: Option<String>,
    /// What the renderer draws otherwise than asked, one sentence each
    /// (`render::admit`), for the request last started.
    pub notices: Vec<String>,
    /// The settings the gate admitted for that request: those asked, or what
    /// the renderer draws in their place (`None` after a refusal).
    pub admitted: Option<RenderSettings>,
    /// Diff view, once complete: pixels that differ from `raytrace:brute`.
    pub differing_pixels: Option<u64>,
}

pub struct Shared {
    pub output: Mutex<Output>,
    pub changed: Condvar,
    /// The latest replay answered (the UI takes it).
    pub replay: Mutex<Option<ReplayResult>>,
}

/// The UI's handle on the worker thread.
pub struct Worker {
    tx: Sender<Msg>,
    cancel: Arc<AtomicBool>,
    pub shared: Arc<Shared>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Worker {
    /// Starts the worker; `repaint` is called whenever a new image is published.
    pub fn start(repaint: Arc<dyn Fn() + Send + Sync>) -> Worker {
        let (tx, rx) = channel();
        let cancel = Arc::new(AtomicBool::new(false));
        let shared = Arc::new(Shared {
            output: Mutex::new(Output {
                width: 0,
                height: 0,
                rgb8: Vec::new(),
                linear: Vec::new(),
                version: 0,
                generation: 0,
                scene_id: 0,
                passes: 0,
                spp: 1,
                preview: false,
                complete: false,
                idle: true,
                stats: Stats::default(),
                error: None,
                notices: Vec::new(),
                admitted: None,
                differing_pixels: None,
            }),
            changed: Condvar::new(),
            replay: Mutex::new(None),
        });
        let (c, s) = (cancel.clone(), shared.clone());
        let thread = std::thread::Builder::new()
            .name("pinhole-render".into())
            .spawn(move || WorkerLoop::new(rx, c, s, repaint).run())
            .expect("cannot start the render thread");
        Worker { tx, cancel, shared, thread: Some(thread) }
    }

    /// Hands a newly loaded scene to the worker (it builds the BVH there).
    pub fn set_scene(&self, id: u64, scene: Arc<Scene>) {
        self.cancel.store(true, Ordering::SeqCst);
        let _ = self.tx.send(Msg::SetScene { id, scene });
    }

    /// Asks for a new image; the frame in flight is abandoned.
    pub fn request(&self, req: Request) {
        self.cancel.store(true, Ordering::SeqCst);
        let _ = self.tx.send(Msg::Render(Box::new(req)));
    }

    /// Asks for a pixel replay. Unlike `request`, the frame in flight goes on:
    /// the replay runs between two of its bands.
    pub fn replay(&self, req: ReplayRequest) {
        let _ = self.tx.send(Msg::Replay(Box::new(req)));
    }

    /// Blocks until the replay `id` (or a later one) was answered (tests only).
    pub fn wait_replay(&self, id: u64, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        let mut out = self.shared.output.lock().unwrap();
        loop {
            if self.shared.replay.lock().unwrap().as_ref().is_some_and(|r| r.id >= id) {
                return true;
            }
            let now = Instant::now();
            if now >= deadline {
                return false;
            }
            out = self.shared.changed.wait_timeout(out, (deadline - now).min(Duration::from_millis(50))).unwrap().0;
        }
    }

    /// Blocks until the worker is idle with request `generation` done (tests
    /// and `--screenshot` only; the UI never calls this). False on timeout.
    pub fn wait_idle(&self, generation: u64, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        let mut out = self.shared.output.lock().unwrap();
        loop {
            if out.idle && out.generation >= generation {
                return true;
            }
            let now = Instant::now();
            if now >= deadline {
                return false;
            }
            out = self.shared.changed.wait_timeout(out, deadline - now).unwrap().0;
        }
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::SeqCst);
        let _ = self.tx.send(Msg::Quit);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The frame being rendered: the request, and the core's accumulator that
/// holds its samples; the rest is timing for the status bar and band sizing.
struct Frame {
    req: Request,
    renderer: Box<dyn Renderer>,
    /// What the renderer draws: `req.settings` as `render::admit` admitted them.
    settings: RenderSettings,
    frame: Accumulator,
    started: Instant,
    /// The coarse preview is still to come, before the passes.
    preview_pending: bool,
    pass_started: Instant,
    pass_counts: RayCounts,
    first_image: bool,
}

struct WorkerLoop {
    rx: Receiver<Msg>,
    cancel: Arc<AtomicBool>,
    shared: Arc<Shared>,
    repaint: Arc<dyn Fn() + Send + Sync>,
    pool: rayon::ThreadPool,
    prepared: Option<(u64, PreparedScene)>,
    frame: Option<Frame>,
    /// The last request rendered to completion.
    last_req: Option<Request>,
    /// Milliseconds per row of the last full-resolution pass, for band sizing.
    ms_per_row: f64,
    /// The preview renders at 1/`preview_div` of the resolution, adapted so
    /// it takes about one display frame (4 to 32).
    preview_div: u32,
    /// Renderer and scene the timings above were measured with.
    timed: (String, u64),
}

/// Aim for a band to take about this long, so the texture updates often.
const BAND_MS: f64 = 30.0;
/// Aim for a coarse preview to take about this long.
const PREVIEW_MS: f64 = 20.0;

impl WorkerLoop {
    fn new(rx: Receiver<Msg>, cancel: Arc<AtomicBool>, shared: Arc<Shared>, repaint: Arc<dyn Fn() + Send + Sync>) -> Self {
        let pool = rayon::ThreadPoolBuilder::new()
            .thread_name(|i| format!("pinhole-render-{i}"))
            .build()
            .expect("cannot start the render thread pool");
        WorkerLoop { rx, cancel, shared, repaint, pool, prepared: None, frame: None, last_req: None, ms_per_row: -1.0, preview_div: 16, timed: (String::new(), 0) }
    }

    fn run(mut self) {
        loop {
            // Block only when there is nothing to render.
            let first = if self.frame.is_none() {
                self.set_idle(true);
                match self.rx.recv() {
                    Ok(m) => Some(m),
                    Err(_) => return,
                }
            } else {
                None
            };
            self.cancel.store(false, Ordering::SeqCst);
            let mut new_scene = None;
            let mut new_req = None;
            let mut new_replay = None;
            for msg in first.into_iter().chain(self.rx.try_iter()) {
                match msg {
                    Msg::Quit => return,
                    Msg::SetScene { id, scene } => new_scene = Some((id, scene)),
                    Msg::Render(r) => new_req = Some(*r),
                    // Only the latest pixel matters.
                    Msg::Replay(r) => new_replay = Some(*r),
                }
            }
            if let Some((id, scene)) = new_scene {
                self.set_idle(false);
                let prepared = PreparedScene::new((*scene).clone());
                let mut out = self.shared.output.lock().unwrap();
                out.stats.build_ms = prepared.build_ms;
                out.stats.triangles = prepared.scene.triangles.len();
                drop(out);
                self.prepared = Some((id, prepared));
                self.frame = None;
            }
            if let Some(req) = new_req {
                self.set_idle(false);
                self.start(req);
            }
            if let Some(r) = new_replay {
                self.replay(r);
            }
            if self.frame.is_some() {
                self.step();
            }
        }
    }

    fn set_idle(&self, idle: bool) {
        let mut out = self.shared.output.lock().unwrap();
        if out.idle != idle {
            out.idle = idle;
            drop(out);
            self.shared.changed.notify_all();
        }
    }

    /// Begins `req`: a display-only change re-encodes the image on show;
    /// anything else starts a new frame.
    fn start(&mut self, req: Request) {
        let Some((scene_id, prepared)) = self.prepared.as_mut() else { return };
        if req.scene_id != *scene_id {
            return; // a request for a scene not loaded yet; its SetScene follows
        }
        // Display-only change: same image, another display transform.
        if let Some(f) = self.frame.as_mut() {
            if f.req.scene_id == req.scene_id
                && f.req.renderer == req.renderer
                && same_but_display(&f.req.settings, &req.settings)
                && f.req.params.same_but_display(&req.params)
            {
                f.req = Request { interactive: f.req.interactive, ..req };
                let mut out = self.shared.output.lock().unwrap();
                out.rgb8 = f.req.encode(&out.linear);
                out.generation = f.req.generation;
                out.version += 1;
                drop(out);
                self.publish_done();
                return;
            }
        }
        let display_only = {
            let out = self.shared.output.lock().unwrap();
            out.complete && self.frame.is_none() && out.scene_id == req.scene_id
        } && self.last_req.as_ref().is_some_and(|l| {
            l.renderer == req.renderer && same_but_display(&l.settings, &req.settings) && l.params.same_but_display(&req.params)
        });
        if display_only {
            let mut out = self.shared.output.lock().unwrap();
            out.rgb8 = req.encode(&out.linear);
            out.generation = req.generation;
            out.version += 1;
            drop(out);
            self.last_req = Some(req);
            self.publish_done();
            return;
        }
        req.params.apply(&mut prepared.scene);
        let renderer = match render::renderer_by_name(&req.renderer) {
            Ok(r) => r,
            Err(e) => {
                self.fail(&req, e);
                return;
            }
        };
        let asked = RenderSettings { width: req.settings.width.max(1), height: req.settings.height.max(1), ..req.settings.clone() };
        // The gate the command line asks too: what the renderer cannot draw
        // (or input made too big to allocate) is refused in one sentence.
        let admitted = render::admit::admit(renderer.as_ref(), &prepared.scene, &asked);
        let admitted = admitted.and_then(|a| renderer.ready(&a.settings).map(|()| a));
        let pool = &self.pool;
        let admitted = admitted.and_then(|a| pool.install(|| render::admit::admit_prepared(prepared, &a.settings)).map(|()| a));
        let render::admit::Admitted { settings, mut notices, caveats } = match admitted {
            Ok(a) => a,
            Err(e) => {
                self.fail(&req, e);
                return;
            }
        };
        {
            let mut out = self.shared.output.lock().unwrap();
            notices.extend(caveats);
            out.notices = notices;
            out.admitted = Some(settings.clone());
        }
        let (width, height) = (settings.width, settings.height);
        if self.timed != (req.renderer.clone(), req.scene_id) {
            // Another renderer or scene: old timings mean nothing.
            self.timed = (req.renderer.clone(), req.scene_id);
            self.ms_per_row = -1.0;
            self.preview_div = 16;
        }
        let slow = self.ms_per_row < 0.0 || self.ms_per_row * height as f64 > 2.0 * BAND_MS;
        let now = Instant::now();
        self.frame = Some(Frame {
            renderer,
            frame: Accumulator::new(&settings),
            settings,
            started: now,
            preview_pending: (req.interactive || slow) && width >= 8 && height >= 8,
            pass_started: now,
            pass_counts: RayCounts::default(),
            first_image: false,
            req,
        });
    }

    /// Replays one pixel through the renderer's own code path with a recorder,
    /// on this thread between two bands, so the UI never waits for it.
    fn replay(&mut self, r: ReplayRequest) {
        let started = Instant::now();
        let mut reference = None;
        let result = match self.prepared.as_mut() {
            Some((id, prepared)) if *id == r.scene_id => {
                r.params.apply(&mut prepared.scene);
                // The diff view replays the shaded pixel of both this
                // renderer and the reference it is compared with.
                let diff = r.settings.view == View::Diff;
                let settings = if diff { RenderSettings { view: View::Shaded, ..r.settings.clone() } } else { r.settings.clone() };
                let pool = &self.pool;
                let prepared_ref = &*prepared;
                // The pixel as the frame drew it: with the settings the gate admitted.
                let run = |renderer: &dyn Renderer| {
                    let admitted = render::admit::admit(renderer, &prepared_ref.scene, &settings)?;
                    pool.install(|| guarded(|| render::replay_pixel(renderer, prepared_ref, &admitted.settings, r.x, r.y))).and_then(|x| x)
                };
                let result = render::renderer_by_name(&r.renderer).and_then(|renderer| run(renderer.as_ref()));
                reference = diff.then(|| run(&render::raytrace::brute_renderer::BruteForce));
                // The frame in flight goes on with its own values.
                if let Some(f) = &self.frame {
                    f.req.params.apply(&mut prepared.scene);
                }
                result
            }
            _ => Err("the scene is still loading".to_string()),
        };
        let answer = ReplayResult { id: r.id, x: r.x, y: r.y, renderer: r.renderer, result, reference, ms: started.elapsed().as_secs_f64() * 1e3 };
        *self.shared.replay.lock().unwrap() = Some(answer);
        self.publish_done();
    }

    fn fail(&mut self, req: &Request, message: String) {
        let mut out = self.shared.output.lock().unwrap();
        out.error = Some(message);
        out.notices.clear();
        out.admitted = None;
        out.generation = req.generation;
        out.complete = true;
        out.version += 1;
        drop(out);
        self.frame = None;
        self.last_req = None;
        self.publish_done();
    }

    fn publish_done(&self) {
        self.shared.changed.notify_all();
        (self.repaint)();
    }

    /// Renders one unit of work: the preview, or one band of one pass.
    fn step(&mut self) {
        let Some(mut f) = self.frame.take() else { return };
        let Some((_, prepared)) = self.prepared.as_ref() else { return };
        let cancel: &AtomicBool = &self.cancel;
        let (width, height) = (f.frame.width(), f.frame.height());
        if f.preview_pending {
            f.preview_pending = false;
            let div = self.preview_div;
            let (pw, ph) = ((width / div).max(1), (height / div).max(1));
            // One sample at 1/div of the resolution, shaded for the diff view.
            let view = if f.settings.view == View::Diff { View::Shaded } else { f.settings.view };
            let settings = RenderSettings { width: pw, height: ph, spp: 1, view, ..f.settings.clone() };
            let mut preview = Accumulator::new(&settings);
            // The preview is not cancelled: it is cheap by construction (its
            // size adapts), and while the camera moves every frame cancels the
            // one before, so a cancellable preview would never be seen.
            let keep_going = AtomicBool::new(false);
            let renderer = f.renderer.as_ref();
            let result = self.pool.install(|| guarded(|| preview.render_band(renderer, prepared, ph, &keep_going)));
            if let Err(e) = result {
                self.fail(&f.req, e);
                return;
            }
            let small = preview.finish().pixels;
            // Nearest-neighbour upsampling into the display image.
            let (w, h) = (width, height);
            let mut big = vec![Radiance::ZERO; (w * h) as usize];
            for y in 0..h {
                let sy = (y * ph / h).min(ph - 1);
                for x in 0..w {
                    let sx = (x * pw / w).min(pw - 1);
                    big[(x + y * w) as usize] = small[(sx + sy * pw) as usize];
                }
            }
            let first_ms = f.started.elapsed().as_secs_f64() * 1e3;
            // Aim the next preview at ~20 ms: its cost scales with 1/div^2.
            let full_ms = first_ms * (div * div) as f64;
            self.preview_div = ((full_ms / PREVIEW_MS).sqrt().ceil() as u32).clamp(4, 32);
            f.first_image = true;
            let req = &f.req;
            let mut out = self.shared.output.lock().unwrap();
            out.rgb8 = req.encode(&big);
            out.linear = big;
            out.width = w;
            out.height = h;
            out.generation = req.generation;
            out.scene_id = req.scene_id;
            out.passes = 0;
            out.spp = f.frame.spp();
            out.preview = true;
            out.complete = false;
            out.error = None;
            out.stats.first_image_ms = first_ms;
            out.stats.frame_ms = 0.0;
            out.differing_pixels = None;
            out.version += 1;
            drop(out);
            self.frame = Some(f);
            self.publish_done();
            return;
        }

        // A sub-sampled frame is rendered whole: which cells are traced in
        // full depends on the grid around them.
        if f.settings.subsample.is_on() && f.settings.view == View::Shaded {
            let renderer = f.renderer.as_ref();
            let settings = &f.settings;
            let result = self.pool.install(|| guarded(|| render::frame::subsample::render_subsampled(renderer, prepared, settings, cancel, None)));
            match result {
                Ok(Some(frame)) => self.publish_whole(f, frame),
                Ok(None) => self.frame = Some(f),
                Err(e) => self.fail(&f.req, e),
            }
            return;
        }

        // One band of the current pass.
        let spp = f.frame.spp();
        let band_rows = if self.ms_per_row > 0.0 { (BAND_MS / self.ms_per_row).clamp(1.0, height as f64) as u32 } else { (height / 16).max(1) };
        if f.frame.next_row() == 0 {
            f.pass_started = Instant::now();
            f.pass_counts = RayCounts::default();
        }
        let band_start = Instant::now();
        let (renderer, frame) = (f.renderer.as_ref(), &mut f.frame);
        let result = self.pool.install(|| guarded(|| frame.render_band(renderer, prepared, band_rows, cancel)));
        let band = match result {
            Ok(Some(band)) => band,
            Ok(None) => {
                // Cancelled, nothing added: the loop looks at what came in,
                // and a display-only change renders this band again.
                self.frame = Some(f);
                return;
            }
            Err(e) => {
                self.fail(&f.req, e);
                return;
            }
        };
        let band_ms = band_start.elapsed().as_secs_f64() * 1e3;
        f.pass_counts += band.counts;
        let rows = band.rows.clone();
        let display = f.frame.mean_rows(rows.clone());
        let rgb = f.req.encode(&display);
        let pass_ms = f.pass_started.elapsed().as_secs_f64() * 1e3;
        self.ms_per_row = if band.pass_done { pass_ms / height as f64 } else { band_ms / rows.len() as f64 };
        let complete = f.frame.is_complete();
        let first_image = !f.first_image;
        f.first_image = true;
        let passes = f.frame.passes_done();
        let noise = if band.pass_done { f.frame.noise_estimate() } else { None };
        let (generation, scene_id) = (f.req.generation, f.req.scene_id);
        let (elapsed_ms, pass_counts) = (f.started.elapsed().as_secs_f64() * 1e3, f.pass_counts);
        // The finished frame replaces the running average whole (for the
        // diff view it is the difference image).
        let finished = if complete {
            let result = f.frame.finish();
            let rgb8 = f.req.encode(&result.pixels);
            self.last_req = Some(f.req);
            Some((result, rgb8))
        } else {
            self.frame = Some(f);
            None
        };
        let mut out = self.shared.output.lock().unwrap();
        if out.generation != generation {
            out.error = None;
            out.passes = 0;
            out.differing_pixels = None;
        }
        if out.width != width || out.height != height {
            // Rows not rendered yet show black until their band arrives.
            out.width = width;
            out.height = height;
            out.linear = vec![Radiance::ZERO; (width * height) as usize];
            out.rgb8 = vec![0; (width * height * 3) as usize];
            out.preview = false;
        }
        if first_image {
            out.stats.first_image_ms = elapsed_ms;
        }
        let (a, b) = (rows.start as usize * width as usize, rows.end as usize * width as usize);
        out.linear[a..b].copy_from_slice(&display);
        out.rgb8[a * 3..b * 3].copy_from_slice(&rgb);
        out.generation = generation;
        out.scene_id = scene_id;
        out.spp = spp;
        if band.pass_done {
            out.passes = passes;
            out.preview = false;
            out.stats.pass_ms = pass_ms;
            out.stats.counts = pass_counts;
            out.stats.noise = noise;
        }
        out.complete = complete;
        if let Some((result, rgb8)) = finished {
            out.linear = result.pixels;
            out.rgb8 = rgb8;
            out.differing_pixels = result.differing_pixels;
            out.stats.frame_ms = elapsed_ms;
        }
        out.version += 1;
        drop(out);
        self.publish_done();
    }
}

impl WorkerLoop {
    /// Shows a frame rendered whole (not band by band) as complete.
    fn publish_whole(&mut self, f: Frame, frame: render::FrameResult) {
        let elapsed_ms = f.started.elapsed().as_secs_f64() * 1e3;
        let rgb8 = f.req.encode(&frame.pixels);
        let mut out = self.shared.output.lock().unwrap();
        out.error = None;
        out.width = frame.width;
        out.height = frame.height;
        out.linear = frame.pixels;
        out.rgb8 = rgb8;
        out.generation = f.req.generation;
        out.scene_id = f.req.scene_id;
        out.spp = f.settings.spp.max(1);
        out.passes = out.spp;
        out.preview = false;
        out.complete = true;
        out.differing_pixels = None;
        if !f.first_image {
            out.stats.first_image_ms = elapsed_ms;
        }
        out.stats.pass_ms = elapsed_ms / out.spp as f64;
        out.stats.counts = frame.counts;
        out.stats.noise = None;
        out.stats.frame_ms = elapsed_ms;
        out.version += 1;
        drop(out);
        self.last_req = Some(f.req);
        self.publish_done();
    }
}

/// Runs a renderer, turning a panic (e.g. a mode it does not implement) into a message.
fn guarded<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).map_err(|p| {
        let msg = p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "the renderer failed".into());
        format!("renderer error: {msg}")
    })
}
