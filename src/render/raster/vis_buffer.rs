//! The per-region buffers of a rasterizer: depth, visibility (which primitive
//! and where on it) and, in forward mode, colour. Every variant writes its
//! fragments here; the depth test, the shading hand-off to `resolve_sample`
//! and the counters live in this one place.
//!
//! Depth keys: smaller is nearer. Variants that cast 3D rays (naive, bbox)
//! store the ray parameter t, exactly as the ray caster compares hits; the
//! others store -1/z, which is affine in image space. Ties keep the earlier
//! fragment (strict `<`), so the earlier triangle in scene order wins, as in
//! the brute-force caster.

use super::setup::{PixelRect, ScreenTri};
use crate::math::{Radiance, Vec3};
use crate::render::trace::NoRecord;
use crate::render::{resolve_sample, PassJob, RayCounts, SceneQuery};

/// No primitive covers the sample.
pub const EMPTY: u32 = u32::MAX;
/// Set in an id for spheres; clear for triangles.
pub const SPHERE_BIT: u32 = 1 << 31;

/// What a depth key measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthKey {
    /// Ray parameter along the eye ray (starts at far_t, the far plane).
    RayT,
    /// -1 / view depth (starts at -1 / far).
    NegInvZ,
}

pub struct VisBuffer<'j, 'a, Q: SceneQuery> {
    pub job: &'j PassJob<'a>,
    pub query: &'j Q,
    pub rect: PixelRect,
    stride: usize,
    pub key: DepthKey,
    /// Shade every fragment that passes the depth test (forward) instead of
    /// once per pixel after visibility is known (early depth).
    pub forward: bool,
    pub depth: Vec<f32>,
    pub id: Vec<u32>,
    /// Triangles: perspective-correct (b1, b2) in the scene triangle. Spheres: (t, 0).
    pub payload: Vec<[f32; 2]>,
    color: Vec<Radiance>,
    pub counts: RayCounts,
}

impl<'j, 'a, Q: SceneQuery> VisBuffer<'j, 'a, Q> {
    pub fn new(job: &'j PassJob<'a>, query: &'j Q, rect: PixelRect, key: DepthKey, forward: bool) -> Self {
        let n = rect.area() as usize;
        let depth = match key {
            DepthKey::NegInvZ => vec![-1.0 / job.view.far; n],
            DepthKey::RayT => {
                let mut d = Vec::with_capacity(n);
                for y in rect.y0..rect.y1 {
                    for x in rect.x0..rect.x1 {
                        let p = job.sample_position(x, y);
                        d.push(job.view.far_t(p.x, p.y));
                    }
                }
                d
            }
        };
        VisBuffer {
            job,
            query,
            rect,
            stride: rect.width() as usize,
            key,
            forward,
            depth,
            id: vec![EMPTY; n],
            payload: vec![[0.0; 2]; n],
            color: if forward { vec![Radiance::ZERO; n] } else { Vec::new() },
            counts: RayCounts::default(),
        }
    }

    /// Index of image pixel `(x, y)` in this region's buffers.
    #[inline(always)]
    pub fn index(&self, x: u32, y: u32) -> usize {
        (x - self.rect.x0) as usize + (y - self.rect.y0) as usize * self.stride
    }

    /// A covered sample of screen triangle `st` with screen-space weights `l`:
    /// depth test on -1/z, then perspective-correct barycentrics on a pass.
    #[inline(always)]
    pub fn triangle_fragment(&mut self, st: &ScreenTri, x: u32, y: u32, l: [f32; 3]) {
        self.counts.samples_covered += 1;
        let i = self.index(x, y);
        let inv_z = st.inv_z_at(l);
        let key = -inv_z;
        if key < self.depth[i] {
            self.depth[i] = key;
            self.id[i] = st.tri;
            self.payload[i] = st.bary_at(l, inv_z);
            if self.forward {
                self.shade_now(i, x, y);
            }
        } else {
            self.counts.depth_fails += 1;
        }
    }

    /// The current depth bound of pixel `(x, y)` (the ray casters' `t_max`).
    #[inline(always)]
    pub fn depth_at(&self, x: u32, y: u32) -> f32 {
        self.depth[self.index(x, y)]
    }

    /// A ray-triangle hit already known to be nearer than `depth_at` (naive, bbox).
    #[inline(always)]
    pub fn ray_fragment(&mut self, x: u32, y: u32, tri: u32, t: f32, b1: f32, b2: f32) {
        self.counts.samples_covered += 1;
        let i = self.index(x, y);
        self.depth[i] = t;
        self.id[i] = tri;
        self.payload[i] = [b1, b2];
        if self.forward {
            self.shade_now(i, x, y);
        }
    }

    /// A covered sample of a ray-triangle test that lost the depth test.
    #[inline(always)]
    pub fn ray_depth_fail(&mut self) {
        self.counts.samples_covered += 1;
        self.counts.depth_fails += 1;
    }

    /// The eye ray hits sphere `s` at `t`. Against another sphere the two ray
    /// parameters are compared (as the ray caster does); against a triangle the
    /// depth keys.
    #[inline]
    pub fn sphere_fragment(&mut self, x: u32, y: u32, s: u32, t: f32, key: f32) {
        self.counts.samples_covered += 1;
        let i = self.index(x, y);
        let cur = self.id[i];
        let nearer = if cur == EMPTY {
            true
        } else if cur & SPHERE_BIT != 0 {
            t < self.payload[i][0]
        } else {
            key < self.depth[i]
        };
        if nearer {
            self.depth[i] = key;
            self.id[i] = s | SPHERE_BIT;
            self.payload[i] = [t, 0.0];
            if self.forward {
                self.shade_now(i, x, y);
            }
        } else {
            self.counts.depth_fails += 1;
        }
    }

    fn shade_now(&mut self, i: usize, x: u32, y: u32) {
        self.counts.fragments_shaded += 1;
        self.color[i] = self.shade(i, x, y);
    }

    /// Builds the `SurfaceHit` of what pixel `i` sees and hands it to the shared shading.
    fn shade(&mut self, i: usize, x: u32, y: u32) -> Radiance {
        let p = self.job.sample_position(x, y);
        let ray = self.job.view.eye_ray(p.x, p.y);
        let id = self.id[i];
        let scene = &self.job.prepared.scene;
        let hit = if id == EMPTY {
            None
        } else if id & SPHERE_BIT != 0 {
            Some(scene.sphere_hit(id & !SPHERE_BIT, self.payload[i][0], &ray))
        } else {
            let [b1, b2] = self.payload[i];
            let b = Vec3::new(1.0 - b1 - b2, b1, b2);
            let t = match self.key {
                DepthKey::RayT => self.depth[i],
                DepthKey::NegInvZ => {
                    let v = &scene.triangles[id as usize].v;
                    let pos = v[0] * b.x + v[1] * b.y + v[2] * b.z;
                    (pos - ray.origin).dot(ray.dir)
                }
            };
            Some(scene.triangle_hit(id, b, t, &ray))
        };
        resolve_sample(self.job, self.query, &ray, hit.as_ref(), &mut self.counts, &mut NoRecord)
    }

    /// Resolves every pixel of the region into `out` (row-major, the region's
    /// width): early-depth mode shades each visible surface once here; forward
    /// mode already shaded it. Counts one primary sample per pixel.
    pub fn finish(mut self, out: &mut [Radiance]) -> RayCounts {
        let stride = self.stride;
        self.finish_into(out, stride, 0)
    }

    /// As `finish`, into rows of `out_stride` pixels starting at column `x_offset`.
    pub fn finish_into(&mut self, out: &mut [Radiance], out_stride: usize, x_offset: usize) -> RayCounts {
        let r = self.rect;
        let mut i = 0;
        for (row, y) in (r.y0..r.y1).enumerate() {
            let line = &mut out[row * out_stride + x_offset..row * out_stride + x_offset + self.stride];
            for (px, x) in line.iter_mut().zip(r.x0..r.x1) {
                self.counts.primary += 1;
                *px = if self.forward && self.id[i] != EMPTY {
                    self.color[i]
                } else {
                    if self.id[i] != EMPTY {
                        self.counts.fragments_shaded += 1;
                    }
                    self.shade(i, x, y)
                };
                i += 1;
            }
        }
        std::mem::take(&mut self.counts)
    }

    /// Empties the buffers for another region of at most the same size (the tiles of a row).
    pub fn reset(&mut self, rect: PixelRect) {
        let n = rect.area() as usize;
        assert!(self.key == DepthKey::NegInvZ && n <= self.id.capacity());
        self.rect = rect;
        self.stride = rect.width() as usize;
        self.depth.clear();
        self.depth.resize(n, -1.0 / self.job.view.far);
        self.id.clear();
        self.id.resize(n, EMPTY);
        self.payload.clear();
        self.payload.resize(n, [0.0; 2]);
        if self.forward {
            self.color.clear();
            self.color.resize(n, Radiance::ZERO);
        }
    }
}
