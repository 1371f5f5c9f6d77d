//! Keeping the other workers of a rayon pool polling for work while one world steps on it,
//! instead of sleeping between the step's parallel loops (docs/performance.md, "The other worker
//! polls through the run"). rayon puts an idle worker to sleep after a few dozen yields, and a
//! sleeping thread wakes slowly on a virtual machine, so a loop that followed a loop with an
//! uneven tail began on one thread. Who runs which task never changes a result
//! (`stages::ParTasks`), so polling changes the speed, never the bits.

use std::sync::atomic::{AtomicBool, Ordering};

/// Runs `f` on `pool` while the pool's other workers poll for its tasks instead of falling
/// asleep between them (docs/performance.md, "The other worker polls through the run").
///
/// Only for a pool that is this run's own, stepping one world at a time, as in `grit sample`,
/// `grit jet`, the bench and a farm worker with a pool of its own: two such runs on one pool at
/// once, each from a worker of it (a sweep's samples in parallel), could each end up polling
/// inside the other's task and wait for each other for ever.
pub fn install_polling<R: Send>(pool: &rayon::ThreadPool, f: impl FnOnce() -> R + Send) -> R {
    pool.install(|| run_polling(f))
}

/// `install_polling` on the current pool (the global one outside any).
fn run_polling<R>(f: impl FnOnce() -> R) -> R {
    let others = rayon::current_num_threads().saturating_sub(1);
    if others == 0 {
        return f();
    }
    let done = AtomicBool::new(false);
    // Set on the way out, a panic included, so the scope never waits on a poller for ever.
    struct Done<'a>(&'a AtomicBool);
    impl Drop for Done<'_> {
        fn drop(&mut self) {
            self.0.store(true, Ordering::Release);
        }
    }
    rayon::in_place_scope(|s| {
        // Pushed before any task of `f`, so a thief takes them first: the calling thread never
        // finds a poller left in its own queue while it waits for a stolen task (it would poll
        // until its own run ended), only at the scope's end, when `done` is already set.
        for _ in 0..others {
            s.spawn(|_| poll(&done));
        }
        let _done = Done(&done);
        f()
    })
}

/// Runs the pool's pending tasks until `done`; with none pending, yields to the OS scheduler,
/// so another process on the machine loses nothing to the polling.
fn poll(done: &AtomicBool) {
    while !done.load(Ordering::Acquire) {
        match rayon::yield_now() {
            Some(rayon::Yield::Executed) => {}
            Some(rayon::Yield::Idle) => std::thread::yield_now(),
            None => break,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    fn pool(n: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    }

    fn sum(n: u32) -> u64 {
        (0..n).into_par_iter().with_max_len(64).map(u64::from).sum()
    }

    #[test]
    fn a_polled_run_does_its_loops_and_returns_on_any_thread_count() {
        for threads in [1, 2, 3] {
            let total =
                install_polling(&pool(threads), || (0..50).map(|_| sum(10_000)).sum::<u64>());
            assert_eq!(total, 50 * (10_000 * 9_999 / 2), "{threads} threads");
        }
        // Outside any pool the pollers run on the global pool's workers.
        assert_eq!(run_polling(|| sum(10_000)), 10_000 * 9_999 / 2);
    }

    #[test]
    fn a_panicking_run_still_returns_its_panic() {
        let r = std::panic::catch_unwind(|| install_polling(&pool(2), || panic!("boom")));
        assert!(r.is_err());
    }
}
