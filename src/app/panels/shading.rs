//! Shading section (the debug view is in the top bar): shadows (none / ray / map / volume, the map's filter) and the ray bump,
//! light samples and MIS for area lights and the sky,
//! samples per pixel, secondary depth, ambient, background, exposure, the
//! display transform (exposure in stops, tone map, transfer curve); the rasterizers' knobs (MSAA, early depth, affine, depth
//! buffer format) and the wireframe view's line algorithm.

use eframe::egui;
use crate::app::panels::{color_edit, section};
use crate::app::settings_store::ViewerSettings;
use crate::display::{Gamma, ToneMap};
use crate::render::transport::gi::{GiMode, GiSettings, MAX_BOUNCES};
use crate::render::raster::clip::ClipMode;
use crate::render::raster::depth_format::DepthFormat;
use crate::render::inspect::wireframe::LineAlgorithm;
use crate::render::shadow::volume::VolumeMode;
use crate::render::shadow::ShadowFilter;
use crate::render::{Interpolation, Reflections, RenderSettings, ShadowMode};
use crate::scene::texture::TextureFilter;
use crate::scene::RenderDefaults;

/// What the renderer draws with, as the admission gate (`render::admit`)
/// let it: the settings admitted for the request last started, and the
/// gate's sentences saying what it substituted.
#[derive(Clone, Copy, Default)]
pub struct InForce<'a> {
    pub admitted: Option<&'a RenderSettings>,
    pub notices: &'a [String],
}

/// `settings`: the render knobs asked for (the worker renders with these,
/// through the gate) and the display transform; `look`: the scene's ambient, background and
/// exposure; `in_force`: what the gate admitted, shown where it differs.
pub fn show(ui: &mut egui::Ui, settings: &mut ViewerSettings, look: &mut RenderDefaults, in_force: InForce) {
    let mut open = settings.panels.shading;
    section(ui, "Shading", &mut open, |ui| {
        let s = &mut settings.render;
        ui.horizontal(|ui| {
            ui.label("shadows");
            for m in ShadowMode::ALL {
                ui.radio_value(&mut s.shadows, m, m.name());
            }
        });
        if let Some(admitted) = in_force.admitted.filter(|a| a.shadows != s.shadows) {
            let line = format!("in force: {} — {}", admitted.shadows.name(), in_force.notices.join("; "));
            ui.colored_label(egui::Color32::from_rgb(230, 180, 60), line);
        }
        ui.horizontal(|ui| {
            let l = ui.label("ray bump ε");
            ui.add(egui::Slider::new(&mut s.shadow_bump, 1e-7..=1e-1).logarithmic(true)).labelled_by(l.id);
        });
        if s.shadows == ShadowMode::Map {
            // CGPP 15.6.5's knobs: too little bias shows acne, too much peter-panning.
            ui.horizontal(|ui| {
                let l = ui.label("map size");
                ui.add(egui::Slider::new(&mut s.shadow_map_size, 16..=4096).logarithmic(true)).labelled_by(l.id);
            });
            ui.horizontal(|ui| {
                let l = ui.label("map bias (texels)");
                ui.add(egui::Slider::new(&mut s.shadow_map_bias, 0.0..=32.0)).labelled_by(l.id);
            });
            // Area lights: how the map's hard edge is softened.
            egui::ComboBox::from_label("shadow filter").selected_text(s.shadow_filter.name()).show_ui(ui, |ui| {
                for f in ShadowFilter::ALL {
                    ui.selectable_value(&mut s.shadow_filter, f, f.name());
                }
            });
            if s.shadow_filter == ShadowFilter::Pcf {
                ui.horizontal(|ui| {
                    let l = ui.label("PCF radius (texels)");
                    ui.add(egui::Slider::new(&mut s.pcf_radius, 0.0..=16.0)).labelled_by(l.id);
                });
            }
        }
        if s.shadows == ShadowMode::Volume {
            // Where the stencil counts volume faces: z-pass fails with the eye in a shadow.
            ui.horizontal(|ui| {
                ui.label("volume count");
                for m in VolumeMode::ALL {
                    ui.radio_value(&mut s.shadow_volume, m, m.name());
                }
            });
        }
        // Area lights and the environment: sampled, not summed.
        ui.horizontal(|ui| {
            let l = ui.label("light samples");
            ui.add(egui::Slider::new(&mut s.light_samples, 0..=64)).labelled_by(l.id)
                .on_hover_text("shadow rays per area light (and for the sky) per shading point; 0: found by BSDF sampling alone");
            ui.checkbox(&mut s.mis, "MIS").on_hover_text("weight light and BSDF samples by the power heuristic; off: light sampling alone");
        });
        ui.checkbox(&mut s.packets, "ray packets").on_hover_text("raytrace:bvh: trace rays as packets through the BVH; off: one ray at a time (the same pixels, slower)");
        gi_knobs(ui, &mut s.gi);
        ui.horizontal(|ui| {
            let l = ui.label("samples per pixel");
            ui.add(egui::Slider::new(&mut s.spp, 1..=256).logarithmic(true)).labelled_by(l.id);
        });
        ui.horizontal(|ui| {
            let l = ui.label("max depth");
            ui.add(egui::Slider::new(&mut s.max_depth, 0..=crate::render::settings_check::MAX_MIRROR_DEPTH)).labelled_by(l.id);
        });
        let r = look;
        color_edit(ui, "ambient", &mut r.ambient, 1.0);
        color_edit(ui, "background", &mut r.background, 1.0);
        ui.horizontal(|ui| {
            let l = ui.label("exposure");
            ui.add(egui::Slider::new(&mut r.exposure, 0.01..=100.0).logarithmic(true)).labelled_by(l.id);
        });
        // The display transform (`crate::display`): stops on top of the
        // scene's exposure, a tone map, the transfer curve (off: none). The
        // curve has this one control: `display.gamma` is its only setting.
        ui.horizontal(|ui| {
            let l = ui.label("exposure (stops)");
            ui.add(egui::Slider::new(&mut s.display.exposure_ev, -10.0..=10.0).step_by(0.1)).labelled_by(l.id);
        });
        egui::ComboBox::from_label("tone map").selected_text(s.display.tonemap.name()).show_ui(ui, |ui| {
            for t in ToneMap::ALL {
                ui.selectable_value(&mut s.display.tonemap, t, t.name());
            }
        });
        egui::ComboBox::from_label("transfer curve").selected_text(s.display.gamma.name()).show_ui(ui, |ui| {
            for g in Gamma::ALL {
                ui.selectable_value(&mut s.display.gamma, g, g.name());
            }
        });
        ui.horizontal(|ui| {
            ui.label("interpolation");
            for m in Interpolation::ALL {
                ui.radio_value(&mut s.interpolation, m, m.name());
            }
        });
        // Combo boxes: "ray" and "nearest" would share their names with other controls.
        egui::ComboBox::from_label("texture filter").selected_text(s.texture_filter.name()).show_ui(ui, |ui| {
            for f in TextureFilter::ALL {
                ui.selectable_value(&mut s.texture_filter, f, f.name());
            }
        });
        egui::ComboBox::from_label("reflections").selected_text(s.reflections.name()).show_ui(ui, |ui| {
            for r in Reflections::ALL {
                ui.selectable_value(&mut s.reflections, r, r.name());
            }
        });
        subsample_controls(ui, &mut s.subsample);
        // Rasterizer-only knobs; the ray casters ignore them.
        ui.horizontal(|ui| {
            ui.label("rasterizer: MSAA");
            for n in [1u32, 2, 4, 8] {
                ui.radio_value(&mut s.msaa, n, if n == 1 { "off".to_string() } else { format!("{n}x") });
            }
        });
        ui.horizontal(|ui| {
            ui.checkbox(&mut s.early_depth, "early depth").on_hover_text("depth pass first, then shade once per pixel (CGPP 15.8.3)");
            ui.checkbox(&mut s.affine, "affine uv").on_hover_text("interpolate in screen space without the 1/z correction: try the uv view");
        });
        ui.horizontal(|ui| {
            let l = ui.label("rasterizer: sub-pixel bits");
            ui.add(egui::Slider::new(&mut s.subpixel_bits, 0..=crate::render::raster::subpixel::SUBPIXEL_BITS)).labelled_by(l.id)
                .on_hover_text("fixed, tiled and painter: the grid vertices are snapped to; fewer bits move edges");
        });
        // A combo box: "f32" and friends would read oddly as a row of radios.
        egui::ComboBox::from_label("rasterizer: depth buffer").selected_text(s.depth_buffer.name()).show_ui(ui, |ui| {
            for f in DepthFormat::ALL {
                ui.selectable_value(&mut s.depth_buffer, f, f.name()).on_hover_text(f.description());
            }
        });
        ui.horizontal(|ui| {
            ui.label("rasterizer: clip at");
            for c in ClipMode::ALL {
                ui.radio_value(&mut s.clip, c, c.name()).on_hover_text(match c {
                    ClipMode::Near => "the near plane only",
                    ClipMode::Frustum => "every plane of the view volume: the same image, measured in pinhole bench",
                });
            }
        });
        ui.horizontal(|ui| {
            ui.label("wireframe lines");
            for a in LineAlgorithm::ALL {
                ui.radio_value(&mut s.lines, a, a.name());
            }
        });
    });
    settings.panels.shading = open;
}

/// Indirect light: the mode and the knobs of the chosen one.
fn gi_knobs(ui: &mut egui::Ui, gi: &mut GiSettings) {
    // A combo box: its choices ("none", "path", ...) would otherwise share
    // their names with other controls on screen.
    egui::ComboBox::from_label("indirect light").selected_text(gi.mode.name()).show_ui(ui, |ui| {
        for m in GiMode::ALL {
            ui.selectable_value(&mut gi.mode, m, m.name());
        }
    });
    match gi.mode {
        GiMode::None => {}
        GiMode::Ao => {
            ui.horizontal(|ui| {
                let l = ui.label("AO rays");
                ui.add(egui::Slider::new(&mut gi.ao_samples, 1..=256).logarithmic(true)).labelled_by(l.id);
            });
            ui.horizontal(|ui| {
                let l = ui.label("AO distance");
                ui.add(egui::Slider::new(&mut gi.ao_distance, 0.01..=100.0).logarithmic(true)).labelled_by(l.id);
            });
        }
        GiMode::Photons => {
            ui.horizontal(|ui| {
                let l = ui.label("photons");
                ui.add(egui::Slider::new(&mut gi.photons, 1_000..=5_000_000).logarithmic(true)).labelled_by(l.id);
            });
            ui.horizontal(|ui| {
                let l = ui.label("nearest photons k");
                ui.add(egui::Slider::new(&mut gi.photon_k, 1..=1024).logarithmic(true)).labelled_by(l.id);
            });
            ui.horizontal(|ui| {
                let l = ui.label("final gather rays");
                ui.add(egui::Slider::new(&mut gi.final_gather, 0..=256)).labelled_by(l.id);
            });
        }
        GiMode::Path => {
            ui.horizontal(|ui| {
                let mut unbounded = gi.bounces.is_none();
                ui.checkbox(&mut unbounded, "unbounded (Russian roulette)");
                let mut n = gi.bounces.unwrap_or(4);
                if !unbounded {
                    let l = ui.label("bounces");
                    ui.add(egui::Slider::new(&mut n, 0..=MAX_BOUNCES)).labelled_by(l.id);
                }
                gi.bounces = (!unbounded).then_some(n);
            });
        }
    }
    ui.horizontal(|ui| {
        let l = ui.label("seed");
        ui.add(egui::DragValue::new(&mut gi.seed)).labelled_by(l.id);
    });
}

/// Sub-sampling: the grid spacing, and whether (and above what contrast)
/// grid cells whose corners differ are traced in full.
fn subsample_controls(ui: &mut egui::Ui, sub: &mut crate::render::frame::Subsample) {
    use crate::render::frame::subsample::STEPS;
    let name = |step: u32| if step == 1 { "off".to_string() } else { format!("every {step}") };
    egui::ComboBox::from_label("sub-sample").selected_text(name(sub.step)).show_ui(ui, |ui| {
        for step in STEPS {
            ui.selectable_value(&mut sub.step, step, name(step));
        }
    })
    .response
    .on_hover_text("trace every N-th pixel in x and y and interpolate the pixels between (whole frames, shaded view)");
    if sub.step > 1 {
        ui.horizontal(|ui| {
            let mut refine = sub.contrast.is_some();
            ui.checkbox(&mut refine, "refine where corners differ by");
            let mut c = sub.contrast.unwrap_or(0.3);
            ui.add_enabled(refine, egui::DragValue::new(&mut c).range(0.0..=1.0).speed(0.01));
            sub.contrast = refine.then_some(c);
        });
    }
}
