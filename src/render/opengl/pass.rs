//! One sample pass through GL: the programs and buffers kept in the
//! context between passes, the pass drawn into a float framebuffer, read
//! back and flipped into the frame's row order.

use crate::render::opengl::context::Gl;
use crate::render::opengl::scene_data;
use crate::render::opengl::shaders;
use crate::math::{Radiance, Vec3};
use crate::render::{Interpolation, PassJob, RayCounts, Reflections, ShadowMode};
use crate::scene::texture::{TextureFilter, Wrap};
use glow::HasContext;

/// What lives in the context between passes.
pub struct State {
    /// The triangle and sphere programs, compiled on first use for each set
    /// of defines (shadow-map lookups, multisampling).
    programs: Vec<(String, Programs)>,
    background: glow::Program,
    maps: crate::render::opengl::shadow_pass::ShadowPass,
    textures: crate::render::opengl::textures::Textures,
    vertex_array: glow::VertexArray,
    vertex_buffer: glow::Buffer,
    cube_array: glow::VertexArray,
    sphere_buffer: glow::Buffer,
    material_buffer: glow::Buffer,
    light_buffer: glow::Buffer,
    /// The area lights and their pattern of points (`scene_data::area_lights`).
    area_light_buffer: glow::Buffer,
    area_point_buffer: glow::Buffer,
    /// The environment light's directions (`scene_data::environment_light`).
    environment_buffer: glow::Buffer,
    /// The uploaded geometry: its fingerprint, triangle runs, sphere count.
    uploaded: Option<(u64, Vec<scene_data::Run>, usize)>,
    /// The two-level layer's shared meshes (`scene_data::layer_geometry`)
    /// and the copies' placements, one instance each.
    layer_array: glow::VertexArray,
    layer_buffer: glow::Buffer,
    instance_buffer: glow::Buffer,
    /// The layer uploaded (held, so its address names it) and each mesh's
    /// first triangle and runs.
    layer: Option<(std::sync::Arc<crate::scene::instanced::InstanceLayer>, Vec<(u32, Vec<scene_data::Run>)>)>,
    /// The CSG objects' buffers (`csg_data`: objects, nodes, spheres,
    /// triangles at bindings 6 to 9) and what they hold.
    csg_buffers: [glow::Buffer; 4],
    csg_uploaded: Option<crate::render::opengl::csg_data::CsgData>,
    target: Option<Target>,
}

/// The programs compiled for one set of defines: triangles, spheres, and
/// the layer's copies (triangles placed per instance).
#[derive(Clone, Copy)]
struct Programs {
    triangles: glow::Program,
    spheres: glow::Program,
    copies: glow::Program,
    csg: glow::Program,
}

/// Sets the triangle vertex layout (`scene_data::VERTEX_FLOATS`) on the
/// bound vertex array, reading the bound array buffer.
unsafe fn vertex_layout(gl: &glow::Context) {
    let stride = (scene_data::VERTEX_FLOATS * 4) as i32;
    unsafe {
        for (location, offset) in [(0u32, 0i32), (1, 12), (2, 24)] {
            gl.enable_vertex_attrib_array(location);
            gl.vertex_attrib_pointer_f32(location, 3, glow::FLOAT, false, stride, offset);
        }
        gl.enable_vertex_attrib_array(3);
        gl.vertex_attrib_pointer_i32(3, 1, glow::UNSIGNED_INT, stride, 36);
        gl.enable_vertex_attrib_array(4);
        gl.vertex_attrib_pointer_f32(4, 2, glow::FLOAT, false, stride, 40);
        gl.enable_vertex_attrib_array(5);
        gl.vertex_attrib_pointer_f32(5, 4, glow::FLOAT, false, stride, 48);
    }
}

/// The framebuffer a pass draws into: RGBA32F colour and a 32-bit float
/// depth; with `--msaa` a multisampled one beside it, resolved into the first.
struct Target {
    width: u32,
    height: u32,
    samples: u32,
    framebuffer: glow::Framebuffer,
    colour: glow::Texture,
    depth: glow::Renderbuffer,
    multisampled: Option<(glow::Framebuffer, glow::Renderbuffer, glow::Renderbuffer)>,
    /// With a debug view: the surface targets (`views`), attachments 1 and up.
    surfaces: Vec<glow::Texture>,
}

impl State {
    unsafe fn new(gl: &glow::Context) -> Result<State, String> {
        unsafe {
            let background = shaders::compile(gl, shaders::BACKGROUND_VERTEX, &shaders::background_fragment())?;
            let maps = crate::render::opengl::shadow_pass::ShadowPass::new(gl)?;
            let vertex_array = gl.create_vertex_array()?;
            let vertex_buffer = gl.create_buffer()?;
            gl.bind_vertex_array(Some(vertex_array));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(vertex_buffer));
            vertex_layout(gl);
            let layer_array = gl.create_vertex_array()?;
            let layer_buffer = gl.create_buffer()?;
            let instance_buffer = gl.create_buffer()?;
            gl.bind_vertex_array(Some(layer_array));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(layer_buffer));
            vertex_layout(gl);
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(instance_buffer));
            let stride = (scene_data::INSTANCE_FLOATS * 4) as i32;
            for location in 6..13u32 {
                gl.enable_vertex_attrib_array(location);
                gl.vertex_attrib_pointer_f32(location, 3, glow::FLOAT, false, stride, (location as i32 - 6) * 12);
                gl.vertex_attrib_divisor(location, 1);
            }
            gl.enable_vertex_attrib_array(13);
            gl.vertex_attrib_pointer_i32(13, 3, glow::UNSIGNED_INT, stride, 84);
            gl.vertex_attrib_divisor(13, 1);
            let cube_array = gl.create_vertex_array()?;
            let cube_buffer = gl.create_buffer()?;
            gl.bind_vertex_array(Some(cube_array));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(cube_buffer));
            gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, bytemuck::cast_slice(&scene_data::cube_corners()), glow::STATIC_DRAW);
            gl.enable_vertex_attrib_array(0);
            gl.vertex_attrib_pointer_f32(0, 3, glow::FLOAT, false, 12, 0);
            gl.bind_vertex_array(None);
            Ok(State {
                programs: Vec::new(),
                background,
                maps,
                textures: crate::render::opengl::textures::Textures::new(gl)?,
                vertex_array,
                vertex_buffer,
                cube_array,
                sphere_buffer: gl.create_buffer()?,
                material_buffer: gl.create_buffer()?,
                light_buffer: gl.create_buffer()?,
                area_light_buffer: gl.create_buffer()?,
                area_point_buffer: gl.create_buffer()?,
                environment_buffer: gl.create_buffer()?,
                uploaded: None,
                layer_array,
                layer_buffer,
                instance_buffer,
                layer: None,
                csg_buffers: [gl.create_buffer()?, gl.create_buffer()?, gl.create_buffer()?, gl.create_buffer()?],
                csg_uploaded: None,
                target: None,
            })
        }
    }

    /// The programs compiled with `defines`.
    unsafe fn programs(&mut self, gl: &glow::Context, defines: &str) -> Result<Programs, String> {
        if let Some((_, p)) = self.programs.iter().find(|p| p.0 == defines) {
            return Ok(*p);
        }
        unsafe {
            let fragment = shaders::triangle_fragment(defines);
            let p = Programs {
                triangles: shaders::compile(gl, &shaders::triangle_vertex(defines), &fragment)?,
                spheres: shaders::compile(gl, shaders::SPHERE_VERTEX, &shaders::sphere_fragment(defines))?,
                copies: shaders::compile(gl, &shaders::triangle_vertex(&format!("{defines}#define INSTANCED 1\n")), &fragment)?,
                csg: shaders::compile(gl, shaders::CSG_VERTEX, &shaders::csg_fragment(defines))?,
            };
            self.programs.push((defines.to_string(), p));
            Ok(p)
        }
    }

    /// Uploads the layer's shared meshes unless they are there already;
    /// returns each mesh's first triangle and runs.
    unsafe fn upload_layer(&mut self, gl: &glow::Context, layer: &std::sync::Arc<crate::scene::instanced::InstanceLayer>) -> Vec<(u32, Vec<scene_data::Run>)> {
        if let Some((l, meshes)) = &self.layer {
            if std::sync::Arc::ptr_eq(l, layer) {
                return meshes.clone();
            }
        }
        let g = scene_data::layer_geometry(layer);
        unsafe {
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.layer_buffer));
            gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, bytemuck::cast_slice(&g.vertices), glow::STATIC_DRAW);
        }
        self.layer = Some((layer.clone(), g.meshes.clone()));
        g.meshes
    }

    /// The framebuffer to draw into and the one to read from (the same
    /// without multisampling).
    unsafe fn target(&mut self, gl: &glow::Context, width: u32, height: u32, samples: u32, views: bool) -> Result<(glow::Framebuffer, glow::Framebuffer), String> {
        unsafe {
            if let Some(t) = &self.target {
                if (t.width, t.height, t.samples, !t.surfaces.is_empty()) == (width, height, samples, views) {
                    return Ok((t.multisampled.map_or(t.framebuffer, |m| m.0), t.framebuffer));
                }
                gl.delete_framebuffer(t.framebuffer);
                gl.delete_texture(t.colour);
                gl.delete_renderbuffer(t.depth);
                if let Some((f, c, d)) = t.multisampled {
                    gl.delete_framebuffer(f);
                    gl.delete_renderbuffer(c);
                    gl.delete_renderbuffer(d);
                }
                for &s in &t.surfaces {
                    gl.delete_texture(s);
                }
                self.target = None;
            }
            let framebuffer = gl.create_framebuffer()?;
            let colour = gl.create_texture()?;
            let depth = gl.create_renderbuffer()?;
            gl.bind_texture(glow::TEXTURE_2D, Some(colour));
            gl.tex_storage_2d(glow::TEXTURE_2D, 1, glow::RGBA32F, width as i32, height as i32);
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
            gl.renderbuffer_storage(glow::RENDERBUFFER, glow::DEPTH_COMPONENT32F, width as i32, height as i32);
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(framebuffer));
            gl.framebuffer_texture_2d(glow::FRAMEBUFFER, glow::COLOR_ATTACHMENT0, glow::TEXTURE_2D, Some(colour), 0);
            gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, glow::DEPTH_ATTACHMENT, glow::RENDERBUFFER, Some(depth));
            let mut surfaces = Vec::new();
            if views {
                for i in 0..crate::render::opengl::views::TARGETS {
                    let t = gl.create_texture()?;
                    let format = if i < crate::render::opengl::views::FLOAT_TARGETS { glow::RGBA32F } else { glow::RGBA32UI };
                    gl.bind_texture(glow::TEXTURE_2D, Some(t));
                    gl.tex_storage_2d(glow::TEXTURE_2D, 1, format, width as i32, height as i32);
                    gl.framebuffer_texture_2d(glow::FRAMEBUFFER, glow::COLOR_ATTACHMENT1 + i as u32, glow::TEXTURE_2D, Some(t), 0);
                    surfaces.push(t);
                }
            }
            let mut status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            let mut multisampled = None;
            if samples > 1 && status == glow::FRAMEBUFFER_COMPLETE {
                let f = gl.create_framebuffer()?;
                let c = gl.create_renderbuffer()?;
                let d = gl.create_renderbuffer()?;
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(c));
                gl.renderbuffer_storage_multisample(glow::RENDERBUFFER, samples as i32, glow::RGBA32F, width as i32, height as i32);
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(d));
                gl.renderbuffer_storage_multisample(glow::RENDERBUFFER, samples as i32, glow::DEPTH_COMPONENT32F, width as i32, height as i32);
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(f));
                gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, glow::COLOR_ATTACHMENT0, glow::RENDERBUFFER, Some(c));
                gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, glow::DEPTH_ATTACHMENT, glow::RENDERBUFFER, Some(d));
                status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
                multisampled = Some((f, c, d));
            }
            let t = Target { width, height, samples, framebuffer, colour, depth, multisampled, surfaces };
            let draw = (t.multisampled.map_or(t.framebuffer, |m| m.0), t.framebuffer);
            self.target = Some(t);
            if status != glow::FRAMEBUFFER_COMPLETE {
                return Err(format!("the driver cannot draw into a {width}x{height} float framebuffer with {samples} samples (status {status:#x})"));
            }
            Ok(draw)
        }
    }

    /// Uploads the geometry unless the same is there already.
    unsafe fn upload(&mut self, gl: &glow::Context, scene: &crate::scene::Scene) {
        let key = scene_data::fingerprint(scene);
        if self.uploaded.as_ref().is_some_and(|u| u.0 == key) {
            return;
        }
        let g = scene_data::geometry(scene);
        unsafe {
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.vertex_buffer));
            gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, bytemuck::cast_slice(&g.vertices), glow::STATIC_DRAW);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.sphere_buffer));
            let spheres = if g.spheres.is_empty() { vec![0.0; 8] } else { g.spheres };
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, bytemuck::cast_slice(&spheres), glow::STATIC_DRAW);
        }
        self.uploaded = Some((key, g.runs, scene.spheres.len()));
    }
}

/// Sets the uniforms both programs share.
/// `environment`: the environment's texture handle (`Textures::handle`).
unsafe fn uniforms(gl: &glow::Context, program: glow::Program, job: &PassJob, environment: (i32, i32)) {
    let view = job.view;
    let scene = &job.prepared.scene;
    let (w, h) = (view.width as f32, view.height as f32);
    unsafe {
        let at = |name: &str| gl.get_uniform_location(program, name);
        gl.uniform_3_f32(at("eye").as_ref(), view.eye.x, view.eye.y, view.eye.z);
        gl.uniform_matrix_3_f32_slice(at("camera_to_world").as_ref(), false, &view.camera_to_world.to_cols_array());
        gl.uniform_matrix_3_f32_slice(at("world_to_camera").as_ref(), false, &view.world_to_camera.to_cols_array());
        gl.uniform_2_f32(at("half_extent").as_ref(), view.half_x, view.half_y);
        gl.uniform_2_f32(at("image_size").as_ref(), w, h);
        gl.uniform_2_f32(at("sample_offset").as_ref(), job.offset.x, job.offset.y);
        // GL samples at pixel centres: shift the image by the pass's offset from them.
        gl.uniform_2_f32(at("ndc_shift").as_ref(), (0.5 - job.offset.x) * 2.0 / w, (job.offset.y - 0.5) * 2.0 / h);
        gl.uniform_1_f32(at("near_plane").as_ref(), view.near);
        gl.uniform_1_f32(at("far_plane").as_ref(), view.far);
        gl.uniform_1_i32(at("orthographic").as_ref(), view.is_orthographic() as i32);
        let a = scene.render.ambient;
        gl.uniform_3_f32(at("ambient").as_ref(), a.x, a.y, a.z);
        gl.uniform_1_i32(at("light_count").as_ref(), scene.lights.len() as i32);
        gl.uniform_1_i32(at("area_light_count").as_ref(), scene.emitters.lights.len() as i32);
        let filter = match job.settings.shadow_filter {
            crate::render::shadow::ShadowFilter::None => 0,
            crate::render::shadow::ShadowFilter::Pcf => 1,
            crate::render::shadow::ShadowFilter::Pcss => 2,
        };
        gl.uniform_1_i32(at("shadow_filter").as_ref(), filter);
        gl.uniform_1_f32(at("pcf_radius").as_ref(), job.settings.pcf_radius);
        gl.uniform_1_i32(at("flat_shading").as_ref(), (job.settings.interpolation == Interpolation::Flat) as i32);
        gl.uniform_1_i32(at("y_down").as_ref(), (job.settings.msaa > 1) as i32);
        let bg = scene.render.background;
        gl.uniform_3_f32(at("background").as_ref(), bg.x, bg.y, bg.z);
        gl.uniform_1_i32(at("has_environment").as_ref(), scene.environment.is_some() as i32);
        gl.uniform_1_f32(at("environment_intensity").as_ref(), scene.environment.as_ref().map_or(0.0, |e| e.intensity));
        gl.uniform_1_i32(at("mirror_env").as_ref(), (job.settings.reflections == Reflections::Env && job.settings.max_depth > 0) as i32);
        let (first, count) = environment;
        gl.uniform_2_i32(at("environment").as_ref(), first, count);
    }
}

/// Sets what the fragment shader reads of material `m`'s texture and
/// normal map.
unsafe fn material_textures(gl: &glow::Context, textures: &crate::render::opengl::textures::Textures, program: glow::Program, job: &PassJob, m: u32) {
    let Some(material) = job.prepared.scene.materials.get(m as usize) else { return };
    unsafe {
        let at = |name: &str| gl.get_uniform_location(program, name);
        for (map, name, flag) in [(&material.texture, "albedo_map", "has_albedo_map"), (&material.normal_map, "normal_map", "has_normal_map")] {
            let (first, count) = map.as_ref().map_or((0, 0), |t| textures.handle(t));
            gl.uniform_2_i32(at(name).as_ref(), first, count);
            gl.uniform_1_i32(at(flag).as_ref(), (count > 0) as i32);
        }
        let chosen = job.settings.texture_filter.at_most(material.finest_filter);
        let filter = match chosen {
            TextureFilter::Nearest => 0,
            TextureFilter::Bilinear => 1,
            TextureFilter::Trilinear => 2,
            TextureFilter::MipmapNearest => 3,
            TextureFilter::Anisotropic2 | TextureFilter::Anisotropic4 | TextureFilter::Anisotropic8 | TextureFilter::Anisotropic16 => 4,
        };
        gl.uniform_1_i32(at("texture_filter").as_ref(), filter);
        gl.uniform_1_i32(at("anisotropic_taps").as_ref(), chosen.anisotropic_taps() as i32);
        gl.uniform_1_i32(at("wrap_clamp").as_ref(), (material.wrap[0] == Wrap::Clamp) as i32);
        gl.uniform_2_f32(at("uv_scale").as_ref(), material.uv_scale.x, material.uv_scale.y);
    }
}

/// Draws `job`'s pass and stores its rows in `out`; with `probe` (a pixel
/// of the pass's rows), also returns what GL's render targets hold there.
pub fn render(g: &mut Gl<State>, job: &PassJob, out: &mut [Radiance], probe: Option<(u32, u32)>) -> Result<(RayCounts, Option<crate::render::inspect::pixel_record::GlReadback>), String> {
    let gl = &g.gl;
    let scene = &job.prepared.scene;
    let (width, height) = (job.view.width, job.view.height);
    unsafe {
        if g.state.is_none() {
            g.state = Some(State::new(gl)?);
        }
        let state = g.state.as_mut().expect("created above");
        let samples = job.settings.msaa.max(1);
        let views = job.settings.view != crate::render::inspect::debug::View::Shaded || probe.is_some();
        let view_colours = job.settings.view != crate::render::inspect::debug::View::Shaded;
        let (framebuffer, resolved) = state.target(gl, width, height, samples, views)?;
        state.upload(gl, scene);
        let keep: Vec<_> = scene
            .materials
            .iter()
            .flat_map(|m| [m.texture.as_ref(), m.normal_map.as_ref()])
            .chain([scene.environment.as_ref().map(|e| &e.texture)])
            .flatten()
            .collect();
        state.textures.prepare(gl, &keep)?;
        let environment = scene.environment.as_ref().map_or((0, 0), |e| state.textures.handle(&e.texture));
        gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 2, Some(state.sphere_buffer));
        let mapped = job.settings.shadows == ShadowMode::Map;
        let (first_faces, first_area_faces) = if mapped {
            let runs = state.uploaded.as_ref().map(|u| u.1.clone()).unwrap_or_default();
            let key = state.uploaded.as_ref().map_or(0, |u| u.0);
            state.maps.draw(gl, g.clip_control, scene, key, &runs, job.settings.shadow_map_size, state.vertex_array, state.cube_array)?
        } else {
            (Vec::new(), Vec::new())
        };
        let area_lit = !scene.emitters.is_empty();
        if area_lit {
            let (lights, points) = scene_data::area_lights(scene, &first_area_faces, job.settings.light_samples, job.sample, job.settings.gi.seed);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(state.area_light_buffer));
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, bytemuck::cast_slice(&lights), glow::DYNAMIC_DRAW);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(state.area_point_buffer));
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, bytemuck::cast_slice(&points), glow::DYNAMIC_DRAW);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 10, Some(state.area_light_buffer));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 11, Some(state.area_point_buffer));
        }
        let sky_lit = scene.environment.as_ref().is_some_and(|e| e.is_light());
        if sky_lit {
            // The count first, then the directions.
            let directions = scene_data::environment_light(scene, job.settings.light_samples, job.sample, job.settings.gi.seed);
            let mut data = vec![(directions.len() / 8) as f32, 0.0, 0.0, 0.0];
            data.extend_from_slice(&directions);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(state.environment_buffer));
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, bytemuck::cast_slice(&data), glow::DYNAMIC_DRAW);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 12, Some(state.environment_buffer));
        }
        gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(state.material_buffer));
        gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, bytemuck::cast_slice(&scene_data::materials(scene)), glow::DYNAMIC_DRAW);
        gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(state.light_buffer));
        gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, bytemuck::cast_slice(&scene_data::lights(scene, &first_faces)), glow::DYNAMIC_DRAW);
        gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 0, Some(state.material_buffer));
        gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 1, Some(state.light_buffer));
        gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 2, Some(state.sphere_buffer));

        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(framebuffer));
        gl.viewport(0, 0, width as i32, height as i32);
        // With --msaa the image is drawn upside down: GL's 4-sample pattern,
        // given in its bottom-up window, then falls where pinhole's top-down
        // D3D pattern puts its samples. Windings turn round with it.
        let y_down = samples > 1;
        let rows = job.rows.start.min(height)..job.rows.end.min(height);
        // Only the rows asked for (GL rows count from the bottom).
        let first_gl_row = if y_down { rows.start } else { height - rows.end };
        gl.enable(glow::SCISSOR_TEST);
        gl.scissor(0, first_gl_row as i32, width as i32, rows.len() as i32);
        // Reversed depth in [0, 1]: 1 at the near plane, 0 at the far plane.
        (g.clip_control)(glow::LOWER_LEFT, glow::ZERO_TO_ONE);
        let bg: Vec3 = scene.render.background;
        gl.clear_buffer_f32_slice(glow::COLOR, 0, &[bg.x, bg.y, bg.z, 1.0]);
        gl.clear_buffer_f32_slice(glow::DEPTH, 0, &[0.0]);
        let all_targets: Vec<u32> = (0..=crate::render::opengl::views::TARGETS as u32).map(|i| glow::COLOR_ATTACHMENT0 + i).collect();
        if views {
            gl.draw_buffers(&all_targets);
            for i in 1..=crate::render::opengl::views::FLOAT_TARGETS as u32 {
                gl.clear_buffer_f32_slice(glow::COLOR, i, &[0.0; 4]);
            }
            gl.clear_buffer_u32_slice(glow::COLOR, crate::render::opengl::views::TARGETS as u32, &[0; 4]);
            // The background writes the colour only.
            gl.draw_buffers(&all_targets[..1]);
        }
        gl.enable(glow::DEPTH_TEST);
        gl.depth_func(glow::GREATER);
        gl.depth_mask(true);
        gl.disable(glow::BLEND);
        gl.front_face(if y_down { glow::CW } else { glow::CCW });
        gl.cull_face(glow::BACK);
        if scene.environment.is_some() {
            gl.disable(glow::DEPTH_TEST);
            gl.depth_mask(false);
            gl.use_program(Some(state.background));
            uniforms(gl, state.background, job, environment);
            gl.bind_vertex_array(Some(state.cube_array));
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_mask(true);
        }

        if views {
            gl.draw_buffers(&all_targets);
        }
        let (runs, sphere_count) = {
            let u = state.uploaded.as_ref().expect("uploaded above");
            (u.1.clone(), u.2)
        };
        let defines = format!(
            "{}{}{}{}{}",
            if mapped { "#define SHADOW_MAP 1\n" } else { "" },
            if area_lit { "#define AREA_LIGHTS 1\n" } else { "" },
            if sky_lit { "#define ENVIRONMENT_LIGHT 1\n" } else { "" },
            if samples > 1 { "#define MSAA 1\n" } else { "" },
            if views { "#define VIEWS 1\n" } else { "" }
        );
        let Programs { triangles, spheres, copies, csg } = state.programs(gl, &defines)?;
        if mapped {
            state.maps.bind_for_lookup(gl);
        }
        if !runs.is_empty() {
            gl.use_program(Some(triangles));
            uniforms(gl, triangles, job, environment);
            if mapped {
                state.maps.lookup_uniforms(gl, triangles, job.settings);
            }
            gl.bind_vertex_array(Some(state.vertex_array));
            for scene_data::Run { first, count, two_sided, material } in runs {
                material_textures(gl, &state.textures, triangles, job, material);
                if two_sided {
                    gl.disable(glow::CULL_FACE);
                } else {
                    gl.enable(glow::CULL_FACE);
                }
                gl.draw_arrays(glow::TRIANGLES, (first * 3) as i32, (count * 3) as i32);
            }
        }
        if let Some(layer) = &scene.layer {
            draw_copies(gl, state, copies, job, layer, environment, mapped, y_down);
        }
        if sphere_count > 0 {
            // Both sides of each sphere's bounding cube: whatever part of
            // the cube the near plane cuts off, the far side still covers
            // the sphere, and the fragment shader finds the exact surface.
            gl.disable(glow::CULL_FACE);
            gl.enable(glow::DEPTH_CLAMP);
            gl.use_program(Some(spheres));
            uniforms(gl, spheres, job, environment);
            if mapped {
                state.maps.lookup_uniforms(gl, spheres, job.settings);
            }
            gl.bind_vertex_array(Some(state.cube_array));
            // One draw per run of spheres sharing a material (and so its textures).
            let mut first = 0;
            while first < sphere_count {
                let m = scene.spheres[first].material;
                let count = scene.spheres[first..].iter().take_while(|s| s.material == m).count();
                material_textures(gl, &state.textures, spheres, job, m);
                gl.uniform_1_i32(gl.get_uniform_location(spheres, "first_sphere").as_ref(), first as i32);
                gl.draw_arrays_instanced(glow::TRIANGLES, 0, 36, count as i32);
                first += count;
            }
            gl.disable(glow::DEPTH_CLAMP);
        }
        if !scene.csgs.is_empty() {
            draw_csgs(gl, state, csg, job, environment)?;
        }
        gl.bind_vertex_array(None);
        if resolved != framebuffer {
            // GL's resolve: each pixel the plain mean of its samples.
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(framebuffer));
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(resolved));
            let (w, h) = (width as i32, height as i32);
            gl.blit_framebuffer(0, 0, w, h, 0, 0, w, h, glow::COLOR_BUFFER_BIT, glow::NEAREST);
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(resolved));
        }
        gl.disable(glow::SCISSOR_TEST);

        let w = width as usize;
        let mut pixels = vec![0f32; w * rows.len() * 4];
        gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
        gl.read_pixels(
            0,
            first_gl_row as i32,
            width as i32,
            rows.len() as i32,
            glow::RGBA,
            glow::FLOAT,
            glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut pixels))),
        );
        let surfaces = views.then(|| crate::render::opengl::views::Readback::read(gl, first_gl_row, width, rows.len() as u32));
        if views {
            gl.draw_buffers(&all_targets[..1]);
        }
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        gl.front_face(glow::CCW);
        let error = gl.get_error();
        if error != glow::NO_ERROR {
            return Err(format!("OpenGL reported error {error:#x} while drawing"));
        }
        // GL's rows run bottom-up: the last row read is the first asked for
        // (unless drawn upside down).
        let n = rows.len();
        for (k, y) in rows.clone().enumerate() {
            let r = if y_down { k } else { n - 1 - k };
            let src = &pixels[r * w * 4..(r + 1) * w * 4];
            for x in 0..width {
                if !job.is_active(x, y) {
                    continue;
                }
                out[k * w + x as usize] = match surfaces.as_ref().filter(|_| view_colours) {
                    Some(s) => crate::render::opengl::views::colour(job, s.hit(scene, r, x as usize).as_ref(), x, y),
                    None => {
                        let p = &src[x as usize * 4..x as usize * 4 + 3];
                        let c = Vec3::new(p[0], p[1], p[2]);
                        // Whatever the driver computed, no NaN reaches the frame.
                        if c.is_finite() { c } else { Vec3::ZERO }
                    }
                };
            }
        }
        let readback = probe.zip(surfaces.as_ref()).and_then(|((x, y), s)| {
            let k = rows.clone().position(|r| r == y)?;
            let r = if y_down { k } else { n - 1 - k };
            let surface = s.hit(scene, r, x as usize).map(|h| {
                let ray = job.view.eye_ray(x as f32 + job.offset.x, y as f32 + job.offset.y);
                crate::scene::SurfaceHit { t: (h.position - ray.origin).length(), ..h }
            });
            Some(crate::render::inspect::pixel_record::GlReadback { surface, output: *out.get(k * w + x as usize)? })
        });
        // GL counts none of this; the counters stay zero.
        Ok((RayCounts::default(), readback))
    }
}

/// Draws the CSG objects: each one's bounding box (both sides, depth
/// clamped, as the spheres' cubes), whose fragments evaluate the object
/// along their eye ray (`shaders::csg_fragment`).
unsafe fn draw_csgs(gl: &glow::Context, state: &mut State, program: glow::Program, job: &PassJob, environment: (i32, i32)) -> Result<(), String> {
    let scene = &job.prepared.scene;
    let data = crate::render::opengl::csg_data::build(&scene.csgs)?;
    unsafe {
        if state.csg_uploaded.as_ref() != Some(&data) {
            for (buffer, floats) in state.csg_buffers.iter().zip([&data.objects, &data.nodes, &data.spheres, &data.triangles]) {
                gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(*buffer));
                gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, bytemuck::cast_slice(floats), glow::STATIC_DRAW);
            }
            state.csg_uploaded = Some(data);
        }
        for (i, buffer) in state.csg_buffers.iter().enumerate() {
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 6 + i as u32, Some(*buffer));
        }
        gl.disable(glow::CULL_FACE);
        gl.enable(glow::DEPTH_CLAMP);
        gl.use_program(Some(program));
        uniforms(gl, program, job, environment);
        gl.bind_vertex_array(Some(state.cube_array));
        for i in 0..scene.csgs.len() {
            // Each surface's material is read per fragment; `check` lets
            // through untextured ones only, so no texture is bound here.
            material_textures(gl, &state.textures, program, job, u32::MAX);
            gl.uniform_1_i32(gl.get_uniform_location(program, "csg_object").as_ref(), i as i32);
            gl.draw_arrays(glow::TRIANGLES, 0, 36);
        }
        gl.disable(glow::DEPTH_CLAMP);
    }
    Ok(())
}

/// Draws the two-level layer's copies: each shared mesh once in GL's
/// buffers, the copies left after culling each by its bounding sphere
/// (`raster::cull::Frustum`, as the rasterizers cull them; with
/// `cull_instances`) placed per instance, one instanced draw per run of a
/// group of copies sharing mesh, material and mirroring.
#[allow(clippy::too_many_arguments)]
unsafe fn draw_copies(
    gl: &glow::Context,
    state: &mut State,
    program: glow::Program,
    job: &PassJob,
    layer: &std::sync::Arc<crate::scene::instanced::InstanceLayer>,
    environment: (i32, i32),
    mapped: bool,
    y_down: bool,
) {
    let scene = &job.prepared.scene;
    let frustum = crate::render::raster::cull::Frustum::new(job.view);
    let cull = job.settings.cull_instances;
    // Copy k's record (its bounding sphere): the one whose triangles start at its base.
    let info = |k: usize| {
        let base = layer.instances[k].base as usize;
        let i = scene.instances.partition_point(|r| r.triangles.start < base);
        scene.instances.get(i).filter(|r| r.triangles.start == base)
    };
    unsafe {
        let meshes = state.upload_layer(gl, layer);
        let (floats, groups) = scene_data::layer_instances(layer, &meshes, |k| !cull || info(k).is_none_or(|r| frustum.may_see(job.view, r.center, r.radius)));
        if groups.is_empty() {
            return;
        }
        gl.bind_buffer(glow::ARRAY_BUFFER, Some(state.instance_buffer));
        gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, bytemuck::cast_slice(&floats), glow::STREAM_DRAW);
        gl.use_program(Some(program));
        uniforms(gl, program, job, environment);
        if mapped {
            state.maps.lookup_uniforms(gl, program, job.settings);
        }
        gl.bind_vertex_array(Some(state.layer_array));
        for (group, first_instance, count) in groups {
            let Some((mesh_first, runs)) = meshes.get(group.mesh as usize) else { continue };
            // A mirroring placement turns the winding round.
            gl.front_face(if y_down != group.flips { glow::CW } else { glow::CCW });
            for run in runs {
                material_textures(gl, &state.textures, program, job, group.material.unwrap_or(run.material));
                if run.two_sided {
                    gl.disable(glow::CULL_FACE);
                } else {
                    gl.enable(glow::CULL_FACE);
                }
                gl.draw_arrays_instanced_base_instance(glow::TRIANGLES, ((mesh_first + run.first) * 3) as i32, (run.count * 3) as i32, count as i32, first_instance);
            }
        }
        gl.front_face(if y_down { glow::CW } else { glow::CCW });
    }
}
