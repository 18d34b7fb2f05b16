//! `pinhole pixel`: a replayed pixel as JSON and as readable text. The
//! record comes from `render::replay_pixel`, which runs the renderer's own
//! code path with a recorder.

use crate::math::Vec3;
use crate::render::accel::intersect::Miss;
use crate::render::accel::csg::SurfaceRef;
use crate::render::inspect::pixel_record::{CsgABufferRecord, FragmentRecord, LightSample, PixelTrace, RayRecord, SampledLight, SampledLightKind};
use crate::render::PixelReplay;
use crate::scene::{PrimitiveKind, Scene, SurfaceHit};
use serde_json::{json, Value};
use std::fmt::Write;

fn v3(v: Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn kind(k: PrimitiveKind) -> &'static str {
    match k {
        PrimitiveKind::Triangle => "triangle",
        PrimitiveKind::Sphere => "sphere",
        PrimitiveKind::Csg => "csg",
    }
}

pub fn miss_reason(m: Miss) -> &'static str {
    match m {
        Miss::Parallel => "parallel",
        Miss::BackFace => "back face",
        Miss::Outside => "outside",
        Miss::Behind => "behind",
        Miss::Farther => "farther",
    }
}

/// The copy (from an `instances` list) a hit is on, if any.
fn instance_of<'s>(scene: &'s Scene, h: &SurfaceHit) -> Option<&'s crate::scene::InstanceInfo> {
    match h.kind {
        PrimitiveKind::Triangle => scene.instance_of_triangle(h.primitive),
        PrimitiveKind::Sphere | PrimitiveKind::Csg => None,
    }
}

/// The named part (a glTF node and mesh) a hit is on, if any.
fn part_of(scene: &Scene, h: &SurfaceHit) -> Option<String> {
    match h.kind {
        PrimitiveKind::Triangle => scene.part_name(h.primitive).map(str::to_string),
        PrimitiveKind::Sphere | PrimitiveKind::Csg => None,
    }
}

fn hit_json(scene: &Scene, h: &SurfaceHit) -> Value {
    json!({
        "kind": kind(h.kind), "primitive": h.primitive, "object": h.object,
        "object_name": scene.objects.get(h.object as usize).map(|o| o.name.clone()),
        "instance": instance_of(scene, h).map(|i| i.index),
        "instance_name": instance_of(scene, h).map(|i| scene.instance_name(i)),
        "part": part_of(scene, h),
        "material": scene.materials.get(h.material as usize).map(|m| m.name.clone()),
        "t": h.t, "position": v3(h.position), "barycentric": v3(h.barycentric),
        "geometric_normal": v3(h.geometric_normal), "shading_normal": v3(h.shading_normal),
        "uv": [h.uv.x, h.uv.y], "back_face": h.back_face,
    })
}

/// A rasterizer's eye ray that saw a CSG object: the A-buffer behind it.
fn abuffer_of<'t>(t: &'t PixelTrace, r: &RayRecord) -> Option<&'t CsgABufferRecord> {
    (r.depth == 0 && !r.shadow).then_some(())?;
    t.csg_abuffer_for(r.closest.as_ref()?)
}

fn ray_json(scene: &Scene, t: &PixelTrace, r: &RayRecord) -> Value {
    let tests: Vec<Value> = r
        .tests
        .iter()
        .map(|t| match t.outcome {
            Ok((tt, b1, b2)) => json!({"kind": kind(t.kind), "index": t.index, "result": "hit", "t": tt, "b1": b1, "b2": b2}),
            Err(m) => json!({"kind": kind(t.kind), "index": t.index, "result": miss_reason(m)}),
        })
        .collect();
    let mut out = json!({
        "origin": v3(r.ray.origin), "direction": v3(r.ray.dir), "t_max": finite_or_null(r.t_max),
        "depth": r.depth, "shadow": r.shadow, "nodes_visited": r.nodes_visited, "tests": tests,
        "tests_omitted": r.tests_omitted, "closest": r.closest.as_ref().map(|h| hit_json(scene, h)),
    });
    // Only a ray that hit a CSG object has the key; a rasterizer's eye ray
    // gives its A-buffer's account, with the sorted fragments.
    if let Some(a) = abuffer_of(t, r) {
        out["csg"] = csg_json(&a.explanation);
        out["csg"]["a_buffer"] = a
            .fragments
            .iter()
            .map(|f| {
                let (kind, primitive, b) = match f.surface {
                    SurfaceRef::Sphere(i) => ("sphere", i, None),
                    SurfaceRef::Triangle { index, b1, b2 } => ("triangle", index, Some(json!([1.0 - b1 - b2, b1, b2]))),
                };
                json!({
                    "t": f.t, "operand": a.operand(f), "boundary": if f.entering { "entry" } else { "exit" },
                    "kind": kind, "primitive": primitive, "barycentric": b, "screen_barycentric": f.screen_barycentric.map(v3),
                    "won": a.won(f),
                })
            })
            .collect();
        out["csg"]["text"] = json!(a.lines());
    } else if let Some(e) = r.closest.as_ref().and_then(|h| crate::render::accel::csg::explain_hit(scene, h, &r.ray, r.t_max)) {
        out["csg"] = csg_json(&e);
    }
    out
}

/// A CSG hit's intervals: each operand's, the combined ones, the winner.
fn csg_json(e: &crate::render::accel::csg::Explanation) -> Value {
    let list = |l: &[crate::render::accel::csg::Interval]| -> Vec<Value> { l.iter().map(|iv| json!([iv.enter.t, iv.exit.t])).collect() };
    json!({
        "op": e.op.name(),
        "operands": e.leaves.iter().map(|l| json!({"operand": l.path, "kind": l.kind, "intervals": list(&l.intervals)})).collect::<Vec<_>>(),
        "combined": list(&e.combined),
        "won": e.winner.map(|(b, entering)| json!({
            "t": b.t, "boundary": if entering { "entry" } else { "exit" },
            "operand": e.leaves.get(b.leaf as usize).map(|l| l.path.clone()), "normal_flipped": b.flipped,
        })),
        "text": e.lines(),
    })
}

fn finite_or_null(v: f32) -> Value {
    if v.is_finite() { json!(v) } else { Value::Null }
}

fn light_json(l: &LightSample) -> Value {
    let mut j = json!({
        "light": l.light, "w_i": v3(l.w_i), "distance": finite_or_null(l.distance), "incident": v3(l.incident),
        "cos_theta": l.cos_theta, "shadow_ray": l.shadow_ray.map(|(r, t)| json!({"origin": v3(r.origin), "direction": v3(r.dir), "t_max": t})),
        "blocked_by": l.blocker.map(|b| json!({"kind": kind(b.kind), "index": b.index, "t": b.t})),
        "bsdf": v3(l.bsdf), "contribution": v3(l.contribution),
    });
    // Only with shadow volumes, so other reports keep their exact form.
    if let Some(c) = l.volume_count {
        j["shadow_volume_count"] = json!(c);
    }
    j
}

/// What a sample of an area light or the environment is called in reports.
fn sampled_light_name(kind: SampledLightKind) -> String {
    match kind {
        SampledLightKind::Area(i) => format!("area light {i}"),
        SampledLightKind::Environment => "environment".into(),
        SampledLightKind::BsdfHit => "BSDF sample".into(),
    }
}

fn sampled_light_json(l: &SampledLight) -> Value {
    json!({
        "light": sampled_light_name(l.kind), "point": l.point.map(v3), "w_i": v3(l.w_i), "pdf": finite_or_null(l.pdf),
        "mis_weight": l.mis_weight, "visible": l.visible, "contribution": v3(l.contribution),
    })
}

fn fragment_json(f: &FragmentRecord) -> Value {
    json!({
        "kind": kind(f.kind), "primitive": f.primitive, "screen_barycentric": f.screen_barycentric.map(v3),
        "barycentric": v3(f.barycentric), "depth": f.depth, "stored_depth": finite_or_null(f.stored_depth),
        "depth_test": if f.passed_depth_test { "passed" } else { "failed" }, "shaded": f.shaded.map(v3), "msaa_sample": f.sample,
    })
}

fn sample_json(scene: &Scene, t: &PixelTrace) -> Value {
    let mut record = json!({
        "rays": t.rays.iter().map(|r| ray_json(scene, t, r)).collect::<Vec<_>>(),
        "lights": t.lights.iter().map(light_json).collect::<Vec<_>>(),
        "fragments": t.fragments.iter().map(fragment_json).collect::<Vec<_>>(),
    });
    if let Some(r) = &t.gl_readback {
        record["gl_readback"] = json!({
            "note": "GL readback, not a replay",
            "surface": r.surface.as_ref().map(|h| hit_json(scene, h)),
            "output": v3(r.output),
        });
    }
    // Area lights' and the environment's samples only where a scene has them.
    if !t.sampled_lights.is_empty() {
        record["sampled_lights"] = t.sampled_lights.iter().map(sampled_light_json).collect();
    }
    // Indirect light's records appear only where a mode made them.
    if !t.bounces.is_empty() {
        record["bounces"] = t
            .bounces
            .iter()
            .map(|b| {
                json!({
                    "depth": b.depth, "direction": v3(b.w_i), "pdf": b.pdf, "weight": v3(b.weight),
                    "throughput": v3(b.throughput), "survival": b.survival,
                })
            })
            .collect();
    }
    if !t.photon_estimates.is_empty() {
        record["photon_estimates"] = t.photon_estimates.iter().map(|l| v3(*l)).collect();
    }
    record
}

/// Most samples the JSON record lists in full: every sample's record can
/// hold hundreds of rays, and 65536 of them would be hundreds of megabytes.
pub const MAX_LISTED_SAMPLES: usize = 256;

/// The JSON record: `renderer`, `x`, `y`, `radiance` (the frame's value) and
/// the samples (the first `MAX_LISTED_SAMPLES`; `samples_omitted` counts the rest).
pub fn to_json(renderer: &str, scene: &Scene, x: u32, y: u32, replay: &PixelReplay) -> Value {
    let display = crate::image_io::display_pixel(replay.radiance, scene.render.exposure, true);
    let mut record = json!({
        "renderer": renderer, "x": x, "y": y, "radiance": v3(replay.radiance), "display_srgb8": display,
        "exposure": scene.render.exposure, "spp": replay.samples.len(),
        "samples": replay.samples.iter().take(MAX_LISTED_SAMPLES).map(|(o, t, v)| {
            let mut s = sample_json(scene, t);
            s["offset"] = json!([o.x, o.y]);
            s["radiance"] = v3(*v);
            s
        }).collect::<Vec<_>>(),
    });
    if replay.samples.len() > MAX_LISTED_SAMPLES {
        record["samples_omitted"] = json!(replay.samples.len() - MAX_LISTED_SAMPLES);
    }
    record
}

fn fmt3(v: Vec3) -> String {
    format!("({:.5}, {:.5}, {:.5})", v.x, v.y, v.z)
}

/// A readable account of the first sample, then the final value.
pub fn to_text(renderer: &str, scene: &Scene, x: u32, y: u32, replay: &PixelReplay) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "pixel ({x}, {y}) of {} by {renderer}, {} sample(s)", scene.name, replay.samples.len());
    if let Some((offset, t, value)) = replay.samples.first() {
        let _ = writeln!(s, "sample 1 at sub-pixel ({:.3}, {:.3})", offset.x, offset.y);
        for r in &t.rays {
            let what = if r.shadow { "shadow ray" } else if r.depth == 0 { "eye ray" } else { "secondary ray" };
            let indent = "  ".repeat(r.depth as usize + 1);
            let _ = writeln!(s, "{indent}{what}: origin {} direction {} t_max {:.5}", fmt3(r.ray.origin), fmt3(r.ray.dir), r.t_max);
            if !r.nodes_visited.is_empty() {
                let _ = writeln!(s, "{indent}  BVH nodes visited: {}", r.nodes_visited.len());
            }
            // A rasterizer's eye ray tests nothing: its visibility is the fragment history.
            let rasterized = r.depth == 0 && r.tests.is_empty() && r.tests_omitted == 0 && !t.fragments.is_empty();
            let hits = r.tests.iter().filter(|t| t.outcome.is_ok()).count();
            let mut reasons: std::collections::BTreeMap<&str, usize> = Default::default();
            for t in &r.tests {
                if let Err(m) = t.outcome {
                    *reasons.entry(miss_reason(m)).or_default() += 1;
                }
            }
            if !rasterized {
                let _ = writeln!(
                    s,
                    "{indent}  primitives tested: {} ({hits} hit{}{}){}",
                    r.tests.len() + r.tests_omitted,
                    if hits == 1 { "" } else { "s" },
                    reasons.iter().map(|(k, v)| format!(", {v} {k}")).collect::<String>(),
                    if r.tests_omitted > 0 { format!(", {} not kept", r.tests_omitted) } else { String::new() }
                );
            }
            for t in r.tests.iter().filter(|t| t.outcome.is_ok()) {
                if let Ok((tt, b1, b2)) = t.outcome {
                    let _ = writeln!(s, "{indent}    {} {} hit at t = {tt:.6}, b = ({:.4}, {b1:.4}, {b2:.4})", kind(t.kind), t.index, 1.0 - b1 - b2);
                }
            }
            match &r.closest {
                Some(h) => {
                    let mat = scene.materials.get(h.material as usize).map(|m| m.name.as_str()).unwrap_or("?");
                    let mut instance = instance_of(scene, h).map(|i| format!(", {}", scene.instance_name(i))).unwrap_or_default();
                    if let Some(part) = part_of(scene, h) {
                        instance += &format!(", {part}");
                    }
                    let _ = writeln!(
                        s,
                        "{indent}  closest: {} {} (object {}{instance}, material {mat}) at t = {:.6}\n{indent}    P = {}  n = {}  b = {}",
                        kind(h.kind),
                        h.primitive,
                        h.object,
                        h.t,
                        fmt3(h.position),
                        fmt3(h.shading_normal),
                        fmt3(h.barycentric)
                    );
                    if let Some(a) = abuffer_of(t, r) {
                        let _ = writeln!(s, "{indent}  csg A-buffer at this sample (scan-converted operand fragments):");
                        for line in a.lines() {
                            let _ = writeln!(s, "{indent}    {line}");
                        }
                    } else if let Some(e) = crate::render::accel::csg::explain_hit(scene, h, &r.ray, r.t_max) {
                        let _ = writeln!(s, "{indent}  csg intervals along the ray (t from its origin):");
                        for line in e.lines() {
                            let _ = writeln!(s, "{indent}    {line}");
                        }
                    }
                }
                None if r.shadow => {}
                None => {
                    let _ = writeln!(s, "{indent}  closest: nothing (background)");
                }
            }
        }
        if let Some(r) = &t.gl_readback {
            let _ = writeln!(s, "  GL readback, not a replay (the render targets at this pixel after the pass):");
            match &r.surface {
                Some(h) => {
                    let _ = writeln!(
                        s,
                        "    {} {} (object {}, material {}): position {}, shading normal {}, geometric normal {}, barycentric {}, uv ({:.5}, {:.5})",
                        kind(h.kind),
                        h.primitive,
                        h.object,
                        h.material,
                        fmt3(h.position),
                        fmt3(h.shading_normal),
                        fmt3(h.geometric_normal),
                        fmt3(h.barycentric),
                        h.uv.x,
                        h.uv.y
                    );
                }
                None => {
                    let _ = writeln!(s, "    no fragment drawn (background)");
                }
            }
            let _ = writeln!(s, "    output {}", fmt3(r.output));
        }
        if !t.fragments.is_empty() {
            let _ = writeln!(s, "  fragment history ({} fragment(s) in draw order; z = view depth):", t.fragments.len());
        }
        for (n, f) in t.fragments.iter().enumerate() {
            let sample = f.sample.map(|k| format!(" [MSAA sample {k}]")).unwrap_or_default();
            let _ = writeln!(
                s,
                "    {}. {} {}{sample}: z {:.6} vs stored {:.6}: depth test {}",
                n + 1,
                kind(f.kind),
                f.primitive,
                f.depth,
                f.stored_depth,
                if f.passed_depth_test { "passed" } else { "failed" },
            );
            let screen = f.screen_barycentric.map(|w| format!("2D weights {}, ", fmt3(w))).unwrap_or_default();
            let shaded = f.shaded.map(|c| format!(", shaded {}", fmt3(c))).unwrap_or_default();
            let _ = writeln!(s, "       {screen}perspective-correct b {}{shaded}", fmt3(f.barycentric));
        }
        for l in &t.lights {
            let blocked = match l.blocker {
                _ if l.volume_count.is_some_and(|c| c != 0) => format!("in shadow: shadow volume count {}", l.volume_count.unwrap_or(0)),
                _ if l.volume_count.is_some() => "visible: shadow volume count 0".into(),
                Some(b) => format!("blocked by {} {} at t = {:.5}", kind(b.kind), b.index, b.t),
                None if l.shadow_ray.is_some() => "visible".into(),
                None => "no shadow ray".into(),
            };
            let _ = writeln!(
                s,
                "  light {}: w_i {} d = {:.4}, L_i {} cos {:.4}, {blocked}, f {} -> {}",
                l.light,
                fmt3(l.w_i),
                l.distance,
                fmt3(l.incident),
                l.cos_theta,
                fmt3(l.bsdf),
                fmt3(l.contribution)
            );
        }
        for l in &t.sampled_lights {
            let point = l.point.map(|p| format!(" at {}", fmt3(p))).unwrap_or_default();
            let seen = if l.visible { "visible" } else { "blocked" };
            let _ = writeln!(
                s,
                "  {}{point}: w_i {} pdf {:.4}, MIS weight {:.4}, {seen} -> {}",
                sampled_light_name(l.kind),
                fmt3(l.w_i),
                l.pdf,
                l.mis_weight,
                fmt3(l.contribution)
            );
        }
        if !t.bounces.is_empty() {
            let _ = writeln!(s, "  path ({} sampled bounce(s)):", t.bounces.len());
        }
        for b in &t.bounces {
            let roulette = match b.survival {
                p if p >= 1.0 => String::new(),
                p if p > 0.0 => format!(", roulette: survived with p = {p:.3}"),
                _ => ", roulette: path ended".into(),
            };
            let _ = writeln!(
                s,
                "    depth {}: w_i {} pdf {:.4}, weight f cos / pdf {}, throughput {}{roulette}",
                b.depth,
                fmt3(b.w_i),
                b.pdf,
                fmt3(b.weight),
                fmt3(b.throughput)
            );
        }
        for l in &t.photon_estimates {
            let _ = writeln!(s, "  photon map estimate {}", fmt3(*l));
        }
        let _ = writeln!(s, "  sample radiance {}", fmt3(*value));
    }
    let d = crate::image_io::display_pixel(replay.radiance, scene.render.exposure, true);
    let _ = writeln!(s, "final radiance {} -> displayed sRGB {:?}", fmt3(replay.radiance), d);
    s
}
