//! What one parallel loop costs the engine's thread pool on this machine when the loop follows a
//! stretch of serial work, as every stage loop of a step does (docs/performance.md, "Why two
//! threads give 1.6").
//!
//! ```sh
//! cargo run --release -p grit-sph --example fork_join
//! ```
//!
//! Each round runs `LOOPS` times: a loop over 6000 values split into the engine's tasks of 64 to
//! 256, each value taking a fixed bit of arithmetic, then `gap` µs of serial spinning on the
//! calling thread. It prints the time per round on 1 and 2 threads and what the second thread
//! costs beyond an ideal halving of the loop: once the gap is long enough for rayon's idle
//! worker to go to sleep, every loop pays for waking it.

use rayon::prelude::*;
use std::hint::black_box;
use std::time::Instant;

const LOOPS: u32 = 5000;
const VALUES: usize = 6000;

/// Seconds per round of `LOOPS` rounds on a pool of `threads`, with `gap_us` of serial work
/// after each loop.
fn per_round(threads: usize, gap_us: u64) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let mut v = vec![1.0f64; VALUES];
    let t = Instant::now();
    pool.install(|| {
        for _ in 0..LOOPS {
            v.par_iter_mut()
                .with_min_len(64)
                .with_max_len(256)
                .for_each(|x| {
                    for _ in 0..20 {
                        *x = (*x * 1.000_000_1).sqrt() + 0.5;
                    }
                });
            let s = Instant::now();
            while s.elapsed().as_nanos() < u128::from(gap_us) * 1000 {
                std::hint::spin_loop();
            }
        }
    });
    black_box(&v);
    t.elapsed().as_secs_f64() / f64::from(LOOPS)
}

fn main() {
    println!("gap (us)  1 thread (us)  2 threads (us)  2-thread overhead per loop (us)");
    for gap in [0, 2, 5, 10, 20, 50, 100] {
        let (one, two) = (per_round(1, gap), per_round(2, gap));
        let g = gap as f64 * 1e-6;
        // An ideal second thread halves the loop and leaves the gap as it is.
        let overhead = two - (g + (one - g) / 2.0);
        println!(
            "{gap:>8}  {:>13.1}  {:>14.1}  {:>31.1}",
            one * 1e6,
            two * 1e6,
            overhead * 1e6
        );
    }
}
