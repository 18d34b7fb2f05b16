//! Cache hints: ask for memory that a loop will read soon, so the load
//! overlaps the work in between. A hint never faults, whatever the address,
//! and changes no result.

/// Asks the cache for the `lines` lines of 64 bytes from `p`.
#[inline(always)]
pub fn prefetch_lines(p: *const u8, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for line in 0..lines {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch never faults, whatever the address.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * line).cast()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (p, lines);
}

/// Asks the cache for the lines holding `bytes` bytes from `p`, which need
/// not start a line.
#[inline(always)]
pub fn prefetch(p: *const u8, bytes: usize) {
    prefetch_lines(p, bytes.div_ceil(64));
    // The last byte's line, when `p` does not start a line.
    prefetch_lines(p.wrapping_add(bytes - 1), 1);
}

/// Asks the cache for every line of `*value`.
#[inline(always)]
pub fn prefetch_value<T>(value: &T) {
    prefetch((value as *const T).cast(), std::mem::size_of::<T>().max(1));
}
