//! Visual debugging state: the selected pixel and its replay, the
//! image zoom and pan, the vertex overlay, and what the values of a debug
//! view mean (for the hover read-out and the inspector).
//!
//! The replay itself runs on the render worker between two bands
//! (`Worker::replay`), through the renderer's own code path with a recorder,
//! so the UI never waits for it and its radiance is the frame's pixel.

use crate::app::worker::{ReplayRequest, ReplayResult};
use crate::app::PinholeApp;
use crate::math::{Radiance, Vec3};
use crate::render::inspect::debug::{depth_distance, invert_cost, object_of_id_color, zbuffer_depth, COST_SCALE};
use crate::render::PixelReplay;
use crate::scene::{CameraView, PrimitiveKind, Scene};
use eframe::egui;
use std::time::Duration;

/// A replay answered by the worker, with the request it belongs to.
pub struct Replayed {
    pub x: u32,
    pub y: u32,
    pub renderer: String,
    /// The render request (`PinholeApp::generation`) whose values it used.
    pub generation: u64,
    pub result: Result<PixelReplay, String>,
    /// Diff view: the same pixel by `raytrace:brute`.
    pub reference: Option<Result<PixelReplay, String>>,
    pub ms: f64,
}

/// What the user looks at closely.
pub struct Inspect {
    /// The selected pixel (image coordinates of the frame on show).
    pub selected: Option<(u32, u32)>,
    /// The pixel under the cursor.
    pub hover: Option<(u32, u32)>,
    /// The latest replay answered for the selection.
    pub replay: Option<Replayed>,
    /// Replay in flight: (id, generation, x, y).
    in_flight: Option<(u64, u64, u32, u32)>,
    next_id: u64,
    /// Image magnification over the fitted size (1 = fit / 1:1), and its
    /// offset from the centred position, in points.
    pub zoom: f32,
    pub pan: egui::Vec2,
    /// Draw every projected triangle vertex as a dot (CGPP 15.6.2).
    pub vertices: bool,
    /// Draw the selected pixel's rays into the view.
    pub paths: bool,
    /// Centre the selected pixel in the viewport on the next frame.
    pub center_on_selection: bool,
    /// The distinct vertices of scene `.0`, for the vertex overlay.
    pub vertex_cache: Option<(u64, std::sync::Arc<Vec<Vec3>>)>,
}

impl Default for Inspect {
    fn default() -> Self {
        Inspect { selected: None, hover: None, replay: None, in_flight: None, next_id: 0, zoom: 1.0, pan: egui::Vec2::ZERO, vertices: false, paths: true, center_on_selection: false, vertex_cache: None }
    }
}

/// Most zoom: one image pixel this many times its fitted size.
pub const MAX_ZOOM: f32 = 64.0;

impl Inspect {
    /// The replay of the current selection for render request `generation`, if answered.
    pub fn current(&self, generation: u64) -> Option<&Replayed> {
        let (x, y) = self.selected?;
        self.replay.as_ref().filter(|r| r.x == x && r.y == y && r.generation == generation)
    }

    /// A pixel is selected but its replay for `generation` has not arrived.
    pub fn waiting(&self, generation: u64) -> bool {
        self.selected.is_some() && self.current(generation).is_none()
    }

    /// Selects pixel `(x, y)`, clamped into a `width` x `height` image.
    pub fn select(&mut self, x: i64, y: i64, width: u32, height: u32) {
        let x = x.clamp(0, width as i64 - 1) as u32;
        let y = y.clamp(0, height as i64 - 1) as u32;
        self.selected = Some((x, y));
    }

    pub fn clear(&mut self) {
        self.selected = None;
        self.replay = None;
    }

    /// Sets the zoom, keeping the image point under `anchor` (screen
    /// position, relative to the viewport centre) where it is.
    pub fn zoom_about(&mut self, new_zoom: f32, anchor: egui::Vec2) {
        let new_zoom = new_zoom.clamp(1.0, MAX_ZOOM);
        let k = new_zoom / self.zoom;
        // Image point under the anchor: (anchor - pan) / zoom stays fixed.
        self.pan = anchor - (anchor - self.pan) * k;
        self.zoom = new_zoom;
        if self.zoom <= 1.0 {
            self.pan = egui::Vec2::ZERO;
        }
    }
}

impl PinholeApp {
    /// Selects pixel `(x, y)` of the image on show (clamped into it).
    pub fn select_pixel(&mut self, x: i64, y: i64) {
        let s = self.effective_settings();
        self.inspect.select(x, y, s.width, s.height);
    }

    /// Takes the worker's answer and asks for the replay of the selection
    /// when it is missing or out of date (one replay in flight at a time:
    /// while the camera moves, replays follow as fast as they finish).
    pub fn sync_inspector(&mut self) {
        let answer: Option<ReplayResult> = self.worker.shared.replay.lock().unwrap().take();
        if let Some(a) = answer {
            if let Some((id, generation, _, _)) = self.inspect.in_flight {
                if a.id == id {
                    self.inspect.in_flight = None;
                    self.inspect.replay = Some(Replayed { x: a.x, y: a.y, renderer: a.renderer, generation, result: a.result, reference: a.reference, ms: a.ms });
                }
            }
        }
        let Some((x, y)) = self.inspect.selected else { return };
        let settings = self.effective_settings();
        if x >= settings.width || y >= settings.height {
            self.select_pixel(x as i64, y as i64);
        }
        let Some((x, y)) = self.inspect.selected else { return };
        if self.inspect.in_flight.is_some() || !self.inspect.waiting(self.generation) || self.params.camera.validate().is_err() {
            return;
        }
        self.inspect.next_id += 1;
        let id = self.inspect.next_id;
        self.inspect.in_flight = Some((id, self.generation, x, y));
        self.worker.replay(ReplayRequest {
            id,
            scene_id: self.scene_id,
            params: self.params.clone(),
            settings,
            renderer: self.settings.renderer.clone(),
            x,
            y,
        });
    }

    /// Blocks until the selection's replay for the current values arrived
    /// (tests and `--screenshot` only). False on timeout.
    pub fn wait_inspector(&mut self, timeout: Duration) -> bool {
        let deadline = std::time::Instant::now() + timeout;
        loop {
            self.sync_worker();
            self.sync_inspector();
            if !self.inspect.waiting(self.generation) {
                return true;
            }
            let now = std::time::Instant::now();
            if now >= deadline {
                return false;
            }
            let id = self.inspect.in_flight.map_or(0, |f| f.0);
            self.worker.wait_replay(id, (deadline - now).min(Duration::from_millis(100)));
        }
    }
}

/// Name of the object a primitive belongs to.
pub fn object_name(scene: &Scene, kind: PrimitiveKind, index: u32) -> String {
    let object = match kind {
        PrimitiveKind::Triangle => ((index as u64) < scene.total_triangles()).then(|| scene.triangle(index).object),
        PrimitiveKind::Sphere => scene.spheres.get(index as usize).map(|s| s.object),
        PrimitiveKind::Csg => scene.csgs.get(index as usize).map(|c| c.object),
    };
    let copy = match kind {
        PrimitiveKind::Triangle => {
            let instance = scene.instance_of_triangle(index).map(|i| format!(", instance {}", i.index));
            match scene.part_name(index) {
                Some(part) => Some(format!("{}, {part}", instance.unwrap_or_default())),
                None => instance,
            }
        }
        PrimitiveKind::Sphere | PrimitiveKind::Csg => None,
    };
    object
        .and_then(|o| scene.objects.get(o as usize).map(|info| format!("'{}' (object {o}{})", info.name, copy.unwrap_or_default())))
        .unwrap_or_else(|| "?".into())
}

pub fn kind_name(kind: PrimitiveKind) -> &'static str {
    match kind {
        PrimitiveKind::Triangle => "triangle",
        PrimitiveKind::Sphere => "sphere",
        PrimitiveKind::Csg => "csg",
    }
}

pub fn fmt3(v: Vec3) -> String {
    format!("({:.5}, {:.5}, {:.5})", v.x, v.y, v.z)
}

/// What pixel value `v` of the view named `view` means, in words and numbers.
pub fn value_text(view: &str, v: Radiance, camera: &CameraView, scene: &Scene) -> String {
    match view {
        "depth" => {
            if v.x <= 0.0 {
                "no hit (or at the near plane)".into()
            } else {
                format!("distance {:.4} (grey {:.4})", depth_distance(camera, v.x), v.x)
            }
        }
        "zbuffer" => {
            if v.x <= 0.0 {
                "no hit (or at the far plane)".into()
            } else {
                format!("z {:.4} (1/z stored as {:.4})", zbuffer_depth(camera, v.x), v.x)
            }
        }
        "cost" => {
            let c = invert_cost(v);
            if c >= COST_SCALE * 0.999 {
                format!("cost >= {COST_SCALE:.0}")
            } else {
                format!("cost {:.0}", c.round())
            }
        }
        "id" => match object_of_id_color(scene, v) {
            Some(i) => format!("object {i}: {}", scene.objects[i].name),
            None if v == Vec3::ZERO => "no hit".into(),
            None => format!("colour {}", fmt3(v)),
        },
        "barycentric" => format!("b = {}", fmt3(v)),
        "diff" => {
            if v.y == 0.0 && v.x >= 0.5 {
                "brighter than raytrace:brute".into()
            } else if v.y == 0.0 && v.z >= 0.5 {
                "darker than raytrace:brute".into()
            } else {
                "same as raytrace:brute".into()
            }
        }
        "raydir" | "normal" => format!("{} = {}", if view == "raydir" { "d" } else { "n" }, fmt3(v * 2.0 - Vec3::ONE)),
        _ => format!("linear {}", fmt3(v)),
    }
}
