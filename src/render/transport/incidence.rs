//! How one light arrives at a surface point, and where the shadow ray
//! towards it leaves the surface. Shared by the scalar and batch shaders,
//! light sampling and shadow maps, so it depends on none of them.

use crate::math::{Radiance, Ray, Vec3};
use crate::render::transport::lighting::{self, IncidenceLanes};
use crate::scene::{Light, Scene, SurfaceHit};

/// How one light arrives at a surface point: the first half of every light's
/// term in `shade()`, before visibility and the BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incidence {
    /// Unit direction towards the light.
    pub w_i: Vec3,
    /// Distance to the light (infinite for directional lights).
    pub distance: f32,
    /// Incident radiance (point, CGPP 15.4.5: power / (4 pi d^2)) or
    /// irradiance (directional), before visibility.
    pub incident: Radiance,
    /// `w_i . n` with the shading normal.
    pub cos_theta: f32,
}

impl Incidence {
    /// Light `light` at point `p` with unit shading normal `n`; `None` when
    /// a point light sits exactly at `p` (it has no direction there and
    /// contributes nothing).
    #[inline]
    pub fn of(light: &Light, p: Vec3, n: Vec3) -> Option<Incidence> {
        let lane = lighting::incidence::<f32>(light, p.into(), n.into());
        lane.exists.then(|| Incidence::from_lane(&lane))
    }

    /// One lane's incidence as this struct.
    #[inline(always)]
    pub fn from_lane(lane: &IncidenceLanes<f32>) -> Incidence {
        Incidence { w_i: lane.w_i.into(), distance: lane.distance, incident: lane.incident.into(), cos_theta: lane.cos_theta }
    }

    /// Whether the light reaches the surface's lit side with some radiance:
    /// only then can it contribute, and only then is a shadow ray cast.
    #[inline]
    pub fn illuminates(&self) -> bool {
        !(self.cos_theta <= 0.0 || self.incident == Vec3::ZERO)
    }

    /// The shadow ray from `hit` towards the light, and its far end. It
    /// leaves from `shadow_origin` and starts `bump` along the ray so it does
    /// not hit P again (CGPP listing 15.20); it ends `bump` short of the light.
    /// `lift`: `RenderSettings::terminator_lift`.
    #[inline]
    pub fn shadow_ray(&self, scene: &Scene, hit: &SurfaceHit, bump: f32, lift: bool) -> (Ray, f32) {
        let leaving = SurfaceHit { position: shadow_origin(scene, hit, self.w_i, lift), ..*hit };
        (leaving.spawn_ray_along(self.w_i, bump), self.distance - bump)
    }
}

/// Where a shadow ray towards `w_i` leaves a surface point. Normally the hit
/// point itself (the ray is then bumped along `w_i`, CGPP listing 15.20). But
/// on a triangle with smooth vertex normals, where the shading normal faces
/// the light while the flat facet faces away (the shadow terminator), a ray
/// from the facet is blocked by the mesh's own neighbouring facets and leaves
/// black speckles. There, following Hanika ("Hacking the shadow terminator",
/// Ray Tracing Gems II, ch. 4), the origin is lifted onto the curved surface
/// the vertex normals imply. Only there: elsewhere the lift would move the
/// origin of a coarse, strongly bent triangle (the book's) far off its surface.
/// Without `lift` (`RenderSettings::terminator_lift` off) always the hit point,
/// to show the speckles it prevents.
pub fn shadow_origin(scene: &Scene, hit: &SurfaceHit, w_i: Vec3, lift: bool) -> Vec3 {
    if !lift || hit.kind != crate::scene::PrimitiveKind::Triangle || hit.geometric_normal.dot(w_i) > 0.0 {
        return hit.position;
    }
    lifted_position(scene, hit)
}

/// The hit point lifted onto the surface implied by the vertex normals
/// (Hanika's construction); the hit point itself on flat triangles.
pub fn lifted_position(scene: &Scene, hit: &SurfaceHit) -> Vec3 {
    let tri = &scene.triangle(hit.primitive);
    let side = if hit.back_face { -1.0 } else { 1.0 };
    let mut lifted = Vec3::ZERO;
    for k in 0..3 {
        let n = tri.n[k] * side;
        let d = hit.position - tri.v[k];
        // Keep only the part of P - v_k above the vertex's tangent plane.
        let below = d.dot(n).min(0.0);
        lifted += hit.barycentric[k] * (tri.v[k] + d - below * n);
    }
    if lifted.is_finite() { lifted } else { hit.position }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shadow_origin_lifts_onto_the_smooth_surface() {
        use crate::scene::{Triangle, PrimitiveKind};
        use glam::Vec2;
        let v = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        // Normals leaning outwards, as on a convex dome: the implied surface bulges up (+z).
        let n = [Vec3::new(-1.0, -1.0, 2.0).normalize(), Vec3::new(1.0, -0.2, 2.0).normalize(), Vec3::new(-0.2, 1.0, 2.0).normalize()];
        let mut scene = Scene::default();
        scene.triangles.push(Triangle { v, n, uv: [Vec2::ZERO; 3], material: 0, object: 0, two_sided: false });
        let b = Vec3::splat(1.0 / 3.0);
        let p = v[0] * b.x + v[1] * b.y + v[2] * b.z;
        let hit = SurfaceHit {
            position: p, geometric_normal: Vec3::Z, shading_normal: Vec3::Z, barycentric: b, uv: Vec2::ZERO, t: 1.0,
            kind: PrimitiveKind::Triangle, primitive: 0, object: 0, material: 0, back_face: false, diff: crate::scene::Differentials::ZERO,
        };
        let lifted = lifted_position(&scene, &hit);
        assert!(lifted.z > 0.05, "the origin must rise above the facet: {lifted}");
        // At a vertex nothing moves; on a flat triangle nothing moves.
        let at_vertex = SurfaceHit { position: v[1], barycentric: Vec3::new(0.0, 1.0, 0.0), ..hit };
        assert!((lifted_position(&scene, &at_vertex) - v[1]).length() < 1e-6);
        // Only towards a light behind the facet: otherwise the book's plain bump.
        assert_eq!(shadow_origin(&scene, &hit, Vec3::Z, true), p);
        assert_eq!(shadow_origin(&scene, &hit, Vec3::new(0.0, 0.6, -0.8), true), lifted);
        assert_eq!(shadow_origin(&scene, &hit, Vec3::new(0.0, 0.6, -0.8), false), p, "no lift when it is turned off");
        scene.triangles.set(0, Triangle { n: [Vec3::Z; 3], ..scene.triangles.at(0) });
        assert!((lifted_position(&scene, &hit) - p).length() < 1e-7);
    }
}
