//! Normal maps (Computer Graphics from Scratch ch. 15): a texture whose
//! texels are unit normals in the surface's tangent frame (x along growing
//! u, y along growing v, z out of the surface), stored as `n * 0.5 + 0.5`.
//! The renderers bend a hit's shading normal here as soon as they have its
//! footprint, so that everything after (shadow rays cast ahead in packets,
//! the eight-wide batch, `shade()`, the debug views) reads the same normal.

use crate::math::Vec3;
use crate::scene::tangents::tangent_at;
use crate::scene::texture::TextureFilter;
use crate::scene::{Scene, SurfaceHit};
use glam::Vec4;

/// The unit normal `n` bent by normal-map texel `texel` in the frame of
/// tangent `t.xyz` (not necessarily unit or orthogonal to `n`) and
/// handedness `t.w` (the bitangent is `sign(w) n x t`). A texel pointing
/// straight out (0.5, 0.5, 1) leaves `n` exactly as it is, bit for bit;
/// so does a frame that cannot be built (no tangent).
#[inline]
pub fn mapped_normal(n: Vec3, t: Vec4, texel: Vec3) -> Vec3 {
    let m = texel * 2.0 - Vec3::ONE;
    if m.x == 0.0 && m.y == 0.0 && m.z > 0.0 {
        return n;
    }
    let tangent = (t.truncate() - n * n.dot(t.truncate())).normalize_or_zero();
    if tangent == Vec3::ZERO {
        return n;
    }
    let bitangent = n.cross(tangent) * if t.w < 0.0 { -1.0 } else { 1.0 };
    (tangent * m.x + bitangent * m.y + n * m.z).normalize_or(n)
}

/// Bends `hit`'s shading normal by its material's normal map, read at the
/// hit's uv and footprint with `filter`. Nothing happens without a map.
#[inline]
pub fn apply(scene: &Scene, filter: TextureFilter, hit: &mut SurfaceHit) {
    let material = &scene.materials[hit.material as usize];
    let Some(texel) = material.normal_map_texel(hit.uv, &hit.diff.footprint(), filter) else { return };
    // The frame belongs to the front side: a back face bends its front
    // normal, then turns the result round.
    if hit.back_face {
        hit.shading_normal = -mapped_normal(-hit.shading_normal, tangent_at(scene, hit), texel);
    } else {
        hit.shading_normal = mapped_normal(hit.shading_normal, tangent_at(scene, hit), texel);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_texel_is_the_identity_bit_for_bit() {
        let n = Vec3::new(0.3, 0.9, 0.1).normalize();
        let t = Vec4::new(1.0, 0.2, 0.0, 1.0);
        assert_eq!(mapped_normal(n, t, Vec3::new(0.5, 0.5, 1.0)).to_array().map(f32::to_bits), n.to_array().map(f32::to_bits));
    }

    #[test]
    fn a_tilted_texel_turns_the_normal_by_its_angle() {
        // Texel (sin a, 0, cos a) * 0.5 + 0.5 in the frame t = +x, n = +z:
        // the normal leans by a towards +x.
        let a = 30f32.to_radians();
        let texel = Vec3::new(a.sin(), 0.0, a.cos()) * 0.5 + Vec3::splat(0.5);
        let bent = mapped_normal(Vec3::Z, Vec4::new(1.0, 0.0, 0.0, 1.0), texel);
        assert!((bent.dot(Vec3::Z).acos() - a).abs() < 1e-5, "{bent}");
        assert!((bent - Vec3::new(0.5, 0.0, 3f32.sqrt() / 2.0)).length() < 1e-6, "{bent}");
        // Along v with handedness -1 the bitangent points down: (0, -sin, cos).
        let texel = Vec3::new(0.0, a.sin(), a.cos()) * 0.5 + Vec3::splat(0.5);
        let bent = mapped_normal(Vec3::Z, Vec4::new(1.0, 0.0, 0.0, -1.0), texel);
        assert!((bent - Vec3::new(0.0, -0.5, 3f32.sqrt() / 2.0)).length() < 1e-6, "{bent}");
    }
}
