//! glTF metallic-roughness materials as pinhole materials, and their
//! textures decoded.
//!
//! A base colour `b`, metallic `m` and roughness `r` become a Lambertian
//! lobe `b (1 - m)` plus a GGX lobe with alpha `r^2` whose Schlick Fresnel
//! term starts at `F0 = mix(0.04, b, m)`. With a base-colour or
//! metallic-roughness texture the lobes are worked out point by point
//! (`Material::metallic`): the base-colour texture multiplies `b`, the
//! metallic-roughness texture's blue channel `m` and its green channel `r`.
//! The emissive factor (times `KHR_materials_emissive_strength`, times the
//! emissive texture) is the emitted radiance; the normal texture bends the
//! shading normal in the frame the uvs give (or the file's TANGENTs). Each
//! texture is read with its own sampler's wrap modes and filters. `alphaMode` MASK cuts the
//! surface away where the base colour's alpha (factor times texture) is
//! below `alphaCutoff`.

use crate::input::{InputKind, MAX_LIGHT};
use crate::math::Vec3;
use crate::scene::material::{Cutout, Fresnel, GlossyModel, MapSamplers, Metallic, Sampler, DIELECTRIC_F0, MIN_ROUGHNESS};
use crate::scene::texture::{decode_alpha, decode_texture, Encoding, Texture, TextureFilter, Wrap};
use crate::scene::Material;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Decodes each image once per encoding, however many materials use it.
pub struct Images<'a> {
    pub folder: &'a Path,
    pub buffers: &'a [Vec<u8>],
    pub decoded: HashMap<(usize, bool), Arc<Texture>>,
    /// Each image's alpha channel, `None` for an image without one.
    pub alphas: HashMap<usize, Option<Arc<Texture>>>,
}

impl Images<'_> {
    /// The image's encoded bytes, from its buffer view or its URI.
    fn bytes(&self, image: &gltf::Image) -> Result<Vec<u8>, String> {
        let what = format!("image {}", image.index());
        match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = &self.buffers[view.buffer().index()];
                let range = view.offset()..view.offset().saturating_add(view.length());
                Ok(buffer.get(range).ok_or(format!("{what}: buffer view {} runs past the end of buffer {}", view.index(), view.buffer().index()))?.to_vec())
            }
            gltf::image::Source::Uri { uri, .. } => super::source::read_uri(uri, self.folder, &what, InputKind::Image),
        }
    }

    fn get(&mut self, image: &gltf::Image, encoding: Encoding) -> Result<Arc<Texture>, String> {
        let i = image.index();
        let key = (i, encoding == Encoding::Srgb);
        if let Some(t) = self.decoded.get(&key) {
            return Ok(Arc::clone(t));
        }
        let texture = Arc::new(decode_texture(self.bytes(image)?, &format!("image {i}"), encoding)?);
        self.decoded.insert(key, Arc::clone(&texture));
        Ok(texture)
    }

    /// The image's alpha channel, `None` when it has none.
    fn alpha(&mut self, image: &gltf::Image) -> Result<Option<Arc<Texture>>, String> {
        let i = image.index();
        if let Some(t) = self.alphas.get(&i) {
            return Ok(t.clone());
        }
        let texture = decode_alpha(&self.bytes(image)?, &format!("image {i}"))?.map(Arc::new);
        self.alphas.insert(i, texture.clone());
        Ok(texture)
    }
}

/// A sampler's wrap mode as pinhole's.
fn wrap(mode: gltf::texture::WrappingMode) -> Wrap {
    match mode {
        gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
        gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
    }
}

/// The finest of pinhole's filters a sampler allows: a NEAREST
/// magnification filter reads single texels, a minification filter
/// without mipmaps reads level 0 only; unset filters allow everything.
pub fn finest_filter(sampler: &gltf::texture::Sampler) -> TextureFilter {
    use gltf::texture::{MagFilter, MinFilter};
    let blends = sampler.mag_filter() != Some(MagFilter::Nearest);
    let mipmapped = !matches!(sampler.min_filter(), Some(MinFilter::Nearest | MinFilter::Linear));
    match (blends, mipmapped) {
        (false, _) => TextureFilter::Nearest,
        (true, false) => TextureFilter::Bilinear,
        (true, true) => TextureFilter::Trilinear,
    }
}

/// Material `m` of the glTF, named `name`; what it has that pinhole does
/// not draw is added to `ignored`.
pub fn convert(m: &gltf::Material, name: String, images: &mut Images, ignored: &mut Vec<String>) -> Result<Material, String> {
    let at = format!("material {}", m.index().unwrap_or(0));
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let base = Vec3::new(r, g, b);
    let metallic = pbr.metallic_factor();
    let roughness = pbr.roughness_factor();
    let finite = base.is_finite() && metallic.is_finite() && roughness.is_finite();
    if !finite || base.min_element() < 0.0 || base.max_element() > 1.0 || !(0.0..=1.0).contains(&metallic) || !(0.0..=1.0).contains(&roughness) {
        return Err(format!("{at}: baseColorFactor, metallicFactor and roughnessFactor must be numbers from 0 to 1"));
    }
    let mut mat = Material::black();
    mat.name = name;
    mat.lambertian = base * (1.0 - metallic);
    mat.glossy = Vec3::splat(DIELECTRIC_F0).lerp(base, metallic);
    mat.glossy_model = GlossyModel::Ggx;
    mat.roughness = (roughness * roughness).max(MIN_ROUGHNESS);
    mat.fresnel = Fresnel::Schlick;
    let strength = m.emissive_strength().unwrap_or(1.0);
    mat.emission = Vec3::from(m.emissive_factor()) * strength;
    if !(mat.emission.is_finite() && mat.emission.min_element() >= 0.0 && mat.emission.max_element() <= MAX_LIGHT) {
        return Err(format!("{at}: emissiveFactor times emissiveStrength must be finite, not negative and at most {MAX_LIGHT:e}"));
    }

    // The textures pinhole reads, each with its uv set and sampler: the
    // material's own sampler is the base-colour texture's (or the first
    // texture's), and any other map whose sampler differs keeps its own.
    let normal = m.normal_texture();
    let emissive = m.emissive_texture();
    let slots: [(&str, Option<(gltf::Texture, u32)>); 4] = [
        ("baseColorTexture", pbr.base_color_texture().map(|i| (i.texture(), i.tex_coord()))),
        ("metallicRoughnessTexture", pbr.metallic_roughness_texture().map(|i| (i.texture(), i.tex_coord()))),
        ("normalTexture", normal.as_ref().map(|i| (i.texture(), i.tex_coord()))),
        ("emissiveTexture", emissive.as_ref().map(|i| (i.texture(), i.tex_coord()))),
    ];
    let mut samplers: [Option<Sampler>; 4] = [None; 4];
    let mut read = [None, None, None, None];
    for (k, (what, slot)) in slots.into_iter().enumerate() {
        let Some((texture, set)) = slot else { continue };
        if set != 0 {
            ignored.push(format!("{at}: its {what} on uv set {set}"));
            continue;
        }
        let s = texture.sampler();
        samplers[k] = Some(Sampler { wrap: [wrap(s.wrap_s()), wrap(s.wrap_t())], finest_filter: finest_filter(&s) });
        let encoding = if matches!(k, 1 | 2) { Encoding::Linear } else { Encoding::Srgb };
        read[k] = Some(images.get(&texture.source(), encoding).map_err(|e| format!("{at}: {what}: {e}"))?);
    }
    if let Some(own) = samplers.iter().flatten().next() {
        mat.wrap = own.wrap;
        mat.finest_filter = own.finest_filter;
    }
    let own = (mat.wrap, mat.finest_filter);
    let differs = |s: Option<Sampler>| s.filter(|s| (s.wrap, s.finest_filter) != own);
    mat.map_samplers = MapSamplers { metallic: differs(samplers[1]), normal: differs(samplers[2]), emission: differs(samplers[3]) };
    let [base_map, metallic_map, normal_map, emission_map] = read;
    if base_map.is_some() || metallic_map.is_some() {
        mat.metallic = Some(Metallic { base, metallic, roughness, map: metallic_map });
    }
    mat.texture = base_map;
    mat.normal_map = normal_map;
    if mat.is_emissive() {
        mat.emission_map = emission_map;
    }
    if normal.as_ref().is_some_and(|n| n.scale() != 1.0) {
        ignored.push(format!("{at}: its normal texture's scale (drawn at 1)"));
    }
    if m.occlusion_texture().is_some() {
        ignored.push(format!("{at}: its occlusion texture"));
    }
    match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => {}
        gltf::material::AlphaMode::Mask => {
            // Alpha is the base colour factor's fourth component times the
            // base-colour texture's alpha (vertex colours' alpha is not read).
            let alpha = pbr.base_color_factor()[3];
            let cutoff = m.alpha_cutoff().unwrap_or(0.5);
            if !(alpha.is_finite() && (0.0..=1.0).contains(&alpha) && cutoff.is_finite() && cutoff >= 0.0) {
                return Err(format!("{at}: the base colour's alpha must be a number from 0 to 1 and alphaCutoff a number from 0 up"));
            }
            let map = match pbr.base_color_texture().filter(|t| t.tex_coord() == 0) {
                Some(info) => images.alpha(&info.texture().source()).map_err(|e| format!("{at}: baseColorTexture: {e}"))?,
                None => None,
            };
            mat.cutout = Some(Cutout { cutoff, alpha, map });
        }
        gltf::material::AlphaMode::Blend => ignored.push(format!("{at}: alphaMode BLEND (drawn opaque)")),
    }
    Ok(mat)
}
