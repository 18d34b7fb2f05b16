//! The pixel recorder: renderers and `shade()` report what they do to a
//! `Recorder`. Frames pass `NoRecord`, whose methods are empty and compile
//! away; `pinhole pixel` and the inspector pass a `PixelTrace` through the
//! very same code.

use crate::render::accel::intersect::Miss;
use crate::render::Occluder;
use crate::math::{Radiance, Ray, Vec3};
use crate::scene::{PrimitiveKind, SurfaceHit};

/// One ray-primitive test.
#[derive(Clone, Debug, PartialEq)]
pub struct PrimitiveTest {
    pub kind: PrimitiveKind,
    pub index: u32,
    /// `Ok((t, b1, b2))` or why it missed.
    pub outcome: Result<(f32, f32, f32), Miss>,
}

/// One light's part in shading a point.
#[derive(Clone, Debug, PartialEq)]
pub struct LightSample {
    pub light: usize,
    pub w_i: Vec3,
    /// Distance to the light (infinite for directional lights).
    pub distance: f32,
    /// Incident radiance (point) or irradiance (directional) before visibility.
    pub incident: Radiance,
    pub cos_theta: f32,
    /// The shadow ray, when one was cast.
    pub shadow_ray: Option<(Ray, f32)>,
    /// What blocked the shadow ray (or, with shadow maps, the stored caster).
    pub blocker: Option<Occluder>,
    /// With shadow volumes at the primary surface: the light's stencil count
    /// (nonzero = in shadow), which replaced the shadow ray.
    pub volume_count: Option<i32>,
    pub bsdf: Vec3,
    pub contribution: Radiance,
}

/// Which light a sample of an area light or the environment was drawn from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SampledLightKind {
    /// A point on area light `Scene::emitters.lights[i]`.
    Area(u32),
    /// A direction of the environment.
    Environment,
    /// MIS's BSDF strategy: a direction sampled from the BSDF, and the
    /// emitter or environment it found (if any).
    BsdfHit,
}

/// One sample of an area light or the environment at a shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledLight {
    pub kind: SampledLightKind,
    /// The point on the light (none for the environment and misses).
    pub point: Option<Vec3>,
    pub w_i: Vec3,
    /// The sampling strategy's density of `w_i` (solid angle).
    pub pdf: f32,
    /// The multiple importance sampling weight (1 without MIS).
    pub mis_weight: f32,
    /// Whether the light was unblocked (found, for the BSDF strategy).
    pub visible: bool,
    /// What it added to the surface's radiance.
    pub contribution: Radiance,
}

/// What `shade()` and the ray casters report. Every method has an empty default.
pub trait Recorder {
    /// False for `NoRecord`: lets callers skip work done only for the record.
    const ENABLED: bool = true;
    /// A ray is about to be traced (`depth` 0 = eye ray).
    fn ray(&mut self, _ray: &Ray, _t_max: f32, _depth: u32) {}
    fn node_visit(&mut self, _node: u32) {}
    fn primitive_test(&mut self, _test: PrimitiveTest) {}
    /// The closest hit of the current ray, or `None` for a miss.
    fn closest(&mut self, _hit: Option<&SurfaceHit>) {}
    fn light(&mut self, _sample: LightSample) {}
    /// A sample of an area light or the environment (or MIS's BSDF sample).
    fn sampled_light(&mut self, _sample: SampledLight) {}
    /// Radiance returned by the shading of the current ray's hit.
    fn shaded(&mut self, _depth: u32, _radiance: Radiance) {}
    /// While true, `primitive_test` and `node_visit` come from a shadow ray.
    fn in_shadow_ray(&mut self, _active: bool) {}
    /// Path tracing sampled the next direction of the path.
    fn bounce(&mut self, _bounce: Bounce) {}
    /// Photon mapping read this radiance from the map.
    fn photons(&mut self, _radiance: Radiance) {}
}

/// One sampled bounce of a path: where it goes and what it weighs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounce {
    /// Depth of the surface the path leaves (0 = the eye ray's hit).
    pub depth: u32,
    pub w_i: Vec3,
    /// Density of `w_i` (solid angle).
    pub pdf: f32,
    /// `f cos / pdf` of this bounce.
    pub weight: Vec3,
    /// The path's throughput after this bounce, before roulette.
    pub throughput: Vec3,
    /// Probability that Russian roulette let the path go on (1: no roulette
    /// at this depth, 0: the path ended here).
    pub survival: f32,
}

/// Records nothing; the frame's recorder.
pub struct NoRecord;

impl Recorder for NoRecord {
    const ENABLED: bool = false;
}

/// Most primitive tests kept per ray: brute force tests every triangle, and a
/// record of 70 000 misses helps nobody. The count of the rest is kept.
pub const MAX_TESTS_PER_RAY: usize = 4096;

/// A recorded ray with everything that happened along it.
#[derive(Clone, Debug, PartialEq)]
pub struct RayRecord {
    pub ray: Ray,
    pub t_max: f32,
    /// 0 = eye ray, 1 = shadow or first secondary ray, ...
    pub depth: u32,
    pub shadow: bool,
    pub nodes_visited: Vec<u32>,
    pub tests: Vec<PrimitiveTest>,
    /// Tests made but not kept (beyond `MAX_TESTS_PER_RAY`).
    pub tests_omitted: usize,
    pub closest: Option<SurfaceHit>,
}

/// One fragment of a rasterizer's pixel history, in draw order (RenderDoc style).
#[derive(Clone, Debug, PartialEq)]
pub struct FragmentRecord {
    pub kind: PrimitiveKind,
    pub primitive: u32,
    /// Screen-space (affine) barycentric weights, when the method has them.
    pub screen_barycentric: Option<Vec3>,
    /// Perspective-correct barycentric weights.
    pub barycentric: Vec3,
    /// Interpolated view depth of the fragment.
    pub depth: f32,
    /// The depth stored in the buffer before this fragment.
    pub stored_depth: f32,
    pub passed_depth_test: bool,
    /// Radiance when the fragment was shaded (forward shading), else `None`.
    pub shaded: Option<Radiance>,
    /// The MSAA coverage sample it was tested at; `None` for the pass's own
    /// sample (without MSAA, or MSAA's pixel-centre shading layer).
    pub sample: Option<u32>,
}

/// One fragment of a CSG object's A-buffer at a sample: where the eye ray
/// enters or leaves one operand solid.
#[derive(Clone, Debug, PartialEq)]
pub struct CsgFragmentRecord {
    /// Along the eye ray (from its origin on the near plane).
    pub t: f32,
    /// The operand (leaf) it bounds, numbered as `csg::Boundary::leaf`.
    pub leaf: u32,
    pub surface: crate::render::accel::csg::SurfaceRef,
    /// A front face (or a sphere's near root): the ray enters the operand.
    pub entering: bool,
    /// The scan-converted triangle's screen-space weights at the sample
    /// (`None` for a sphere's analytic roots).
    pub screen_barycentric: Option<Vec3>,
}

/// A rasterizer's A-buffer at one sample for one CSG object: its fragments
/// sorted by depth and what the interval rule made of them.
#[derive(Clone, Debug, PartialEq)]
pub struct CsgABufferRecord {
    /// Index into `Scene::csgs`.
    pub csg: u32,
    /// The MSAA coverage sample, as in `FragmentRecord::sample`.
    pub sample: Option<u32>,
    pub fragments: Vec<CsgFragmentRecord>,
    /// Each operand's intervals, the combined ones and the winner.
    pub explanation: crate::render::accel::csg::Explanation,
}

impl CsgABufferRecord {
    /// Whether fragment `f` is the boundary that won.
    pub fn won(&self, f: &CsgFragmentRecord) -> bool {
        self.explanation.winner.is_some_and(|(b, _)| b.leaf == f.leaf && b.surface == f.surface && b.t == f.t)
    }

    /// The operand's path in the tree ("a", "b.a", ...).
    pub fn operand(&self, f: &CsgFragmentRecord) -> &str {
        self.explanation.leaves.get(f.leaf as usize).map(|l| l.path.as_str()).unwrap_or("?")
    }

    /// Text lines: the sorted fragments, then the intervals and the winner
    /// (`Explanation::lines`).
    pub fn lines(&self) -> Vec<String> {
        let mut out = vec![format!("A-buffer: {} fragment(s) sorted by depth (t along the eye ray)", self.fragments.len())];
        for f in &self.fragments {
            let surface = match f.surface {
                crate::render::accel::csg::SurfaceRef::Sphere(_) => "sphere".to_string(),
                crate::render::accel::csg::SurfaceRef::Triangle { index, .. } => format!("mesh triangle {index}"),
            };
            let screen = f.screen_barycentric.map(|w| format!(", 2D weights ({:.4}, {:.4}, {:.4})", w.x, w.y, w.z)).unwrap_or_default();
            out.push(format!(
                "  t {:.4}: operand {} ({surface}{screen}) {}{}",
                f.t,
                self.operand(f),
                if f.entering { "entry" } else { "exit" },
                if self.won(f) { "  <- won" } else { "" }
            ));
        }
        out.extend(self.explanation.lines());
        out
    }
}

/// What the `opengl` renderer's pass left at a pixel: the surface its
/// fragment shader saw (interpolated position, normals, barycentrics, uv,
/// primitive; `None` where no fragment was drawn) and the colour it wrote.
/// Read back after the pass, not a replay.
#[derive(Clone, Debug, PartialEq)]
pub struct GlReadback {
    pub surface: Option<crate::scene::SurfaceHit>,
    pub output: Radiance,
}

/// Everything one sample of one pixel did, in order. Built by passing a
/// `PixelTrace` through the renderer's real code path.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PixelTrace {
    pub rays: Vec<RayRecord>,
    pub lights: Vec<LightSample>,
    /// Samples of area lights and the environment, in the order drawn.
    pub sampled_lights: Vec<SampledLight>,
    pub fragments: Vec<FragmentRecord>,
    /// Rasterizers: the A-buffer of each CSG object at this sample, in draw order.
    pub csg_abuffers: Vec<CsgABufferRecord>,
    /// Radiance returned at each shading depth, innermost first.
    pub shaded: Vec<(u32, Radiance)>,
    /// Path tracing: the sampled bounces, in order.
    pub bounces: Vec<Bounce>,
    /// Photon mapping: the density estimates read, in order.
    pub photon_estimates: Vec<Radiance>,
    /// The `opengl` renderer: what GL reported for the pixel, read back
    /// from its render targets (GL's shaders cannot be replayed).
    pub gl_readback: Option<GlReadback>,
    shadow_active: bool,
    /// Index of the ray that events go to (shadow rays interleave with the parent's).
    current: Option<usize>,
    parent: Vec<usize>,
}

impl PixelTrace {
    pub fn new() -> PixelTrace {
        PixelTrace::default()
    }

    /// Adds `other`'s records after this one's (a rasterizer's layers, one
    /// record each, become the pixel's record).
    pub fn append(&mut self, other: PixelTrace) {
        let PixelTrace { rays, lights, sampled_lights, fragments, csg_abuffers, shaded, bounces, photon_estimates, .. } = other;
        self.rays.extend(rays);
        self.lights.extend(lights);
        self.sampled_lights.extend(sampled_lights);
        self.fragments.extend(fragments);
        self.csg_abuffers.extend(csg_abuffers);
        self.shaded.extend(shaded);
        self.bounces.extend(bounces);
        self.photon_estimates.extend(photon_estimates);
    }

    /// A rasterizer's A-buffer record behind CSG hit `hit` (its eye ray's
    /// hit): the record of the hit's object whose winner is the hit's boundary.
    pub fn csg_abuffer_for(&self, hit: &SurfaceHit) -> Option<&CsgABufferRecord> {
        if hit.kind != PrimitiveKind::Csg {
            return None;
        }
        let mine = self.csg_abuffers.iter().filter(|a| a.csg == hit.primitive);
        let mut same = mine.clone().filter(|a| a.explanation.winner.is_some_and(|(b, _)| b.t == hit.t));
        same.next().or_else(|| mine.clone().find(|a| a.explanation.winner.is_some()))
    }

    fn current_ray(&mut self) -> Option<&mut RayRecord> {
        self.current.and_then(|i| self.rays.get_mut(i))
    }
}

impl Recorder for PixelTrace {
    fn bounce(&mut self, bounce: Bounce) {
        self.bounces.push(bounce);
    }

    fn photons(&mut self, radiance: Radiance) {
        self.photon_estimates.push(radiance);
    }

    fn ray(&mut self, ray: &Ray, t_max: f32, depth: u32) {
        if let Some(c) = self.current {
            self.parent.push(c);
        }
        self.rays.push(RayRecord {
            ray: *ray,
            t_max,
            depth,
            shadow: self.shadow_active,
            nodes_visited: Vec::new(),
            tests: Vec::new(),
            tests_omitted: 0,
            closest: None,
        });
        self.current = Some(self.rays.len() - 1);
    }

    fn node_visit(&mut self, node: u32) {
        if let Some(r) = self.current_ray() {
            r.nodes_visited.push(node);
        }
    }

    fn primitive_test(&mut self, test: PrimitiveTest) {
        if let Some(r) = self.current_ray() {
            if r.tests.len() < MAX_TESTS_PER_RAY {
                r.tests.push(test);
            } else {
                r.tests_omitted += 1;
            }
        }
    }

    fn closest(&mut self, hit: Option<&SurfaceHit>) {
        if let Some(r) = self.current_ray() {
            r.closest = hit.copied();
        }
    }

    fn light(&mut self, sample: LightSample) {
        self.lights.push(sample);
    }

    fn sampled_light(&mut self, sample: SampledLight) {
        self.sampled_lights.push(sample);
    }

    fn shaded(&mut self, depth: u32, radiance: Radiance) {
        self.shaded.push((depth, radiance));
        // Shading of this ray's hit is over: later events belong to its parent.
        self.current = self.parent.pop();
    }

    fn in_shadow_ray(&mut self, active: bool) {
        self.shadow_active = active;
        if !active {
            // The shadow ray is done; return to the ray being shaded.
            self.current = self.parent.pop();
        }
    }
}
