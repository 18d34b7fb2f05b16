//! Where an object or a copy of it stands: its scale, rotation and
//! translation made into one matrix, and the triangles, corners and spheres
//! it places. The scene file's objects and the instance layer's copies are
//! placed with the same arithmetic.

use crate::scene::Triangle;
use crate::math::Vec3;

/// Object placement: scale, then rotate about X, Y, Z, then translate.
#[derive(Clone, Debug)]
pub struct Placement {
    matrix: glam::Mat4,
    normal_matrix: glam::Mat3,
    uniform_scale: Option<f32>,
    identity: bool,
    /// The matrix mirrors (negative determinant).
    flips: bool,
}

impl Placement {
    pub fn new(translate: Vec3, rotate_deg: Vec3, scale: Vec3) -> Placement {
        let rot = glam::Quat::from_rotation_z(rotate_deg.z.to_radians())
            * glam::Quat::from_rotation_y(rotate_deg.y.to_radians())
            * glam::Quat::from_rotation_x(rotate_deg.x.to_radians());
        let matrix = glam::Mat4::from_scale_rotation_translation(scale, rot, translate);
        let normal_matrix = glam::Mat3::from_mat4(matrix).inverse().transpose();
        let uniform_scale = (scale.x == scale.y && scale.y == scale.z).then_some(scale.x);
        let identity = translate == Vec3::ZERO && rotate_deg == Vec3::ZERO && scale == Vec3::ONE;
        let flips = matrix.determinant() < 0.0;
        Placement { matrix, normal_matrix, uniform_scale, identity, flips }
    }

    /// A placement by any affine matrix (a glTF node's world transform).
    pub fn from_matrix(matrix: glam::Mat4) -> Placement {
        let normal_matrix = glam::Mat3::from_mat4(matrix).inverse().transpose();
        let (scale, rotation, _) = matrix.to_scale_rotation_translation();
        let rebuilt = glam::Mat4::from_scale_rotation_translation(scale, rotation, matrix.w_axis.truncate());
        let uniform_scale = (scale.x == scale.y && scale.y == scale.z && rebuilt.abs_diff_eq(matrix, 1e-6)).then_some(scale.x);
        let identity = matrix == glam::Mat4::IDENTITY;
        let flips = matrix.determinant() < 0.0;
        Placement { matrix, normal_matrix, uniform_scale, identity, flips }
    }

    /// The 4x4 matrix of the placement.
    pub fn matrix(&self) -> glam::Mat4 {
        self.matrix
    }

    /// The vertices `apply` gives, alone (the normals left out).
    #[inline]
    pub fn apply_vertices(&self, v: [Vec3; 3]) -> [Vec3; 3] {
        if self.identity {
            return v;
        }
        let mut w = v.map(|p| self.matrix.transform_point3(p));
        if self.flips {
            w.swap(1, 2);
        }
        w
    }

    /// One corner's position and normal placed as `apply` places them (a
    /// flat triangle's normal aside, which `apply` makes anew).
    #[inline]
    pub fn apply_corner(&self, p: Vec3, n: Vec3) -> (Vec3, Vec3) {
        if self.identity {
            return (p, n);
        }
        (self.matrix.transform_point3(p), (self.normal_matrix * n).normalize_or_zero())
    }

    /// Whether the placement mirrors, so that `apply` reverses windings.
    pub fn flips(&self) -> bool {
        !self.identity && self.flips
    }

    /// The triangle placed: vertices by the matrix, normals by its inverse
    /// transpose, corners reordered when the placement mirrors.
    pub fn apply(&self, mut t: Triangle) -> Triangle {
        if self.identity {
            return t;
        }
        // A mirroring scale flips the winding; swap two corners to keep fronts in front.
        let flips = self.flips;
        let flat = t.is_flat();
        for k in 0..3 {
            t.v[k] = self.matrix.transform_point3(t.v[k]);
            t.n[k] = (self.normal_matrix * t.n[k]).normalize_or_zero();
        }
        if flips {
            t.v.swap(1, 2);
            t.n.swap(1, 2);
            t.uv.swap(1, 2);
        }
        // A flat triangle stays flat: its normal is the placed triangle's own
        // (equal to the transformed one up to rounding).
        if flat {
            t.n = [t.geometric_normal(); 3];
        }
        t
    }

    /// The sphere placed; only a uniform scale keeps it a sphere.
    pub(super) fn apply_sphere(&self, center: Vec3, radius: f32) -> Result<(Vec3, f32), String> {
        match self.uniform_scale {
            Some(s) => Ok((self.matrix.transform_point3(center), radius * s.abs())),
            None => Err("a sphere's scale must be one number (non-uniform scale would not keep it a sphere)".into()),
        }
    }
}
