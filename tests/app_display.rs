//! The viewer's display transform: the tone-map selector, the exposure in
//! stops and the transfer curve change the image on show and never the
//! rendered data (no re-render, the linear image stays bit for bit).

use egui_kittest::kittest::Queryable;
use pinhole::display::ToneMap;

#[path = "common/app.rs"]
mod app_common;
use app_common::{new_harness, settle, small_scene};

fn srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

#[test]
fn the_tone_map_selector_changes_the_displayed_image_only() {
    let mut h = new_harness(small_scene("spheres"));
    h.state_mut().settings_mut().panels.shading = true;
    settle(&mut h);
    let (linear, before) = h.state().with_output(|o| (o.linear.clone(), o.rgb8.clone()));
    let exposure = h.state().params().render.exposure;

    h.get_by_label("tone map").click();
    h.run();
    h.get_by_label("reinhard").click();
    settle(&mut h);
    assert_eq!(h.state().settings().render.display.tonemap, ToneMap::Reinhard);
    let (linear_after, reinhard) = h.state().with_output(|o| (o.linear.clone(), o.rgb8.clone()));
    assert_eq!(linear_after, linear, "a tone map renders nothing again");
    assert_ne!(reinhard, before, "the selector changes the image on show");
    // Each channel is x / (1 + x) of the exposed value, then sRGB.
    let expect: Vec<u8> = linear
        .iter()
        .flat_map(|c| [c.x, c.y, c.z])
        .map(|v| {
            let v = (v * exposure).max(0.0);
            (srgb(v / (1.0 + v)).clamp(0.0, 1.0) * 255.0 + 0.5) as u8
        })
        .collect();
    assert_eq!(reinhard, expect);

    // One stop up without a tone map doubles the linear value before the curve.
    h.state_mut().settings_mut().render.display.tonemap = ToneMap::Standard;
    h.state_mut().settings_mut().render.display.exposure_ev = 1.0;
    settle(&mut h);
    let (linear_after, brighter) = h.state().with_output(|o| (o.linear.clone(), o.rgb8.clone()));
    assert_eq!(linear_after, linear);
    let expect: Vec<u8> = linear
        .iter()
        .flat_map(|c| [c.x, c.y, c.z])
        .map(|v| (srgb((2.0 * v * exposure).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8)
        .collect();
    assert_eq!(brighter, expect);
}

#[test]
fn display_settings_save_and_load_back() {
    // Every curve and tone map by name in the viewer's saved settings,
    // including the transfer curve called "2.2".
    use pinhole::app::settings_store::{MemoryStorage, ViewerSettings};
    use pinhole::display::Gamma;
    for tonemap in ToneMap::ALL {
        for gamma in Gamma::ALL {
            let mut p = ViewerSettings::default();
            p.render.display = pinhole::display::DisplaySettings { exposure_ev: -1.5, tonemap, gamma };
            let mut mem = MemoryStorage::default();
            p.save(&mut mem);
            let text = mem.0.values().next().unwrap().clone();
            assert_eq!(ViewerSettings::load(Some(&mem)), Some(p), "{text}");
        }
    }
}
