//! Materials: the terms of the scene format's BSDF, plus an optional texture.

use crate::scene::texture::{Footprint, Texture, TextureFilter, Wrap};
use crate::math::{Vec2, Vec3};
use std::sync::Arc;

pub const DEFAULT_MATERIAL: &str = "default";

/// The microfacet alpha a material has when its entry gives none.
pub const DEFAULT_ROUGHNESS: f32 = 0.1;
/// The smallest microfacet alpha: smaller values are raised to it (as
/// Mitsuba 3 does), so that `D` stays a finite number in f32.
pub const MIN_ROUGHNESS: f32 = 1e-4;

/// The shape of a material's glossy lobe (`glossy_model` in a scene file).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GlossyModel {
    /// Normalized Blinn-Phong `N(s) (n.h)^s` (uses `sharpness`).
    #[default]
    BlinnPhong,
    /// Normalized Phong `(s + 2) / (2 pi) (r.w_i)^s`, r the mirror direction
    /// of the viewer (uses `sharpness`).
    Phong,
    /// Microfacets with the GGX (Trowbridge-Reitz) distribution (uses `roughness`).
    Ggx,
    /// Microfacets with the Beckmann distribution (uses `roughness`).
    Beckmann,
    /// Ward's anisotropic lobe, alpha_u and alpha_v (`roughness_uv`) along
    /// the surface's tangent (growing u) and bitangent.
    Ward,
}

impl GlossyModel {
    /// The names a scene file gives the models, with the model each names.
    pub const NAMES: [(&'static str, GlossyModel); 5] =
        [("blinn-phong", GlossyModel::BlinnPhong), ("phong", GlossyModel::Phong), ("ggx", GlossyModel::Ggx), ("beckmann", GlossyModel::Beckmann), ("ward", GlossyModel::Ward)];

    /// The model named `name` in a scene file.
    pub fn parse(name: &str) -> Option<GlossyModel> {
        GlossyModel::NAMES.iter().find(|(n, _)| *n == name).map(|&(_, m)| m)
    }

    /// Whether the lobe is a microfacet one (shaped by `roughness`).
    pub fn is_microfacet(self) -> bool {
        matches!(self, GlossyModel::Ggx | GlossyModel::Beckmann)
    }
}

/// The shape of a material's diffuse lobe (`diffuse_model` in a scene
/// file), with its parameter; every model reflects the albedo k_L.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum DiffuseModel {
    /// `k_L / pi`.
    #[default]
    Lambert,
    /// Oren and Nayar's rough diffuse surface (their qualitative model),
    /// `sigma` the standard deviation of the facets' slope angle in radians.
    OrenNayar { sigma: f32 },
    /// Minnaert's moon-like lobe `k_L (k + 1) / (2 pi) cos_i^(k-1) cos_o^(1-k)`,
    /// k = `darkening` in [0, 1] (1 is Lambert).
    Minnaert { darkening: f32 },
    /// Cel shading: `cos_i` rounded to one of `bands` lit tones (or dark).
    Toon { bands: u32 },
}

impl DiffuseModel {
    /// The names a scene file gives the models.
    pub const NAMES: [&'static str; 4] = ["lambert", "oren-nayar", "minnaert", "toon"];

    /// The scene file's name of this model.
    pub fn name(self) -> &'static str {
        match self {
            DiffuseModel::Lambert => "lambert",
            DiffuseModel::OrenNayar { .. } => "oren-nayar",
            DiffuseModel::Minnaert { .. } => "minnaert",
            DiffuseModel::Toon { .. } => "toon",
        }
    }

    /// The model's one parameter as a number (0 for Lambert).
    pub fn parameter(self) -> f32 {
        match self {
            DiffuseModel::Lambert => 0.0,
            DiffuseModel::OrenNayar { sigma } => sigma,
            DiffuseModel::Minnaert { darkening } => darkening,
            DiffuseModel::Toon { bands } => bands as f32,
        }
    }
}

/// The Fresnel term of a material's glossy lobe (`fresnel` in a scene file):
/// how its reflectance changes with the angle between the light and the
/// microfacet (the half vector).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Fresnel {
    /// F = 1: the lobe reflects `glossy` at every angle.
    #[default]
    None,
    /// Schlick's approximation with F0 = `glossy`: `F0 + (1 - F0) (1 - cos)^5`.
    Schlick,
    /// The exact Fresnel reflectance of a conductor with complex index of
    /// refraction `eta + i k` per channel, scaled by `glossy`.
    Conductor { eta: Vec3, k: Vec3 },
}

impl Fresnel {
    /// The names a scene file gives the Fresnel terms.
    pub const NAMES: [&'static str; 3] = ["none", "schlick", "conductor"];

    /// The scene file's name of this term.
    pub fn name(self) -> &'static str {
        match self {
            Fresnel::None => "none",
            Fresnel::Schlick => "schlick",
            Fresnel::Conductor { .. } => "conductor",
        }
    }
}

/// The metallic-roughness model's parameters: base colour `b`, metalness
/// `m` and perceptual roughness `r`, each possibly varying over the
/// surface. At a point they give a diffuse lobe `b (1 - m)` and a glossy
/// lobe of alpha `r^2` whose Schlick Fresnel term starts at
/// `F0 = mix(0.04, b, m)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Metallic {
    /// `b`, multiplied by the material's `texture` where it has one.
    pub base: Vec3,
    pub metallic: f32,
    pub roughness: f32,
    /// Linear data multiplying the factors: blue is metalness, green roughness.
    pub map: Option<Arc<Texture>>,
}

/// How one texture is read: addressing along u and v outside [0, 1], and
/// the finest filter (the render's filter is lowered to it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampler {
    pub wrap: [Wrap; 2],
    pub finest_filter: TextureFilter,
}

/// Samplers of a material's maps other than its base texture; `None`
/// reads the map with the material's own `wrap` and `finest_filter`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MapSamplers {
    pub metallic: Option<Sampler>,
    pub normal: Option<Sampler>,
    pub emission: Option<Sampler>,
}

impl MapSamplers {
    /// Whether some map has a sampler of its own.
    pub fn any(&self) -> bool {
        self.metallic.is_some() || self.normal.is_some() || self.emission.is_some()
    }
}

/// F0 of dielectrics in the metallic-roughness model.
pub const DIELECTRIC_F0: f32 = 0.04;

/// What the BSDF reads of a material at one surface point, once its
/// textures are looked up there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLobes {
    /// k_L, the diffuse albedo.
    pub albedo: Vec3,
    /// k_G, the glossy lobe's weight (F0 under Schlick's Fresnel).
    pub glossy: Vec3,
    /// The microfacet alpha (not squared).
    pub roughness: f32,
}

impl PointLobes {
    /// A point of `material` whose lobes are its constants, with diffuse albedo `albedo`.
    #[inline]
    pub fn with_albedo(material: &Material, albedo: Vec3) -> PointLobes {
        PointLobes { albedo, glossy: material.glossy, roughness: material.roughness }
    }
}

/// What the BSDF routines accept for a point's lobes: a `PointLobes`, or a
/// bare diffuse albedo, the other lobes then the material's constants.
pub trait IntoLobes {
    fn into_lobes(self, material: &Material) -> PointLobes;
}

impl IntoLobes for PointLobes {
    #[inline(always)]
    fn into_lobes(self, _: &Material) -> PointLobes {
        self
    }
}

impl IntoLobes for Vec3 {
    #[inline(always)]
    fn into_lobes(self, material: &Material) -> PointLobes {
        PointLobes::with_albedo(material, self)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// k_L: diffuse albedo; the BSDF term is k_L / pi.
    pub lambertian: Vec3,
    /// The shape of the diffuse lobe.
    pub diffuse_model: DiffuseModel,
    /// k_G: the glossy lobe's weight (whichever `glossy_model` it has).
    pub glossy: Vec3,
    /// The Blinn-Phong and Phong lobes' exponent s.
    pub sharpness: f32,
    /// The shape of the glossy lobe.
    pub glossy_model: GlossyModel,
    /// The microfacet lobes' alpha (not squared), at least `MIN_ROUGHNESS`.
    pub roughness: f32,
    /// Ward's alpha along u and along v, each at least `MIN_ROUGHNESS`.
    pub roughness_uv: Vec2,
    /// The glossy lobe's Fresnel term.
    pub fresnel: Fresnel,
    pub mirror: Vec3,
    pub transmission: Vec3,
    pub ior: f32,
    /// Emitted radiance (W m^-2 sr^-1) from the front side (both sides when
    /// the object is two-sided): any surface with it is an area light.
    pub emission: Vec3,
    /// Multiplies `lambertian` when present (linear values, decoded from
    /// sRGB); with `metallic`, multiplies its base colour instead.
    pub texture: Option<Arc<Texture>>,
    /// Addressing of the material's textures outside [0, 1]: along u
    /// (columns) and along v (rows); `map_samplers` may give other maps
    /// their own.
    pub wrap: [Wrap; 2],
    /// The finest filter the material's textures are read with: the
    /// render's filter is lowered to it (a sampler that asks for nearest
    /// or unmipmapped reads); `map_samplers` may give other maps their own.
    pub finest_filter: TextureFilter,
    /// The samplers of the metallic-roughness, normal and emission maps
    /// where they differ from `wrap` and `finest_filter` (a glTF gives
    /// each texture its own).
    pub map_samplers: MapSamplers,
    /// Lobes worked out point by point from a base colour, metalness and
    /// roughness (the metallic-roughness model), instead of `lambertian`,
    /// `glossy` and `roughness`.
    pub metallic: Option<Metallic>,
    /// Multiplies `emission` when present (linear values, decoded from sRGB).
    pub emission_map: Option<Arc<Texture>>,
    /// Multiplies uvs before any lookup (a checker repeated n times).
    pub uv_scale: Vec2,
    /// Tangent-space normal map (linear data: 0.5, 0.5, 1 is "straight out").
    pub normal_map: Option<Arc<Texture>>,
    /// Where the surface is cut away (glTF's `alphaMode` MASK): rays pass
    /// through the points whose alpha is below the cutoff.
    pub cutout: Option<Cutout>,
}

/// An alpha-tested surface: its alpha at a point is `alpha` times the
/// alpha map there, and the surface is absent where that is below `cutoff`.
#[derive(Clone, Debug, PartialEq)]
pub struct Cutout {
    pub cutoff: f32,
    /// The constant alpha (glTF's base colour factor's fourth component).
    pub alpha: f32,
    /// Alpha in every channel, read with the material's `wrap` and filter.
    pub map: Option<Arc<Texture>>,
}

impl Material {
    /// Equal in every value, its textures compared by identity rather than
    /// texel by texel: what the viewer asks each frame to learn whether a
    /// material was edited (it never edits texels).
    pub fn same_but_texels(&self, o: &Material) -> bool {
        fn same_texture(a: &Option<Arc<Texture>>, b: &Option<Arc<Texture>>) -> bool {
            match (a, b) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (a, b) => a.is_none() && b.is_none(),
            }
        }
        let metallic_map = |m: &Material| m.metallic.as_ref().and_then(|m| m.map.clone());
        let without_texels = |m: &Material| Material {
            texture: None,
            normal_map: None,
            emission_map: None,
            metallic: m.metallic.clone().map(|metallic| Metallic { map: None, ..metallic }),
            cutout: m.cutout.clone().map(|cutout| Cutout { map: None, ..cutout }),
            ..m.clone()
        };
        let cutout_map = |m: &Material| m.cutout.as_ref().and_then(|c| c.map.clone());
        same_texture(&self.texture, &o.texture)
            && same_texture(&self.normal_map, &o.normal_map)
            && same_texture(&self.emission_map, &o.emission_map)
            && same_texture(&metallic_map(self), &metallic_map(o))
            && same_texture(&cutout_map(self), &cutout_map(o))
            && without_texels(self) == without_texels(o)
    }

    pub fn default_grey() -> Material {
        Material { name: DEFAULT_MATERIAL.into(), ..Material::black() }.with_lambertian(Vec3::splat(0.8))
    }

    /// All terms zero: the base that a scene file's entries fill in.
    pub fn black() -> Material {
        Material {
            name: String::new(),
            lambertian: Vec3::ZERO,
            diffuse_model: DiffuseModel::Lambert,
            glossy: Vec3::ZERO,
            sharpness: 100.0,
            glossy_model: GlossyModel::BlinnPhong,
            roughness: DEFAULT_ROUGHNESS,
            roughness_uv: Vec2::splat(DEFAULT_ROUGHNESS),
            fresnel: Fresnel::None,
            mirror: Vec3::ZERO,
            transmission: Vec3::ZERO,
            ior: 1.5,
            emission: Vec3::ZERO,
            texture: None,
            wrap: [Wrap::Repeat; 2],
            finest_filter: TextureFilter::Trilinear,
            map_samplers: MapSamplers::default(),
            metallic: None,
            emission_map: None,
            uv_scale: Vec2::ONE,
            normal_map: None,
            cutout: None,
        }
    }

    fn with_lambertian(mut self, k: Vec3) -> Material {
        self.lambertian = k;
        self
    }

    // These two are asked per shaded sample and bounce: the comparisons are
    // made lane by lane and combined without a branch per component.
    #[inline]
    pub fn has_glossy(&self) -> bool {
        self.glossy.cmpne(Vec3::ZERO).any()
    }

    /// True when surfaces of this material emit light.
    #[inline]
    pub fn is_emissive(&self) -> bool {
        self.emission.cmpne(Vec3::ZERO).any()
    }

    /// True when shading this material casts secondary rays.
    #[inline]
    pub fn has_secondary(&self) -> bool {
        (self.mirror.cmpne(Vec3::ZERO) | self.transmission.cmpne(Vec3::ZERO)).any()
    }

    /// Whether the lobes are worked out point by point (a texture feeds
    /// them, or the metallic-roughness model does) rather than read from
    /// the constants.
    #[inline]
    pub fn varies_over_surface(&self) -> bool {
        self.texture.is_some() || self.metallic.is_some()
    }

    /// Diffuse albedo at a surface point with uv `uv` and footprint `f`
    /// (textures applied, read with `filter`).
    #[inline]
    pub fn albedo(&self, uv: Vec2, f: &Footprint, filter: TextureFilter) -> Vec3 {
        self.lobes(uv, f, filter).albedo
    }

    /// The lobes at a surface point with uv `uv` and footprint `f`, the
    /// textures read with `filter` (lowered to `finest_filter`).
    #[inline]
    pub fn lobes(&self, uv: Vec2, f: &Footprint, filter: TextureFilter) -> PointLobes {
        self.lobes_tinted(uv, f, filter, Vec3::ONE)
    }

    /// `lobes` at a point whose vertex colour is `tint`: it multiplies the
    /// diffuse albedo, or under the metallic-roughness model the base
    /// colour (so a metal's F0 too). White changes nothing, bit for bit.
    #[inline]
    pub fn lobes_tinted(&self, uv: Vec2, f: &Footprint, requested: TextureFilter, tint: Vec3) -> PointLobes {
        let filter = requested.at_most(self.finest_filter);
        let Some(m) = &self.metallic else {
            let albedo = match &self.texture {
                Some(t) => {
                    let (uv, f) = self.scaled(uv, f);
                    self.lambertian * t.sample(uv, &f, filter, self.wrap)
                }
                None => self.lambertian,
            };
            return PointLobes::with_albedo(self, albedo * tint);
        };
        let (uv, f) = self.scaled(uv, f);
        let base = match &self.texture {
            Some(t) => m.base * t.sample(uv, &f, filter, self.wrap),
            None => m.base,
        } * tint;
        let (metallic, roughness) = match &m.map {
            Some(t) => {
                let (wrap, filter) = self.read_with(self.map_samplers.metallic, requested);
                let texel = t.sample(uv, &f, filter, wrap);
                (m.metallic * texel.z, m.roughness * texel.y)
            }
            None => (m.metallic, m.roughness),
        };
        PointLobes {
            albedo: base * (1.0 - metallic),
            glossy: Vec3::splat(DIELECTRIC_F0).lerp(base, metallic),
            roughness: (roughness * roughness).max(MIN_ROUGHNESS),
        }
    }

    /// Emitted radiance at `uv` (the emission map read bilinearly at its
    /// finest level, or nearest when the sampler asks for it).
    #[inline]
    pub fn emission_at(&self, uv: Vec2) -> Vec3 {
        match &self.emission_map {
            Some(t) => {
                let (uv, f) = self.scaled(uv, &Footprint::default());
                let (wrap, filter) = self.read_with(self.map_samplers.emission, TextureFilter::Bilinear);
                self.emission * t.sample(uv, &f, filter, wrap)
            }
            None => self.emission,
        }
    }

    /// The normal map's value at `uv` (linear, 0..1 per channel), if there is one.
    #[inline]
    pub fn normal_map_texel(&self, uv: Vec2, f: &Footprint, filter: TextureFilter) -> Option<Vec3> {
        self.normal_map.as_ref().map(|t| {
            let (uv, f) = self.scaled(uv, f);
            let (wrap, filter) = self.read_with(self.map_samplers.normal, filter);
            t.sample(uv, &f, filter, wrap)
        })
    }

    /// Whether the surface is cut away at `uv`: its alpha there (read
    /// bilinearly at the finest level, or nearest when the sampler asks for
    /// it) is below the cutoff. Always false without a cutout.
    #[inline]
    pub fn cut_out_at(&self, uv: Vec2) -> bool {
        let Some(c) = &self.cutout else { return false };
        let alpha = match &c.map {
            Some(t) => {
                let (uv, f) = self.scaled(uv, &Footprint::default());
                c.alpha * t.sample(uv, &f, TextureFilter::Bilinear.at_most(self.finest_filter), self.wrap).x
            }
            None => c.alpha,
        };
        alpha < c.cutoff
    }

    /// The addressing and filter a map is read with: its own `sampler`, or
    /// the material's; `requested` lowered to the sampler's finest filter.
    #[inline]
    fn read_with(&self, sampler: Option<Sampler>, requested: TextureFilter) -> ([Wrap; 2], TextureFilter) {
        match sampler {
            Some(s) => (s.wrap, requested.at_most(s.finest_filter)),
            None => (self.wrap, requested.at_most(self.finest_filter)),
        }
    }

    /// uv and footprint with `uv_scale` applied.
    #[inline]
    pub fn scaled(&self, uv: Vec2, f: &Footprint) -> (Vec2, Footprint) {
        let s = self.uv_scale;
        (uv * s, Footprint { duv_dx: f.duv_dx * s, duv_dy: f.duv_dy * s })
    }
}
