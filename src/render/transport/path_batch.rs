//! Path tracing's bounces for many eye samples at once. `shade()` follows
//! one sample's path by recursion: direct light at a surface, then one
//! sampled direction, the radiance found along it (`shade()` again, one
//! level deeper) times the bounce's weight. A `PathPool` follows the paths
//! of all the samples put in it (a ray caster's band of tiles, a
//! rasterizer's batches) together, one bounce at a time: the surviving
//! paths' rays are traced (through the flat tree in packets of 64, which
//! walk together near the root and split into single walks below), their
//! hit records built eight at a time, their shadow rays traced ahead in
//! packets too, and their direct light computed eight lanes wide, as
//! `shade_batch` does for the eye's surfaces. The more samples, the fuller
//! the lanes and packets stay as paths end. The answers are each single
//! ray's, bit for bit.
//!
//! Each sample gets what the recursion computes for it, bit for bit (pixel
//! replays run the recursion): the same random draws in the same order,
//! the same rays, the same records and direct light, and the sums taken in
//! the recursion's order, from the last bounce back to the first
//! (`direct + weight * deeper`). A path that reaches a mirror or glass,
//! whose delta lobes add a second branch, or its last permitted bounce,
//! finishes in `shade()`'s own code from there.

use crate::render::transport::bsdf_sampling::cosine_lobe;
use crate::scene::material::{DiffuseModel, PointLobes};
use crate::render::transport::gi;
use crate::render::transport::gi::{GiMode, PathState};
use crate::render::inspect::pixel_record::NoRecord;
use crate::render::transport::shade;
use crate::render::transport::shading::Shading;
use crate::render::transport::shade_batch::{direct_in_lanes, shadow_rays_of, Batch, IN_ORDER, LANES};
use crate::render::accel::packet::{Packet, HYBRID_ALONE, PACKET_RAYS};
use crate::render::{BatchHit, PassJob, RayCounts, SceneQuery, ShadowMode};
use crate::render::transport::sampling::{luminance, StreamLanes};
use crate::math::lanes::{mask_bits, simd_level, Lane, V3};
use crate::math::{Radiance, Ray, Vec3};
use fearless_simd::{dispatch, f32x8, Simd, SimdFrom};
use crate::scene::hit_lanes::{Floats, HitLanes, TriangleHitInput};

/// Whether frames hand their samples' paths to a `PathPool`.
#[inline]
pub fn takes(job: &PassJob) -> bool {
    // Emitters and the environment are lit by `shade()`'s own code (light
    // samples weighted against the bounces): those scenes follow its recursion.
    let scene = &job.prepared.scene;
    job.settings.gi.mode == GiMode::Path && !scene.has_sampled_lights() && !scene.materials.iter().any(|m| m.is_emissive())
}

/// `shade_batch` with `--gi path`, the paths not followed yet: the batch's
/// samples go into `pool`, lane k's radiance meant for `slots[k]` of what
/// `PathPool::follow_into` writes, with those of other batches. (Frames
/// take this way; `shade_batch` itself follows each lane's path alone, by
/// `shade()`'s recursion, to the same bits.)
#[allow(clippy::too_many_arguments)]
pub fn start_paths<'p, Q: SceneQuery>(job: &PassJob<'p>, query: &Q, batch: &Batch, blocked: Option<&[u8]>, slots: &[usize], counts: &mut RayCounts, pool: &mut PathPool<'p>) {
    assert_eq!(slots.len(), batch.len);
    assert!(batch.pending.len == 0 && batch.pending_ray_count == 0, "start_paths on a batch with hits not built (`build_pending`)");
    let settings = job.settings;
    let paths = pool.start(batch.len, |i| PathState::new(batch.pixels[i], batch.samples[i], settings.spp, &settings.gi, job.photons));
    let (lobes, direct) = direct_in_lanes(job, query, &batch.hits, &batch.w_o, batch.len, paths, &IN_ORDER, blocked, counts);
    pool.add(&batch.hits, &batch.w_o, slots, &lobes, &direct);
}

/// One bounce a path took, kept until the radiance found beyond it is
/// known: which sample, the surface's direct light (with its ambient
/// term) and the bounce's weight.
struct Bounce {
    sample: usize,
    direct: Radiance,
    weight: Vec3,
}

/// Up to eight surfaces that live paths stand on: lane k holds sample
/// `sample[k]`'s hit, the unit direction back along its ray, its lobes
/// and its direct light.
struct Group {
    len: usize,
    hits: HitLanes,
    w_o: [Floats; 3],
    sample: [usize; LANES],
    lobes: [PointLobes; LANES],
    direct: [Radiance; LANES],
    /// Triangle hits whose records are not built yet, and their lanes.
    pending: [TriangleHitInput; LANES],
    pending_lanes: [usize; LANES],
    pending_len: usize,
}

/// The samples whose paths are followed together. Kept between flushes
/// (`follow_into` empties it), so that its buffers are allocated once.
pub struct PathPool<'p> {
    /// Each sample's random numbers and throughput.
    paths: Vec<PathState<'p>>,
    /// Where each sample's radiance goes in the caller's output.
    slots: Vec<usize>,
    /// What each sample's path finds beyond its last bounce in `bounces`.
    beyond: Vec<Radiance>,
    bounces: Vec<Bounce>,
    /// The surfaces at the current depth, in groups of eight (the first
    /// `live` of them), and room for the next depth's.
    front: Vec<Group>,
    live: usize,
    next: Vec<Group>,
    /// Per material of the scene, what its bounce needs (`SurfaceKind`),
    /// worked out once instead of per lane and bounce.
    kinds: Vec<SurfaceKind>,
    /// The current depth's bounce rays, by sample, in the order sampled.
    rays: Vec<(usize, Ray)>,
    /// Room for a packet of them (made at the first use of packets).
    packet: Option<Box<Packet>>,
    /// Per group and light, the lanes whose shadow ray is blocked.
    blocked: Vec<u8>,
}

/// How a path leaves a surface of some material.
#[derive(Clone, Copy, PartialEq, Eq)]
enum SurfaceKind {
    /// Mirror or glass (`Material::has_secondary`): `shade()`'s own code
    /// finishes the path.
    Secondary,
    /// A glossy lobe beside the diffuse one, or a diffuse lobe that is not
    /// Lambertian: `gi::sample_bounce`.
    Glossy,
    /// Lambertian only: the cosine lobe, sampled eight lanes at a time.
    Lambertian,
}

impl Default for PathPool<'_> {
    fn default() -> Self {
        Self::new()
    }
}

impl<'p> PathPool<'p> {
    pub fn new() -> PathPool<'p> {
        PathPool { paths: Vec::new(), slots: Vec::new(), beyond: Vec::new(), bounces: Vec::new(), front: Vec::new(), live: 0, next: Vec::new(), kinds: Vec::new(), rays: Vec::new(), packet: None, blocked: Vec::new() }
    }

    /// A pool with room for `samples` samples (and a batch more) and a few
    /// bounces each, so that filling it does not reallocate and copy: the
    /// ray caster makes one per rayon job of a pass, and per call of a
    /// chunk's passes.
    pub fn with_capacity(samples: usize) -> PathPool<'p> {
        let n = samples + LANES;
        let groups = n.div_ceil(LANES);
        PathPool {
            paths: Vec::with_capacity(n),
            slots: Vec::with_capacity(n),
            beyond: Vec::with_capacity(n),
            bounces: Vec::with_capacity(4 * n),
            front: Vec::with_capacity(groups),
            live: 0,
            next: Vec::with_capacity(groups),
            kinds: Vec::new(),
            rays: Vec::with_capacity(n),
            packet: None,
            blocked: Vec::new(),
        }
    }

    /// Number of samples put in.
    pub fn len(&self) -> usize {
        self.paths.len()
    }

    pub fn is_empty(&self) -> bool {
        self.paths.is_empty()
    }

    /// Starts the paths of `n` eye samples, path k made by `start(k)`, and
    /// lends them out (for the direct light at their surfaces, which may
    /// draw from their random numbers); `add` puts in their surfaces. Made
    /// in place, the paths are not copied in afterwards.
    pub fn start(&mut self, n: usize, start: impl Fn(usize) -> PathState<'p>) -> &mut [PathState<'p>] {
        let first = self.paths.len();
        self.paths.extend((0..n).map(start));
        &mut self.paths[first..]
    }

    /// Puts in the eye samples whose rays see `hits` (lanes `0..n`, n =
    /// `slots.len()`) from directions `w_o`, following the `n` paths last
    /// `start`ed, with the albedo and direct light `direct_in_lanes` found
    /// there; lane k's radiance goes to `out[slots[k]]` of `follow_into`.
    pub fn add(&mut self, hits: &HitLanes, w_o: &[Floats; 3], slots: &[usize], lobes: &[PointLobes; LANES], direct: &[Radiance; LANES]) {
        let n = slots.len();
        let first = self.slots.len();
        debug_assert_eq!(self.paths.len(), first + n, "`add` follows `start` of as many paths");
        self.slots.extend_from_slice(slots);
        self.beyond.resize(first + n, Radiance::ZERO);
        let group = slot(&mut self.front, self.live);
        group.len = n;
        group.hits = *hits;
        group.w_o = *w_o;
        group.sample = std::array::from_fn(|k| first + k);
        group.lobes = *lobes;
        group.direct = *direct;
        self.live += 1;
    }

    /// Follows every sample's path to its end and writes its radiance
    /// (what `shade::after_direct` at depth 0 returns for it) to `out` at
    /// its slot; the pool is then empty.
    pub fn follow_into<Q: SceneQuery>(&mut self, job: &PassJob, query: &Q, counts: &mut RayCounts, out: &mut [Radiance]) {
        let materials = &job.prepared.scene.materials;
        let normal_maps = materials.iter().any(|m| m.normal_map.is_some());
        // A pool serves one call of its renderer, so one scene: the table
        // is made at its first flush.
        if self.kinds.len() != materials.len() {
            self.kinds.clear();
            // Only the Lambertian lobe takes the eight-wide cosine bounce; other diffuse models go through `sample_bounce`.
            self.kinds.extend(materials.iter().map(|m| match (m.has_secondary(), m.has_glossy() || m.diffuse_model != DiffuseModel::Lambert) {
                (true, _) => SurfaceKind::Secondary,
                (false, true) => SurfaceKind::Glossy,
                (false, false) => SurfaceKind::Lambertian,
            }));
        }
        let mut depth = 0;
        while self.live > 0 {
            let mut pass = DepthPass { job, query, counts: &mut *counts, paths: &mut self.paths, beyond: &mut self.beyond, bounces: &mut self.bounces, next: &mut self.next, next_len: 0, depth, kinds: &self.kinds, rays: &mut self.rays };
            for group in &self.front[..self.live] {
                pass.bounce(group);
            }
            pass.trace(&mut self.packet);
            self.live = pass.next_len.div_ceil(LANES);
            let groups = &mut self.next[..self.live];
            for group in groups.iter_mut() {
                group.build(job, normal_maps);
            }
            let lights = job.prepared.scene.lights.len();
            let blocked = shadow_bits(job, query, groups, &mut self.packet, &mut self.blocked, counts);
            for (g, group) in groups.iter_mut().enumerate() {
                let bits = blocked.then(|| &self.blocked[g * lights..(g + 1) * lights]);
                (group.lobes, group.direct) = direct_in_lanes(job, query, &group.hits, &group.w_o, group.len, &mut self.paths, &group.sample, bits, counts);
            }
            std::mem::swap(&mut self.front, &mut self.next);
            depth += 1;
        }
        // The recursion's sums, innermost first: each bounce adds its weight
        // times what lies beyond it to its surface's direct light.
        for b in self.bounces.iter().rev() {
            self.beyond[b.sample] = b.direct + b.weight * self.beyond[b.sample];
        }
        for (&slot, value) in self.slots.iter().zip(&self.beyond) {
            out[slot] = *value;
        }
        self.paths.clear();
        self.slots.clear();
        self.beyond.clear();
        self.bounces.clear();
    }
}

/// What one depth's bounces read and write.
struct DepthPass<'w, 'p, 'j, Q> {
    job: &'w PassJob<'j>,
    query: &'w Q,
    counts: &'w mut RayCounts,
    paths: &'w mut [PathState<'p>],
    beyond: &'w mut [Radiance],
    bounces: &'w mut Vec<Bounce>,
    /// The next depth's groups, and the surfaces put in them so far.
    next: &'w mut Vec<Group>,
    next_len: usize,
    depth: u32,
    kinds: &'w [SurfaceKind],
    /// The depth's bounce rays so far, by sample (`go_on`), for `trace`.
    rays: &'w mut Vec<(usize, Ray)>,
}

impl<Q: SceneQuery> DepthPass<'_, '_, '_, Q> {
    /// The bounce of every path of `group`: `after_direct`'s indirect term
    /// as `indirect_path` and `follow` take it, up to the bounce's ray
    /// (queued for `trace`). Lambertian surfaces sample their bounce eight
    /// lanes at a time.
    fn bounce(&mut self, group: &Group) {
        dispatch!(simd_level(), simd => self.sample_bounces(simd, group))
    }

    /// The bounce of every path of `group` up to its ray: the paths that
    /// go on have their ray queued, for `trace`.
    #[inline(always)]
    fn sample_bounces<S: Simd>(&mut self, simd: S, group: &Group) {
        let scene = &self.job.prepared.scene;
        let settings = self.job.settings;
        // Paths at their last permitted bounce finish in `shade()`'s code.
        let last = self.depth >= settings.gi.max_path_depth();
        let mut lambertian = 0u8;
        // The Lambertian lanes' streams, which make their draws together.
        let mut streams = StreamLanes::default();
        for k in 0..group.len {
            let s = group.sample[k];
            let kind = self.kinds[group.hits.material[k] as usize];
            let material = &scene.materials[group.hits.material[k] as usize];
            let path = &mut self.paths[s];
            if last || kind == SurfaceKind::Secondary {
                let hit = group.hits.get(k);
                let w_o = Vec3::new(group.w_o[0][k], group.w_o[1][k], group.w_o[2][k]);
                let mut sh = Shading { scene, query: self.query, settings, path, counts: &mut *self.counts, rec: &mut NoRecord };
                self.beyond[s] = shade::after_direct(&mut sh, &hit, material, group.lobes[k], w_o, self.depth, group.direct[k]);
                continue;
            }
            if kind == SurfaceKind::Lambertian {
                streams.load(k, &path.rng);
                lambertian |= 1 << k;
                continue;
            }
            let hit = group.hits.get(k);
            let w_o = Vec3::new(group.w_o[0][k], group.w_o[1][k], group.w_o[2][k]);
            match gi::sample_bounce(scene, material, group.lobes[k], &hit, w_o, self.depth, path, &mut NoRecord) {
                Some((w_i, weight, _)) => self.go_on(group, k, w_i, weight),
                None => self.beyond[s] = group.direct[k] + Vec3::ZERO,
            }
        }
        if lambertian == 0 {
            return;
        }
        // `sample_bounce`'s draws (the lobe choice, unused by a single
        // lobe, then the 2D point), made by the eight streams together.
        let _choice = streams.next_f32();
        let u = streams.next_2d(simd, lambertian);
        let mut m = lambertian;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            streams.store(k, &mut self.paths[group.sample[k]].rng);
        }
        let (w_i, usable) = cosine_lobes8(simd, &group.hits, &u);
        let mut m = lambertian;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            let s = group.sample[k];
            let albedo = group.lobes[k].albedo;
            // `sample_bsdf`'s tests for a Lambertian surface (it reflects
            // something; its sample is usable), `sample_bounce`'s (the
            // direction leaves the geometric surface's front), then the
            // roulette.
            let reflects = luminance(albedo).max(0.0) > 0.0 && albedo.is_finite();
            let survival = if reflects && usable & 1 << k != 0 { gi::roulette(self.depth, self.paths[s].throughput * albedo, &mut self.paths[s].rng) } else { None };
            match survival {
                Some((scale, _)) => self.go_on(group, k, Vec3::new(w_i[0][k], w_i[1][k], w_i[2][k]), albedo * scale),
                None => self.beyond[s] = group.direct[k] + Vec3::ZERO,
            }
        }
    }

    /// Lane `k`'s path goes on along `w_i` with `weight`: the bounce is
    /// kept and its ray queued, as `follow` and `radiance_along` go on.
    #[inline(always)]
    fn go_on(&mut self, group: &Group, k: usize, w_i: Vec3, weight: Vec3) {
        let s = group.sample[k];
        self.bounces.push(Bounce { sample: s, direct: group.direct[k], weight });
        let origin = Vec3::new(group.hits.position[0][k], group.hits.position[1][k], group.hits.position[2][k]);
        let geometric = Vec3::new(group.hits.geometric_normal[0][k], group.hits.geometric_normal[1][k], group.hits.geometric_normal[2][k]);
        // `SurfaceHit::spawn_ray_front`.
        let ray = Ray::new(origin + geometric * self.job.settings.shadow_bump, w_i);
        self.paths[s].throughput *= weight;
        self.counts.secondary += 1;
        self.rays.push((s, ray));
    }

    /// Traces the depth's queued rays: the surface each finds is put in
    /// the next depth's groups (in the order the rays were queued), the
    /// background noted where it escapes. Through the flat tree they go in
    /// packets (`closest_hybrid`: walked together near the root, where
    /// many rays of a packet enter the same nodes, then ray by ray; alone,
    /// these incoherent rays took about a quarter longer); else one by one.
    fn trace(&mut self, packet: &mut Option<Box<Packet>>) {
        // Taken for the loop (`found` needs `self`), given back emptied.
        let mut rays = std::mem::take(self.rays);
        match self.query.bvh_packets() {
            Some(bvh) => {
                let pk = packet.get_or_insert_with(Packet::new);
                for chunk in rays.chunks(PACKET_RAYS) {
                    for (k, (_, ray)) in chunk.iter().enumerate() {
                        pk.rays[k] = *ray;
                        pk.t_max[k] = f32::INFINITY;
                    }
                    let valid = u64::MAX >> (64 - chunk.len());
                    bvh.closest_hybrid(pk, valid, HYBRID_ALONE, self.counts);
                    for (k, &(s, ray)) in chunk.iter().enumerate() {
                        match pk.triangle_hit_input(k) {
                            Some(input) => self.found(s, &ray, Some(BatchHit::Triangle(input))),
                            None => self.found(s, &ray, pk.batch_hit(bvh, k)),
                        }
                    }
                }
            }
            None => dispatch!(simd_level(), simd => {
                for &(s, ray) in &rays {
                    let hit = self.query.closest_for_batch_at(simd, &ray, f32::INFINITY, false, self.counts);
                    self.found(s, &ray, hit);
                }
            }),
        }
        rays.clear();
        *self.rays = rays;
    }

    /// Sample `s`'s bounce ray `ray` found `hit`: it goes in the next
    /// depth's groups, or the path ends in the background.
    #[inline(always)]
    fn found(&mut self, s: usize, ray: &Ray, hit: Option<BatchHit>) {
        match hit {
            None => self.beyond[s] = self.job.prepared.scene.miss_radiance(ray.dir),
            Some(found) => {
                let into = slot(self.next, self.next_len / LANES);
                if self.next_len.is_multiple_of(LANES) {
                    into.len = 0;
                    into.pending_len = 0;
                }
                into.push(s, found, -ray.dir);
                self.next_len += 1;
            }
        }
    }
}

/// The shadow rays of `groups`' surfaces towards every light, traced ahead
/// in packets through the flat tree (`occluded_hybrid`; these rays leave
/// scattered surfaces, so the packets go on ray by ray once few share an
/// entry): `blocked[g * lights + k]` gets the lanes of group g whose ray
/// towards light k is blocked. False, leaving `direct_in_lanes` to cast
/// them one by one, where rays are not how the frame finds shadows or
/// the query has no packets.
fn shadow_bits<Q: SceneQuery>(job: &PassJob, query: &Q, groups: &[Group], packet: &mut Option<Box<Packet>>, blocked: &mut Vec<u8>, counts: &mut RayCounts) -> bool {
    let settings = job.settings;
    let Some(bvh) = query.bvh_packets().filter(|_| settings.shadows == ShadowMode::Ray) else { return false };
    let scene = &job.prepared.scene;
    let lights = scene.lights.len();
    blocked.clear();
    blocked.resize(groups.len() * lights, 0);
    let pk = packet.get_or_insert_with(Packet::new);
    // Which group, lane and light each packet lane's ray belongs to.
    let mut owner = [(0usize, 0usize); PACKET_RAYS];
    let mut n = 0;
    let flush = |pk: &mut Packet, owner: &[(usize, usize)], n: usize, blocked: &mut [u8], counts: &mut RayCounts| {
        let valid = u64::MAX >> (64 - n);
        bvh.occluded_hybrid(pk, valid, HYBRID_ALONE, counts);
        for (i, &(slot, lane)) in owner[..n].iter().enumerate() {
            blocked[slot] |= (pk.occluder(i).is_some() as u8) << lane;
        }
    };
    for (k, light) in scene.lights.iter().enumerate() {
        for (g, group) in groups.iter().enumerate() {
            shadow_rays_of(scene, &group.hits, group.len, light, settings.shadow_bump, settings.terminator_lift, |lane, ray, t_max| {
                pk.rays[n] = ray;
                pk.t_max[n] = t_max;
                owner[n] = (g * lights + k, lane);
                n += 1;
                if n == owner.len() {
                    flush(pk, &owner, n, blocked, counts);
                    n = 0;
                }
            });
        }
    }
    if n > 0 {
        flush(pk, &owner, n, blocked, counts);
    }
    true
}

/// `cosine_lobe` at the shading normals of `hits` for the points `u`, eight
/// lanes wide: the directions, and the lanes whose direction is usable and
/// leaves the geometric surface's front (`sample_bounce`'s test, written
/// so that a NaN passes as it does there).
#[inline(always)]
fn cosine_lobes8<S: Simd>(simd: S, hits: &HitLanes, u: &[Floats; 2]) -> ([Floats; 3], u8) {
    let n = V3::from_soa(simd, &hits.shading_normal);
    let geometric = V3::from_soa(simd, &hits.geometric_normal);
    let (w_i, _pdf, usable) = cosine_lobe(n, f32x8::simd_from(simd, u[0]), f32x8::simd_from(simd, u[1]));
    let cos = w_i.dot(geometric);
    let front = !Lane::le(cos, cos.splat(0.0));
    (w_i.to_soa(), mask_bits(usable & front))
}

/// Group `i` of `groups`, made if there is none yet.
fn slot(groups: &mut Vec<Group>, i: usize) -> &mut Group {
    while groups.len() <= i {
        groups.push(Group::new());
    }
    &mut groups[i]
}

impl Group {
    fn new() -> Group {
        Group {
            len: 0,
            hits: HitLanes::new(),
            w_o: [[0.0; LANES]; 3],
            sample: [0; LANES],
            lobes: [PointLobes { albedo: Vec3::ZERO, glossy: Vec3::ZERO, roughness: 1.0 }; LANES],
            direct: [Radiance::ZERO; LANES],
            pending: [TriangleHitInput::default(); LANES],
            pending_lanes: [0; LANES],
            pending_len: 0,
        }
    }

    /// Adds sample `sample`'s hit, seen from unit direction `w_o`: a
    /// record at once, a triangle's when the group is complete.
    #[inline]
    fn push(&mut self, sample: usize, found: BatchHit, w_o: Vec3) {
        let k = self.len;
        match found {
            BatchHit::Triangle(input) => {
                self.pending[self.pending_len] = input;
                self.pending_lanes[self.pending_len] = k;
                self.pending_len += 1;
            }
            BatchHit::Record(h) => self.hits.set(k, &h),
        }
        self.sample[k] = sample;
        (self.w_o[0][k], self.w_o[1][k], self.w_o[2][k]) = (w_o.x, w_o.y, w_o.z);
        self.len += 1;
    }

    /// Builds the pending triangles' records (eight at a time), as
    /// `closest` gives them, and completes every record as `radiance_along`
    /// does (`normal_maps`: whether any material has a normal map); their
    /// direct light comes next (`follow_into`).
    fn build(&mut self, job: &PassJob, normal_maps: bool) {
        let scene = &job.prepared.scene;
        let triangles = self.pending_len;
        if triangles == self.len {
            scene.triangle_hits(&self.pending[..triangles], &mut self.hits);
        } else if triangles > 0 {
            let mut built = HitLanes::new();
            scene.triangle_hits(&self.pending[..triangles], &mut built);
            for (j, &k) in self.pending_lanes[..triangles].iter().enumerate() {
                self.hits.copy_lane(k, &built, j);
            }
        }
        if normal_maps {
            for k in 0..self.len {
                let mut h = self.hits.get(k);
                crate::scene::normal_map::apply(scene, job.settings.texture_filter, &mut h);
                self.hits.set(k, &h);
            }
        }
    }
}
