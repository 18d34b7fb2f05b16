//! A one-slot cache keyed by what its value was built from: asked with the
//! key it holds, it hands out the value it holds; asked with another key, it
//! builds the value anew and keeps that instead. A prepared scene keeps its
//! last shadow maps, shadow volumes and photon map this way.
//!
//! `ThreadCopy` is the lock-free front for values read per sample: each
//! thread keeps the value it last took from a cache and goes back to the
//! cache only when that value no longer fits.

use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// The last value built and the key it was built for.
pub struct KeyedCache<K, V> {
    /// Tells this cache from every other one (see `ThreadCopy`).
    id: u64,
    slot: Mutex<Option<(K, Arc<V>)>>,
}

impl<K, V> Default for KeyedCache<K, V> {
    fn default() -> Self {
        static NEXT: AtomicU64 = AtomicU64::new(1);
        KeyedCache { id: NEXT.fetch_add(1, Ordering::Relaxed), slot: Mutex::new(None) }
    }
}

impl<K: PartialEq, V> KeyedCache<K, V> {
    /// A number no other cache has.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Whether the value held was built for `key` (`get` would not build).
    pub fn holds(&self, key: &K) -> bool {
        let slot = self.slot.lock().unwrap_or_else(|e| e.into_inner());
        slot.as_ref().is_some_and(|(held, _)| held == key)
    }

    /// The value for `key`: the one held when it was built for `key`, else
    /// `build(&key)`'s, which replaces it. Callers asking meanwhile wait for
    /// the build rather than building too.
    pub fn get(&self, key: K, build: impl FnOnce(&K) -> V) -> Arc<V> {
        let mut slot = self.slot.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((held, value)) = slot.as_ref()
            && *held == key
        {
            return value.clone();
        }
        let value = Arc::new(build(&key));
        *slot = Some((key, value.clone()));
        value
    }
}

/// A thread's copy of the value it last took from a `KeyedCache`, kept in a
/// `thread_local!` so that reading it again takes no lock.
pub struct ThreadCopy<V>(RefCell<Option<(u64, Arc<V>)>>);

impl<V> ThreadCopy<V> {
    pub const fn new() -> Self {
        ThreadCopy(RefCell::new(None))
    }

    /// Runs `f` with the copy when it came from the cache `cache_id` and
    /// `fits` it; else with `fetch()`'s value (from that cache), which
    /// becomes the copy. A call from inside `f` that has to fetch leaves in
    /// place the copy `f` may be reading.
    pub fn with<T>(&self, cache_id: u64, fits: impl FnOnce(&V) -> bool, fetch: impl FnOnce() -> Arc<V>, f: impl FnOnce(&V) -> T) -> T {
        if let Ok(copy) = self.0.try_borrow()
            && let Some((id, value)) = copy.as_ref()
            && *id == cache_id
            && fits(value)
        {
            return f(value);
        }
        let value = fetch();
        if let Ok(mut copy) = self.0.try_borrow_mut() {
            *copy = Some((cache_id, value.clone()));
        }
        f(&value)
    }
}

impl<V> Default for ThreadCopy<V> {
    fn default() -> Self {
        ThreadCopy::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn same_key_hits_new_key_rebuilds() {
        let cache: KeyedCache<u32, String> = KeyedCache::default();
        let builds = Cell::new(0);
        let build = |k: &u32| {
            builds.set(builds.get() + 1);
            format!("built for {k}")
        };
        assert!(!cache.holds(&1), "an empty cache holds nothing");
        let a = cache.get(1, build);
        assert!(cache.holds(&1) && !cache.holds(&2));
        let b = cache.get(1, build);
        assert_eq!(builds.get(), 1);
        assert!(Arc::ptr_eq(&a, &b));
        let c = cache.get(2, build);
        assert_eq!(builds.get(), 2);
        assert!(cache.holds(&2) && !cache.holds(&1), "one slot");
        assert_eq!(*c, "built for 2");
        // One slot: going back to the first key builds again.
        let d = cache.get(1, build);
        assert_eq!(builds.get(), 3);
        assert!(!Arc::ptr_eq(&a, &d));
        assert_eq!(*d, "built for 1");
    }

    #[test]
    fn caches_have_their_own_ids() {
        let (a, b): (KeyedCache<u32, u32>, KeyedCache<u32, u32>) = (KeyedCache::default(), KeyedCache::default());
        assert_ne!(a.id(), b.id());
    }

    #[test]
    fn thread_copy_is_read_while_it_fits() {
        let cache: KeyedCache<u32, u32> = KeyedCache::default();
        let copy = ThreadCopy::default();
        let fetches = Cell::new(0);
        let read = |key: u32| {
            let fetch = || {
                fetches.set(fetches.get() + 1);
                cache.get(key, |k| k * 10)
            };
            copy.with(cache.id(), |v| *v == key * 10, fetch, |v| *v)
        };
        assert_eq!(read(1), 10);
        assert_eq!(read(1), 10);
        assert_eq!(fetches.get(), 1);
        assert_eq!(read(2), 20);
        assert_eq!(fetches.get(), 2);
        // A copy from another cache does not fit this one.
        let other: KeyedCache<u32, u32> = KeyedCache::default();
        assert_eq!(copy.with(other.id(), |_| true, || other.get(2, |_| 7), |v| *v), 7);
    }
}
