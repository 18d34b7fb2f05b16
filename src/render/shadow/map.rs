//! Shadow maps (CGPP 15.6.5): for every light, a depth image rendered from the
//! light by rasterization, looked up by `shade()` instead of casting a shadow
//! ray when `settings.shadows == ShadowMode::Map`.
//!
//! - A point light gets six 90-degree perspective faces (a cube map) of
//!   `shadow_map_size`^2 texels; each texel stores the distance from the light
//!   to the first surface along the ray through the texel's centre.
//! - A directional light gets one orthographic map whose rectangle is fitted
//!   to the scene's shadow casters (see `caster_bounds`); each texel stores the
//!   depth along the light's direction.
//!
//! The maps are rasterized with the rasterizers' own parts: near clipping
//! (`clip`), the screen triangle (`setup`) and the watertight fixed-point
//! coverage loop (`fixed`). Coverage decides which texels a triangle owns;
//! the stored depth comes from the triangle's plane intersected with the
//! texel's ray, so it is what a ray cast from the light finds, whatever the
//! projection does to precision. Spheres stay analytic: a conservative box
//! (`sphere_bounds`) and a ray-sphere test per texel.
//!
//! What is stored matches what the ray caster's shadow rays can hit, so a map
//! with enough resolution gives the ray-cast image: two-sided triangles from
//! either side; one-sided triangles only when they face away from the light
//! (a shadow ray travels towards the light and meets only front faces), so
//! a closed one-sided mesh stores its far side and never shadows its own lit
//! side. Spheres store the first point the light sees, as a GPU shadow map
//! would: they, like two-sided surfaces, can shadow themselves and show acne.
//!
//! The lookup (`ShadowMaps::occluder`) projects the shaded point into the map,
//! takes the nearest texel (no filtering) and calls the point shadowed when
//! it lies farther from the light than the stored depth by more than the
//! bias. The bias is slope-scaled and measured in texels: the tolerance is
//! `shadow_map_bias * w * (1 + tan(theta))`, with `w` the world size of one
//! texel at the point's depth and `theta` the angle between the surface's
//! geometric normal and the light direction (tan clamped to `MAX_SLOPE`).
//! A point may lie up to about 0.7 texel from its texel's centre, where the
//! surface's depth differs by up to 0.7 w tan(theta); a bias below that
//! shows acne, one far above it detaches shadows from their casters
//! (peter-panning).
//!
//! Maps depend on geometry, lights and `shadow_map_size` only (not on the
//! camera or the bias), so `PreparedScene` caches the last set built; a frame
//! builds them once before its passes, and a pass that finds none builds
//! them on first use.

use crate::render::raster::clip::{clip_near, triangle_vertices};
use crate::render::raster::cull::Frustum;
use crate::render::raster::fixed::{self, FixedTri};
use crate::render::raster::rect::{sample_span, PixelRect};
use crate::render::raster::setup::{bin_rows, ScreenTri};
use crate::render::raster::subpixel::snap_offset;
use crate::render::raster::sphere::sphere_bounds;
use crate::render::keyed_cache::{KeyedCache, ThreadCopy};
use crate::render::inspect::pixel_record::Recorder;
use crate::render::shadow::ShadowFilter;
use crate::render::{Occluder, PassJob, PreparedScene, RenderSettings};
use crate::math::{Radiance, Ray, Vec2, Vec3};
use crate::scene::{Camera, CameraView, Fov, Light, PrimitiveId, Scene, Sphere, SurfaceHit, Triangle};
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;

/// Texels per side of each map (per cube face for point lights).
pub const DEFAULT_SIZE: u32 = 1024;
/// Largest accepted `shadow_map_size` (a point light's six faces at 4096 hold
/// 100 M texels, 800 MB).
pub const MAX_SIZE: u32 = 4096;
/// Default slope-scaled bias, in texels (see the module documentation).
pub const DEFAULT_BIAS: f32 = 1.0;
/// The slope factor tan(theta) of the bias is clamped here (about 84 degrees).
pub const MAX_SLOPE: f32 = 10.0;

/// Most memory all of a scene's shadow maps together may take: 1 GiB.
pub const MAX_BYTES: u64 = 1 << 30;

/// Memory the maps of every light of `scene` take at `size` texels per side:
/// a depth and a primitive id per texel, six faces per point light.
pub fn memory_bytes(scene: &Scene, size: u32) -> u64 {
    let faces: u64 = scene.lights.iter().map(|l| if matches!(l, Light::Point { .. }) { 6 } else { 1 }).sum::<u64>() + 6 * scene.emitters.lights.len() as u64;
    let texel = (std::mem::size_of::<f32>() + std::mem::size_of::<PrimitiveId>()) as u64;
    let side = size.clamp(1, MAX_SIZE) as u64;
    side * side * faces * texel
}

/// Refuses, before anything is allocated, maps that would take more than `MAX_BYTES`.
pub fn check_memory(scene: &Scene, size: u32) -> Result<(), String> {
    let bytes = memory_bytes(scene, size);
    if bytes > MAX_BYTES {
        return Err(format!(
            "shadow maps of {} lights at {size}x{size} texels would take {} MiB, more than the limit of {} MiB; use a smaller --shadow-map-size",
            scene.lights.len() + scene.emitters.lights.len(),
            bytes >> 20,
            MAX_BYTES >> 20
        ));
    }
    Ok(())
}


/// Rows of a map rasterized together (bands run in parallel).
const BAND: u32 = 32;

/// One depth image: a cube face or a directional light's map.
pub struct Face {
    /// The light's camera: eye at the light (perspective, 90 degrees) or at the
    /// centre of the fitted rectangle (orthographic, `half_x`/`half_y` are then
    /// the rectangle's half extents in world units).
    pub view: CameraView,
    pub ortho: bool,
    /// Per texel (row-major): distance from the light (perspective) or depth
    /// along the light direction from the view's eye (orthographic);
    /// `f32::INFINITY` where nothing was drawn.
    pub depth: Vec<f32>,
    /// Per texel: the primitive stored, `PrimitiveId::NONE` when empty.
    pub id: Vec<PrimitiveId>,
}

/// The maps of one light.
pub struct LightMap {
    /// Six faces (+x, -x, +y, -y, +z, -z) for a point light, one for a directional light.
    pub faces: Vec<Face>,
    /// Range of the finite depths stored, for the visualization.
    pub depth_range: (f32, f32),
}

/// The shadow maps of every light of a scene, in scene order.
pub struct ShadowMaps {
    pub size: u32,
    /// The lights they were built for (the cache key with `size`).
    pub lights: Vec<Light>,
    pub maps: Vec<LightMap>,
    /// Per area light (`Scene::emitters.lights`): a cube map drawn from its
    /// centre without its own surfaces, read by `area_light_visibility`.
    pub area: Vec<LightMap>,
    /// What `area` was built for: each area light's object and centre.
    pub area_lights: Vec<(u32, Vec3)>,
    /// Time to build them all, milliseconds.
    pub build_ms: f64,
}

/// A triangle piece set up for one face: coverage plus the plane its depth comes from.
struct FaceTri {
    ft: FixedTri,
    /// The (unclipped) triangle's plane in the face's camera space: `n . q = k`.
    n: Vec3,
    k: f32,
    /// Range of view depth over the piece: interpolated depths are clamped to it.
    z_lo: f32,
    z_hi: f32,
}

impl ShadowMaps {
    /// Rasterizes the maps of every light of `scene`. With `parallel`, the
    /// bands of every face run on the rayon pool; without it everything runs
    /// on the calling thread (safe to call from inside a parallel pass).
    pub fn build(scene: &Scene, size: u32, parallel: bool) -> ShadowMaps {
        let start = Instant::now();
        let size = size.clamp(1, MAX_SIZE);
        // (map index, the object whose surfaces it leaves out, face): point
        // and directional lights first, then the area lights.
        let mut faces: Vec<(usize, Option<u32>, Face)> = Vec::new();
        for (li, light) in scene.lights.iter().enumerate() {
            for view in light_views(scene, light, size) {
                let ortho = matches!(light, Light::Directional { .. });
                faces.push((li, None, Face { view, ortho, depth: Vec::new(), id: Vec::new() }));
            }
        }
        let lights = scene.lights.len();
        for (ai, area) in scene.emitters.lights.iter().enumerate() {
            for view in cube_views(scene, area.centre, size) {
                faces.push((lights + ai, Some(area.object), Face { view, ortho: false, depth: Vec::new(), id: Vec::new() }));
            }
        }
        let draw = |skip: Option<u32>, face: &mut Face| draw_face(scene, face, size, parallel, skip);
        if parallel {
            faces.par_iter_mut().for_each(|(_, skip, f)| draw(*skip, f));
        } else {
            faces.iter_mut().for_each(|(_, skip, f)| draw(*skip, f));
        }
        let count = lights + scene.emitters.lights.len();
        let mut maps: Vec<LightMap> = (0..count).map(|_| LightMap { faces: Vec::new(), depth_range: (0.0, 0.0) }).collect();
        for (li, _, face) in faces {
            maps[li].faces.push(face);
        }
        let area = maps.split_off(lights);
        let mut maps = maps;
        for m in &mut maps {
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for d in m.faces.iter().flat_map(|f| f.depth.iter()).filter(|d| d.is_finite()) {
                lo = lo.min(*d);
                hi = hi.max(*d);
            }
            m.depth_range = if lo <= hi { (lo, hi) } else { (0.0, 0.0) };
        }
        ShadowMaps { size, lights: scene.lights.clone(), maps, area, area_lights: area_key(scene), build_ms: start.elapsed().as_secs_f64() * 1e3 }
    }

    /// True when these maps were built for `scene`'s lights at `size`.
    #[inline]
    pub fn matches(&self, scene: &Scene, size: u32) -> bool {
        // Compared in place: asked on every lookup, so nothing is allocated.
        let areas = &scene.emitters.lights;
        self.size == size.clamp(1, MAX_SIZE)
            && self.lights == scene.lights
            && self.area_lights.len() == areas.len()
            && self.area_lights.iter().zip(areas).all(|(&(object, centre), l)| object == l.object && centre == l.centre)
    }

    /// The map's verdict for light `light` at `hit`: the primitive stored in
    /// the texel and how far before the point it lies (as a shadow ray's
    /// blocker, t being the distance from the point), or `None` when lit.
    /// `bias` is in texels, slope-scaled (module documentation) unless
    /// `slope_scaled` is off (`RenderSettings::shadow_map_slope_bias`); `lift`
    /// is `RenderSettings::terminator_lift`.
    #[allow(clippy::too_many_arguments)]
    pub fn occluder(&self, scene: &Scene, light: usize, hit: &SurfaceHit, w_i: Vec3, bias: f32, slope_scaled: bool, lift: bool) -> Option<Occluder> {
        let map = self.maps.get(light).filter(|m| !m.faces.is_empty())?;
        // The same point a shadow ray would leave from (lifted on smooth triangles).
        let p = crate::render::transport::incidence::shadow_origin(scene, hit, w_i, lift);
        let n = self.size as f32;
        let (face, dist, texel_w) = match scene.lights[light] {
            Light::Point { position, .. } => {
                let face = &map.faces[cube_face(p - position)];
                let z = face.view.view_depth(p);
                (face, (p - position).length(), 2.0 * z / n)
            }
            Light::Directional { .. } => {
                let face = &map.faces[0];
                (face, face.view.view_depth(p), 2.0 * face.view.half_x.max(face.view.half_y) / n)
            }
        };
        let (x, y) = face.texel_of(p)?;
        let i = (x + y * self.size) as usize;
        let id = face.id[i];
        if id.is_none() {
            return None;
        }
        let cos = hit.geometric_normal.dot(w_i).abs().clamp(1e-6, 1.0);
        let tan = if slope_scaled { ((1.0 - cos * cos).max(0.0).sqrt() / cos).min(MAX_SLOPE) } else { 0.0 };
        let gap = dist - face.depth[i];
        if gap > bias * texel_w * (1.0 + tan) {
            Some(Occluder::new(id, gap))
        } else {
            None
        }
    }

    /// The fraction of area light `light` (`Scene::emitters.lights`) that
    /// `hit` sees according to the maps, filtered as `settings.shadow_filter`
    /// says; `None` where the maps hold no map of that light.
    pub fn area_light_visibility(&self, scene: &Scene, light: usize, hit: &SurfaceHit, settings: &RenderSettings) -> Option<f32> {
        let map = self.area.get(light).filter(|m| m.faces.len() == 6)?;
        let area = scene.emitters.lights.get(light)?;
        let to_light = area.centre - hit.position;
        let w_i = to_light.normalize_or_zero();
        let p = crate::render::transport::incidence::shadow_origin(scene, hit, w_i, settings.terminator_lift);
        let v = p - area.centre;
        let dist = v.length();
        if !(dist > 0.0) {
            return Some(1.0);
        }
        let face = &map.faces[cube_face(v)];
        let c = face.view.to_camera(p);
        if !(c.z < 0.0) {
            return Some(1.0);
        }
        let centre = face.view.project_camera(c);
        let n = self.size as f32;
        let texel_w = 2.0 * -c.z / n;
        let cos = hit.geometric_normal.dot(w_i).abs().clamp(1e-6, 1.0);
        let tan = if settings.shadow_map_slope_bias { ((1.0 - cos * cos).max(0.0).sqrt() / cos).min(MAX_SLOPE) } else { 0.0 };
        let taps = Taps { face, size: self.size, centre, dist, texel_w, bias: settings.shadow_map_bias, tan };
        Some(match settings.shadow_filter {
            ShadowFilter::None => taps.lit_fraction(0.0),
            ShadowFilter::Pcf => taps.lit_fraction(settings.pcf_radius),
            ShadowFilter::Pcss => {
                // The light as a disc of equal area (a square's half diagonal
                // is sqrt(pi / 2) times that disc's radius).
                let radius = area.radius * (2.0 / std::f32::consts::PI).sqrt();
                // Blockers that can shade this point lie in the cone from it
                // to the light; searched where that cone is at least a
                // quarter of the way from the light (nearer blockers are
                // rare), as an angle from the light and then in texels.
                let near = 0.25 * dist;
                let search = (radius * (dist - near) / (dist * near)).min(0.6) * n * 0.5;
                let Some(blocker) = taps.mean_blocker_distance(search) else { return Some(1.0) };
                // Similar triangles: the penumbra's half width at the point
                // is radius (d - d_b) / d_b; seen from the light, over d.
                let penumbra = radius * (dist - blocker) / (blocker * dist) * n * 0.5;
                taps.lit_fraction(penumbra.min(n * 0.25))
            }
        })
    }

    /// The `shadowmap` view at image position `pos` of a `width` x `height`
    /// image: the lights one below the other, each as a grey depth image
    /// (black = near the light, white = far or empty, CGPP Figure 15.14;
    /// linear for a directional light, log scale for a point light's
    /// distances); a point light's faces in a 3 x 2 grid (+x -x +y / -y +z -z).
    /// Outside the maps: dark blue.
    pub fn view_color(&self, pos: Vec2, width: u32, height: u32) -> Radiance {
        const OUTSIDE: Vec3 = Vec3::new(0.0, 0.0, 0.15);
        let count = self.maps.len();
        if count == 0 || width == 0 || height == 0 {
            return OUTSIDE;
        }
        let row_h = height as f32 / count as f32;
        let li = ((pos.y / row_h) as usize).min(count - 1);
        let map = &self.maps[li];
        let local = Vec2::new(pos.x, pos.y - li as f32 * row_h);
        let n = self.size as f32;
        let (cols, rows) = if map.faces.len() == 6 { (3.0, 2.0) } else { (1.0, 1.0) };
        let scale = (width as f32 / (cols * n)).min(row_h / (rows * n));
        let origin = Vec2::new((width as f32 - cols * n * scale) * 0.5, (row_h - rows * n * scale) * 0.5);
        let t = (local - origin) / scale;
        if !(t.x >= 0.0 && t.y >= 0.0 && t.x < cols * n && t.y < rows * n) {
            return OUTSIDE;
        }
        let (fx, fy) = ((t.x / n) as usize, (t.y / n) as usize);
        let Some(face) = map.faces.get(fx + fy * cols as usize) else { return OUTSIDE };
        let x = ((t.x - fx as f32 * n) as u32).min(self.size - 1);
        let y = ((t.y - fy as f32 * n) as u32).min(self.size - 1);
        let d = face.depth[(x + y * self.size) as usize];
        if !d.is_finite() {
            return Vec3::ONE;
        }
        let (lo, hi) = map.depth_range;
        let grey = if !(hi > lo) {
            0.5
        } else if face.ortho || lo <= 0.0 {
            (d - lo) / (hi - lo)
        } else {
            // Distances from a point light span decades (a ground plane to the
            // horizon): a log scale, as the depth view uses.
            (d / lo).ln() / (hi / lo).ln()
        };
        Vec3::splat(grey.clamp(0.0, 1.0))
    }
}

/// Depth tests around one point's position in a face of an area light's
/// cube map, for the filters.
struct Taps<'a> {
    face: &'a Face,
    size: u32,
    /// The point's position in the face, in texels, and its distance from the light.
    centre: Vec2,
    dist: f32,
    /// World size of a texel at the point's depth; bias in texels; the
    /// slope term tan(theta) of the bias (0 without slope scaling).
    texel_w: f32,
    bias: f32,
    tan: f32,
}

/// Most taps per side of a filter or blocker search: wider kernels spread
/// this many taps over their width instead of reading every texel.
const MAX_TAPS_PER_SIDE: i32 = 9;

impl Taps<'_> {
    /// The texel `offset` texels from the point (clamped to the face), its
    /// stored distance, and whether the point is lit there. The bias grows
    /// with the offset by the slope: a tilted receiver's own depth changes
    /// by `tan` texel widths per texel across the kernel.
    #[inline]
    fn test(&self, offset: Vec2) -> (f32, bool) {
        let last = (self.size - 1) as f32;
        let x = (self.centre.x + offset.x).clamp(0.0, last) as u32;
        let y = (self.centre.y + offset.y).clamp(0.0, last) as u32;
        let stored = self.face.depth[(x + y * self.size) as usize];
        let tolerance = self.texel_w * (self.bias * (1.0 + self.tan) + offset.length() * self.tan);
        (stored, !(self.dist - stored > tolerance))
    }

    /// Tap offsets covering a square of half width `radius` texels: every
    /// texel while that is at most `MAX_TAPS_PER_SIDE` per side, else a
    /// regular grid of that many.
    fn offsets(radius: f32) -> impl Iterator<Item = Vec2> {
        let k = (radius.max(0.0).ceil() as i32).min(MAX_TAPS_PER_SIDE / 2);
        let step = if k > 0 { radius / k as f32 } else { 0.0 };
        (-k..=k).flat_map(move |j| (-k..=k).map(move |i| Vec2::new(i as f32, j as f32) * step))
    }

    /// The fraction of taps within `radius` texels that see the light
    /// (percentage-closer filtering; one tap at radius 0).
    fn lit_fraction(&self, radius: f32) -> f32 {
        let (mut lit, mut total) = (0u32, 0u32);
        for o in Self::offsets(radius) {
            lit += self.test(o).1 as u32;
            total += 1;
        }
        lit as f32 / total as f32
    }

    /// The mean distance from the light of the blockers found within
    /// `radius` texels; `None` when nothing there blocks the point.
    fn mean_blocker_distance(&self, radius: f32) -> Option<f32> {
        let (mut sum, mut count) = (0.0f32, 0u32);
        for o in Self::offsets(radius) {
            let (stored, lit) = self.test(o);
            if !lit {
                sum += stored;
                count += 1;
            }
        }
        (count > 0).then(|| sum / count as f32)
    }
}

impl Face {
    /// The texel whose ray passes nearest `p`; `None` for a point outside an
    /// orthographic map (no caster there) or behind a perspective face.
    #[inline]
    pub fn texel_of(&self, p: Vec3) -> Option<(u32, u32)> {
        let c = self.view.to_camera(p);
        let img = if self.ortho {
            ortho_project(&self.view, c)
        } else {
            if !(c.z < 0.0) {
                return None;
            }
            self.view.project_camera(c)
        };
        let n = self.view.width as f32;
        if self.ortho && !(img.x >= 0.0 && img.y >= 0.0 && img.x < n && img.y < n) {
            return None;
        }
        if !(img.x.is_finite() && img.y.is_finite()) {
            return None;
        }
        let clamp = |v: f32| (v.max(0.0) as u32).min(self.view.width - 1);
        Some((clamp(img.x), clamp(img.y)))
    }
}

/// Which cube face (+x, -x, +y, -y, +z, -z) the direction `v` from the light falls in.
#[inline]
pub fn cube_face(v: Vec3) -> usize {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        if v.x >= 0.0 { 0 } else { 1 }
    } else if a.y >= a.z {
        if v.y >= 0.0 { 2 } else { 3 }
    } else if v.z >= 0.0 {
        4
    } else {
        5
    }
}

/// Image position (texels) of a camera-space point in an orthographic face.
#[inline]
fn ortho_project(view: &CameraView, c: Vec3) -> Vec2 {
    Vec2::new(
        (c.x / view.half_x + 1.0) * 0.5 * view.width as f32,
        (1.0 - c.y / view.half_y) * 0.5 * view.height as f32,
    )
}

/// The light's cameras: six cube faces for a point light, one orthographic
/// view for a directional light.
pub fn light_views(scene: &Scene, light: &Light, size: u32) -> Vec<CameraView> {
    let Some((lo, hi)) = scene.bounds() else { return Vec::new() };
    match *light {
        Light::Point { position, .. } => cube_views(scene, position, size),
        Light::Directional { direction, .. } => {
            let forward = direction.normalize_or(Vec3::NEG_Y);
            let up = if forward.y.abs() < 0.9 { Vec3::Y } else { Vec3::Z };
            let (clo, chi) = caster_bounds(scene).unwrap_or((lo, hi));
            let centre = (clo + chi) * 0.5;
            let cam = Camera { eye: centre, target: centre + forward, up, fov: Fov::Y(90.0), near: 1.0, far: 2.0, ..Camera::default() };
            let mut v = CameraView::new(&cam, size, size);
            // The rectangle: the casters' box projected across the light, plus a
            // texel of margin so silhouettes on its edge are not cut.
            let (mut hx, mut hy) = (0.0f32, 0.0f32);
            for i in 0..8 {
                let corner = Vec3::new(if i & 1 == 0 { clo.x } else { chi.x }, if i & 2 == 0 { clo.y } else { chi.y }, if i & 4 == 0 { clo.z } else { chi.z });
                let c = v.to_camera(corner);
                hx = hx.max(c.x.abs());
                hy = hy.max(c.y.abs());
            }
            let grow = 1.0 + 2.0 / size as f32;
            v.half_x = (hx * grow).max(1e-6);
            v.half_y = (hy * grow).max(1e-6);
            v.near = f32::NEG_INFINITY;
            v.far = f32::INFINITY;
            vec![v]
        }
    }
}

/// The six 90-degree faces (+x, -x, +y, -y, +z, -z) of a cube map drawn from
/// `position`: a point light's, or an area light's from its centre.
pub fn cube_views(scene: &Scene, position: Vec3, size: u32) -> Vec<CameraView> {
    let Some((lo, hi)) = scene.bounds() else { return Vec::new() };
    // Nothing nearer than this to the light is drawn (the near plane).
    let far_corner = (0..8)
        .map(|i| Vec3::new(if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z }))
        .map(|c| (c - position).length())
        .fold(0.0f32, f32::max);
    let near = (far_corner * 1e-6).max(1e-9);
    let axes = [
        (Vec3::X, Vec3::Y),
        (Vec3::NEG_X, Vec3::Y),
        (Vec3::Y, Vec3::Z),
        (Vec3::NEG_Y, Vec3::NEG_Z),
        (Vec3::Z, Vec3::Y),
        (Vec3::NEG_Z, Vec3::Y),
    ];
    axes.iter()
        .map(|&(forward, up)| {
            let cam = Camera { eye: position, target: position + forward, up, fov: Fov::Y(90.0), near, far: f32::MAX, ..Camera::default() };
            let mut v = CameraView::new(&cam, size, size);
            // Exactly 90 degrees: faces meet edge to edge.
            v.half_x = 1.0;
            v.half_y = 1.0;
            v
        })
        .collect()
}

/// The box a directional light's map must cover: that of every primitive
/// except the huge ones (a ground plane or a planet-sized sphere, larger than
/// half the whole scene), which rarely cast shadows on anything visible and
/// would spread the map's texels over kilometres. Shadows fall along the
/// light's direction, so outside the casters' rectangle nothing is shadowed;
/// a huge primitive still receives shadows inside it. `None` when every
/// primitive is huge (use the whole scene).
pub fn caster_bounds(scene: &Scene) -> Option<(Vec3, Vec3)> {
    let (lo, hi) = scene.bounds()?;
    let limit = 0.5 * (hi - lo).length();
    // The two-level layer's copies triangle by triangle, placed as flattening
    // places them, so the rectangle is the flattened scene's (min and max
    // are exact, so the order does not matter). On the calling thread, as
    // the maps may be built inside a parallel pass.
    let layer_bounds = scene.layer.as_ref().map(|layer| {
        layer
            .instances
            .iter()
            .map(|inst| {
                let mut b = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
                for local in 0..layer.meshes[inst.mesh as usize].len() {
                    let (v, _) = layer.world_vertices(inst, local);
                    let (tl, th) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
                    if (th - tl).length() <= limit {
                        b.0 = b.0.min(tl);
                        b.1 = b.1.max(th);
                    }
                }
                b
            })
            .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |a, c| (a.0.min(c.0), a.1.max(c.1)))
    });
    let mut b = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let mut add = |l: Vec3, h: Vec3| {
        if (h - l).length() <= limit {
            b.0 = b.0.min(l);
            b.1 = b.1.max(h);
        }
    };
    for t in &scene.triangles {
        add(t.v[0].min(t.v[1]).min(t.v[2]), t.v[0].max(t.v[1]).max(t.v[2]));
    }
    for s in &scene.spheres {
        add(s.center - Vec3::splat(s.radius), s.center + Vec3::splat(s.radius));
    }
    if let Some((l, h)) = layer_bounds {
        b = (b.0.min(l), b.1.max(h));
    }
    (b.0.x <= b.1.x).then_some(b)
}

/// Rasterizes every triangle (in scene order) and then every sphere into one face.
/// `skip`: an object whose surfaces are left out (an area light's own, which
/// would otherwise hide the light from everything).
fn draw_face(scene: &Scene, face: &mut Face, size: u32, parallel: bool, skip: Option<u32>) {
    let n = size as usize;
    face.depth = vec![f32::INFINITY; n * n];
    face.id = vec![PrimitiveId::NONE; n * n];
    let (view, ortho) = (&face.view.clone(), face.ortho);
    let mut tris = Vec::new();
    for (i, t) in scene.triangles.iter().enumerate() {
        if skip.is_some_and(|o| o == t.object) {
            continue;
        }
        setup_face_triangle(view, ortho, &t, i as u32, size, &mut tris);
    }
    // The two-level layer's copies after them, in index order, each culled
    // whole by its bounding sphere against the face (a culled copy covers no
    // texel) and drawn a batch of copies at a time, so the set-up pieces of
    // a large layer never all sit in memory at once. Depth ties keep the
    // first drawn, so batches drawn in index order give the flattened map.
    if let Some(layer) = &scene.layer {
        let frustum = (!ortho).then(|| Frustum::new(view));
        let seen = |info: &crate::scene::InstanceInfo| match &frustum {
            Some(f) => f.may_see(view, info.center, info.radius),
            None => {
                let c = view.to_camera(info.center);
                let r = info.radius * (1.0 + 1e-4) + 1e-5 * c.length();
                c.x.abs() - r <= view.half_x && c.y.abs() - r <= view.half_y
            }
        };
        let infos = scene.instances.iter().filter(|i| i.triangles.start >= scene.triangles.len());
        for (inst, info) in layer.instances.iter().zip(infos) {
            // (A record that is not this copy's culls nothing.)
            if info.triangles.start == inst.base as usize && !seen(info) {
                continue;
            }
            for local in 0..layer.meshes[inst.mesh as usize].len() {
                setup_face_triangle(view, ortho, &layer.world(inst, local), inst.base + local as u32, size, &mut tris);
            }
            if tris.len() >= LAYER_BATCH {
                draw_pieces(face, &tris, &[], size, parallel);
                tris.clear();
            }
        }
    }
    let spheres: Vec<(u32, &Sphere, PixelRect)> = scene
        .spheres
        .iter()
        .enumerate()
        .filter(|(_, s)| !skip.is_some_and(|o| o == s.object))
        .filter_map(|(i, s)| sphere_rect(view, ortho, s, size).map(|r| (i as u32, s, r)))
        .collect();
    draw_pieces(face, &tris, &spheres, size, parallel);
}

/// Set-up triangle pieces of the two-level layer drawn into a face at once.
const LAYER_BATCH: usize = 1 << 20;

/// Draws `tris` (binned by rows) and then `spheres` into `face`, band by band.
fn draw_pieces(face: &mut Face, tris: &[FaceTri], spheres: &[(u32, &Sphere, PixelRect)], size: u32, parallel: bool) {
    let n = size as usize;
    let (view, ortho) = (&face.view, face.ortho);
    let bins = bin_rows(tris.iter().map(|t| t.ft.bbox), 0, size, BAND);
    let band = |(b, (depth, id)): (usize, (&mut [f32], &mut [PrimitiveId]))| {
        let y0 = b as u32 * BAND;
        let rect = PixelRect::new(0, y0, size, (y0 + BAND).min(size));
        draw_band(view, ortho, tris, &bins[b], spheres, rect, depth, id);
    };
    let chunks = face.depth.chunks_mut(n * BAND as usize).zip(face.id.chunks_mut(n * BAND as usize));
    if parallel {
        chunks.enumerate().par_bridge().for_each(band);
    } else {
        chunks.enumerate().for_each(band);
    }
}

/// Culls, transforms, clips and projects one scene triangle for a face.
fn setup_face_triangle(view: &CameraView, ortho: bool, t: &Triangle, index: u32, size: u32, out: &mut Vec<FaceTri>) {
    let c = t.v.map(|v| view.to_camera(v));
    let n = (c[1] - c[0]).cross(c[2] - c[0]);
    // Keep what a shadow ray can hit: one-sided triangles only when they face
    // away from the light, i.e. along the light's rays.
    if !t.two_sided {
        let toward = if ortho { n.dot(Vec3::NEG_Z) } else { n.dot(c[0]) };
        if !(toward > 0.0) {
            return;
        }
    }
    let k = n.dot(c[0]);
    let off = Vec2::splat(0.5);
    let soff = snap_offset(off);
    let mut push = |p: [Vec2; 3], z: [f32; 3]| {
        let Some(st) = ScreenTri::new(index, p, [1.0; 3], [Vec3::X, Vec3::Y, Vec3::Z], true, off, size, size) else { return };
        let Some(ft) = FixedTri::new(&st, soff, off, size, size) else { return };
        let (z_lo, z_hi) = (z[0].min(z[1]).min(z[2]), z[0].max(z[1]).max(z[2]));
        out.push(FaceTri { ft, n, k, z_lo, z_hi });
    };
    if ortho {
        push(c.map(|c| ortho_project(view, c)), c.map(|c| -c.z));
        return;
    }
    // Entirely outside one side of the 90-degree frustum: nothing to draw.
    let outside = |f: &dyn Fn(Vec3) -> bool| c.iter().all(|&v| f(v));
    if outside(&|v| -v.z < view.near) || outside(&|v| v.x > -v.z) || outside(&|v| v.x < v.z) || outside(&|v| v.y > -v.z) || outside(&|v| v.y < v.z) {
        return;
    }
    for piece in clip_near(triangle_vertices(c), view.near).as_slice() {
        push(piece.map(|v| view.project_camera(v.pos)), piece.map(|v| -v.pos.z));
    }
}

/// Texels a sphere may cover in a face.
fn sphere_rect(view: &CameraView, ortho: bool, s: &Sphere, size: u32) -> Option<PixelRect> {
    if !ortho {
        return sphere_bounds(view, s, Vec2::splat(0.5));
    }
    let c = view.to_camera(s.center);
    let lo = ortho_project(view, c + Vec3::new(-s.radius, s.radius, 0.0));
    let hi = ortho_project(view, c + Vec3::new(s.radius, -s.radius, 0.0));
    let (x0, x1) = sample_span(lo.x - 1.0, hi.x + 1.0, 0.5, size);
    let (y0, y1) = sample_span(lo.y - 1.0, hi.y + 1.0, 0.5, size);
    let r = PixelRect::new(x0, y0, x1, y1);
    (!r.is_empty()).then_some(r)
}

/// Camera-space ray of texel `(x, y)`: origin and direction, the direction's
/// view-axis component being 1 (so ray parameter = view depth).
#[inline(always)]
fn texel_ray(view: &CameraView, ortho: bool, x: u32, y: u32) -> (Vec3, Vec3) {
    let sx = (2.0 * (x as f32 + 0.5) / view.width as f32 - 1.0) * view.half_x;
    let sy = (1.0 - 2.0 * (y as f32 + 0.5) / view.height as f32) * view.half_y;
    if ortho {
        (Vec3::new(sx, sy, 0.0), Vec3::NEG_Z)
    } else {
        (Vec3::ZERO, Vec3::new(sx, sy, -1.0))
    }
}

#[allow(clippy::too_many_arguments)]
fn draw_band(
    view: &CameraView,
    ortho: bool,
    tris: &[FaceTri],
    bin: &[u32],
    spheres: &[(u32, &Sphere, PixelRect)],
    rect: PixelRect,
    depth: &mut [f32],
    id: &mut [PrimitiveId],
) {
    let stride = rect.width() as usize;
    let off = snap_offset(Vec2::splat(0.5));
    let mut tested = 0u64;
    for &ti in bin {
        let t = &tris[ti as usize];
        fixed::raster(&t.ft, rect, off, &mut tested, |x, y, _| {
            let (o, d) = texel_ray(view, ortho, x, y);
            // The plane n . (o + z d) = k; NaN-safe clamp to the piece's depths.
            let z = ((t.k - t.n.dot(o)) / t.n.dot(d)).max(t.z_lo).min(t.z_hi);
            let value = if ortho { z } else { z * d.length() };
            let i = (x - rect.x0) as usize + (y - rect.y0) as usize * stride;
            if value < depth[i] {
                depth[i] = value;
                id[i] = PrimitiveId::triangle(t.ft.st.tri);
            }
        });
    }
    for &(si, s, r) in spheres {
        let r = r.intersect(&rect);
        if r.is_empty() {
            continue;
        }
        let c = view.to_camera(s.center);
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                let (o, d) = texel_ray(view, ortho, x, y);
                let Some(value) = sphere_entry(o, d, c, s.radius, ortho) else { continue };
                let i = (x - rect.x0) as usize + (y - rect.y0) as usize * stride;
                if value < depth[i] {
                    depth[i] = value;
                    id[i] = PrimitiveId::sphere(si);
                }
            }
        }
    }
}

/// Where the ray `o + t d` first meets the sphere (centre `c`) ahead of `o`:
/// the distance along the unit direction (perspective) or the view depth
/// (orthographic, `o` on the plane z = 0, every depth counts); `None` on a
/// miss. From inside the sphere (a light in a glass ball) it is the exit. The
/// centre-to-line form keeps huge spheres accurate.
#[inline]
fn sphere_entry(o: Vec3, d: Vec3, c: Vec3, radius: f32, ortho: bool) -> Option<f32> {
    let u = d.normalize();
    let f = o - c;
    let b = -f.dot(u);
    let l = f + u * b;
    let dist = l.length();
    let disc = (radius - dist) * (radius + dist);
    if !(disc >= 0.0) {
        return None;
    }
    let h = disc.sqrt();
    if ortho {
        return Some(b - h);
    }
    let t = if f.length() > radius { b - h } else { b + h };
    (t > 0.0).then_some(t)
}

/// The last shadow maps built for a `PreparedScene`, keyed by
/// `shadow_map_size` (clamped) and the lights.
pub type ShadowMapCache = KeyedCache<(u32, Vec<Light>, Vec<(u32, Vec3)>), ShadowMaps>;

/// What an area light's map depends on besides geometry: its object and
/// centre (emission edits that make or unmake emitters change it).
fn area_key(scene: &Scene) -> Vec<(u32, Vec3)> {
    scene.emitters.lights.iter().map(|l| (l.object, l.centre)).collect()
}

/// The maps for `prepared` at `size`, built now unless the cached ones match.
/// See `ShadowMaps::build` for `parallel`.
fn cached_maps(prepared: &PreparedScene, size: u32, parallel: bool) -> Arc<ShadowMaps> {
    let key = (size.clamp(1, MAX_SIZE), prepared.scene.lights.clone(), area_key(&prepared.scene));
    prepared.shadow_cache.get(key, |_| ShadowMaps::build(&prepared.scene, size, parallel))
}

impl PreparedScene {
    /// The scene's shadow maps at `size` texels per side, from the cache or
    /// built now in parallel. Call it outside a parallel pass (before the
    /// frame); inside one, `with_maps` builds on the calling thread instead.
    pub fn shadow_maps(&self, size: u32) -> Arc<ShadowMaps> {
        cached_maps(self, size, true)
    }
}

thread_local! {
    /// The maps this thread used last, so samples find them without a lock.
    static CURRENT: ThreadCopy<ShadowMaps> = const { ThreadCopy::new() };
}

/// Runs `f` with the shadow maps for `prepared` and `settings`: from this
/// thread's last ones when they still match (no lock, no shared counter per
/// sample), else from the cache, built serially if missing.
pub fn with_maps<T>(prepared: &PreparedScene, settings: &RenderSettings, f: impl FnOnce(&ShadowMaps) -> T) -> T {
    let size = settings.shadow_map_size;
    let fits = |maps: &ShadowMaps| maps.matches(&prepared.scene, size);
    CURRENT.with(|copy| copy.with(prepared.shadow_cache.id(), fits, || cached_maps(prepared, size, false), f))
}

/// The `shadowmap` view's value for the sample whose eye ray is `ray`: the
/// ray is projected back to its image position, so every renderer (and the
/// viewer's passes) draw the same picture through `resolve_sample`.
pub fn view_sample<R: Recorder>(job: &PassJob, ray: &Ray, rec: &mut R) -> Radiance {
    let pos = job.view.project_camera(job.view.to_camera(ray.origin + ray.dir));
    let c = with_maps(job.prepared, job.settings, |maps| maps.view_color(pos, job.view.width, job.view.height));
    rec.shaded(0, c);
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_faces_by_major_axis() {
        assert_eq!(cube_face(Vec3::new(2.0, 1.0, -1.0)), 0);
        assert_eq!(cube_face(Vec3::new(-2.0, 1.0, -1.0)), 1);
        assert_eq!(cube_face(Vec3::new(0.1, 3.0, -1.0)), 2);
        assert_eq!(cube_face(Vec3::new(0.1, -3.0, -1.0)), 3);
        assert_eq!(cube_face(Vec3::new(0.1, 0.2, 0.5)), 4);
        assert_eq!(cube_face(Vec3::new(0.1, 0.2, -0.5)), 5);
    }

    #[test]
    fn sphere_entry_by_hand() {
        // Unit sphere 5 ahead on the axis: entered at 4 from outside; from the
        // centre, left at 1; a line 0.6 off the axis enters at 5 - 0.8.
        let c = Vec3::new(0.0, 0.0, -5.0);
        assert!((sphere_entry(Vec3::ZERO, Vec3::NEG_Z, c, 1.0, false).unwrap() - 4.0).abs() < 1e-6);
        assert!((sphere_entry(c, Vec3::NEG_Z * 3.0, c, 1.0, false).unwrap() - 1.0).abs() < 1e-6);
        assert!((sphere_entry(Vec3::new(0.6, 0.0, 0.0), Vec3::NEG_Z, c, 1.0, true).unwrap() - 4.2).abs() < 1e-6);
        assert_eq!(sphere_entry(Vec3::new(1.5, 0.0, 0.0), Vec3::NEG_Z, c, 1.0, false), None);
        // Behind a perspective ray's origin: not seen.
        assert_eq!(sphere_entry(Vec3::ZERO, Vec3::Z, c, 1.0, false), None);
    }

    #[test]
    fn shadow_map_memory_is_bounded_over_all_lights() {
        let point = Light::Point { position: Vec3::Y, power: Vec3::ONE };
        let mut scene = Scene::default();
        scene.lights = vec![point.clone()];
        // One point light at the largest size: 6 * 4096^2 texels of 4 + 4 bytes.
        assert_eq!(memory_bytes(&scene, MAX_SIZE), 6 * 4096 * 4096 * 8);
        assert!(check_memory(&scene, MAX_SIZE).is_ok());
        scene.lights = vec![point; 200];
        let e = check_memory(&scene, DEFAULT_SIZE).unwrap_err();
        assert!(e.contains("200 lights") && e.contains("limit of 1024 MiB"), "{e}");
    }

    #[test]
    fn caster_bounds_leave_out_huge_primitives() {
        let mut scene = Scene::default();
        scene.spheres.push(Sphere { center: Vec3::new(0.0, -1000.0, 0.0), radius: 999.0, material: 0, object: 0 });
        scene.spheres.push(Sphere { center: Vec3::new(1.0, 0.0, 0.0), radius: 0.5, material: 0, object: 1 });
        let (lo, hi) = caster_bounds(&scene).unwrap();
        assert_eq!((lo, hi), (Vec3::new(0.5, -0.5, -0.5), Vec3::new(1.5, 0.5, 0.5)));
        // Only huge primitives: none left, the caller falls back to the whole scene.
        scene.spheres.pop();
        assert_eq!(caster_bounds(&scene), None);
    }

    #[test]
    fn a_scene_without_geometry_has_empty_maps_and_no_shadows() {
        let mut scene = Scene::default();
        scene.lights.push(Light::Point { position: Vec3::ZERO, power: Vec3::ONE });
        let maps = ShadowMaps::build(&scene, 16, false);
        assert!(maps.maps[0].faces.is_empty());
        let hit = SurfaceHit {
            position: Vec3::NEG_Y, geometric_normal: Vec3::Y, shading_normal: Vec3::Y, barycentric: Vec3::ZERO, uv: Vec2::ZERO, t: 1.0,
            kind: crate::scene::PrimitiveKind::Sphere, primitive: 0, object: 0, material: 0, back_face: false, diff: crate::scene::Differentials::ZERO,
        };
        assert_eq!(maps.occluder(&scene, 0, &hit, Vec3::Y, 1.0, true, true), None);
        assert!(maps.view_color(Vec2::new(1.0, 1.0), 10, 10).is_finite());
    }
}
