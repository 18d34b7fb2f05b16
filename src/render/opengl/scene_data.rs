//! The scene as GL buffers take it: one vertex per triangle corner (no
//! index buffer, so the face normal and material can be per triangle),
//! runs of single- and two-sided triangles in scene order, spheres, and
//! the materials and lights the fragment shaders read.

use crate::scene::{Light, Scene};

/// Floats per vertex: position, shading normal, face normal, material
/// bits, uv, tangent and handedness (zero without a normal map).
pub const VERTEX_FLOATS: usize = 16;

/// The vertex data of every triangle, in scene order.
pub struct Geometry {
    pub vertices: Vec<f32>,
    /// Consecutive triangles with the same sidedness and material: (first triangle, count, two-sided, material).
    pub runs: Vec<Run>,
    /// Per sphere: (centre, radius), (material bits, object bits, 0, 0).
    pub spheres: Vec<f32>,
}

/// Consecutive triangles drawn with one call: first, count, two-sided, material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Run {
    pub first: u32,
    pub count: u32,
    pub two_sided: bool,
    pub material: u32,
}

/// Appends triangle `i`'s three vertices (position, normal, face normal,
/// material, uv, tangent) and counts it into `runs`, its draws of one
/// sidedness and material.
fn push_triangle(vertices: &mut Vec<f32>, runs: &mut Vec<Run>, i: u32, t: &crate::scene::Triangle, tangents: [glam::Vec4; 3]) {
    let face = t.geometric_normal();
    for k in 0..3 {
        vertices.extend_from_slice(&t.v[k].to_array());
        vertices.extend_from_slice(&t.n[k].to_array());
        vertices.extend_from_slice(&face.to_array());
        vertices.push(f32::from_bits(t.material));
        vertices.extend_from_slice(&t.uv[k].to_array());
        vertices.extend_from_slice(&tangents[k].to_array());
    }
    match runs.last_mut() {
        Some(run) if run.two_sided == t.two_sided && run.material == t.material => run.count += 1,
        _ => runs.push(Run { first: i, count: 1, two_sided: t.two_sided, material: t.material }),
    }
}

/// The scene's flattened triangles as vertex data and draw runs.
pub fn geometry(scene: &Scene) -> Geometry {
    let mut vertices = Vec::with_capacity(scene.triangles.len() * 3 * VERTEX_FLOATS);
    let mut runs: Vec<Run> = Vec::new();
    for (i, t) in scene.triangles.iter().enumerate() {
        // The handedness of the first corner on all three (`tangent_at`).
        let tangents = scene.tangents.get(i).map_or([glam::Vec4::ZERO; 3], |c| c.map(|ck| ck.truncate().extend(c[0].w)));
        push_triangle(&mut vertices, &mut runs, i as u32, &t, tangents);
    }
    let mut spheres = Vec::with_capacity(scene.spheres.len() * 8);
    for s in &scene.spheres {
        spheres.extend_from_slice(&[s.center.x, s.center.y, s.center.z, s.radius, f32::from_bits(s.material), f32::from_bits(s.object), 0.0, 0.0]);
    }
    Geometry { vertices, runs, spheres }
}

/// A fingerprint of what `geometry` reads, to know when the uploaded
/// buffers are stale (a scene loaded or edited since).
pub fn fingerprint(scene: &Scene) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325 ^ scene.triangles.len() as u64 ^ ((scene.spheres.len() as u64) << 32);
    let mut mix = |x: u32| h = (h ^ x as u64).wrapping_mul(0x0000_0100_0000_01b3).rotate_left(5);
    for (i, t) in scene.triangles.iter().enumerate() {
        for k in 0..3 {
            for v in [t.v[k], t.n[k]] {
                mix(v.x.to_bits());
                mix(v.y.to_bits());
                mix(v.z.to_bits());
            }
            mix(t.uv[k].x.to_bits());
            mix(t.uv[k].y.to_bits());
            if let Some(c) = scene.tangents.get(i) {
                for x in c[k].to_array() {
                    mix(x.to_bits());
                }
            }
        }
        mix(t.material | (t.two_sided as u32) << 31);
    }
    for s in &scene.spheres {
        for x in [s.center.x, s.center.y, s.center.z, s.radius] {
            mix(x.to_bits());
        }
        mix(s.material);
        mix(s.object);
    }
    h
}

/// Per material: (k_L, glossy model), (k_G, sharpness), (k_M, roughness),
/// (eta, Fresnel term), (k, diffuse model), (diffuse parameter, emission),
/// (Ward's alpha u and alpha v, 0, 0);
/// the models and the Fresnel term as `lighting::model_lane`,
/// `diffuse_lane` and `fresnel_lane` code them.
pub const MATERIAL_FLOATS: usize = 28;

pub fn materials(scene: &Scene) -> Vec<f32> {
    let mut out = Vec::with_capacity(scene.materials.len().max(1) * MATERIAL_FLOATS);
    for m in &scene.materials {
        let model = crate::render::transport::lighting::model_lane(m.glossy_model);
        out.extend_from_slice(&[m.lambertian.x, m.lambertian.y, m.lambertian.z, model, m.glossy.x, m.glossy.y, m.glossy.z, m.sharpness]);
        out.extend_from_slice(&[m.mirror.x, m.mirror.y, m.mirror.z, m.roughness]);
        let (eta, k) = match m.fresnel {
            crate::scene::material::Fresnel::Conductor { eta, k } => (eta, k),
            _ => (crate::math::Vec3::ZERO, crate::math::Vec3::ZERO),
        };
        let fresnel = crate::render::transport::lighting::fresnel_lane(m.fresnel);
        let diffuse = crate::render::transport::lighting::diffuse_lane(m.diffuse_model);
        out.extend_from_slice(&[eta.x, eta.y, eta.z, fresnel, k.x, k.y, k.z, diffuse]);
        out.extend_from_slice(&[m.diffuse_model.parameter(), m.emission.x, m.emission.y, m.emission.z]);
        out.extend_from_slice(&[m.roughness_uv.x, m.roughness_uv.y, 0.0, 0.0]);
    }
    if out.is_empty() {
        out.resize(MATERIAL_FLOATS, 0.0);
    }
    out
}

/// Per light: (position or direction, 0 = point | 1 = directional),
/// (power or irradiance, first shadow-map face or -1). `first_faces`: per
/// light, with `--shadows map`.
pub fn lights(scene: &Scene, first_faces: &[i32]) -> Vec<f32> {
    let mut out = Vec::with_capacity(scene.lights.len().max(1) * 8);
    for (i, l) in scene.lights.iter().enumerate() {
        let face = first_faces.get(i).copied().unwrap_or(-1) as f32;
        match *l {
            Light::Point { position, power } => out.extend_from_slice(&[position.x, position.y, position.z, 0.0, power.x, power.y, power.z, face]),
            Light::Directional { direction, irradiance } => {
                out.extend_from_slice(&[direction.x, direction.y, direction.z, 1.0, irradiance.x, irradiance.y, irradiance.z, face])
            }
        }
    }
    if out.is_empty() {
        out.resize(8, 0.0);
    }
    out
}

/// Points per light sample of the fixed pattern that lights area lights
/// (`area_lights`), and the most points in all.
pub const AREA_POINTS_PER_SAMPLE: u32 = 64;
pub const MAX_AREA_POINTS: u32 = 4096;

/// The area lights as the fragment shaders light them, for a pass: per
/// area light (`Scene::emitters.lights`) two vec4, (centre, first face of
/// its shadow cube map or -1) and (radius, first point, point count, 0);
/// and the points of a fixed pattern over the emitters, three vec4 each,
/// (position, both sides emit), (unit normal, 0), (radiance over the
/// point's area density and the point count, 0), grouped by light.
///
/// The pattern: `AREA_POINTS_PER_SAMPLE * light_samples` points (at most
/// `MAX_AREA_POINTS`), each emitter chosen in proportion to its power by a
/// stratified number and the point placed on it by a 2D low-discrepancy
/// sequence (R2), the whole pattern shifted per pass by a hash of (pass,
/// seed), so the passes of a frame sample different points. It is the
/// same for every pixel of the pass: GL has no per-pixel stream of random
/// numbers matching the CPU renderers'.
pub fn area_lights(scene: &Scene, first_faces: &[i32], light_samples: u32, pass: u32, seed: u64) -> (Vec<f32>, Vec<f32>) {
    let emitters = &scene.emitters;
    let count = light_samples.saturating_mul(AREA_POINTS_PER_SAMPLE).clamp(1, MAX_AREA_POINTS);
    let shift = crate::render::transport::sampling::hashed_unit_pair(0xA4EA_0000_0000 | pass as u64, seed);
    let shift_choose = crate::render::transport::sampling::hashed_unit_pair(0xA4EA_0001_0000_0000 | pass as u64, seed).x;
    // R2: the plastic number's powers as the two axes' steps.
    const A1: f64 = 0.754_877_666_246_692_7;
    const A2: f64 = 0.569_840_290_998_053_3;
    let mut points: Vec<(u32, [f32; 12])> = Vec::with_capacity(count as usize);
    for k in 0..count {
        let u_choose = ((k as f32 + shift_choose) / count as f32).min(0.999_999_94);
        let u = crate::math::Vec2::new(((k as f64 * A1 + shift.x as f64).fract()) as f32, ((k as f64 * A2 + shift.y as f64).fract()) as f32);
        let Some((p, n, two_sided, light, value)) = emitters.area_sample(scene, u_choose, u) else { continue };
        let v = value / count as f32;
        points.push((light, [p.x, p.y, p.z, two_sided as u32 as f32, n.x, n.y, n.z, 0.0, v.x, v.y, v.z, 0.0]));
    }
    points.sort_by_key(|(light, _)| *light);
    let mut lights = Vec::with_capacity(emitters.lights.len().max(1) * 8);
    for (i, l) in emitters.lights.iter().enumerate() {
        let first = points.partition_point(|(light, _)| (*light as usize) < i);
        let end = points.partition_point(|(light, _)| (*light as usize) <= i);
        let face = first_faces.get(i).copied().unwrap_or(-1) as f32;
        lights.extend_from_slice(&[l.centre.x, l.centre.y, l.centre.z, face, l.radius, first as f32, (end - first) as f32, 0.0]);
    }
    if lights.is_empty() {
        lights.resize(8, 0.0);
    }
    let mut flat: Vec<f32> = points.iter().flat_map(|(_, v)| *v).collect();
    if flat.is_empty() {
        flat.resize(12, 0.0);
    }
    (lights, flat)
}

/// The `[environment]` as the fragment shaders light with it, for a pass:
/// `AREA_POINTS_PER_SAMPLE * light_samples` directions (at most
/// `MAX_AREA_POINTS`) importance-sampled from the map's distribution
/// (`EnvironmentLight::sample`) at an R2 low-discrepancy sequence shifted
/// per pass by a hash of (pass, seed); two vec4 each, (unit direction, 0)
/// and (radiance over the direction's density and the count, 0). Empty
/// without an environment light.
pub fn environment_light(scene: &Scene, light_samples: u32, pass: u32, seed: u64) -> Vec<f32> {
    let Some(light) = scene.environment.as_ref().and_then(|e| e.light.as_deref()) else { return Vec::new() };
    let count = light_samples.saturating_mul(AREA_POINTS_PER_SAMPLE).clamp(1, MAX_AREA_POINTS);
    let shift = crate::render::transport::sampling::hashed_unit_pair(0xE4F1_0000_0000 | pass as u64, seed);
    const A1: f64 = 0.754_877_666_246_692_7;
    const A2: f64 = 0.569_840_290_998_053_3;
    let mut out = Vec::with_capacity(count as usize * 8);
    for k in 0..count {
        let u = crate::math::Vec2::new(((k as f64 * A1 + shift.x as f64).fract()) as f32, ((k as f64 * A2 + shift.y as f64).fract()) as f32);
        let Some((w, pdf)) = light.sample(u) else { continue };
        let v = scene.miss_radiance(w) / (pdf * count as f32);
        if !v.is_finite() || v == crate::math::Vec3::ZERO {
            continue;
        }
        out.extend_from_slice(&[w.x, w.y, w.z, 0.0, v.x, v.y, v.z, 0.0]);
    }
    out
}

/// The unit cube's 12 triangles as 36 corners, for the spheres' bounding boxes.
pub fn cube_corners() -> Vec<f32> {
    const FACES: [[usize; 4]; 6] = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    let corner = |i: usize| [if i & 1 != 0 { 1.0 } else { -1.0 }, if i & 2 != 0 { 1.0 } else { -1.0 }, if i & 4 != 0 { 1.0 } else { -1.0 }];
    let mut out = Vec::with_capacity(36 * 3);
    for f in FACES {
        for k in [0, 1, 2, 0, 2, 3] {
            out.extend_from_slice(&corner(f[k]));
        }
    }
    out
}

/// The two-level layer's shared meshes (`scene::instanced`), each uploaded
/// once in the vertex layout of `geometry` (no tangent frames: the layer
/// keeps none), one after the other.
pub struct LayerGeometry {
    pub vertices: Vec<f32>,
    /// Per mesh: its first triangle in `vertices` and its runs (first
    /// triangle counted within the mesh).
    pub meshes: Vec<(u32, Vec<Run>)>,
}

pub fn layer_geometry(layer: &crate::scene::instanced::InstanceLayer) -> LayerGeometry {
    let total: usize = layer.meshes.iter().map(|m| m.len()).sum();
    let mut vertices = Vec::with_capacity(total * 3 * VERTEX_FLOATS);
    let mut meshes = Vec::with_capacity(layer.meshes.len());
    let mut first = 0u32;
    for mesh in &layer.meshes {
        let mut runs: Vec<Run> = Vec::new();
        for (i, t) in mesh.iter().enumerate() {
            push_triangle(&mut vertices, &mut runs, i as u32, t, [glam::Vec4::ZERO; 3]);
        }
        meshes.push((first, runs));
        first += mesh.len() as u32;
    }
    LayerGeometry { vertices, meshes }
}

/// Floats per copy in the instance buffer: the placement's matrix (four
/// columns of three), its normal matrix (three columns), then as bits: the
/// copy's first virtual triangle less its mesh's first (so that adding the
/// vertex's triangle number gives the virtual index), its material or
/// `u32::MAX`, and 1 when the placement mirrors.
pub const INSTANCE_FLOATS: usize = 24;

/// A group of copies drawn with one instanced call per run: same mesh,
/// same material override, same mirroring.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct CopyGroup {
    pub mesh: u32,
    pub material: Option<u32>,
    pub flips: bool,
}

/// The copies `keep` lets through (by index), sorted by `CopyGroup` and
/// within one by index, as instance-buffer floats; and per group its
/// first instance and count.
pub fn layer_instances(layer: &crate::scene::instanced::InstanceLayer, meshes: &[(u32, Vec<Run>)], keep: impl Fn(usize) -> bool) -> (Vec<f32>, Vec<(CopyGroup, u32, u32)>) {
    let mut order: Vec<(CopyGroup, usize)> = Vec::new();
    for (k, inst) in layer.instances.iter().enumerate() {
        if !keep(k) {
            continue;
        }
        let flips = inst.placement.matrix().determinant() < 0.0;
        order.push((CopyGroup { mesh: inst.mesh, material: inst.material, flips }, k));
    }
    // Stable within a group: copies keep their index order (the id order).
    order.sort_by_key(|(g, k)| (*g, *k));
    let mut floats = Vec::with_capacity(order.len() * INSTANCE_FLOATS);
    let mut groups: Vec<(CopyGroup, u32, u32)> = Vec::new();
    for (i, (group, k)) in order.iter().enumerate() {
        let inst = &layer.instances[*k];
        let m = inst.placement.matrix();
        // As `Placement::new` makes it.
        let n = glam::Mat3::from_mat4(m).inverse().transpose();
        for c in [m.x_axis, m.y_axis, m.z_axis, m.w_axis] {
            floats.extend_from_slice(&c.truncate().to_array());
        }
        floats.extend_from_slice(&n.to_cols_array());
        let mesh_first = meshes.get(inst.mesh as usize).map_or(0, |m| m.0);
        floats.push(f32::from_bits(inst.base.wrapping_sub(mesh_first)));
        floats.push(f32::from_bits(inst.material.unwrap_or(u32::MAX)));
        floats.push(f32::from_bits(group.flips as u32));
        match groups.last_mut() {
            Some(g) if g.0 == *group => g.2 += 1,
            _ => groups.push((*group, i as u32, 1)),
        }
    }
    (floats, groups)
}
