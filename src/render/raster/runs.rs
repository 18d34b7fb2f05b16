//! A pass's set-up pieces as the threads made them: one run per chunk of
//! triangles, in scene order. The fixed-point rasterizer draws straight
//! from the runs, naming a piece by an id that packs its run and its place
//! in it; joining the runs into one array would copy every piece (about
//! 250 bytes each) once more per pass. Ids increase in run order, so
//! binning by id keeps the pieces in scene order.

use rayon::prelude::*;

/// Pieces run by run; `id = run << place_bits | place`.
pub struct Runs<T> {
    runs: Vec<Vec<T>>,
    place_bits: u32,
}

impl<T: Copy + Send + Sync> Runs<T> {
    pub fn new(runs: Vec<Vec<T>>) -> Runs<T> {
        let longest = runs.iter().map(Vec::len).max().unwrap_or(0) as u64;
        let place_bits = 64 - longest.leading_zeros();
        if (runs.len() as u64) << place_bits <= u32::MAX as u64 + 1 {
            return Runs { runs, place_bits };
        }
        // Too many pieces for packed ids (no scene within the input limits
        // comes near): one run, ids are places.
        Runs { runs: vec![join_runs(runs)], place_bits: 32 }
    }

    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.runs.iter().map(Vec::len).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.runs.iter().all(Vec::is_empty)
    }

    /// Every piece with its id, in order.
    pub fn with_ids(&self) -> impl Iterator<Item = (u32, &T)> + '_ {
        let bits = self.place_bits;
        self.runs.iter().enumerate().flat_map(move |(r, run)| run.iter().enumerate().map(move |(p, t)| (((r as u64) << bits | p as u64) as u32, t)))
    }

    /// The piece with id `id`.
    #[inline(always)]
    pub fn get(&self, id: u32) -> &T {
        let id = id as u64;
        &self.runs[(id >> self.place_bits) as usize][(id & ((1u64 << self.place_bits) - 1)) as usize]
    }

    /// The pieces in one array, in order.
    pub fn joined(self) -> Vec<T> {
        join_runs(self.runs)
    }
}

/// The runs' pieces in one array, in run order. Each run is copied by the
/// thread that takes it (one thread copying them all held up the other).
pub fn join_runs<T: Copy + Send + Sync>(runs: Vec<Vec<T>>) -> Vec<T> {
    let total = runs.iter().map(Vec::len).sum();
    let mut all: Vec<T> = Vec::with_capacity(total);
    let mut rest = &mut all.spare_capacity_mut()[..total];
    let mut places = Vec::with_capacity(runs.len());
    for run in &runs {
        let (place, after) = rest.split_at_mut(run.len());
        places.push(place);
        rest = after;
    }
    runs.par_iter().zip(places).for_each(|(run, place)| {
        // SAFETY: `place` is `run.len()` uninitialised slots of `all`,
        // disjoint from every other run's; `T: Copy`, so `run` still owns
        // (and frees) its values.
        unsafe { std::ptr::copy_nonoverlapping(run.as_ptr(), place.as_mut_ptr().cast::<T>(), run.len()) }
    });
    // SAFETY: the places cover the first `total` slots, all written above.
    unsafe { all.set_len(total) };
    all
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_name_every_piece_in_order_and_joining_keeps_it() {
        let runs: Vec<Vec<u32>> = vec![(0..5).collect(), vec![], (5..6).collect(), (6..300).collect(), (300..301).collect()];
        let r = Runs::new(runs.clone());
        assert_eq!(r.len(), 301);
        let ids: Vec<(u32, u32)> = r.with_ids().map(|(id, &v)| (id, v)).collect();
        assert_eq!(ids.iter().map(|x| x.1).collect::<Vec<_>>(), (0..301).collect::<Vec<_>>());
        assert!(ids.windows(2).all(|w| w[0].0 < w[1].0), "ids increase");
        assert!(ids.iter().all(|&(id, v)| *r.get(id) == v));
        assert_eq!(r.joined(), (0..301).collect::<Vec<_>>());
        assert!(Runs::<u32>::new(vec![]).is_empty());
    }
}
