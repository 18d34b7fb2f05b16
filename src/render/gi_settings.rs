//! The settings of the indirect-light modes, part of `RenderSettings`: read
//! by shading (`transport::gi`), by the photon map's build and by the
//! command line and the panels, so they sit below all of them.

use crate::named::named_enum;

named_enum! {
    /// How light that has bounced off other surfaces is accounted for.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum GiMode ("gi mode") {
        /// Direct light plus the scene's constant ambient term.
        #[default]
        None = "none",
        /// The ambient term weighted by the unoccluded part of the hemisphere.
        Ao = "ao",
        /// Indirect light estimated from photons shot from the lights.
        Photons = "photons",
        /// Unidirectional path tracing with next-event estimation.
        Path = "path",
    }
}

/// The knobs of the indirect-light modes.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct GiSettings {
    pub mode: GiMode,
    /// Path tracing: indirect bounces; `None` = as many as Russian roulette
    /// lets live (up to `MAX_BOUNCES`).
    pub bounces: Option<u32>,
    /// Ambient occlusion: hemisphere rays per sample, and how far they look.
    pub ao_samples: u32,
    pub ao_distance: f32,
    /// Photon mapping: photons shot, and neighbours per density estimate.
    pub photons: u32,
    pub photon_k: u32,
    /// Photon mapping: rays gathered at the first hit (0: read the map there).
    pub final_gather: u32,
    /// Every random number depends on (pixel, sample index, seed) only.
    pub seed: u64,
}

impl Default for GiSettings {
    fn default() -> Self {
        GiSettings { mode: GiMode::None, bounces: None, ao_samples: 16, ao_distance: 1.0, photons: 200_000, photon_k: 64, final_gather: 0, seed: 0 }
    }
}

/// Unbounded paths still stop here, so recursion depth stays bounded; the
/// throughput left after this many bounces off anything but a perfect
/// mirror is far below what a pixel can show.
pub const MAX_BOUNCES: u32 = 100;

impl GiSettings {
    /// The deepest ray a path may cast (0 = eye ray), for `Path`.
    pub fn max_path_depth(&self) -> u32 {
        self.bounces.map_or(MAX_BOUNCES, |b| b.min(MAX_BOUNCES))
    }
}
