//! The viewer's saved settings store views, shadow modes and interpolation by
//! the names the command line takes, and settings saved with the earlier
//! spellings (`geometricnormal`, `triangleid`, `materialid`) still load.

use pinhole::app::settings_store::ViewerSettings;
use pinhole::render::inspect::debug::View;
use pinhole::render::{Interpolation, ShadowMode};

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
                let p = ViewerSettings { view, shadows, interpolation, ..ViewerSettings::default() };
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
        assert_eq!((p.view, p.shadows, p.interpolation, p.spp), (view, ShadowMode::Map, Interpolation::Gouraud, 4));
        assert_eq!(p.scene.as_deref(), Some("teapot"));
    }
    // An unknown name fails the load (the viewer then starts from defaults).
    assert_eq!(ViewerSettings::load(Some(&stored("(view:nonsense)"))), None);
}
