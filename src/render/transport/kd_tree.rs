//! A balanced kd-tree over points for k-nearest-neighbour queries, the
//! spatial structure of the photon map. Stored implicitly: the points are
//! reordered so that each range's median splits it, with the split axis kept
//! per median, so the tree costs one byte per point beyond the points.

use crate::math::Vec3;

pub struct KdTree<T> {
    items: Vec<T>,
    positions: Vec<Vec3>,
    /// Split axis of the range whose median is this index.
    axes: Vec<u8>,
}

/// One neighbour found by `nearest`: the item's index and squared distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbour {
    pub index: u32,
    pub distance2: f32,
}

impl<T> KdTree<T> {
    /// Builds the tree over `items` placed at `position(item)`. Items at
    /// non-finite positions are dropped: they can be nobody's neighbour.
    pub fn build(items: Vec<T>, position: impl Fn(&T) -> Vec3) -> KdTree<T> {
        let mut pairs: Vec<(Vec3, T)> = items.into_iter().map(|t| (position(&t), t)).filter(|(p, _)| p.is_finite()).collect();
        let mut axes = vec![0u8; pairs.len()];
        build_range(&mut pairs, &mut axes, 0);
        let (positions, items) = pairs.into_iter().unzip();
        KdTree { items, positions, axes }
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    pub fn item(&self, index: u32) -> &T {
        &self.items[index as usize]
    }

    pub fn position(&self, index: u32) -> Vec3 {
        self.positions[index as usize]
    }

    /// The `k` items nearest to `at` within squared distance `max_distance2`,
    /// nearest first (ties broken by index, so the answer is a function of
    /// the query alone).
    pub fn nearest(&self, at: Vec3, k: usize, max_distance2: f32, out: &mut Vec<Neighbour>) {
        self.nearest_as_heap(at, k, max_distance2, out);
        out.sort_by(|a, b| a.distance2.total_cmp(&b.distance2).then(a.index.cmp(&b.index)));
    }

    /// `nearest` without the sort: the same neighbours, as a max-heap on
    /// (distance, index), so the farthest comes first. Their order is still
    /// a function of the query alone (the tree is walked the same way every
    /// time), which is all a sum over them needs to be reproducible.
    pub fn nearest_as_heap(&self, at: Vec3, k: usize, max_distance2: f32, out: &mut Vec<Neighbour>) {
        out.clear();
        if k == 0 || self.items.is_empty() {
            return;
        }
        let mut search = Search { at, k, worst: max_distance2, found: out };
        self.visit(0, self.items.len(), &mut search);
    }

    fn visit(&self, lo: usize, hi: usize, s: &mut Search) {
        if lo >= hi {
            return;
        }
        let mid = (lo + hi) / 2;
        let p = self.positions[mid];
        s.offer(mid as u32, (p - s.at).length_squared());
        if hi - lo == 1 {
            return;
        }
        let axis = self.axes[mid] as usize;
        let delta = s.at[axis] - p[axis];
        let (near, far) = if delta < 0.0 { ((lo, mid), (mid + 1, hi)) } else { ((mid + 1, hi), (lo, mid)) };
        self.visit(near.0, near.1, s);
        if delta * delta <= s.bound() {
            self.visit(far.0, far.1, s);
        }
    }
}

/// The running k-nearest set: a max-heap on (distance, index) once full.
struct Search<'a> {
    at: Vec3,
    k: usize,
    worst: f32,
    found: &'a mut Vec<Neighbour>,
}

impl Search<'_> {
    /// The squared distance a point must not exceed to be of interest.
    fn bound(&self) -> f32 {
        if self.found.len() < self.k { self.worst } else { self.found[0].distance2 }
    }

    fn offer(&mut self, index: u32, distance2: f32) {
        let n = Neighbour { index, distance2 };
        if self.found.len() < self.k {
            if distance2 <= self.worst {
                self.found.push(n);
                let last = self.found.len() - 1;
                sift_up(self.found, last);
            }
        } else if farther(&self.found[0], &n) {
            self.found[0] = n;
            sift_down(self.found, 0);
        }
    }
}

/// True when `a` ranks after `b`: farther, or as far with a larger index.
#[inline]
fn farther(a: &Neighbour, b: &Neighbour) -> bool {
    a.distance2 > b.distance2 || (a.distance2 == b.distance2 && a.index > b.index)
}

fn sift_up(heap: &mut [Neighbour], mut i: usize) {
    while i > 0 {
        let parent = (i - 1) / 2;
        if !farther(&heap[i], &heap[parent]) {
            break;
        }
        heap.swap(i, parent);
        i = parent;
    }
}

fn sift_down(heap: &mut [Neighbour], mut i: usize) {
    loop {
        let (l, r) = (2 * i + 1, 2 * i + 2);
        let mut top = i;
        if l < heap.len() && farther(&heap[l], &heap[top]) {
            top = l;
        }
        if r < heap.len() && farther(&heap[r], &heap[top]) {
            top = r;
        }
        if top == i {
            return;
        }
        heap.swap(i, top);
        i = top;
    }
}

/// Orders `pairs` so that its median splits it along the axis of largest
/// extent, records that axis, and recurses into both halves.
fn build_range<T>(pairs: &mut [(Vec3, T)], axes: &mut [u8], _depth: u32) {
    if pairs.len() <= 1 {
        return;
    }
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for (p, _) in pairs.iter() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let extent = hi - lo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z { 0 } else if extent.y >= extent.z { 1 } else { 2 };
    let mid = pairs.len() / 2;
    pairs.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
    axes[mid] = axis as u8;
    let (left, right) = pairs.split_at_mut(mid);
    let (left_axes, right_axes) = axes.split_at_mut(mid);
    build_range(left, left_axes, _depth + 1);
    build_range(&mut right[1..], &mut right_axes[1..], _depth + 1);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::transport::sampling::SampleRng;

    fn brute(points: &[Vec3], at: Vec3, k: usize, max2: f32) -> Vec<f32> {
        let mut d: Vec<f32> = points.iter().map(|p| (*p - at).length_squared()).filter(|d| *d <= max2).collect();
        d.sort_by(f32::total_cmp);
        d.truncate(k);
        d
    }

    #[test]
    fn nearest_equals_brute_force() {
        let mut r = SampleRng::for_index(11, 0, 0);
        for n in [0usize, 1, 2, 3, 10, 257, 2000] {
            let points: Vec<Vec3> = (0..n).map(|_| Vec3::new(r.next_f32(), r.next_f32(), r.next_f32() * 0.1)).collect();
            let tree = KdTree::build(points.clone(), |p| *p);
            let mut out = Vec::new();
            for _ in 0..50 {
                let at = Vec3::new(r.next_f32(), r.next_f32(), 0.05);
                for (k, max2) in [(1, f32::INFINITY), (8, f32::INFINITY), (50, 0.01), (5000, 0.04)] {
                    tree.nearest(at, k, max2, &mut out);
                    let got: Vec<f32> = out.iter().map(|n| n.distance2).collect();
                    assert_eq!(got, brute(&points, at, k, max2), "n {n}, k {k}");
                    for nb in &out {
                        assert_eq!((tree.position(nb.index) - at).length_squared(), nb.distance2);
                    }
                    // The heap form holds the same neighbours, the farthest first.
                    let mut heap = Vec::new();
                    tree.nearest_as_heap(at, k, max2, &mut heap);
                    let mut sorted = heap.clone();
                    sorted.sort_by(|a, b| a.distance2.total_cmp(&b.distance2).then(a.index.cmp(&b.index)));
                    assert_eq!(sorted, out, "n {n}, k {k}");
                    assert_eq!(heap.first().map(|n| n.distance2), out.last().map(|n| n.distance2));
                }
            }
        }
    }

    #[test]
    fn non_finite_points_are_dropped() {
        let tree = KdTree::build(vec![Vec3::ZERO, Vec3::NAN, Vec3::INFINITY, Vec3::ONE], |p| *p);
        assert_eq!(tree.len(), 2);
        let mut out = Vec::new();
        tree.nearest(Vec3::splat(0.9), 4, f32::INFINITY, &mut out);
        assert_eq!(out.len(), 2);
        assert_eq!(tree.position(out[0].index), Vec3::ONE);
    }
}
