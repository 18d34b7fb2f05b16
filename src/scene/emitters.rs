//! Emissive surfaces as lights: every triangle and sphere whose material has
//! `emission`, gathered once per scene (and again when materials change),
//! with a distribution that picks one in proportion to its power and the
//! densities with which a point on each is sampled from a shading point.
//!
//! Triangles are sampled uniformly by area and the density converted to
//! solid angle (`d^2 / (area cos)`); spheres by the cone of directions they
//! subtend, which wastes no sample on their far side.

use crate::math::{Vec2, Vec3};
use crate::scene::{PrimitiveId, PrimitiveKind, Scene, SurfaceHit};
use std::collections::HashMap;
use std::f32::consts::PI;

/// A point uniform on one emissive primitive, with what the samplers read
/// there.
struct UniformPoint {
    point: Vec3,
    /// The primitive's outward unit normal at `point` (a triangle's
    /// geometric normal).
    normal: Vec3,
    /// Triangles: whether both sides emit, and the uvs at `point`.
    two_sided: bool,
    uv: Option<Vec2>,
    area: f32,
    material: u32,
}

impl UniformPoint {
    /// The point `u` places uniformly on `shape`: by the square-root warp on
    /// a triangle, over the whole surface of a sphere.
    fn on(scene: &Scene, shape: EmitterShape, u: Vec2) -> UniformPoint {
        match shape {
            EmitterShape::Triangle(i) => {
                let t = scene.triangles.at(i as usize);
                let r = u.x.sqrt();
                let (b0, b1) = (1.0 - r, u.y * r);
                let point = t.v[0] * b0 + t.v[1] * b1 + t.v[2] * (1.0 - b0 - b1);
                let uv = t.uv[0] * b0 + t.uv[1] * b1 + t.uv[2] * (1.0 - b0 - b1);
                UniformPoint { point, normal: t.geometric_normal(), two_sided: t.two_sided, uv: Some(uv), area: t.area(), material: t.material }
            }
            EmitterShape::Sphere(i) => {
                let s = &scene.spheres[i as usize];
                let z = 1.0 - 2.0 * u.x;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                UniformPoint { point: s.center + n * s.radius, normal: n, two_sided: false, uv: None, area: 4.0 * PI * s.radius * s.radius, material: s.material }
            }
        }
    }
}

/// One emissive primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EmitterShape {
    /// Index into `Scene::triangles`.
    Triangle(u32),
    /// Index into `Scene::spheres`.
    Sphere(u32),
}

/// The emissive primitives of one `[[object]]`, as the viewer's overlay,
/// the shadow maps and the inspector name it: one area light.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    /// Index into `Scene::objects`.
    pub object: u32,
    /// The centre of its bounding box: where a shadow map of it is drawn from.
    pub centre: Vec3,
    /// Half the diagonal of its bounding box: how large it looks to a
    /// shadow filter that estimates a penumbra.
    pub radius: f32,
    /// Total emitted power (luminance, watts), what the distribution weighs.
    pub power: f32,
    /// Its outline: edges of its triangles that no other of its triangles
    /// shares (for a sphere, empty: it is drawn as a circle).
    pub outline: Vec<[Vec3; 2]>,
}

/// A point sampled on an emitter as seen from a shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitterSample {
    /// The point on the emitter and its unit normal (front side).
    pub point: Vec3,
    pub normal: Vec3,
    /// Unit direction from the shading point to `point`, and the distance.
    pub w_i: Vec3,
    pub distance: f32,
    /// Density of `w_i` in solid angle, the choice of emitter included.
    pub pdf: f32,
    /// Radiance leaving `point` towards the shading point (zero from the back
    /// of a one-sided emitter).
    pub radiance: Vec3,
    /// Which area light (`Emitters::lights`) it lies on.
    pub light: u32,
}

/// The scene's emitters and how to sample them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Emitters {
    shapes: Vec<EmitterShape>,
    /// Per shape: the probability of choosing it, and the running sum up to it.
    pmf: Vec<f32>,
    cdf: Vec<f32>,
    /// Per shape: which area light it belongs to.
    light_of: Vec<u32>,
    /// Which shape a primitive is.
    index_of: HashMap<PrimitiveId, u32>,
    pub lights: Vec<AreaLight>,
    /// Emissive primitives left out because they have no area.
    pub degenerate: usize,
}

/// Most boundary edges kept per area light for drawing its outline.
const MAX_OUTLINE_EDGES: usize = 4096;

/// Most triangles of one area light whose shared edges are traced for its
/// outline; a larger emissive mesh is outlined by its bounding box, so a
/// million-triangle emitter costs no edge table of millions.
const MAX_OUTLINE_TRIANGLES: usize = 65_536;

impl Emitters {
    /// Gathers the emitters of `scene`.
    pub fn build(scene: &Scene) -> Emitters {
        let mut e = Emitters::default();
        let mut powers = Vec::new();
        // Per object: (light index) in `e.lights`.
        let mut light_of_object: HashMap<u32, u32> = HashMap::new();
        let mut bounds: Vec<(Vec3, Vec3)> = Vec::new();
        let mut light_triangles: Vec<Vec<[Vec3; 3]>> = Vec::new();
        let mut add = |e: &mut Emitters, shape: EmitterShape, object: u32, power: f32, lo: Vec3, hi: Vec3, tri: Option<[Vec3; 3]>| {
            let light = *light_of_object.entry(object).or_insert_with(|| {
                e.lights.push(AreaLight { object, centre: Vec3::ZERO, radius: 0.0, power: 0.0, outline: Vec::new() });
                bounds.push((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)));
                light_triangles.push(Vec::new());
                (e.lights.len() - 1) as u32
            });
            let id = match shape {
                EmitterShape::Triangle(i) => PrimitiveId::triangle(i),
                EmitterShape::Sphere(i) => PrimitiveId::sphere(i),
            };
            e.index_of.insert(id, e.shapes.len() as u32);
            e.shapes.push(shape);
            e.light_of.push(light);
            powers.push(power);
            let b = &mut bounds[light as usize];
            *b = (b.0.min(lo), b.1.max(hi));
            e.lights[light as usize].power += power;
            if let Some(t) = tri {
                let tris = &mut light_triangles[light as usize];
                // One past the limit marks the light as outlined by its box.
                if tris.len() <= MAX_OUTLINE_TRIANGLES {
                    tris.push(t);
                }
            }
        };
        let emissive: Vec<bool> = scene.materials.iter().map(|m| m.is_emissive() && luminance(m.emission) > 0.0).collect();
        if !emissive.iter().any(|&x| x) {
            return e;
        }
        for i in 0..scene.triangles.len() {
            let t = scene.triangles.at(i);
            if !emissive.get(t.material as usize).copied().unwrap_or(false) {
                continue;
            }
            let area = t.area();
            if !(area > 0.0 && area.is_finite()) {
                e.degenerate += 1;
                continue;
            }
            let sides = if t.two_sided { 2.0 } else { 1.0 };
            let power = PI * area * sides * luminance(scene.materials[t.material as usize].emission);
            let lo = t.v[0].min(t.v[1]).min(t.v[2]);
            let hi = t.v[0].max(t.v[1]).max(t.v[2]);
            add(&mut e, EmitterShape::Triangle(i as u32), t.object, power, lo, hi, Some(t.v));
        }
        for (i, s) in scene.spheres.iter().enumerate() {
            if !emissive.get(s.material as usize).copied().unwrap_or(false) {
                continue;
            }
            if !(s.radius > 0.0) {
                e.degenerate += 1;
                continue;
            }
            let power = PI * 4.0 * PI * s.radius * s.radius * luminance(scene.materials[s.material as usize].emission);
            add(&mut e, EmitterShape::Sphere(i as u32), s.object, power, s.center - s.radius, s.center + s.radius, None);
        }
        let total: f64 = powers.iter().map(|&p| p as f64).sum();
        if !(total > 0.0 && total.is_finite()) {
            return Emitters { degenerate: e.degenerate, ..Emitters::default() };
        }
        let mut running = 0.0f64;
        for &p in &powers {
            e.pmf.push((p as f64 / total) as f32);
            running += p as f64 / total;
            e.cdf.push(running as f32);
        }
        if let Some(last) = e.cdf.last_mut() {
            *last = 1.0;
        }
        for (light, ((lo, hi), tris)) in e.lights.iter_mut().zip(bounds.into_iter().zip(light_triangles)) {
            light.centre = (lo + hi) * 0.5;
            light.radius = (hi - lo).length() * 0.5;
            light.outline = if tris.len() > MAX_OUTLINE_TRIANGLES { box_outline(lo, hi) } else { outline(&tris) };
        }
        e
    }

    /// True when the scene has no usable emitter.
    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }

    pub fn len(&self) -> usize {
        self.shapes.len()
    }

    /// About how many bytes of memory these tables hold (for the bounds
    /// tests and the memory estimate): a few dozen per emissive primitive.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        let per_index_entry = size_of::<PrimitiveId>() + size_of::<u32>() + 8;
        self.shapes.capacity() * size_of::<EmitterShape>()
            + (self.pmf.capacity() + self.cdf.capacity() + self.light_of.capacity()) * size_of::<f32>()
            + self.index_of.capacity() * per_index_entry
            + self.lights.iter().map(|l| size_of::<AreaLight>() + l.outline.capacity() * size_of::<[Vec3; 2]>()).sum::<usize>()
    }

    /// Total emitted power (luminance): what a photon shot from the
    /// emitters shares, and how often they are chosen beside other lights.
    pub fn total_power(&self) -> f32 {
        self.lights.iter().map(|l| l.power).sum()
    }

    /// The primitive `u_choose` picks in proportion to power (by inverting
    /// the running sum of powers) and the probability of that pick. `None`
    /// where there are no emitters or the pick has no power.
    fn choose(&self, u_choose: f32) -> Option<(usize, f32)> {
        if self.shapes.is_empty() {
            return None;
        }
        let k = self.cdf.partition_point(|&c| c <= u_choose).min(self.shapes.len() - 1);
        let pmf = self.pmf[k];
        (pmf > 0.0).then_some((k, pmf))
    }

    /// Where a photon leaves the emitters: a primitive chosen by `u_choose`
    /// in proportion to power, a point uniform on it by `u`, on the side
    /// `u_side` picks for a two-sided triangle. Returns the point, the unit
    /// normal of the side it leaves from, and the flux the photon carries
    /// (before dividing by the photons shot): with a cosine-distributed
    /// direction, `L_e * total_power / luminance(L_e)`.
    pub fn sample_emission(&self, scene: &Scene, u_choose: f32, u: Vec2, u_side: f32) -> Option<(Vec3, Vec3, Vec3)> {
        let (k, _) = self.choose(u_choose)?;
        let at = UniformPoint::on(scene, self.shapes[k], u);
        let normal = if at.two_sided && u_side < 0.5 { -at.normal } else { at.normal };
        let material = &scene.materials[at.material as usize];
        // Only a triangle's point has uvs to read an emission map at.
        let emission = match at.uv {
            Some(uv) => material.emission_at(uv),
            None => material.emission,
        };
        let point = at.point;
        let lum = luminance(emission);
        let flux = emission * (self.total_power() / lum);
        (lum > 0.0 && flux.is_finite() && point.is_finite()).then_some((point, normal, flux))
    }

    /// A point on the emitters for a fixed pattern of light samples, not
    /// seen from any shading point: the primitive chosen by `u_choose` in
    /// proportion to power, the point uniform on it by `u` (on the whole
    /// surface of a sphere). Returns the point, its unit normal, whether
    /// both sides emit, the area light it belongs to and the emitted
    /// radiance divided by the density of the point in area measure (the
    /// choice included): a shading point at distance `d` gets
    /// `value * cos_surface * cos_light / d^2` from it.
    pub fn area_sample(&self, scene: &Scene, u_choose: f32, u: Vec2) -> Option<(Vec3, Vec3, bool, u32, Vec3)> {
        let (k, pmf) = self.choose(u_choose)?;
        let UniformPoint { point, normal, two_sided, area, material, .. } = UniformPoint::on(scene, self.shapes[k], u);
        let emission = scene.materials[material as usize].emission;
        let value = emission * (area / pmf);
        (value.is_finite() && point.is_finite() && normal.is_finite()).then_some((point, normal, two_sided, self.light_of[k], value))
    }

    /// A point on an emitter, seen from `p`: the emitter chosen by `u_choose`
    /// in proportion to power, the point placed on it by `u`. `None` where
    /// there are no emitters or the point is degenerate (on the emitter).
    pub fn sample(&self, scene: &Scene, p: Vec3, u_choose: f32, u: Vec2) -> Option<EmitterSample> {
        let (k, pmf) = self.choose(u_choose)?;
        let light = self.light_of[k];
        match self.shapes[k] {
            EmitterShape::Triangle(i) => {
                let t = scene.triangles.at(i as usize);
                let r = u.x.sqrt();
                let (b0, b1) = (1.0 - r, u.y * r);
                let point = t.v[0] * b0 + t.v[1] * b1 + t.v[2] * (1.0 - b0 - b1);
                let normal = t.geometric_normal();
                let offset = point - p;
                let d2 = offset.length_squared();
                let distance = d2.sqrt();
                if !(distance > 0.0) {
                    return None;
                }
                let w_i = offset / distance;
                let cos_l = -normal.dot(w_i);
                let facing = cos_l > 0.0 || t.two_sided;
                let cos_l = cos_l.abs();
                if !(cos_l > 1e-7) {
                    return None;
                }
                let pdf = pmf * d2 / (t.area() * cos_l);
                let uv = t.uv[0] * b0 + t.uv[1] * b1 + t.uv[2] * (1.0 - b0 - b1);
                let radiance = if facing { scene.materials[t.material as usize].emission_at(uv) } else { Vec3::ZERO };
                let normal = if -normal.dot(w_i) > 0.0 { normal } else { -normal };
                finite(EmitterSample { point, normal, w_i, distance, pdf, radiance, light })
            }
            EmitterShape::Sphere(i) => {
                let s = &scene.spheres[i as usize];
                let emission = scene.materials[s.material as usize].emission;
                let to_centre = s.center - p;
                let d2 = to_centre.length_squared();
                let r2 = s.radius * s.radius;
                if d2 <= r2 * (1.0 + 1e-4) {
                    // Inside (or on) the sphere: its outside is never seen.
                    return None;
                }
                let d = d2.sqrt();
                let axis = to_centre / d;
                let sin2_max = r2 / d2;
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                // 1 - cos_max without cancellation for small cones.
                let one_minus = sin2_max / (1.0 + cos_max);
                let cos_t = 1.0 - u.x * one_minus;
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                let (t1, t2) = tangents(axis);
                let w_i = (axis * cos_t + t1 * (sin_t * phi.cos()) + t2 * (sin_t * phi.sin())).normalize();
                // Nearest intersection along w_i (clamped onto the tangent for the cone's rim).
                let along = d * cos_t;
                let distance = along - (r2 - d2 * sin_t * sin_t).max(0.0).sqrt();
                let point = p + w_i * distance;
                let normal = (point - s.center).normalize_or_zero();
                let pdf = pmf / (2.0 * PI * one_minus);
                finite(EmitterSample { point, normal, w_i, distance, pdf, radiance: emission, light })
            }
        }
    }

    /// The density (solid angle, choice included) with which `sample`
    /// returns the direction from `p` towards `hit`, a point on an emitter;
    /// zero when `hit` is on no emitter.
    pub fn pdf(&self, scene: &Scene, p: Vec3, hit: &SurfaceHit) -> f32 {
        let id = PrimitiveId::new(hit.kind, hit.primitive);
        let Some(&k) = self.index_of.get(&id) else { return 0.0 };
        let pmf = self.pmf[k as usize];
        match hit.kind {
            PrimitiveKind::Triangle => {
                let t = scene.triangles.at(hit.primitive as usize);
                let offset = hit.position - p;
                let d2 = offset.length_squared();
                let cos_l = t.geometric_normal().dot(offset).abs() / d2.sqrt();
                if !(cos_l > 1e-7) {
                    return 0.0;
                }
                pmf * d2 / (t.area() * cos_l)
            }
            PrimitiveKind::Sphere => {
                let s = &scene.spheres[hit.primitive as usize];
                let d2 = (s.center - p).length_squared();
                let r2 = s.radius * s.radius;
                if d2 <= r2 * (1.0 + 1e-4) {
                    return 0.0;
                }
                let sin2_max = r2 / d2;
                let one_minus = sin2_max / (1.0 + (1.0 - sin2_max).max(0.0).sqrt());
                pmf / (2.0 * PI * one_minus)
            }
            PrimitiveKind::Csg => 0.0,
        }
    }
}

/// Radiance a surface hit emits towards unit `w_o`: its material's emission
/// from the front side (either side when two-sided: the hit then faces the
/// viewer already), zero otherwise.
#[inline]
pub fn emitted(scene: &Scene, hit: &SurfaceHit, w_o: Vec3) -> Vec3 {
    let material = &scene.materials[hit.material as usize];
    if !material.is_emissive() || hit.back_face || hit.geometric_normal.dot(w_o) <= 0.0 {
        return Vec3::ZERO;
    }
    material.emission_at(hit.uv)
}

/// The luminance of a linear RGB colour (Rec. 709 weights).
#[inline]
fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Two unit vectors that make an orthonormal frame with unit `n`.
fn tangents(n: Vec3) -> (Vec3, Vec3) {
    let a = if n.x.abs() > 0.9 { Vec3::Y } else { Vec3::X };
    let t1 = n.cross(a).normalize();
    (t1, n.cross(t1))
}

fn finite(s: EmitterSample) -> Option<EmitterSample> {
    (s.pdf.is_finite() && s.pdf > 0.0 && s.point.is_finite() && s.w_i.is_finite() && s.distance.is_finite()).then_some(s)
}

/// The edges of `tris` that no other of them shares (a quad's four sides).
/// The twelve edges of the box from `lo` to `hi`.
fn box_outline(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 2]> {
    let corner = |i: usize| Vec3::new(if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z });
    let mut edges = Vec::with_capacity(12);
    for i in 0..8 {
        for bit in [1, 2, 4] {
            if i & bit == 0 {
                edges.push([corner(i), corner(i | bit)]);
            }
        }
    }
    edges
}

fn outline(tris: &[[Vec3; 3]]) -> Vec<[Vec3; 2]> {
    let key = |v: Vec3| v.to_array().map(f32::to_bits);
    let mut count: HashMap<([u32; 3], [u32; 3]), (u32, [Vec3; 2])> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (ka, kb) = (key(a), key(b));
            let id = if ka <= kb { (ka, kb) } else { (kb, ka) };
            count.entry(id).or_insert((0, [a, b])).0 += 1;
        }
    }
    let mut edges: Vec<[Vec3; 2]> = count.into_values().filter(|(n, _)| *n == 1).map(|(_, e)| e).collect();
    edges.sort_by(|a, b| a[0].to_array().partial_cmp(&b[0].to_array()).unwrap_or(std::cmp::Ordering::Equal));
    edges.truncate(MAX_OUTLINE_EDGES);
    edges
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, Sphere, Triangle};

    fn lamp_scene() -> Scene {
        let mut scene = Scene::default();
        let mut lamp = Material::black();
        lamp.emission = Vec3::splat(2.0);
        scene.materials.push(lamp);
        // A unit square at y = 1 facing down, as two triangles.
        let v = [Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 1.0), Vec3::new(0.0, 1.0, 1.0)];
        for tri in [[v[0], v[1], v[2]], [v[0], v[2], v[3]]] {
            let n = Triangle::normal_of(&tri);
            scene.triangles.push(Triangle { v: tri, n: [n; 3], uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided: false });
        }
        scene.spheres.push(Sphere { center: Vec3::new(5.0, 0.0, 0.0), radius: 0.5, material: 0, object: 1 });
        scene
    }

    #[test]
    fn power_picks_emitters_and_outlines_join_triangles() {
        let scene = lamp_scene();
        let e = Emitters::build(&scene);
        assert_eq!(e.len(), 3);
        assert_eq!(e.lights.len(), 2);
        // The square's four sides, not its diagonal.
        assert_eq!(e.lights[0].outline.len(), 4);
        // Power: pi * area * L for the square (area 1), pi * 4 pi r^2 * L for the sphere.
        let square = PI * 2.0;
        let sphere = PI * 4.0 * PI * 0.25 * 2.0;
        assert!((e.lights[0].power - square).abs() < 1e-4);
        assert!((e.pmf[2] - sphere / (square + sphere)).abs() < 1e-5);
    }

    #[test]
    fn sampled_densities_match_pdf_and_integrate_to_one() {
        // Monte-Carlo: E[1 / pdf] over samples from p equals the solid angle
        // the emitters cover, which for the sphere alone is 2 pi (1 - cos_max).
        let scene = lamp_scene();
        let e = Emitters::build(&scene);
        let p = Vec3::new(0.5, 0.0, 0.5);
        let mut rng = 1u64;
        let mut next = || {
            rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (rng >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..200 {
            let s = e.sample(&scene, p, next(), Vec2::new(next(), next())).unwrap();
            let (kind, primitive) = match e.shapes[e.light_of.iter().position(|&l| l == s.light).unwrap()] {
                EmitterShape::Triangle(_) => (PrimitiveKind::Triangle, if (s.point.x - s.point.z) > 0.0 { 0 } else { 1 }),
                EmitterShape::Sphere(i) => (PrimitiveKind::Sphere, i),
            };
            let hit = SurfaceHit {
                position: s.point, geometric_normal: s.normal, shading_normal: s.normal, barycentric: Vec3::ZERO, uv: Vec2::ZERO, t: s.distance,
                kind, primitive, object: 0, material: 0, back_face: false, diff: crate::scene::Differentials::ZERO,
            };
            let again = e.pdf(&scene, p, &hit);
            assert!((again - s.pdf).abs() <= 1e-3 * s.pdf, "{again} vs {}", s.pdf);
        }
    }
}
