//! The approximations of shadow rays: shadow maps (`map`, with PCF) and
//! shadow volumes (`volume`, counted in the rasterizer's stencil). Each is
//! measured against the ray-traced shadows it stands in for.

pub mod map;
pub mod volume;

use crate::named::named_enum;

named_enum! {
    /// How a shadow map is read (`--shadow-filter`).
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum ShadowFilter ("shadow filter") {
        /// The nearest texel: a hard edge, as from a point at the light's centre.
        #[default]
        None = "none",
        /// Percentage-closer filtering: the fraction of texels within
        /// `pcf_radius` that do not shadow the point (the same blur everywhere).
        Pcf = "pcf",
        /// Percentage-closer soft shadows: a blocker search, a penumbra width
        /// estimated from the light's size, then PCF of that width.
        Pcss = "pcss",
    }
}

use crate::math::Ray;
use crate::render::inspect::pixel_record::Recorder;
use crate::render::{Occluder, RayCounts, SceneQuery};
use crate::scene::SurfaceHit;

/// A scene query whose light visibility may come from an approximation: the
/// rays go to `inner` unchanged, and `shade()` asks `shadow_maps()` (with
/// `ShadowMode::Map`) or `volume_count()` (with `ShadowMode::Volume`, at
/// depth 0: a stencil's per-light counts for the primary surface) before it
/// would cast a shadow ray.
pub struct ApproximateShadows<'a, Q> {
    pub inner: &'a Q,
    pub maps: Option<&'a map::ShadowMaps>,
    /// One count per light, in scene order.
    pub volume_counts: Option<&'a [i32]>,
}

impl<Q: SceneQuery> SceneQuery for ApproximateShadows<'_, Q> {
    #[inline]
    fn closest<R: Recorder>(&self, ray: &Ray, t_max: f32, inside: bool, counts: &mut RayCounts, rec: &mut R) -> Option<SurfaceHit> {
        self.inner.closest(ray, t_max, inside, counts, rec)
    }

    #[inline]
    fn occluder<R: Recorder>(&self, ray: &Ray, t_max: f32, counts: &mut RayCounts, rec: &mut R) -> Option<Occluder> {
        self.inner.occluder(ray, t_max, counts, rec)
    }

    #[inline]
    fn shadow_maps(&self) -> Option<&map::ShadowMaps> {
        self.maps
    }

    #[inline]
    fn volume_count(&self, light: usize) -> Option<i32> {
        self.volume_counts.and_then(|c| c.get(light).copied())
    }
}
