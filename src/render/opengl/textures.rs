//! The scene's textures as GL textures: each material texture, normal map
//! and the environment uploaded once as RGBA32F with the CPU's own mip
//! pyramid (one `glTexImage2D` per level, so GL filters the very texels
//! `Texture::sample` reads), and the filter and wrap state a draw needs.

use crate::scene::texture::{Texture, TextureFilter, Wrap};
use glow::HasContext;
use std::sync::Arc;

/// The texture unit uploads bind to; the draws use lower ones.
const UPLOAD_UNIT: u32 = 7;

/// Uploaded textures, kept while the scene holds them. The `Arc` held
/// here keeps its address from being reused by another texture.
#[derive(Default)]
pub struct Textures {
    uploaded: Vec<(Arc<Texture>, glow::Texture)>,
}

impl Textures {
    /// The GL texture holding `t`, uploaded on first use.
    pub unsafe fn get(&mut self, gl: &glow::Context, t: &Arc<Texture>) -> Result<glow::Texture, String> {
        if let Some((_, id)) = self.uploaded.iter().find(|(u, _)| Arc::ptr_eq(u, t)) {
            return Ok(*id);
        }
        unsafe {
            let id = gl.create_texture()?;
            // A unit of its own, so that no texture bound for drawing is replaced.
            gl.active_texture(glow::TEXTURE0 + UPLOAD_UNIT);
            gl.bind_texture(glow::TEXTURE_2D, Some(id));
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
            for (level, l) in t.levels.iter().enumerate() {
                let mut texels = Vec::with_capacity(l.texels.len() * 4);
                // Row 0 (the top) first: GL's t = 1 - v, as `MipLevel::position` reads.
                for c in &l.texels {
                    texels.extend_from_slice(&[c.x, c.y, c.z, 1.0]);
                }
                gl.tex_image_2d(
                    glow::TEXTURE_2D,
                    level as i32,
                    glow::RGBA32F as i32,
                    l.width as i32,
                    l.height as i32,
                    0,
                    glow::RGBA,
                    glow::FLOAT,
                    glow::PixelUnpackData::Slice(Some(super::pass::bytes(&texels))),
                );
            }
            gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_BASE_LEVEL, 0);
            gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAX_LEVEL, t.levels.len() as i32 - 1);
            self.uploaded.push((t.clone(), id));
            Ok(id)
        }
    }

    /// Forgets the textures no longer in `keep` (a scene replaced).
    pub unsafe fn retain(&mut self, gl: &glow::Context, keep: &[&Arc<Texture>]) {
        self.uploaded.retain(|(t, id)| {
            let kept = keep.iter().any(|k| Arc::ptr_eq(k, t));
            if !kept {
                unsafe { gl.delete_texture(*id) };
            }
            kept
        });
    }
}

/// Binds `texture` to `unit` with the filter and addressing the CPU's
/// `Texture::sample` uses: nearest and bilinear read level 0 only
/// (GL_NEAREST, GL_LINEAR), trilinear blends two levels
/// (GL_LINEAR_MIPMAP_LINEAR, magnified: GL_LINEAR).
pub unsafe fn bind(gl: &glow::Context, unit: u32, texture: glow::Texture, filter: TextureFilter, wrap_s: Wrap, wrap_t: Wrap) {
    let (min, mag) = match filter {
        TextureFilter::Nearest => (glow::NEAREST, glow::NEAREST),
        TextureFilter::Bilinear => (glow::LINEAR, glow::LINEAR),
        TextureFilter::Trilinear => (glow::LINEAR_MIPMAP_LINEAR, glow::LINEAR),
    };
    let address = |w: Wrap| match w {
        Wrap::Repeat => glow::REPEAT,
        Wrap::Clamp => glow::CLAMP_TO_EDGE,
    } as i32;
    unsafe {
        gl.active_texture(glow::TEXTURE0 + unit);
        gl.bind_texture(glow::TEXTURE_2D, Some(texture));
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MIN_FILTER, min as i32);
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAG_FILTER, mag as i32);
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_WRAP_S, address(wrap_s));
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_WRAP_T, address(wrap_t));
    }
}
