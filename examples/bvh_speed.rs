//! Times the BVH: build and primary rays on benchmark scenes, the figures
//! that are compared with Embree 3 (`tools/peers/embree_primary.py`).
//!
//!     cargo run --release --example bvh_speed -- ../shared/bench/stanford-bunny.toml ...
//!
//! Prints, per scene: best-of-N build ms, and Mrays/s for bare closest-hit
//! queries (eye ray + traversal, like Embree's rtcIntersect1 loop), the same
//! rays as 8x8 packets (what `render_pass` traces, like rtcIntersect8), the depth
//! view (`render_pass`, primary rays only) and the shaded frame with shadow rays.

use pinhole::render::accel::bvh::{Bvh, BvhQuery};
use pinhole::render::raytrace::bvh_renderer::BvhRayTracer;
use pinhole::render::accel::packet;
use pinhole::render::accel::packet::{Packet, TILE_H, TILE_W};
use pinhole::render::inspect::pixel_record::NoRecord;
use pinhole::render::transport::sampling::{cosine_hemisphere, from_local, SampleRng};
use pinhole::render::inspect::debug::View;
use pinhole::render::{PassJob, PreparedScene, RayCounts, RenderSettings, Renderer, SceneQuery, ShadowMode};
use pinhole::math::{Radiance, Vec2};
use rayon::prelude::*;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

fn best_of<F: FnMut()>(n: usize, mut f: F) -> f64 {
    (0..n)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() {
        args = vec!["/work/shared/bench/stanford-bunny.toml".into(), "/work/shared/bench/teapot.toml".into()];
    }
    let reps = 7;
    for path in args {
        let scene = pinhole::scene::file::load_scene_file(Path::new(&path)).expect("scene");
        let prepared = PreparedScene::new(scene);
        let build = best_of(reps, || {
            std::hint::black_box(Bvh::build(&prepared.scene, &prepared.edges));
        });
        let (w, h) = (prepared.scene.render.width, prepared.scene.render.height);
        let view = prepared.scene.camera.view(w, h);
        let rays = (w * h) as f64;

        // Bare closest-hit queries, rows in parallel.
        let query = BvhQuery::new(&prepared);
        let mut hits = 0u64;
        let bare = best_of(reps, || {
            hits = (0..h)
                .into_par_iter()
                .map(|y| {
                    let mut counts = RayCounts::default();
                    let mut n = 0u64;
                    for x in 0..w {
                        let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                        let ray = view.eye_ray(px, py);
                        n += query.closest(&ray, view.far_t(px, py), false, &mut counts, &mut NoRecord).is_some() as u64;
                    }
                    n
                })
                .sum();
        });

        // The same rays as packets of TILE_W x TILE_H pixels (what render_pass does).
        let mut packet_hits = 0u64;
        let packets = best_of(reps, || {
            packet_hits = (0..h.div_ceil(TILE_H as u32))
                .into_par_iter()
                .map(|band| {
                    let mut counts = RayCounts::default();
                    let mut pk = Packet::new();
                    let mut n = 0u64;
                    for x0 in (0..w).step_by(TILE_W) {
                        let mut valid = 0u64;
                        for i in 0..TILE_W * TILE_H {
                            let (tx, ty) = packet::lane_xy(i);
                            let (x, y) = (x0 + tx as u32, band * TILE_H as u32 + ty as u32);
                            if x < w && y < h {
                                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                                pk.rays[i] = view.eye_ray(px, py);
                                pk.t_max[i] = view.far_t(px, py);
                                valid |= 1 << i;
                            }
                        }
                        query.closest_packet(&mut pk, valid, &mut counts);
                        n += pk.hit_count(valid) as u64;
                    }
                    n
                })
                .sum();
        });

        // Incoherent rays: from each primary hit one cosine-sampled direction,
        // the first bounce of a path tracer; traced one at a time, one thread
        // (what `--gi path` spends most of its walk time on).
        let mut bounce_rays = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                let ray = view.eye_ray(px, py);
                if let Some(hit) = query.closest(&ray, view.far_t(px, py), false, &mut RayCounts::default(), &mut NoRecord) {
                    let mut rng = SampleRng::for_pixel(x + y * w, 0, 0);
                    let dir = from_local(cosine_hemisphere(rng.next_2d()), hit.geometric_normal);
                    bounce_rays.push(hit.spawn_ray_front(dir, 1e-4));
                }
            }
        }
        // For a peer's walk over the same rays: PINHOLE_DUMP_RAYS=DIR writes
        // DIR/NAME.tris (9 f32 per triangle) and DIR/NAME.rays (origin and
        // direction, 6 f32 per ray).
        if let Ok(dir) = std::env::var("PINHOLE_DUMP_RAYS") {
            let stem = Path::new(&path).file_stem().unwrap().to_string_lossy().to_string();
            let mut tris = Vec::new();
            for t in prepared.scene.triangles.iter() {
                for v in t.v {
                    tris.extend(v.to_array());
                }
            }
            let rays: Vec<f32> = bounce_rays.iter().flat_map(|r| r.origin.to_array().into_iter().chain(r.dir.to_array())).collect();
            let bytes = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
            std::fs::write(format!("{dir}/{stem}.tris"), bytes(&tris)).expect("write tris");
            std::fs::write(format!("{dir}/{stem}.rays"), bytes(&rays)).expect("write rays");
        }
        let mut bounce_hits = 0u64;
        let mut bounce_counts = RayCounts::default();
        let bounce = best_of(reps, || {
            bounce_counts = RayCounts::default();
            bounce_hits = bounce_rays.iter().map(|r| query.closest(r, f32::INFINITY, false, &mut bounce_counts, &mut NoRecord).is_some() as u64).sum();
        });
        // The same rays as a path frame's pool traces them: the walk and the
        // winning triangle's id and weights, its record built later eight at
        // a time (`closest_for_batch`). What a peer's bare walk compares with.
        let mut walk_hits = 0u64;
        let walk = best_of(reps, || {
            let mut counts = RayCounts::default();
            walk_hits = bounce_rays.iter().map(|r| query.closest_for_batch(r, f32::INFINITY, false, &mut counts).is_some() as u64).sum();
        });
        assert_eq!(walk_hits, bounce_hits, "the batch query finds what the closest-hit query finds");
        // The same rays in packets of consecutive ones, walked together
        // until few of a packet are in an entry, then alone (`closest_hybrid`
        // with the sizes path frames use). PINHOLE_HYBRID_SWEEP=1
        // prints other packet sizes and switch points too.
        let hybrid_time = |rays: &[pinhole::math::Ray], size: usize, switch: u32| {
            let mut pk = Packet::new();
            let mut hits = 0u64;
            let t = best_of(reps, || {
                let mut counts = RayCounts::default();
                hits = 0;
                for chunk in rays.chunks(size) {
                    for (k, r) in chunk.iter().enumerate() {
                        pk.rays[k] = *r;
                        pk.t_max[k] = f32::INFINITY;
                    }
                    let valid = u64::MAX >> (64 - chunk.len());
                    query.closest_hybrid(&mut pk, valid, switch, &mut counts);
                    hits += pk.hit_count(valid) as u64;
                }
            });
            assert_eq!(hits, bounce_hits, "the hybrid packets find what single rays find");
            t
        };
        let hybrid = hybrid_time(&bounce_rays, packet::PACKET_RAYS, packet::HYBRID_ALONE);
        if std::env::var("PINHOLE_HYBRID_SWEEP").is_ok() {
            for size in [8usize, 16, 32, 64] {
                for switch in [0u32, 1, 2, 4, 8, 12, 16] {
                    eprintln!("hybrid size={size} switch={switch} ns_per_ray={:.1}", hybrid_time(&bounce_rays, size, switch) * 1e9 / bounce_rays.len() as f64);
                }
            }
        }

        let cancel = AtomicBool::new(false);
        let mut out = vec![Radiance::ZERO; (w * h) as usize];
        let mut pass = |view_kind: View, shadows: ShadowMode| {
            let settings = RenderSettings { view: view_kind, shadows, ..RenderSettings::for_scene(&prepared.scene) };
            let mut counts = RayCounts::default();
            let t = best_of(reps, || {
                let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: Vec2::splat(0.5), sample: 0, photons: None, active: None, rows: 0..h, cancel: &cancel, keep_non_finite: false };
                counts = BvhRayTracer.render_pass(&job, &mut out);
            });
            (t, counts)
        };
        let (depth, dc) = pass(View::Depth, ShadowMode::None);
        let (shaded, sc) = pass(View::Shaded, ShadowMode::Ray);
        println!(
            "pinhole {} tris={} {}x{} threads={} nodes={} depth={} build_ms={:.1} bare_ms={:.1} bare_mrays_per_s={:.2} hits={} packet_ms={:.1} packet_mrays_per_s={:.2} packet_hits={} \
             depth_view_ms={:.1} depth_view_mrays_per_s={:.2} nodes_per_ray={:.1} tests_per_ray={:.1} \
             bounce_rays={} bounce_ns_per_ray_1_thread={:.1} bounce_walk_ns_per_ray_1_thread={:.1} bounce_hybrid_ns_per_ray_1_thread={:.1} bounce_hits={} bounce_nodes_per_ray={:.2} bounce_tests_per_ray={:.2} shaded_ms={:.1} shaded_mrays_per_s={:.2} (primary+shadow)",
            Path::new(&path).file_stem().unwrap().to_string_lossy(),
            prepared.edges.len(),
            w,
            h,
            rayon::current_num_threads(),
            prepared.bvh.node_count(),
            prepared.bvh.depth(),
            build * 1e3,
            bare * 1e3,
            rays / bare / 1e6,
            hits,
            packets * 1e3,
            rays / packets / 1e6,
            packet_hits,
            depth * 1e3,
            rays / depth / 1e6,
            dc.nodes as f64 / rays,
            dc.tests as f64 / rays,
            bounce_rays.len(),
            bounce * 1e9 / bounce_rays.len() as f64,
            walk * 1e9 / bounce_rays.len() as f64,
            hybrid * 1e9 / bounce_rays.len() as f64,
            bounce_hits,
            bounce_counts.nodes as f64 / bounce_rays.len() as f64,
            bounce_counts.tests as f64 / bounce_rays.len() as f64,
            shaded * 1e3,
            (sc.primary + sc.shadow) as f64 / shaded / 1e6,
        );
    }
}
