//! The scene model every renderer reads: world-space triangles and analytic
//! spheres, lights, materials and the camera. Scene files are parsed into it
//! by `file.rs`; meshes come from `obj.rs`; built-in scenes from `builtin.rs`.

pub mod assets;
pub mod builtin;
pub mod camera;
pub mod csg;
pub mod emitters;
pub mod environment;
pub mod file;
pub mod forest;
pub mod gltf;
pub mod hit_lanes;
pub mod instanced;
pub mod load;
pub mod mesh_cache;
pub mod mesh_file;
pub mod normal_map;
pub mod material;
pub mod obj;
pub mod placement;
pub mod ply;
pub mod recentre;
pub mod tangents;
pub mod tessellate;
pub mod texture;
pub mod triangles;

pub use camera::{Camera, CameraView, Fov};
pub use material::Material;
pub use texture::Texture;
pub use triangles::Triangles;

use crate::math::{Ray, Vec2, Vec3};

/// A light source. Point lights follow CGPP 15.4.5: `L_i = power / (4 pi d^2)`.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    Point { position: Vec3, power: Vec3 },
    /// `direction` is the unit direction the light travels.
    Directional { direction: Vec3, irradiance: Vec3 },
}

/// One world-space triangle with its shading attributes.
#[derive(Clone, Debug, PartialEq)]
pub struct Triangle {
    pub v: [Vec3; 3],
    /// Unit shading normals per vertex (the geometric normal when the file has none).
    pub n: [Vec3; 3],
    pub uv: [Vec2; 3],
    pub material: u32,
    pub object: u32,
    pub two_sided: bool,
}

impl Triangle {
    /// `(v1 - v0) x (v2 - v0)`, normalized: the front side (CCW winding).
    #[inline(always)]
    pub fn geometric_normal(&self) -> Vec3 {
        Self::normal_of(&self.v)
    }

    /// The geometric normal of a triangle with vertices `v`.
    #[inline(always)]
    pub fn normal_of(v: &[Vec3; 3]) -> Vec3 {
        (v[1] - v[0]).cross(v[2] - v[0]).normalize()
    }

    /// The geometric normal of a triangle with vertices `v`, made exactly as
    /// `geometric_normal` makes it (so that the scene can store flat
    /// triangles' normals as a flag, `Triangles`), or `None` where it cannot
    /// be formed: the
    /// triangle covers no area, or its sides overflow. Mesh readers skip
    /// such triangles and count them.
    pub fn normal_if_not_degenerate(v: &[Vec3; 3]) -> Option<Vec3> {
        let geo = (v[1] - v[0]).cross(v[2] - v[0]);
        let len = geo.length();
        (len > 0.0 && (geo / len).is_finite()).then(|| Triangle::normal_of(v))
    }

    /// Flat-shaded: every corner's normal is exactly (bit for bit) the
    /// geometric normal, so it can be recomputed instead of stored.
    pub fn is_flat(&self) -> bool {
        self.normals_are(self.geometric_normal())
    }

    /// Whether every corner's normal is `n`, bit for bit.
    #[inline]
    pub fn normals_are(&self, n: Vec3) -> bool {
        let bits = n.to_array().map(f32::to_bits);
        self.n.iter().all(|c| c.to_array().map(f32::to_bits) == bits)
    }

    pub fn area(&self) -> f32 {
        0.5 * (self.v[1] - self.v[0]).cross(self.v[2] - self.v[0]).length()
    }
}

/// An analytic sphere: never tessellated.
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub material: u32,
    pub object: u32,
}

/// What kind of primitive a hit or an id refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PrimitiveKind {
    Triangle,
    Sphere,
    /// A constructive solid geometry object (`Scene::csgs`): the surface
    /// is one of its operands', which the hit's material and normal describe.
    Csg,
}

/// One primitive named by a single integer: a triangle index, a sphere
/// index with the top bit set, or a CSG object's index with the top two bits
/// set. Compared as integers, ids order primitives as the brute-force caster
/// scans them (every triangle, then every sphere, then every CSG object, each
/// by index), which is the order every renderer's tie rule follows. `NONE`
/// names no primitive (an empty buffer entry, no hit yet) and compares above
/// every real id.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct PrimitiveId(u32);

// SAFETY: a transparent wrapper of a u32 that any 32 bits make (the kind
// and index are read from the bits): packets compare ids eight lanes at a
// time as u32 lanes.
unsafe impl bytemuck::Zeroable for PrimitiveId {}
unsafe impl bytemuck::Pod for PrimitiveId {}

impl PrimitiveId {
    const SPHERE_BIT: u32 = 1 << 31;
    const CSG_BITS: u32 = 3 << 30;
    /// No primitive.
    pub const NONE: PrimitiveId = PrimitiveId(u32::MAX);

    /// Triangle `index` of `Scene::triangles` (below 2^30).
    #[inline(always)]
    pub const fn triangle(index: u32) -> PrimitiveId {
        PrimitiveId(index)
    }

    /// Sphere `index` of `Scene::spheres` (below 2^30).
    #[inline(always)]
    pub const fn sphere(index: u32) -> PrimitiveId {
        PrimitiveId(index | Self::SPHERE_BIT)
    }

    /// CSG object `index` of `Scene::csgs` (below 2^30 - 1).
    #[inline(always)]
    pub const fn csg(index: u32) -> PrimitiveId {
        PrimitiveId(index | Self::CSG_BITS)
    }

    #[inline(always)]
    pub fn new(kind: PrimitiveKind, index: u32) -> PrimitiveId {
        match kind {
            PrimitiveKind::Triangle => PrimitiveId::triangle(index),
            PrimitiveKind::Sphere => PrimitiveId::sphere(index),
            PrimitiveKind::Csg => PrimitiveId::csg(index),
        }
    }

    #[inline(always)]
    pub fn is_none(self) -> bool {
        self == PrimitiveId::NONE
    }

    /// A sphere (false for `NONE`, CSG objects and triangles).
    #[inline(always)]
    pub fn is_sphere(self) -> bool {
        self.0 & Self::CSG_BITS == Self::SPHERE_BIT
    }

    /// A CSG object (false for `NONE`).
    #[inline(always)]
    pub fn is_csg(self) -> bool {
        self.0 & Self::CSG_BITS == Self::CSG_BITS && !self.is_none()
    }

    /// The kind of primitive (meaningless for `NONE`).
    #[inline(always)]
    pub fn kind(self) -> PrimitiveKind {
        match self.0 & Self::CSG_BITS {
            Self::CSG_BITS => PrimitiveKind::Csg,
            Self::SPHERE_BIT => PrimitiveKind::Sphere,
            _ => PrimitiveKind::Triangle,
        }
    }

    /// Index into `Scene::triangles`, `Scene::spheres` or `Scene::csgs`
    /// (meaningless for `NONE`).
    #[inline(always)]
    pub fn index(self) -> u32 {
        self.0 & !Self::CSG_BITS
    }

    /// Kind and index, `None` for `NONE`.
    #[inline(always)]
    pub fn decode(self) -> Option<(PrimitiveKind, u32)> {
        (!self.is_none()).then(|| (self.kind(), self.index()))
    }

    /// The id's bits, as buffers of ids hold them.
    #[inline(always)]
    pub fn bits(self) -> u32 {
        self.0
    }

    /// Whether every one of `ids` is `NONE`: one test of all their bits
    /// together (`NONE` is the only id with every bit set).
    #[inline(always)]
    pub fn all_none<const N: usize>(ids: &[PrimitiveId; N]) -> bool {
        ids.iter().fold(u32::MAX, |all, id| all & id.0) == u32::MAX
    }

    /// The triangle indices of `ids` when every one is a triangle, else
    /// `None` (a sphere, a CSG object or `NONE` among them). One test of
    /// the kind bits of all of them together: a triangle's are clear, and
    /// its id is its index.
    #[inline(always)]
    pub fn triangle_indices<const N: usize>(ids: &[PrimitiveId; N]) -> Option<[u32; N]> {
        let bits = ids.map(|id| id.0);
        (bits.iter().fold(0, |kinds, b| kinds | b) & Self::CSG_BITS == 0).then_some(bits)
    }
}

/// One `[[object]]` of the scene file, for id views and the inspector.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectInfo {
    pub name: String,
    pub kind: String,
    /// Range of this object's triangles in `Scene::triangles` (empty for spheres).
    pub triangles: std::ops::Range<usize>,
}

/// A named part of an object (a glTF node's mesh): its flattened triangles,
/// or one of its object's copies in the instance layer.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedPart {
    /// Index into `Scene::objects`.
    pub object: u32,
    pub what: PartOf,
    pub name: String,
}

/// Where a named part's triangles are.
#[derive(Clone, Debug, PartialEq)]
pub enum PartOf {
    /// A range of `Scene::triangles`.
    Triangles(std::ops::Range<usize>),
    /// The object's copy with this `InstanceInfo::index`.
    Copy(u32),
}

/// One copy made by a mesh object's `instances` list: where its triangles
/// lie in `Scene::triangles`, and the sphere around them that rasterizers
/// cull it by.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceInfo {
    /// The `[[object]]` it is a copy of (index into `Scene::objects`).
    pub object: u32,
    /// Its position in that object's `instances` list.
    pub index: u32,
    pub triangles: std::ops::Range<usize>,
    pub center: Vec3,
    /// Holds every vertex of the copy (rounded up).
    pub radius: f32,
}

impl InstanceInfo {
    /// The record of copy `index` of `object`, whose world-space triangles are
    /// `tris`, found at `range` of `Scene::triangles`.
    pub fn new(object: u32, index: u32, range: std::ops::Range<usize>, tris: impl Iterator<Item = Triangle> + Clone) -> InstanceInfo {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for t in tris.clone() {
            for v in t.v {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        let (center, radius) = if lo.x <= hi.x {
            let center = (lo + hi) * 0.5;
            let r2 = tris.flat_map(|t| t.v).map(|v| (v - center).length_squared()).fold(0.0f32, f32::max);
            // Grown a little, so that rounding in the distance never leaves a vertex outside.
            (center, r2.sqrt() * (1.0 + 1e-5) + 1e-6 * center.abs().max_element())
        } else {
            (Vec3::ZERO, 0.0)
        };
        InstanceInfo { object, index, triangles: range, center, radius }
    }
}

/// How a scene's lights and lobes are read (`[render] lighting`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Lighting {
    /// Radiometric: a point light's `power` falls off as `1 / (4 pi d^2)`,
    /// lobes are normalized, `mirror` adds its reflection.
    #[default]
    Physical,
    /// Computer Graphics from Scratch's model: a light's `power` or
    /// `irradiance` is an intensity that does not fall off with distance,
    /// the diffuse lobe reflects `k_L cos` (no `1 / pi`), the glossy lobe is
    /// the raw power `k_G c^s` (no normalization, no cosine), and `mirror`
    /// is the book's `reflective` r: the colour is `(1 - r) local + r
    /// reflected` (the local colour alone where the recursion stops).
    Classic,
}

impl Lighting {
    /// The names a scene file gives the models.
    pub const NAMES: [&'static str; 2] = ["physical", "classic"];

    pub fn name(self) -> &'static str {
        match self {
            Lighting::Physical => "physical",
            Lighting::Classic => "classic",
        }
    }

    pub fn parse(name: &str) -> Option<Lighting> {
        match name {
            "physical" => Some(Lighting::Physical),
            "classic" => Some(Lighting::Classic),
            _ => None,
        }
    }
}

/// Image and display settings from `[render]`.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderDefaults {
    pub width: u32,
    pub height: u32,
    pub background: Vec3,
    pub ambient: Vec3,
    pub exposure: f32,
    /// How lights and lobes are read: physically, or as Computer Graphics
    /// from Scratch's classic model.
    pub lighting: Lighting,
    /// A ground-truth image (linear EXR of this size) that charts measure
    /// error against; the path is resolved against the scene file's folder.
    pub reference: Option<std::path::PathBuf>,
}

impl Default for RenderDefaults {
    fn default() -> Self {
        RenderDefaults {
            width: 800,
            height: 500,
            background: Vec3::new(0.0, 0.0, 0.1),
            ambient: Vec3::ZERO,
            exposure: 1.0,
            lighting: Lighting::Physical,
            reference: None,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// A name to show and to build file names from (the file stem or built-in name).
    pub name: String,
    pub camera: Camera,
    pub render: RenderDefaults,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub triangles: Triangles,
    pub spheres: Vec<Sphere>,
    /// Constructive solid geometry objects, kept apart from the triangles
    /// and spheres (`render::accel::csg` answers rays for them).
    pub csgs: Vec<csg::Csg>,
    pub objects: Vec<ObjectInfo>,
    /// The copies made by `instances` lists, in the order of their triangles.
    pub instances: Vec<InstanceInfo>,
    /// Copies not flattened into `triangles` (`instanced`): their triangles
    /// have the indices after `triangles`, read through `Scene::triangle`.
    pub layer: Option<std::sync::Arc<instanced::InstanceLayer>>,
    /// Things worth telling the user that did not stop the scene loading.
    pub warnings: Vec<String>,
    /// `[environment]`: what rays that hit nothing see instead of `background`.
    pub environment: Option<environment::Environment>,
    /// Per triangle, per corner: the normal map's tangent frame
    /// (`tangents::build_tangents`); empty when no material has a normal map.
    pub tangents: Vec<[glam::Vec4; 3]>,
    /// Cameras a loaded file offers by name (a glTF's), for `--camera` and
    /// the viewer's camera list; `camera` is the one in use.
    pub named_cameras: Vec<(String, Camera)>,
    /// Names of the parts of objects read from other formats (a glTF's
    /// node and mesh), for the inspector.
    pub parts: Vec<NamedPart>,
    /// Per flattened triangle, per corner: a linear colour multiplying the
    /// material's base colour (a glTF's `COLOR_0`). Triangles past its end
    /// have none (white); empty when no file gives colours.
    pub vertex_colours: Vec<[Vec3; 3]>,
    /// Per flattened triangle, per corner: the tangent (xyz, world space)
    /// and handedness (w) a file gives (a glTF's `TANGENT`), which
    /// `tangents::build_tangents` takes instead of the uvs' frame. Zero
    /// where none is given, and triangles past its end have none; empty
    /// when no file gives tangents.
    pub given_tangents: Vec<[glam::Vec4; 3]>,
    /// The emissive triangles and spheres, gathered by `refresh_emitters`
    /// (after loading, and whenever materials or geometry change).
    pub emitters: std::sync::Arc<emitters::Emitters>,
}

/// Everything a renderer found about the surface a sample sees. Renderers
/// answer visibility only; `shade()` turns this into radiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub position: Vec3,
    /// Unit geometric normal, flipped towards the viewer on two-sided surfaces.
    pub geometric_normal: Vec3,
    /// Unit interpolated shading normal, flipped with the geometric one.
    pub shading_normal: Vec3,
    pub barycentric: Vec3,
    pub uv: Vec2,
    /// Ray parameter of the hit (distance from the ray origin, rays being unit).
    pub t: f32,
    pub kind: PrimitiveKind,
    /// Index into `Scene::triangles` or `Scene::spheres`.
    pub primitive: u32,
    pub object: u32,
    pub material: u32,
    /// True when the surface was hit from its back (two-sided surfaces only).
    pub back_face: bool,
    /// How position, direction and uv change from this pixel to the next
    /// (zero when not tracked): the texture level of detail and the
    /// differentials of reflected rays come from here.
    pub diff: Differentials,
}

/// Derivatives with respect to the image position (x right, y down, in
/// pixels) of a sample's hit point, of the direction of the ray that found
/// it, and of the hit's uv. Ray casters carry ray differentials (Igehy
/// 1999) to the hit; rasterizers differentiate their perspective-correct
/// interpolation. All zero: no footprint (the finest texture level).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Differentials {
    pub dp_dx: Vec3,
    pub dp_dy: Vec3,
    pub dd_dx: Vec3,
    pub dd_dy: Vec3,
    pub duv_dx: Vec2,
    pub duv_dy: Vec2,
}

impl Differentials {
    pub const ZERO: Differentials = Differentials {
        dp_dx: Vec3::ZERO,
        dp_dy: Vec3::ZERO,
        dd_dx: Vec3::ZERO,
        dd_dy: Vec3::ZERO,
        duv_dx: Vec2::ZERO,
        duv_dy: Vec2::ZERO,
    };

    /// The texture footprint these derivatives give.
    #[inline]
    pub fn footprint(&self) -> texture::Footprint {
        texture::Footprint { duv_dx: self.duv_dx, duv_dy: self.duv_dy }
    }
}

/// Rays leaving a surface start a little off it, so that rounding cannot
/// make them hit the very surface they leave (CGPP's `rayBumpEpsilon`,
/// listing 15.20). Each kind of ray has its own offset, kept in one place.
impl SurfaceHit {
    /// A ray towards unit `dir` whose origin is the hit point moved `bump`
    /// along `dir` itself (shadow rays).
    #[inline]
    pub fn spawn_ray_along(&self, dir: Vec3, bump: f32) -> Ray {
        Ray::new(self.position + dir * bump, dir)
    }

    /// A ray towards `dir` whose origin is the hit point moved `bump` along
    /// the geometric normal, to the side the surface was seen from (mirror
    /// reflections).
    #[inline]
    pub fn spawn_ray_front(&self, dir: Vec3, bump: f32) -> Ray {
        Ray::new(self.position + self.geometric_normal * bump, dir)
    }

    /// A ray towards `dir` whose origin is the hit point moved `bump` against
    /// the geometric normal, through to the surface's far side (refraction).
    #[inline]
    pub fn spawn_ray_back(&self, dir: Vec3, bump: f32) -> Ray {
        Ray::new(self.position - self.geometric_normal * bump, dir)
    }
}

impl Scene {
    /// Whether some material reads a texture or normal map: only then do
    /// renderers work out their samples' footprints (`SurfaceHit::diff`).
    pub fn has_textures(&self) -> bool {
        self.materials.iter().any(|m| m.texture.is_some() || m.normal_map.is_some())
    }

    /// Gathers the emissive surfaces again (materials or geometry changed).
    pub fn refresh_emitters(&mut self) {
        self.emitters = std::sync::Arc::new(emitters::Emitters::build(self));
    }

    /// Whether direct light is sampled (area lights or an environment)
    /// besides the point and directional lights that `direct_light` sums.
    #[inline]
    pub fn has_sampled_lights(&self) -> bool {
        !self.emitters.is_empty() || self.environment.as_ref().is_some_and(|e| e.is_light())
    }

    /// The radiance a ray along unit `dir` sees when it hits nothing.
    #[inline]
    pub fn miss_radiance(&self, dir: Vec3) -> Vec3 {
        match &self.environment {
            Some(env) => env.radiance(dir),
            None => self.render.background,
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// For each material, whether anything drawn uses it: triangles,
    /// spheres, CSG leaves and the instance layer's copies. A material only
    /// named in `[materials]` is not asked of any renderer.
    pub fn materials_in_use(&self) -> Vec<bool> {
        let mut used = vec![false; self.materials.len()];
        let mut mark = |m: u32| {
            if let Some(u) = used.get_mut(m as usize) {
                *u = true;
            }
        };
        self.triangles.materials().for_each(&mut mark);
        self.spheres.iter().for_each(|s| mark(s.material));
        for c in &self.csgs {
            c.spheres.iter().for_each(|s| mark(s.material));
            c.triangles.iter().for_each(|t| mark(t.material));
        }
        if let Some(layer) = &self.layer {
            // A mesh shared by thousands of copies is walked once, not once
            // per copy.
            let mut mesh_marked = vec![false; layer.meshes.len()];
            for inst in &layer.instances {
                match inst.material {
                    Some(m) => mark(m),
                    None if !mesh_marked[inst.mesh as usize] => {
                        mesh_marked[inst.mesh as usize] = true;
                        layer.meshes[inst.mesh as usize].iter().for_each(|t| mark(t.material));
                    }
                    None => {}
                }
            }
        }
        used
    }

    /// Triangles drawn, the two-level layer's included.
    pub fn total_triangles(&self) -> u64 {
        self.triangles.len() as u64 + self.layer.as_ref().map_or(0, |l| l.triangle_count())
    }

    /// Triangle `index` in world space: a flattened one, or one of the
    /// two-level layer made as flattening would make it.
    #[inline]
    pub fn triangle(&self, index: u32) -> Triangle {
        match self.triangles.get(index as usize) {
            Some(t) => t,
            None => {
                let layer = self.layer.as_ref().expect("a triangle index past the scene's triangles");
                let (inst, local) = layer.locate(index).expect("a triangle index past the two-level layer");
                layer.world(inst, local)
            }
        }
    }

    /// Whether triangle `index` is cut away where its barycentric weights
    /// of v1 and v2 are `b1` and `b2` (its material's alpha there is below
    /// the cutoff): a ray meeting it there passes through.
    pub fn cut_out_at(&self, index: u32, b1: f32, b2: f32) -> bool {
        let tri = self.triangle(index);
        match self.materials.get(tri.material as usize) {
            Some(m) if m.cutout.is_some() => m.cut_out_at(tri.uv[0] * (1.0 - b1 - b2) + tri.uv[1] * b1 + tri.uv[2] * b2),
            _ => false,
        }
    }

    /// Whether any material has a cutout, so ray queries must look at the
    /// alpha of what they meet.
    pub fn has_cutouts(&self) -> bool {
        self.materials.iter().any(|m| m.cutout.is_some())
    }

    /// The vertex positions of `triangle(index)`, without its other attributes.
    #[inline]
    pub fn triangle_positions(&self, index: u32) -> [Vec3; 3] {
        if (index as usize) < self.triangles.len() {
            self.triangles.positions(index as usize)
        } else {
            self.triangle(index).v
        }
    }

    /// World-space bounds of all geometry, `None` for an empty scene.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for t in &self.triangles {
            for v in t.v {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        for s in &self.spheres {
            lo = lo.min(s.center - Vec3::splat(s.radius));
            hi = hi.max(s.center + Vec3::splat(s.radius));
        }
        // Copies of the two-level layer, by their bounding spheres.
        for i in self.instances.iter().filter(|i| i.triangles.start >= self.triangles.len()) {
            lo = lo.min(i.center - Vec3::splat(i.radius));
            hi = hi.max(i.center + Vec3::splat(i.radius));
        }
        for c in &self.csgs {
            lo = lo.min(c.lo);
            hi = hi.max(c.hi);
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }

    /// The surface record for a ray that hit triangle `index` with barycentric
    /// weights `b` (of v0, v1, v2) at parameter `t`. Both the ray tracer and the
    /// rasterizer build their hits here, so identical visibility gives identical
    /// shading inputs.
    pub fn triangle_hit(&self, index: u32, b: Vec3, t: f32, ray: &Ray) -> SurfaceHit {
        // A flattened triangle is assembled from its shared corners; a copy
        // of the two-level layer is placed in world space first.
        match self.triangles.get(index as usize) {
            Some(tri) => Self::hit_on(&tri, index, b, t, ray),
            None => Self::hit_on(&self.triangle(index), index, b, t, ray),
        }
    }

    /// `triangle_hit` on the world-space triangle `tri`.
    #[inline(always)]
    fn hit_on(tri: &Triangle, index: u32, b: Vec3, t: f32, ray: &Ray) -> SurfaceHit {
        let position = tri.v[0] * b.x + tri.v[1] * b.y + tri.v[2] * b.z;
        let mut geometric_normal = tri.geometric_normal();
        // A flat triangle's normals are all the geometric one: its shading
        // normal is that, not a blend of three equal vectors renormalised
        // (which only adds rounding, and a square root per hit).
        let mut shading_normal = if tri.normals_are(geometric_normal) { geometric_normal } else { (tri.n[0] * b.x + tri.n[1] * b.y + tri.n[2] * b.z).normalize_or(geometric_normal) };
        let back_face = geometric_normal.dot(ray.dir) > 0.0;
        if back_face {
            geometric_normal = -geometric_normal;
            shading_normal = -shading_normal;
        }
        SurfaceHit {
            position,
            geometric_normal,
            shading_normal,
            barycentric: b,
            uv: tri.uv[0] * b.x + tri.uv[1] * b.y + tri.uv[2] * b.z,
            t,
            kind: PrimitiveKind::Triangle,
            primitive: index,
            object: tri.object,
            material: tri.material,
            back_face,
            diff: Differentials::ZERO,
        }
    }

    /// The surface record for a ray that hit sphere `index` at parameter `t`.
    pub fn sphere_hit(&self, index: u32, t: f32, ray: &Ray) -> SurfaceHit {
        let s = &self.spheres[index as usize];
        let position = ray.at(t);
        let outward = (position - s.center) / s.radius;
        let back_face = outward.dot(ray.dir) > 0.0;
        let n = if back_face { -outward } else { outward };
        // Spherical uv: u around +y, v from the south pole up.
        let u = 0.5 + outward.z.atan2(outward.x) * -0.5 * std::f32::consts::FRAC_1_PI;
        let v = 0.5 + outward.y.clamp(-1.0, 1.0).asin() * std::f32::consts::FRAC_1_PI;
        SurfaceHit {
            position,
            geometric_normal: n,
            shading_normal: n,
            barycentric: Vec3::ZERO,
            uv: Vec2::new(u, v),
            t,
            kind: PrimitiveKind::Sphere,
            primitive: index,
            object: s.object,
            material: s.material,
            back_face,
            diff: Differentials::ZERO,
        }
    }


    /// The copy (from an `instances` list) that triangle `index` belongs to.
    pub fn instance_of_triangle(&self, index: u32) -> Option<&InstanceInfo> {
        let index = index as usize;
        let k = self.instances.partition_point(|i| i.triangles.end <= index);
        self.instances.get(k).filter(|i| i.triangles.contains(&index))
    }

    /// The vertex colour at a hit (white where there is none).
    #[inline]
    pub fn vertex_colour(&self, kind: PrimitiveKind, index: u32, b: Vec3) -> Vec3 {
        if kind != PrimitiveKind::Triangle {
            return Vec3::ONE;
        }
        let c = match self.vertex_colours.get(index as usize) {
            Some(c) => *c,
            // A copy in the two-level layer: its shared mesh's colours.
            None if index as usize >= self.triangles.len() => {
                let Some(layer) = self.layer.as_ref().filter(|l| !l.colours.is_empty()) else { return Vec3::ONE };
                match layer.locate(index).and_then(|(inst, local)| layer.world_colours(inst, local)) {
                    Some(c) => c,
                    None => return Vec3::ONE,
                }
            }
            None => return Vec3::ONE,
        };
        c[0] * b.x + c[1] * b.y + c[2] * b.z
    }

    /// Whether any triangle, flattened or in the layer, has vertex colours.
    pub fn has_vertex_colours(&self) -> bool {
        !self.vertex_colours.is_empty() || self.layer.as_ref().is_some_and(|l| l.colours.iter().any(Option::is_some))
    }

    /// The name of the part (a glTF node and mesh) triangle `index` belongs to, if it has one.
    pub fn part_name(&self, index: u32) -> Option<&str> {
        if self.parts.is_empty() {
            return None;
        }
        let found = match self.instance_of_triangle(index) {
            Some(copy) => self.parts.iter().find(|p| p.object == copy.object && p.what == PartOf::Copy(copy.index)),
            None => self.parts.iter().find(|p| matches!(&p.what, PartOf::Triangles(r) if r.contains(&(index as usize)))),
        };
        found.map(|p| p.name.as_str())
    }

    /// A copy's name: its object's name and its position in the object's list.
    pub fn instance_name(&self, instance: &InstanceInfo) -> String {
        let object = self.objects.get(instance.object as usize).map_or("?", |o| o.name.as_str());
        format!("{object} instance {}", instance.index)
    }

    /// A default grey Lambertian material, added on demand.
    pub fn default_material_index(&mut self) -> u32 {
        if let Some(i) = self.materials.iter().position(|m| m.name == material::DEFAULT_MATERIAL) {
            return i as u32;
        }
        self.materials.push(Material::default_grey());
        (self.materials.len() - 1) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primitive_ids_encode_kind_and_index_in_scan_order() {
        let (t, s) = (PrimitiveId::triangle(7), PrimitiveId::sphere(3));
        assert_eq!(t.decode(), Some((PrimitiveKind::Triangle, 7)));
        assert_eq!(s.decode(), Some((PrimitiveKind::Sphere, 3)));
        assert_eq!(PrimitiveId::new(PrimitiveKind::Sphere, 3), s);
        assert_eq!(PrimitiveId::NONE.decode(), None);
        assert!(PrimitiveId::NONE.is_none() && !t.is_none() && !s.is_none());
        // Every triangle before every sphere, each by index; NONE above all.
        assert!(PrimitiveId::triangle(6) < t && t < PrimitiveId::triangle(u32::MAX >> 1));
        assert!(PrimitiveId::triangle(u32::MAX >> 1) < PrimitiveId::sphere(0) && PrimitiveId::sphere(0) < s);
        let c = PrimitiveId::csg(2);
        assert_eq!(c.decode(), Some((PrimitiveKind::Csg, 2)));
        assert!(c.is_csg() && !c.is_sphere() && !s.is_csg() && !t.is_csg() && !PrimitiveId::NONE.is_csg());
        assert!(s < c && c < PrimitiveId::NONE);
        assert!(s < PrimitiveId::NONE);
    }

    #[test]
    fn all_none_only_when_every_id_is_none() {
        assert!(PrimitiveId::all_none(&[PrimitiveId::NONE; 16]));
        for other in [PrimitiveId::triangle(0), PrimitiveId::triangle((1 << 30) - 1), PrimitiveId::sphere((1 << 30) - 1), PrimitiveId::csg(4)] {
            for k in [0, 9, 15] {
                let mut ids = [PrimitiveId::NONE; 16];
                ids[k] = other;
                assert!(!PrimitiveId::all_none(&ids), "{other:?} in lane {k}");
            }
        }
    }

    #[test]
    fn triangle_indices_only_of_triangles() {
        let ids = [3, 0, 9, 9, 1 << 29, 4, 5, 6].map(PrimitiveId::triangle);
        assert_eq!(PrimitiveId::triangle_indices(&ids), Some([3, 0, 9, 9, 1 << 29, 4, 5, 6]));
        for other in [PrimitiveId::sphere(0), PrimitiveId::csg(4), PrimitiveId::NONE] {
            for k in [0, 7] {
                let mut mixed = ids;
                mixed[k] = other;
                assert_eq!(PrimitiveId::triangle_indices(&mixed), None, "{other:?} in lane {k}");
            }
        }
    }
}
