//! How a camera maps image positions to directions: the pinhole's
//! perspective (CGPP 15.4.1), parallel rays (orthographic), and two
//! projections that bend straight lines, an equidistant fisheye and a
//! cylindrical panorama. `CameraView` holds the scale of each: its
//! `half_x`/`half_y` are the image's half extents in the unit each
//! projection measures the image in (see `Projection`).

use crate::math::Vec3;

/// A camera's projection.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Projection {
    /// Rays from the eye through an image plane at distance 1; `half_x` and
    /// `half_y` are tan(fov / 2).
    #[default]
    Perspective,
    /// Parallel rays along the view axis from a rectangle `height` world
    /// units high; `half_x` and `half_y` are its half extents.
    Orthographic { height: f32 },
    /// Equidistant fisheye: the angle from the view axis grows linearly
    /// with the distance from the image centre; `half_x` and `half_y` are
    /// the angles (radians) at the image edges. Angles past 180 degrees
    /// look straight back.
    Fisheye,
    /// A panorama on a cylinder around the up axis: the angle about it
    /// grows linearly across the image (`half_x`, radians at the side
    /// edges), height on the unit cylinder linearly down it (`half_y`).
    Cylindrical,
}

impl Projection {
    /// The names the scene format uses.
    pub const NAMES: [&'static str; 4] = ["perspective", "orthographic", "fisheye", "cylindrical"];

    pub fn name(&self) -> &'static str {
        match self {
            Projection::Perspective => "perspective",
            Projection::Orthographic { .. } => "orthographic",
            Projection::Fisheye => "fisheye",
            Projection::Cylindrical => "cylindrical",
        }
    }

    /// Whether straight lines in the scene stay straight in the image (what
    /// a rasterizer, which interpolates between projected corners, needs).
    pub fn keeps_lines_straight(&self) -> bool {
        matches!(self, Projection::Perspective | Projection::Orthographic { .. })
    }

    /// The widest field of view, degrees, the projection forms an image
    /// with, across the image's width (`horizontal`) or height.
    pub fn max_fov_deg(&self, horizontal: bool) -> f32 {
        match (self, horizontal) {
            (Projection::Fisheye, _) | (Projection::Cylindrical, true) => 360.0,
            _ => super::MAX_FOV_DEG,
        }
    }

    /// The image's half extents for a field of view of `deg` degrees across
    /// the width (`horizontal`) or height, and width / height `aspect`.
    /// (An orthographic camera's come from its height instead.)
    pub fn half_extents(&self, deg: f32, horizontal: bool, aspect: f32) -> (f32, f32) {
        let half_angle = deg.to_radians() * 0.5;
        // Measured along the given edge, then carried to the other one.
        let along = match (self, horizontal) {
            (Projection::Fisheye, _) | (Projection::Cylindrical, true) => half_angle,
            _ => half_angle.tan(),
        };
        if horizontal {
            (along, along / aspect)
        } else {
            (along * aspect, along)
        }
    }

    /// The camera-space direction (not of unit length, except for the
    /// fisheye's) of scaled image position `(sx, sy)` (in units of the
    /// half extents, already multiplied by them). Orthographic rays all
    /// point down -z.
    #[inline]
    pub fn direction(&self, sx: f32, sy: f32) -> Vec3 {
        match self {
            Projection::Perspective => Vec3::new(sx, sy, -1.0),
            Projection::Orthographic { .. } => Vec3::NEG_Z,
            Projection::Fisheye => {
                let theta = (sx * sx + sy * sy).sqrt();
                if theta == 0.0 {
                    return Vec3::NEG_Z;
                }
                let s = theta.sin() / theta;
                Vec3::new(sx * s, sy * s, -theta.cos())
            }
            Projection::Cylindrical => Vec3::new(sx.sin(), sy, -sx.cos()),
        }
    }

    /// The scaled image position `(sx, sy)` a camera-space point `c` is
    /// seen at: the inverse of `direction` (and, orthographic, of the
    /// ray's offset from the axis).
    #[inline]
    pub fn image_of(&self, c: Vec3) -> (f32, f32) {
        match self {
            Projection::Perspective => {
                let inv = 1.0 / -c.z;
                (c.x * inv, c.y * inv)
            }
            Projection::Orthographic { .. } => (c.x, c.y),
            Projection::Fisheye => {
                let rho = (c.x * c.x + c.y * c.y).sqrt();
                if rho == 0.0 {
                    return (0.0, 0.0);
                }
                let theta = rho.atan2(-c.z);
                (c.x * theta / rho, c.y * theta / rho)
            }
            Projection::Cylindrical => {
                let r = (c.x * c.x + c.z * c.z).sqrt();
                (c.x.atan2(-c.z), c.y / r)
            }
        }
    }

    /// Whether a camera-space point lies beyond the near surface the eye
    /// rays start on (a plane for the straight projections, a sphere for
    /// the fisheye, a cylinder for the panorama).
    #[inline]
    pub fn beyond_near(&self, c: Vec3, near: f32) -> bool {
        match self {
            Projection::Perspective | Projection::Orthographic { .. } => -c.z >= near,
            Projection::Fisheye => c.length() >= near,
            Projection::Cylindrical => (c.x * c.x + c.z * c.z).sqrt() >= near,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_of_inverts_direction() {
        for p in [Projection::Perspective, Projection::Fisheye, Projection::Cylindrical] {
            for &(sx, sy) in &[(0.0, 0.0), (0.3, -0.2), (-1.1, 0.7), (2.5, 0.1)] {
                if p == Projection::Perspective && (sx as f32).abs() > 2.0 {
                    continue;
                }
                let d = p.direction(sx, sy) * 3.7;
                let (x, y) = p.image_of(d);
                assert!((x - sx).abs() < 1e-5 && (y - sy).abs() < 1e-5, "{p:?} ({sx}, {sy}) came back as ({x}, {y})");
            }
        }
    }

    #[test]
    fn fisheye_angle_from_the_axis_grows_linearly_with_the_radius() {
        // By hand: 90 degrees from the axis at radius pi/2 is a direction in the image plane.
        let d = Projection::Fisheye.direction(std::f32::consts::FRAC_PI_2, 0.0);
        assert!((d - Vec3::X).length() < 1e-6, "{d:?}");
        let d = Projection::Fisheye.direction(0.0, std::f32::consts::PI);
        assert!((d - Vec3::Z).length() < 1e-6, "{d:?}");
    }

    #[test]
    fn cylindrical_columns_are_angles_and_rows_heights() {
        let d = Projection::Cylindrical.direction(std::f32::consts::FRAC_PI_2, 0.5);
        assert!((d - Vec3::new(1.0, 0.5, 0.0)).length() < 1e-6, "{d:?}");
        assert_eq!(Projection::Cylindrical.half_extents(180.0, true, 2.0), (std::f32::consts::FRAC_PI_2, std::f32::consts::FRAC_PI_4));
    }
}
