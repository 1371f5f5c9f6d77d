//! The impact benchmark (`grit bench impact`): one impact of a sample, timed on 1 thread and on N threads
//! from the same surface state, with the engine's per-stage timers.

use std::collections::BTreeMap;
use std::hint::black_box;
use std::time::Instant;

use grit_sph::World;
use serde::{Deserialize, Serialize};

use crate::impact::sample::{Sample, SampleError};

/// Figures of one timed impact, as `grit bench impact --json` prints them (names kept stable).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactBench {
    /// Particles in the scene at the start of the impact (surface and grain).
    pub particles: usize,
    /// Steps the impact took.
    pub steps: u64,
    /// Wall time of the impact on `threads` threads (s).
    pub wall_s: f64,
    /// particles × steps / wall time, on `threads` threads.
    pub particle_steps_per_s: f64,
    /// The same divided by the thread count.
    pub particle_steps_per_s_per_thread: f64,
    /// Threads of the timed run.
    pub threads: usize,
    /// Wall time on 1 thread over wall time on 2 threads, same impact, same run (the median of
    /// the repeats' ratios).
    pub speedup_1_to_2: Option<f64>,
    /// Wall time on 1 thread (s).
    pub wall_1_thread_s: f64,
    /// Repeats: 1-thread and `threads`-thread runs alternate this many times; the wall times
    /// above are medians.
    #[serde(default = "one")]
    pub repeats: usize,
    /// Wall time of each repeat on `threads` threads (s), in run order.
    #[serde(default)]
    pub wall_s_runs: Vec<f64>,
    /// Wall time of each repeat on 1 thread (s), in run order.
    #[serde(default)]
    pub wall_1_thread_s_runs: Vec<f64>,
    /// Seconds per engine stage on `threads` threads (the last repeat).
    pub stages: BTreeMap<String, f64>,
    /// Seconds per engine stage on 1 thread (the last repeat): over `stages`, each stage's
    /// speed-up.
    #[serde(default)]
    pub stages_1_thread: BTreeMap<String, f64>,
    /// Impacts the surface had taken before the timed one.
    pub surface_impacts: u32,
    /// The bare kernel-sum loop over the same pairs, timed in the same run.
    #[serde(default)]
    pub ceiling: Option<Ceiling>,
    /// The pair pass's path on this CPU (`grit_sph::pair_pass`): figures of two machines
    /// compare only where it is the same.
    #[serde(default)]
    pub pair_pass: String,
}

/// The ceiling of the pair loops: after every step of one more run of the same impact on 1
/// thread, the bare Shepard sum Σ_j V_j W_ij (eq. 9 denominator) over the pairs that step used
/// (`World::kernel_sum_ceiling`), timed alone. No step can run its pair loops faster than this
/// one loop over the same pairs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ceiling {
    /// Steps the loop ran after (every step of the impact whose pairs were still current).
    pub steps: u64,
    /// Seconds per step of the loop, 1 thread.
    pub s_per_step: f64,
    /// Pair terms per step (every used pair from each end).
    pub pair_terms_per_step: f64,
    /// Pair terms per second, 1 thread.
    pub pair_terms_per_s: f64,
    /// particles / `s_per_step`: the particle-steps per second per thread a step made of this
    /// loop alone would reach.
    pub particle_steps_per_s: f64,
    /// The full step's time on 1 thread (`wall_1_thread_s` / steps) over `s_per_step`: how many
    /// bare kernel sums the step costs.
    pub full_step_over_ceiling: f64,
}

fn one() -> usize {
    1
}

/// Seconds per engine stage of the last impact `s` ran, by stage name.
fn breakdown(s: &Sample) -> BTreeMap<String, f64> {
    // The fluid, grain and flow stages do not run in an impact scene: no rows of zeros.
    s.last_timers()
        .breakdown()
        .into_iter()
        .filter(|&(_, v)| v > 0.0)
        .map(|(k, v)| (k.to_string(), v))
        .collect()
}

/// The middle value (the mean of the two middle ones for an even count).
fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Times the next impact of `sample` on 1 thread and on `threads` threads, each from a copy of
/// the same state, so both runs do bitwise the same work (the engine is deterministic). The two
/// alternate `repeats` times and the figures are medians: on a shared machine one pair of runs
/// can give a speed-up anywhere from 1.4 to 1.9 (docs/performance.md).
pub fn impact(sample: &Sample, threads: usize, repeats: usize) -> Result<ImpactBench, SampleError> {
    let timed = |n: usize| -> Result<(f64, Sample), SampleError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| SampleError::Checkpoint(format!("thread pool: {e}")))?;
        let mut s = sample.clone();
        let t0 = Instant::now();
        grit_sph::polling::install_polling(&pool, || s.run_next().map(|_| ()))?;
        Ok((t0.elapsed().as_secs_f64(), s))
    };
    let repeats = repeats.max(1);
    let (mut walls1, mut walls, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    let (mut last, mut last_one) = (None, None);
    for _ in 0..repeats {
        let (wall1, one) = timed(1)?;
        last_one = Some(breakdown(&one));
        let (wall, many) = if threads == 1 {
            (wall1, one)
        } else {
            timed(threads)?
        };
        walls1.push(wall1);
        walls.push(wall);
        ratios.push(wall1 / wall);
        last = Some(many);
    }
    let many = last.expect("at least one repeat ran");
    let (wall, wall1) = (median(&walls), median(&walls1));
    let r = many.records().last().expect("one impact ran");
    let particles = many.last_particles();
    let ps = particles as f64 * r.outcome.steps as f64;
    let ceiling = ceiling(sample)?.map(|(steps, seconds, terms)| {
        let s_per_step = seconds / steps as f64;
        Ceiling {
            steps,
            s_per_step,
            pair_terms_per_step: terms as f64 / steps as f64,
            pair_terms_per_s: terms as f64 / seconds,
            particle_steps_per_s: particles as f64 / s_per_step,
            full_step_over_ceiling: wall1 / r.outcome.steps as f64 / s_per_step,
        }
    });
    Ok(ImpactBench {
        particles,
        steps: r.outcome.steps,
        wall_s: wall,
        particle_steps_per_s: ps / wall,
        particle_steps_per_s_per_thread: ps / wall / threads as f64,
        threads,
        speedup_1_to_2: (threads == 2).then(|| median(&ratios)),
        wall_1_thread_s: wall1,
        repeats,
        wall_s_runs: walls,
        wall_1_thread_s_runs: walls1,
        stages: breakdown(&many),
        stages_1_thread: last_one.unwrap_or_default(),
        surface_impacts: sample.impacts_done(),
        ceiling,
        pair_pass: grit_sph::pair_pass().to_string(),
    })
}

/// Runs the next impact of `sample` once more on 1 thread and times the bare kernel sum after
/// every step: (steps timed, seconds, pair terms), or None when no step had current pairs.
fn ceiling(sample: &Sample) -> Result<Option<(u64, f64, u64)>, SampleError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| SampleError::Checkpoint(format!("thread pool: {e}")))?;
    let (mut steps, mut seconds, mut terms) = (0u64, 0.0, 0u64);
    let mut time_it = |w: &World| {
        let t0 = Instant::now();
        // black_box: the sum is otherwise unused and the loop would be optimised away.
        if let Some(c) = black_box(w.kernel_sum_ceiling()) {
            seconds += t0.elapsed().as_secs_f64();
            steps += 1;
            terms += c.pair_terms;
        }
    };
    let mut s = sample.clone();
    pool.install(|| {
        s.run_next_observed(&|| false, Some(&mut time_it))
            .map(|_| ())
    })?;
    Ok((steps > 0).then_some((steps, seconds, terms)))
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&[7.0]), 7.0);
    }
}
