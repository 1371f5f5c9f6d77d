//! Speed-up of each engine stage from 1 to 2 threads, each stage timed alone on the
//! reference scene caught mid-contact, the two thread counts alternated:
//! `cargo run --release -p grit-erosion --example stage_scaling -- [SPACING_M [REPEATS]]`.
use std::time::Instant;

use grit_erosion::impact::mid_contact_world;
use grit_sph::Stage;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let spacing: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(8e-6);
    let reps: usize = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(5);
    let mut w = mid_contact_world(spacing, 100).expect("a stable scene");
    w.run_stage(Stage::KernelSums).unwrap();
    let pools: Vec<rayon::ThreadPool> = [1, 2]
        .iter()
        .map(|&t| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .unwrap()
        })
        .collect();
    let stages = [
        ("neighbours", Some(Stage::Neighbours)),
        ("kernel_sums", Some(Stage::KernelSums)),
        ("stress", Some(Stage::Stress)),
        ("forces", Some(Stage::Forces)),
        ("contact", Some(Stage::Contact)),
        ("full_step", None),
    ];
    let iters = 40;
    println!(
        "{} particles, {iters} calls per timing, median of {reps}",
        w.particles().len()
    );
    for (name, stage) in stages {
        let mut t = [Vec::new(), Vec::new()];
        for _ in 0..reps {
            for (k, pool) in pools.iter().enumerate() {
                let mut c = w.clone();
                let s = pool.install(|| {
                    let t0 = Instant::now();
                    for _ in 0..iters {
                        match stage {
                            Some(s) => c.run_stage(s).unwrap(),
                            None => c.step().unwrap(),
                        }
                    }
                    t0.elapsed().as_secs_f64()
                });
                t[k].push(s / iters as f64);
            }
        }
        let (a, b) = (median(t[0].clone()), median(t[1].clone()));
        println!(
            "{name:12} 1 thread {:8.3} ms  2 threads {:8.3} ms  speed-up {:.2}",
            a * 1e3,
            b * 1e3,
            a / b
        );
    }
}
