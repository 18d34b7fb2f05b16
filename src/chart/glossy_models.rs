//! The model sweep's scene edit: every glossy lobe of a scene drawn by one
//! glossy model, its parameter chosen so that the lobe keeps its width, so
//! that the chart can set the models' costs and errors side by side.

use crate::scene::material::{GlossyModel, MIN_ROUGHNESS};
use crate::scene::Scene;
use glam::Vec2;

/// The models the sweep switches to, cheapest-looking first.
pub const SWEPT: [GlossyModel; 5] = [GlossyModel::BlinnPhong, GlossyModel::Phong, GlossyModel::Ggx, GlossyModel::Beckmann, GlossyModel::Ward];

/// The scene file's name of `model`.
pub fn name(model: GlossyModel) -> &'static str {
    GlossyModel::NAMES.iter().find(|(_, m)| *m == model).map_or("?", |(n, _)| n)
}

/// Whether any material something is drawn with has a glossy lobe.
pub fn has_glossy(scene: &Scene) -> bool {
    scene.materials.iter().zip(scene.materials_in_use()).any(|(m, used)| used && m.has_glossy())
}

/// A copy of `scene` whose glossy materials all use `model`, with the
/// parameter that model reads set from the lobe's width in its own model:
/// a microfacet alpha a, Blinn-Phong's exponent `2 / a^2 - 2` (the
/// Beckmann lobe's match, as Walter et al. give it), Phong's a quarter of
/// that (the mirror direction's angle to the light is about twice the half
/// vector's to the normal), Ward's `a` along both directions.
pub fn switched(scene: &Scene, model: GlossyModel) -> Scene {
    let mut out = scene.clone();
    for m in out.materials.iter_mut().filter(|m| m.has_glossy()) {
        let alpha = alpha_of(m.glossy_model, m.sharpness, m.roughness, m.roughness_uv);
        m.glossy_model = model;
        match model {
            GlossyModel::BlinnPhong => m.sharpness = blinn_phong_exponent(alpha),
            GlossyModel::Phong => m.sharpness = blinn_phong_exponent(alpha) / 4.0,
            GlossyModel::Ggx | GlossyModel::Beckmann => m.roughness = alpha,
            GlossyModel::Ward => m.roughness_uv = Vec2::splat(alpha),
        }
    }
    out
}

/// The lobe width as a microfacet alpha in [MIN_ROUGHNESS, 1].
fn alpha_of(model: GlossyModel, sharpness: f32, roughness: f32, roughness_uv: Vec2) -> f32 {
    let from_exponent = |s: f32| (2.0 / (s.max(0.0) + 2.0)).sqrt();
    let alpha = match model {
        GlossyModel::BlinnPhong => from_exponent(sharpness),
        GlossyModel::Phong => from_exponent(4.0 * sharpness),
        GlossyModel::Ggx | GlossyModel::Beckmann => roughness,
        GlossyModel::Ward => (roughness_uv.x * roughness_uv.y).sqrt(),
    };
    alpha.clamp(MIN_ROUGHNESS, 1.0)
}

/// The Blinn-Phong exponent whose lobe matches a Beckmann alpha.
fn blinn_phong_exponent(alpha: f32) -> f32 {
    (2.0 / (alpha * alpha) - 2.0).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_survive_a_round_trip_through_every_model() {
        for alpha in [0.05f32, 0.2, 0.5] {
            let s = blinn_phong_exponent(alpha);
            assert!((alpha_of(GlossyModel::BlinnPhong, s, 0.0, Vec2::ZERO) - alpha).abs() < 1e-5);
            assert!((alpha_of(GlossyModel::Phong, s / 4.0, 0.0, Vec2::ZERO) - alpha).abs() < 1e-5);
            assert_eq!(alpha_of(GlossyModel::Ward, 0.0, 0.0, Vec2::splat(alpha)), alpha);
        }
        // Blinn-Phong at s = 100 (the default) is a Beckmann alpha of 0.14.
        assert!((alpha_of(GlossyModel::BlinnPhong, 100.0, 0.0, Vec2::ZERO) - 0.140028).abs() < 1e-5);
    }

    #[test]
    fn switching_changes_only_the_glossy_materials() {
        let scene = crate::scene::builtin::load_builtin("spheres").unwrap().unwrap();
        let ggx = switched(&scene, GlossyModel::Ggx);
        for (a, b) in scene.materials.iter().zip(&ggx.materials) {
            if a.has_glossy() {
                assert_eq!(b.glossy_model, GlossyModel::Ggx);
                assert!((b.roughness - (2.0 / (a.sharpness + 2.0)).sqrt()).abs() < 1e-6, "{}", a.name);
            } else {
                assert_eq!(a, b);
            }
        }
    }
}
