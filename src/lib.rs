//! pinhole: a CPU ray tracer and a CPU rasterizer that render the same scene
//! through one shading routine, with the tools to compare and debug them.
//!
//! The core (everything but `app`) has no GUI types and never refers to
//! `app`; the binary opens the viewer when `cli::run` asks for it.

pub mod chart;
pub mod cli;
pub mod display;
pub mod env_overrides;
pub mod file_identity;
pub mod gallery;
pub mod image_io;
pub mod input;
pub mod math;
pub mod metrics;
pub mod named;
pub mod part_file;
pub mod part_merge;
pub mod part_status;
pub mod render;
pub mod scene;
pub mod app;
