//! The surfaces' scattering: the BSDF one sample evaluates (Lambertian plus
//! a glossy lobe: normalized Blinn-Phong, CGPP listing 15.19, Phong, or GGX
//! or Beckmann microfacets; written once over lanes in `lighting`) and the delta lobes of mirrors and glass (Fresnel by Schlick's
//! approximation, refraction by Snell's law).

use crate::math::Vec3;
use crate::render::transport::lighting;
use crate::render::transport::lighting::SurfaceLanes;
use crate::scene::material::{GlossyModel, IntoLobes, PointLobes};
use crate::scene::tangents::tangent_at;
use crate::scene::{Material, Scene, SurfaceHit};

/// Where a BSDF is evaluated: the unit shading normal and the surface's
/// tangent (growing u; zero where there is none, and then a fixed
/// perpendicular stands in). Only Ward's anisotropic lobe reads the
/// tangent, so a bare normal converts into a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingFrame {
    pub n: Vec3,
    pub tangent: Vec3,
}

impl From<Vec3> for ShadingFrame {
    #[inline(always)]
    fn from(n: Vec3) -> Self {
        ShadingFrame { n, tangent: Vec3::ZERO }
    }
}

impl ShadingFrame {
    /// The frame at `hit` for `material`: the tangent is looked up only for
    /// Ward's lobe, which is the only one to read it.
    #[inline]
    pub fn at(scene: &Scene, hit: &SurfaceHit, material: &Material) -> Self {
        let tangent = if material.glossy_model == GlossyModel::Ward { tangent_at(scene, hit).truncate() } else { Vec3::ZERO };
        ShadingFrame { n: hit.shading_normal, tangent }
    }
}

/// The BSDF for one sample (`lighting::bsdf`, one lane wide): the diffuse
/// lobe plus the material's glossy lobe, `f = f_d + k_G lobe`, at `frame`
/// (a normal, or a normal and tangent).
#[inline]
pub fn bsdf(material: &Material, lobes: impl IntoLobes, frame: impl Into<ShadingFrame>, w_i: Vec3, w_o: Vec3) -> Vec3 {
    let surface = surface_lane(material, lobes.into_lobes(material), Vec3::ZERO, frame.into(), w_o);
    lighting::bsdf(&surface, w_i.into()).into()
}

/// One sample's surface as the lane-generic lighting code reads it: the
/// material's lobes at the point (`lobes`) and its models.
#[inline(always)]
pub(crate) fn surface_lane(material: &Material, lobes: PointLobes, position: Vec3, frame: ShadingFrame, w_o: Vec3) -> SurfaceLanes<f32> {
    SurfaceLanes {
        position: position.into(),
        normal: frame.n.into(),
        w_o: w_o.into(),
        albedo: lobes.albedo.into(),
        diffuse: lighting::DiffuseLanes::splat(0.0, material.diffuse_model),
        glossy: lobes.glossy.into(),
        sharpness: material.sharpness,
        glossy_model: lighting::model_lane(material.glossy_model),
        roughness: lighting::roughness_u(material, lobes.roughness),
        roughness_v: lighting::roughness_v(material),
        tangent: frame.tangent.into(),
        fresnel: lighting::FresnelLanes::splat(0.0, material.fresnel),
    }
}

/// The Fresnel reflectance (Schlick's approximation) at a dielectric seen
/// from `w_o`, and the refracted direction unless the light is totally
/// reflected. Entering when the front side faces us (spheres flip
/// `back_face` inside).
#[inline]
pub fn refraction(hit: &SurfaceHit, material: &Material, w_o: Vec3) -> (f32, Option<Vec3>) {
    let n = hit.geometric_normal;
    let cos_o = w_o.dot(n).clamp(-1.0, 1.0);
    let (eta_i, eta_t) = if hit.back_face { (material.ior, 1.0) } else { (1.0, material.ior) };
    let eta = eta_i / eta_t;
    let sin2_t = eta * eta * (1.0 - cos_o * cos_o).max(0.0);
    let r0 = ((eta_i - eta_t) / (eta_i + eta_t)).powi(2);
    let fresnel = if sin2_t >= 1.0 { 1.0 } else { r0 + (1.0 - r0) * (1.0 - cos_o.abs()).powi(5) };
    let refracted = (sin2_t < 1.0).then(|| {
        let cos_t = (1.0 - sin2_t).sqrt();
        (-w_o * eta + n * (eta * cos_o - cos_t)).normalize()
    });
    (fresnel, refracted)
}

/// The two delta lobes of a surface seen from `w_o`: mirror reflection
/// (the material's mirror weight plus the Fresnel-reflected part of its
/// transmission) and refraction (the rest of the transmission, unless the
/// light is totally reflected).
pub(crate) struct DeltaLobes {
    pub reflect_dir: Vec3,
    pub reflect_weight: Vec3,
    /// Direction and weight.
    pub refract: Option<(Vec3, Vec3)>,
}

impl DeltaLobes {
    #[inline]
    pub fn at(hit: &SurfaceHit, material: &Material, w_o: Vec3) -> DeltaLobes {
        let n = hit.geometric_normal;
        let cos_o = w_o.dot(n).clamp(-1.0, 1.0);
        let mut reflect_weight = material.mirror;
        let mut refract = None;
        if material.transmission != Vec3::ZERO {
            let (fresnel, dir) = refraction(hit, material, w_o);
            reflect_weight += material.transmission * fresnel;
            refract = dir.map(|d| (d, material.transmission * (1.0 - fresnel)));
        }
        DeltaLobes { reflect_dir: (2.0 * cos_o * n - w_o).normalize(), reflect_weight, refract }
    }
}

/// The mirror direction of `w_o` about the normal `n`: `2 (w_o.n) n - w_o`
/// (photons' bounces; `DeltaLobes` clamps the cosine first, as shading has
/// always done, so its bits stay its own).
#[inline]
pub fn mirror_direction(n: Vec3, w_o: Vec3) -> Vec3 {
    (2.0 * w_o.dot(n) * n - w_o).normalize()
}
