//! Direct light, written once over a lane type (`math::lanes`): how each
//! light arrives at a surface point, the BSDF (CGPP listing 15.19) and their
//! sum over the lights. `shade()` runs it one sample wide, and a frame's
//! batches (`shade_batch`) eight wide, through the same code: the pixel a
//! replay shows is the pixel the frame computed, bit for bit.
//!
//! Visibility is not decided here: a [`LightVisibility`] answers it per light
//! (shadow rays, maps, volumes, or a packet's answers), because how it is
//! known differs between callers while the arithmetic must not.

use crate::math::lanes::{exp2, pow, Lane, V3};
use crate::scene::Light;
use std::f32::consts::PI;

/// What the BSDF and the lights need of a surface, per lane.
#[derive(Clone, Copy)]
pub struct SurfaceLanes<L: Lane> {
    pub position: V3<L>,
    /// Unit shading normal.
    pub normal: V3<L>,
    /// Unit direction towards the viewer.
    pub w_o: V3<L>,
    /// Diffuse albedo k_L (texture applied).
    pub albedo: V3<L>,
    /// Blinn-Phong weight k_G and sharpness s.
    pub glossy: V3<L>,
    pub sharpness: L,
}

/// How one light arrives at a surface point, per lane, before visibility.
#[derive(Clone, Copy)]
pub struct IncidenceLanes<L: Lane> {
    /// Unit direction towards the light.
    pub w_i: V3<L>,
    /// Distance to the light (infinite for directional lights).
    pub distance: L,
    /// Incident radiance (point, CGPP 15.4.5: power / (4 pi d^2)) or
    /// irradiance (directional).
    pub incident: V3<L>,
    /// `w_i . n` with the shading normal.
    pub cos_theta: L,
    /// False where a point light sits exactly at the point: it has no
    /// direction there and contributes nothing (the other fields are then
    /// meaningless).
    pub exists: L::Mask,
}

impl<L: Lane> IncidenceLanes<L> {
    /// Where the light reaches the surface's lit side with some radiance:
    /// only there can it contribute, and only there is visibility asked.
    #[inline(always)]
    pub fn illuminates(&self) -> L::Mask {
        let zero = self.cos_theta.splat(0.0);
        self.exists & !(self.cos_theta.le(zero) | self.incident.is_zero())
    }
}

/// Light `light` at points `p` with unit shading normals `n`.
#[inline(always)]
pub fn incidence<L: Lane>(light: &Light, p: V3<L>, n: V3<L>) -> IncidenceLanes<L> {
    let like = p.x;
    let (w_i, distance, incident, exists) = match *light {
        Light::Point { position, power } => {
            let offset = V3::splat(like, position) - p;
            let d = offset.length();
            let w_i = offset.div(d);
            (w_i, d, V3::splat(like, power).div(like.splat(4.0 * PI) * d * d), d.gt(like.splat(0.0)))
        }
        Light::Directional { direction, irradiance } => {
            let always = like.eq(like) | !like.eq(like);
            (V3::splat(like, -direction), like.splat(f32::INFINITY), V3::splat(like, irradiance), always)
        }
    };
    IncidenceLanes { w_i, distance, incident, cos_theta: w_i.dot(n), exists }
}

/// The BSDF of CGPP listing 15.19: Lambertian plus normalized Blinn-Phong,
/// `f = k_L / pi + k_G N(s) max(0, n.h)^s` with `N` from
/// `blinn_phong_normalization`. The glossy lobe is
/// left out where k_G = 0, and where it cannot matter: `c^s <= exp(-s (1 -
/// c))` since `ln c <= c - 1`, so when that bound is below 1e-9 the lobe adds
/// nothing visible and the power is not computed (in no lane, when no lane
/// needs it).
#[inline(always)]
pub fn bsdf<L: Lane>(s: &SurfaceLanes<L>, w_i: V3<L>) -> V3<L> {
    let like = s.sharpness;
    let f = s.albedo.scale(like.splat(1.0 / PI));
    let glossy = !s.glossy.is_zero();
    if !L::any(glossy) {
        return f;
    }
    let w_h = (w_i + s.w_o).normalize_or_zero();
    let c = s.normal.dot(w_h).max(like.splat(0.0));
    let sharp = s.sharpness;
    let needed = glossy & (sharp * (like.splat(1.0) - c)).lt(like.splat(20.7));
    if !L::any(needed) {
        return f;
    }
    let lobe = blinn_phong_normalization(sharp) * pow(c, sharp);
    V3::select(needed, f + s.glossy.scale(lobe), f)
}

/// `N(s) = (s + 2)(s + 4) / (8 pi (2^(-s/2) + s))`: the factor that makes
/// the Blinn-Phong lobe `N(s) (n.h)^s` reflect exactly what arrives when
/// seen along the normal, and less at every other angle (the horizon cuts
/// the lobe off there). The book's `(s + 8) / (8 pi)` approximates it and
/// reflects up to 7.5% more than arrives near s = 8; both tend to `s / (8
/// pi)` as s grows, and at s = 0 both give the Lambertian `1 / pi`.
#[inline(always)]
pub fn blinn_phong_normalization<L: Lane>(s: L) -> L {
    let half = (s * s.splat(-0.5)).max(s.splat(-126.0));
    (s + s.splat(2.0)) * (s + s.splat(4.0)) / (s.splat(8.0 * PI) * (exp2(half) + s))
}

/// Answers, per light, whether it is visible from the surface, and hears
/// what it contributed (for the pixel recorder).
pub trait LightVisibility<L: Lane> {
    /// Visibility of light `light` in the lanes of `lit` (other lanes are ignored).
    fn visible(&mut self, light: usize, incidence: &IncidenceLanes<L>, lit: L::Mask) -> L::Mask;

    /// Light `light`'s BSDF value and contribution, zero where not lit or
    /// not visible; called for every light that exists in some lane.
    #[inline(always)]
    fn reflected(&mut self, _light: usize, _incidence: &IncidenceLanes<L>, _lit: L::Mask, _bsdf: V3<L>, _contribution: V3<L>) {}
}

/// `start` (the ambient or indirect term) plus every light's
/// `incident * f * cos`, in the order of `lights`, where visible.
#[inline(always)]
pub fn direct_light<L: Lane, V: LightVisibility<L>>(lights: &[Light], s: &SurfaceLanes<L>, start: V3<L>, vis: &mut V) -> V3<L> {
    let zero = V3::splat(s.sharpness, glam::Vec3::ZERO);
    let mut l_o = start;
    for (index, light) in lights.iter().enumerate() {
        let inc = incidence(light, s.position, s.normal);
        if !L::any(inc.exists) {
            continue;
        }
        let lit = inc.illuminates();
        if !L::any(lit) {
            vis.reflected(index, &inc, lit, zero, zero);
            continue;
        }
        let visible = vis.visible(index, &inc, lit);
        let f = bsdf(s, inc.w_i);
        let contribution = (inc.incident * f).scale(inc.cos_theta);
        let counted = lit & visible;
        l_o = V3::select(counted, l_o + contribution, l_o);
        vis.reflected(index, &inc, lit, V3::select(lit, f, zero), V3::select(counted, contribution, zero));
    }
    l_o
}
