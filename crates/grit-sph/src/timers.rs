//! Per-stage wall-clock counters, so a benchmark can say where the time goes.

use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The stages of one engine step, in the order `World::step` runs them (docs/design.md#the-engine-step).
/// A scene without fluid, grains or open boundaries leaves their stages at zero.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Cell-list neighbour search (rebuilt only when the skin is used up).
    Neighbours,
    /// Shepard sums, correction matrices L and velocity gradients (eqs. 8, 9, 15), in one pass.
    KernelSums,
    /// The coupled fluid's porosity from the grains (the AWJ paper eq. 20), with the grain–fluid
    /// pairs the coupling forces reuse.
    GrainPorosity,
    /// Continuity, Jaumann rate, return mapping, heating, damage (eqs. 5, 11, 13, 18–20).
    Stress,
    /// The fluid's continuity (the AWJ paper eq. 22, the target's particles as moving walls) and
    /// its density update.
    FluidDensity,
    /// Stress divergence and hourglass forces (eqs. 6, 16).
    Forces,
    /// The fluid's pressure, viscous and fluid–solid accelerations (the AWJ paper eqs. 23–27) and
    /// the loads on its walls.
    FluidForces,
    /// Contact detection and forces between bodies (eqs. 21–29).
    Contact,
    /// The coupling forces between grains and fluid (the AWJ paper eqs. 42–50).
    GrainCoupling,
    /// The penalty contact between grains and deformable particles (the AWJ paper eqs. 12–14).
    GrainContact,
    /// The grains' DEM sub-steps (the AWJ paper eq. 1).
    GrainDem,
    /// Rigid-body force, torque and motion (eq. 17).
    Rigid,
    /// Particle integration, the solids' energy equation and the failure checks.
    Integrate,
    /// Shepard density filter (eq. 12), deletion of failed particles, next time step.
    Housekeeping,
    /// Open boundaries: the outflows' deletions of fluid particles and grains, the inflows' new
    /// rows (docs/jet.md#inflow-and-outflow).
    Flow,
}

impl Stage {
    /// Number of stages.
    pub const COUNT: usize = 15;

    /// All stages, in step order.
    pub const ALL: [Stage; Stage::COUNT] = [
        Stage::Neighbours,
        Stage::KernelSums,
        Stage::GrainPorosity,
        Stage::Stress,
        Stage::FluidDensity,
        Stage::Forces,
        Stage::FluidForces,
        Stage::Contact,
        Stage::GrainCoupling,
        Stage::GrainContact,
        Stage::GrainDem,
        Stage::Rigid,
        Stage::Integrate,
        Stage::Housekeeping,
        Stage::Flow,
    ];

    /// Stable name used in reports and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Neighbours => "neighbours",
            Stage::KernelSums => "kernel_sums",
            Stage::GrainPorosity => "grain_porosity",
            Stage::Stress => "stress",
            Stage::FluidDensity => "fluid_density",
            Stage::Forces => "forces",
            Stage::FluidForces => "fluid_forces",
            Stage::Contact => "contact",
            Stage::GrainCoupling => "grain_coupling",
            Stage::GrainContact => "grain_contact",
            Stage::GrainDem => "grain_dem",
            Stage::Rigid => "rigid",
            Stage::Integrate => "integrate",
            Stage::Housekeeping => "housekeeping",
            Stage::Flow => "flow",
        }
    }
}

/// Accumulated seconds per stage.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Timers {
    seconds: [f64; Stage::COUNT],
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
        self.seconds = [0.0; Stage::COUNT];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_stage_has_its_own_counter_and_name() {
        for (k, s) in Stage::ALL.iter().enumerate() {
            assert_eq!(*s as usize, k, "{s:?} out of step order");
        }
        let mut names: Vec<&str> = Stage::ALL.iter().map(|s| s.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Stage::COUNT);
        let mut t = Timers::default();
        t.time(Stage::Flow, || {
            std::thread::sleep(std::time::Duration::from_millis(1))
        });
        assert!(t.seconds(Stage::Flow) > 0.0);
        assert_eq!(t.total(), t.seconds(Stage::Flow));
        assert_eq!(t.breakdown().last().map(|b| b.0), Some("flow"));
    }
}
