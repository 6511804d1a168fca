//! The thread setting. [`Driver::step`](crate::driver::Driver::step) runs its
//! particle phases on the current rayon thread pool: inside
//! [`rayon::ThreadPool::install`] on that pool, elsewhere on rayon's global pool
//! (all cores unless configured). The results do not depend on the number of
//! threads, bit for bit (see [`crate::driver::phases`]).
//!
//! ```
//! let pool = psmpm::threads::pool(Some(2)).unwrap();
//! let sum: usize = pool.install(|| (0..10usize).sum());
//! assert_eq!(sum, 45);
//! ```

pub use rayon::{ThreadPool, ThreadPoolBuildError};

/// A pool of `threads` threads (`None` or `Some(0)`: one per core).
pub fn pool(threads: Option<usize>) -> Result<ThreadPool, ThreadPoolBuildError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .thread_name(|i| format!("psmpm-{i}"))
        .build()
}

/// Runs `work` on a pool of `threads` threads (`None`: one per core), so that
/// every step it takes uses them.
pub fn install<R: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> R + Send,
) -> Result<R, ThreadPoolBuildError> {
    Ok(pool(threads)?.install(work))
}

/// Whether the process runs under an address-space limit (`ulimit -v`), which
/// counts the address space each thread reserves (its stack, and up to 64 MB for
/// its allocator's arena) before anything is resident.
pub fn address_space_limited() -> bool {
    crate::setup::memory::address_space_limit_set()
}

/// The number of threads of the current pool.
pub fn current() -> usize {
    rayon::current_num_threads()
}
