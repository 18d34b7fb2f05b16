//! glTF 2.0 scenes (`.gltf` with embedded or external buffers, `.glb`),
//! parsed by the `gltf` crate and turned into pinhole's scene: the default
//! scene's node hierarchy with each node's world transform, a mesh used by
//! several nodes stored once in the instance layer, cameras, punctual
//! lights and metallic-roughness materials (`materials`).
//!
//! Photometric lights become radiometric ones at 683 lm/W (the luminous
//! efficacy of 555 nm light, which defines the candela): a point light of
//! `I` candela has power `4 pi I / 683` W, a directional light of `E` lux
//! gives irradiance `E / 683` W/m^2, each times its colour.

pub mod accessor;
pub mod materials;
pub mod source;

use crate::input::{InputKind, MAX_COORDINATE, MAX_LIGHT};
use crate::math::{Vec2, Vec3};
use crate::scene::assets::read_asset;
use crate::scene::instanced::{Layered, MeshCopy};
use crate::scene::placement::Placement;
use crate::scene::{Camera, Fov, Light, NamedPart, ObjectInfo, PartOf, Scene, Triangle};
use glam::{Mat4, Vec4};
use std::path::Path;
use std::sync::Arc;

/// Lumens per watt: photometric to radiometric units.
pub const LUMENS_PER_WATT: f32 = 683.0;

/// The extensions pinhole reads; a file that requires another is refused.
pub const SUPPORTED_EXTENSIONS: &[&str] = &["KHR_lights_punctual", "KHR_materials_emissive_strength"];

/// One of the glTF's cameras, placed.
#[derive(Clone, Debug)]
pub struct NamedCamera {
    pub name: String,
    pub camera: Camera,
    /// Width over height, when the file gives it.
    pub aspect: Option<f32>,
}

/// What a glTF adds besides its triangles and materials.
#[derive(Default)]
pub struct GltfParts {
    pub cameras: Vec<NamedCamera>,
    pub lights: Vec<Light>,
    /// What the file has that pinhole does not draw, one entry each.
    pub ignored: Vec<String>,
}

/// Whether `path` names a glTF file by its extension.
pub fn is_gltf(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// Adds the glTF at `path` to `scene` as object `object`, every node placed
/// by `placement` after its own transform: triangles of meshes used once
/// flattened, meshes used by several nodes into `layered`. Materials are
/// appended to the scene's. Errors are one sentence naming the file.
pub fn add_gltf(scene: &mut Scene, path: &Path, placement: &Placement, object: u32, layered: &mut Layered) -> Result<GltfParts, String> {
    let name = path.display().to_string();
    add_gltf_unnamed(scene, path, placement, object, layered).map_err(|e| crate::input::bounded_message(&format!("{name}: {e}")))
}

fn add_gltf_unnamed(scene: &mut Scene, path: &Path, placement: &Placement, object: u32, layered: &mut Layered) -> Result<GltfParts, String> {
    let bytes = read_asset(path, InputKind::Mesh).map_err(|e| format!("cannot read glTF: {e}"))?;
    let folder = path.parent().unwrap_or(Path::new("."));
    refuse_required_extensions(&bytes)?;
    let gltf::Gltf { document: doc, mut blob } = gltf::Gltf::from_slice_without_validation(&bytes).map_err(describe)?;
    drop(bytes);
    // The crate's validation reads each POSITION accessor without checking
    // that it exists: an index beyond the accessors is refused here first.
    let root = doc.as_json();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let position = prim.attributes.get(&gltf::json::validation::Checked::Valid(gltf::Semantic::Positions));
            if let Some(i) = position.filter(|i| i.value() >= root.accessors.len()) {
                return Err(format!("invalid glTF at meshes[{m}].primitives[{p}].attributes[\"POSITION\"]: accessor {} does not exist", i.value()));
            }
        }
    }
    // Its image sources unwrap a missing URI, view or MIME type: refused here first.
    for (i, image) in root.images.iter().enumerate() {
        let well_formed = match &image.buffer_view {
            Some(view) => view.value() < root.buffer_views.len() && image.mime_type.is_some(),
            None => image.uri.is_some(),
        };
        if !well_formed {
            return Err(format!("invalid glTF at images[{i}]: an image needs a uri, or a bufferView that exists and a mimeType"));
        }
    }
    let doc = gltf::Document::from_json(doc.into_json()).map_err(describe)?;
    let mut parts = GltfParts::default();

    // Buffers, each checked against its declared length.
    let mut buffers = Vec::new();
    for b in doc.buffers() {
        let what = format!("buffer {}", b.index());
        let data = match b.source() {
            // Taken, not copied: a large model's binary chunk is held once.
            gltf::buffer::Source::Bin => blob.take().ok_or(format!("{what} is the GLB's binary chunk, but the file has none (or another buffer took it)"))?,
            gltf::buffer::Source::Uri(uri) => source::read_uri(uri, folder, &what, InputKind::Mesh)?,
        };
        if data.len() < b.length() {
            return Err(format!("{what} declares {} bytes but holds only {}", b.length(), data.len()));
        }
        buffers.push(data);
    }
    drop(blob);

    let ignored = &mut parts.ignored;
    for (what, n) in [("skins", doc.skins().count()), ("animations", doc.animations().count())] {
        if n > 0 {
            ignored.push(format!("{n} {what}"));
        }
    }
    for ext in doc.extensions_used() {
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            ignored.push(format!("extension {}", ext.chars().take(60).collect::<String>()));
        }
    }

    // Materials, appended under "<file stem>/<name>".
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let first_material = scene.materials.len() as u32;
    let mut images = materials::Images { folder, buffers: &buffers, decoded: Default::default(), alphas: Default::default() };
    let mut double_sided = Vec::new();
    for m in doc.materials() {
        let label = m.name().map(str::to_string).unwrap_or_else(|| format!("material {}", m.index().unwrap_or(0)));
        let mat = materials::convert(&m, format!("{stem}/{label}"), &mut images, ignored)?;
        scene.materials.push(mat);
        double_sided.push(m.double_sided());
    }
    drop(images);
    let fallback = scene.default_material_index();

    // The default scene's nodes, each with its world transform.
    let gscene = doc.default_scene().or_else(|| doc.scenes().next()).ok_or("it has no scene")?;
    let mut visited = vec![false; doc.nodes().count()];
    let mut stack: Vec<(gltf::Node, Mat4)> = gscene.nodes().map(|n| (n, placement.matrix())).collect();
    let mut uses: Vec<Vec<(Mat4, usize)>> = vec![Vec::new(); doc.meshes().count()];
    while let Some((node, parent)) = stack.pop() {
        let i = node.index();
        if std::mem::replace(&mut visited[i], true) {
            return Err(format!("node {i} is reached twice from scene {} (its node graph has a cycle or a node with two parents)", gscene.index()));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        if !local.is_finite() {
            return Err(format!("node {i}: its transform is not finite"));
        }
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            uses[mesh.index()].push((world, i));
        }
        if let Some(camera) = node.camera() {
            let cam_name = camera.name().or(node.name()).map(str::to_string).unwrap_or_else(|| format!("camera {}", camera.index()));
            let eye = world.transform_point3(Vec3::ZERO);
            let forward = world.transform_vector3(-Vec3::Z).normalize_or_zero();
            let placed = Camera { eye, target: eye + forward, up: world.transform_vector3(Vec3::Y).normalize_or_zero(), ..Camera::default() };
            let (c, aspect) = match camera.projection() {
                gltf::camera::Projection::Perspective(p) => {
                    (Camera { fov: Fov::Y(p.yfov().to_degrees()), near: p.znear(), far: p.zfar().unwrap_or(p.znear() * 1e6), ..placed }, p.aspect_ratio())
                }
                // xmag and ymag are half the view's width and height; the
                // image's own aspect ratio sizes its width, as it does a
                // perspective camera's.
                gltf::camera::Projection::Orthographic(o) => {
                    let projection = crate::scene::camera::Projection::Orthographic { height: 2.0 * o.ymag() };
                    let aspect = (o.ymag() != 0.0).then(|| o.xmag() / o.ymag()).filter(|a| a.is_finite() && *a > 0.0);
                    // glTF lets an orthographic znear be 0; eye rays start on the near plane, so it becomes a sliver.
                    let near = if o.znear() > 0.0 { o.znear() } else { 1e-4 * o.zfar().abs().max(1e-3) };
                    (Camera { projection, near, far: o.zfar(), ..placed }, aspect)
                }
            };
            c.validate().map_err(|e| format!("camera {} (node {i}): {e}", camera.index()))?;
            parts.cameras.push(NamedCamera { name: cam_name, camera: c, aspect });
        }
        if let Some(light) = node.light() {
            let colour = Vec3::from(light.color()) * light.intensity();
            let converted = match light.kind() {
                gltf::khr_lights_punctual::Kind::Point => {
                    Some(Light::Point { position: world.transform_point3(Vec3::ZERO), power: colour * 4.0 * std::f32::consts::PI / LUMENS_PER_WATT })
                }
                gltf::khr_lights_punctual::Kind::Directional => {
                    let d = world.transform_vector3(-Vec3::Z);
                    Some(Light::Directional { direction: d.normalize_or(-Vec3::Z), irradiance: colour / LUMENS_PER_WATT })
                }
                gltf::khr_lights_punctual::Kind::Spot { .. } => {
                    parts.ignored.push(format!("spot light {} (pinhole has no spot lights yet)", light.index()));
                    None
                }
            };
            if let Some(l) = converted {
                let (power, at) = match &l {
                    Light::Point { power, position } => (*power, *position),
                    Light::Directional { irradiance, .. } => (*irradiance, Vec3::ZERO),
                };
                if !(power.is_finite() && power.min_element() >= 0.0 && power.max_element() <= MAX_LIGHT && at.abs().max_element() <= MAX_COORDINATE) {
                    return Err(format!("light {} (node {i}): its colour, intensity or position is out of range", light.index()));
                }
                parts.lights.push(l);
            }
        }
        stack.extend(node.children().map(|c| (c, world)));
    }

    // Meshes: flattened when one node uses them, shared when several do.
    let first = scene.triangles.len();
    let mut degenerate = 0;
    let mut copy_index = 0u32;
    let quoted = |name: Option<&str>| name.map(|n| format!(" \"{}\"", n.chars().take(60).collect::<String>())).unwrap_or_default();
    let node_names: Vec<Option<&str>> = doc.nodes().map(|n| n.name()).collect();
    for mesh in doc.meshes() {
        let placed = &uses[mesh.index()];
        if placed.is_empty() {
            continue;
        }
        let part_name = |node: usize| {
            format!("glTF node {node}{}, mesh {}{}", quoted(node_names.get(node).copied().flatten()), mesh.index(), quoted(mesh.name()))
        };
        let MeshCorners { triangles: local, keys, vertices, colours, tangents } = mesh_triangles(&mesh, &buffers, first_material, fallback, &double_sided, object, &mut degenerate, &mut parts.ignored)?;
        if placed.len() == 1 {
            let p = Placement::from_matrix(placed[0].0);
            let start = scene.triangles.len();
            // A mirroring placement swaps corners 1 and 2 of each triangle
            // (`Placement::apply`); their colours and tangents go with them.
            let flips = p.flips();
            if let Some(colours) = colours {
                scene.vertex_colours.resize(start, [Vec3::ONE; 3]);
                scene.vertex_colours.extend(colours.into_iter().map(|c| in_corner_order(c, flips)));
            }
            if let Some(tangents) = tangents {
                // A tangent is a direction in the surface: it turns with the
                // placement's matrix, and a mirror flips the frame's handedness.
                let m = p.matrix();
                let w_sign = if m.determinant() < 0.0 { -1.0 } else { 1.0 };
                let place = |t: Vec4| if t == Vec4::ZERO { t } else { m.transform_vector3(t.truncate()).normalize_or_zero().extend(t.w * w_sign) };
                scene.given_tangents.resize(start, [Vec4::ZERO; 3]);
                scene.given_tangents.extend(tangents.into_iter().map(|c| in_corner_order(c.map(place), flips)));
            }
            // Corners are shared by vertex as they are pushed (each is a
            // function of its vertex), so no table of every corner is built
            // to merge them afterwards.
            let mut made = vec![u32::MAX; vertices];
            scene.triangles.reserve_faces(local.len());
            for (t, key) in local.into_iter().zip(keys) {
                let t = p.apply(t);
                if !t.v.iter().all(|v| v.abs().max_element() <= MAX_COORDINATE) {
                    return Err(format!("mesh {} placed by node {}: a vertex lands out of range (coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e})", mesh.index(), placed[0].1));
                }
                scene.triangles.push_keyed(t, in_corner_order(key, flips).map(|k| k as usize), &mut made);
            }
            scene.parts.push(NamedPart { object, what: PartOf::Triangles(start..scene.triangles.len()), name: part_name(placed[0].1) });
        } else if !local.is_empty() {
            if tangents.is_some() {
                parts.ignored.push(format!("mesh {}: TANGENT (its nodes share it, and shared meshes take no tangent frame)", mesh.index()));
            }
            let (lo, hi) = local.iter().flat_map(|t| t.v).fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), v| (lo.min(v), hi.max(v)));
            let mut copies = Vec::new();
            for (world, node) in placed.iter() {
                for c in 0..8 {
                    let corner = Vec3::new(if c & 1 == 0 { lo.x } else { hi.x }, if c & 2 == 0 { lo.y } else { hi.y }, if c & 4 == 0 { lo.z } else { hi.z });
                    if !(world.transform_point3(corner).abs().max_element() <= MAX_COORDINATE) {
                        return Err(format!("mesh {} placed by node {node}: a vertex lands out of range (coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e})", mesh.index()));
                    }
                }
                copies.push(MeshCopy { placement: Some(Placement::from_matrix(*world)), material: None, index: Some(copy_index) });
                scene.parts.push(NamedPart { object, what: PartOf::Copy(copy_index), name: part_name(*node) });
                copy_index += 1;
            }
            layered.colours.resize(layered.objects.len(), None);
            layered.colours.push(colours.map(Arc::new));
            layered.objects.push((object, Arc::new(local), copies));
        }
    }
    if degenerate > 0 {
        parts.ignored.push(format!("{degenerate} triangles with zero area"));
    }
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    scene.objects.push(ObjectInfo { name, kind: "gltf".into(), triangles: first..scene.triangles.len() });
    Ok(parts)
}

/// A triangle's per-corner values in the corner order of the placed
/// triangle: a mirroring placement swaps corners 1 and 2.
fn in_corner_order<T>(mut c: [T; 3], flips: bool) -> [T; 3] {
    if flips {
        c.swap(1, 2);
    }
    c
}

/// The triangles of a mesh in its own frame, with what their corners carry
/// besides position, normal and uv.
struct MeshCorners {
    triangles: Vec<Triangle>,
    /// Per triangle, its corners' vertices numbered across the mesh's
    /// primitives (each primitive's after the previous one's).
    keys: Vec<[u32; 3]>,
    /// How many vertices the numbering covers.
    vertices: usize,
    /// Per triangle, when a primitive has `COLOR_0` (white where another has none).
    colours: Option<Vec<[Vec3; 3]>>,
    /// Per triangle, when a primitive has `TANGENT`: the tangent (xyz) and
    /// the handedness of the frame (w); zero where another has none.
    tangents: Option<Vec<[Vec4; 3]>>,
}

/// The triangles of every primitive of `mesh`, in the mesh's own frame,
/// and their corners' vertex colours and tangents where a primitive has them.
#[allow(clippy::too_many_arguments)]
fn mesh_triangles(
    mesh: &gltf::Mesh,
    buffers: &[Vec<u8>],
    first_material: u32,
    fallback: u32,
    double_sided: &[bool],
    object: u32,
    degenerate: &mut usize,
    ignored: &mut Vec<String>,
) -> Result<MeshCorners, String> {
    let mut out = Vec::new();
    let mut colours_out: Option<Vec<[Vec3; 3]>> = None;
    let mut tangents_out: Option<Vec<[Vec4; 3]>> = None;
    let mut keys = Vec::new();
    let mut vertices = 0usize;
    for prim in mesh.primitives() {
        let at = format!("mesh {} primitive {}", mesh.index(), prim.index());
        let positions = prim.get(&gltf::Semantic::Positions).ok_or(format!("{at} has no POSITION attribute"))?;
        let pos = accessor::read_floats::<3>(&positions, buffers).map_err(|e| format!("{at}: {e}"))?;
        let pos: Vec<Vec3> = pos.into_iter().map(Vec3::from).collect();
        if let Some(k) = pos.iter().position(|p| !(p.abs().max_element() <= MAX_COORDINATE)) {
            return Err(format!("{at}: position {k} (accessor {}) is not finite or out of range", positions.index()));
        }
        let normals = match prim.get(&gltf::Semantic::Normals) {
            Some(a) => Some(accessor::read_floats::<3>(&a, buffers).map_err(|e| format!("{at}: {e}"))?),
            None => None,
        };
        let uvs = match prim.get(&gltf::Semantic::TexCoords(0)) {
            Some(a) => Some(accessor::read_floats::<2>(&a, buffers).map_err(|e| format!("{at}: {e}"))?),
            None => None,
        };
        for (what, attr) in [("normals", normals.as_ref().map(Vec::len)), ("uvs", uvs.as_ref().map(Vec::len))] {
            if attr.is_some_and(|n| n != pos.len()) {
                return Err(format!("{at}: its {what} and positions differ in count"));
            }
        }
        let colours: Option<Vec<Vec3>> = match prim.get(&gltf::Semantic::Colors(0)) {
            Some(a) => {
                let read = match a.dimensions().multiplicity() {
                    4 => accessor::read_floats::<4>(&a, buffers).map(|c| c.into_iter().map(|[r, g, b, _]| Vec3::new(r, g, b)).collect::<Vec<_>>()),
                    _ => accessor::read_floats::<3>(&a, buffers).map(|c| c.into_iter().map(Vec3::from).collect()),
                };
                let c = read.map_err(|e| format!("{at}: COLOR_0: {e}"))?;
                if c.len() != pos.len() {
                    return Err(format!("{at}: its COLOR_0 and positions differ in count"));
                }
                if let Some(k) = c.iter().position(|v| !(v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= 1.0)) {
                    return Err(format!("{at}: colour {k} of COLOR_0 (accessor {}) is not a number from 0 to 1", a.index()));
                }
                Some(c)
            }
            None => None,
        };
        if colours.is_some() && colours_out.is_none() {
            colours_out = Some(vec![[Vec3::ONE; 3]; out.len()]);
        }
        let tangents: Option<Vec<Vec4>> = match prim.get(&gltf::Semantic::Tangents) {
            Some(a) => {
                let t = accessor::read_floats::<4>(&a, buffers).map_err(|e| format!("{at}: TANGENT: {e}"))?;
                if t.len() != pos.len() {
                    return Err(format!("{at}: its TANGENT and positions differ in count"));
                }
                // A tangent that is not finite, or has no length, gives no
                // frame: the uvs' frame is used at that corner instead.
                Some(t.into_iter().map(Vec4::from).map(|t| if t.is_finite() && t.truncate().length() > 0.0 { t } else { Vec4::ZERO }).collect())
            }
            None => None,
        };
        if tangents.is_some() && tangents_out.is_none() {
            tangents_out = Some(vec![[Vec4::ZERO; 3]; out.len()]);
        }
        if prim.morph_targets().next().is_some() {
            ignored.push(format!("{at}: morph targets"));
        }
        let indices: Vec<u32> = match prim.indices() {
            Some(a) => {
                let idx = accessor::read_indices(&a, buffers).map_err(|e| format!("{at}: {e}"))?;
                if let Some(k) = idx.iter().position(|&i| i as usize >= pos.len()) {
                    return Err(format!("{at}: index {k} of accessor {} is {}, beyond its {} vertices", a.index(), idx[k], pos.len()));
                }
                idx
            }
            None => (0..pos.len() as u32).collect(),
        };
        let triangles: Vec<[u32; 3]> = match prim.mode() {
            gltf::mesh::Mode::Triangles => indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            gltf::mesh::Mode::TriangleStrip => {
                (2..indices.len()).map(|k| if k % 2 == 0 { [indices[k - 2], indices[k - 1], indices[k]] } else { [indices[k - 1], indices[k - 2], indices[k]] }).collect()
            }
            gltf::mesh::Mode::TriangleFan => (2..indices.len()).map(|k| [indices[0], indices[k - 1], indices[k]]).collect(),
            other => {
                ignored.push(format!("{at}: {other:?} (only triangles are drawn)"));
                continue;
            }
        };
        drop(indices);
        let (material, two_sided) = match prim.material().index() {
            Some(m) => (first_material + m as u32, double_sided.get(m).copied().unwrap_or(false)),
            None => (fallback, false),
        };
        out.reserve(triangles.len());
        keys.reserve(triangles.len());
        let first_vertex = vertices as u32;
        vertices += pos.len();
        for idx in triangles {
            let v = idx.map(|i| pos[i as usize]);
            let Some(geo) = Triangle::normal_if_not_degenerate(&v) else {
                *degenerate += 1;
                continue;
            };
            let n = match &normals {
                Some(ns) => idx.map(|i| Vec3::from(ns[i as usize]).normalize_or(geo)),
                None => [geo; 3],
            };
            // glTF's v runs down the image; pinhole's runs up.
            let uv = match &uvs {
                Some(ts) => idx.map(|i| {
                    let [u, v] = ts[i as usize];
                    let t = Vec2::new(u, 1.0 - v);
                    if t.is_finite() { t } else { Vec2::ZERO }
                }),
                None => [Vec2::ZERO; 3],
            };
            out.push(Triangle { v, n, uv, material, object, two_sided });
            keys.push(idx.map(|i| first_vertex + i));
            if let Some(c) = colours_out.as_mut() {
                c.push(colours.as_ref().map_or([Vec3::ONE; 3], |cs| idx.map(|i| cs[i as usize])));
            }
            if let Some(t) = tangents_out.as_mut() {
                t.push(tangents.as_ref().map_or([Vec4::ZERO; 3], |ts| idx.map(|i| ts[i as usize])));
            }
        }
    }
    Ok(MeshCorners { triangles: out, keys, vertices, colours: colours_out, tangents: tangents_out })
}

/// Refuses a file whose `extensionsRequired` names an extension pinhole
/// does not read, before anything else is parsed.
fn refuse_required_extensions(bytes: &[u8]) -> Result<(), String> {
    let json: std::borrow::Cow<[u8]> = if bytes.starts_with(b"glTF") {
        gltf::binary::Glb::from_slice(bytes).map_err(|e| format!("not a valid GLB file ({} bytes; a chunk is cut short or malformed): {e}", bytes.len()))?.json
    } else {
        std::borrow::Cow::Borrowed(bytes)
    };
    #[derive(serde::Deserialize)]
    struct Required {
        #[serde(default, rename = "extensionsRequired")]
        extensions_required: Vec<String>,
    }
    let required: Required = serde_json::from_slice(&json).map_err(|e| format!("not valid glTF JSON: {e}"))?;
    match required.extensions_required.iter().find(|e| !SUPPORTED_EXTENSIONS.contains(&e.as_str())) {
        Some(e) => Err(format!(
            "it requires the extension {} (extensionsRequired), which pinhole does not support (it reads {})",
            e.chars().take(60).collect::<String>(),
            SUPPORTED_EXTENSIONS.join(", ")
        )),
        None => Ok(()),
    }
}

/// The gltf crate's error in one sentence, with the JSON path of the first
/// invalid value.
fn describe(e: gltf::Error) -> String {
    match e {
        gltf::Error::Validation(errors) => match errors.first() {
            Some((path, err)) => format!("invalid glTF at {path}: {err}"),
            None => "invalid glTF".into(),
        },
        other => format!("cannot read glTF: {other}"),
    }
}

/// A scene around a bare glTF: its first perspective camera (or the one
/// named `camera`), or framed like a bare OBJ when it has none; its lights,
/// or the bare OBJ's light when it has none (with a notice).
pub fn frame_bare_gltf(path: &Path, camera: Option<&str>) -> Result<Scene, String> {
    let mut scene = Scene { name: path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "gltf".into()), ..Scene::default() };
    let mut layered = Layered::default();
    let identity = Placement::from_matrix(Mat4::IDENTITY);
    let parts = add_gltf(&mut scene, path, &identity, 0, &mut layered)?;
    crate::scene::instanced::build_layer(&mut scene, layered)?;
    let name = path.display();
    let (lo, hi) = scene.bounds().ok_or(format!("{name}: its default scene has no triangles"))?;
    let chosen = match camera {
        Some(wanted) => Some(parts.cameras.iter().find(|c| c.name == wanted).ok_or_else(|| {
            let names: Vec<String> = parts.cameras.iter().map(|c| format!("\"{}\"", c.name)).collect();
            format!("{name}: no camera is named \"{wanted}\" (its cameras: {})", if names.is_empty() { "none".into() } else { names.join(", ") })
        })?),
        // The first perspective camera: the view the asset's author framed
        // for looking at it; an orthographic one only when there is no other.
        None => parts.cameras.iter().find(|c| c.camera.projection == crate::scene::camera::Projection::Perspective).or(parts.cameras.first()),
    };
    crate::scene::obj::frame_camera(&mut scene, lo, hi);
    let rig = std::mem::take(&mut scene.lights);
    if let Some(c) = chosen {
        scene.camera = c.camera.clone();
        if let Some(aspect) = c.aspect.filter(|a| a.is_finite() && *a > 0.0) {
            scene.render.height = ((scene.render.width as f32 / aspect).round() as u32).clamp(1, 16384);
        }
    }
    scene.named_cameras = parts.cameras.iter().map(|c| (c.name.clone(), c.camera.clone())).collect();
    scene.lights = parts.lights;
    if scene.lights.is_empty() && !scene.materials.iter().any(|m| m.is_emissive()) {
        scene.lights = rig;
        scene.warnings.push(format!("{name}: it has no lights; lit by a default point light above and behind the view"));
    }
    if !parts.ignored.is_empty() {
        scene.warnings.push(format!("{name}: not drawn: {}", parts.ignored.join("; ")));
    }
    scene.triangles.share_corners();
    if scene.materials.iter().any(|m| m.normal_map.is_some() || m.glossy_model == crate::scene::material::GlossyModel::Ward) {
        scene.tangents = crate::scene::tangents::build_tangents(&scene);
    }
    scene.refresh_emitters();
    Ok(scene)
}
