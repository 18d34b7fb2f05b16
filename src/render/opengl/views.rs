//! What each fragment saw, read back from the pass's extra render targets
//! (`VIEWS` in `shaders`): the surface record GL interpolated, turned into
//! a `SurfaceHit` so that the debug views are coloured by the CPU
//! renderers' own `debug::view_color`, and a clicked pixel can be reported.

use crate::math::{Radiance, Vec2, Vec3};
use crate::render::inspect::debug;
use crate::render::PassJob;
use crate::scene::{Differentials, PrimitiveKind, Scene, SurfaceHit};
use glow::HasContext;

/// The render targets after the colour: five RGBA32F, then one RGBA32UI.
pub const FLOAT_TARGETS: usize = 5;
pub const TARGETS: usize = FLOAT_TARGETS + 1;

/// The debug views GL can draw: those coloured from the surface record alone.
pub fn drawable(view: debug::View) -> bool {
    use debug::View::*;
    matches!(view, Barycentric | Raydir | Depth | Zbuffer | Normal | GeometricNormal | Id | TriangleId | MaterialId | Uv)
}

/// The surface targets of `rows` GL rows from `first_gl_row`, `width` wide.
pub struct Readback {
    width: usize,
    floats: Vec<Vec<f32>>,
    ids: Vec<u32>,
}

impl Readback {
    /// Reads the targets of the framebuffer bound for reading.
    pub unsafe fn read(gl: &glow::Context, first_gl_row: u32, width: u32, rows: u32) -> Readback {
        let n = width as usize * rows as usize * 4;
        let mut floats = Vec::with_capacity(FLOAT_TARGETS);
        let mut ids = vec![0u32; n];
        unsafe {
            for i in 0..FLOAT_TARGETS {
                let mut buf = vec![0f32; n];
                gl.read_buffer(glow::COLOR_ATTACHMENT1 + i as u32);
                gl.read_pixels(
                    0,
                    first_gl_row as i32,
                    width as i32,
                    rows as i32,
                    glow::RGBA,
                    glow::FLOAT,
                    glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut buf))),
                );
                floats.push(buf);
            }
            gl.read_buffer(glow::COLOR_ATTACHMENT0 + TARGETS as u32);
            // SAFETY: u32 has no padding and u8 has alignment 1.
            let id_bytes = std::slice::from_raw_parts_mut(ids.as_mut_ptr().cast::<u8>(), n * 4);
            gl.read_pixels(
                0,
                first_gl_row as i32,
                width as i32,
                rows as i32,
                glow::RGBA_INTEGER,
                glow::UNSIGNED_INT,
                glow::PixelPackData::Slice(Some(id_bytes)),
            );
            gl.read_buffer(glow::COLOR_ATTACHMENT0);
        }
        Readback { width: width as usize, floats, ids }
    }

    /// The surface GL drew at row `r` (of those read, in GL's order) and
    /// column `x`; `None` where nothing was drawn or the record is not
    /// finite or names no primitive of `scene`.
    pub fn hit(&self, scene: &Scene, r: usize, x: usize) -> Option<SurfaceHit> {
        let i = (r * self.width + x) * 4;
        let v = |t: usize| Vec3::new(self.floats[t][i], self.floats[t][i + 1], self.floats[t][i + 2]);
        let (kind, primitive) = (self.ids[i], self.ids[i + 1]);
        let (kind, object, material) = match kind {
            1 => {
                if primitive as u64 >= scene.total_triangles() {
                    return None;
                }
                let t = scene.triangle(primitive);
                (PrimitiveKind::Triangle, t.object, t.material)
            }
            2 => {
                let s = scene.spheres.get(primitive as usize)?;
                (PrimitiveKind::Sphere, s.object, s.material)
            }
            3 => {
                let c = scene.csgs.get(primitive as usize)?;
                (PrimitiveKind::Csg, c.object, self.ids[i + 2])
            }
            _ => return None,
        };
        let position = v(0);
        let (n, g, b) = (v(1), v(2), v(3));
        let uv = Vec2::new(self.floats[4][i], self.floats[4][i + 1]);
        if !(position.is_finite() && n.is_finite() && g.is_finite() && b.is_finite() && uv.is_finite()) {
            return None;
        }
        Some(SurfaceHit {
            position,
            geometric_normal: g,
            shading_normal: n,
            barycentric: b,
            uv,
            t: 0.0,
            kind,
            primitive,
            object,
            material,
            back_face: self.floats[1][i + 3] != 0.0,
            diff: Differentials::ZERO,
        })
    }
}

/// The debug view's colour of pixel `(x, y)` (image rows, top-down) from
/// the surface GL drew there, as the CPU renderers colour it.
pub fn colour(job: &PassJob, hit: Option<&SurfaceHit>, x: u32, y: u32) -> Radiance {
    let ray = job.view.eye_ray(x as f32 + job.offset.x, y as f32 + job.offset.y);
    let hit = hit.map(|h| SurfaceHit { t: (h.position - ray.origin).length(), ..*h });
    let c = debug::view_color(job.settings.view, job.view, &ray, hit.as_ref());
    if c.is_finite() { c } else { Vec3::ZERO }
}
