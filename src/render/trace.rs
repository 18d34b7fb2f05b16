//! The pixel recorder (DESIGN.md principle 6): renderers and `shade()` report
//! what they do to a `Recorder`. Frames pass `NoRecord`, whose methods are
//! empty and compile away; `pinhole pixel` and the inspector pass a
//! `PixelTrace` through the very same code.

use super::raytrace::intersect::Miss;
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
    /// What blocked the shadow ray: primitive and t.
    pub blocker: Option<(PrimitiveKind, u32, f32)>,
    pub bsdf: Vec3,
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
    /// Radiance returned by the shading of the current ray's hit.
    fn shaded(&mut self, _depth: u32, _radiance: Radiance) {}
    /// While true, `primitive_test` and `node_visit` come from a shadow ray.
    fn in_shadow_ray(&mut self, _active: bool) {}
}

/// Records nothing; the frame's recorder.
pub struct NoRecord;

impl Recorder for NoRecord {
    const ENABLED: bool = false;
}
