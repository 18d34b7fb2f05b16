//! The approximations of shadow rays: shadow maps (`map`, with PCF) and
//! shadow volumes (`volume`, counted in the rasterizer's stencil). Each is
//! measured against the ray-traced shadows it stands in for.

pub mod map;
pub mod volume;
