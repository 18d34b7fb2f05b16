//! OBJ/MTL meshes through tobj, checked for bad data, and the automatic
//! framing of a bare `.obj` given on the command line.
//!
//! MTL mapping: `Kd` -> lambertian, `Ks` -> glossy, `Ns` -> sharpness,
//! `Ke` -> emission, `map_Kd` -> texture. Other MTL terms are ignored.

use crate::scene::assets::read_asset;
use crate::input::{InputKind, MAX_COORDINATE, MAX_VALUE};
use crate::scene::texture::load_texture;
use crate::scene::{Camera, Fov, Light, Material, Scene, Triangle, Triangles};
use crate::math::{Vec2, Vec3};
use serde::Deserialize;
use std::path::Path;
use std::sync::Arc;

/// How a mesh gets its shading normals.
#[derive(Deserialize, Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum NormalMode {
    /// The file's normals, else smooth.
    Auto,
    Smooth,
    Flat,
}

pub struct LoadedMesh {
    /// `material` is an index into `materials`, or `u32::MAX` for "none given".
    /// Corners shared, so that each copy placed into a scene shares them too.
    pub triangles: Triangles,
    pub materials: Vec<Material>,
    /// Triangles dropped because they have no area.
    pub degenerate: usize,
    /// Things that load but are probably not what the file meant: a missing
    /// or broken MTL file, a `usemtl` naming no material.
    pub warnings: Vec<String>,
}

/// Which of the file's MTL materials to load textures for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MtlTextures {
    /// Those of materials a face uses.
    Used,
    /// None: the mesh is drawn with a material of the scene instead.
    None,
}

thread_local! {
    /// OBJ files parsed by this thread so far (see `parses_on_this_thread`).
    static PARSES: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// How many OBJ files `load_obj` has read and parsed on the calling thread:
/// lets tests see that a scene load parses a shared mesh once. Per thread,
/// so tests running in parallel do not count each other's loads.
pub fn parses_on_this_thread() -> u64 {
    PARSES.with(|p| p.get())
}

pub fn load_obj(path: &Path, mode: NormalMode, textures: MtlTextures) -> Result<LoadedMesh, String> {
    PARSES.with(|p| p.set(p.get() + 1));
    load_obj_unbounded(path, mode, textures).map_err(|e| crate::input::bounded_message(&e))
}

/// `load_obj` before its message is bounded (MTL material names are echoed).
fn load_obj_unbounded(path: &Path, mode: NormalMode, textures: MtlTextures) -> Result<LoadedMesh, String> {
    let name = path.display();
    let bytes = read_asset(path, InputKind::Mesh).map_err(|e| format!("cannot read OBJ {e}"))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let options = tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
    // The first malformed MTL line, reported with its file and line: tobj's
    // material loader can only say that it failed.
    let mtl_error = std::cell::RefCell::new(None);
    let warnings = std::cell::RefCell::new(Vec::new());
    let (models, mtl) = tobj::load_obj_buf(&mut std::io::Cursor::new(&bytes), &options, |mtl_path| {
        let mtl_file = base.join(mtl_path);
        let data = read_asset(&mtl_file, InputKind::Mtl).map_err(|e| {
            warnings.borrow_mut().push(format!("{name}: cannot read its MTL file ({e}); its faces use the default material"));
            tobj::LoadError::OpenFileFailed
        })?;
        let data = normalize_mtl_colours(&data).map_err(|e| {
            *mtl_error.borrow_mut() = Some(format!("{}:{e}", mtl_file.display()));
            tobj::LoadError::MaterialParseError
        })?;
        tobj::load_mtl_buf(&mut std::io::Cursor::new(data)).inspect_err(|e| {
            warnings.borrow_mut().push(format!("{}: cannot parse the MTL file ({e}); its faces use the default material", mtl_file.display()));
        })
    })
    .map_err(|e| format!("{name}: cannot read OBJ: {e}"))?;
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let mut warnings = warnings.into_inner();
    let used: std::collections::HashSet<usize> = models.iter().filter_map(|m| m.mesh.material_id).collect();
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let materials = match mtl {
        Ok(ms) => {
            if let Some(undefined) = undefined_usemtl(&bytes, &ms) {
                warnings.push(format!("{name}: `usemtl {undefined}` names no material of its MTL files; those faces use the default material"));
            }
            ms.iter()
                .enumerate()
                .map(|(i, m)| {
                    let mut mat = mtl_material(m).map_err(|e| format!("{name}: MTL material \"{}\": {e}", m.name))?;
                    mat.name = format!("{stem}/{}", m.name);
                    // A texture is decoded only when a face is drawn with it.
                    if let (Some(tex), MtlTextures::Used, true) = (&m.diffuse_texture, textures, used.contains(&i)) {
                        mat.texture = Some(Arc::new(load_texture(&base.join(tex)).map_err(|e| format!("{name}: MTL {}: {e}", m.name))?));
                    }
                    Ok(mat)
                })
                .collect::<Result<Vec<_>, String>>()?
        }
        // A missing or broken MTL is not fatal: the mesh falls back to the
        // default material (the loader above has said why).
        Err(e) => {
            if warnings.is_empty() {
                warnings.push(format!("{name}: cannot load its MTL file ({e}); its faces use the default material"));
            }
            Vec::new()
        }
    };

    let mut triangles = Triangles::new();
    // Per vertex of every model so far: the corner made for it, if any.
    let mut vertex_corner: Vec<u32> = Vec::new();
    let mut degenerate = 0;
    for model in &models {
        let m = &model.mesh;
        // The object's name as messages echo it: a file's name line can be any length.
        let model_name: String = model.name.chars().take(60).collect();
        let pos: Vec<Vec3> = m.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        if let Some(i) = pos.iter().position(|p| !crate::math::is_finite(*p)) {
            return Err(format!("{name}: vertex {} of \"{}\" is not finite", i + 1, model_name));
        }
        if let Some(i) = pos.iter().position(|p| p.abs().max_element() > MAX_COORDINATE) {
            return Err(format!(
                "{name}: vertex {} of \"{}\" is {}; coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e}",
                i + 1,
                model_name,
                pos[i]
            ));
        }
        let corner_base = vertex_corner.len();
        vertex_corner.resize(corner_base + pos.len(), u32::MAX);
        let normals: Vec<Vec3> = m.normals.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        let uvs: Vec<Vec2> = m.texcoords.chunks_exact(2).map(|p| Vec2::new(p[0], p[1])).collect();
        let check = |idx: &[u32], len: usize, what: &str| -> Result<(), String> {
            match idx.iter().find(|&&i| i as usize >= len) {
                Some(i) => Err(format!("{name}: a face of \"{model_name}\" uses {what} {} but the file has only {len}", i + 1)),
                None => Ok(()),
            }
        };
        check(&m.indices, pos.len(), "vertex")?;
        let has_normals = !m.normal_indices.is_empty() && m.normal_indices.len() == m.indices.len();
        let has_uvs = !m.texcoord_indices.is_empty() && m.texcoord_indices.len() == m.indices.len();
        if has_normals {
            check(&m.normal_indices, normals.len(), "normal")?;
        }
        if has_uvs {
            check(&m.texcoord_indices, uvs.len(), "texture coordinate")?;
        }
        let use_file_normals = has_normals && mode == NormalMode::Auto;
        let smooth = if mode == NormalMode::Smooth || (mode == NormalMode::Auto && !has_normals) {
            Some(smooth_normals(&pos, &m.indices))
        } else {
            None
        };
        let material = m.material_id.map(|i| i as u32).filter(|&i| (i as usize) < materials.len()).unwrap_or(u32::MAX);
        for (f, idx) in m.indices.chunks_exact(3).enumerate() {
            let v = [pos[idx[0] as usize], pos[idx[1] as usize], pos[idx[2] as usize]];
            // Skip triangles whose normal cannot be formed; they cover no area.
            let Some(geo) = Triangle::normal_if_not_degenerate(&v) else {
                degenerate += 1;
                continue;
            };
            let corner = |k: usize| -> Vec3 {
                if use_file_normals {
                    normals[m.normal_indices[3 * f + k] as usize].normalize_or(geo)
                } else if let Some(s) = &smooth {
                    s[idx[k] as usize].normalize_or(geo)
                } else {
                    geo
                }
            };
            let uv = |k: usize| if has_uvs { uvs[m.texcoord_indices[3 * f + k] as usize] } else { Vec2::ZERO };
            let t = Triangle { v, n: [corner(0), corner(1), corner(2)], uv: [uv(0), uv(1), uv(2)], material, object: 0, two_sided: false };
            if has_uvs || use_file_normals {
                triangles.push(t);
            } else {
                // Each corner is then a function of its vertex alone (bar a
                // rare fallback normal, which `push_keyed` tells apart): find
                // it by the vertex, not by hashing it.
                triangles.push_keyed(t, [0, 1, 2].map(|k| corner_base + idx[k] as usize), &mut vertex_corner);
            }
        }
    }
    if triangles.is_empty() {
        return Err(format!("{name}: the OBJ has no triangles with area"));
    }
    triangles.share_corners();
    Ok(LoadedMesh { triangles, materials, degenerate, warnings })
}

/// Area-weighted vertex normals (the un-normalized face normal is already
/// area-weighted).
pub(crate) fn smooth_normals(pos: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; pos.len()];
    for idx in indices.chunks_exact(3) {
        let (a, b, c) = (pos[idx[0] as usize], pos[idx[1] as usize], pos[idx[2] as usize]);
        let n = (b - a).cross(c - a);
        if n.is_finite() {
            for &i in idx {
                acc[i as usize] += n;
            }
        }
    }
    acc
}

/// Points the camera at a bounding box from +z with the box in view, and adds
/// a light above and behind the camera, strong enough to light the box.
pub fn frame_camera(scene: &mut Scene, lo: Vec3, hi: Vec3) {
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-6);
    let fov_y: f32 = 45.0;
    let aspect = scene.render.width as f32 / scene.render.height as f32;
    let half = (fov_y.to_radians() * 0.5).tan().min((fov_y.to_radians() * 0.5).tan() * aspect);
    let distance = radius / half.atan().sin() * 1.05;
    scene.camera = Camera {
        eye: center + Vec3::new(0.0, 0.0, distance),
        target: center,
        up: Vec3::Y,
        fov: Fov::Y(fov_y),
        near: ((distance - radius) * 0.5).max(distance * 1e-3),
        far: (distance + radius) * 2.0,
        ..Camera::default()
    };
    let light_pos = center + Vec3::new(0.5 * distance, 1.5 * distance, 1.2 * distance);
    let d2 = (light_pos - center).length_squared();
    // About irradiance 3 W/m^2 at the object: a well-exposed grey at exposure 1.
    scene.lights.push(Light::Point { position: light_pos, power: Vec3::splat(3.0 * 4.0 * std::f32::consts::PI * d2) });
}

/// The MTL terms pinhole uses, checked as the scene file's materials are:
/// colours finite and from 0 to `MAX_VALUE`, `Ns` from 0 to `MAX_VALUE`.
fn mtl_material(m: &tobj::Material) -> Result<Material, String> {
    let colour = |v: Option<[f32; 3]>, default: Vec3, key: &str| -> Result<Vec3, String> {
        let c = v.map(Vec3::from).unwrap_or(default);
        if !crate::math::is_finite(c) || c.min_element() < 0.0 || c.max_element() > MAX_VALUE {
            return Err(format!("{key} must be finite numbers from 0 to {MAX_VALUE:e}, found {c}"));
        }
        Ok(c)
    };
    let mut mat = Material::black();
    mat.lambertian = colour(m.diffuse, Vec3::splat(0.8), "Kd")?;
    mat.glossy = colour(m.specular, Vec3::ZERO, "Ks")?;
    // tobj keeps the statements it does not model as text.
    if let Some(ke) = m.unknown_param.get("Ke") {
        let values: Vec<f32> = ke.split_whitespace().filter_map(|w| w.parse().ok()).collect();
        let ke = match values[..] {
            [g] => Some([g; 3]),
            [r, g, b] => Some([r, g, b]),
            _ => return Err(format!("Ke takes one or three numbers (r g b), found \"{}\"", ke.chars().take(40).collect::<String>())),
        };
        mat.emission = colour(ke, Vec3::ZERO, "Ke")?;
    }
    mat.sharpness = m.shininess.unwrap_or(100.0);
    if !(mat.sharpness.is_finite() && (0.0..=MAX_VALUE).contains(&mat.sharpness)) {
        return Err(format!("Ns must be a finite number from 0 to {MAX_VALUE:e}, found {}", mat.sharpness));
    }
    Ok(mat)
}

/// The first name a `usemtl` line gives that no loaded material has.
fn undefined_usemtl(obj: &[u8], materials: &[tobj::Material]) -> Option<String> {
    String::from_utf8_lossy(obj).lines().find_map(|line| {
        let rest = line.trim_start().strip_prefix("usemtl")?;
        let wanted = rest.trim();
        let defined = wanted.is_empty() || !rest.starts_with(char::is_whitespace) || materials.iter().any(|m| m.name == wanted);
        (!defined).then(|| wanted.chars().take(60).collect())
    })
}

/// MTL colour statements (`Ka`, `Kd`, `Ks`, `Ke`, `Tf`) as tobj can read
/// them: one number means grey (the format allows `Kd r` for `Kd r r r`)
/// and is written out as three; any count but one or three, or a word that
/// is not a number, is an error naming the line (`LINE: ...`), where tobj
/// itself would panic or silently read part of it.
pub fn normalize_mtl_colours(data: &[u8]) -> Result<Vec<u8>, String> {
    let text = String::from_utf8_lossy(data);
    let mut out = String::with_capacity(text.len() + 64);
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let key = words.next().unwrap_or("");
        if matches!(key, "Ka" | "Kd" | "Ks" | "Ke" | "Tf") {
            let values: Vec<&str> = words.collect();
            if let Some(bad) = values.iter().find(|v| v.parse::<f32>().is_err()) {
                return Err(format!("{}: {key} takes numbers (r g b), not \"{}\"", i + 1, bad.chars().take(40).collect::<String>()));
            }
            match values.len() {
                3 => out.push_str(line),
                1 => out.push_str(&format!("{key} {0} {0} {0}", values[0])),
                n => return Err(format!("{}: {key} takes one or three numbers (r g b), not {n}", i + 1)),
            }
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    Ok(out.into_bytes())
}
