//! The context every step of `shade()` carries: what one sample reads and
//! writes besides the surface it lights. In its own file so that the modules
//! `shade()` calls (light sampling, indirect light) can take it without
//! importing `shade` back.

use crate::render::transport::gi::PathState;
use crate::render::{RayCounts, RenderSettings};
use crate::scene::Scene;

/// What shading one sample reads and writes besides the surface: the scene
/// and its query, the settings, the sample's path (random numbers,
/// throughput, photon map), the counters and the recorder. Passed down
/// whole through every step of `shade()` and the rays it follows.
pub struct Shading<'a, 'p, Q, R> {
    pub scene: &'a Scene,
    pub query: &'a Q,
    pub settings: &'a RenderSettings,
    pub path: &'a mut PathState<'p>,
    pub counts: &'a mut RayCounts,
    pub rec: &'a mut R,
}
