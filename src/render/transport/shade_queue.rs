//! A band's visible samples waiting to be shaded: up to eight batches of
//! eight (`shade_batch::Batch`). This is the rasterizers' batched hand-off
//! to shading, as `resolve_sample` is the one-sample hand-off: they push
//! the samples their visibility buffer sees (`push_*`) and `finish`; the
//! queue shades them when full and, with `--gi path`, hands them on to the
//! path pool it owns. With `--shadows ray` the queued surfaces'
//! shadow rays are traced as one packet per light before the batches are
//! shaded, as the ray caster does for its tiles: neighbouring samples'
//! rays towards a light walk the BVH together instead of one by one. The
//! packet answers whether each ray is blocked exactly as the single ray
//! would, so the image is the same.

use crate::math::Radiance;
use crate::render::transport::path_batch;
use crate::render::transport::path_batch::PathPool;
use crate::render::accel::packet::Packet;
use crate::render::transport::shadow_packets::shadow_packets;
use crate::render::transport::shade_batch;
use crate::render::transport::shade_batch::{Batch, LANES};
use crate::render::inspect::debug::View;
use crate::render::{PassJob, RayCounts, SceneQuery, ShadowMode};
use crate::math::{Vec2, Vec3};
use crate::scene::hit_lanes::EyeSamples;
use crate::scene::SurfaceHit;

/// Batches queued before their shadow packets are traced: eight batches of
/// eight lanes fill a packet's 64 rays.
const BATCHES: usize = 8;

/// Samples gathered before their paths are followed together (`PathPool`):
/// as many as a ray caster's tile, which keeps the lanes about as full.
const PATH_SAMPLES: usize = 64;

pub struct ShadeQueue<'p> {
    batches: Vec<Batch>,
    /// The batch new samples go into; those before it are full.
    current: usize,
    shadow_pk: Box<Packet>,
    /// Per light, the queue's blocked lanes (bit 8 b + j: lane j of batch b).
    queue_blocked: Vec<u64>,
    /// Per light, one batch's blocked lanes, as `shade_batch` takes them.
    batch_blocked: Vec<u8>,
    /// The same for the batch after it, when the two are shaded together.
    next_blocked: Vec<u8>,
    /// With `--gi path`, the shaded samples whose paths wait to be
    /// followed together.
    paths: PathPool<'p>,
}

impl<'p> ShadeQueue<'p> {
    /// Samples a batch holds: a row of this many covered samples can fill
    /// an empty batch at once (`push_eye_row`).
    pub const LANES: usize = LANES;

    pub fn new(lights: usize) -> ShadeQueue<'p> {
        ShadeQueue {
            batches: (0..BATCHES).map(|_| Batch::new()).collect(),
            current: 0,
            shadow_pk: Packet::new(),
            queue_blocked: vec![0; lights],
            batch_blocked: vec![0; lights],
            next_blocked: vec![0; lights],
            paths: PathPool::new(),
        }
    }

    /// Whether `job`'s samples may go through a queue at all: the shaded
    /// view and the debug views that only colour what is hit.
    pub fn takes(job: &PassJob) -> bool {
        shade_batch::resolved_in_batches(job)
    }

    /// Whether the batch the next sample goes into is empty, so that
    /// `push_eye_row` may fill it.
    pub fn batch_is_empty(&self) -> bool {
        self.batches[self.current].is_empty()
    }

    /// Queues the eye samples of `LANES` pixels in a row from pixel (x, y)
    /// on, which see the scene triangles `index` at barycentrics `bary`;
    /// their results go to `out[slot..slot + LANES]`. The batch must be
    /// empty (`batch_is_empty`).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn push_eye_row<Q: SceneQuery>(&mut self, job: &PassJob<'p>, query: &Q, counts: &mut RayCounts, out: &mut [Radiance], index: &[u32; LANES], bary: &[[f32; 2]; LANES], (x, y): (u32, u32), slot: usize) {
        self.batches[self.current].fill_eye_row(index, bary, (x, y), job.offset, job.pixel_index(x, y), job.sample, slot);
        self.advance(job, query, counts, out);
    }

    /// Queues pixel (x, y)'s eye sample, which sees scene triangle `index`
    /// at barycentrics (b1, b2); its result goes to `out[slot]`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn push_eye_triangle<Q: SceneQuery>(&mut self, job: &PassJob<'p>, query: &Q, counts: &mut RayCounts, out: &mut [Radiance], index: u32, b: (f32, f32), (x, y): (u32, u32), slot: usize) {
        self.batches[self.current].push_eye_triangle(index, b, job.sample_position(x, y), job.pixel_index(x, y), job.sample, slot);
        self.advance(job, query, counts, out);
    }

    /// Queues pixel (x, y)'s sample, whose eye ray along `dir` found `hit`;
    /// its result goes to `out[slot]`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn push_hit<Q: SceneQuery>(&mut self, job: &PassJob<'p>, query: &Q, counts: &mut RayCounts, out: &mut [Radiance], hit: &SurfaceHit, dir: Vec3, (x, y): (u32, u32), slot: usize) {
        self.batches[self.current].push(shade_batch::build_interpolation(job), hit, dir, job.pixel_index(x, y), job.sample, slot);
        self.advance(job, query, counts, out);
    }

    /// Queues the eye samples `eight` (of pixel indices `pixels`, meant for
    /// `slots`), a whole batch at once when it starts one, and empties
    /// `eight`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn push_eye_samples<Q: SceneQuery>(&mut self, job: &PassJob<'p>, query: &Q, counts: &mut RayCounts, out: &mut [Radiance], eight: &mut EyeSamples, pixels: &[u32; LANES], slots: &[usize; LANES]) {
        if eight.len == LANES && self.batch_is_empty() {
            self.batches[self.current].fill_eye_triangles(eight, pixels, job.sample, slots);
            self.advance(job, query, counts, out);
        } else {
            for k in 0..eight.len {
                let p = Vec2::new(eight.px[k], eight.py[k]);
                self.batches[self.current].push_eye_triangle(eight.index[k], (eight.b1[k], eight.b2[k]), p, pixels[k], job.sample, slots[k]);
                self.advance(job, query, counts, out);
            }
        }
        eight.len = 0;
    }

    /// Shades everything still queued and follows every waiting path:
    /// every pushed sample's result is in `out` when this returns.
    pub fn finish<Q: SceneQuery>(&mut self, job: &PassJob<'p>, query: &Q, counts: &mut RayCounts, out: &mut [Radiance]) {
        self.flush(job, query, counts, out);
        self.paths.follow_into(job, query, counts, out);
    }

    /// Call after each sample put in the current batch: moves on when that
    /// batch is full, and shades the whole queue when it is full.
    #[inline(always)]
    fn advance<Q: SceneQuery>(&mut self, job: &PassJob<'p>, query: &Q, counts: &mut RayCounts, out: &mut [Radiance]) {
        if self.batches[self.current].is_full() {
            self.current += 1;
            if self.current == BATCHES {
                self.flush(job, query, counts, out);
            }
        }
    }

    /// Shades every queued sample into `out` at its slot (with `--gi
    /// path`, puts it into the path pool, followed once it holds
    /// `PATH_SAMPLES`) and empties the queue.
    fn flush<Q: SceneQuery>(&mut self, job: &PassJob<'p>, query: &Q, counts: &mut RayCounts, out: &mut [Radiance]) {
        let queued = if self.current < BATCHES && !self.batches[self.current].is_empty() { self.current + 1 } else { self.current };
        self.current = 0;
        if queued == 0 {
            return;
        }
        let batches = &mut self.batches[..queued];
        for batch in batches.iter_mut() {
            batch.build_pending(&job.prepared.scene, job.view, shade_batch::build_interpolation(job));
        }
        let view = job.settings.view;
        if view != View::Shaded {
            // Only the debug views that colour what is hit come here
            // (`shade_batch::resolved_in_batches`).
            shade_batch::colour_batches(job, batches, |batch, j, colour| out[batch.slots[j]] = colour);
            return;
        }
        let packets = if job.settings.shadows == ShadowMode::Ray { query.bvh_packets() } else { None };
        if let Some(bvh) = packets {
            shadow_packets(bvh, job.settings, batches, |b, j| LANES * b + j, &mut self.shadow_pk, &mut self.queue_blocked, counts);
        }
        // Without packets the lanes' rays are cast one by one in shading.
        let queue_blocked = &self.queue_blocked;
        let unpack = packets.is_some().then_some(|b: usize, _: &Batch, bits: &mut [u8]| {
            for (bits, queue_bits) in bits.iter_mut().zip(queue_blocked) {
                *bits = (queue_bits >> (LANES * b)) as u8;
            }
        });
        if !path_batch::takes(job) {
            shade_batch::shade_batches(job, query, batches, unpack, [&mut self.batch_blocked, &mut self.next_blocked], counts, |batch, j, value| out[batch.slots[j]] = value);
            return;
        }
        for (b, batch) in batches.iter_mut().enumerate() {
            if let Some(unpack) = &unpack {
                unpack(b, batch, &mut self.batch_blocked);
            }
            let blocked = unpack.is_some().then_some(&self.batch_blocked[..]);
            path_batch::start_paths(job, query, batch, blocked, &batch.slots[..batch.len()], counts, &mut self.paths);
            if self.paths.len() >= PATH_SAMPLES {
                self.paths.follow_into(job, query, counts, out);
            }
            batch.clear();
        }
    }
}

const _: () = assert!(BATCHES * LANES <= 64 && LANES == 8, "a queue's lanes fill one shadow packet, eight bits per batch");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::transport::gi::GiMode;
    use crate::render::inspect::pixel_record::NoRecord;
    use crate::render::accel::bvh::BvhQuery;
    use crate::render::{resolve_sample, Interpolation, PreparedScene, RenderSettings};
    use crate::scene::builtin;
    use std::sync::atomic::AtomicBool;

    /// Every visible sample of every built-in scene put through the queue
    /// (its shadow rays traced as packets, its paths followed by the pool)
    /// comes out as `resolve_sample` shades it alone, bit for bit.
    #[test]
    fn queued_samples_equal_one_sample_shading() {
        let mut compared = 0;
        for name in builtin::names() {
            let prepared = PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap());
            let query = BvhQuery::new(&prepared);
            let (w, h) = (37u32, 23u32);
            let view = prepared.scene.camera.view(w, h);
            let cancel = AtomicBool::new(false);
            for (shadows, gi) in [(ShadowMode::Ray, GiMode::None), (ShadowMode::Ray, GiMode::Path), (ShadowMode::None, GiMode::None)] {
                let mut settings = RenderSettings { interpolation: Interpolation::Phong, shadows, spp: 2, ..RenderSettings::for_scene(&prepared.scene) };
                settings.gi.mode = gi;
                let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: glam::Vec2::splat(0.5), sample: 1, photons: None, active: None, rows: 0..h, cancel: &cancel, keep_non_finite: false };
                let mut queue = ShadeQueue::new(prepared.scene.lights.len());
                let mut out = vec![Radiance::splat(-1.0); (w * h) as usize];
                let mut expected = vec![None; (w * h) as usize];
                for (x, y) in (0..h).flat_map(|y| (0..w).map(move |x| (x, y))) {
                    let p = job.sample_position(x, y);
                    let ray = view.eye_ray(p.x, p.y);
                    let Some(hit) = query.closest(&ray, view.far_t(p.x, p.y), false, &mut RayCounts::default(), &mut NoRecord) else { continue };
                    let pixel = job.pixel_index(x, y);
                    expected[pixel as usize] = Some(resolve_sample(&job, &query, &ray, Some(&hit), pixel, &mut RayCounts::default(), &mut NoRecord));
                    queue.push_hit(&job, &query, &mut RayCounts::default(), &mut out, &hit, ray.dir, (x, y), pixel as usize);
                }
                queue.finish(&job, &query, &mut RayCounts::default(), &mut out);
                for (i, e) in expected.iter().enumerate() {
                    if let Some(e) = e {
                        assert_eq!(out[i].to_array().map(f32::to_bits), e.to_array().map(f32::to_bits), "{name} {shadows:?} {gi:?} pixel {i}");
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared > 5000, "only {compared} samples compared");
    }

    /// `shadow_packets` sets lane j of batch b's bit exactly where the
    /// single shadow ray of that lane finds an occluder, for batches of
    /// every length, on scenes with shadows falling on their floors.
    #[test]
    fn packet_shadow_bits_are_the_single_rays_answers() {
        let mut blocked_seen = 0;
        for name in ["bunny", "spheres", "cornell-gi", "teapot"] {
            let prepared = PreparedScene::new(builtin::load_builtin(name).unwrap().unwrap());
            let query = BvhQuery::new(&prepared);
            let bvh = query.bvh_packets().expect("a flat scene traces packets");
            let settings = RenderSettings { shadows: ShadowMode::Ray, ..RenderSettings::for_scene(&prepared.scene) };
            let (w, h) = (64u32, 48u32);
            let view = prepared.scene.camera.view(w, h);
            let scene = &prepared.scene;
            let mut batches: Vec<Batch> = (0..BATCHES).map(|_| Batch::new()).collect();
            let mut pk = Packet::new();
            let mut blocked = vec![0u64; scene.lights.len()];
            let mut b = 0;
            let mut check = |batches: &mut Vec<Batch>, used: usize| {
                for batch in batches[..used].iter_mut() {
                    batch.build_pending(scene, &view, settings.interpolation);
                }
                shadow_packets(bvh, &settings, &batches[..used], |b, j| LANES * b + j, &mut pk, &mut blocked, &mut RayCounts::default());
                for (k, light) in scene.lights.iter().enumerate() {
                    let mut expected = 0u64;
                    for (b, batch) in batches[..used].iter().enumerate() {
                        batch.shadow_rays(scene, light, settings.shadow_bump, settings.terminator_lift, |j, ray, t_max| {
                            let hit = query.occluder(&ray, t_max, &mut RayCounts::default(), &mut NoRecord).is_some();
                            expected |= (hit as u64) << (LANES * b + j);
                        });
                    }
                    assert_eq!(blocked[k], expected, "{name} light {k}");
                    blocked_seen += expected.count_ones();
                }
                for batch in batches.iter_mut() {
                    batch.clear();
                }
            };
            let mut n = 0usize;
            for (x, y) in (0..h).flat_map(|y| (0..w).map(move |x| (x, y))) {
                let p = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let ray = view.eye_ray(p.x, p.y);
                let Some(hit) = query.closest(&ray, view.far_t(p.x, p.y), false, &mut RayCounts::default(), &mut NoRecord) else { continue };
                batches[b].push(settings.interpolation, &hit, ray.dir, 0, 0, 0);
                n += 1;
                // Batches of one to eight lanes: move on after a length
                // that cycles through them.
                if batches[b].len() == 1 + n % LANES || batches[b].is_full() {
                    b += 1;
                    if b == BATCHES {
                        check(&mut batches, b);
                        b = 0;
                    }
                }
            }
            let used = b + usize::from(!batches[b].is_empty());
            check(&mut batches, used);
        }
        assert!(blocked_seen > 500, "only {blocked_seen} blocked shadow rays");
    }
}
