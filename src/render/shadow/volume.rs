//! Stencil shadow volumes (Computer Graphics from Scratch, ch. 15 "Shadows";
//! Crow 1977, Heidmann 1991, Carmack's z-fail): for every light, the closed
//! solid of space its casters hide from it; a point lies in shadow when it
//! lies inside at least one such solid. `--shadows volume` decides light
//! visibility that way for the surface the eye sees.
//!
//! Construction (`light_volume`, once per scene and lights, cached on
//! `PreparedScene` like the shadow maps):
//! - The casters are what a shadow ray can hit: two-sided triangles that are
//!   not edge-on to the light, one-sided triangles only when they face away
//!   from it (a shadow ray, travelling towards the light, meets only front
//!   faces), and spheres. Each caster is wound to face the light.
//! - Every caster triangle `abc` gets its own closed volume: the front cap
//!   `abc` itself, the back cap (the triangle extruded away from the light,
//!   wound the other way) and one quad per edge joining the two, all faces
//!   wound so their normals point out of the volume. Per-triangle volumes are
//!   correct for any mesh, open or non-manifold: a point's count is the
//!   number of casters that hide the light from it, whatever the topology.
//!   Where two casters share an edge in opposite directions their side quads
//!   coincide with opposite windings and cancel in every count, so they are
//!   dropped: what stays of the sides is the silhouette of the lit set (its
//!   edges between casters and non-casters, and its open boundary), the
//!   classic construction for closed meshes, found without knowing whether
//!   the mesh is closed.
//! - A sphere casts the disk bounded by its silhouette circle as seen from the
//!   light (tessellated into `SPHERE_SEGMENTS` fan triangles with their
//!   corners on the circle), which goes through the same construction; the
//!   fan's inner edges cancel and the rim is extruded. Both families count
//!   the same polygons, so they agree; the tessellation shrinks a sphere's
//!   shadow by at most `1 - cos(pi / SPHERE_SEGMENTS)` (8e-5) of its radius.
//!   A point light inside a sphere casts nothing from that sphere.
//! - "Infinity" is finite: directional lights extrude along the direction by
//!   four diagonals of the scene's box, point lights away from the light to
//!   four times the farthest corner of the box, so every volume reaches well
//!   beyond anything visible.
//!
//! Counting, for the eye sample seeing a surface at ray parameter `t` (the
//! eye ray starting on the near plane): faces the ray enters through (front
//! faces, seen from the eye) and leaves through (back faces) are counted on
//! one side of the *split depth* `t (1 - DEPTH_BIAS)`:
//! - z-pass counts front faces +1 and back faces -1 in front of it. Wrong
//!   when the eye (the near plane) is inside a volume: the entry is missed.
//! - z-fail counts back faces +1 and front faces -1 behind it. Right
//!   wherever the eye is, because every volume is closed by its caps.
//!
//! Nonzero is shadow. The bias: a lit surface point lies exactly on the
//! front cap of its own triangle's volume (a two-sided floor facing the
//! light), so the split is pulled towards the eye by 0.1% of the hit's
//! distance, as engines offset the volume's depth; the cap then counts as
//! behind the surface, and the point outside the volume.
//!
//! Where counts come from: the rasterizers rasterize each light's volume
//! faces into a per-pixel stencil count after their depth pass
//! (`raster::stencil`); the ray casters count crossings along the eye ray
//! through a BVH over the volume faces (`ShadowVolumes::count`). Either way
//! the counts reach `shade()` through `shadow::ApproximateShadows`, which answers the
//! primary surface only (`depth == 0`, with Gouraud its vertices, masked by
//! the pixel's count as a stencil masks them). Every secondary hit (mirror,
//! glass, indirect bounces) has no stencil and casts shadow rays instead.

use crate::render::keyed_cache::{KeyedCache, ThreadCopy};
use crate::render::accel::bvh::Bvh;
use crate::render::accel::intersect::{intersect_triangle, TriangleEdges};
use crate::render::{PreparedScene, RenderSettings};
use crate::math::{Ray, Vec2, Vec3};
use crate::named::named_enum;
use crate::scene::{Light, Scene, Sphere, Triangle};
use std::sync::Arc;
use std::time::Instant;

named_enum! {
    /// Which side of the visible surface the volume faces are counted on.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum VolumeMode ("shadow volume mode") {
        /// Faces in front of the surface (fails with the eye inside a volume).
        ZPass = "zpass",
        /// Faces behind the surface (Carmack's reverse; needs the caps).
        #[default]
        ZFail = "zfail",
    }
}

/// Triangles of the fan that stands for a sphere's silhouette disk.
pub const SPHERE_SEGMENTS: usize = 256;
/// How far, relative to the hit's distance, the split depth lies in front of
/// the visible surface (see the module documentation).
pub const DEPTH_BIAS: f32 = 1e-3;
/// Extrusion length, in scene-box diagonals (directional) or farthest-corner
/// distances (point).
const EXTRUSION: f32 = 4.0;

/// The depth that divides "in front of the surface" from "behind it" for a
/// sample whose eye ray hits at ray parameter `t`.
#[inline]
pub fn split_depth(t: f32) -> f32 {
    t * (1.0 - DEPTH_BIAS)
}

/// The change of a count when the eye ray crosses a volume face at ray
/// parameter `t`, `entering` when it crosses from outside (a front face).
#[inline(always)]
pub fn crossing(mode: VolumeMode, t: f32, split: f32, entering: bool) -> i32 {
    match mode {
        VolumeMode::ZPass if t < split => if entering { 1 } else { -1 },
        VolumeMode::ZFail if t > split => if entering { -1 } else { 1 },
        _ => 0,
    }
}

/// The volume of one light: its faces, wound outwards, and a BVH over them.
pub struct LightVolume {
    pub faces: Vec<[Vec3; 3]>,
    edges: Vec<TriangleEdges>,
    bvh: Bvh,
}

impl LightVolume {
    fn new(faces: Vec<[Vec3; 3]>) -> LightVolume {
        let mut holder = Scene::default();
        holder.triangles = faces
            .iter()
            .map(|&v| Triangle { v, n: [Vec3::Z; 3], uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided: true })
            .collect();
        let edges: Vec<TriangleEdges> = holder.triangles.iter().map(|t| TriangleEdges::new(&t)).collect();
        let bvh = Bvh::build(&holder, &edges);
        LightVolume { faces, edges, bvh }
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }
}

/// The shadow volumes of every light of a scene, in scene order.
pub struct ShadowVolumes {
    /// The lights they were built for (the cache key).
    pub lights: Vec<Light>,
    pub volumes: Vec<LightVolume>,
    /// Time to build them all, milliseconds.
    pub build_ms: f64,
}

impl ShadowVolumes {
    pub fn build(scene: &Scene) -> ShadowVolumes {
        let start = Instant::now();
        let volumes = scene.lights.iter().map(|l| LightVolume::new(light_volume(scene, l))).collect();
        ShadowVolumes { lights: scene.lights.clone(), volumes, build_ms: start.elapsed().as_secs_f64() * 1e3 }
    }

    #[inline]
    pub fn matches(&self, scene: &Scene) -> bool {
        self.lights == scene.lights
    }

    /// The count of light `light`'s volume along `ray` for a surface at ray
    /// parameter `t_hit` (the ray casters' stencil): crossings found with the
    /// ray caster's own triangle test, signed by `crossing`.
    pub fn count(&self, light: usize, ray: &Ray, t_hit: f32, mode: VolumeMode) -> i32 {
        self.count_split(light, ray, split_depth(t_hit), mode)
    }

    /// As `count`, with the split depth given.
    fn count_split(&self, light: usize, ray: &Ray, split: f32, mode: VolumeMode) -> i32 {
        let Some(v) = self.volumes.get(light) else { return 0 };
        let t_max = if mode == VolumeMode::ZPass { split } else { f32::INFINITY };
        let mut n = 0;
        v.bvh.for_each_candidate(ray, t_max, |e, _| {
            if let Ok((t, _, _)) = intersect_triangle(ray, e, f32::INFINITY) {
                n += crossing(mode, t, split, e.e1.cross(e.e2).dot(ray.dir) < 0.0);
            }
        });
        n
    }

    /// Whether `p` lies inside light `light`'s volume: the z-pass count of a
    /// ray from far outside every volume to `p` (for tests and tools).
    pub fn contains(&self, light: usize, p: Vec3) -> bool {
        let Some(v) = self.volumes.get(light) else { return false };
        let far = v.faces.iter().flatten().fold(1.0f32, |m, q| m.max((*q - p).length()));
        // An odd direction, so the ray does not run along faces or through edges.
        let dir = Vec3::new(0.3127, 0.8211, 0.4771).normalize();
        let origin = p + dir * (2.0 * far);
        let ray = Ray::new(origin, -dir);
        self.count_split(light, &ray, 2.0 * far, VolumeMode::ZPass) != 0
    }
}

/// Where vertex `p` goes when extruded away from `light` to "infinity".
struct Extrude {
    point: Option<Vec3>,
    along: Vec3,
    reach: f32,
}

impl Extrude {
    fn new(scene: &Scene, light: &Light) -> Option<Extrude> {
        let (lo, hi) = scene.bounds()?;
        Some(match *light {
            Light::Point { position, .. } => {
                let far = (0..8)
                    .map(|i| Vec3::new(if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z }))
                    .map(|c| (c - position).length())
                    .fold(0.0f32, f32::max);
                Extrude { point: Some(position), along: Vec3::ZERO, reach: EXTRUSION * far + 1.0 }
            }
            Light::Directional { direction, .. } => {
                Extrude { point: None, along: direction.normalize_or(Vec3::NEG_Y), reach: EXTRUSION * (hi - lo).length() + 1.0 }
            }
        })
    }

    /// Direction from `p` towards the light (not normalized for point lights).
    #[inline]
    fn toward_light(&self, p: Vec3) -> Vec3 {
        match self.point {
            Some(l) => l - p,
            None => -self.along,
        }
    }

    #[inline]
    fn far(&self, p: Vec3) -> Vec3 {
        match self.point {
            Some(l) => l + (p - l).normalize_or_zero() * self.reach,
            None => p + self.along * self.reach,
        }
    }
}

/// A vertex position as a hashable key (-0 and +0 alike).
fn key(p: Vec3) -> [u32; 3] {
    [(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits(), (p.z + 0.0).to_bits()]
}

/// The faces of light `light`'s shadow volume (see the module documentation).
pub fn light_volume(scene: &Scene, light: &Light) -> Vec<[Vec3; 3]> {
    let Some(ex) = Extrude::new(scene, light) else { return Vec::new() };
    let mut casters: Vec<[Vec3; 3]> = Vec::new();
    for t in &scene.triangles {
        let [a, b, c] = t.v;
        let facing = (b - a).cross(c - a).dot(ex.toward_light(a));
        if !facing.is_finite() || facing == 0.0 {
            continue;
        }
        if facing > 0.0 && t.two_sided {
            casters.push([a, b, c]);
        } else if facing < 0.0 {
            casters.push([a, c, b]);
        }
    }
    for s in &scene.spheres {
        sphere_disk(s, &ex, &mut casters);
    }
    volume_of_casters(&casters, &ex)
}

/// The fan of triangles covering sphere `s`'s silhouette disk, facing the light.
fn sphere_disk(s: &Sphere, ex: &Extrude, out: &mut Vec<[Vec3; 3]>) {
    let (centre, radius, axis) = match ex.point {
        Some(l) => {
            let d = (s.center - l).length();
            if !(d > s.radius) {
                return;
            }
            let axis = (s.center - l) / d;
            (l + axis * (d - s.radius * s.radius / d), s.radius * (d * d - s.radius * s.radius).sqrt() / d, axis)
        }
        None => (s.center, s.radius, ex.along),
    };
    if !(radius > 0.0 && radius.is_finite()) {
        return;
    }
    let e1 = axis.any_orthonormal_vector();
    let e2 = axis.cross(e1);
    let corner = |k: usize| {
        let a = std::f32::consts::TAU * (k % SPHERE_SEGMENTS) as f32 / SPHERE_SEGMENTS as f32;
        centre + (e1 * a.cos() + e2 * a.sin()) * radius
    };
    for k in 0..SPHERE_SEGMENTS {
        let (p, q) = (corner(k), corner(k + 1));
        // Wound to face the light (against the axis).
        if (p - centre).cross(q - centre).dot(axis) < 0.0 {
            out.push([centre, p, q]);
        } else {
            out.push([centre, q, p]);
        }
    }
}

/// Caps and side quads of the casters (each wound to face the light), with
/// the side quads that cancel between neighbours left out.
fn volume_of_casters(casters: &[[Vec3; 3]], ex: &Extrude) -> Vec<[Vec3; 3]> {
    let mut faces = Vec::with_capacity(casters.len() * 2);
    // Each directed edge as (smaller key, larger key, +1 / -1 for its direction).
    let mut edges: Vec<([u32; 3], [u32; 3], i32)> = Vec::with_capacity(casters.len() * 3);
    for &[a, b, c] in casters {
        faces.push([a, b, c]);
        faces.push([ex.far(a), ex.far(c), ex.far(b)]);
        for (p, q) in [(a, b), (b, c), (c, a)] {
            let (kp, kq) = (key(p), key(q));
            edges.push(if kp < kq { (kp, kq, 1) } else { (kq, kp, -1) });
        }
    }
    edges.sort_unstable();
    let point = |k: [u32; 3]| Vec3::new(f32::from_bits(k[0]), f32::from_bits(k[1]), f32::from_bits(k[2]));
    let mut i = 0;
    while i < edges.len() {
        let (lo, hi) = (edges[i].0, edges[i].1);
        let mut sum = 0;
        while i < edges.len() && edges[i].0 == lo && edges[i].1 == hi {
            sum += edges[i].2;
            i += 1;
        }
        let (p, q) = if sum > 0 { (point(lo), point(hi)) } else { (point(hi), point(lo)) };
        // The quad of directed edge p -> q, wound outwards.
        for _ in 0..sum.abs() {
            faces.push([q, p, ex.far(p)]);
            faces.push([q, ex.far(p), ex.far(q)]);
        }
    }
    faces
}

/// The last shadow volumes built for a `PreparedScene`, keyed by the lights.
pub type ShadowVolumeCache = KeyedCache<Vec<Light>, ShadowVolumes>;

impl PreparedScene {
    /// The scene's shadow volumes, from the cache or built now. A frame
    /// builds them before its passes (`frame::build_shadow_volumes`).
    pub fn shadow_volumes(&self) -> Arc<ShadowVolumes> {
        self.volume_cache.get(self.scene.lights.clone(), |_| ShadowVolumes::build(&self.scene))
    }
}

thread_local! {
    /// The volumes this thread used last, so samples find them without a lock.
    static CURRENT: ThreadCopy<ShadowVolumes> = const { ThreadCopy::new() };
}

/// Runs `f` with the shadow volumes of `prepared`: this thread's last ones
/// when they still match, else from the cache.
pub fn with_volumes<T>(prepared: &PreparedScene, f: impl FnOnce(&ShadowVolumes) -> T) -> T {
    let fits = |v: &ShadowVolumes| v.matches(&prepared.scene);
    CURRENT.with(|copy| copy.with(prepared.volume_cache.id(), fits, || prepared.shadow_volumes(), f))
}

/// The ray casters' counts for the sample whose eye ray `ray` hits at `t_hit`.
pub fn ray_counts(prepared: &PreparedScene, settings: &RenderSettings, ray: &Ray, t_hit: f32) -> Vec<i32> {
    with_volumes(prepared, |v| (0..prepared.scene.lights.len()).map(|l| v.count(l, ray, t_hit, settings.shadow_volume)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_with(tris: Vec<Triangle>, light: Light) -> Scene {
        let mut s = Scene::default();
        s.triangles = tris.into();
        s.lights.push(light);
        s
    }

    fn tri(v: [Vec3; 3], two_sided: bool) -> Triangle {
        Triangle { v, n: [Vec3::Y; 3], uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided }
    }

    fn sun() -> Light {
        Light::Directional { direction: Vec3::NEG_Y, irradiance: Vec3::ONE }
    }

    #[test]
    fn a_triangle_hides_what_lies_behind_it_only() {
        // A two-sided triangle at y = 1 under a sun straight above.
        let t = tri([Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, -1.0), Vec3::new(0.0, 1.0, 1.0)], true);
        let mut s = scene_with(vec![t], sun());
        s.triangles.push(tri([Vec3::new(-5.0, -1.0, -5.0), Vec3::new(-5.0, -1.0, 5.0), Vec3::new(5.0, -1.0, 5.0)], false));
        let v = ShadowVolumes::build(&s);
        // One cap each side and three side quads: 8 faces.
        assert_eq!(v.volumes[0].len(), 8);
        assert!(v.contains(0, Vec3::new(0.0, 0.0, 0.0)), "below the triangle");
        assert!(v.contains(0, Vec3::new(0.0, -0.9, -0.2)));
        assert!(!v.contains(0, Vec3::new(2.0, 0.0, 0.0)), "beside it");
        assert!(!v.contains(0, Vec3::new(0.0, 2.0, 0.0)), "between it and the light");
    }

    #[test]
    fn one_sided_triangles_cast_only_facing_away_from_the_light() {
        let up = tri([Vec3::new(-1.0, 1.0, 1.0), Vec3::new(1.0, 1.0, 1.0), Vec3::new(0.0, 1.0, -1.0)], false);
        assert!((up.v[1] - up.v[0]).cross(up.v[2] - up.v[0]).y > 0.0);
        let v = ShadowVolumes::build(&scene_with(vec![up.clone()], sun()));
        assert!(v.volumes[0].is_empty(), "a one-sided triangle facing the light lets shadow rays through");
        let down = tri([up.v[0], up.v[2], up.v[1]], false);
        let v = ShadowVolumes::build(&scene_with(vec![down], sun()));
        assert!(v.contains(0, Vec3::new(0.0, 0.0, 0.0)));
    }

    #[test]
    fn shared_edges_cancel_and_leave_the_silhouette() {
        // A square of two triangles: 2 x 2 caps + 4 outer edges x 2 triangles.
        let (a, b, c, d) = (Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, 1.0), Vec3::new(-1.0, 1.0, 1.0));
        let v = ShadowVolumes::build(&scene_with(vec![tri([a, d, c], true), tri([a, c, b], true)], sun()));
        assert_eq!(v.volumes[0].len(), 4 + 8);
        // Near the shared diagonal (x = z): inside once, not twice or zero times.
        let p = Vec3::new(0.3, 0.0, 0.29);
        assert_eq!(v.count(0, &Ray::new(Vec3::new(0.3, 10.0, 0.29), Vec3::NEG_Y), 10.0, VolumeMode::ZPass), 1);
        assert!(v.contains(0, p));
    }

    #[test]
    fn z_pass_and_z_fail_agree_outside_and_differ_inside() {
        let t = tri([Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, -1.0), Vec3::new(0.0, 1.0, 1.0)], true);
        let v = ShadowVolumes::build(&scene_with(vec![t], sun()));
        // From outside, looking down through the volume at a floor at y = -1.
        let ray = Ray::new(Vec3::new(0.0, 3.0, 0.0), Vec3::NEG_Y);
        assert_eq!(v.count(0, &ray, 4.0, VolumeMode::ZPass), 1);
        assert_eq!(v.count(0, &ray, 4.0, VolumeMode::ZFail), 1);
        // From inside the volume (eye at y = 0.5): z-pass misses the entry.
        let ray = Ray::new(Vec3::new(0.0, 0.5, 0.0), Vec3::NEG_Y);
        assert_eq!(v.count(0, &ray, 1.5, VolumeMode::ZPass), 0);
        assert_eq!(v.count(0, &ray, 1.5, VolumeMode::ZFail), 1);
    }

    #[test]
    fn a_sphere_shadows_the_point_behind_it_from_a_point_light() {
        let mut s = Scene::default();
        s.spheres.push(Sphere { center: Vec3::ZERO, radius: 1.0, material: 0, object: 0 });
        s.lights.push(Light::Point { position: Vec3::new(0.0, 5.0, 0.0), power: Vec3::ONE });
        let v = ShadowVolumes::build(&s);
        assert!(v.contains(0, Vec3::new(0.0, -3.0, 0.0)));
        assert!(v.contains(0, Vec3::new(1.0, -3.0, 0.0)), "inside the widening cone");
        assert!(!v.contains(0, Vec3::new(2.0, -3.0, 0.0)));
        assert!(!v.contains(0, Vec3::new(0.0, 1.5, 0.0)), "between the sphere and the light");
        // The lit cap of the sphere is outside its volume.
        assert!(!v.contains(0, Vec3::new(0.0, 1.0, 0.0)));
    }
}
