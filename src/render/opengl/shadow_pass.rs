//! `--shadows map` in GL: every light's shadow map drawn by GL from the
//! light's own cameras (`shadow_map::light_views`, the CPU maps' cameras:
//! six 90-degree faces per point light, one orthographic rectangle fitted to
//! the casters per directional light) into the layers of an R32F texture
//! array, storing what the CPU maps store (distance from the light, or depth
//! along its direction). One-sided triangles are drawn only where they face
//! away from the light, as the CPU maps draw them. Each area light gets a
//! cube map from its centre without its own surfaces, as the CPU draws it
//! (`shadow_map::cube_views`). The fragment shaders look the maps up as
//! `ShadowMaps::occluder` and `ShadowMaps::area_light_visibility` do
//! (`shaders`, `shadowed` and `area_visibility`).

use crate::render::opengl::shaders::{self, compile};
use crate::render::shadow::map::{cube_views, light_views};
use crate::render::RenderSettings;
use crate::scene::{CameraView, Light, Scene};
use glow::HasContext;

/// The key of the maps drawn and each light's and area light's first face.
type Drawn = (u64, Vec<Light>, Vec<(u32, crate::math::Vec3)>, u32, FirstFaces);

/// Each light's first face (-1: no map), then each area light's.
pub type FirstFaces = (Vec<i32>, Vec<i32>);

pub struct ShadowPass {
    triangles: glow::Program,
    spheres: glow::Program,
    framebuffer: glow::Framebuffer,
    face_buffer: glow::Buffer,
    /// The texture array and its depth buffer: (size, layers).
    storage: Option<(u32, u32, glow::Texture, glow::Renderbuffer)>,
    /// What the maps in `storage` were drawn for: geometry, lights, area
    /// lights (object and centre), size; and each light's and each area
    /// light's first face.
    drawn: Option<Drawn>,
}

impl ShadowPass {
    pub unsafe fn new(gl: &glow::Context) -> Result<ShadowPass, String> {
        unsafe {
            Ok(ShadowPass {
                triangles: compile(gl, shaders::SHADOW_VERTEX, shaders::SHADOW_FRAGMENT)?,
                spheres: compile(gl, shaders::SHADOW_SPHERE_VERTEX, shaders::SHADOW_SPHERE_FRAGMENT)?,
                framebuffer: gl.create_framebuffer()?,
                face_buffer: gl.create_buffer()?,
                storage: None,
                drawn: None,
            })
        }
    }

    /// Draws the maps unless those of the same geometry (`key`), lights,
    /// area lights and size are there; returns each light's and each area
    /// light's first face (-1: no map).
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn draw(
        &mut self,
        gl: &glow::Context,
        clip_control: crate::render::opengl::context::ClipControl,
        scene: &Scene,
        key: u64,
        runs: &[crate::render::opengl::scene_data::Run],
        size: u32,
        vertex_array: glow::VertexArray,
        cube_array: glow::VertexArray,
    ) -> Result<FirstFaces, String> {
        let areas: Vec<(u32, crate::math::Vec3)> = scene.emitters.lights.iter().map(|l| (l.object, l.centre)).collect();
        if let Some((k, lights, a, s, first)) = &self.drawn {
            if *k == key && *lights == scene.lights && *a == areas && *s == size {
                return Ok(first.clone());
            }
        }
        // (camera, orthographic, the object whose surfaces are left out)
        let mut faces: Vec<(CameraView, bool, Option<u32>)> = Vec::new();
        let mut first = Vec::new();
        for light in &scene.lights {
            let views = light_views(scene, light, size);
            first.push(if views.is_empty() { -1 } else { faces.len() as i32 });
            let ortho = matches!(light, Light::Directional { .. });
            faces.extend(views.into_iter().map(|v| (v, ortho, None)));
        }
        let mut first_area = Vec::new();
        for &(object, centre) in &areas {
            let views = cube_views(scene, centre, size);
            first_area.push(if views.len() == 6 { faces.len() as i32 } else { -1 });
            if views.len() == 6 {
                faces.extend(views.into_iter().map(|v| (v, false, Some(object))));
            }
        }
        // Per area light's object: the runs' triangles without that object's.
        let without = |object: u32| -> Vec<(u32, u32, bool)> {
            let mut out: Vec<(u32, u32, bool)> = Vec::new();
            for run in runs {
                for i in run.first..run.first + run.count {
                    if scene.triangles.at(i as usize).object == object {
                        continue;
                    }
                    match out.last_mut() {
                        Some(last) if last.0 + last.1 == i && last.2 == run.two_sided => last.1 += 1,
                        _ => out.push((i, 1, run.two_sided)),
                    }
                }
            }
            out
        };
        let all: Vec<(u32, u32, bool)> = runs.iter().map(|r| (r.first, r.count, r.two_sided)).collect();
        unsafe {
            let layers = (faces.len() as u32).max(1);
            if self.storage.is_none_or(|(s, l, _, _)| (s, l) != (size, layers)) {
                if let Some((_, _, t, d)) = self.storage.take() {
                    gl.delete_texture(t);
                    gl.delete_renderbuffer(d);
                }
                let texture = gl.create_texture()?;
                gl.bind_texture(glow::TEXTURE_2D_ARRAY, Some(texture));
                gl.tex_storage_3d(glow::TEXTURE_2D_ARRAY, 1, glow::R32F, size as i32, size as i32, layers as i32);
                let depth = gl.create_renderbuffer()?;
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
                gl.renderbuffer_storage(glow::RENDERBUFFER, glow::DEPTH_COMPONENT32F, size as i32, size as i32);
                self.storage = Some((size, layers, texture, depth));
            }
            let (_, _, texture, depth) = self.storage.expect("allocated above");
            // Per face: (eye, half_x), (half_y, ortho, 0, 0), the rows of world-to-camera.
            let mut data = Vec::with_capacity(faces.len().max(1) * 20);
            for (v, ortho, _) in &faces {
                let c = v.camera_to_world;
                data.extend_from_slice(&[v.eye.x, v.eye.y, v.eye.z, v.half_x, v.half_y, *ortho as u32 as f32, 0.0, 0.0]);
                for axis in [c.x_axis, c.y_axis, c.z_axis] {
                    data.extend_from_slice(&[axis.x, axis.y, axis.z, 0.0]);
                }
            }
            if data.is_empty() {
                data.resize(20, 0.0);
            }
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.face_buffer));
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, bytemuck::cast_slice(&data), glow::DYNAMIC_DRAW);

            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.framebuffer));
            gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, glow::DEPTH_ATTACHMENT, glow::RENDERBUFFER, Some(depth));
            gl.viewport(0, 0, size as i32, size as i32);
            gl.disable(glow::SCISSOR_TEST);
            (clip_control)(glow::LOWER_LEFT, glow::ZERO_TO_ONE);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::GREATER);
            gl.depth_mask(true);
            gl.front_face(glow::CCW);
            let bounds = scene.bounds();
            let mut skipped: Option<(u32, Vec<(u32, u32, bool)>)> = None;
            for (i, (view, ortho, skip)) in faces.iter().enumerate() {
                gl.framebuffer_texture_layer(glow::FRAMEBUFFER, glow::COLOR_ATTACHMENT0, Some(texture), 0, i as i32);
                let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
                if status != glow::FRAMEBUFFER_COMPLETE {
                    return Err(format!("the driver cannot draw a {size}x{size} shadow map (status {status:#x})"));
                }
                gl.clear_buffer_f32_slice(glow::COLOR, 0, &[f32::INFINITY, 0.0, 0.0, 0.0]);
                gl.clear_buffer_f32_slice(glow::DEPTH, 0, &[0.0]);
                // Orthographic: the depths of the scene's box, with a margin.
                let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
                if let Some((a, b)) = bounds {
                    for k in 0..8 {
                        let corner = crate::math::Vec3::new(if k & 1 == 0 { a.x } else { b.x }, if k & 2 == 0 { a.y } else { b.y }, if k & 4 == 0 { a.z } else { b.z });
                        let d = view.view_depth(corner);
                        lo = lo.min(d);
                        hi = hi.max(d);
                    }
                }
                let margin = (hi - lo).abs() * 1e-3 + 1e-6;
                let range = if lo.is_finite() && hi.is_finite() { (lo - margin, hi + margin) } else { (-1.0, 1.0) };
                for program in [self.triangles, self.spheres] {
                    gl.use_program(Some(program));
                    let at = |name: &str| gl.get_uniform_location(program, name);
                    gl.uniform_3_f32(at("eye").as_ref(), view.eye.x, view.eye.y, view.eye.z);
                    gl.uniform_matrix_3_f32_slice(at("world_to_camera").as_ref(), false, &view.world_to_camera.to_cols_array());
                    gl.uniform_matrix_3_f32_slice(at("camera_to_world").as_ref(), false, &view.camera_to_world.to_cols_array());
                    gl.uniform_2_f32(at("half_extent").as_ref(), view.half_x, view.half_y);
                    gl.uniform_1_i32(at("ortho").as_ref(), *ortho as i32);
                    gl.uniform_1_f32(at("near_plane").as_ref(), if *ortho { 1.0 } else { view.near });
                    gl.uniform_2_f32(at("depth_range").as_ref(), range.0, range.1);
                    gl.uniform_1_f32(at("map_size").as_ref(), size as f32);
                    gl.uniform_1_i32(at("skip_object").as_ref(), skip.map_or(-1, |o| o as i32));
                }
                let drawn_runs = match skip {
                    None => &all,
                    Some(o) => {
                        if skipped.as_ref().is_none_or(|(so, _)| so != o) {
                            skipped = Some((*o, without(*o)));
                        }
                        &skipped.as_ref().expect("made above").1
                    }
                };
                gl.use_program(Some(self.triangles));
                gl.bind_vertex_array(Some(vertex_array));
                for &(start, count, two_sided) in drawn_runs {
                    if two_sided {
                        gl.disable(glow::CULL_FACE);
                    } else {
                        // What a shadow ray meets: one-sided triangles facing away from the light.
                        gl.enable(glow::CULL_FACE);
                        gl.cull_face(glow::FRONT);
                    }
                    gl.draw_arrays(glow::TRIANGLES, (start * 3) as i32, (count * 3) as i32);
                }
                if !scene.spheres.is_empty() {
                    gl.disable(glow::CULL_FACE);
                    gl.enable(glow::DEPTH_CLAMP);
                    gl.use_program(Some(self.spheres));
                    gl.bind_vertex_array(Some(cube_array));
                    gl.draw_arrays_instanced(glow::TRIANGLES, 0, 36, scene.spheres.len() as i32);
                    gl.disable(glow::DEPTH_CLAMP);
                }
            }
            gl.cull_face(glow::BACK);
            gl.bind_vertex_array(None);
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
        let first = (first, first_area);
        self.drawn = Some((key, scene.lights.clone(), areas, size, first.clone()));
        Ok(first)
    }

    /// Binds the maps (texture unit 0) and their faces (storage binding 3).
    pub unsafe fn bind_for_lookup(&self, gl: &glow::Context) {
        unsafe {
            gl.active_texture(glow::TEXTURE0);
            gl.bind_texture(glow::TEXTURE_2D_ARRAY, self.storage.map(|s| s.2));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 3, Some(self.face_buffer));
        }
    }

    /// The lookup's uniforms in `program` (current).
    pub unsafe fn lookup_uniforms(&self, gl: &glow::Context, program: glow::Program, settings: &RenderSettings) {
        unsafe {
            let at = |name: &str| gl.get_uniform_location(program, name);
            gl.uniform_1_i32(at("shadow_maps").as_ref(), 0);
            gl.uniform_1_f32(at("map_size").as_ref(), self.storage.map_or(1, |s| s.0) as f32);
            gl.uniform_1_f32(at("map_bias").as_ref(), settings.shadow_map_bias);
            gl.uniform_1_i32(at("slope_bias").as_ref(), settings.shadow_map_slope_bias as i32);
        }
    }
}
