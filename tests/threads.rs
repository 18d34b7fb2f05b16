//! The image never depends on the thread count: work is split by rows and
//! tiles, never by a shared counter, so 1 thread and N threads agree bit for bit.

mod common;
use common::*;
use pinhole::render::{renderer_names, PreparedScene, RenderSettings};

#[test]
fn one_thread_equals_all_threads() {
    for scene_name in pinhole::scene::builtin::names() {
        let scene = builtin(scene_name);
        let mut settings = RenderSettings::for_scene(&scene);
        settings.width = 96;
        settings.height = 60;
        settings.spp = 2;
        let prepared = PreparedScene::new(scene);
        for r in renderer_names() {
            let one = render_with_threads(1, r, &prepared, &settings);
            let many = render_with_threads(4, r, &prepared, &settings);
            assert!(one == many, "{r} on {scene_name}: 1 thread and 4 threads differ");
        }
    }
}
