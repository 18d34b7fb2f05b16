//! The viewer driven like a user with egui_kittest: pick a renderer, edit a
//! material colour, move a light, export; each test checks the app state and
//! the rendered pixels (against `render_frame` of the same scene) or the file.

use eframe::egui;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pinhole::app::PinholeApp;
use pinhole::math::{Radiance, Vec3};
use pinhole::render::{self, PreparedScene};
use pinhole::scene::{Light, Scene};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

#[path = "common/app.rs"]
mod app_common;
use app_common::{WAIT, new_harness, settle, small_scene};

fn harness(scene: Scene) -> Harness<'static, PinholeApp> {
    let mut h = new_harness(scene);
    settle(&mut h);
    h
}

/// Runs frames until the worker finished what the UI asked, and one more
/// frame so the texture shows it.
/// What `pinhole render` computes for the app's current scene, settings and renderer.
fn reference(app: &PinholeApp) -> Vec<Radiance> {
    let mut scene = (*app.scene()).clone();
    app.params().apply(&mut scene);
    let prepared = PreparedScene::new(scene);
    let renderer = render::renderer_by_name(&app.settings().renderer).unwrap();
    let settings = app.effective_settings();
    render::render_frame(renderer.as_ref(), &prepared, &settings, &AtomicBool::new(false), None)
        .unwrap()
        .pixels
}

fn shown(app: &PinholeApp) -> Vec<Radiance> {
    app.with_output(|o| {
        assert!(o.complete && o.error.is_none(), "frame not complete: {:?}", o.error);
        o.linear.clone()
    })
}

fn pixel(app: &PinholeApp, x: u32, y: u32) -> Radiance {
    app.with_output(|o| o.linear[(x + y * o.width) as usize])
}

#[test]
fn first_frame_matches_the_reference_renderer() {
    let h = harness(small_scene("one-triangle"));
    let app = h.state();
    assert_eq!(app.with_output(|o| (o.width, o.height)), (160, 100));
    assert_eq!(shown(app), reference(app));
    let status = app.status_line();
    assert!(status.contains("160x100") && status.contains("1/1 spp") && status.contains("1 triangles"), "{status}");
}

#[test]
fn renderer_combo_and_number_keys_switch_renderer_in_place() {
    let mut h = harness(small_scene("one-triangle"));
    let names = h.state().renderer_names().to_vec();
    let target = *names.iter().find(|n| **n != h.state().settings().renderer).expect("at least two renderers");
    let camera = h.state().params().camera.clone();
    h.get_by_label("Renderer").click();
    h.step();
    h.step();
    h.get_by_label(target).click();
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.settings().renderer, target);
    assert_eq!(app.params().camera, camera, "the camera stays when the renderer changes");
    assert_eq!(shown(app), reference(app), "{target} image differs from render_frame");
    assert!(app.status_line().starts_with(target));

    // Key 1 picks the first renderer.
    h.key_press(egui::Key::Num1);
    settle(&mut h);
    assert_eq!(h.state().settings().renderer, names[0]);
}

#[test]
fn editing_a_material_colour_rerenders_with_it() {
    let mut h = harness(small_scene("one-triangle"));
    let centre = pixel(h.state(), 80, 60);
    assert!(centre.x < 1e-6, "the green triangle has (almost) no red: {centre}");
    h.get_by_label("Materials").click();
    h.step();
    h.step();
    h.get_by_label("green k_L R").set_value_accesskit(0.8);
    settle(&mut h);
    let app = h.state();
    let green = app.params().materials.iter().find(|m| m.name == "green").unwrap();
    assert_eq!(green.lambertian, Vec3::new(0.8, 0.8, 0.0));
    let after = pixel(app, 80, 60);
    assert!(after.x > 1e-4 && after.x > 0.5 * after.y, "red appears where the triangle is lit: {after}");
    assert_eq!(shown(app), reference(app));
}

#[test]
fn choosing_a_diffuse_model_in_the_panel_rerenders_with_it() {
    use pinhole::scene::material::DiffuseModel;
    let mut h = harness(small_scene("one-triangle"));
    let before = shown(h.state());
    h.get_by_label("Materials").click();
    h.step();
    h.step();
    h.get_by_label("green diffuse model").click();
    h.step();
    h.step();
    h.get_by_label("toon").click();
    settle(&mut h);
    let app = h.state();
    let green = app.params().materials.iter().find(|m| m.name == "green").unwrap();
    assert_eq!(green.diffuse_model, DiffuseModel::Toon { bands: 3 });
    let after = shown(app);
    assert_ne!(before, after, "the toon lobe changed nothing");
    assert_eq!(after, reference(app));
}

#[test]
fn moving_a_light_in_the_panel_and_by_its_marker() {
    let mut h = harness(small_scene("one-triangle"));
    let before = shown(h.state());
    // Bring the light in front of the camera with the panel's drag values.
    h.get_by_label("L0 position z").set_value_accesskit(-1.0);
    settle(&mut h);
    h.get_by_label("L0 position y").set_value_accesskit(0.0);
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.params().lights[0], Light::Point { position: Vec3::new(1.0, 0.0, -1.0), power: Vec3::splat(10.0) });
    let after = shown(app);
    assert_ne!(before, after);
    assert_eq!(after, reference(app));

    // Drag its marker 30 points left: the light moves left in the view plane at its depth.
    let settings = app.effective_settings();
    let view = app.params().camera.view(settings.width, settings.height);
    let rect = app.viewport_rect().unwrap();
    let (p, depth) = view.project(Vec3::new(1.0, 0.0, -1.0)).unwrap();
    let scale = rect.width() / settings.width as f32;
    let start = rect.min + egui::vec2(p.x, p.y) * scale;
    h.drag_at(start);
    h.step();
    h.hover_at(start + egui::vec2(-10.0, 0.0));
    h.step();
    h.hover_at(start + egui::vec2(-30.0, 0.0));
    h.step();
    h.drop_at(start + egui::vec2(-30.0, 0.0));
    settle(&mut h);
    let app = h.state();
    let Light::Point { position, .. } = app.params().lights[0] else { panic!("not a point light") };
    assert!(position.x < 1.0 - 1e-3, "light did not move left: {position}");
    assert!((view.view_depth(position) - depth).abs() < 1e-3, "depth kept");
    assert_eq!(shown(app), reference(app));
}

#[test]
fn adding_and_removing_lights() {
    let mut h = harness(small_scene("one-triangle"));
    h.get_by_label("+ directional").click();
    settle(&mut h);
    assert!(matches!(h.state().params().lights[1], Light::Directional { .. }));
    assert_eq!(shown(h.state()), reference(h.state()));
    h.get_all_by_label("remove").next().unwrap().click();
    settle(&mut h);
    assert_eq!(h.state().params().lights.len(), 1);
    assert!(matches!(h.state().params().lights[0], Light::Directional { .. }));
}

#[test]
fn ctrl_s_exports_png_as_displayed_and_linear_exr() {
    let mut h = harness(small_scene("one-triangle"));
    let dir = std::env::temp_dir().join(format!("pinhole-app-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A debug view is exported as displayed, too.
    h.state_mut().settings_mut().render.view = render::inspect::debug::View::Barycentric;
    settle(&mut h);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    h.step();
    h.step();
    let suggested = h.state().export_path().to_string();
    assert!(suggested.contains("one-triangle-raytrace_"), "{suggested}");
    let base = dir.join("shot");
    h.get_by_label("file").set_text_value_accesskit(&base.with_extension("png").to_string_lossy());
    h.step();
    h.get_by_label("Save PNG (as displayed)").click();
    h.step();
    h.step();
    let png = image::open(base.with_extension("png")).unwrap().to_rgb8();
    let displayed = h.state().with_output(|o| o.rgb8.clone());
    assert_eq!(png.as_raw(), &displayed);
    assert!(h.state().message().unwrap_or("").contains("saved"));

    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    h.step();
    h.step();
    h.get_by_label("file").set_text_value_accesskit(&base.with_extension("png").to_string_lossy());
    h.step();
    h.get_by_label("Save EXR (linear)").click();
    h.step();
    let exr = pinhole::image_io::load_image(&base.with_extension("exr")).unwrap();
    assert_eq!(exr.pixels, shown(h.state()));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_broken_file_shows_its_error_and_the_scene_stays_then_reloads_on_change() {
    let mut h = harness(small_scene("one-triangle"));
    let dir = std::env::temp_dir().join(format!("pinhole-app-reload-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("mine.toml");
    let good = "[render]\nwidth = 64\nheight = 40\nbackground = [0.5, 0.0, 0.0]\n\n[[light]]\ntype = \"point\"\nposition = [0.0, 2.0, 0.0]\npower = [10.0, 10.0, 10.0]\n\n[[object]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, -3.0]\nradius = 1.0\n";
    std::fs::write(&path, "[camera]\neye = [0.0, 0.0]\n").unwrap();

    // Open through the dialog: type the path, press Open.
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::O);
    h.step();
    h.step();
    assert!(h.state().open_dialog_is_open());
    h.get_by_label("path").set_text_value_accesskit(&path.to_string_lossy());
    h.step();
    h.get_by_label("Open").click();
    h.step();
    assert!(h.state_mut().wait_loaded(WAIT));
    h.step();
    let err = h.state().error_bar().map(str::to_string).expect("an error bar");
    assert!(err.contains("mine.toml"), "{err}");
    assert_eq!(h.state().scene().name, "one-triangle", "the previous scene stays");
    assert!(h.query_by_label_contains("mine.toml").is_some(), "the error is on screen");

    // Fix the file: the viewer notices and reloads it.
    std::fs::write(&path, good).unwrap();
    h.state_mut().open(path.to_string_lossy().into_owned());
    assert!(h.state_mut().wait_loaded(WAIT));
    settle(&mut h);
    assert!(h.state().error_bar().is_none());
    assert_eq!(h.state().scene().name, "mine");
    assert_eq!(pixel(h.state(), 0, 0), Vec3::new(0.5, 0.0, 0.0));
    std::thread::sleep(Duration::from_millis(1100));
    std::fs::write(&path, good.replace("[0.5, 0.0, 0.0]", "[0.0, 0.25, 0.0]")).unwrap();
    let start = std::time::Instant::now();
    while h.state().params().render.background.y != 0.25 && start.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(100));
        h.step();
        h.state_mut().wait_loaded(WAIT);
    }
    settle(&mut h);
    assert_eq!(pixel(h.state(), 0, 0), Vec3::new(0.0, 0.25, 0.0), "reloaded after the file changed");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn orbit_drag_moves_the_eye_around_the_target() {
    let mut h = harness(small_scene("teapot"));
    let before = h.state().params().camera.clone();
    let c = h.state().viewport_rect().unwrap().center();
    h.drag_at(c);
    h.step();
    h.hover_at(c + egui::vec2(40.0, 10.0));
    h.step();
    h.drop_at(c + egui::vec2(40.0, 10.0));
    settle(&mut h);
    let cam = &h.state().params().camera;
    assert_eq!(cam.target, before.target);
    assert!((cam.eye - before.eye).length() > 1e-3);
    assert!(((cam.eye - cam.target).length() - (before.eye - before.target).length()).abs() < 1e-3);
    assert_eq!(shown(h.state()), reference(h.state()));
    // F frames everything; Home resets.
    h.key_press(egui::Key::Home);
    settle(&mut h);
    assert_eq!(h.state().params().camera, before);
}

#[test]
fn samples_accumulate_and_exposure_is_display_only() {
    let mut h = harness(small_scene("one-triangle"));
    h.state_mut().settings_mut().render.spp = 4;
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.with_output(|o| (o.passes, o.spp)), (4, 4));
    assert_eq!(shown(app).len(), reference(app).len());
    let lin = shown(app);
    let refr = reference(app);
    let max = lin.iter().zip(&refr).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0, f32::max);
    assert!(max < 1e-5, "4 spp differs from render_frame by {max}");
    let rgb_before = app.with_output(|o| o.rgb8.clone());
    h.state_mut().params_mut().render.exposure = 4.0;
    settle(&mut h);
    assert_eq!(shown(h.state()), lin, "exposure does not re-render");
    assert_ne!(h.state().with_output(|o| o.rgb8.clone()), rgb_before);
}

#[test]
fn shadow_map_mode_never_crashes_the_viewer() {
    let mut h = harness(small_scene("triangle-ground"));
    h.get_by_label("map").click();
    settle(&mut h);
    assert_eq!(h.state().settings().render.shadows, render::ShadowMode::Map);
    let status = h.state().status_line();
    assert!(status.contains("done") || status.contains("error"), "{status}");
    // And back to ray shadows renders normally.
    h.get_by_label("ray").click();
    settle(&mut h);
    assert_eq!(shown(h.state()), reference(h.state()));
}

/// Shadow maps too big for memory (many lights at a large size) are an
/// error in the viewer, not an abort; a smaller size renders again.
#[test]
fn shadow_maps_over_the_memory_limit_are_an_error_not_a_crash() {
    let mut scene = small_scene("triangle-ground");
    let light = scene.lights[0].clone();
    scene.lights = vec![light; 40];
    let mut h = harness(scene);
    {
        let app = h.state_mut();
        app.settings_mut().render.shadows = render::ShadowMode::Map;
        app.settings_mut().render.shadow_map_size = 4096;
    }
    settle(&mut h);
    let error = h.state().with_output(|o| o.error.clone()).expect("an error");
    assert!(error.contains("shadow maps") && error.contains("MiB"), "{error}");
    h.state_mut().settings_mut().render.shadow_map_size = 64;
    settle(&mut h);
    assert!(h.state().with_output(|o| o.error.is_none() && o.complete));
}

#[test]
fn settings_persist_between_runs() {
    use pinhole::app::settings_store::MemoryStorage as Mem;
    let mut app = PinholeApp::new_for_test(small_scene("one-triangle"));
    app.settings_mut().renderer = "raytrace:brute".into();
    app.settings_mut().render.spp = 9;
    app.settings_mut().render.display.gamma = pinhole::display::Gamma::Off;
    app.settings_mut().panels.materials = true;
    let mut mem = Mem::default();
    app.settings().save(&mut mem);
    let p = pinhole::app::settings_store::ViewerSettings::load(Some(&mem)).unwrap();
    let again = PinholeApp::new(small_scene("spheres"), "spheres".into(), Some(&p));
    assert_eq!(p.scene.as_deref(), Some("one-triangle"));
    assert_eq!(again.settings().renderer, "raytrace:brute");
    assert_eq!(again.settings().render.spp, 9);
    assert!(again.settings().render.display.gamma == pinhole::display::Gamma::Off && again.settings().panels.materials);
}

#[test]
fn open_dialog_lists_scenes_and_folders() {
    let dir = std::env::temp_dir().join(format!("pinhole-app-list-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    for f in ["b.toml", "a.obj", "c.txt", ".hidden.toml"] {
        std::fs::write(dir.join(f), "").unwrap();
    }
    let names: Vec<String> = pinhole::app::open_dialog::list_dir(&dir)
        .unwrap()
        .into_iter()
        .map(|(p, _)| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["sub", "a.obj", "b.toml"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[derive(Debug)]
struct Dropped(std::path::PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &std::path::Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn dropping_an_obj_on_the_window_opens_it_framed() {
    let mut h = harness(small_scene("one-triangle"));
    let dir = std::env::temp_dir().join(format!("pinhole-app-drop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("tri.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    h.input_mut().dropped_files.push(std::sync::Arc::new(Dropped(obj.clone())));
    h.step();
    assert!(h.state_mut().wait_loaded(WAIT));
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.scene().name, "tri");
    assert_eq!(app.scene().triangles.len(), 1);
    assert!(app.error_bar().is_none());
    assert_eq!(shown(app), reference(app));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rasterizer_knobs_in_the_shading_panel_reach_the_pixels() {
    // The teapot's ground quad under the uv view: ticking "affine uv" bends the
    // checker (screen-space interpolation), and MSAA 4x changes edge pixels.
    let mut h = harness(small_scene("teapot"));
    h.state_mut().settings_mut().renderer = "rasterize".into();
    h.state_mut().settings_mut().render.view = pinhole::render::inspect::debug::View::Uv;
    h.state_mut().settings_mut().panels.shading = true;
    settle(&mut h);
    let before = shown(h.state());
    h.get_by_label("affine uv").click();
    settle(&mut h);
    assert!(h.state().settings().render.affine);
    let affine = shown(h.state());
    assert_eq!(affine, reference(h.state()), "the viewer shows what render_frame gives");
    let changed = before.iter().zip(&affine).filter(|(a, b)| a != b).count();
    assert!(changed > before.len() / 20, "affine uv changed only {changed} pixels");
    h.get_by_label("4x").click();
    settle(&mut h);
    assert_eq!(h.state().settings().render.msaa, 4);
    assert_eq!(shown(h.state()), reference(h.state()));
}

#[test]
fn indirect_light_selector_reaches_the_pixels() {
    // The Cornell box at a few samples: choosing path tracing in the shading
    // panel brightens the walls with bounced light, the image is the one
    // render_frame gives for the same settings, and the status bar reports
    // the noise left once two passes are in.
    let mut h = harness(small_scene("cornell-gi"));
    h.state_mut().settings_mut().panels.shading = true;
    h.state_mut().settings_mut().render.spp = 4;
    settle(&mut h);
    let direct = shown(h.state());
    h.get_by_label("indirect light").click();
    h.run();
    h.get_by_label("path").click();
    settle(&mut h);
    assert_eq!(h.state().settings().render.gi.mode, pinhole::render::transport::gi::GiMode::Path);
    let path = shown(h.state());
    assert_eq!(path, reference(h.state()), "the viewer shows what render_frame gives");
    let mean = |img: &[pinhole::math::Radiance]| img.iter().map(|c| c.x + c.y + c.z).sum::<f32>() / img.len() as f32;
    assert!(mean(&path) > 1.3 * mean(&direct), "bounced light adds nothing: {} vs {}", mean(&path), mean(&direct));
    let status = h.state().status_line();
    assert!(status.contains("noise ≈"), "{status}");
}

#[test]
fn opengl_in_the_viewer_draws_what_render_frame_draws() {
    // The viewer's worker calls the renderer on its own thread; the
    // headless GL context is made current there for each pass.
    if !app_common::have_gl() {
        return;
    }
    let mut h = harness(small_scene("teapot"));
    h.state_mut().settings_mut().renderer = "opengl".into();
    settle(&mut h);
    // Shadow rays (the default) are drawn as shadow maps, and the status bar says so.
    let (error, notices) = h.state().with_output(|o| (o.error.clone(), o.notices.clone()));
    assert_eq!(error, None);
    let notice = "opengl cannot trace shadow rays; drawing shadow maps instead (--shadows map)";
    assert_eq!(notices, vec![notice.to_string()]);
    h.get_by_label(notice);
    let substituted = shown(h.state());
    h.state_mut().settings_mut().render.shadows = pinhole::render::ShadowMode::Map;
    settle(&mut h);
    assert_eq!(shown(h.state()), substituted, "the image is the shadow maps'");
    assert_eq!(substituted, reference(h.state()));
    assert!(h.state().with_output(|o| o.notices.is_empty()), "asked for maps, nothing is substituted");
    h.state_mut().settings_mut().render.shadows = pinhole::render::ShadowMode::None;
    settle(&mut h);
    let img = shown(h.state());
    assert_eq!(img, reference(h.state()));
    let background = h.state().scene().render.background;
    assert!(img.iter().filter(|p| **p != background).count() > img.len() / 10, "the teapot is drawn");
}

#[test]
fn the_lobe_plot_opens_with_the_directional_albedo() {
    let mut h = harness(small_scene("spheres"));
    h.get_by_label("Materials").click();
    h.step();
    h.step();
    h.get_by_label("red lobe plot").click_accesskit();
    h.step();
    h.step();
    // The albedo printed is the plot module's integral for the red material
    // at the default angle, and a Lambertian-plus-glossy lobe reflects
    // between its diffuse albedo's share and 1.
    let red = h.state().params().materials.iter().find(|m| m.name == "red").unwrap().clone();
    let a = pinhole::app::panels::bsdf_plot::directional_albedo(&red, 45.0);
    let text = format!("red directional albedo: {:.4} {:.4} {:.4}", a.x, a.y, a.z);
    h.get_by_label(&text);
    assert!(a.x > 0.8 && a.x < 1.0, "{a}");
    // Another incident angle, another albedo (the glossy lobe loses light at grazing).
    h.get_by_role_and_label(egui::accesskit::Role::Slider, "red incident angle").set_value_accesskit(85.0);
    h.step();
    h.step();
    let b = pinhole::app::panels::bsdf_plot::directional_albedo(&red, 85.0);
    assert!(b.x < a.x, "{b} at 85 degrees, {a} at 45");
    h.get_by_label(&format!("red directional albedo: {:.4} {:.4} {:.4}", b.x, b.y, b.z));
}
