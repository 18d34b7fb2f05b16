//! Speed against accuracy, measured rather than assumed: render each
//! configuration, time it, measure its error against a reference, and draw
//! the trade-off as a chart (PNG) and a table (CSV).
//!
//! - `configurations`: what the methods sweep measures on a scene;
//! - `glossy_models`: the model sweep's edit, every glossy lobe in one model;
//! - `reference`: the truth (an EXR, or a cached path-traced image);
//! - `measure`: timing and error of one configuration, the Pareto front, CSV;
//! - `spp_sweep`: the older sweep over samples per pixel;
//! - `gi_sweep`: each method of indirect light as a curve, and a peer's curve;
//! - `plot`: the PNG charts.

pub mod configurations;
pub mod gi_sweep;
pub mod glossy_models;
pub mod measure;
pub mod plot;
pub mod reference;
pub mod spp_sweep;

pub use configurations::{describe, method_configurations, Configuration};
pub use measure::{measure, methods_csv, pareto_front, ErrorMetric, Measurement};
pub use reference::{load_reference, Reference, ReferenceSource};
