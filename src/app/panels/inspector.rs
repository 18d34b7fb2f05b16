//! The pixel inspector: the record of the selected pixel, replayed
//! by the renderer's own code path (`render::replay_pixel`). Ray tracers:
//! the eye ray, its traversal (nodes visited, every primitive tested in
//! order with t, barycentrics or why it was rejected), the closest hit, each
//! light's sample with its shadow ray, secondary rays as a tree. Rasterizers:
//! the fragment history in draw order, and for a CSG object its A-buffer.
//! Then the final radiance, checked against the frame's pixel, and the
//! displayed 8-bit value.

use eframe::egui;
use crate::app::inspect::{fmt3, kind_name, object_name, Inspect};
use crate::math::Radiance;
use crate::render::inspect::pixel_report::miss_reason;
use crate::render::inspect::pixel_record::{CsgABufferRecord, FragmentRecord, GlReadback, LightSample, PixelTrace, RayRecord};
use crate::render::PixelReplay;
use crate::scene::{Light, Material, Scene};
use egui::{Color32, RichText};

const DIM: Color32 = Color32::from_gray(150);

/// What the inspector reads beside its own state: the request the frame
/// belongs to, the scene with the values being edited, and how the pixel
/// is displayed.
pub struct Viewed<'a> {
    /// The last render request sent: a replay for it is current.
    pub generation: u64,
    pub scene: &'a Scene,
    pub lights: &'a [Light],
    pub materials: &'a [Material],
    pub renderer: &'a str,
    /// The scene's exposure (a linear factor) and the display transform.
    pub exposure: f32,
    pub display: crate::display::DisplaySettings,
    /// The frame's own value at the selected pixel, once the frame of
    /// `generation` is complete.
    pub frame_pixel: Option<Radiance>,
}

/// The inspector as a right-hand panel, while a pixel is selected. It edits
/// only `inspect` (selection, zoom, drawn rays), so it asks nothing more of
/// the viewer.
pub fn show(ui: &mut egui::Ui, inspect: &mut Inspect, viewed: &Viewed) {
    let Some((x, y)) = inspect.selected else { return };
    egui::Panel::right("inspector").default_size(420.0).size_range(300.0..=640.0).resizable(true).show(ui, |ui| {
        // Fill the panel's width (the panel takes the size of its content,
        // which would otherwise be the narrow "replaying…" of the first frame).
        ui.set_min_width(ui.available_width());
        ui.horizontal(|ui| {
            ui.heading("Inspector");
            if ui.button("clear (Esc)").clicked() {
                inspect.clear();
            }
            if ui.button("zoom to pixel").on_hover_text("magnify 16x around the selected pixel").clicked() {
                inspect.zoom = inspect.zoom.max(16.0);
                inspect.center_on_selection = true;
            }
        });
        ui.horizontal(|ui| {
            ui.checkbox(&mut inspect.paths, "draw rays");
            ui.label(RichText::new("arrows move · shift+arrows by 10").small().color(DIM));
        });
        ui.label(RichText::new(format!("pixel ({x}, {y})")).strong());
        let current = inspect.current(viewed.generation).is_some();
        let Some(replay) = inspect.replay.as_ref().filter(|r| r.x == x && r.y == y) else {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label("replaying…");
            });
            return;
        };
        ui.label(RichText::new(format!("{} · replayed in {:.1} ms{}", replay.renderer, replay.ms, if current { "" } else { " · updating…" })).small().color(DIM));
        ui.separator();
        let names = SceneNames { scene: viewed.scene, lights: viewed.lights, materials: viewed.materials.iter().map(|m| m.name.clone()).collect() };
        match &replay.result {
            Err(e) => {
                ui.colored_label(Color32::LIGHT_RED, format!("cannot replay this pixel: {e}"));
            }
            Ok(r) => {
                let reference = replay.reference.as_ref();
                egui::ScrollArea::both().auto_shrink([false, false]).show(ui, |ui| {
                    record(viewed, reference, ui, &names, r, current);
                });
            }
        }
    });
}

/// The scene with the values being edited (lights, materials) for names.
struct SceneNames<'a> {
    scene: &'a Scene,
    lights: &'a [Light],
    materials: Vec<String>,
}

/// The replayed samples, then the final value; in the diff view, both
/// renderers' values (`reference`: the reference renderer's replay).
fn record(viewed: &Viewed, reference: Option<&Result<PixelReplay, String>>, ui: &mut egui::Ui, names: &SceneNames, r: &PixelReplay, current: bool) {
    let many = r.samples.len() > 1;
    for (i, (offset, trace, value)) in r.samples.iter().enumerate() {
        if many {
            egui::CollapsingHeader::new(format!("sample {} at ({:.3}, {:.3}) -> {}", i + 1, offset.x, offset.y, fmt3(*value)))
                .id_salt(("sample", i))
                .default_open(i == 0)
                .show(ui, |ui| sample(ui, names, trace, *value));
        } else {
            sample(ui, names, trace, *value);
        }
    }
    ui.separator();
    if let Some(reference) = reference {
        // Diff view: both renderers' shaded values; the frame shows their difference.
        ui.label(RichText::new(format!("{} (shaded) {}", viewed.renderer, fmt3(r.radiance))).monospace());
        match reference {
            Ok(b) => {
                ui.label(RichText::new(format!("raytrace:brute (shaded) {}", fmt3(b.radiance))).monospace());
                if crate::render::inspect::debug::differs(r.radiance, b.radiance) {
                    ui.colored_label(Color32::from_rgb(240, 110, 100), "this pixel differs from the reference");
                } else {
                    ui.colored_label(Color32::LIGHT_GREEN, "this pixel agrees with the reference");
                }
            }
            Err(e) => {
                ui.colored_label(Color32::LIGHT_RED, format!("raytrace:brute cannot replay: {e}"));
            }
        }
        return;
    }
    final_value(viewed, ui, r.radiance, current);
}

/// The `opengl` renderer's record: what its render targets hold at the pixel.
fn gl_readback(ui: &mut egui::Ui, names: &SceneNames, r: &GlReadback) {
    ui.label(RichText::new("GL readback, not a replay").strong());
    ui.label(
        RichText::new("GL's shaders cannot be stepped through: the pixel's row was drawn again and its render targets read back.")
            .small()
            .color(DIM),
    );
    egui::Grid::new("gl-readback").num_columns(2).spacing([8.0, 2.0]).show(ui, |ui| match &r.surface {
        Some(h) => {
            grid_row(ui, "primitive", format!("{} {}", kind_name(h.kind), h.primitive));
            grid_row(ui, "object", object_name(names.scene, h.kind, h.primitive));
            grid_row(ui, "material", names.materials.get(h.material as usize).cloned().unwrap_or_default());
            grid_row(ui, "position", fmt3(h.position));
            grid_row(ui, "shading normal", fmt3(h.shading_normal));
            grid_row(ui, "geometric normal", fmt3(h.geometric_normal));
            grid_row(ui, "barycentric", fmt3(h.barycentric));
            grid_row(ui, "uv", format!("({:.5}, {:.5})", h.uv.x, h.uv.y));
            grid_row(ui, "back face", h.back_face.to_string());
            grid_row(ui, "output", fmt3(r.output));
        }
        None => {
            grid_row(ui, "fragment", "none drawn (background)".into());
            grid_row(ui, "output", fmt3(r.output));
        }
    });
}

fn sample(ui: &mut egui::Ui, names: &SceneNames, t: &PixelTrace, value: Radiance) {
    if let Some(r) = &t.gl_readback {
        gl_readback(ui, names, r);
    }
    // Rays other than shadow rays, as a tree by depth; shadow rays go with their light.
    let mut shadow_rays: Vec<&RayRecord> = t.rays.iter().filter(|r| r.shadow).collect();
    // A rasterizer: visibility came from the fragments; its eye ray only carries w_o to shading.
    let raster = !t.fragments.is_empty();
    if raster {
        fragments(ui, names.scene, &t.fragments);
    }
    for (i, r) in t.rays.iter().enumerate().filter(|(_, r)| !r.shadow) {
        let title = match r.depth {
            0 if raster => "eye ray (for shading; the fragments decided visibility)".to_string(),
            0 => "eye ray".to_string(),
            d => format!("secondary ray (depth {d})"),
        };
        ui.horizontal(|ui| {
            ui.add_space(12.0 * r.depth as f32);
            ui.vertical(|ui| {
                egui::CollapsingHeader::new(RichText::new(title).strong()).id_salt(("ray", i)).default_open(true).show(ui, |ui| {
                    // A rasterizer's eye ray on a CSG object: the A-buffer that resolved it.
                    let abuffer = if r.depth == 0 && !r.shadow { r.closest.as_ref().and_then(|h| t.csg_abuffer_for(h)) } else { None };
                    ray(ui, names, r, i, abuffer);
                });
            });
        });
    }
    if !t.lights.is_empty() {
        ui.label(RichText::new("lights").strong());
        for (k, l) in t.lights.iter().enumerate() {
            // The shadow ray record that traced this light's shadow ray.
            let traced = l.shadow_ray.and_then(|(sr, _)| shadow_rays.iter().position(|r| r.ray == sr)).map(|p| shadow_rays.remove(p));
            light(ui, names, l, traced, k);
        }
    }
    if !t.bounces.is_empty() {
        ui.label(RichText::new("path: sampled bounces").strong());
        egui::Grid::new("bounces").striped(true).num_columns(5).spacing([10.0, 2.0]).show(ui, |ui| {
            for h in ["depth", "direction", "pdf", "f cos / pdf", "throughput, roulette"] {
                ui.label(RichText::new(h).color(DIM));
            }
            ui.end_row();
            for b in &t.bounces {
                ui.monospace(b.depth.to_string());
                ui.monospace(fmt3(b.w_i));
                ui.monospace(format!("{:.4}", b.pdf));
                ui.monospace(fmt3(b.weight));
                let roulette = match b.survival {
                    p if p >= 1.0 => String::new(),
                    p if p > 0.0 => format!(" (survived, p = {p:.2})"),
                    _ => " (ended by roulette)".into(),
                };
                ui.monospace(format!("{}{roulette}", fmt3(b.throughput)));
                ui.end_row();
            }
        });
    }
    for l in &t.photon_estimates {
        ui.monospace(format!("photon map estimate {}", fmt3(*l)));
    }
    if t.shaded.len() > 1 {
        ui.label(RichText::new("radiance returned per depth (innermost first)").small().color(DIM));
        for (d, rad) in &t.shaded {
            ui.monospace(format!("  depth {d}: {}", fmt3(*rad)));
        }
    }
    ui.monospace(format!("sample radiance {}", fmt3(value)));
}

fn grid_row(ui: &mut egui::Ui, name: &str, value: String) {
    ui.label(RichText::new(name).color(DIM));
    ui.monospace(value);
    ui.end_row();
}

fn ray(ui: &mut egui::Ui, names: &SceneNames, r: &RayRecord, index: usize, abuffer: Option<&CsgABufferRecord>) {
    let scene = names.scene;
    egui::Grid::new(("ray-grid", index)).num_columns(2).spacing([8.0, 2.0]).show(ui, |ui| {
        grid_row(ui, "origin", fmt3(r.ray.origin));
        grid_row(ui, "direction", fmt3(r.ray.dir));
        grid_row(ui, "t_max", format!("{:.5}", r.t_max));
        if !r.nodes_visited.is_empty() {
            grid_row(ui, "BVH nodes visited", r.nodes_visited.len().to_string());
        }
        let tested = r.tests.len() + r.tests_omitted;
        let traced = tested > 0 || !r.nodes_visited.is_empty();
        if traced {
            grid_row(ui, "primitives tested", tested.to_string());
        }
        if r.depth == 0 && traced {
            grid_row(ui, "cost (nodes + tests)", (r.nodes_visited.len() + tested).to_string());
        }
    });
    traversal(ui, scene, r, index);
    match &r.closest {
        Some(h) => {
            ui.label(RichText::new("closest hit").strong());
            egui::Grid::new(("hit-grid", index)).num_columns(2).spacing([8.0, 2.0]).show(ui, |ui| {
                grid_row(ui, "object", object_name(scene, h.kind, h.primitive));
                grid_row(ui, kind_name(h.kind), h.primitive.to_string());
                let mat = names.materials.get(h.material as usize).cloned().unwrap_or_else(|| "?".into());
                grid_row(ui, "material", format!("{mat} ({})", h.material));
                grid_row(ui, "t", format!("{:.6}", h.t));
                grid_row(ui, "P", fmt3(h.position));
                grid_row(ui, "barycentric", fmt3(h.barycentric));
                grid_row(ui, "uv", format!("({:.5}, {:.5})", h.uv.x, h.uv.y));
                grid_row(ui, "geometric normal", fmt3(h.geometric_normal));
                grid_row(ui, "shading normal", fmt3(h.shading_normal));
                grid_row(ui, "w_o", fmt3(-r.ray.dir));
                if h.back_face {
                    grid_row(ui, "side", "back face (two-sided)".into());
                }
            });
            if let Some(a) = abuffer {
                csg_abuffer(ui, a, index);
            } else if let Some(e) = crate::render::accel::csg::explain_hit(scene, h, &r.ray, r.t_max) {
                ui.label(RichText::new("csg intervals (t along the ray)").strong());
                for line in e.lines() {
                    ui.monospace(line);
                }
            }
        }
        None => {
            ui.label("closest hit: nothing (background)");
        }
    }
}

/// Every primitive test in order, collapsible (brute force tests thousands).
fn traversal(ui: &mut egui::Ui, scene: &Scene, r: &RayRecord, index: usize) {
    if r.tests.is_empty() {
        return;
    }
    let hits = r.tests.iter().filter(|t| t.outcome.is_ok()).count();
    let mut reasons: std::collections::BTreeMap<&str, usize> = Default::default();
    for t in &r.tests {
        if let Err(m) = t.outcome {
            *reasons.entry(miss_reason(m)).or_default() += 1;
        }
    }
    let summary = format!(
        "tests in order: {hits} hit{}{}{}",
        if hits == 1 { "" } else { "s" },
        reasons.iter().map(|(k, v)| format!(", {v} {k}")).collect::<String>(),
        if r.tests_omitted > 0 { format!(", {} more not kept", r.tests_omitted) } else { String::new() }
    );
    egui::CollapsingHeader::new(summary).id_salt(("tests", index)).default_open(false).show(ui, |ui| {
        let row_h = ui.text_style_height(&egui::TextStyle::Monospace);
        egui::ScrollArea::vertical().id_salt(("tests-scroll", index)).max_height(240.0).show_rows(ui, row_h, r.tests.len(), |ui, rows| {
            for i in rows {
                let t = &r.tests[i];
                let what = match t.outcome {
                    Ok((tt, b1, b2)) => format!("hit t = {tt:.6}, b = ({:.4}, {b1:.4}, {b2:.4})", 1.0 - b1 - b2),
                    Err(m) => miss_reason(m).to_string(),
                };
                let obj = object_name(scene, t.kind, t.index);
                let text = format!("#{i:<5} {} {} [{obj}]: {what}", kind_name(t.kind), t.index);
                if t.outcome.is_ok() {
                    ui.label(RichText::new(text).monospace().color(Color32::LIGHT_GREEN));
                } else {
                    ui.monospace(text);
                }
            }
        });
    });
}

fn light(ui: &mut egui::Ui, names: &SceneNames, l: &LightSample, traced: Option<&RayRecord>, k: usize) {
    let kind = match names.lights.get(l.light) {
        Some(Light::Point { .. }) => "point",
        Some(Light::Directional { .. }) => "directional",
        None => "?",
    };
    let visibility = match (l.shadow_ray, l.blocker) {
        _ if l.volume_count.is_some_and(|c| c != 0) => format!("in shadow: shadow volume count {}", l.volume_count.unwrap_or(0)),
        _ if l.volume_count.is_some() => "visible: shadow volume count 0".into(),
        (_, Some(b)) => format!("blocked by {} {} {} at t = {:.5}", kind_name(b.kind), b.index, object_name(names.scene, b.kind, b.index), b.t),
        (Some(_), None) => "visible".into(),
        (None, None) => "no shadow ray".into(),
    };
    let short = match l.blocker {
        Some(b) => format!("blocked at t = {:.5}", b.t),
        None => visibility.clone(),
    };
    let color = if l.blocker.is_some() || l.volume_count.is_some_and(|c| c != 0) { Color32::from_rgb(240, 110, 100) } else { Color32::from_rgb(110, 220, 120) };
    let title = RichText::new(format!("L{} ({kind}): {short}", l.light)).color(color);
    egui::CollapsingHeader::new(title).id_salt(("light", k)).default_open(true).show(ui, |ui| {
        egui::Grid::new(("light-grid", k)).num_columns(2).spacing([8.0, 2.0]).show(ui, |ui| {
            grid_row(ui, "w_i", fmt3(l.w_i));
            grid_row(ui, "distance", if l.distance.is_finite() { format!("{:.5}", l.distance) } else { "inf".into() });
            grid_row(ui, "incident radiance", fmt3(l.incident));
            grid_row(ui, "cos θ", format!("{:.5}", l.cos_theta));
            if let Some((r, t_max)) = l.shadow_ray {
                grid_row(ui, "shadow ray origin", fmt3(r.origin));
                grid_row(ui, "shadow ray direction", fmt3(r.dir));
                grid_row(ui, "shadow ray t_max", if t_max.is_finite() { format!("{t_max:.5}") } else { "inf".into() });
            }
            if let Some(s) = traced {
                let nodes = if s.nodes_visited.is_empty() { String::new() } else { format!("{} nodes, ", s.nodes_visited.len()) };
                grid_row(ui, "shadow traversal", format!("{nodes}{} tests", s.tests.len() + s.tests_omitted));
            }
            grid_row(ui, "visibility", visibility.clone());
            grid_row(ui, "BSDF", fmt3(l.bsdf));
            grid_row(ui, "contribution", fmt3(l.contribution));
        });
    });
}

/// A CSG object's A-buffer at the sample: its fragments sorted by depth (the
/// winner marked), then each operand's intervals, the combined ones and the winner.
fn csg_abuffer(ui: &mut egui::Ui, a: &CsgABufferRecord, index: usize) {
    ui.label(RichText::new(format!("csg A-buffer: {} scan-converted fragments sorted by depth", a.fragments.len())).strong());
    egui::Grid::new(("csg-abuffer", index)).striped(true).num_columns(4).spacing([10.0, 2.0]).show(ui, |ui| {
        for h in ["t", "operand", "surface", "boundary"] {
            ui.label(RichText::new(h).color(DIM));
        }
        ui.end_row();
        for f in &a.fragments {
            ui.monospace(format!("{:.5}", f.t));
            ui.monospace(a.operand(f));
            ui.monospace(match f.surface {
                crate::render::accel::csg::SurfaceRef::Sphere(_) => "sphere".to_string(),
                crate::render::accel::csg::SurfaceRef::Triangle { index, .. } => format!("triangle {index}"),
            });
            let b = RichText::new(if f.entering { "entry" } else { "exit" }).monospace();
            ui.label(if a.won(f) { b.color(Color32::LIGHT_GREEN).strong() } else { b });
            ui.end_row();
        }
    });
    ui.label(RichText::new("csg intervals (t along the ray)").strong());
    for line in a.explanation.lines() {
        ui.monospace(line);
    }
}

/// The rasterizer's pixel history (RenderDoc style): every fragment in draw
/// order as a table row, its weights and shaded value under it.
fn fragments(ui: &mut egui::Ui, scene: &Scene, frags: &[FragmentRecord]) {
    ui.label(RichText::new(format!("fragment history: {} fragment{} in draw order", frags.len(), if frags.len() == 1 { "" } else { "s" })).strong());
    let pass = |f: &FragmentRecord| {
        if f.passed_depth_test {
            RichText::new("passed").monospace().color(Color32::LIGHT_GREEN)
        } else {
            RichText::new("failed").monospace().color(Color32::from_rgb(240, 110, 100))
        }
    };
    egui::Grid::new("fragments").striped(true).num_columns(5).spacing([10.0, 2.0]).show(ui, |ui| {
        for h in ["#", "primitive", "depth", "stored depth", "depth test"] {
            ui.label(RichText::new(h).color(DIM));
        }
        ui.end_row();
        for (i, f) in frags.iter().enumerate() {
            ui.monospace(i.to_string());
            ui.monospace(format!("{} {}", kind_name(f.kind), f.primitive));
            ui.monospace(format!("{:.6}", f.depth));
            ui.monospace(if f.stored_depth.is_finite() { format!("{:.6}", f.stored_depth) } else { "inf (empty)".into() });
            ui.label(pass(f));
            ui.end_row();
        }
    });
    for (i, f) in frags.iter().enumerate() {
        let title = RichText::new(format!("fragment {i}: {} {} {}", kind_name(f.kind), f.primitive, object_name(scene, f.kind, f.primitive)));
        egui::CollapsingHeader::new(title).id_salt(("fragment", i)).default_open(frags.len() <= 4).show(ui, |ui| {
            egui::Grid::new(("fragment-grid", i)).num_columns(2).spacing([8.0, 2.0]).show(ui, |ui| {
                grid_row(ui, "2D (screen) weights", f.screen_barycentric.map(fmt3).unwrap_or_else(|| "-".into()));
                grid_row(ui, "perspective-correct", fmt3(f.barycentric));
                let stored = if f.stored_depth.is_finite() { format!("{:.6}", f.stored_depth) } else { "inf".into() };
                grid_row(ui, "depth vs stored", format!("{:.6} vs {stored}: {}", f.depth, if f.passed_depth_test { "passed" } else { "failed" }));
                grid_row(ui, "shaded radiance", f.shaded.map(fmt3).unwrap_or_else(|| "- (shaded after visibility)".into()));
            });
        });
    }
}

/// The label of the final radiance (tests look for exactly this text).
pub fn final_radiance_text(r: Radiance) -> String {
    format!("final radiance ({:.6}, {:.6}, {:.6})", r.x, r.y, r.z)
}

fn final_value(viewed: &Viewed, ui: &mut egui::Ui, radiance: Radiance, current: bool) {
    ui.label(RichText::new(final_radiance_text(radiance)).strong().monospace());
    // The frame's own pixel: the same number, once the frame is complete.
    let frame = viewed.frame_pixel;
    match frame {
        Some(f) if current && f == radiance => {
            ui.label(RichText::new("= the frame's pixel, exactly").color(Color32::LIGHT_GREEN));
        }
        Some(f) if current => {
            ui.colored_label(Color32::LIGHT_RED, format!("!= the frame's pixel {} (a replay bug: please report)", fmt3(f)));
        }
        _ => {
            ui.label(RichText::new("the frame is still rendering").color(DIM));
        }
    }
    let exposure = viewed.exposure;
    // The pixel through the display transform on show; the numbers above are linear.
    let t = viewed.display;
    let d = crate::display::display_rgb8(radiance, t.scale(exposure), t.tonemap, t.gamma);
    ui.horizontal(|ui| {
        let (r, _) = ui.allocate_exact_size(egui::vec2(18.0, 18.0), egui::Sense::hover());
        ui.painter().rect_filled(r, 2.0, Color32::from_rgb(d[0], d[1], d[2]));
        ui.monospace(format!(
            "displayed [{}, {}, {}] (exposure {exposure}, {:+} stops, {}, {})",
            d[0],
            d[1],
            d[2],
            t.exposure_ev,
            t.tonemap.name(),
            t.gamma.name()
        ));
    });
}
