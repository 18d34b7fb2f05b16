//! How the ray that reached an emitter was chosen, and the weight multiple
//! importance sampling gives it. Carried by every path (`gi::PathState`),
//! read by light sampling; in its own file so neither imports the other.

use crate::math::Vec3;

/// How the ray that reached a surface (or missed everything) was chosen,
/// which decides how much of the light it finds on an emitter counts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Arrival {
    /// An eye ray, or a mirror's or glass's delta lobe: no light sample
    /// could have found this light, so all of it counts.
    #[default]
    Direct,
    /// A path's bounce sampled from the BSDF with density `pdf` at `from`:
    /// the light found is weighted against light sampling.
    Bsdf { pdf: f32, from: Vec3 },
    /// A final-gather ray of photon mapping: light sampling at the surface
    /// it left already counted direct light, so lights found count nothing.
    Gathered,
}

/// The power heuristic (exponent 2): the weight of a sample drawn with
/// density `a` by a strategy competing with one of density `b` (each
/// density already multiplied by its strategy's sample count).
#[inline]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    if a.is_infinite() {
        return 1.0;
    }
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}
