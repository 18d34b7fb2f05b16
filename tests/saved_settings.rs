//! The viewer's saved settings store views, shadow modes and interpolation by
//! the names the command line takes; settings saved with the earlier
//! spellings (`geometricnormal`, `triangleid`, `materialid`) and files the
//! last release saved (its render knobs beside the others) still load.

use pinhole::app::settings_store::ViewerSettings;
use pinhole::render::inspect::debug::View;
use pinhole::render::{Interpolation, Reflections, RenderSettings, ShadowMode};

use pinhole::app::settings_store::MemoryStorage as Mem;

fn stored(text: &str) -> Mem {
    let mut mem = Mem::default();
    mem.0.insert(pinhole::app::settings_store::STORAGE_KEY.into(), text.into());
    mem
}

#[test]
fn every_choice_saves_under_its_name_and_loads_back() {
    for view in View::ALL {
        for shadows in ShadowMode::ALL {
            for interpolation in Interpolation::ALL {
                let mut p = ViewerSettings::default();
                (p.render.view, p.render.shadows, p.render.interpolation) = (view, shadows, interpolation);
                let mut mem = Mem::default();
                p.save(&mut mem);
                let text = mem.0.values().next().unwrap().clone();
                assert!(text.contains(view.name()), "{text} lacks {}", view.name());
                assert_eq!(ViewerSettings::load(Some(&mem)), Some(p), "{text}");
            }
        }
    }
}

#[test]
fn settings_saved_with_the_old_spellings_load() {
    for (old, view) in [("geometricnormal", View::GeometricNormal), ("triangleid", View::TriangleId), ("materialid", View::MaterialId), ("zbuffer", View::Zbuffer)] {
        let mem = stored(&format!("(scene:Some(\"teapot\"),spp:4,shadows:map,view:{old},interpolation:gouraud)"));
        let p = ViewerSettings::load(Some(&mem)).unwrap_or_else(|| panic!("{old} does not load"));
        assert_eq!((p.render.view, p.render.shadows, p.render.interpolation, p.render.spp), (view, ShadowMode::Map, Interpolation::Gouraud, 4));
        assert_eq!(p.scene.as_deref(), Some("teapot"));
    }
    // An unknown name fails the load (the viewer then starts from defaults).
    assert_eq!(ViewerSettings::load(Some(&stored("(view:nonsense)"))), None);
}

/// Files as the last release wrote them (`ViewerSettings::save`, before the
/// render knobs became a `RenderSettings`): its defaults, and every knob it
/// saved changed.
const LAST_RELEASE_DEFAULT: &str = r#"(scene:None,renderer:Some("raytrace:bvh"),spp:1,shadows:ray,shadow_volume:zfail,shadow_bump:0.0001,max_depth:4,view:shaded,interpolation:phong,gi:(mode:none,bounces:None,ao_samples:16,ao_distance:1.0,photons:200000,photon_k:64,final_gather:0,seed:0),texture_filter:trilinear,reflections:ray,subsample:(step:1,contrast:None),res_scale:1.0,gamma:true,panels:(side:true,camera:false,lights:true,materials:false,shading:true))"#;
const LAST_RELEASE_CHANGED: &str = r#"(scene:Some("spheres"),renderer:Some("rasterize:fixed"),spp:9,shadows:map,shadow_volume:zpass,shadow_bump:0.001,max_depth:6,view:normal,interpolation:gouraud,gi:(mode:path,bounces:Some(3),ao_samples:16,ao_distance:1.0,photons:200000,photon_k:64,final_gather:0,seed:7),texture_filter:bilinear,reflections:env,subsample:(step:4,contrast:Some(0.3)),res_scale:0.5,gamma:false,panels:(side:true,camera:true,lights:false,materials:false,shading:true))"#;

#[test]
fn files_the_last_release_saved_load_with_their_values() {
    let p = ViewerSettings::load(Some(&stored(LAST_RELEASE_DEFAULT))).expect("the last release's defaults load");
    assert_eq!(p, ViewerSettings::default());

    let p = ViewerSettings::load(Some(&stored(LAST_RELEASE_CHANGED))).expect("the last release's settings load");
    assert_eq!(p.scene.as_deref(), Some("spheres"));
    assert_eq!(p.renderer, "rasterize:fixed");
    // The old "gamma" checkbox off: no transfer curve.
    assert_eq!((p.res_scale, p.render.display.gamma), (0.5, pinhole::display::Gamma::Off));
    assert!(p.panels.camera && !p.panels.lights);
    let r = &p.render;
    let mut expected = RenderSettings::default();
    expected.spp = 9;
    expected.shadows = ShadowMode::Map;
    expected.shadow_volume = pinhole::render::shadow::volume::VolumeMode::ZPass;
    expected.shadow_bump = 0.001;
    expected.max_depth = 6;
    expected.view = View::Normal;
    expected.interpolation = Interpolation::Gouraud;
    expected.gi.mode = pinhole::render::transport::gi::GiMode::Path;
    expected.gi.bounces = Some(3);
    expected.gi.seed = 7;
    expected.texture_filter = pinhole::scene::texture::TextureFilter::Bilinear;
    // The old checkbox's `gamma:false` is the transfer curve `off` now.
    expected.display.gamma = pinhole::display::Gamma::Off;
    expected.reflections = Reflections::Env;
    expected.subsample = pinhole::render::frame::Subsample { step: 4, contrast: Some(0.3) };
    assert_eq!(*r, expected);

    // Saved again, they load again (in this release's layout).
    let mut mem = Mem::default();
    p.save(&mut mem);
    assert!(mem.0.values().next().unwrap().contains("render:("), "saved in the new layout");
    assert_eq!(ViewerSettings::load(Some(&mem)), Some(p));
}
