//! The scene's textures as the shaders read them: every level of each
//! material texture, normal map and the environment, the CPU's own pyramid,
//! in one shader storage buffer of linear RGB floats, and a table of levels
//! (where each starts, its width and height). The shaders address and
//! filter the texels themselves, in float, as `Texture::sample` does
//! (`shaders::sample_texture`); no sampler state, level selection or
//! fixed-point filter weights of the driver take part.

use crate::scene::texture::Texture;
use glow::HasContext;
use std::sync::Arc;

/// Storage-buffer bindings of the texels and of the level table.
pub const TEXEL_BINDING: u32 = 4;
pub const LEVEL_BINDING: u32 = 5;

/// The uploaded textures: each one's first row in the level table and its
/// level count. The `Arc` held here keeps its address from being reused
/// by another texture.
pub struct Textures {
    uploaded: Vec<(Arc<Texture>, i32, i32)>,
    texels: glow::Buffer,
    levels: glow::Buffer,
}

impl Textures {
    pub unsafe fn new(gl: &glow::Context) -> Result<Textures, String> {
        unsafe {
            let t = Textures { uploaded: Vec::new(), texels: gl.create_buffer()?, levels: gl.create_buffer()? };
            t.upload(gl)?;
            Ok(t)
        }
    }

    /// Makes the buffers hold exactly `keep` (a scene loaded or edited
    /// since: rebuilt whole) and binds them.
    pub unsafe fn prepare(&mut self, gl: &glow::Context, keep: &[&Arc<Texture>]) -> Result<(), String> {
        let same = self.uploaded.len() == keep.len() && self.uploaded.iter().zip(keep).all(|((u, _, _), k)| Arc::ptr_eq(u, k));
        if !same {
            let mut first = 0;
            self.uploaded = keep
                .iter()
                .map(|t| {
                    let entry = ((*t).clone(), first, t.levels.len() as i32);
                    first += t.levels.len() as i32;
                    entry
                })
                .collect();
            unsafe { self.upload(gl)? };
        }
        unsafe {
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, TEXEL_BINDING, Some(self.texels));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, LEVEL_BINDING, Some(self.levels));
        }
        Ok(())
    }

    /// `t`'s (first level, level count) for the shaders' `ivec2` texture
    /// uniforms; (0, 0) when it is not uploaded.
    pub fn handle(&self, t: &Arc<Texture>) -> (i32, i32) {
        self.uploaded.iter().find(|(u, _, _)| Arc::ptr_eq(u, t)).map_or((0, 0), |&(_, first, count)| (first, count))
    }

    unsafe fn upload(&self, gl: &glow::Context) -> Result<(), String> {
        let mut texels: Vec<f32> = Vec::new();
        let mut levels: Vec<i32> = Vec::new();
        for (t, _, _) in &self.uploaded {
            for l in &t.levels {
                levels.extend_from_slice(&[(texels.len() / 3) as i32, l.width as i32, l.height as i32, 0]);
                // Row 0 (the top) first, as `MipLevel::texels` holds them.
                for c in &l.texels {
                    texels.extend_from_slice(&[c.x, c.y, c.z]);
                }
            }
        }
        if texels.len() / 3 > i32::MAX as usize / 3 {
            return Err("the scene's textures are too large for the opengl renderer's texel buffer".into());
        }
        // GL refuses empty buffers as storage blocks.
        if texels.is_empty() {
            texels.resize(3, 0.0);
        }
        if levels.is_empty() {
            levels.resize(4, 0);
        }
        unsafe {
            let max = gl.get_parameter_i64(glow::MAX_SHADER_STORAGE_BLOCK_SIZE);
            if (texels.len() * 4) as i64 > max {
                return Err(format!("the scene's textures take {} MB, more than the driver's {} MB storage buffers", texels.len() * 4 >> 20, max >> 20));
            }
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.texels));
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, bytemuck::cast_slice(&texels), glow::STATIC_DRAW);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.levels));
            let level_bytes = std::slice::from_raw_parts(levels.as_ptr().cast::<u8>(), std::mem::size_of_val(levels.as_slice()));
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, level_bytes, glow::STATIC_DRAW);
        }
        Ok(())
    }
}
