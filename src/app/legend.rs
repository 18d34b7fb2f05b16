//! The debug view's legend, drawn over the viewport's top-right corner:
//! what the colours mean and the numbers they stand for (depth's near/far
//! log mapping, the z-buffer's 1/z, the cost heat scale, object id colours).
//! Views are told apart by name, so views added to the core later get a
//! plain legend (their name) without a change here.

use crate::render::inspect::debug::{cost_of_t, depth_distance, t_of_cost, zbuffer_depth};
use crate::app::viewed::Viewed;
use crate::scene::Camera;
use crate::math::Vec3;
use crate::render::inspect::debug::{cost_color, id_color, mip_color, COST_SCALE, MIP_SCALE};
use eframe::egui;
use egui::{Color32, Pos2, Rect};

/// Most objects listed in the id legend.
const MAX_IDS: usize = 16;

pub fn color(v: Vec3) -> Color32 {
    let c = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    Color32::from_rgb(c(v.x), c(v.y), c(v.z))
}

/// The legend's title for a view (tests look for it), `None` for shaded.
pub fn title(view: &str) -> Option<String> {
    Some(match view {
        "shaded" => return None,
        "depth" => "depth: distance along the eye ray".into(),
        "zbuffer" => "zbuffer: 1/z as a depth buffer stores it".into(),
        "cost" => "cost: work per pixel".into(),
        "id" => "id: objects".into(),
        "barycentric" => "barycentric: weights of v0, v1, v2".into(),
        "raydir" => "raydir: eye-ray direction".into(),
        "normal" => "normal: shading normal".into(),
        "uv" => "uv: texture coordinates".into(),
        "diff" => "diff: this renderer minus raytrace:brute".into(),
        "shadowmap" => "shadowmap: a light's depth map".into(),
        "mip" => "mip: texture level read per pixel".into(),
        "false-colour" => "false colour: luminance in stops".into(),
        "error" => "error: |a - b| / b against the reference".into(),
        "absolute-error" => "absolute error: |a - b| against the reference".into(),
        "signed-error" => "signed error: a - b against the reference".into(),
        "nan" => "nan: pixels that took a non-finite sample".into(),
        other => format!("view: {other}"),
    })
}

/// A horizontal colour bar of `colour(t)`, t in [0, 1], with tick labels
/// `(t, text)` under it.
fn bar(ui: &mut egui::Ui, colour: impl Fn(f32) -> Vec3, ticks: &[(f32, String)]) {
    let (rect, _) = ui.allocate_exact_size(egui::vec2(240.0, 30.0), egui::Sense::hover());
    let bar = Rect::from_min_size(rect.min, egui::vec2(rect.width(), 14.0));
    let p = ui.painter();
    const STEPS: usize = 96;
    for i in 0..STEPS {
        let t0 = i as f32 / STEPS as f32;
        let x0 = bar.min.x + t0 * bar.width();
        let x1 = bar.min.x + (i + 1) as f32 / STEPS as f32 * bar.width();
        p.rect_filled(Rect::from_min_max(Pos2::new(x0, bar.min.y), Pos2::new(x1 + 0.5, bar.max.y)), 0.0, color(colour(t0 + 0.5 / STEPS as f32)));
    }
    p.rect_stroke(bar, 0.0, egui::Stroke::new(1.0, Color32::from_gray(140)), egui::StrokeKind::Outside);
    let font = egui::FontId::proportional(10.0);
    for (i, (t, text)) in ticks.iter().enumerate() {
        let x = bar.min.x + t * bar.width();
        p.line_segment([Pos2::new(x, bar.max.y), Pos2::new(x, bar.max.y + 3.0)], egui::Stroke::new(1.0, Color32::from_gray(200)));
        let align = if i == 0 {
            egui::Align2::LEFT_TOP
        } else if i + 1 == ticks.len() {
            egui::Align2::RIGHT_TOP
        } else {
            egui::Align2::CENTER_TOP
        };
        p.text(Pos2::new(x, bar.max.y + 4.0), align, text, font.clone(), Color32::from_gray(230));
    }
}

/// An error view's tick label: percentages for relative errors below one,
/// else a short number with its sign.
fn error_tick(v: f32) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() < 1e-2 || v.abs() >= 1e3 {
        format!("{v:+.0e}")
    } else {
        format!("{v:+}")
    }
}

/// Short numbers for tick labels.
fn num(v: f32) -> String {
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else if v >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

/// Draws the legend of the current view in the corner of `viewport`
/// (nothing for shaded): `viewed` is the frame on show, `hover` the pixel
/// under the cursor, `camera` the camera as edited.
pub fn show(viewed: &Viewed, hover: Option<(u32, u32)>, camera: &Camera, ctx: &egui::Context, viewport: Rect) {
    let s = viewed.settings;
    let view = s.view.name();
    let Some(title) = title(view) else { return };
    let camera = camera.view(s.width, s.height);
    egui::Area::new(egui::Id::unique("view-legend"))
        .order(egui::Order::Foreground)
        .pivot(egui::Align2::RIGHT_TOP)
        .fixed_pos(viewport.right_top() + egui::vec2(-8.0, 8.0))
        .constrain(false)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).fill(Color32::from_black_alpha(200)).show(ui, |ui| {
                ui.set_max_width(250.0);
                ui.strong(title);
                let small = |ui: &mut egui::Ui, t: &str| {
                    ui.label(egui::RichText::new(t).small());
                };
                match view {
                    "depth" => {
                        small(ui, &format!("log scale from near = {} (black) to far = {} (white)", num(camera.near), num(camera.far)));
                        let ticks: Vec<(f32, String)> = [0.0, 0.25, 0.5, 0.75, 1.0].iter().map(|&t| (t, num(depth_distance(&camera, t)))).collect();
                        bar(ui, |t| Vec3::splat(t), &ticks);
                        small(ui, "no hit: black");
                    }
                    "zbuffer" => {
                        small(ui, &format!("(1/z - 1/far) / (1/near - 1/far): near = {} white, far = {} black; linear in screen space", num(camera.near), num(camera.far)));
                        // Left to right: near to far, as the stored value falls.
                        let ticks: Vec<(f32, String)> = [0.0, 0.25, 0.5, 0.75, 1.0].iter().map(|&t| (t, num(zbuffer_depth(&camera, 1.0 - t)))).collect();
                        bar(ui, |t| Vec3::splat(1.0 - t), &ticks);
                        small(ui, "ticks: view depth z; no hit: black");
                    }
                    "cost" => {
                        let what = if viewed.renderer.starts_with("raytrace") {
                            "BVH nodes visited + primitives tested by the eye ray"
                        } else {
                            "the renderer's work for the pixel's samples"
                        };
                        small(ui, &format!("{what}; log scale up to {COST_SCALE:.0} (white)"));
                        let mut ticks = vec![(0.0, "0".to_string())];
                        let mut c = 1.0;
                        while c < COST_SCALE {
                            ticks.push((t_of_cost(c), format!("{c:.0}")));
                            c *= 4.0;
                        }
                        ticks.push((1.0, format!("{COST_SCALE:.0}")));
                        bar(ui, |t| cost_color(cost_of_t(t)), &ticks);
                        if let Some((x, y)) = hover {
                            let v = viewed.with_output(|o| (x < o.width && y < o.height).then(|| o.linear[(x + y * o.width) as usize]));
                            if let Some(v) = v {
                                small(ui, &format!("under the cursor: {}", crate::app::inspect::value_text("cost", v, &camera, viewed.scene)));
                            }
                        }
                    }
                    "id" => {
                        let objects = &viewed.scene.objects;
                        egui::Grid::new("id-legend").num_columns(2).spacing([6.0, 2.0]).show(ui, |ui| {
                            for (i, o) in objects.iter().enumerate().take(MAX_IDS) {
                                let (r, _) = ui.allocate_exact_size(egui::vec2(14.0, 14.0), egui::Sense::hover());
                                ui.painter().rect_filled(r, 2.0, color(id_color(i as u32)));
                                ui.label(format!("{i}: {}", o.name));
                                ui.end_row();
                            }
                        });
                        if objects.len() > MAX_IDS {
                            small(ui, &format!("… and {} more objects", objects.len() - MAX_IDS));
                        }
                        small(ui, "no hit: black");
                    }
                    "barycentric" => small(ui, "red = b0 (v0), green = b1 (v1), blue = b2 (v2); they sum to 1"),
                    "raydir" => small(ui, "colour = (d + 1) / 2: red grows with x (right), green with y (up), blue with z (back)"),
                    "normal" => small(ui, "colour = (n + 1) / 2 in world space"),
                    "mip" => {
                        small(ui, &format!("level 0 = the full-size texture, each next level half as wide; {} filter", s.texture_filter.name()));
                        let ticks: Vec<(f32, String)> = (0..=MIP_SCALE as u32).step_by(2).map(|l| (l as f32 / MIP_SCALE, format!("{l}"))).collect();
                        bar(ui, |t| mip_color(t * MIP_SCALE), &ticks);
                        small(ui, "nearest and bilinear read level 0 only; dark grey: no texture; no hit: black");
                    }
                    "false-colour" => {
                        use crate::display::false_colour::{viridis, MAX_STOP, MIN_STOP};
                        small(ui, "log2 of the linear luminance (stop 0 = luminance 1) through viridis; black and NaN take the bottom colour");
                        let span = MAX_STOP - MIN_STOP;
                        let ticks: Vec<(f32, String)> = (MIN_STOP as i32..=MAX_STOP as i32).step_by(4).map(|s| ((s as f32 - MIN_STOP) / span, format!("{s:+}"))).collect();
                        bar(ui, |t| Vec3::from(viridis(t)), &ticks);
                    }
                    "error" | "absolute-error" | "signed-error" => match viewed.error {
                        Some(crate::app::reference_view::Mapped::Against { source, map }) => {
                            small(ui, &format!("luminance of this image (a) against {source} (b)"));
                            let ticks: Vec<(f32, String)> = map.legend().iter().map(|(v, _)| (map.position(*v), error_tick(*v))).collect();
                            bar(ui, |t| Vec3::from(map.colour(map.value_at(t))), &ticks);
                            if view == "signed-error" {
                                small(ui, "red: brighter than b, green: darker; the scale is the largest difference, rounded up");
                            }
                        }
                        Some(crate::app::reference_view::Mapped::Unmapped(why)) => small(ui, &format!("showing the shaded image: {why}")),
                        None => small(ui, "waiting for the image…"),
                    },
                    "nan" => {
                        let marked = viewed.with_output(|o| o.linear.iter().filter(|c| **c == crate::render::frame::NAN_MARK).count());
                        small(ui, "magenta: a sample of the pixel was NaN or infinite (the frame counts it as black); the rest: luminance, dimmed");
                        ui.label(format!("pixels marked: {marked}"));
                    }
                    "uv" => small(ui, "an 8 × 8 checker in (u, v): straight in perspective-correct interpolation, bent in affine"),
                    "diff" => {
                        small(ui, "red: brighter, blue: darker than the reference (10% of its mean = full scale); equal pixels dimmed grey");
                        match viewed.with_output(|o| o.differing_pixels.filter(|_| o.complete)) {
                            Some(n) => {
                                ui.label(format!("differing pixels: {n}"));
                            }
                            None => small(ui, "counting when both frames are complete…"),
                        }
                    }
                    _ => {}
                }
            });
        });
}
