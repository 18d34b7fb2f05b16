//! Multisample antialiasing (CGPP 15.6.6; the D3D standard sample patterns):
//! N coverage samples per pixel, each with its own depth, and ONE shade per
//! pixel per primitive, weighted by the share of samples it covers.
//!
//! The pass rasterizes N + 1 layers (see `pass.rs`): layer 0 at the pass's
//! own sample (the pixel centre without `spp`), layers 1..=N at the coverage
//! samples. A primitive is shaded where layer 0 sees it when it does (so a
//! pixel covered by one primitive shades exactly as without MSAA), else at its
//! covered sample nearest the centre (always on the primitive: no
//! extrapolation, like centroid sampling). Only the coverage samples weigh in
//! the resolve. With `spp` passes the pattern is scaled into the pass's
//! stratum: sample k sits at `offset + pattern_k / sqrt(spp)`.

use crate::render::raster::vis_buffer::{FragmentRecorder, VisBuffer};
use crate::math::{Radiance, Vec2};
use crate::render::inspect::debug::cost_color;
use crate::render::finite::admit_all;
use crate::render::{RayCounts, SceneQuery};
use crate::scene::PrimitiveId;

/// The sample counts accepted by `--msaa`.
pub const COUNTS: [u32; 4] = [1, 2, 4, 8];

/// D3D's standard sample positions in 1/16 pixel from the pixel centre.
const PATTERN_2: [(i8, i8); 2] = [(4, 4), (-4, -4)];
const PATTERN_4: [(i8, i8); 4] = [(-2, -6), (6, -2), (-6, 2), (2, 6)];
const PATTERN_8: [(i8, i8); 8] = [(1, -3), (-1, 3), (5, 1), (-3, -5), (-5, 5), (-7, -1), (3, 7), (7, -7)];

/// The standard pattern of `n` samples, as offsets from the pixel centre in pixels.
pub fn pattern(n: u32) -> Vec<Vec2> {
    let p: &[(i8, i8)] = match n {
        2 => &PATTERN_2,
        4 => &PATTERN_4,
        8 => &PATTERN_8,
        _ => &[],
    };
    p.iter().map(|&(x, y)| Vec2::new(x as f32, y as f32) / 16.0).collect()
}

/// Sub-pixel positions of the coverage samples of a pass at `offset` (in
/// [0, 1)^2) of a frame of `spp` passes, nearest the centre first; empty
/// without MSAA.
pub fn sample_offsets(msaa: u32, offset: Vec2, spp: u32) -> Vec<Vec2> {
    let scale = 1.0 / (spp.max(1) as f32).sqrt();
    let mut p = pattern(msaa);
    p.sort_by(|a, b| a.length_squared().total_cmp(&b.length_squared()));
    p.into_iter().map(|d| offset + d * scale).collect()
}

/// The final value of pixel `(x, y)` (index `i` in every buffer): the
/// coverage samples grouped by primitive, each group shaded once.
pub fn resolve<Q: SceneQuery, R: FragmentRecorder>(vbs: &mut [VisBuffer<Q, R>], i: usize, x: u32, y: u32) -> Radiance {
    let n = vbs.len() - 1;
    vbs[0].counts.primary += 1;
    let centre = vbs[0].id[i];
    // (primitive id, samples covered, layer to shade from), in sample order.
    let mut groups = [(PrimitiveId::NONE, 0u32, 0usize); 8];
    let mut ng = 0;
    for k in 1..=n {
        let id = vbs[k].id[i];
        match groups[..ng].iter_mut().find(|g| g.0 == id) {
            Some(g) => g.1 += 1,
            None => {
                groups[ng] = (id, 1, if id == centre { 0 } else { k });
                ng += 1;
            }
        }
    }
    if vbs[0].cost_view() {
        let shades = groups[..ng].iter().filter(|g| !g.0.is_none()).count() as u32;
        vbs[0].counts.fragments_shaded += shades as u64;
        let work: u32 = vbs.iter().map(|vb| vb.work_at(i)).sum::<u32>() + shades;
        return cost_color(work as f32);
    }
    let mut value = Radiance::ZERO;
    for &(id, count, src) in &groups[..ng] {
        if !id.is_none() {
            vbs[src].counts.fragments_shaded += 1;
        }
        let v = vbs[src].shade(i, x, y);
        value += v * (count as f32 / n as f32);
    }
    value
}

/// Resolves the common region of `vbs` into rows of `out_stride` pixels
/// starting at column `x_offset`, and returns the counts of every layer.
/// Each row is put through `admit_all` as soon as it is written.
pub fn resolve_into<Q: SceneQuery, R: FragmentRecorder>(vbs: &mut [VisBuffer<Q, R>], out: &mut [Radiance], out_stride: usize, x_offset: usize) -> RayCounts {
    let r = vbs[0].rect;
    let w = r.width() as usize;
    let keep_non_finite = vbs[0].job.keep_non_finite;
    let mut non_finite = 0;
    let mut i = 0;
    for (row, y) in (r.y0..r.y1).enumerate() {
        let line = &mut out[row * out_stride + x_offset..row * out_stride + x_offset + w];
        for (px, x) in line.iter_mut().zip(r.x0..r.x1) {
            *px = resolve(vbs, i, x, y);
            i += 1;
        }
        if !keep_non_finite {
            non_finite += admit_all(line);
        }
    }
    let mut counts = RayCounts { non_finite, ..RayCounts::default() };
    for vb in vbs {
        counts += std::mem::take(&mut vb.counts);
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_are_inside_the_pixel_and_centred() {
        for n in [2, 4, 8] {
            let p = pattern(n);
            assert_eq!(p.len(), n as usize);
            let mean = p.iter().copied().sum::<Vec2>() / n as f32;
            assert!(mean.length() < 1e-6, "{n}: {mean}");
            assert!(p.iter().all(|d| d.x.abs() < 0.5 && d.y.abs() < 0.5));
            // Rotated grids: no two samples share a column or a row.
            for a in 0..p.len() {
                for b in a + 1..p.len() {
                    assert!(p[a].x != p[b].x && p[a].y != p[b].y);
                }
            }
        }
        assert!(pattern(1).is_empty());
        let s = sample_offsets(4, Vec2::splat(0.5), 4);
        assert!(s.iter().all(|o| (*o - Vec2::splat(0.5)).length() < 0.25));
    }
}
