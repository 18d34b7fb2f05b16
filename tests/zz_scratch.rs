mod common;
use common::{builtin, render};
use pinhole::render::{PreparedScene, RenderSettings};
#[test]
fn scratch() {
    for (w, h, msaa) in [(160u32, 120u32, 1u32), (640, 480, 1), (160, 120, 4)] {
        let scene = builtin("csg");
        let mut settings = RenderSettings::for_scene(&scene);
        settings.width = w;
        settings.height = h;
        settings.msaa = msaa;
        let prepared = PreparedScene::new(scene);
        let reference = render("raytrace:brute", &prepared, &settings);
        for name in ["rasterize:fixed", "rasterize:tiled", "rasterize:barycentric", "rasterize:scanline", "rasterize:bbox", "rasterize:naive", "rasterize:incremental"] {
            let s = if msaa > 1 { RenderSettings { msaa, ..settings.clone() } } else { settings.clone() };
            let img = render(name, &prepared, &s);
            let mut exact = 0; let mut close = 0; let mut maxrel = 0f32;
            for (a, b) in reference.iter().zip(&img) {
                if a == b { exact += 1; }
                let d = (*a - *b).abs(); let m = a.abs().max(b.abs());
                if d.x <= 1e-4 * m.x + 1e-6 && d.y <= 1e-4 * m.y + 1e-6 && d.z <= 1e-4 * m.z + 1e-6 { close += 1; } else { maxrel = maxrel.max((d / (m + 1e-6)).max_element()); }
            }
            let n = (w * h) as f64;
            eprintln!("{w}x{h} msaa {msaa} {name}: exact {:.3}% close {:.3}% (differ {}), max rel of differing {maxrel}", exact as f64 / n * 100.0, close as f64 / n * 100.0, (w*h) as usize - close);
        }
    }
}
