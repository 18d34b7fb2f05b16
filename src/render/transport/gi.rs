//! Indirect light behind every renderer's primary visibility: ambient
//! occlusion, unidirectional path tracing and photon mapping. All three are
//! parts of `shade()`, so the ray casters and the rasterizers get them alike;
//! their random numbers come from the sample's own stream (`SampleRng`).

use crate::render::transport::bsdf_sampling::sample_bsdf;
use crate::render::transport::photon_map::PhotonMap;
use crate::render::inspect::pixel_record::{Bounce, Recorder};
use crate::render::transport::sampling::{cosine_hemisphere, from_local, luminance, SampleRng};
use crate::render::{RayCounts, SceneQuery};
use crate::math::Vec3;
use crate::scene::SurfaceHit;

pub use crate::render::gi_settings::{GiMode, GiSettings, MAX_BOUNCES};

/// Russian roulette decides on the bounce from this depth on (0 = the eye
/// ray's surface): from the fifth surface a path reaches, as Mitsuba's
/// `path` integrator with its default `rr_depth` of 5 (its depth counts
/// surfaces from 1), so that both render the same estimator and their
/// times at equal samples compare like with like.
const ROULETTE_DEPTH: u32 = 4;

/// What a sample carries down its path: its random numbers, the product of
/// the weights so far (for Russian roulette), and the photon map to read.
pub struct PathState<'a> {
    pub rng: SampleRng,
    pub throughput: Vec3,
    pub photons: Option<&'a PhotonMap>,
    /// How the ray being followed was chosen (weights the light it finds).
    pub arrival: crate::render::transport::arrival::Arrival,
}

impl<'a> PathState<'a> {
    pub fn new(pixel: u32, sample: u32, spp: u32, gi: &GiSettings, photons: Option<&'a PhotonMap>) -> PathState<'a> {
        PathState { rng: SampleRng::stratified(pixel, sample, spp, gi.seed), throughput: Vec3::ONE, photons, arrival: Default::default() }
    }
}

/// The unoccluded fraction of the cosine-weighted hemisphere above `hit`
/// within `distance`, estimated with `samples` rays.
pub fn ambient_occlusion<Q: SceneQuery, R: Recorder>(
    query: &Q,
    hit: &SurfaceHit,
    gi: &GiSettings,
    bump: f32,
    rng: &mut SampleRng,
    counts: &mut RayCounts,
    rec: &mut R,
) -> f32 {
    let samples = gi.ao_samples.max(1);
    let mut open = 0u32;
    for _ in 0..samples {
        let dir = from_local(cosine_hemisphere(rng.next_2d()), hit.shading_normal);
        // Directions below the geometric surface are blocked by it.
        if dir.dot(hit.geometric_normal) <= 0.0 {
            continue;
        }
        let ray = hit.spawn_ray_front(dir, bump);
        counts.shadow += 1;
        rec.in_shadow_ray(true);
        rec.ray(&ray, gi.ao_distance, 1);
        let blocked = query.occluder(&ray, gi.ao_distance, counts, rec).is_some();
        rec.in_shadow_ray(false);
        open += (!blocked) as u32;
    }
    open as f32 / samples as f32
}

/// Russian roulette for a path about to continue with `throughput`: `None`
/// ends it, otherwise the factor that keeps the estimate unbiased.
pub fn roulette(depth: u32, throughput: Vec3, rng: &mut SampleRng) -> Option<(f32, f32)> {
    if depth < ROULETTE_DEPTH {
        return Some((1.0, 1.0));
    }
    let q = throughput.max_element().clamp(0.05, 0.95);
    (rng.next_f32() < q).then_some((1.0 / q, q))
}

/// One sampled bounce off the non-delta lobes at `hit`: the direction, its
/// weight with the roulette applied, and its density; `None` when the path
/// ends here.
#[allow(clippy::too_many_arguments)]
pub fn sample_bounce<R: Recorder>(
    scene: &crate::scene::Scene,
    material: &crate::scene::Material,
    lobes: crate::scene::material::PointLobes,
    hit: &SurfaceHit,
    w_o: Vec3,
    depth: u32,
    path: &mut PathState,
    rec: &mut R,
) -> Option<(Vec3, Vec3, f32)> {
    let choice = path.rng.next_f32();
    let u = path.rng.next_2d();
    let frame = crate::render::transport::bsdf::ShadingFrame::at(scene, hit, material);
    let s = sample_bsdf(material, lobes, frame, w_o, choice, u)?;
    // A direction into the geometric surface would leave from its far side.
    if s.w_i.dot(hit.geometric_normal) <= 0.0 {
        return None;
    }
    let survival = roulette(depth, path.throughput * s.weight, &mut path.rng);
    if R::ENABLED {
        rec.bounce(Bounce { depth, w_i: s.w_i, pdf: s.pdf, weight: s.weight, throughput: path.throughput * s.weight, survival: survival.map_or(0.0, |x| x.1) });
    }
    let (scale, _) = survival?;
    Some((s.w_i, s.weight * scale, s.pdf))
}

/// Choose between two delta lobes with weights `a` and `b` in proportion to
/// their luminance: `Some(true)` picks `a`; the factor keeps the estimate unbiased.
pub fn choose_lobe(a: Vec3, b: Vec3, rng: &mut SampleRng) -> (bool, f32) {
    let (la, lb) = (luminance(a).max(0.0), luminance(b).max(0.0));
    if lb <= 0.0 {
        return (true, 1.0);
    }
    if la <= 0.0 {
        return (false, 1.0);
    }
    let p = la / (la + lb);
    if rng.next_f32() < p { (true, 1.0 / p) } else { (false, 1.0 / (1.0 - p)) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::PreparedScene;
    use crate::render::inspect::pixel_record::NoRecord;
    use crate::render::accel::bvh::BvhQuery;
    use crate::scene::{PrimitiveKind, Scene, Triangle};
    use crate::math::Vec2;

    /// A point at distance d from an infinite wall, facing it, sees the wall
    /// within distance D in the directions with cos(theta) > d / D, whose
    /// cosine-weighted share is 1 - (d/D)^2: the unoccluded fraction is (d/D)^2.
    #[test]
    fn occlusion_by_a_wall_matches_the_analytic_fraction() {
        let big = 1e4;
        let mut scene = Scene::default();
        scene.materials.push(crate::scene::Material::default_grey());
        let wall = [Vec3::new(-big, -big, 0.0), Vec3::new(big, -big, 0.0), Vec3::new(big, big, 0.0), Vec3::new(-big, big, 0.0)];
        for t in [[0, 1, 2], [0, 2, 3]] {
            scene.triangles.push(Triangle { v: t.map(|i| wall[i]), n: [Vec3::Z; 3], uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided: true });
        }
        let prepared = PreparedScene::new(scene);
        let query = BvhQuery::new(&prepared);
        for (d, distance) in [(0.5f32, 1.0f32), (0.25, 1.0), (1.0, 4.0), (2.0, 1.0)] {
            let hit = SurfaceHit {
                position: Vec3::new(0.3, -0.2, d),
                geometric_normal: -Vec3::Z,
                shading_normal: -Vec3::Z,
                barycentric: Vec3::ZERO,
                uv: Vec2::ZERO,
                t: 1.0,
                kind: PrimitiveKind::Sphere,
                primitive: 0,
                object: 0,
                material: 0,
                back_face: false,
                diff: crate::scene::Differentials::ZERO,
            };
            let gi = GiSettings { mode: GiMode::Ao, ao_samples: 20_000, ao_distance: distance, ..GiSettings::default() };
            let mut rng = SampleRng::for_pixel(1, 2, 3);
            let open = ambient_occlusion(&query, &hit, &gi, 0.0, &mut rng, &mut RayCounts::default(), &mut NoRecord);
            let exact = (d / distance).min(1.0).powi(2);
            let sigma = (exact * (1.0 - exact) / 20_000.0).sqrt();
            assert!((open - exact).abs() <= 4.0 * sigma + 1e-6, "d {d}, D {distance}: {open} vs {exact}");
        }
    }

    #[test]
    fn roulette_keeps_the_expected_weight() {
        let mut rng = SampleRng::for_index(5, 0, 0);
        let t = Vec3::splat(0.3);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            if let Some((scale, _)) = roulette(10, t, &mut rng) {
                sum += scale as f64;
            }
        }
        assert!((sum / n as f64 - 1.0).abs() < 0.02, "{}", sum / n as f64);
        assert_eq!(roulette(0, Vec3::ZERO, &mut rng), Some((1.0, 1.0)));
        // Mitsuba's rr_depth = 5: the bounces off the first four surfaces
        // always go on, the fifth's faces the roulette.
        assert!((0..1000).all(|_| roulette(3, Vec3::splat(0.01), &mut rng) == Some((1.0, 1.0))));
        assert!((0..1000).any(|_| roulette(4, Vec3::splat(0.01), &mut rng).is_none()));
    }
}
