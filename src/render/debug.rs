//! Debug views: per-sample colours that show what the renderer saw instead of
//! shading it (CGPP 15.4.1.2). Every renderer calls the same function, so a
//! view means the same thing in each.

use crate::math::{Radiance, Ray, Vec3};
use crate::scene::{CameraView, SurfaceHit};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum View {
    /// The shaded image.
    Shaded,
    /// Barycentric weights of v0, v1, v2 as red, green, blue (Figure 15.6).
    Barycentric,
    /// Eye-ray direction as (d + 1) / 2 (Figure 15.4).
    Raydir,
    /// View-axis depth, near = white, far = black (linear in 1/z).
    Depth,
    /// Shading normal as (n + 1) / 2.
    Normal,
    /// Object ids as distinct colours.
    Id,
    /// A checker in texture coordinates.
    Uv,
}

impl View {
    pub const ALL: [View; 7] = [View::Shaded, View::Barycentric, View::Raydir, View::Depth, View::Normal, View::Id, View::Uv];

    pub fn name(self) -> &'static str {
        match self {
            View::Shaded => "shaded",
            View::Barycentric => "barycentric",
            View::Raydir => "raydir",
            View::Depth => "depth",
            View::Normal => "normal",
            View::Id => "id",
            View::Uv => "uv",
        }
    }

    pub fn parse(s: &str) -> Result<View, String> {
        Self::ALL.into_iter().find(|v| v.name() == s).ok_or_else(|| {
            let names: Vec<_> = Self::ALL.iter().map(|v| v.name()).collect();
            format!("unknown view \"{s}\" (choose from {})", names.join(", "))
        })
    }
}

/// The colour of one sample in a debug view. Values are "radiance" in [0, 1],
/// shown with exposure 1.
pub fn view_color(view: View, camera: &CameraView, ray: &Ray, hit: Option<&SurfaceHit>) -> Radiance {
    if view == View::Raydir {
        return (ray.dir + Vec3::ONE) * 0.5;
    }
    let Some(h) = hit else { return Vec3::ZERO };
    match view {
        View::Shaded | View::Raydir => unreachable!("handled above"),
        View::Barycentric => h.barycentric,
        View::Depth => {
            // 1/z maps near to 1 and far to 0; it is what a depth buffer stores.
            let z = camera.view_depth(h.position).max(camera.near);
            let inv = (1.0 / z - 1.0 / camera.far) / (1.0 / camera.near - 1.0 / camera.far);
            Vec3::splat(inv.clamp(0.0, 1.0).powf(0.25))
        }
        View::Normal => (h.shading_normal + Vec3::ONE) * 0.5,
        View::Id => id_color(h.object),
        View::Uv => {
            let c = ((h.uv.x * 8.0).floor() as i64 + (h.uv.y * 8.0).floor() as i64).rem_euclid(2);
            if c == 0 { Vec3::new(0.9, 0.9, 0.9) } else { Vec3::new(0.1, 0.1, 0.1) }
        }
    }
}

/// A distinct, stable colour for an id (golden-ratio hue steps).
pub fn id_color(id: u32) -> Vec3 {
    let h = (id as f32 * 0.618_034).fract();
    let k = |n: f32| {
        let k = (n + h * 6.0) % 6.0;
        1.0 - (k.min(4.0 - k).clamp(0.0, 1.0))
    };
    Vec3::new(k(5.0), k(3.0), k(1.0)) * 0.8 + Vec3::splat(0.1)
}
