//! The Compare window's measurements: the methods sweep of `chart`, run on a
//! background thread on a small copy of the scene as edited, with progress
//! that the window reads each frame and a cancel flag it can raise.

use crate::chart::{self, Configuration, ErrorMetric, Measurement, ReferenceSource};
use crate::render::{PreparedScene, RenderSettings};
use crate::scene::Scene;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

/// The sweep's images are at most this wide: a sweep of twenty
/// configurations (and a path-traced reference) then takes seconds.
pub const LAB_WIDTH: u32 = 200;

/// What the thread has done so far.
#[derive(Default)]
pub struct Progress {
    /// "rendering the reference", "3/21 rasterize:fixed --msaa 4", "done"...
    pub stage: String,
    pub reference: Option<String>,
    /// The configurations measured so far, in sweep order.
    pub points: Vec<(Configuration, Measurement)>,
    pub total: usize,
    pub error: Option<String>,
    pub finished: bool,
}

/// The Compare window's state.
pub struct CompareLab {
    pub open: bool,
    pub metric: ErrorMetric,
    /// Where Export writes the chart (and the CSV beside it).
    pub export_path: String,
    pub progress: Arc<Mutex<Progress>>,
    cancel: Arc<AtomicBool>,
    /// Passes of the reference render done, for its progress bar.
    pub reference_passes: Arc<AtomicU32>,
    pub reference_spp: u32,
    /// Where path-traced references are cached (`None`: not cached).
    pub cache_dir: Option<PathBuf>,
    running: Option<std::thread::JoinHandle<()>>,
    /// The measurement the pointer is over, as an index into `points`.
    pub hovered: Option<usize>,
    /// The plot's last transform from plot to screen space (tests click through it).
    pub last_transform: Option<egui_plot::PlotTransform>,
}

impl Default for CompareLab {
    fn default() -> Self {
        CompareLab {
            open: false,
            metric: ErrorMetric::RelRmse,
            export_path: "pinhole-chart.png".into(),
            progress: Default::default(),
            cancel: Arc::new(AtomicBool::new(false)),
            reference_passes: Arc::new(AtomicU32::new(0)),
            reference_spp: chart::reference::PATH_REFERENCE_SPP,
            cache_dir: chart::reference::default_cache_dir(),
            running: None,
            hovered: None,
            last_transform: None,
        }
    }
}

/// The lab's image size for a scene of `width` x `height`: at most `LAB_WIDTH` wide.
pub fn lab_size(width: u32, height: u32) -> (u32, u32) {
    if width <= LAB_WIDTH {
        return (width.max(1), height.max(1));
    }
    let s = LAB_WIDTH as f32 / width as f32;
    (LAB_WIDTH, ((height as f32 * s).round() as u32).max(1))
}

impl CompareLab {
    pub fn running(&self) -> bool {
        self.running.as_ref().is_some_and(|h| !h.is_finished())
    }

    /// Starts measuring `scene` (already carrying the edited camera, lights
    /// and materials); a sweep in progress is cancelled first.
    pub fn start(&mut self, scene: Scene, seed: u64, reference: Option<PathBuf>, on_progress: Arc<dyn Fn() + Send + Sync>) {
        self.cancel_and_wait();
        self.cancel = Arc::new(AtomicBool::new(false));
        self.progress = Arc::new(Mutex::new(Progress { stage: "preparing the scene".into(), ..Default::default() }));
        self.reference_passes = Arc::new(AtomicU32::new(0));
        self.hovered = None;
        let (progress, cancel, passes) = (self.progress.clone(), self.cancel.clone(), self.reference_passes.clone());
        let (spp, cache) = (self.reference_spp, self.cache_dir.clone());
        self.running = Some(std::thread::spawn(move || {
            let job = Job { scene, seed, reference, reference_spp: spp, cache };
            let result = job.run(&progress, &cancel, &passes, &*on_progress);
            let mut p = progress.lock().unwrap();
            match result {
                Ok(()) if cancel.load(Ordering::Relaxed) => p.stage = "cancelled".into(),
                Ok(()) => p.stage = format!("done: {} configurations", p.points.len()),
                Err(e) => {
                    p.stage = "failed".into();
                    p.error = Some(e);
                }
            }
            p.finished = true;
            drop(p);
            on_progress();
        }));
    }

    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Cancels a sweep in progress and waits for its thread (a frame at most).
    pub fn cancel_and_wait(&mut self) {
        self.cancel();
        if let Some(h) = self.running.take() {
            let _ = h.join();
        }
    }

    /// Writes the chart as drawn by `pinhole chart` (PNG) and the CSV beside it.
    pub fn export(&self, title: &str) -> Result<String, String> {
        let path = PathBuf::from(self.export_path.trim());
        if path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() != Some("png") {
            return Err(format!("{}: the chart is written as .png", path.display()));
        }
        let points: Vec<Measurement> = self.progress.lock().unwrap().points.iter().map(|(_, m)| m.clone()).collect();
        if points.is_empty() {
            return Err("nothing measured yet".into());
        }
        let png = chart::plot::draw_methods_png(&points, self.metric, title, 1100, 700)?;
        let csv = path.with_extension("csv");
        crate::image_io::write_all_atomic(&[(&path, &png), (&csv, chart::methods_csv(&points).as_bytes())])?;
        Ok(format!("saved {} and {}", path.display(), csv.display()))
    }
}

impl Drop for CompareLab {
    fn drop(&mut self) {
        self.cancel_and_wait();
    }
}

/// What one sweep measures.
struct Job {
    scene: Scene,
    seed: u64,
    reference: Option<PathBuf>,
    reference_spp: u32,
    cache: Option<PathBuf>,
}

impl Job {
    fn run(self, progress: &Mutex<Progress>, cancel: &AtomicBool, passes: &AtomicU32, on_progress: &(dyn Fn() + Send + Sync)) -> Result<(), String> {
        let (width, height) = lab_size(self.scene.render.width, self.scene.render.height);
        let prepared = PreparedScene::new(self.scene);
        let source = ReferenceSource::choose(self.reference.as_deref(), &prepared, self.reference_spp);
        let stage = |s: String| {
            progress.lock().unwrap().stage = s;
            on_progress();
        };
        stage(format!("reference: {}", source.describe()));
        let Some(truth) = chart::load_reference(&source, &prepared, width, height, self.cache.as_deref(), cancel, Some(passes))? else {
            return Ok(());
        };
        let mut base = RenderSettings { width, height, ..RenderSettings::for_scene(&prepared.scene) };
        base.gi.seed = self.seed;
        let configs = chart::method_configurations(&prepared.scene, &base);
        let total = configs.len();
        {
            let mut p = progress.lock().unwrap();
            p.reference = Some(truth.name.clone());
            p.total = total;
        }
        for (i, c) in configs.into_iter().enumerate() {
            stage(format!("{}/{total}: {}", i + 1, c.label));
            let Some(m) = chart::measure(&prepared, &c, &truth, 3, cancel)? else {
                return Ok(());
            };
            progress.lock().unwrap().points.push((c, m));
            on_progress();
        }
        Ok(())
    }
}
