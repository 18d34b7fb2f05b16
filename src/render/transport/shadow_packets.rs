//! The shadow rays of batches of surfaces traced as packets of the BVH.

use crate::render::accel::bvh::BvhQuery;
use crate::render::accel::packet::Packet;
use crate::render::transport::shade_batch::Batch;
use crate::render::{RayCounts, RenderSettings};

/// The shadow rays `shade()` casts from the surfaces of `batches` (hits
/// built) towards each light, traced as one packet per light: lane j of
/// batch b goes into packet lane `lane(b, j)`, and that bit of
/// `blocked[light]` is set when its ray meets something before the light,
/// exactly when the single ray's `occluder` would (see `occluded_packet`).
/// What `shade_batch` and `start_paths` then take as their `blocked`.
pub fn shadow_packets(query: &BvhQuery, settings: &RenderSettings, batches: &[Batch], lane: impl Fn(usize, usize) -> usize, pk: &mut Packet, blocked: &mut [u64], counts: &mut RayCounts) {
    let scene = &query.prepared.scene;
    for (k, light) in scene.lights.iter().enumerate() {
        let mut cast = 0u64;
        for (b, batch) in batches.iter().enumerate() {
            batch.shadow_rays(scene, light, settings.shadow_bump, settings.terminator_lift, |j, ray, t_max| {
                let i = lane(b, j);
                pk.rays[i] = ray;
                pk.t_max[i] = t_max;
                cast |= 1 << i;
            });
        }
        blocked[k] = 0;
        if cast != 0 {
            query.occluded_packet(pk, cast, counts);
            let mut m = cast;
            while m != 0 {
                let i = m.trailing_zeros() as usize;
                m &= m - 1;
                blocked[k] |= (pk.occluder(i).is_some() as u64) << i;
            }
        }
    }
}

