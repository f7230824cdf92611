//! Parallelism inside one run, with results bit for bit those of the sequential loops.
//!
//! A run's loops run over the rayon pool they are called in (`with_threads` gives a run one of
//! its own) and in order outside any pool, so a run is sequential unless asked otherwise. The
//! work is cut the same way for any thread count: per-particle loops into `CHUNK` particles,
//! and the particle-to-grid sums into blocks of nodes, each block's task adding the particles'
//! contributions in particle order (`Stencils::scatter`). No floating-point sum is
//! split between tasks.

use std::panic;

use rayon::prelude::*;

/// Particles per task of a per-particle loop: large enough that a task outweighs its
/// scheduling, small enough to balance two to a few dozen threads on a large run.
pub const CHUNK: usize = 1024;

/// The threads the loops of a run called here share: those of the current rayon pool, one
/// outside any pool.
pub fn threads() -> usize {
    if rayon::current_thread_index().is_some() {
        rayon::current_num_threads()
    } else {
        1
    }
}

/// `task` of every part, in parallel over the current pool when there is more than one thread
/// and more than one part, in order otherwise; the results in the order of the parts. Parts are
/// disjoint pieces of the data the task writes (chunks of particles, blocks of nodes).
pub fn map_chunks<P, R>(parts: impl Iterator<Item = P>, task: impl Fn(P) -> R + Sync) -> Vec<R>
where
    P: Send,
    R: Send,
{
    if threads() == 1 {
        return parts.map(task).collect();
    }
    let parts: Vec<P> = parts.collect();
    if parts.len() == 1 {
        return parts.into_iter().map(task).collect();
    }
    parts.into_par_iter().map(&task).collect()
}

/// The length of the blocks `0..len` is cut into, one per thread of the current pool (the
/// whole outside a pool): the node blocks of a scatter, whose tasks each walk every particle,
/// so more blocks than threads would only add walks.
pub fn block_len(len: usize) -> usize {
    len.div_ceil(threads()).max(1)
}

/// Runs `work` with its loops over `threads` threads: on a thread of its own, in a pool of
/// `threads` threads when there is more than one (none for 0 or 1). The caller waits without running other
/// rayon jobs meanwhile: rayon lets a worker of one pool that waits on another run its own
/// pool's jobs, which would start the runner's next run inside this one. A panic of `work`
/// is passed on to the caller.
pub fn with_threads<R: Send>(
    threads: usize,
    work: impl FnOnce() -> R + Send,
) -> Result<R, rayon::ThreadPoolBuildError> {
    let pool = match threads {
        0 | 1 => None,
        n => Some(rayon::ThreadPoolBuilder::new().num_threads(n).build()?),
    };
    let outcome = std::thread::scope(|scope| {
        scope
            .spawn(|| match &pool {
                Some(pool) => pool.install(work),
                None => work(),
            })
            .join()
    });
    Ok(outcome.unwrap_or_else(|payload| panic::resume_unwind(payload)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_are_one_per_thread_at_most() {
        for threads in [1, 2, 3, 7] {
            let len = with_threads(threads, || block_len(10)).unwrap();
            assert!(10usize.div_ceil(len) <= threads, "{threads} threads: {len}");
        }
        assert_eq!(block_len(10), 10);
        assert_eq!(block_len(0), 1);
    }

    #[test]
    fn results_come_in_the_order_of_the_parts() {
        let squares = with_threads(3, || map_chunks(0..100usize, |i| i * i)).unwrap();
        assert_eq!(squares, (0..100).map(|i| i * i).collect::<Vec<_>>());
    }

    #[test]
    fn loops_are_sequential_outside_a_pool_and_use_the_run_pool_inside() {
        assert_eq!(threads(), 1);
        assert_eq!(with_threads(1, threads).unwrap(), 1);
        assert_eq!(with_threads(3, threads).unwrap(), 3);
    }
}
