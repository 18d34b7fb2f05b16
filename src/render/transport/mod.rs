//! Hits to radiance: everything that lights a surface the renderers found.
//! `shade` is the one shading entry for a single sample and `shade_batch` the
//! same over eight lanes, `shade_queue` the rasterizers' batched hand-off; `lighting` evaluates lights; `gi` holds the
//! indirect-light modes, `path_batch` the path pool, `photon_map` photons
//! and `bsdf_sampling` the BSDFs' importance sampling, `microfacet` the
//! microfacet lobes' distributions; `sampled_light` samples area lights and
//! the environment; `sampling` is the
//! sampler whose numbers are a pure function of (pixel, sample, seed).

pub mod arrival;
pub mod bsdf;
pub mod bsdf_sampling;
pub mod gi;
pub mod incidence;
pub mod kd_tree;
pub mod lighting;
pub mod microfacet;
pub mod path_batch;
pub mod photon_map;
pub mod sampled_light;
pub mod sampling;
pub mod shade;
pub mod shade_batch;
pub mod shade_queue;
pub mod shading;
pub mod shadow_packets;
