//! Scene files: TOML parsed with serde into plain
//! descriptions, then checked and turned into a `Scene`. Every error names the
//! file, the line and the key or table at fault.

use crate::scene::mesh_cache::MeshCache;
use crate::scene::obj::{self, NormalMode};
use crate::scene::texture::{load_texture_as, Encoding, Wrap};
use crate::scene::material::{DiffuseModel, Fresnel, GlossyModel, MIN_ROUGHNESS};
use crate::scene::instanced::{build_layer, Layered, MeshCopy};
use crate::scene::placement::Placement;
use crate::scene::camera::Projection;
use crate::scene::{Camera, Fov, InstanceInfo, Light, Lighting, Material, ObjectInfo, RenderDefaults, Scene, Sphere, Triangle};
use crate::input::{MAX_COORDINATE, MAX_LIGHT, MAX_VALUE};
use crate::math::{Vec2, Vec3};

/// Largest index of refraction.
const MAX_IOR: f32 = 100.0;
/// Smallest and largest size of a scale factor.
const MIN_SCALE: f32 = 1e-6;
const MAX_SCALE: f32 = 1e6;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneDesc {
    camera: Option<Spanned<CameraDesc>>,
    render: Option<Spanned<RenderDesc>>,
    #[serde(default)]
    light: Vec<Spanned<LightDesc>>,
    #[serde(default)]
    materials: BTreeMap<String, Spanned<MaterialDesc>>,
    #[serde(default)]
    object: Vec<Spanned<ObjectDesc>>,
    environment: Option<Spanned<EnvironmentDesc>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvironmentDesc {
    file: String,
    intensity: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraDesc {
    eye: Option<F3>,
    target: Option<F3>,
    up: Option<F3>,
    fov_y_deg: Option<f32>,
    fov_x_deg: Option<f32>,
    near: Option<f32>,
    far: Option<f32>,
    projection: Option<String>,
    height: Option<f32>,
    aperture: Option<f32>,
    focus_distance: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderDesc {
    width: Option<i64>,
    height: Option<i64>,
    background: Option<F3>,
    ambient: Option<F3>,
    exposure: Option<f32>,
    lighting: Option<String>,
    reference: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightDesc {
    #[serde(rename = "type")]
    kind: String,
    position: Option<F3>,
    power: Option<F3>,
    direction: Option<F3>,
    irradiance: Option<F3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialDesc {
    lambertian: Option<F3>,
    diffuse_model: Option<String>,
    sigma: Option<f32>,
    darkening: Option<f32>,
    bands: Option<i64>,
    glossy: Option<F3>,
    sharpness: Option<f32>,
    glossy_model: Option<String>,
    roughness: Option<f32>,
    roughness_uv: Option<F2>,
    fresnel: Option<String>,
    eta: Option<F3>,
    k: Option<F3>,
    mirror: Option<F3>,
    transmission: Option<F3>,
    ior: Option<f32>,
    emission: Option<F3>,
    texture: Option<String>,
    wrap: Option<String>,
    uv_scale: Option<F2>,
    normal_map: Option<String>,
}

#[derive(Deserialize)]
#[serde(untagged, expecting = "`scale` must be one number or an array of three numbers [x, y, z]")]
enum ScaleDesc {
    Uniform(f32),
    PerAxis(F3),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectDesc {
    #[serde(rename = "type")]
    kind: String,
    file: Option<String>,
    normals: Option<Normals>,
    material: Option<String>,
    two_sided: Option<bool>,
    translate: Option<F3>,
    rotate_deg: Option<F3>,
    scale: Option<ScaleDesc>,
    vertices: Option<Vec<F3>>,
    uvs: Option<Vec<F2>>,
    center: Option<F3>,
    radius: Option<f32>,
    /// sphere only: draw it as a mesh of about this many triangles instead
    /// of the analytic surface.
    tessellate: Option<i64>,
    instances: Option<Vec<Spanned<InstanceDesc>>>,
    /// csg only: the operation and its two operands (inline tables).
    op: Option<String>,
    a: Option<Spanned<Box<ObjectDesc>>>,
    b: Option<Spanned<Box<ObjectDesc>>>,
    // `normals` for triangles is a list of vectors; meshes use the mode string.
}

/// One copy of a mesh object: its placement within the object's frame and
/// its material, each optional.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InstanceDesc {
    translate: Option<F3>,
    rotate_deg: Option<F3>,
    scale: Option<ScaleDesc>,
    material: Option<String>,
}

/// `normals` is a mode string on meshes and a list of three vectors on triangles.
#[derive(Deserialize)]
#[serde(
    untagged,
    expecting = "`normals` must be \"auto\", \"smooth\" or \"flat\" on a mesh, or one [x, y, z] per vertex on a triangle or quad"
)]
enum Normals {
    Mode(NormalMode),
    PerVertex(Vec<F3>),
}

/// N numbers, exactly: serde's fixed arrays would silently drop extra
/// elements (`eye = [0, 0, 3, 99]`).
#[derive(Deserialize, Clone, Copy)]
#[serde(try_from = "Vec<f32>")]
struct Numbers<const N: usize>([f32; N]);
type F3 = Numbers<3>;
type F2 = Numbers<2>;

impl<const N: usize> TryFrom<Vec<f32>> for Numbers<N> {
    type Error = String;
    fn try_from(v: Vec<f32>) -> Result<Self, String> {
        let n = v.len();
        v.try_into().map(Numbers).map_err(|_| format!("expected an array of {N} numbers, found {n}"))
    }
}

impl From<Numbers<3>> for Vec3 {
    fn from(n: Numbers<3>) -> Vec3 {
        Vec3::from(n.0)
    }
}

impl From<Numbers<2>> for Vec2 {
    fn from(n: Numbers<2>) -> Vec2 {
        Vec2::from(n.0)
    }
}

/// Reads and parses a scene file from disk.
pub fn load_scene_file(path: &Path) -> Result<Scene, String> {
    let bytes = crate::input::read_file(path, crate::input::InputKind::Scene)?;
    let text = String::from_utf8(bytes).map_err(|_| format!("{}: cannot read scene file: it is not UTF-8 text", path.display()))?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
    parse_scene(&text, &path.display().to_string(), &base, &name)
}

/// Parses scene TOML. `origin` names the source in messages; `base` resolves
/// relative paths.
pub fn parse_scene(text: &str, origin: &str, base: &Path, name: &str) -> Result<Scene, String> {
    parse_scene_with(text, origin, base, name, TwoLevel::Auto)
}

/// How the copies made by `instances` lists are held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TwoLevel {
    /// Flattened into `Scene::triangles` while the copies flattened so far
    /// hold at most `FLATTEN_LIMIT` triangles; the rest in the two-level layer.
    #[default]
    Auto,
    /// Every copy in the two-level layer (to test it against flattening).
    Always,
    /// Every copy flattened, however many triangles that makes.
    Never,
}

/// The `[camera]` table's projection: its name, and `height` for the
/// orthographic one (which alone takes it).
fn camera_projection(c: &CameraDesc) -> Result<Projection, String> {
    let name = c.projection.as_deref().unwrap_or("perspective");
    let projection = match name {
        "perspective" => Projection::Perspective,
        "fisheye" => Projection::Fisheye,
        "cylindrical" => Projection::Cylindrical,
        "orthographic" if c.fov_x_deg.is_some() || c.fov_y_deg.is_some() => {
            return Err("camera.projection = \"orthographic\" is sized by camera.height and takes no field of view (fov_x_deg, fov_y_deg)".to_string())
        }
        "orthographic" => match c.height {
            Some(height) => return Ok(Projection::Orthographic { height }),
            None => return Err("camera.projection = \"orthographic\" needs camera.height, the view's height in world units".to_string()),
        },
        other => return Err(format!("camera.projection = \"{other}\" is not one of {}", Projection::NAMES.join(", "))),
    };
    if let Some(h) = c.height {
        return Err(format!("camera.height = {h} sizes an orthographic view, and camera.projection is \"{name}\" (its field of view sizes it)"));
    }
    Ok(projection)
}

/// Most triangles made by copies that are flattened (`TwoLevel::Auto`):
/// beyond it a scene holds its copies as shared meshes and placements.
pub const FLATTEN_LIMIT: usize = 2_000_000;

/// `parse_scene`, choosing how copies are held.
pub fn parse_scene_with(text: &str, origin: &str, base: &Path, name: &str, two_level: TwoLevel) -> Result<Scene, String> {
    parse_scene_unbounded(text, origin, base, name, two_level).map_err(|e| crate::input::bounded_message(&e))
}

/// `parse_scene` before its message is bounded: messages quote names from
/// the file (materials, types, paths), which can be of any length.
fn parse_scene_unbounded(text: &str, origin: &str, base: &Path, name: &str, two_level: TwoLevel) -> Result<Scene, String> {
    let desc: SceneDesc = toml::from_str(text).map_err(|e| toml_error(origin, text, &e))?;
    let at = |span: std::ops::Range<usize>| format!("{origin}:{}", line_of(text, span.start));
    let mut scene = Scene { name: name.to_string(), ..Scene::default() };

    if let Some(cam) = &desc.camera {
        let c = cam.get_ref();
        let where_ = at(cam.span());
        let fov = match (c.fov_x_deg, c.fov_y_deg) {
            (Some(_), Some(_)) => return Err(format!("{where_}: [camera] gives both fov_x_deg and fov_y_deg; give one")),
            (Some(x), None) => Fov::X(x),
            (None, Some(y)) => Fov::Y(y),
            (None, None) => Fov::Y(60.0),
        };
        let d = Camera::default();
        let projection = camera_projection(c).map_err(|e| format!("{where_}: {e}"))?;
        scene.camera = Camera {
            eye: c.eye.map(Vec3::from).unwrap_or(d.eye),
            target: c.target.map(Vec3::from).unwrap_or(d.target),
            up: c.up.map(Vec3::from).unwrap_or(d.up),
            fov,
            near: c.near.unwrap_or(d.near),
            far: c.far.unwrap_or(d.far),
            projection,
            aperture: c.aperture.unwrap_or(d.aperture),
            focus_distance: c.focus_distance.unwrap_or(d.focus_distance),
        };
        scene.camera.validate().map_err(|e| format!("{where_}: {e}"))?;
    }

    if let Some(r) = &desc.render {
        let where_ = at(r.span());
        let r = r.get_ref();
        let d = RenderDefaults::default();
        let dim = |v: Option<i64>, key: &str, def: u32| -> Result<u32, String> {
            match v {
                None => Ok(def),
                Some(n) if (1..=16384).contains(&n) => Ok(n as u32),
                Some(n) => Err(format!("{where_}: render.{key} = {n} is not between 1 and 16384")),
            }
        };
        scene.render = RenderDefaults {
            width: dim(r.width, "width", d.width)?,
            height: dim(r.height, "height", d.height)?,
            background: color(r.background, d.background, MAX_VALUE, &where_, "render.background")?,
            ambient: color(r.ambient, d.ambient, MAX_VALUE, &where_, "render.ambient")?,
            exposure: r.exposure.unwrap_or(d.exposure),
            lighting: match r.lighting.as_deref() {
                None => d.lighting,
                Some(name) => Lighting::parse(name)
                    .ok_or_else(|| format!("{where_}: render.lighting = \"{name}\" is not a lighting model (expected \"physical\" or \"classic\")"))?,
            },
            reference: r.reference.as_ref().map(|f| base.join(f)),
        };
        if !(scene.render.exposure.is_finite() && scene.render.exposure >= 0.0 && scene.render.exposure <= MAX_VALUE) {
            return Err(format!("{where_}: render.exposure must be a finite number >= 0 (at most {MAX_VALUE:e})"));
        }
    }

    for (i, l) in desc.light.iter().enumerate() {
        let where_ = format!("{}: light {}", at(l.span()), i + 1);
        let l = l.get_ref();
        let light = match l.kind.as_str() {
            "point" => {
                reject(&where_, "point light", &[("direction", l.direction.is_some()), ("irradiance", l.irradiance.is_some())])?;
                Light::Point {
                    position: position(l.position, &where_, "position")?.ok_or(format!("{where_}: a point light needs `position`"))?,
                    power: color(l.power, Vec3::ZERO, MAX_LIGHT, &where_, "power")?,
                }
            }
            "directional" => {
                reject(&where_, "directional light", &[("position", l.position.is_some()), ("power", l.power.is_some())])?;
                let dir = finite(l.direction, &where_, "direction")?.ok_or(format!("{where_}: a directional light needs `direction`"))?;
                // Only the direction matters: a huge or tiny vector is scaled
                // (exactly, by a power of two) so that normalizing it cannot overflow.
                let dir = crate::math::rescale_direction(dir);
                if dir.length_squared() < 1e-20 {
                    return Err(format!("{where_}: direction must not be zero"));
                }
                Light::Directional { direction: dir.normalize(), irradiance: color(l.irradiance, Vec3::ZERO, MAX_LIGHT, &where_, "irradiance")? }
            }
            other => return Err(format!("{where_}: unknown light type \"{other}\" (expected \"point\" or \"directional\")")),
        };
        scene.lights.push(light);
    }

    // Textures are decoded after the objects are known, and only for
    // materials something is drawn with.
    let mut textures = Vec::new();
    for (mat_name, m) in &desc.materials {
        let where_ = format!("{}: material \"{mat_name}\"", at(m.span()));
        let m = m.get_ref();
        let mut mat = Material::black();
        mat.name = mat_name.clone();
        mat.lambertian = color(m.lambertian, Vec3::ZERO, MAX_VALUE, &where_, "lambertian")?;
        mat.glossy = color(m.glossy, Vec3::ZERO, MAX_VALUE, &where_, "glossy")?;
        mat.mirror = color(m.mirror, Vec3::ZERO, MAX_VALUE, &where_, "mirror")?;
        mat.transmission = color(m.transmission, Vec3::ZERO, MAX_VALUE, &where_, "transmission")?;
        mat.emission = color(m.emission, Vec3::ZERO, MAX_LIGHT, &where_, "emission")?;
        mat.sharpness = m.sharpness.unwrap_or(100.0);
        if !(mat.sharpness.is_finite() && mat.sharpness >= 0.0 && mat.sharpness <= MAX_VALUE) {
            return Err(format!("{where_}: sharpness must be a finite number >= 0 (at most {MAX_VALUE:e})"));
        }
        mat.diffuse_model = diffuse_lobe(m, &where_)?;
        glossy_lobe(&mut mat, m, &where_)?;
        mat.ior = m.ior.unwrap_or(1.5);
        if !(mat.ior.is_finite() && mat.ior > 0.0 && mat.ior <= MAX_IOR) {
            return Err(format!("{where_}: ior must be a finite number > 0 (at most {MAX_IOR})"));
        }
        if let Some(w) = &m.wrap {
            mat.wrap = [Wrap::parse(w).map_err(|e| format!("{where_}: wrap: {e}"))?; 2];
        }
        if let Some(scale) = m.uv_scale {
            let scale = Vec2::from(scale);
            if !(scale.is_finite() && scale.abs().max_element() <= MAX_VALUE) {
                return Err(format!("{where_}: uv_scale must be two finite numbers between -{MAX_VALUE:e} and {MAX_VALUE:e}"));
            }
            mat.uv_scale = scale;
        }
        if let Some(tex) = &m.texture {
            textures.push((scene.materials.len(), base.join(tex), where_.clone(), Encoding::Srgb));
        }
        if let Some(map) = &m.normal_map {
            textures.push((scene.materials.len(), base.join(map), where_, Encoding::Linear));
        }
        scene.materials.push(mat);
    }

    let mut meshes = MeshCache::default();
    let mut layered = Layered::default();
    for (i, o) in desc.object.iter().enumerate() {
        let where_ = format!("{}: object {}", at(o.span()), i + 1);
        let before = scene.triangles.len();
        add_object(&mut scene, o.get_ref(), i as u32, &where_, base, &mut meshes, &at, two_level, &mut layered)?;
        ward_has_uvs(&scene, before, &where_)?;
    }
    build_layer(&mut scene, layered)?;
    for (index, path, where_, encoding) in textures {
        let in_layer = scene.layer.as_ref().is_some_and(|l| {
            l.instances.iter().any(|i| i.material == Some(index as u32)) || l.meshes.iter().any(|m| m.iter().any(|t| t.material as usize == index))
        });
        let drawn = in_layer
            || scene.triangles.iter().any(|t| t.material as usize == index)
            || scene.spheres.iter().any(|s| s.material as usize == index)
            || scene.csgs.iter().any(|c| c.triangles.iter().any(|t| t.material as usize == index) || c.spheres.iter().any(|s| s.material as usize == index));
        if drawn {
            let loaded = Some(Arc::new(load_texture_as(&path, encoding).map_err(|e| match encoding {
                Encoding::Srgb => format!("{where_}: texture: {e}"),
                Encoding::Linear => format!("{where_}: normal_map: {e}"),
            })?));
            match encoding {
                Encoding::Srgb => scene.materials[index].texture = loaded,
                Encoding::Linear => scene.materials[index].normal_map = loaded,
            }
        }
    }
    if scene.materials.iter().any(|m| m.normal_map.is_some() || m.glossy_model == GlossyModel::Ward) {
        scene.tangents = crate::scene::tangents::build_tangents(&scene);
    }
    if let Some(env) = &desc.environment {
        let where_ = format!("{}: [environment]", at(env.span()));
        let env = env.get_ref();
        let intensity = env.intensity.unwrap_or(1.0);
        if !(intensity.is_finite() && (0.0..=MAX_VALUE).contains(&intensity)) {
            return Err(format!("{where_}: intensity must be a finite number from 0 to {MAX_VALUE:e}"));
        }
        let texture = load_texture_as(&base.join(&env.file), Encoding::Srgb).map_err(|e| format!("{where_}: file: {e}"))?;
        let non_finite = texture.levels[0].texels.iter().filter(|t| !t.is_finite()).count();
        if non_finite > 0 {
            scene.warnings.push(format!("{where_}: file: {non_finite} texels are not finite numbers; they send no light"));
        }
        let environment = crate::scene::environment::Environment::new(Arc::new(texture), intensity);
        if !environment.is_light() && intensity > 0.0 {
            scene.warnings.push(format!("{where_}: file: the image is black everywhere, so the environment lights nothing"));
        }
        scene.environment = Some(environment);
    }
    // Each triangle was pushed with corners of its own; store each corner once.
    scene.triangles.share_corners();
    scene.refresh_emitters();
    if scene.emitters.degenerate > 0 {
        scene.warnings.push(format!("{} emissive triangles or spheres have no area and emit nothing", scene.emitters.degenerate));
    }
    Ok(scene)
}

/// Turns `span` of the file into "file:line".
type At<'a> = dyn Fn(std::ops::Range<usize>) -> String + 'a;

#[allow(clippy::too_many_arguments)]
fn add_object(
    scene: &mut Scene,
    o: &ObjectDesc,
    object: u32,
    where_: &str,
    base: &Path,
    meshes: &mut MeshCache,
    at_line: &dyn Fn(std::ops::Range<usize>) -> String,
    two_level: TwoLevel,
    layered: &mut Layered,
) -> Result<(), String> {
    let at = at_line;
    if o.kind != "csg" {
        for (key, here) in [("op", o.op.is_some()), ("a", o.a.is_some()), ("b", o.b.is_some())] {
            if here {
                return Err(format!("{where_}: `{key}` is not a key of a {} object (only of a csg)", o.kind));
            }
        }
    }
    let two_sided = o.two_sided.unwrap_or(false);
    let placement = placement(o, where_)?;
    let explicit_material = material_index(scene, o.material.as_deref(), || where_.to_string())?;
    let first = scene.triangles.len();
    let kind = o.kind.as_str();
    let only = |allowed: &[&str]| -> Result<(), String> {
        let present = [
            ("file", o.file.is_some()),
            ("normals", o.normals.is_some()),
            ("vertices", o.vertices.is_some()),
            ("uvs", o.uvs.is_some()),
            ("center", o.center.is_some()),
            ("radius", o.radius.is_some()),
            ("tessellate", o.tessellate.is_some()),
            ("instances", o.instances.is_some()),
        ];
        for (key, here) in present {
            if here && !allowed.contains(&key) {
                return Err(format!("{where_}: `{key}` is not a key of a {kind} object"));
            }
        }
        Ok(())
    };
    match kind {
        "mesh" => {
            only(&["file", "normals", "instances"])?;
            let file = o.file.as_ref().ok_or(format!("{where_}: a mesh needs `file`"))?;
            let mode = match &o.normals {
                None => NormalMode::Auto,
                Some(Normals::Mode(m)) => *m,
                Some(Normals::PerVertex(_)) => return Err(format!("{where_}: mesh `normals` must be \"auto\", \"smooth\" or \"flat\"")),
            };
            let path = base.join(file);
            let textures = if explicit_material.is_some() { obj::MtlTextures::None } else { obj::MtlTextures::Used };
            let loaded = meshes.load(&path, mode, textures).map_err(|e| format!("{where_}: {e}"))?;
            scene.warnings.extend(loaded.warnings.iter().cloned());
            if loaded.degenerate > 0 {
                scene.warnings.push(format!("{}: skipped {} triangles with zero area", path.display(), loaded.degenerate));
            }
            // MTL materials are added under "<file>/<name>" so they never clash with the scene's.
            let mut mtl_index = Vec::new();
            for m in &loaded.materials {
                scene.materials.push(m.clone());
                mtl_index.push((scene.materials.len() - 1) as u32);
            }
            let fallback = match explicit_material {
                Some(m) => m,
                None => scene.default_material_index(),
            };
            let copies = match &o.instances {
                None => vec![MeshCopy { placement: None, material: explicit_material, index: None }],
                Some(list) => copies(scene, list, explicit_material, where_, at_line)?,
            };
            let flatten = match (two_level, &o.instances) {
                (_, None) | (TwoLevel::Never, _) => true,
                (TwoLevel::Always, Some(_)) => false,
                (TwoLevel::Auto, Some(_)) => layered.flattened + loaded.triangles.len() * copies.len() <= FLATTEN_LIMIT,
            };
            if !flatten {
                // The object's triangles placed once; each copy adds only its placement.
                let mesh: Vec<Triangle> = loaded
                    .triangles
                    .iter()
                    .map(|t| {
                        let mut t = t.clone();
                        t.material = match (explicit_material, t.material) {
                            (Some(m), _) => m,
                            (None, u32::MAX) => fallback,
                            (None, k) => mtl_index[k as usize],
                        };
                        t.object = object;
                        t.two_sided = two_sided;
                        placement.apply(t)
                    })
                    .collect();
                let (lo, hi) = mesh.iter().flat_map(|t| t.v).fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), v| (lo.min(v), hi.max(v)));
                for copy in &copies {
                    let m = copy.placement.as_ref().map_or(glam::Mat4::IDENTITY, |p| p.matrix());
                    for k in 0..8 {
                        let corner = Vec3::new(if k & 1 == 0 { lo.x } else { hi.x }, if k & 2 == 0 { lo.y } else { hi.y }, if k & 4 == 0 { lo.z } else { hi.z });
                        let v = m.transform_point3(corner);
                        if !(v.abs().max_element() <= MAX_COORDINATE) {
                            return Err(format!(
                                "{where_}: placed, copy {} reaches {v}; coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e}",
                                copy.index.unwrap_or(0)
                            ));
                        }
                    }
                }
                let name = Path::new(file).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
                let at = scene.triangles.len();
                scene.objects.push(ObjectInfo { name, kind: kind.to_string(), triangles: at..at });
                layered.objects.push((object, Arc::new(mesh), copies));
                return Ok(());
            }
            if o.instances.is_some() {
                layered.flattened += loaded.triangles.len() * copies.len();
            }
            scene.triangles.reserve_copies(&loaded.triangles, copies.len());
            for copy in &copies {
                let start = scene.triangles.len();
                let material = |m: u32| match (copy.material, m) {
                    (Some(m), _) => m,
                    (None, u32::MAX) => fallback,
                    (None, k) => mtl_index[k as usize],
                };
                // The object's own placement first, then the copy's: each by
                // the same arithmetic as `Placement::apply` on a lone object,
                // but once per shared corner.
                let place = |p: Vec3, n: Vec3| {
                    let (p, n) = placement.apply_corner(p, n);
                    match &copy.placement {
                        Some(c) => c.apply_corner(p, n),
                        None => (p, n),
                    }
                };
                let flips = placement.flips() != copy.placement.as_ref().is_some_and(|c| c.flips());
                scene.triangles.append_copy(&loaded.triangles, place, flips, material, object, two_sided);
                if let Some(index) = copy.index {
                    scene.instances.push(InstanceInfo::new(object, index, start..scene.triangles.len(), scene.triangles.range(start..scene.triangles.len())));
                }
            }
        }
        "gltf" => {
            only(&["file"])?;
            reject(where_, "gltf object (its own materials and sides are used)", &[("material", o.material.is_some()), ("two_sided", o.two_sided.is_some())])?;
            let file = o.file.as_ref().ok_or(format!("{where_}: a gltf object needs `file`"))?;
            let path = base.join(file);
            let parts = crate::scene::gltf::add_gltf(scene, &path, &placement, object, layered).map_err(|e| format!("{where_}: {e}"))?;
            scene.lights.extend(parts.lights);
            scene.named_cameras.extend(parts.cameras.into_iter().map(|c| (c.name, c.camera)));
            if !parts.ignored.is_empty() {
                scene.warnings.push(format!("{}: not drawn: {}", path.display(), parts.ignored.join("; ")));
            }
            return Ok(());
        }
        "triangle" | "quad" => {
            only(&["vertices", "normals", "uvs"])?;
            let count = if kind == "triangle" { 3 } else { 4 };
            let vs = o.vertices.as_ref().ok_or(format!("{where_}: a {kind} needs `vertices`"))?;
            if vs.len() != count {
                return Err(format!("{where_}: a {kind} needs {count} vertices, found {}", vs.len()));
            }
            let vs: Vec<Vec3> = vs.iter().map(|v| Vec3::from(*v)).collect();
            if vs.iter().any(|v| !crate::math::is_finite(*v)) {
                return Err(format!("{where_}: vertices must be finite numbers"));
            }
            if let Some(v) = vs.iter().find(|v| v.abs().max_element() > MAX_COORDINATE) {
                return Err(format!("{where_}: vertex {v} is out of range; coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e}"));
            }
            let ns: Option<Vec<Vec3>> = match &o.normals {
                None => None,
                Some(Normals::PerVertex(ns)) if ns.len() == count => {
                    let ns: Vec<Vec3> = ns.iter().map(|n| crate::math::rescale_direction(Vec3::from(*n))).collect();
                    if ns.iter().any(|n| !crate::math::is_finite(*n) || n.length_squared() < 1e-20) {
                        return Err(format!("{where_}: normals must be finite, non-zero vectors"));
                    }
                    Some(ns.into_iter().map(Vec3::normalize).collect())
                }
                Some(_) => return Err(format!("{where_}: `normals` of a {kind} must be {count} vectors")),
            };
            let uvs: Option<Vec<Vec2>> = match &o.uvs {
                None => None,
                Some(uvs) if uvs.len() == count => Some(uvs.iter().map(|u| Vec2::from(*u)).collect()),
                Some(_) => return Err(format!("{where_}: `uvs` of a {kind} must be {count} pairs")),
            };
            let material = match explicit_material {
                Some(m) => m,
                None => scene.default_material_index(),
            };
            let corners: &[[usize; 3]] = if count == 3 { &[[0, 1, 2]] } else { &[[0, 1, 2], [0, 2, 3]] };
            for c in corners {
                let v = [vs[c[0]], vs[c[1]], vs[c[2]]];
                let geo = (v[1] - v[0]).cross(v[2] - v[0]);
                if !(geo.length() > 0.0) {
                    return Err(format!("{where_}: the {kind} has zero area (its vertices are collinear)"));
                }
                let geo = geo.normalize();
                let t = Triangle {
                    v,
                    n: ns.as_ref().map(|n| [n[c[0]], n[c[1]], n[c[2]]]).unwrap_or([geo; 3]),
                    uv: uvs.as_ref().map(|u| [u[c[0]], u[c[1]], u[c[2]]]).unwrap_or([Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(if count == 3 { 0.0 } else { 1.0 }, 1.0)]),
                    material,
                    object,
                    two_sided,
                };
                scene.triangles.push(placement.apply(t));
            }
        }
        "sphere" => {
            only(&["center", "radius", "tessellate"])?;
            let center = position(o.center, where_, "center")?.ok_or(format!("{where_}: a sphere needs `center`"))?;
            let radius = o.radius.ok_or(format!("{where_}: a sphere needs `radius`"))?;
            if !(radius.is_finite() && radius > 0.0 && radius <= MAX_COORDINATE) {
                return Err(format!("{where_}: radius must be a finite number > 0 and at most {MAX_COORDINATE:e}, found {radius}"));
            }
            let material = match explicit_material {
                Some(m) => m,
                None => scene.default_material_index(),
            };
            if let Some(n) = o.tessellate {
                if !(crate::scene::tessellate::MIN_TRIANGLES as i64..=crate::scene::tessellate::MAX_TRIANGLES as i64).contains(&n) {
                    return Err(format!(
                        "{where_}: tessellate must be a triangle count from {} to {}, found {n}",
                        crate::scene::tessellate::MIN_TRIANGLES,
                        crate::scene::tessellate::MAX_TRIANGLES
                    ));
                }
                for t in crate::scene::tessellate::sphere_triangles(center, radius, n as u32, material, object, two_sided) {
                    scene.triangles.push(placement.apply(t));
                }
            } else {
                // A sphere stays analytic, so only uniform scale keeps it a sphere.
                let (center, radius) = placement.apply_sphere(center, radius).map_err(|e| format!("{where_}: {e}"))?;
                if center.abs().max_element() > MAX_COORDINATE || radius > MAX_COORDINATE {
                    return Err(format!(
                        "{where_}: placed, the sphere has centre {center} and radius {radius}; coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e}"
                    ));
                }
                scene.spheres.push(Sphere { center, radius, material, object });
            }
        }
        "csg" => {
            only(&[])?;
            reject(where_, "csg object (place its operands instead)", &[
                ("translate", o.translate.is_some()),
                ("rotate_deg", o.rotate_deg.is_some()),
                ("scale", o.scale.is_some()),
                ("two_sided", o.two_sided.is_some()),
            ])?;
            let mut parts = CsgParts::default();
            let root = csg_node(scene, o, object, where_, "", base, meshes, at, explicit_material, 0, &mut parts)?;
            scene.csgs.push(crate::scene::csg::Csg::new(root, parts.spheres, parts.triangles, object));
        }
        other => return Err(format!("{where_}: unknown object type \"{other}\" (expected mesh, gltf, triangle, quad, sphere or csg)")),
    }
    // Placement (scale, translate) can carry in-range vertices out of range.
    if let Some(t) = scene.triangles.range(first..scene.triangles.len()).find(|t| t.v.iter().any(|v| !(v.abs().max_element() <= MAX_COORDINATE))) {
        let v = t.v.into_iter().find(|v| !(v.abs().max_element() <= MAX_COORDINATE)).unwrap_or_default();
        return Err(format!("{where_}: placed, a vertex lands at {v}; coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e}"));
    }
    let name = match (&o.file, kind) {
        (Some(f), _) => Path::new(f).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(),
        (None, k) => format!("{k} {}", object + 1),
    };
    scene.objects.push(ObjectInfo { name, kind: kind.to_string(), triangles: first..scene.triangles.len() });
    Ok(())
}

/// The copies an `instances` list asks for, checked: every error names the
/// line of the entry at fault and its key.
fn copies(
    scene: &Scene,
    list: &[Spanned<InstanceDesc>],
    object_material: Option<u32>,
    where_: &str,
    at_line: &dyn Fn(std::ops::Range<usize>) -> String,
) -> Result<Vec<MeshCopy>, String> {
    if list.len() > MAX_INSTANCES {
        return Err(format!("{where_}: `instances` lists {} copies; at most {MAX_INSTANCES} are allowed", list.len()));
    }
    let mut out = Vec::with_capacity(list.len());
    for (k, d) in list.iter().enumerate() {
        // The line is found only for a message: counting lines for every
        // entry of a long list would take time quadratic in its length.
        let span = d.span();
        let here = || format!("{}: instances[{k}]", at_line(span.clone()));
        let d = d.get_ref();
        let placement = placement_of(d.translate, d.rotate_deg, d.scale.as_ref(), "").map_err(|_| {
            placement_of(d.translate, d.rotate_deg, d.scale.as_ref(), &here()).err().unwrap_or_default()
        })?;
        let material = material_index(scene, d.material.as_deref(), here)?.or(object_material);
        out.push(MeshCopy { placement: Some(placement), material, index: Some(k as u32) });
    }
    Ok(out)
}

/// Most copies one `instances` list may make.
const MAX_INSTANCES: usize = 1 << 20;

/// The leaves' geometry of a CSG object being read.
#[derive(Default)]
struct CsgParts {
    spheres: Vec<Sphere>,
    triangles: Vec<Triangle>,
}

/// Reads csg node `o` (at `path` in its object's tree, "" for the object
/// itself). Operands are read as objects of their own, then moved out of the
/// scene's lists into `parts`; an operand without `material` takes the
/// nearest enclosing csg's `material` when there is one.
#[allow(clippy::too_many_arguments)]
fn csg_node(
    scene: &mut Scene,
    o: &ObjectDesc,
    object: u32,
    where_: &str,
    path: &str,
    base: &Path,
    meshes: &mut MeshCache,
    at: &At,
    inherited: Option<u32>,
    depth: usize,
    parts: &mut CsgParts,
) -> Result<crate::scene::csg::CsgNode, String> {
    use crate::scene::csg::{CsgNode, CsgOp, MAX_DEPTH};
    let material = material_index(scene, o.material.as_deref(), || where_.to_string())?.or(inherited);
    if depth >= MAX_DEPTH {
        return Err(format!("{where_}: csg operations are nested more than {MAX_DEPTH} deep"));
    }
    let op_name = o.op.as_deref().ok_or(format!("{where_}: a csg needs `op` (\"union\", \"intersection\" or \"difference\")"))?;
    let op = CsgOp::parse(op_name)
        .ok_or(format!("{where_}: unknown csg op \"{op_name}\" (expected \"union\", \"intersection\" or \"difference\")"))?;
    let operand = |side: &str, desc: &Option<Spanned<Box<ObjectDesc>>>, scene: &mut Scene, meshes: &mut MeshCache, parts: &mut CsgParts| -> Result<CsgNode, String> {
        let key = if path.is_empty() { side.to_string() } else { format!("{path}.{side}") };
        let desc = desc.as_ref().ok_or(format!("{where_}: a csg needs operand `{key}` (a sphere, a closed mesh or a csg, as an inline table)"))?;
        let here = format!("{}: object {}, operand `{key}`", at(desc.span()), object + 1);
        let d: &ObjectDesc = desc.get_ref();
        match d.kind.as_str() {
            "csg" => csg_node(scene, d, object, &here, &key, base, meshes, at, material, depth + 1, parts),
            "sphere" | "mesh" => {
                let (t0, s0, o0) = (scene.triangles.len(), scene.spheres.len(), scene.objects.len());
                add_object(scene, d, object, &here, base, meshes, at, TwoLevel::Never, &mut Layered::default())?;
                let mut tris: Vec<Triangle> = scene.triangles.split_off(t0);
                let mut spheres: Vec<Sphere> = scene.spheres.drain(s0..).collect();
                scene.objects.truncate(o0);
                if let (None, Some(m)) = (&d.material, material) {
                    tris.iter_mut().for_each(|t| t.material = m);
                    spheres.iter_mut().for_each(|s| s.material = m);
                }
                if let Some(s) = spheres.pop() {
                    parts.spheres.push(s);
                    return Ok(CsgNode::Sphere(parts.spheres.len() as u32 - 1));
                }
                if let Err(e) = crate::scene::csg::check_closed(&tris) {
                    let file = d.file.as_deref().unwrap_or("?");
                    return Err(format!("{here}: the mesh \"{file}\" is not closed ({e}); a csg operand must be a closed solid"));
                }
                // Wound inside out, the solid would be its complement and vanish.
                if crate::scene::csg::signed_volume(&tris) < 0.0 {
                    crate::scene::csg::turn_right_side_out(&mut tris);
                    let file = d.file.as_deref().unwrap_or("?");
                    scene.warnings.push(format!("{here}: the mesh \"{file}\" is wound inside out (its triangles face inwards); its winding was reversed so the solid is what it encloses"));
                }
                let first = parts.triangles.len() as u32;
                let mut lo = Vec3::splat(f32::INFINITY);
                let mut hi = Vec3::splat(f32::NEG_INFINITY);
                for t in &mut tris {
                    t.two_sided = true;
                    for v in t.v {
                        lo = lo.min(v);
                        hi = hi.max(v);
                    }
                }
                parts.triangles.extend(tris);
                Ok(CsgNode::Mesh { first, end: parts.triangles.len() as u32, lo, hi })
            }
            other => Err(format!("{here}: a csg operand must be a sphere, a closed mesh or a csg, not \"{other}\"")),
        }
    };
    let a = operand("a", &o.a, scene, meshes, parts)?;
    let b = operand("b", &o.b, scene, meshes, parts)?;
    Ok(CsgNode::Op { op, a: Box::new(a), b: Box::new(b) })
}

/// The index of the material called `name` in `[materials]`, `None` when no
/// name is given. `where_` names the place for the message when no material
/// has that name (made only then).
fn material_index(scene: &Scene, name: Option<&str>, where_: impl FnOnce() -> String) -> Result<Option<u32>, String> {
    let Some(name) = name else { return Ok(None) };
    match scene.materials.iter().position(|m| m.name == name) {
        Some(index) => Ok(Some(index as u32)),
        None => Err(format!("{}: material \"{name}\" is not defined in [materials]", where_())),
    }
}

fn placement(o: &ObjectDesc, where_: &str) -> Result<Placement, String> {
    placement_of(o.translate, o.rotate_deg, o.scale.as_ref(), where_)
}

fn placement_of(translate: Option<F3>, rotate_deg: Option<F3>, scale: Option<&ScaleDesc>, where_: &str) -> Result<Placement, String> {
    let translate = position(translate, where_, "translate")?.unwrap_or(Vec3::ZERO);
    let rotate = finite(rotate_deg, where_, "rotate_deg")?.unwrap_or(Vec3::ZERO);
    let scale = match scale {
        None => Vec3::ONE,
        Some(ScaleDesc::Uniform(s)) => Vec3::splat(*s),
        Some(ScaleDesc::PerAxis(s)) => Vec3::from(*s),
    };
    if !crate::math::is_finite(scale) || scale.x * scale.y * scale.z == 0.0 {
        return Err(format!("{where_}: scale must be finite and non-zero"));
    }
    let size = scale.abs();
    if size.min_element() < MIN_SCALE || size.max_element() > MAX_SCALE {
        return Err(format!("{where_}: scale {scale} is out of range; each factor's size must be from {MIN_SCALE:e} to {MAX_SCALE:e}"));
    }
    let rotate_size = rotate.abs().max_element();
    if rotate_size > 1e6 {
        return Err(format!("{where_}: rotate_deg {rotate} is out of range (at most 1e6 degrees)"));
    }
    Ok(Placement::new(translate, rotate, scale))
}

fn reject(where_: &str, what: &str, keys: &[(&str, bool)]) -> Result<(), String> {
    match keys.iter().find(|(_, present)| *present) {
        Some((key, _)) => Err(format!("{where_}: `{key}` is not a key of a {what}")),
        None => Ok(()),
    }
}

fn finite(v: Option<F3>, where_: &str, key: &str) -> Result<Option<Vec3>, String> {
    match v.map(Vec3::from) {
        Some(v) if !crate::math::is_finite(v) => Err(format!("{where_}: `{key}` must be finite numbers, found {v}")),
        other => Ok(other),
    }
}

/// Ward's lobe is laid along the tangent frame the uvs give: refused on the
/// triangles from `first` on (one object's) that have a Ward material but
/// no uvs (all three corners' uvs the same, as a mesh without them loads).
fn ward_has_uvs(scene: &Scene, first: usize, where_: &str) -> Result<(), String> {
    for i in first..scene.triangles.len() {
        let t = scene.triangles.at(i);
        let material = &scene.materials[t.material as usize];
        if material.glossy_model == GlossyModel::Ward && t.uv[0] == t.uv[1] && t.uv[1] == t.uv[2] {
            return Err(format!(
                "{where_}: material \"{}\" has glossy_model = \"ward\", which needs uvs for its tangent frame, but this object's triangles have none",
                material.name
            ));
        }
    }
    Ok(())
}

/// The most toon bands a material may have.
const MAX_BANDS: i64 = 256;

/// The diffuse lobe's model and its parameter of material entry `m`.
fn diffuse_lobe(m: &MaterialDesc, where_: &str) -> Result<DiffuseModel, String> {
    let model = match m.diffuse_model.as_deref() {
        None | Some("lambert") => DiffuseModel::Lambert,
        Some("oren-nayar") => {
            let sigma = m.sigma.unwrap_or(0.0);
            if !(sigma.is_finite() && (0.0..=std::f32::consts::FRAC_PI_2).contains(&sigma)) {
                return Err(format!("{where_}: sigma must be an angle in radians from 0 to pi/2, found {sigma}"));
            }
            DiffuseModel::OrenNayar { sigma }
        }
        Some("minnaert") => {
            let darkening = m.darkening.unwrap_or(1.0);
            if !(darkening.is_finite() && (0.0..=1.0).contains(&darkening)) {
                return Err(format!("{where_}: darkening must be a number from 0 to 1, found {darkening}"));
            }
            DiffuseModel::Minnaert { darkening }
        }
        Some("toon") => {
            let bands = m.bands.unwrap_or(2);
            if !(1..=MAX_BANDS).contains(&bands) {
                return Err(format!("{where_}: bands must be a whole number from 1 to {MAX_BANDS}, found {bands}"));
            }
            DiffuseModel::Toon { bands: bands as u32 }
        }
        Some(other) => {
            let names: Vec<String> = DiffuseModel::NAMES.iter().map(|n| format!("\"{n}\"")).collect();
            return Err(format!("{where_}: unknown diffuse_model \"{other}\" (expected one of {})", names.join(", ")));
        }
    };
    for (key, present, owner) in [("sigma", m.sigma.is_some(), "oren-nayar"), ("darkening", m.darkening.is_some(), "minnaert"), ("bands", m.bands.is_some(), "toon")] {
        if present && model.name() != owner {
            return Err(format!("{where_}: `{key}` is given but diffuse_model is \"{}\"; `{key}` belongs to diffuse_model = \"{owner}\"", model.name()));
        }
    }
    Ok(model)
}

/// The glossy lobe's model, roughness and Fresnel term of material entry `m`.
fn glossy_lobe(mat: &mut Material, m: &MaterialDesc, where_: &str) -> Result<(), String> {
    if let Some(name) = &m.glossy_model {
        mat.glossy_model = match GlossyModel::parse(name) {
            Some(model) => model,
            None => {
                let names: Vec<String> = GlossyModel::NAMES.iter().map(|(n, _)| format!("\"{n}\"")).collect();
                return Err(format!("{where_}: unknown glossy_model \"{name}\" (expected one of {})", names.join(", ")));
            }
        };
    }
    if let Some(alpha) = m.roughness {
        // An alpha of 0 would be a mirror, which the microfacet lobes cannot
        // represent (their D is a delta there): refused, while tiny positive
        // values are raised to the smallest alpha f32 evaluates.
        if !(alpha.is_finite() && alpha > 0.0 && alpha <= 1.0) {
            return Err(format!("{where_}: roughness must be a number greater than 0 and at most 1, found {alpha}"));
        }
        mat.roughness = alpha.max(MIN_ROUGHNESS);
    }
    if let Some(uv) = m.roughness_uv {
        let uv = Vec2::from(uv);
        if mat.glossy_model != GlossyModel::Ward {
            return Err(format!("{where_}: `roughness_uv` is given but glossy_model is not \"ward\"; `roughness_uv` belongs to glossy_model = \"ward\""));
        }
        if !(uv.is_finite() && uv.min_element() > 0.0 && uv.max_element() <= 1.0) {
            return Err(format!("{where_}: roughness_uv must be two numbers greater than 0 and at most 1, found [{}, {}]", uv.x, uv.y));
        }
        mat.roughness_uv = uv.max(Vec2::splat(MIN_ROUGHNESS));
    } else if mat.glossy_model == GlossyModel::Ward {
        mat.roughness_uv = Vec2::splat(mat.roughness);
    }
    mat.fresnel = match m.fresnel.as_deref() {
        None | Some("none") => Fresnel::None,
        Some("schlick") => Fresnel::Schlick,
        Some("conductor") => {
            let (Some(eta), Some(k)) = (m.eta, m.k) else {
                let missing = if m.eta.is_none() { "eta" } else { "k" };
                return Err(format!("{where_}: fresnel \"conductor\" needs `{missing}` (the conductor's complex index of refraction eta + i k, three numbers each)"));
            };
            Fresnel::Conductor { eta: color(Some(eta), Vec3::ZERO, MAX_VALUE, where_, "eta")?, k: color(Some(k), Vec3::ZERO, MAX_VALUE, where_, "k")? }
        }
        Some(other) => {
            let names: Vec<String> = Fresnel::NAMES.iter().map(|n| format!("\"{n}\"")).collect();
            return Err(format!("{where_}: unknown fresnel \"{other}\" (expected one of {})", names.join(", ")));
        }
    };
    if !matches!(mat.fresnel, Fresnel::Conductor { .. }) {
        if let Some(key) = [("eta", m.eta.is_some()), ("k", m.k.is_some())].iter().find(|(_, present)| *present).map(|(key, _)| key) {
            return Err(format!("{where_}: `{key}` is given but fresnel is \"{}\"; `eta` and `k` belong to fresnel = \"conductor\"", mat.fresnel.name()));
        }
    }
    Ok(())
}

/// A radiance, power or reflectance: finite and not negative.
fn color(v: Option<F3>, default: Vec3, max: f32, where_: &str, key: &str) -> Result<Vec3, String> {
    let v = v.map(Vec3::from).unwrap_or(default);
    if !crate::math::is_finite(v) || v.min_element() < 0.0 || v.max_element() > max {
        return Err(format!("{where_}: `{key}` must be finite and not negative (at most {max:e}), found {v}"));
    }
    Ok(v)
}

/// A point in the scene: finite and within `MAX_COORDINATE` on every axis.
fn position(v: Option<F3>, where_: &str, key: &str) -> Result<Option<Vec3>, String> {
    match finite(v, where_, key)? {
        Some(p) if p.abs().max_element() > MAX_COORDINATE => Err(format!(
            "{where_}: `{key}` is {p}; coordinates must be between -{MAX_COORDINATE:e} and {MAX_COORDINATE:e}"
        )),
        other => Ok(other),
    }
}

/// 1-based line of a byte offset.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

fn toml_error(origin: &str, text: &str, e: &toml::de::Error) -> String {
    let msg = shorten(&e.message().trim().replace('\n', " "), MAX_ECHO_CHARS);
    match e.span() {
        Some(span) => {
            let line = line_of(text, span.start);
            let snippet = shorten(text.lines().nth(line - 1).unwrap_or("").trim(), MAX_ECHO_CHARS);
            format!("{origin}:{line}: {msg} (in `{snippet}`)")
        }
        None => format!("{origin}: {msg}"),
    }
}

/// Most characters of the scene file a message echoes: a 5 MB line must
/// not make a 5 MB message.
const MAX_ECHO_CHARS: usize = 200;

fn shorten(s: &str, max: usize) -> String {
    match s.char_indices().nth(max) {
        Some((cut, _)) => format!("{}...", &s[..cut]),
        None => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_with(material: &str) -> Result<Scene, String> {
        let text = format!("[camera]\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\n\n[materials.metal]\n{material}\n");
        parse_scene(&text, "test.toml", Path::new("."), "test")
    }

    fn metal(material: &str) -> Material {
        let scene = scene_with(material).unwrap();
        scene.materials.iter().find(|m| m.name == "metal").unwrap().clone()
    }

    #[test]
    fn glossy_model_and_roughness_are_read() {
        let m = metal("glossy = [0.9, 0.9, 0.9]");
        assert_eq!((m.glossy_model, m.roughness), (GlossyModel::BlinnPhong, crate::scene::material::DEFAULT_ROUGHNESS));
        let m = metal("glossy = [0.9, 0.9, 0.9]\nglossy_model = \"ggx\"\nroughness = 0.2\nfresnel = \"none\"");
        assert_eq!((m.glossy_model, m.roughness), (GlossyModel::Ggx, 0.2));
        assert_eq!(metal("glossy_model = \"beckmann\"").glossy_model, GlossyModel::Beckmann);
        assert_eq!(metal("glossy_model = \"phong\"").glossy_model, GlossyModel::Phong);
        assert_eq!(metal("glossy_model = \"blinn-phong\"").glossy_model, GlossyModel::BlinnPhong);
        let ward = metal("glossy_model = \"ward\"\nroughness_uv = [0.1, 0.4]");
        assert_eq!((ward.glossy_model, ward.roughness_uv), (GlossyModel::Ward, Vec2::new(0.1, 0.4)));
        assert_eq!(metal("glossy_model = \"ward\"\nroughness = 0.3").roughness_uv, Vec2::splat(0.3));
        // A tiny roughness is raised to the smallest alpha rather than overflowing D.
        assert_eq!(metal("roughness = 1e-7").roughness, MIN_ROUGHNESS);
        assert_eq!(metal("roughness = 1.0").roughness, 1.0);
        assert_eq!(metal("glossy = [0.9, 0.9, 0.9]").fresnel, Fresnel::None);
        assert_eq!(metal("lambertian = [0.5, 0.5, 0.5]").diffuse_model, DiffuseModel::Lambert);
        assert_eq!(metal("diffuse_model = \"oren-nayar\"\nsigma = 0.3").diffuse_model, DiffuseModel::OrenNayar { sigma: 0.3 });
        assert_eq!(metal("diffuse_model = \"minnaert\"\ndarkening = 0.6").diffuse_model, DiffuseModel::Minnaert { darkening: 0.6 });
        assert_eq!(metal("diffuse_model = \"toon\"\nbands = 3").diffuse_model, DiffuseModel::Toon { bands: 3 });
        assert_eq!(metal("fresnel = \"schlick\"").fresnel, Fresnel::Schlick);
        let conductor = metal("fresnel = \"conductor\"\neta = [0.2, 0.9, 1.1]\nk = [3.9, 2.4, 2.2]").fresnel;
        assert_eq!(conductor, Fresnel::Conductor { eta: Vec3::new(0.2, 0.9, 1.1), k: Vec3::new(3.9, 2.4, 2.2) });
    }

    #[test]
    fn bad_glossy_lobes_are_refused_with_the_key_named() {
        for (entry, words) in [
            ("glossy_model = \"gxx\"", &["material \"metal\"", "glossy_model", "\"gxx\"", "\"ggx\"", "\"beckmann\""][..]),
            ("roughness_uv = [0.1, 0.2]", &["material \"metal\"", "`roughness_uv`", "\"ward\""][..]),
            ("glossy_model = \"ward\"\nroughness_uv = [0.1, 0.0]", &["material \"metal\"", "roughness_uv", "greater than 0"][..]),
            ("glossy_model = \"ward\"\nroughness_uv = [nan, 0.1]", &["material \"metal\"", "roughness_uv"][..]),
            ("glossy_model = \"ward\"\nroughness_uv = [-0.1, 0.1]", &["material \"metal\"", "roughness_uv"][..]),
            ("roughness = -0.1", &["material \"metal\"", "roughness"][..]),
            ("roughness = 0.0", &["material \"metal\"", "roughness", "greater than 0"][..]),
            ("roughness = inf", &["material \"metal\"", "roughness"][..]),
            ("roughness = 1.5", &["material \"metal\"", "roughness"][..]),
            ("roughness = nan", &["material \"metal\"", "roughness"][..]),
            ("fresnel = \"conductor\"", &["material \"metal\"", "conductor", "`eta`"][..]),
            ("diffuse_model = \"oren\"", &["material \"metal\"", "diffuse_model", "\"oren-nayar\"", "\"toon\""][..]),
            ("diffuse_model = \"oren-nayar\"\nsigma = -0.1", &["material \"metal\"", "sigma"][..]),
            ("diffuse_model = \"oren-nayar\"\nsigma = nan", &["material \"metal\"", "sigma"][..]),
            ("diffuse_model = \"oren-nayar\"\nsigma = 2.0", &["material \"metal\"", "sigma", "pi/2"][..]),
            ("diffuse_model = \"minnaert\"\ndarkening = -0.5", &["material \"metal\"", "darkening"][..]),
            ("diffuse_model = \"minnaert\"\ndarkening = nan", &["material \"metal\"", "darkening"][..]),
            ("diffuse_model = \"toon\"\nbands = 0", &["material \"metal\"", "bands"][..]),
            ("diffuse_model = \"toon\"\nbands = -3", &["material \"metal\"", "bands"][..]),
            ("diffuse_model = \"toon\"\nbands = 2.5", &["bands"][..]),
            ("sigma = 0.3", &["material \"metal\"", "`sigma`", "\"lambert\"", "oren-nayar"][..]),
            ("diffuse_model = \"toon\"\ndarkening = 0.3", &["material \"metal\"", "`darkening`", "\"toon\"", "minnaert"][..]),
            ("fresnel = \"conductor\"\neta = [0.2, 0.9, 1.1]", &["material \"metal\"", "conductor", "`k`"][..]),
            ("fresnel = \"dielectric\"", &["material \"metal\"", "fresnel", "\"none\"", "\"conductor\""][..]),
            ("eta = [0.2, 0.9, 1.1]", &["material \"metal\"", "`eta`", "\"none\"", "conductor"][..]),
            ("fresnel = \"schlick\"\nk = [3.9, 2.4, 2.2]", &["material \"metal\"", "`k`", "\"schlick\"", "conductor"][..]),
            ("fresnel = \"conductor\"\neta = [0.2, -0.9, 1.1]\nk = [3.9, 2.4, 2.2]", &["material \"metal\"", "`eta`", "not negative"][..]),
            ("fresnel = \"conductor\"\neta = [0.2, 0.9, 1.1]\nk = [3.9, nan, 2.2]", &["material \"metal\"", "`k`", "finite"][..]),
        ] {
            let e = scene_with(entry).err().unwrap_or_else(|| panic!("{entry}: accepted"));
            for w in words {
                assert!(e.contains(w), "{entry}: {e:?} does not contain {w}");
            }
        }
    }
}
