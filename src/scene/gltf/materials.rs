//! glTF metallic-roughness materials as pinhole materials, and their
//! base-colour textures decoded.
//!
//! A base colour `b`, metallic `m` and roughness `r` become a Lambertian
//! lobe `b (1 - m)` plus a GGX lobe with alpha `r^2` whose Schlick Fresnel
//! term starts at `F0 = mix(0.04, b, m)`. The base-colour texture
//! multiplies the Lambertian lobe. The emissive factor (times
//! `KHR_materials_emissive_strength`) is the emitted radiance.

use crate::input::{InputKind, MAX_LIGHT};
use crate::math::Vec3;
use crate::scene::material::{Fresnel, GlossyModel, MIN_ROUGHNESS};
use crate::scene::texture::{decode_texture, Encoding, Texture, Wrap};
use crate::scene::Material;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// F0 of dielectrics in the metallic-roughness model.
const DIELECTRIC_F0: f32 = 0.04;

/// Decodes each image once, however many materials use it.
pub struct Images<'a> {
    pub folder: &'a Path,
    pub buffers: &'a [Vec<u8>],
    pub decoded: HashMap<usize, Arc<Texture>>,
}

impl Images<'_> {
    fn get(&mut self, image: &gltf::Image) -> Result<Arc<Texture>, String> {
        let i = image.index();
        if let Some(t) = self.decoded.get(&i) {
            return Ok(Arc::clone(t));
        }
        let what = format!("image {i}");
        let bytes = match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = &self.buffers[view.buffer().index()];
                let range = view.offset()..view.offset().saturating_add(view.length());
                buffer.get(range).ok_or(format!("{what}: buffer view {} runs past the end of buffer {}", view.index(), view.buffer().index()))?.to_vec()
            }
            gltf::image::Source::Uri { uri, .. } => super::source::read_uri(uri, self.folder, &what, InputKind::Image)?,
        };
        let texture = Arc::new(decode_texture(bytes, &what, Encoding::Srgb)?);
        self.decoded.insert(i, Arc::clone(&texture));
        Ok(texture)
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
    if let Some(info) = pbr.base_color_texture() {
        if info.tex_coord() != 0 {
            ignored.push(format!("{at}: a base-colour texture on uv set {}", info.tex_coord()));
        } else {
            let texture = info.texture();
            mat.texture = Some(images.get(&texture.source()).map_err(|e| format!("{at}: baseColorTexture: {e}"))?);
            mat.wrap = match texture.sampler().wrap_s() {
                gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
                gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
                gltf::texture::WrappingMode::MirroredRepeat => {
                    ignored.push(format!("{at}: mirrored-repeat wrapping (drawn as repeat)"));
                    Wrap::Repeat
                }
            };
        }
    }
    for (what, present) in [
        ("metallic-roughness texture", pbr.metallic_roughness_texture().is_some()),
        ("normal texture", m.normal_texture().is_some()),
        ("occlusion texture", m.occlusion_texture().is_some()),
        ("emissive texture", m.emissive_texture().is_some()),
    ] {
        if present {
            ignored.push(format!("{at}: its {what}"));
        }
    }
    match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => {}
        gltf::material::AlphaMode::Mask => ignored.push(format!("{at}: alphaMode MASK (drawn opaque)")),
        gltf::material::AlphaMode::Blend => ignored.push(format!("{at}: alphaMode BLEND (drawn opaque)")),
    }
    Ok(mat)
}
