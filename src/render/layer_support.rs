//! What can draw a scene whose copies live in the two-level instance layer
//! (`scene::instanced`): the BVH ray tracer, the rasterizers and `opengl`
//! (its copies instanced in GL), with ray or no shadows, and the CPU
//! renderers with shadow maps too. The rest read `Scene::triangles` alone, so they refuse
//! such a scene with one sentence instead of drawing it without its copies.

use crate::render::inspect::debug::View;
use crate::render::{RenderSettings, ShadowMode};
use crate::scene::Scene;

/// `Ok` when `renderer` (by name) with `settings` draws every copy of `scene`.
pub fn check(renderer: &str, scene: &Scene, settings: &RenderSettings) -> Result<(), String> {
    if scene.layer.is_none() {
        return Ok(());
    }
    let why = |what: &str| {
        Err(format!(
            "{what} cannot draw this scene's {} copies held as shared meshes (over {} triangles are not flattened); use raytrace or rasterize with --shadows ray, map or none",
            scene.layer.as_ref().map_or(0, |l| l.instances.len()),
            crate::scene::file::FLATTEN_LIMIT
        ))
    };
    match renderer {
        "raytrace:brute" => return why(renderer),
        _ => {}
    }
    match settings.shadows {
        // The CPU maps draw the copies (each culled whole per light face).
        ShadowMode::Map if renderer == "opengl" => return why("opengl's --shadows map"),
        ShadowMode::Volume => return why("--shadows volume"),
        ShadowMode::None | ShadowMode::Ray | ShadowMode::Map => {}
    }
    match settings.view {
        View::Wireframe => why("--view wireframe"),
        View::Shadowmap => why("--view shadowmap"),
        _ => Ok(()),
    }
}
