//! The stages of one explicit step (docs/design.md "Engine step"; seed sections 2 and 3), as free
//! functions: each reads the step's [`StepCtx`], writes into the outputs it is given and returns
//! the rest. `World::step` is the one place that runs them, in order.

mod abrasives;
mod ceiling;
mod contact;
mod density_filter;
mod energy;
mod fluid;
mod forces;
mod integrate;
mod interface;
mod kernel_sums;
pub(crate) mod pairs;
mod rigid;
mod stress;
mod time_step;

pub(crate) use abrasives::{
    advance, coupling_forces, evaluate_coupling, fresh_loads, grain_porosity, penalty,
    CouplingFrame, GrainLoads,
};
pub(crate) use ceiling::ceiling;
pub use ceiling::CeilingPass;
pub(crate) use contact::{contact, PassedThrough};
pub(crate) use density_filter::filter_density;
pub(crate) use energy::{add_heat, any_solid_energy, solid_energy_rates};
use fluid::fluid_dt;
pub use fluid::WallLoad;
pub(crate) use fluid::{
    fluid_accelerations, fluid_continuity, fluid_density, particle_state, wall_forces, FluidConst,
};
pub(crate) use forces::{forces, PairForce};
pub(crate) use integrate::{integrate, Blowup};
pub(crate) use interface::{interface_continuity, interface_forces};
pub(crate) use kernel_sums::{kernel_sums, KernelSums};
pub(crate) use pairs::rows_mut;
pub(crate) use pairs::PairCache;
pub(crate) use rigid::rigid;
pub(crate) use stress::{stress, YieldMemo};
pub(crate) use time_step::stable_dt;

use rayon::iter::{IndexedParallelIterator, MaxLen, MinLen};

use crate::body::Body;
use crate::eos::EquationOfState;
use crate::jh2::{self, Jh2Laws};
use crate::kernel::Kernel;
use crate::material::Material;
use crate::math::Vector;
use crate::neighbours::{HalfIndex, NeighbourLists};
use crate::particles::Particles;
use crate::world::Settings;

/// A deformable particle with fewer same-body neighbours inside the kernel support than this is
/// a fragment torn off its body: its kernel sums no longer describe a continuum (the Shepard
/// normalisation of eq. 9 divides by a near-empty sum and blows up), so it flies ballistically,
/// keeping its stress, until it rejoins material. A particle inside a body has about 44.
pub const MIN_SUPPORT_NEIGHBOURS: u32 = 6;

/// Pair separation (in h) below which the hourglass force of eq. 16 stops growing as 1/r².
pub const HG_MIN_SEPARATION_H: f64 = 0.4;

/// Smallest number of particles one rayon task takes: below it the per-task overhead costs more
/// than the work.
const MIN_LEN: usize = 64;

/// Largest number of particles one rayon task takes. The work of a step is uneven along the
/// index (the grain's particles and the free surface do less, the few hundred particles under
/// the grain do the contact), and rayon's adaptive splitting can leave a few large tasks, so one
/// thread sits idle while the other finishes; small tasks let the idle thread steal
/// (docs/performance.md, "Smaller tasks").
const MAX_LEN: usize = 256;

/// The task sizes of every parallel loop over particles. Each task writes only its own
/// particles, every sum across particles is gathered serially, and the one parallel reduction
/// (the time step's maximum speed) does not depend on order, so the task sizes change the speed,
/// never the results.
pub(crate) trait ParTasks: IndexedParallelIterator {
    /// This loop, split into tasks of `MIN_LEN` to `MAX_LEN` particles.
    fn par_tasks(self) -> MaxLen<MinLen<Self>> {
        self.with_min_len(MIN_LEN).with_max_len(MAX_LEN)
    }
}

impl<I: IndexedParallelIterator> ParTasks for I {}

/// Each particle's acceleration beside its θ, for the loops that add to both in one pass.
pub(crate) fn accel_and_theta<'a>(
    accel: &'a mut [Vector],
    theta: &'a mut [Vector],
) -> impl IndexedParallelIterator<Item = (&'a mut Vector, &'a mut Vector)> {
    use rayon::prelude::*;
    accel.par_iter_mut().zip(theta.par_iter_mut())
}

/// Particle volumes V_i = m_i/ρ_i into `out`, taken once per particle so that no sum over pairs
/// divides for its neighbour's volume.
pub(crate) fn volumes(p: &Particles, out: &mut Vec<f64>) {
    use rayon::prelude::*;
    out.clear();
    out.par_extend(
        p.mass
            .par_iter()
            .zip(&p.rho)
            .par_tasks()
            .map(|(m, r)| m / r),
    );
}

/// Per-body constants the stages need, looked up by particle.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct BodyConst {
    pub deformable: bool,
    /// Small-strain bulk modulus of the pressure law (the EOS's ρ0 c0² where there is one).
    pub bulk: f64,
    pub shear: f64,
    pub youngs: f64,
    pub sound: f64,
    /// The material's EOS; `None` is the linear law of seed eq. 11.
    pub eos: Option<EquationOfState>,
    /// Density up to which the EOS is evaluated: 0.9 of its singular compression, so a
    /// particle crushed beyond it gets a large finite pressure instead of a division by zero.
    pub rho_cap: f64,
    /// The constants of a fluid body (AWJ paper eqs. 21–27); `None` for solids.
    pub fluid: Option<FluidConst>,
    /// The JH-2 laws of a rock (AWJ paper eqs. 38–41); `None` for every other material.
    pub jh2: Option<Jh2Laws>,
}

impl BodyConst {
    /// Pressure of a particle of density `rho`, reference density `rho0` and specific internal
    /// energy `e`: K (ρ/ρ0 − 1) (seed eq. 11, which ignores e), or the Mie–Grüneisen law (AWJ
    /// paper eq. 24).
    #[inline]
    pub fn pressure(&self, rho: f64, rho0: f64, e: f64) -> f64 {
        match &self.eos {
            None => self.bulk * (rho / rho0 - 1.0),
            Some(eos) => eos.pressure(rho.min(self.rho_cap), e),
        }
    }

    /// The pressure of particle `i` of `p`: [`Self::pressure`], or for a JH-2 rock the
    /// polynomial EOS with the particle's bulking pressure, never below −T (1 − D) (AWJ paper
    /// eqs. 40–41, `jh2::pressure_of`).
    #[inline]
    pub fn particle_pressure(&self, p: &Particles, i: usize) -> f64 {
        match &self.jh2 {
            None => self.pressure(p.rho[i], p.rho0[i], p.energy[i]),
            Some(l) => jh2::pressure_of(l, p.rho[i], p.bulking[i], p.damage[i]),
        }
    }

    /// Whether the body's particles integrate an internal energy: a solid whose pressure law
    /// reads one (Mie–Grüneisen). A fluid stays on its cold curve (docs/jet.md#energy), and
    /// JH-2's polynomial reads none.
    #[inline]
    pub fn has_energy(&self) -> bool {
        self.deformable && self.eos.is_some_and(|e| e.reads_energy())
    }
}

impl BodyConst {
    /// The constants of a deformable body of material `m`.
    pub fn of(m: &Material) -> BodyConst {
        BodyConst {
            deformable: true,
            bulk: m.pressure_bulk_modulus(),
            shear: m.shear_modulus(),
            youngs: m.youngs_modulus_pa,
            sound: m.sound_speed(),
            eos: m.eos,
            rho_cap: m.eos.map_or(f64::INFINITY, |e| {
                e.reference_density() * (1.0 + 0.9 * e.singular_compression())
            }),
            fluid: None,
            jh2: m.jh2(),
        }
    }

    /// True for the particles the integration moves: deformable or fluid.
    #[inline]
    pub fn integrated(&self) -> bool {
        self.deformable || self.fluid.is_some()
    }
}

/// Whether any body is a fluid: solid-only scenes skip every fluid pass.
pub(crate) fn any_fluid(bc: &[BodyConst]) -> bool {
    bc.iter().any(|c| c.fluid.is_some())
}

/// The constants of each body, by body index (all zero and not deformable for a rigid body;
/// a fluid body has only its `fluid` constants).
pub(crate) fn body_consts(bodies: &[Body]) -> Vec<BodyConst> {
    bodies
        .iter()
        .map(|b| match (b.material(), b.fluid()) {
            (Some(m), _) => BodyConst::of(m),
            (None, Some(f)) => BodyConst {
                fluid: Some(FluidConst::of(f)),
                ..BodyConst::default()
            },
            (None, None) => BodyConst::default(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pressure_law_is_the_material_s() {
        // AISI 304 has no EOS: eq. 11 with K from E and ν, the same bits as before the EOS.
        let steel = Material::aisi304();
        let c = BodyConst::of(&steel);
        let (rho, rho0) = (7911.3, steel.density_kg_m3);
        assert_eq!(c.bulk, steel.bulk_modulus());
        assert_eq!(
            c.pressure(rho, rho0, 0.0).to_bits(),
            (steel.bulk_modulus() * (rho / rho0 - 1.0)).to_bits()
        );
        // Copper: the Mie–Grüneisen cold curve, with ρ0 c0² as the bulk modulus and in the
        // CFL's sound speed.
        let cu = Material::copper();
        let eos = cu.eos.unwrap();
        let c = BodyConst::of(&cu);
        assert_eq!(c.bulk, eos.bulk_modulus());
        assert_eq!(c.bulk, 8960.0 * 3940.0 * 3940.0);
        let rho = 1.05 * cu.density_kg_m3;
        assert_eq!(
            c.pressure(rho, cu.density_kg_m3, 0.0),
            eos.pressure(rho, 0.0)
        );
        assert_eq!(
            c.pressure(rho, cu.density_kg_m3, 1e4),
            eos.pressure(rho, 1e4)
        );
        assert!(c.pressure(rho, cu.density_kg_m3, 0.0) > cu.bulk_modulus() * 0.05);
        let g = cu.shear_modulus();
        assert_eq!(
            c.sound,
            ((c.bulk + 4.0 / 3.0 * g) / cu.density_kg_m3).sqrt()
        );
        // Crushed past the singular compression: large, finite, and no larger than at the cap.
        let crushed = cu.density_kg_m3 * (1.0 + 1.1 * eos.singular_compression());
        let p = c.pressure(crushed, cu.density_kg_m3, 0.0);
        assert!(p.is_finite() && p > 0.0 && p == c.pressure(c.rho_cap, cu.density_kg_m3, 0.0));
    }
}

/// What the SPH sums over neighbours read: the particles, their neighbour lists, the kernel and
/// the per-body constants.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SphView<'a> {
    pub p: &'a Particles,
    pub nl: &'a NeighbourLists,
    pub k: &'a Kernel,
    pub bc: &'a [BodyConst],
}

/// What the stages of one step share (docs/design.md "Engine step"): the particles and bodies
/// they advance, the constants and neighbour lists they read, the clock and the time step.
/// `World::step` builds one per step; each stage takes it beside the outputs of its own, so a
/// stage's signature says what it writes.
pub(crate) struct StepCtx<'a> {
    /// The particles: the stress, fluid density, rigid and integration stages write them.
    pub p: &'a mut Particles,
    /// The bodies: the contact stage writes the rigid bodies' loads, the rigid stage their motion.
    pub bodies: &'a mut [Body],
    /// The bodies' constants, by body index.
    pub bc: &'a [BodyConst],
    /// The world's settings.
    pub settings: &'a Settings,
    /// The kernel W and its smoothing length h.
    pub kernel: &'a Kernel,
    /// Same-body neighbours, built before the step's first stage.
    pub same: &'a NeighbourLists,
    /// The unordered pair of each entry of `same`.
    pub half: &'a HalfIndex,
    /// Fluid–solid pairs (`WorldLists::cross`).
    pub cross: &'a NeighbourLists,
    /// Simulated time at the step's start (s).
    pub time: f64,
    /// The step's time step (s).
    pub dt: f64,
}

impl StepCtx<'_> {
    /// What the SPH sums read, over the particles as they are now.
    pub fn sph(&self) -> SphView<'_> {
        SphView {
            p: self.p,
            nl: self.same,
            k: self.kernel,
            bc: self.bc,
        }
    }
}
