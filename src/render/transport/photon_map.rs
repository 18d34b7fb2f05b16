//! Photon mapping (Jensen): photons shot from the lights bounce through the
//! scene and are stored where they land on diffuse surfaces after at least
//! one bounce, so the map holds the indirect light, caustics included, while
//! `shade()` keeps computing direct light with shadow rays. Radiance is
//! estimated from the k nearest photons. The map is built once per scene,
//! lights, materials and photon settings, and cached on the prepared scene.

use crate::render::gi_settings::GiSettings;
use crate::render::transport::kd_tree::{KdTree, Neighbour};
use crate::render::inspect::pixel_record::NoRecord;
use crate::render::accel::bvh::BvhQuery;
use crate::render::transport::sampling::{cosine_hemisphere, from_local, luminance, tangents, uniform_disk, uniform_sphere, SampleRng};
use crate::render::transport::bsdf::{bsdf, mirror_direction, refraction};
use crate::render::{PreparedScene, RayCounts, SceneQuery};
use crate::render::keyed_cache::KeyedCache;
use crate::math::{Radiance, Ray, Vec3};
use crate::scene::{Light, Material, Scene, SurfaceHit};
use rayon::prelude::*;
use std::cell::RefCell;
use std::f32::consts::PI;
use std::sync::Arc;

/// One stored photon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    pub position: Vec3,
    /// Unit direction back towards where the photon came from.
    pub w_i: Vec3,
    /// Flux it carries (watts per colour channel).
    pub power: Vec3,
    /// The geometric normal of the surface it landed on (photons on the
    /// other side of a thin wall must not light this side).
    pub normal: Vec3,
}

/// The seed stream photons draw from, apart from every pixel's.
const PHOTON_STREAM: u64 = 0x70686f746f6e;

/// A photon path ends after this many bounces whatever roulette says.
const MAX_PHOTON_BOUNCES: u32 = 32;

pub struct PhotonMap {
    tree: KdTree<Photon>,
    /// Photons shot (the stored ones are fewer: some escape or are absorbed).
    pub shot: u32,
    /// No photon farther than this (squared) enters an estimate.
    max_radius2: f32,
}

/// What a photon map is built from: when any of it changes, the map must be rebuilt.
#[derive(Clone, Debug, PartialEq)]
pub struct MapKey {
    lights: Vec<Light>,
    /// Per material: the terms photons read (textures are never edited).
    materials: Vec<[f32; 13]>,
    photons: u32,
    seed: u64,
    bump: u32,
}

impl MapKey {
    fn of(scene: &Scene, gi: &GiSettings, bump: f32) -> MapKey {
        let m = |m: &Material| {
            let (l, g, r, t) = (m.lambertian, m.glossy, m.mirror, m.transmission);
            [l.x, l.y, l.z, g.x, g.y, g.z, r.x, r.y, r.z, t.x, t.y, t.z, m.ior]
        };
        MapKey { lights: scene.lights.clone(), materials: scene.materials.iter().map(m).collect(), photons: gi.photons, seed: gi.seed, bump: bump.to_bits() }
    }
}

/// The last map built for a prepared scene, keyed by what it was built from.
pub type PhotonMapCache = KeyedCache<MapKey, PhotonMap>;

impl PreparedScene {
    /// The photon map for the scene's current lights and materials and the
    /// photon settings `gi`, from the cache or built now (in parallel).
    pub fn photon_map(&self, gi: &GiSettings, bump: f32) -> Arc<PhotonMap> {
        self.photon_cache.get(MapKey::of(&self.scene, gi, bump), |_| PhotonMap::build(self, gi, bump))
    }
}

/// The most memory a photon map's build may take (`check_budget`).
pub const MAX_PHOTON_MAP_BYTES: u64 = 4 << 30;
/// Bytes per stored photon at the build's peak. The kd-tree build holds its
/// (position, photon) pairs (60 bytes) beside the finished positions,
/// photons and split axes (61); measured, the peak resident memory grows by
/// 132 bytes per stored photon (`cornell-gi`, 1 to 4 million shot).
const PEAK_BYTES_PER_STORED: u64 = 136;
/// Photons traced to measure how many each one stores.
const PILOT_PHOTONS: u32 = 4096;

impl PreparedScene {
    /// Refuses, before building, a photon map whose build would take more
    /// than `MAX_PHOTON_MAP_BYTES`. How many photons one shot stores depends
    /// on the scene (walls bounce it on, open sky lets it go), so it is
    /// measured: up to `PILOT_PHOTONS` of the map's own photons, spread over
    /// its index range, are traced, and the estimate takes the mean plus
    /// three standard errors.
    pub fn check_photon_budget(&self, gi: &GiSettings, bump: f32) -> Result<(), String> {
        let shot = gi.photons as u64;
        let most_stored_per_shot = (MAX_PHOTON_BOUNCES - 1) as u64;
        if shot * most_stored_per_shot * PEAK_BYTES_PER_STORED <= MAX_PHOTON_MAP_BYTES {
            return Ok(());
        }
        // A map built already passed (the viewer asks again with every
        // frame it requests).
        if self.photon_cache.holds(&MapKey::of(&self.scene, gi, bump)) {
            return Ok(());
        }
        let sources = Sources::of(&self.scene);
        if !(sources.total > 0.0 && sources.total.is_finite()) {
            return Ok(());
        }
        let query = BvhQuery::new(self);
        let n = PILOT_PHOTONS.min(gi.photons);
        let counts: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|k| {
                let i = (k as u64 * shot / n as u64) as u32;
                sources.shoot(&self.scene, &query, i, gi.photons, gi.seed, bump).len() as f64
            })
            .collect();
        let mean = counts.iter().sum::<f64>() / n as f64;
        let var = counts.iter().map(|c| (c - mean) * (c - mean)).sum::<f64>() / (n.max(2) - 1) as f64;
        let per_shot = mean + 3.0 * (var / n as f64).sqrt();
        let bytes = shot as f64 * per_shot * PEAK_BYTES_PER_STORED as f64;
        if bytes <= MAX_PHOTON_MAP_BYTES as f64 {
            return Ok(());
        }
        let most = (MAX_PHOTON_MAP_BYTES as f64 / (per_shot * PEAK_BYTES_PER_STORED as f64)) as u64;
        Err(format!(
            "--photons {shot} would store about {:.0} million photons ({mean:.2} per photon shot, measured on {n}) and take about {:.1} GiB to build, more than the photon map's budget of {} GiB; use at most {most} photons",
            shot as f64 * mean / 1e6,
            bytes / (1u64 << 30) as f64,
            MAX_PHOTON_MAP_BYTES >> 30
        ))
    }
}

thread_local! {
    static NEIGHBOURS: RefCell<Vec<Neighbour>> = const { RefCell::new(Vec::new()) };
}

impl PhotonMap {
    fn build(prepared: &PreparedScene, gi: &GiSettings, bump: f32) -> PhotonMap {
        let query = BvhQuery::new(prepared);
        let sources = Sources::of(&prepared.scene);
        let radius = sources.radius;
        let shot = gi.photons;
        let photons: Vec<Photon> = if sources.total > 0.0 && sources.total.is_finite() && shot > 0 {
            (0..shot).into_par_iter().map(|i| sources.shoot(&prepared.scene, &query, i, shot, gi.seed, bump)).flatten_iter().collect()
        } else {
            Vec::new()
        };
        let tree = KdTree::build(photons, |p| p.position);
        // The estimate's radius is capped at a tenth of the scene: beyond it,
        // a sparse map would smear light across whole walls.
        let max_radius2 = (0.1 * radius) * (0.1 * radius);
        PhotonMap { tree, shot, max_radius2 }
    }

    /// Photons stored.
    pub fn len(&self) -> usize {
        self.tree.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tree.is_empty()
    }

    /// Reflected radiance towards `w_o` at `hit` from the `k` nearest photons:
    /// the sum of `f * flux` over a disc of their radius, divided by its area.
    pub fn radiance(&self, hit: &SurfaceHit, material: &Material, lobes: crate::scene::material::PointLobes, w_o: Vec3, k: usize) -> Radiance {
        NEIGHBOURS.with(|cell| {
            let mut found = cell.borrow_mut();
            self.tree.nearest_as_heap(hit.position, k.max(1), self.max_radius2, &mut found);
            // The heap's top is the farthest neighbour: the disc's radius.
            let Some(farthest) = found.first() else { return Radiance::ZERO };
            let r2 = farthest.distance2;
            if r2 <= 0.0 {
                return Radiance::ZERO;
            }
            let mut sum = Vec3::ZERO;
            for nb in found.iter() {
                let p = self.tree.item(nb.index);
                if p.normal.dot(hit.geometric_normal) <= 0.0 || p.w_i.dot(hit.shading_normal) <= 0.0 {
                    continue;
                }
                sum += bsdf(material, lobes, hit.shading_normal, p.w_i, w_o) * p.power;
            }
            sum / (PI * r2)
        })
    }
}

/// Where photons leave from: the point and directional lights, then (one
/// source each) the emissive surfaces and the environment, picked in
/// proportion to the flux they send into the scene. Only the choice needs
/// the flux; each photon's power is divided by its own probability.
struct Sources {
    flux: Vec<Vec3>,
    weights: Vec<f32>,
    total: f32,
    emitters_source: usize,
    sky_source: usize,
    sky: Option<Arc<crate::scene::environment::EnvironmentLight>>,
    /// The scene's bounding sphere: parallel light enters through a disc across it.
    center: Vec3,
    radius: f32,
}

impl Sources {
    fn of(scene: &Scene) -> Sources {
        let (center, radius) = match scene.bounds() {
            Some((lo, hi)) => ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-3)),
            None => (Vec3::ZERO, 1.0),
        };
        let mut flux: Vec<Vec3> = scene
            .lights
            .iter()
            .map(|l| match *l {
                Light::Point { power, .. } => power,
                Light::Directional { irradiance, .. } => irradiance * (PI * radius * radius),
            })
            .collect();
        let emitters_source = flux.len();
        flux.push(Vec3::splat(scene.emitters.total_power()));
        let sky = scene.environment.as_ref().and_then(|e| e.light.clone());
        let sky_source = flux.len();
        flux.push(Vec3::splat(sky.as_ref().map_or(0.0, |l| l.flux_estimate() * PI * radius * radius)));
        let weights: Vec<f32> = flux.iter().map(|f| luminance(*f).max(0.0)).collect();
        let total: f32 = weights.iter().sum();
        Sources { flux, weights, total, emitters_source, sky_source, sky, center, radius }
    }

    /// Photon `i` of `shot`: its light, its first ray and power, and what it
    /// stores on its way. A function of (i, shot, seed) alone.
    fn shoot(&self, scene: &Scene, query: &BvhQuery, i: u32, shot: u32, seed: u64, bump: f32) -> Vec<Photon> {
        let (center, radius) = (self.center, self.radius);
        let mut rng = SampleRng::for_index(PHOTON_STREAM, i as u64, seed);
        let mut pick = rng.next_f32() * self.total;
        let mut light = self.weights.len() - 1;
        for (k, w) in self.weights.iter().enumerate() {
            if pick < *w {
                light = k;
                break;
            }
            pick -= w;
        }
        let p_light = self.weights[light] / self.total;
        let share = 1.0 / (shot as f32 * p_light);
        let (ray, power) = if light == self.emitters_source {
            // A point on an emitter, a cosine-weighted direction
            // about its normal (as a Lambertian emitter sends light).
            let (u_choose, u, u_side) = (rng.next_f32(), rng.next_2d(), rng.next_f32());
            let Some((point, normal, flux)) = scene.emitters.sample_emission(scene, u_choose, u, u_side) else { return Vec::new() };
            let dir = from_local(cosine_hemisphere(rng.next_2d()), normal);
            (Ray::new(point + normal * bump, dir), flux * share)
        } else if light == self.sky_source {
            // A direction sampled from the sky, entering through a
            // disc across the scene's bounding sphere.
            let Some(l) = self.sky.as_ref() else { return Vec::new() };
            let Some((to_sky, pdf)) = l.sample(rng.next_2d()) else { return Vec::new() };
            let d = -to_sky;
            let (t, b) = tangents(d);
            let o = uniform_disk(rng.next_2d()) * radius;
            let radiance = scene.miss_radiance(to_sky);
            let ray = Ray::new(center - d * (2.0 * radius) + t * o.x + b * o.y, d);
            (ray, radiance * (PI * radius * radius / pdf) * share)
        } else {
            let ray = match scene.lights[light] {
                Light::Point { position, .. } => Ray::new(position, uniform_sphere(rng.next_2d())),
                Light::Directional { direction, .. } => {
                    let d = direction.normalize_or_zero();
                    let (t, b) = tangents(d);
                    let o = uniform_disk(rng.next_2d()) * radius;
                    Ray::new(center - d * (2.0 * radius) + t * o.x + b * o.y, d)
                }
            };
            (ray, self.flux[light] * share)
        };
        if !power.is_finite() {
            return Vec::new();
        }
        trace_photon(scene, query, ray, power, bump, &mut rng)
    }
}

/// Follows one photon from the light, storing it at each diffuse surface it
/// reaches after its first bounce, until it is absorbed or escapes.
fn trace_photon(scene: &Scene, query: &BvhQuery, mut ray: Ray, mut power: Vec3, bump: f32, rng: &mut SampleRng) -> Vec<Photon> {
    let mut stored = Vec::new();
    let mut inside = false;
    let mut counts = RayCounts::default();
    for bounce in 0..MAX_PHOTON_BOUNCES {
        let Some(hit) = query.closest(&ray, f32::INFINITY, inside, &mut counts, &mut NoRecord) else { break };
        let material = &scene.materials[hit.material as usize];
        // Photons have no pixel footprint: the finest level, bilinear.
        let tint = scene.vertex_colour(hit.kind, hit.primitive, hit.barycentric);
        let lobes = material.lobes_tinted(hit.uv, &crate::scene::texture::Footprint::default(), crate::scene::texture::TextureFilter::Bilinear, tint);
        let diffuse = lobes.albedo + if material.has_glossy() { lobes.glossy } else { Vec3::ZERO };
        if bounce > 0 && diffuse != Vec3::ZERO {
            stored.push(Photon { position: hit.position, w_i: -ray.dir, power, normal: hit.geometric_normal });
        }
        // Russian roulette between the lobes by their luminance.
        let (p_d, p_m, p_t) = (luminance(diffuse).max(0.0), luminance(material.mirror).max(0.0), luminance(material.transmission).max(0.0));
        let sum = p_d + p_m + p_t;
        let scale = if sum > 1.0 { 1.0 / sum } else { 1.0 };
        let (p_d, p_m, p_t) = (p_d * scale, p_m * scale, p_t * scale);
        let u = rng.next_f32();
        let w_o = -ray.dir;
        if u < p_d {
            let dir = from_local(cosine_hemisphere(rng.next_2d()), hit.shading_normal);
            if dir.dot(hit.geometric_normal) <= 0.0 {
                break;
            }
            power *= diffuse / p_d;
            ray = hit.spawn_ray_front(dir, bump);
            inside = false;
        } else if u < p_d + p_m {
            let dir = mirror_direction(hit.geometric_normal, w_o);
            power *= material.mirror / p_m;
            ray = hit.spawn_ray_front(dir, bump);
            inside = false;
        } else if u < p_d + p_m + p_t {
            power *= material.transmission / p_t;
            let (fresnel, refracted) = refraction(&hit, material, w_o);
            match refracted {
                Some(dir) if rng.next_f32() >= fresnel => {
                    ray = hit.spawn_ray_back(dir, bump);
                    inside = true;
                }
                _ => {
                    ray = hit.spawn_ray_front(mirror_direction(hit.geometric_normal, w_o), bump);
                    inside = false;
                }
            }
        } else {
            break;
        }
        if !power.is_finite() {
            break;
        }
    }
    stored
}
