//! The third renderer (CGPP 15.7): the scene handed to OpenGL. Triangles
//! go through a vertex shader, GL's fixed-function rasterizer and depth test
//! and a fragment shader that computes `shade()` (`shaders`); spheres stay
//! exact (a bounding cube whose fragments intersect the ray with the sphere
//! and write `gl_FragDepth`), and so do CSG objects (their bounding box,
//! whose fragments evaluate the interval rule along the eye ray); the
//! two-level layer's copies are instanced. Runs in a headless EGL context (`context`),
//! so it works without a window, on Mesa's llvmpipe where there is no GPU.

mod context;
mod csg_data;
mod pass;
mod scene_data;
mod shaders;
mod shadow_pass;
mod textures;
mod views;

use crate::math::Radiance;
use crate::render::inspect::debug;
use crate::render::transport::gi;
use crate::render::{Interpolation, PassJob, RayCounts, Reflections, RenderSettings, Renderer, ShadowMode};
use crate::render::admit::Substitute;
use crate::render::layer_support::LayerSupport;
use crate::render::inspect::pixel_record::{GlReadback, PixelTrace};
use crate::scene::Scene;

static GL: context::Shared<pass::State> = context::Shared::new();

/// Releases the OpenGL context before the process exits (a no-op when the
/// `opengl` renderer was never used).
pub fn shutdown() {
    GL.shutdown();
}

/// `f` with the context current (made on first use), and the context's
/// release at exit arranged once the driver is loaded.
fn with_gl<R>(f: impl FnOnce(&mut context::Gl<pass::State>) -> R) -> Result<R, String> {
    let result = GL.with(f);
    release_at_exit();
    result
}

/// Makes sure the context is released at exit even when nobody calls
/// `shutdown` (test harnesses, a `process::exit` elsewhere): the C
/// library's exit handlers run in reverse order of registration, so a
/// handler registered after the driver was loaded runs before the
/// driver's own teardown, while the process is still whole.
fn release_at_exit() {
    static REGISTERED: std::sync::Once = std::sync::Once::new();
    extern "C" fn release() {
        GL.try_shutdown();
    }
    unsafe extern "C" {
        fn atexit(callback: extern "C" fn()) -> std::ffi::c_int;
    }
    // SAFETY: `atexit` is the C library's; `release` is a plain function
    // that takes nothing and unwinds nowhere (`shutdown` only drops the context).
    REGISTERED.call_once(|| unsafe {
        atexit(release);
    });
}

pub struct OpenGl;

impl Renderer for OpenGl {
    fn name(&self) -> &'static str {
        "opengl"
    }

    fn description(&self) -> &'static str {
        "the scene through OpenGL (CGPP 15.7): vertex and fragment shaders, GL's rasterizer and depth test, headless EGL"
    }

    fn check(&self, scene: &Scene, settings: &RenderSettings) -> Result<(), String> {
        crate::render::accel::csg::check(scene, settings)?;
        csg_data::build(&scene.csgs)?;
        let csg_materials = scene.csgs.iter().flat_map(|c| c.spheres.iter().map(|s| s.material).chain(c.triangles.iter().map(|t| t.material)));
        if let Some(m) = csg_materials.filter_map(|m| scene.materials.get(m as usize)).find(|m| m.texture.is_some() || m.normal_map.is_some()) {
            return Err(format!("the opengl renderer draws csg objects without textures only (material \"{}\")", m.name));
        }
        unsupported(scene, settings)
    }

    /// Shadow rays it cannot cast: shadow maps in the shaded view, else no
    /// shadows. BSDF-sampled rays it cannot cast either: area lights and the
    /// environment by light sampling alone (`--mis off`), tried after the
    /// shadows alone.
    fn substitutes(&self, settings: &RenderSettings) -> Vec<Substitute> {
        let mut out = Vec::new();
        if settings.shadows == ShadowMode::Ray {
            let with = |shadows, notice: String| Substitute { settings: RenderSettings { shadows, ..settings.clone() }, notice };
            if settings.view != debug::View::Shaded {
                let notice = format!("opengl cannot trace shadow rays, which the {} view does not show; drawing no shadows (--shadows none)", settings.view.name());
                out.push(with(ShadowMode::None, notice));
            } else {
                out.push(with(ShadowMode::Map, "opengl cannot trace shadow rays; drawing shadow maps instead (--shadows map)".into()));
                out.push(with(ShadowMode::None, "opengl cannot trace shadow rays, and shadow maps cannot draw this scene; drawing no shadows instead (--shadows none)".into()));
            }
        }
        if settings.mis {
            const NO_MIS: &str = "opengl cannot trace the BSDF-sampled rays that MIS weighs against light samples; lighting by light sampling alone";
            let no_mis = |s: &RenderSettings, notice: String| Substitute { settings: RenderSettings { mis: false, ..s.clone() }, notice };
            let mut all = vec![no_mis(settings, format!("{NO_MIS} (--mis off)"))];
            for sub in &out {
                let flag = format!("--shadows {}", sub.settings.shadows.name());
                let (why, what) = match sub.settings.shadows {
                    ShadowMode::Map => ("", "shadow maps"),
                    _ => (" (and shadow maps cannot draw this scene)", "no shadows"),
                };
                let notice = format!("opengl cannot trace shadow rays{why}, nor the BSDF-sampled rays that MIS weighs against light samples; drawing {what} and lighting by light sampling alone ({flag} --mis off)");
                all.push(no_mis(&sub.settings, notice));
            }
            out.extend(all);
        }
        out
    }

    /// The copies are instanced in GL; its shadow pass draws `Scene::triangles` only.
    fn instance_layer(&self) -> LayerSupport {
        LayerSupport::WithoutShadowMaps
    }

    /// The driver, and as many multisamples as `--msaa` asks for.
    fn ready(&self, settings: &RenderSettings) -> Result<(), String> {
        let max_samples = max_samples()?;
        if settings.msaa > 1 && settings.msaa as i32 > max_samples {
            return Err(format!("the opengl renderer's driver offers at most {max_samples} samples per pixel, not --msaa {}", settings.msaa));
        }
        Ok(())
    }

    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
        match with_gl(|g| pass::render(g, job, out, None)) {
            Ok(Ok((counts, _))) => counts,
            Ok(Err(e)) | Err(e) => {
                // `check` and `ready` refuse what cannot be drawn before a frame starts;
                // a failure here leaves the rows black rather than stale.
                eprintln!("warning: opengl: {e}");
                out.fill(Radiance::ZERO);
                RayCounts::default()
            }
        }
    }

    /// Not a replay: GL's shaders cannot be stepped through. The pixel's
    /// row is drawn again and what the render targets hold there (the
    /// fragment's interpolated inputs and its output) is recorded.
    fn trace_pixel(&self, job: &PassJob, x: u32, y: u32, rec: &mut PixelTrace) -> Option<Radiance> {
        match self.read_back(job, x, y) {
            Ok(r) => {
                let value = r.output;
                rec.gl_readback = Some(r);
                Some(value)
            }
            Err(e) => {
                eprintln!("warning: opengl: {e}");
                None
            }
        }
    }
}

impl OpenGl {
    /// Draws row `y` of `job`'s pass and reads back what GL left at `(x, y)`.
    fn read_back(&self, job: &PassJob, x: u32, y: u32) -> Result<GlReadback, String> {
        let row = PassJob { rows: y..y + 1, active: None, ..*job };
        let mut out = vec![Radiance::ZERO; job.view.width as usize];
        let (_, readback) = with_gl(|g| pass::render(g, &row, &mut out, Some((x, y))))??;
        readback.ok_or_else(|| format!("no GL readback at pixel ({x}, {y})"))
    }
}

/// What the fragment shaders do not compute yet, as one sentence.
fn unsupported(scene: &Scene, settings: &RenderSettings) -> Result<(), String> {
    let refuse = |what: &str| Err(format!("the opengl renderer {what}"));
    if !matches!(settings.shadows, ShadowMode::None | ShadowMode::Map) {
        return refuse("supports --shadows none|map only (it casts no rays)");
    }
    if settings.view != debug::View::Shaded && !views::drawable(settings.view) {
        return refuse("draws the shaded view and --view barycentric|raydir|depth|zbuffer|normal|geometric-normal|id|triangle-id|material-id|uv only");
    }
    if settings.view != debug::View::Shaded && settings.msaa > 1 {
        return refuse("draws debug views without --msaa only");
    }
    if settings.gi.mode != gi::GiMode::None {
        return refuse("supports --gi none only");
    }
    if matches!(settings.interpolation, Interpolation::Gouraud | Interpolation::Faceted) {
        return refuse("supports --interpolation phong|flat only: it shades each fragment where it lies, not a triangle's vertices or centroid");
    }
    // Area lights and the environment are summed over fixed patterns of
    // light samples (`scene_data::area_lights`, `environment_light`): there
    // is no BSDF-sampled ray to weigh them against, and no light sample at
    // all with --light-samples 0. The environment's light is unshadowed.
    let sky = scene.environment.as_ref().is_some_and(|e| e.is_light());
    if (sky || !scene.emitters.is_empty()) && settings.view == debug::View::Shaded {
        if settings.light_samples == 0 {
            return refuse("lights area lights and the [environment] by light samples only, not --light-samples 0");
        }
        if settings.mis {
            return refuse("lights area lights and the [environment] by light samples alone (it traces no BSDF-sampled rays), not with --mis on");
        }
        if sky && settings.shadows != ShadowMode::None {
            return refuse("lights the scene with the [environment] without shadows (it casts no rays, and no shadow map holds the sky's), so with --shadows none only");
        }
    }
    if scene.render.lighting == crate::scene::Lighting::Classic {
        return refuse("cannot shade [render] lighting = \"classic\" (its shader has the physical model only); use raytrace or rasterize");
    }
    // Only materials something is drawn with: one merely named in the file asks nothing.
    let in_use = scene.materials_in_use();
    let mut drawn = scene.materials.iter().zip(in_use).filter(|(_, used)| *used).map(|(m, _)| m);
    if scene.has_vertex_colours() {
        return refuse("cannot draw vertex colours yet; use raytrace or rasterize");
    }
    if let Some(m) = drawn.clone().find(|m| m.cutout.is_some()) {
        return refuse(&format!("cannot cut surfaces away where their alpha is low (alphaMode MASK, material \"{}\") yet; use raytrace or rasterize", m.name));
    }
    if let Some(m) = drawn.clone().find(|m| m.metallic.is_some() || m.emission_map.is_some()) {
        return refuse(&format!("cannot draw textured metallic-roughness or emission yet (material \"{}\"); use raytrace or rasterize", m.name));
    }
    if let Some(m) = drawn.clone().find(|m| m.map_samplers.any()) {
        return refuse(&format!("reads every texture of a material with one sampler, and material \"{}\" gives its maps different wrap modes or filters; use raytrace or rasterize", m.name));
    }
    if let Some(m) = drawn.clone().find(|m| m.wrap[0] != m.wrap[1] || m.wrap[0] == crate::scene::texture::Wrap::MirroredRepeat) {
        return refuse(&format!("wraps textures the same way along u and v, by repeat or clamp only (material \"{}\"); use raytrace or rasterize", m.name));
    }
    if let Some(m) = drawn.clone().find(|m| m.transmission != crate::math::Vec3::ZERO) {
        return refuse(&format!("cannot trace glass rays (material \"{}\")", m.name));
    }
    if settings.reflections == Reflections::Ray {
        if let Some(m) = drawn.find(|m| m.has_secondary()) {
            return refuse(&format!("cannot trace mirror rays; use --reflections env (material \"{}\")", m.name));
        }
    }
    Ok(())
}

/// The OpenGL driver in use (`GL_RENDERER`), or why there is none.
pub fn driver() -> Result<String, String> {
    with_gl(|g| g.renderer.clone())
}

/// The most samples per pixel the driver's multisampling offers (`GL_MAX_SAMPLES`).
pub fn max_samples() -> Result<i32, String> {
    // SAFETY: a plain query on the current context.
    with_gl(|g| unsafe { glow::HasContext::get_parameter_i32(&g.gl, glow::MAX_SAMPLES) })
}
