//! Per-stage wall-clock counters, so a benchmark can say where the time goes.

use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The stages of one engine step, in the order `World::step` runs them (docs/design.md#the-engine-step).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Cell-list neighbour search (rebuilt only when the skin is used up).
    Neighbours,
    /// Shepard sums and correction matrices L (eqs. 8, 9).
    KernelSums,
    /// Velocity gradient and density rate (eqs. 5, 14, 15). `World::step` sums them in the kernel
    /// sums' pass and books their time there, so this counter stays at zero in a step;
    /// `World::run_stage` runs that pass.
    Rates,
    /// EOS, Jaumann rate, return mapping, heating, damage (eqs. 11, 13, 18–20).
    Stress,
    /// Stress divergence and hourglass forces (eqs. 6, 16).
    Forces,
    /// Contact detection and forces (eqs. 21–29), and the abrasive grains' coupling, penalty
    /// contact and DEM sub-steps (the AWJ paper eqs. 1, 12–14, 42–50).
    Contact,
    /// Rigid-body force, torque and motion (eq. 17).
    Rigid,
    /// Particle integration and the failure checks.
    Integrate,
    /// Shepard density filter (eq. 12), deletion of failed particles, next time step.
    Housekeeping,
}

impl Stage {
    /// All stages, in step order.
    pub const ALL: [Stage; 9] = [
        Stage::Neighbours,
        Stage::KernelSums,
        Stage::Rates,
        Stage::Stress,
        Stage::Forces,
        Stage::Contact,
        Stage::Rigid,
        Stage::Integrate,
        Stage::Housekeeping,
    ];

    /// Stable name used in reports and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Neighbours => "neighbours",
            Stage::KernelSums => "kernel_sums",
            Stage::Rates => "rates",
            Stage::Stress => "stress",
            Stage::Forces => "forces",
            Stage::Contact => "contact",
            Stage::Rigid => "rigid",
            Stage::Integrate => "integrate",
            Stage::Housekeeping => "housekeeping",
        }
    }
}

/// Accumulated seconds per stage.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Timers {
    seconds: [f64; 9],
}

impl Timers {
    /// Runs `f`, adding its wall time to `stage`.
    #[inline]
    pub fn time<R>(&mut self, stage: Stage, f: impl FnOnce() -> R) -> R {
        let t0 = Instant::now();
        let r = f();
        self.seconds[stage as usize] += t0.elapsed().as_secs_f64();
        r
    }

    /// Seconds spent in `stage` so far.
    pub fn seconds(&self, stage: Stage) -> f64 {
        self.seconds[stage as usize]
    }

    /// (name, seconds) for every stage.
    pub fn breakdown(&self) -> Vec<(&'static str, f64)> {
        Stage::ALL
            .iter()
            .map(|s| (s.name(), self.seconds(*s)))
            .collect()
    }

    /// Total seconds over all stages.
    pub fn total(&self) -> f64 {
        self.seconds.iter().sum()
    }

    /// Zeroes all counters.
    pub fn reset(&mut self) {
        self.seconds = [0.0; 9];
    }
}
