//! The render worker: one thread that owns the `PreparedScene`, renders the
//! requested frame band by band (a coarse preview first when the frame is
//! slow or the camera moves), accumulates stratified passes up to the chosen
//! spp and publishes finished bands for the UI. The UI never waits on it: it
//! sends requests over a channel, raises the cancel flag, and reads the
//! latest published image under a short lock.

use crate::image_io;
use crate::math::{Radiance, Vec3};
use crate::render::debug::View;
use crate::render::{self, PassJob, PreparedScene, RayCounts, RenderSettings, Renderer};
use crate::scene::{Camera, Light, Material, RenderDefaults, Scene};
use std::ops::Range;
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
        scene.materials = self.materials.clone();
    }

    /// Equality that ignores textures (never edited; comparing texels every frame is waste).
    pub fn same_as(&self, o: &SceneParams) -> bool {
        self.camera == o.camera
            && self.render == o.render
            && self.lights == o.lights
            && self.materials.len() == o.materials.len()
            && self.materials.iter().zip(&o.materials).all(|(a, b)| {
                a.name == b.name
                    && a.lambertian == b.lambertian
                    && a.glossy == b.glossy
                    && a.sharpness == b.sharpness
                    && a.mirror == b.mirror
                    && a.transmission == b.transmission
                    && a.ior == b.ior
            })
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
    pub gamma: bool,
    /// The camera is moving: show a coarse preview first.
    pub interactive: bool,
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
}

/// The image the UI shows, as the worker last published it.
pub struct Output {
    pub width: u32,
    pub height: u32,
    /// Display-encoded image (exposure, sRGB if gamma on), RGB8 row-major.
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
    /// What the renderer reported when it failed (a panic message).
    pub error: Option<String>,
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

/// Progress of the frame being rendered.
struct Frame {
    req: Request,
    renderer: Box<dyn Renderer>,
    /// What each pass renders with: the request's settings, shaded for the diff view.
    pass_settings: RenderSettings,
    /// Diff view: the reference `raytrace:brute` and the sum of its samples,
    /// rendered band by band beside this renderer; the difference image
    /// replaces the shaded one when every sample is done.
    reference: Option<(Box<dyn Renderer>, Vec<Radiance>)>,
    started: Instant,
    width: u32,
    height: u32,
    /// Sum of the samples per pixel, and per row how many passes it holds.
    sum: Vec<Radiance>,
    row_passes: Vec<u32>,
    /// Next pass and next row to render; `preview_pending` before the passes.
    pass: u32,
    row: u32,
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
        // Display-only change: same image, different exposure or gamma.
        if let Some(f) = self.frame.as_mut() {
            if f.req.scene_id == req.scene_id
                && f.req.renderer == req.renderer
                && f.req.settings == req.settings
                && f.req.params.same_but_display(&req.params)
            {
                f.req = Request { interactive: f.req.interactive, ..req };
                let mut out = self.shared.output.lock().unwrap();
                out.rgb8 = image_io::to_rgb8(&out.linear, f.req.params.render.exposure, f.req.gamma);
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
            l.renderer == req.renderer && l.settings == req.settings && l.params.same_but_display(&req.params)
        });
        if display_only {
            let mut out = self.shared.output.lock().unwrap();
            out.rgb8 = image_io::to_rgb8(&out.linear, req.params.render.exposure, req.gamma);
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
        let (width, height) = (req.settings.width.max(1), req.settings.height.max(1));
        let n = (width * height) as usize;
        if self.timed != (req.renderer.clone(), req.scene_id) {
            // Another renderer or scene: old timings mean nothing.
            self.timed = (req.renderer.clone(), req.scene_id);
            self.ms_per_row = -1.0;
            self.preview_div = 16;
        }
        let slow = self.ms_per_row < 0.0 || self.ms_per_row * height as f64 > 2.0 * BAND_MS;
        let now = Instant::now();
        let diff = req.settings.view == View::Diff;
        let pass_settings = if diff { RenderSettings { view: View::Shaded, ..req.settings.clone() } } else { req.settings.clone() };
        self.frame = Some(Frame {
            renderer,
            pass_settings,
            reference: diff.then(|| (Box::new(render::raytrace::brute::BruteForce) as Box<dyn Renderer>, vec![Radiance::ZERO; n])),
            started: now,
            width,
            height,
            sum: vec![Radiance::ZERO; n],
            row_passes: vec![0; height as usize],
            pass: 0,
            row: 0,
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
                let run = |renderer: &dyn Renderer| {
                    pool.install(|| guarded(|| render::replay_pixel(renderer, prepared_ref, &settings, r.x, r.y))).and_then(|x| x)
                };
                let result = render::renderer_by_name(&r.renderer).and_then(|renderer| run(renderer.as_ref()));
                reference = diff.then(|| run(&render::raytrace::brute::BruteForce));
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
        let Some((_, prepared)) = self.prepared.as_ref() else {
            self.frame = None;
            return;
        };
        let f = self.frame.as_mut().expect("step without a frame");
        let cancel: &AtomicBool = &self.cancel;
        if f.preview_pending {
            f.preview_pending = false;
            let div = self.preview_div;
            let (pw, ph) = ((f.width / div).max(1), (f.height / div).max(1));
            let view = prepared.scene.camera.view(pw, ph);
            let mut settings = f.pass_settings.clone();
            settings.width = pw;
            settings.height = ph;
            settings.spp = 1;
            let mut small = vec![Radiance::ZERO; (pw * ph) as usize];
            // The preview is not cancelled: it is cheap by construction (its
            // size adapts), and while the camera moves every frame cancels the
            // one before, so a cancellable preview would never be seen.
            let keep_going = AtomicBool::new(false);
            let job = PassJob { prepared, view: &view, settings: &settings, offset: render::sample_offset(0, 1), rows: 0..ph, cancel: &keep_going };
            let renderer = &f.renderer;
            let result = self.pool.install(|| guarded(|| renderer.render_pass(&job, &mut small)));
            if let Err(e) = result {
                let req = f.req.clone();
                self.fail(&req, e);
                return;
            }
            // Nearest-neighbour upsampling into the display image.
            let (w, h) = (f.width, f.height);
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
            let req = f.req.clone();
            let mut out = self.shared.output.lock().unwrap();
            out.rgb8 = image_io::to_rgb8(&big, req.params.render.exposure, req.gamma);
            out.linear = big;
            out.width = w;
            out.height = h;
            out.generation = req.generation;
            out.scene_id = req.scene_id;
            out.passes = 0;
            out.spp = req.settings.spp.max(1);
            out.preview = true;
            out.complete = false;
            out.error = None;
            out.stats.first_image_ms = first_ms;
            out.stats.frame_ms = 0.0;
            out.differing_pixels = None;
            out.version += 1;
            drop(out);
            self.publish_done();
            return;
        }

        // One band of the current pass.
        let spp = f.req.settings.spp.max(1);
        let band = if self.ms_per_row > 0.0 { (BAND_MS / self.ms_per_row).clamp(1.0, f.height as f64) as u32 } else { (f.height / 16).max(1) };
        let rows: Range<u32> = f.row..(f.row + band).min(f.height);
        if rows.start == 0 {
            f.pass_started = Instant::now();
            f.pass_counts = RayCounts::default();
        }
        let view = prepared.scene.camera.view(f.width, f.height);
        let settings = f.pass_settings.clone();
        let mut buf = vec![Radiance::ZERO; (f.width * rows.len() as u32) as usize];
        let job = PassJob { prepared, view: &view, settings: &settings, offset: render::sample_offset(f.pass, spp), rows: rows.clone(), cancel };
        let renderer = &f.renderer;
        let band_start = Instant::now();
        let result = self.pool.install(|| guarded(|| renderer.render_pass(&job, &mut buf)));
        if cancel.load(Ordering::Relaxed) {
            return;
        }
        let counts = match result {
            Ok(c) => c,
            Err(e) => {
                let req = f.req.clone();
                self.fail(&req, e);
                return;
            }
        };
        let w = f.width as usize;
        if let Some((reference, ref_sum)) = f.reference.as_mut() {
            let mut theirs = vec![Radiance::ZERO; buf.len()];
            let result = self.pool.install(|| guarded(|| reference.render_pass(&job, &mut theirs)));
            if cancel.load(Ordering::Relaxed) {
                return;
            }
            if let Err(e) = result {
                let req = f.req.clone();
                self.fail(&req, e);
                return;
            }
            let a = rows.start as usize * w;
            for (s, p) in ref_sum[a..a + theirs.len()].iter_mut().zip(&theirs) {
                *s += if p.is_finite() { *p } else { Vec3::ZERO };
            }
        }
        let band_ms = band_start.elapsed().as_secs_f64() * 1e3;
        f.pass_counts += counts;
        let mut display = Vec::with_capacity(buf.len());
        for (i, y) in rows.clone().enumerate() {
            let row_sum = &mut f.sum[y as usize * w..(y as usize + 1) * w];
            for (s, p) in row_sum.iter_mut().zip(&buf[i * w..(i + 1) * w]) {
                *s += if p.is_finite() { *p } else { Vec3::ZERO };
            }
            f.row_passes[y as usize] += 1;
            let inv = 1.0 / f.row_passes[y as usize] as f32;
            display.extend(row_sum.iter().map(|s| *s * inv));
        }
        let rgb = image_io::to_rgb8(&display, f.req.params.render.exposure, f.req.gamma);
        f.row = rows.end;
        let mut pass_done = false;
        if f.row >= f.height {
            f.row = 0;
            f.pass += 1;
            pass_done = true;
            let pass_ms = f.pass_started.elapsed().as_secs_f64() * 1e3;
            self.ms_per_row = pass_ms / f.height as f64;
        } else {
            self.ms_per_row = band_ms / rows.len() as f64;
        }
        let complete = f.pass >= spp;
        let first_image = !f.first_image;
        f.first_image = true;
        let req = &f.req;
        let mut out = self.shared.output.lock().unwrap();
        if out.generation != req.generation {
            out.error = None;
            out.passes = 0;
            out.differing_pixels = None;
        }
        if out.width != f.width || out.height != f.height {
            // Rows not rendered yet show black until their band arrives.
            out.width = f.width;
            out.height = f.height;
            out.linear = vec![Radiance::ZERO; (f.width * f.height) as usize];
            out.rgb8 = vec![0; (f.width * f.height * 3) as usize];
            out.preview = false;
        }
        if first_image {
            out.stats.first_image_ms = f.started.elapsed().as_secs_f64() * 1e3;
        }
        let (a, b) = (rows.start as usize * w, rows.end as usize * w);
        out.linear[a..b].copy_from_slice(&display);
        out.rgb8[a * 3..b * 3].copy_from_slice(&rgb);
        out.generation = req.generation;
        out.scene_id = req.scene_id;
        out.spp = spp;
        if pass_done {
            out.passes = f.pass;
            out.preview = false;
            out.stats.pass_ms = f.pass_started.elapsed().as_secs_f64() * 1e3;
            out.stats.counts = f.pass_counts;
        }
        out.complete = complete;
        if complete {
            if let Some((_, ref_sum)) = &f.reference {
                // Averaged as render_frame averages, then the core's diff.
                let inv = 1.0 / spp as f32;
                let mine: Vec<Radiance> = f.sum.iter().map(|s| *s * inv).collect();
                let theirs: Vec<Radiance> = ref_sum.iter().map(|s| *s * inv).collect();
                let (image, count) = render::debug::diff_image(&mine, &theirs);
                out.rgb8 = image_io::to_rgb8(&image, req.params.render.exposure, req.gamma);
                out.linear = image;
                out.differing_pixels = Some(count);
            }
            out.stats.frame_ms = f.started.elapsed().as_secs_f64() * 1e3;
        }
        out.version += 1;
        drop(out);
        if complete {
            let f = self.frame.take().unwrap();
            self.last_req = Some(f.req);
        }
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
