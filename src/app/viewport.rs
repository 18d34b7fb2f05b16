//! The central viewport: the rendered image (1:1 in pixels when it fits,
//! zoomable to pixel level with nearest filtering and a pixel grid), light
//! markers, the selected pixel and its rays, vertex dots and the debug
//! view's legend drawn over it; mouse/keyboard navigation and pixel picking.

use eframe::egui;
use crate::scene::camera::control as cc;
use crate::app::inspect::Inspect;
use crate::app::overlay::{self, ImageMap};
use crate::app::split_view::SplitView;
use crate::app::viewed::Viewed;
use crate::math::{Vec2, Vec3};
use crate::scene::{Camera, Light, Scene};
use egui::{Color32, Pos2, Rect, Sense, Stroke};

/// What the viewport edits: the camera and lights (dragged), the
/// inspection (selection, zoom, hover), configuration B's divider and
/// region, and its own focus and drag.
pub struct Edited<'a> {
    pub camera: &'a mut Camera,
    pub lights: &'a mut [Light],
    pub inspect: &'a mut Inspect,
    pub split: &'a mut SplitView,
    pub state: &'a mut ViewportState,
}

/// The viewport's own state between frames.
#[derive(Clone, Debug, Default)]
pub struct ViewportState {
    /// Index of the light being dragged.
    pub dragging_light: Option<usize>,
    /// Clicked last: the keyboard flies the camera.
    pub focused: bool,
}

/// What the viewport asks of the viewer this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewportRequests {
    /// The camera was moved (orbit, pan, dolly, fly): render a quick preview.
    pub camera_moved: bool,
    /// Where the image was drawn, in points.
    pub image_rect: Option<Rect>,
}

pub fn show(ui: &mut egui::Ui, viewed: &Viewed, edited: Edited) -> ViewportRequests {
    let Edited { camera, lights, inspect, split, state } = edited;
    let mut requests = ViewportRequests::default();
    let avail = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(avail, Sense::click_and_drag());
    let ppp = ui.ctx().pixels_per_point();
    let settings = viewed.settings;
    let (iw, ih) = (settings.width as f32, settings.height as f32);

    // Zoom: ctrl+wheel (or pinch) about the cursor; right drag pans the image.
    if response.hovered() {
        let zoom = ui.input(|i| i.zoom_delta());
        if zoom != 1.0 {
            let anchor = response.hover_pos().map_or(egui::Vec2::ZERO, |p| p - avail.center());
            inspect.zoom_about(inspect.zoom * zoom, anchor);
        }
    }
    if response.dragged_by(egui::PointerButton::Secondary) && inspect.zoom > 1.0 {
        inspect.pan += response.drag_delta();
    }

    // 1 image pixel = 1 screen pixel when it fits; otherwise scaled to fit;
    // then magnified by the zoom.
    let mut size = egui::vec2(iw / ppp, ih / ppp);
    let fit = (avail.width() / size.x).min(avail.height() / size.y);
    if fit < 1.0 {
        size *= fit;
    }
    size *= inspect.zoom;
    if std::mem::take(&mut inspect.center_on_selection) {
        if let Some((x, y)) = inspect.selected {
            let (cx, cy) = (x as f32 + 0.5 - iw * 0.5, y as f32 + 0.5 - ih * 0.5);
            inspect.pan = -egui::vec2(cx / iw * size.x, cy / ih * size.y);
        }
    }
    let min = avail.center() + inspect.pan - size * 0.5;
    let min = Pos2::new((min.x * ppp).round() / ppp, (min.y * ppp).round() / ppp);
    let rect = Rect::from_min_size(min, size);
    requests.image_rect = Some(rect);
    let painter = ui.painter_at(avail);
    if let Some(t) = viewed.texture {
        // The texture samples with nearest filtering: zoomed pixels stay square.
        painter.image(t.id(), rect, Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)), Color32::WHITE);
    }
    let map = ImageMap { rect, width: iw, height: ih };
    let split_drag = split_view(split, ui, &response, &painter, &map);
    overlay::pixel_grid(&painter, &map, avail);

    // Image pixel of a screen point and back.
    let to_px = |p: Pos2| map.to_px(p);
    let to_screen = |v: Vec2| map.to_screen(v);
    let px_per_point = iw / rect.width().max(1.0);

    let view = camera.view(settings.width, settings.height);
    let markers: Vec<(usize, Option<Pos2>)> = lights
        .iter()
        .enumerate()
        .map(|(i, l)| match l {
            Light::Point { position, .. } => (i, view.project(*position).map(|(p, _)| to_screen(p))),
            Light::Directional { .. } => (i, None),
        })
        .collect();

    // Clicking a pixel selects it for the inspector.
    if response.clicked() {
        if let Some((x, y)) = response.interact_pointer_pos().and_then(|p| map.pixel_at(p)) {
            inspect.select(x as i64, y as i64, settings.width, settings.height);
        }
    }
    inspect.hover = response.hover_pos().and_then(|p| map.pixel_at(p));

    // Focus: clicking the viewport gives it the keyboard (WASD/QE fly).
    if response.clicked() || response.drag_started() {
        state.focused = true;
        ui.ctx().memory_mut(|m| m.surrender_focus(m.focused().unwrap_or(egui::Id::NULL)));
    } else if ui.input(|i| i.pointer.any_pressed()) && !response.hovered() {
        state.focused = false;
    }

    // Dragging a point-light marker moves the light in the view plane.
    if response.drag_started_by(egui::PointerButton::Primary) && !split_drag {
        if let Some(p) = ui.input(|i| i.pointer.press_origin()) {
            state.dragging_light = markers
                .iter()
                .filter_map(|(i, m)| m.map(|m| (*i, m.distance(p))))
                .filter(|(_, d)| *d < 10.0)
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(i, _)| i);
        }
    }
    if response.drag_stopped() {
        state.dragging_light = None;
    }
    let delta = response.drag_delta() * px_per_point;
    let shift = ui.input(|i| i.modifiers.shift);
    if let Some(i) = state.dragging_light {
        if let (Some(p), Some(Light::Point { position, .. })) = (response.interact_pointer_pos(), lights.get_mut(i)) {
            let depth = view.view_depth(*position);
            if depth > view.near {
                let q = to_px(p);
                *position = view.point_at_depth(q.x, q.y, depth);
            }
        }
    } else if delta != egui::Vec2::ZERO && !split_drag {
        let cam = &mut *camera;
        if response.dragged_by(egui::PointerButton::Middle) || (response.dragged_by(egui::PointerButton::Primary) && shift) {
            cc::pan(cam, delta.x, delta.y, settings.width, settings.height);
            requests.camera_moved = true;
        } else if response.dragged_by(egui::PointerButton::Primary) {
            cc::orbit(cam, delta.x, delta.y);
            requests.camera_moved = true;
        }
    }
    if response.hovered() && ui.input(|i| i.zoom_delta()) == 1.0 {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            cc::dolly(camera, scroll / 50.0);
            requests.camera_moved = true;
        }
    }
    if state.focused && !ui.ctx().egui_wants_keyboard_input() {
        requests.camera_moved |= fly_keys(camera, viewed.scene, ui);
    }

    if inspect.vertices {
        let verts = match &inspect.vertex_cache {
            Some((id, v)) if *id == viewed.scene_id => v.clone(),
            _ => {
                let v = std::sync::Arc::new(overlay::unique_vertices(viewed.scene));
                inspect.vertex_cache = Some((viewed.scene_id, v.clone()));
                v
            }
        };
        let drawn = overlay::vertices(&painter, &map, &view, &verts, avail);
        let total = verts.len();
        let note = if total > overlay::MAX_VERTEX_DOTS {
            format!("{drawn} vertices drawn (1 in {} of {total})", total.div_ceil(overlay::MAX_VERTEX_DOTS))
        } else {
            format!("{drawn} of {total} vertices in view")
        };
        painter.text(avail.left_top() + egui::vec2(6.0, 6.0), egui::Align2::LEFT_TOP, note, egui::FontId::monospace(11.0), Color32::from_rgb(255, 80, 200));
    }
    // The selected pixel's rays, then the pixel itself.
    if let Some((x, y)) = inspect.selected {
        if inspect.paths {
            if let Some(Ok(replay)) = inspect.current(viewed.generation).map(|r| &r.result) {
                if let Some((_, trace, _)) = replay.samples.first() {
                    let length = cc::scene_scale(viewed.scene.bounds());
                    overlay::paths(&painter, &map, &view, trace, lights, length);
                }
            }
        }
        overlay::selected_pixel(&painter, &map, x, y);
    }

    // Light markers.
    for (i, m) in &markers {
        if let Some(p) = m {
            let hot = state.dragging_light == Some(*i);
            painter.circle(*p, if hot { 7.0 } else { 5.0 }, Color32::from_rgb(255, 220, 80), Stroke::new(1.5, Color32::BLACK));
            painter.text(*p + egui::vec2(8.0, -8.0), egui::Align2::LEFT_BOTTOM, format!("L{i}"), egui::FontId::monospace(12.0), Color32::YELLOW);
        }
    }
    // Area lights: their outlines, labelled A0, A1, ... as the inspector lists them.
    let outline_colour = Color32::from_rgb(255, 220, 80);
    for (i, area) in viewed.scene.emitters.lights.iter().enumerate() {
        for [a, b] in &area.outline {
            if let Some(p) = overlay::project_segment(&view, &map, *a, *b) {
                painter.line_segment(p, Stroke::new(3.0, Color32::from_black_alpha(140)));
                painter.line_segment(p, Stroke::new(1.5, outline_colour));
            }
        }
        if area.outline.is_empty() && area.radius > 0.0 {
            // A sphere: the circle of its radius facing the camera.
            let c = view.to_camera(area.centre);
            if c.z < -view.near {
                let ring: Vec<Pos2> = (0..=32)
                    .map(|k| {
                        let a = k as f32 / 32.0 * std::f32::consts::TAU;
                        to_screen(view.project_camera(c + Vec3::new(a.cos(), a.sin(), 0.0) * area.radius))
                    })
                    .collect();
                painter.add(egui::Shape::line(ring, Stroke::new(1.5, outline_colour)));
            }
        }
        if let Some((p, _)) = view.project(area.centre) {
            painter.text(to_screen(p) + egui::vec2(6.0, -6.0), egui::Align2::LEFT_BOTTOM, format!("A{i}"), egui::FontId::monospace(12.0), Color32::YELLOW);
        }
    }
    // Directional lights: an arrow in the corner along the projected direction.
    let mut corner = rect.left_top() + egui::vec2(28.0, 28.0);
    for (i, l) in lights.iter().enumerate() {
        if let Light::Directional { direction, .. } = l {
            let d = view.world_to_camera * direction.normalize_or(Vec3::NEG_Y);
            let v = egui::vec2(d.x, -d.y);
            let v = if v.length() > 1e-3 { v.normalized() * 18.0 } else { egui::Vec2::ZERO };
            painter.circle_stroke(corner, 20.0, Stroke::new(1.0, Color32::from_gray(160)));
            painter.arrow(corner - v, v * 2.0, Stroke::new(2.0, Color32::from_rgb(255, 220, 80)));
            painter.text(corner + egui::vec2(22.0, -18.0), egui::Align2::LEFT_TOP, format!("L{i}"), egui::FontId::monospace(12.0), Color32::YELLOW);
            corner.y += 48.0;
        }
    }
    if state.focused {
        painter.rect_stroke(avail.shrink(1.0), 0.0, Stroke::new(1.0, Color32::from_rgb(80, 120, 200)), egui::StrokeKind::Inside);
    }
    hover_readout(viewed, inspect.hover, &painter, avail, &view);
    crate::app::legend::show(viewed, inspect.hover, camera, ui.ctx(), avail);
    requests
}

/// Configuration B over the image (right of the divider, or as the
/// difference), the divider, B's label and the measured rectangle. Dragging
/// the divider moves it; alt+drag measures a rectangle. Returns whether a
/// drag of the primary button was taken here (so it does not orbit).
fn split_view(split: &mut SplitView, ui: &egui::Ui, response: &egui::Response, painter: &egui::Painter, map: &ImageMap) -> bool {
    use crate::app::split_view::SplitMode;
    if !split.enabled {
        return false;
    }
    let rect = map.rect;
    let divider_x = rect.min.x + split.divider * rect.width();
    if response.drag_started_by(egui::PointerButton::Primary) {
        if let Some(p) = ui.input(|i| i.pointer.press_origin()) {
            if ui.input(|i| i.modifiers.alt) {
                split.region_start = map.pixel_at(p);
            } else if split.mode == SplitMode::Wipe && (p.x - divider_x).abs() <= 8.0 {
                split.dragging_divider = true;
            }
        }
    }
    let pointer = response.interact_pointer_pos();
    let mut taken = split.dragging_divider || split.region_start.is_some();
    if let (true, Some(p)) = (split.dragging_divider, pointer) {
        split.divider = ((p.x - rect.min.x) / rect.width().max(1.0)).clamp(0.0, 1.0);
    }
    if let (Some((x0, y0)), Some(p)) = (split.region_start, pointer) {
        let v = map.to_px(p);
        let x1 = (v.x.max(0.0) as u32).min(map.width as u32 - 1);
        let y1 = (v.y.max(0.0) as u32).min(map.height as u32 - 1);
        split.region = Some([x0.min(x1), y0.min(y1), x0.max(x1) + 1, y0.max(y1) + 1]);
    }
    if response.drag_stopped() {
        taken |= split.dragging_divider || split.region_start.is_some();
        split.dragging_divider = false;
        split.region_start = None;
    }
    let uv = |a: f32, b: f32| Rect::from_min_max(Pos2::new(a, 0.0), Pos2::new(b, 1.0));
    match split.mode {
        SplitMode::Wipe => {
            if let Some(t) = &split.texture {
                let right = Rect::from_min_max(Pos2::new(divider_x, rect.min.y), rect.max);
                painter.image(t.id(), right, uv(split.divider, 1.0), Color32::WHITE);
            }
            painter.line_segment([Pos2::new(divider_x, rect.min.y), Pos2::new(divider_x, rect.max.y)], Stroke::new(2.0, Color32::WHITE));
            painter.circle(Pos2::new(divider_x, rect.center().y), 6.0, Color32::WHITE, Stroke::new(1.0, Color32::BLACK));
            let tag = |pos: Pos2, align, text: &str| {
                painter.text(pos, align, text, egui::FontId::proportional(14.0), Color32::WHITE);
            };
            tag(Pos2::new(divider_x - 8.0, rect.min.y + 6.0), egui::Align2::RIGHT_TOP, "A");
            tag(Pos2::new(divider_x + 8.0, rect.min.y + 6.0), egui::Align2::LEFT_TOP, "B");
        }
        SplitMode::Difference => {
            if let Some(t) = &split.diff_texture {
                painter.image(t.id(), rect, uv(0.0, 1.0), Color32::WHITE);
            }
        }
    }
    if let Some([x0, y0, x1, y1]) = split.region {
        let r = Rect::from_min_max(map.to_screen(Vec2::new(x0 as f32, y0 as f32)), map.to_screen(Vec2::new(x1 as f32, y1 as f32)));
        painter.rect_stroke(r, 0.0, Stroke::new(1.5, Color32::from_rgb(120, 255, 120)), egui::StrokeKind::Outside);
    }
    taken
}

/// The pixel under the cursor: coordinates, the value on show and what it
/// means in this view, in the viewport's bottom-left corner.
fn hover_readout(viewed: &Viewed, hover: Option<(u32, u32)>, painter: &egui::Painter, avail: Rect, view: &crate::scene::CameraView) {
    let Some((x, y)) = hover else { return };
    let exposure = viewed.exposure;
    let Some(v) = viewed.with_output(|o| (x < o.width && y < o.height && o.linear.len() == (o.width * o.height) as usize).then(|| o.linear[(x + y * o.width) as usize])) else { return };
    let meaning = crate::app::inspect::value_text(viewed.settings.view.name(), v, view, viewed.scene);
    let t = viewed.display;
    let d = crate::display::display_rgb8(v, t.scale(exposure), t.tonemap, t.gamma);
    let text = if meaning.starts_with("linear") {
        format!("({x}, {y})  {meaning}  -> {d:?}")
    } else {
        format!("({x}, {y})  {meaning}  linear {}", crate::app::inspect::fmt3(v))
    };
    let galley = painter.layout_no_wrap(text, egui::FontId::monospace(12.0), Color32::WHITE);
    let pos = avail.left_bottom() + egui::vec2(6.0, -6.0 - galley.size().y);
    painter.rect_filled(Rect::from_min_size(pos, galley.size()).expand(3.0), 3.0, Color32::from_black_alpha(190));
    painter.galley(pos, galley, Color32::WHITE);
}

/// WASD/QE fly at a speed proportional to the scene's size; true when the
/// camera moved.
fn fly_keys(camera: &mut Camera, scene: &Scene, ui: &egui::Ui) -> bool {
    use egui::Key;
    let (dir, dt, fast) = ui.input(|i| {
        let k = |key: Key| if i.key_down(key) { 1.0 } else { 0.0 };
        let dir = Vec3::new(k(Key::D) - k(Key::A), k(Key::E) - k(Key::Q), k(Key::W) - k(Key::S));
        (dir, i.stable_dt.min(0.1), i.modifiers.shift)
    });
    if dir == Vec3::ZERO {
        return false;
    }
    let speed = cc::scene_scale(scene.bounds()) * if fast { 1.0 } else { 0.3 };
    cc::fly(camera, dir, speed * dt.max(1.0 / 60.0));
    ui.ctx().request_repaint();
    true
}
