//! Drawings over the image: the pixel grid when zoomed in, the selected
//! pixel, its rays projected into the view (eye-ray hit, shadow rays green
//! when visible and red up to the blocker, secondary rays), and every
//! projected triangle vertex as a dot (CGPP 15.6.2's test).

use crate::math::{Vec2, Vec3};
use crate::render::inspect::pixel_record::PixelTrace;
use crate::scene::{CameraView, Light, Scene};
use eframe::egui;
use egui::{Color32, Painter, Pos2, Rect, Stroke};

/// Where the image sits on screen: image pixels to points and back.
#[derive(Clone, Copy, Debug)]
pub struct ImageMap {
    pub rect: Rect,
    pub width: f32,
    pub height: f32,
}

impl ImageMap {
    pub fn to_screen(&self, v: Vec2) -> Pos2 {
        Pos2::new(self.rect.min.x + v.x / self.width * self.rect.width(), self.rect.min.y + v.y / self.height * self.rect.height())
    }

    pub fn to_px(&self, p: Pos2) -> Vec2 {
        Vec2::new((p.x - self.rect.min.x) / self.rect.width() * self.width, (p.y - self.rect.min.y) / self.rect.height() * self.height)
    }

    /// Points per image pixel.
    pub fn pixel_size(&self) -> f32 {
        self.rect.width() / self.width.max(1.0)
    }

    /// The pixel under a screen point, if inside the image.
    pub fn pixel_at(&self, p: Pos2) -> Option<(u32, u32)> {
        let v = self.to_px(p);
        (v.x >= 0.0 && v.y >= 0.0 && v.x < self.width && v.y < self.height).then(|| (v.x as u32, v.y as u32))
    }

    pub fn pixel_rect(&self, x: u32, y: u32) -> Rect {
        Rect::from_min_max(self.to_screen(Vec2::new(x as f32, y as f32)), self.to_screen(Vec2::new(x as f32 + 1.0, y as f32 + 1.0)))
    }
}

/// Pixel size in points above which the grid is drawn.
pub const GRID_MIN_POINTS: f32 = 8.0;

/// Lines between pixels, over the visible part of the image, once a pixel is
/// larger than `GRID_MIN_POINTS`.
pub fn pixel_grid(painter: &Painter, map: &ImageMap, clip: Rect) {
    let size = map.pixel_size();
    if size < GRID_MIN_POINTS {
        return;
    }
    let vis = map.rect.intersect(clip);
    if vis.is_negative() {
        return;
    }
    let lo = map.to_px(vis.min);
    let hi = map.to_px(vis.max);
    // Mid grey shows on dark and light pixels alike; it fades in as pixels grow.
    let alpha = (40.0 + (size - GRID_MIN_POINTS) * 10.0).clamp(40.0, 110.0) as u8;
    let stroke = Stroke::new(1.0, Color32::from_rgba_unmultiplied(128, 128, 128, alpha));
    for x in lo.x.floor().max(0.0) as u32..=hi.x.ceil().min(map.width) as u32 {
        let sx = map.to_screen(Vec2::new(x as f32, 0.0)).x;
        painter.line_segment([Pos2::new(sx, vis.min.y), Pos2::new(sx, vis.max.y)], stroke);
    }
    for y in lo.y.floor().max(0.0) as u32..=hi.y.ceil().min(map.height) as u32 {
        let sy = map.to_screen(Vec2::new(0.0, y as f32)).y;
        painter.line_segment([Pos2::new(vis.min.x, sy), Pos2::new(vis.max.x, sy)], stroke);
    }
}

/// A square around the selected pixel (at least 9 points wide so it shows
/// when a pixel is smaller than a point).
pub fn selected_pixel(painter: &Painter, map: &ImageMap, x: u32, y: u32) {
    let r = map.pixel_rect(x, y);
    let r = Rect::from_center_size(r.center(), r.size().max(egui::vec2(9.0, 9.0)));
    painter.rect_stroke(r.expand(1.0), 0.0, Stroke::new(1.0, Color32::BLACK), egui::StrokeKind::Outside);
    painter.rect_stroke(r, 0.0, Stroke::new(1.5, Color32::from_rgb(0, 230, 255)), egui::StrokeKind::Outside);
}

/// The segment a..b (world) projected to the screen, clipped to the near
/// plane; `None` when it lies behind it.
pub fn project_segment(view: &CameraView, map: &ImageMap, a: Vec3, b: Vec3) -> Option<[Pos2; 2]> {
    let (mut ca, mut cb) = (view.to_camera(a), view.to_camera(b));
    let near = -view.near * 1.0001;
    if ca.z > near && cb.z > near {
        return None;
    }
    if ca.z > near {
        ca = ca + (cb - ca) * ((near - ca.z) / (cb.z - ca.z));
    } else if cb.z > near {
        cb = ca + (cb - ca) * ((near - ca.z) / (cb.z - ca.z));
    }
    Some([map.to_screen(view.project_camera(ca)), map.to_screen(view.project_camera(cb))])
}

pub const VISIBLE: Color32 = Color32::from_rgb(60, 220, 90);
pub const BLOCKED: Color32 = Color32::from_rgb(240, 60, 50);
pub const SECONDARY: Color32 = Color32::from_rgb(120, 170, 255);

/// A segment with a dark outline so it reads on any image.
fn line(painter: &Painter, p: [Pos2; 2], color: Color32, width: f32) {
    painter.line_segment(p, Stroke::new(width + 2.0, Color32::from_black_alpha(160)));
    painter.line_segment(p, Stroke::new(width, color));
}

/// The rays of one replayed sample: the eye ray's hit point, a shadow ray
/// per light (green to the light when visible, red up to the blocker), and
/// secondary rays to their hits. `length` is how far rays that hit nothing
/// are drawn (directional lights, misses).
pub fn paths(painter: &Painter, map: &ImageMap, view: &CameraView, trace: &PixelTrace, lights: &[Light], length: f32) {
    let eye_hit = trace.rays.iter().find(|r| r.depth == 0 && !r.shadow).and_then(|r| r.closest.map(|h| h.position));
    // Secondary rays (mirror, refraction): origin to hit, or a stub on a miss.
    for r in trace.rays.iter().filter(|r| r.depth > 0 && !r.shadow) {
        let end = match &r.closest {
            Some(h) => h.position,
            None => r.ray.origin + r.ray.dir * r.t_max.min(length),
        };
        if let Some(p) = project_segment(view, map, r.ray.origin, end) {
            line(painter, p, SECONDARY, 1.5);
            painter.circle_filled(p[1], 2.5, SECONDARY);
        }
    }
    for l in &trace.lights {
        let (start, end, blocked) = match (l.shadow_ray, l.blocker) {
            (Some((ray, _)), Some(b)) => (ray.origin, ray.origin + ray.dir * b.t, true),
            (Some((ray, t_max)), None) => {
                let t = if t_max.is_finite() { t_max } else { length };
                (ray.origin, ray.origin + ray.dir * t, false)
            }
            (None, _) => {
                // No shadow ray (shadows off, or facing away): a thin line to the light.
                let Some(p) = eye_hit else { continue };
                let end = match lights.get(l.light) {
                    Some(Light::Point { position, .. }) => *position,
                    _ => p + l.w_i * length,
                };
                if let Some(s) = project_segment(view, map, p, end) {
                    painter.line_segment(s, Stroke::new(1.0, Color32::from_gray(200)));
                }
                continue;
            }
        };
        if let Some(p) = project_segment(view, map, start, end) {
            let color = if blocked { BLOCKED } else { VISIBLE };
            line(painter, p, color, 1.5);
            if blocked {
                painter.circle_filled(p[1], 3.5, BLOCKED);
            }
        }
    }
    if let Some(p) = eye_hit.and_then(|p| view.project(p)) {
        let s = map.to_screen(p.0);
        painter.circle(s, 4.0, Color32::WHITE, Stroke::new(1.5, Color32::BLACK));
    }
}

/// Most vertex dots drawn; bigger meshes are subsampled evenly.
pub const MAX_VERTEX_DOTS: usize = 20_000;

/// The scene's distinct triangle vertices (triangles store their corners, so
/// a mesh vertex appears once per triangle around it).
pub fn unique_vertices(scene: &Scene) -> Vec<Vec3> {
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    for t in &scene.triangles {
        for v in t.v {
            if seen.insert([v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]) {
                out.push(v);
            }
        }
    }
    out
}

/// Each vertex projected to the screen as a dot (every k-th one past
/// `MAX_VERTEX_DOTS`), as one mesh. Returns the dots drawn.
pub fn vertices(painter: &Painter, map: &ImageMap, view: &CameraView, vertices: &[Vec3], clip: Rect) -> usize {
    let stride = vertices.len().div_ceil(MAX_VERTEX_DOTS).max(1);
    let vis = map.rect.intersect(clip);
    let color = Color32::from_rgb(255, 80, 200);
    let r = (map.pixel_size() * 0.15).clamp(1.0, 4.0);
    let mut mesh = egui::Mesh::default();
    for v in vertices.iter().step_by(stride) {
        if let Some((p, _)) = view.project(*v) {
            let s = map.to_screen(p);
            if vis.contains(s) {
                mesh.add_colored_rect(Rect::from_center_size(s, egui::vec2(2.0 * r, 2.0 * r)), color);
            }
        }
    }
    let drawn = mesh.vertices.len() / 4;
    painter.add(egui::Shape::mesh(mesh));
    drawn
}
