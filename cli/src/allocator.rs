//! The allocator the `frictionid` binary, the Python module and the benchmarks share:
//! mimalloc, keeping the memory a fit frees.
//!
//! glibc's malloc gave the fits' buffers (residual vectors and Jacobians of 50 to 300 kB)
//! back to the system and faulted them in again at every evaluation, a sixth of a Coulomb
//! fit's time; mimalloc keeps those. A replay's buffers along a long record are larger (a
//! 19 000-sample GMS replay's sensitivities and Jacobian rows are 2.4 MB each), and mimalloc
//! purges freed memory of that size back to the system after a delay, so every replay
//! faulted fresh pages in again (8 % of a GMS fit's profile was the kernel zeroing them;
//! the compare of every law on a 19 000-sample drive record took 4-5 % more CPU). With purging off, freed memory is reused: the process keeps its peak, no more.

/// mimalloc's `mi_option_purge_delay` (the position of that option in `mi_option_t` of
/// mimalloc.h, versions 2 and 3; libmimalloc-sys names no constant for it).
const PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Turns off mimalloc's purging of freed memory (a purge delay of -1 milliseconds): call
/// once, first thing. The results are the same to the bit.
pub fn keep_freed_memory() {
    // SAFETY: mi_option_set only stores an option's value; mimalloc reads it when it next
    // decides whether to purge.
    unsafe { libmimalloc_sys::mi_option_set(PURGE_DELAY, -1) }
}

/// mimalloc as the global allocator of whichever target includes this file.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;
