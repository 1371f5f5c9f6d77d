//! The fluid's parts of the step (the AWJ paper eqs. 20–27, docs/jet.md#water-in-the-engine):
//! the continuity rate of the porosity-weighted density ρ̄ and its update, then the
//! accelerations from the updated density, both summed over the same-body pairs the kernel
//! sums cached, and the fluid's time-step limits.

use rayon::prelude::*;

use super::pairs::{pairs_of, PairCache};
use super::{accel_and_theta, BodyConst, ParTasks, SphView, StepCtx};
use crate::eos::MieGruneisen;
use crate::fluid::{self, ArtificialViscosity, Fluid};
use crate::math::Vector;
use crate::particles::{Particles, KINEMATIC};

/// The porosity the fluid's EOS reads: 1, so the pressure is the EOS's at ρ̄ itself. The grains
/// reach the water through the coupling forces alone; ρ̄/ε, the paper's other reading, blew the
/// jet up where grains cross slow water (docs/jet.md#porosity-and-the-eos).
const EOS_POROSITY: f64 = 1.0;

/// The constants of a fluid body the stages read, copied out of its [`Fluid`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct FluidConst {
    eos: MieGruneisen,
    min_pressure: f64,
    /// Kinematic viscosity ν = μ/ρ0 of the Shao–Lo term (eq. 25).
    pub nu: f64,
    av: ArtificialViscosity,
    /// δ c0 of the density diffusion (`Fluid::density_diffusion`; times h in the sum).
    delta_c0: f64,
    /// The densities a free particle is kept within (`Fluid::density_range` times ρ0).
    keep: Option<(f64, f64)>,
    /// Density up to which the EOS is evaluated: 0.9 of its singular compression, so a particle
    /// crushed beyond it gets a large finite pressure instead of a division by zero.
    rho_cap: f64,
}

impl FluidConst {
    /// The constants of `f`.
    pub fn of(f: &Fluid) -> FluidConst {
        FluidConst {
            eos: f.eos,
            min_pressure: f.min_pressure_pa,
            nu: f.kinematic_viscosity(),
            av: f.artificial_viscosity,
            delta_c0: f.density_diffusion * f.eos.c0_m_s,
            keep: f
                .density_range
                .map(|[lo, hi]| (lo * f.eos.rho0_kg_m3, hi * f.eos.rho0_kg_m3)),
            rho_cap: f.eos.rho0_kg_m3 * (1.0 + 0.9 * f.eos.singular_compression()),
        }
    }

    /// `Fluid::pressure` (eq. 24 at ρ = ρ̄/ε, cut at the cavitation pressure) on its cold curve,
    /// e = 0 (docs/jet.md#energy: the water's energy equation was measured and not adopted),
    /// with the density capped below the singular compression.
    #[inline]
    pub fn pressure(&self, rho_bar: f64, porosity: f64) -> f64 {
        self.eos
            .pressure((rho_bar / porosity).min(self.rho_cap), 0.0)
            .max(self.min_pressure)
    }

    /// Whether a free particle of density `rho_bar` has left the fluid's density range.
    #[inline]
    pub fn out_of_range(&self, rho_bar: f64) -> bool {
        self.keep
            .is_some_and(|(lo, hi)| !(lo..=hi).contains(&rho_bar))
    }

    /// The lowest gauge pressure the fluid sustains (its cavitation cut, Pa).
    #[inline]
    pub fn min_pressure(&self) -> f64 {
        self.min_pressure
    }

    /// Its artificial-viscosity coefficients (eq. 26).
    #[inline]
    pub fn av(&self) -> ArtificialViscosity {
        self.av
    }

    /// `Fluid::sound_speed` (the cold curve's √(dp/dρ) at ρ = ρ̄/ε), capped like the pressure.
    #[inline]
    pub fn sound_speed(&self, rho_bar: f64, porosity: f64) -> f64 {
        self.eos.sound_speed((rho_bar / porosity).min(self.rho_cap))
    }
}

/// Continuity rates dρ̄/dt (eq. 22, plus the fluid's density diffusion where it has one) of
/// every fluid particle, walls included, into `drho` (0 for the other particles), from the pairs
/// `cache` holds for this step; each particle gathers its pairs in its own row's order.
pub(crate) fn fluid_continuity(ctx: &StepCtx<'_>, cache: &PairCache, drho: &mut Vec<f64>) {
    let (s, hi) = (ctx.sph(), ctx.half);
    let p = s.p;
    let h = s.k.h;
    drho.clear();
    drho.par_extend((0..p.len()).into_par_iter().par_tasks().map(|i| {
        let Some(f) = s.bc[p.body[i] as usize].fluid else {
            return 0.0;
        };
        let (rho_a, v_a) = (p.rho[i], p.vel[i]);
        let rate: f64 = pairs_of(s, hi, cache, i)
            .map(|(j, pair)| {
                let grad = pair.xij * pair.dw_r;
                fluid::continuity_rate(rho_a, p.mass[j], p.rho[j], v_a - p.vel[j], grad)
            })
            .sum();
        if f.delta_c0 == 0.0 {
            return rate;
        }
        // Molteni–Colagrossi: ψ_ab·∇_a W_ab = 2 (ρ̄_b − ρ̄_a)(−dW/dr / r), a Laplacian of ρ̄.
        let diffusion: f64 = pairs_of(s, hi, cache, i)
            .map(|(j, pair)| {
                let vol = p.mass[j] / p.rho[j];
                2.0 * (p.rho[j] - rho_a) * (-pair.dw_r) * vol
            })
            .sum();
        rate + f.delta_c0 * h * diffusion
    }));
}

/// Pressure and sound speed of every particle once per step, read by each of its pairs: a fluid
/// particle's from its EOS (eq. 24 at ρ̄, [`EOS_POROSITY`]), a deformable one's from its
/// material's pressure law and sound speed (for the fluid–solid pairs), zero otherwise.
pub(crate) fn particle_state(p: &Particles, bc: &[BodyConst]) -> Vec<(f64, f64)> {
    (0..p.len())
        .into_par_iter()
        .par_tasks()
        .map(|i| {
            let c = &bc[p.body[i] as usize];
            match c.fluid {
                Some(f) => (
                    f.pressure(p.rho[i], EOS_POROSITY),
                    f.sound_speed(p.rho[i], EOS_POROSITY),
                ),
                None if c.deformable => (c.particle_pressure(p, i), c.sound),
                None => (0.0, 0.0),
            }
        })
        .collect()
}

/// Accelerations of the fluid particles into `accel`: pressure gradient (eq. 23) with the
/// pressures of `state` ([`particle_state`]), Shao–Lo laminar viscosity (eq. 25), Monaghan
/// artificial viscosity (eqs. 26–27) and the settings' gravity; `theta` gets the pressure and
/// laminar parts alone, θ_a of eq. 43, which the coupling interpolates at the grains (0 for other
/// particles). Kinematic fluid particles (the walls) get the pair terms alone, which the
/// integration ignores and [`wall_forces`] sums; the other bodies' particles keep what `accel`
/// holds. Reads the densities after this step's continuity update, so density and velocity
/// advance as a symplectic pair.
pub(crate) fn fluid_accelerations(
    ctx: &StepCtx<'_>,
    cache: &PairCache,
    state: &[(f64, f64)],
    accel: &mut [Vector],
    theta: &mut Vec<Vector>,
) {
    let (s, hi, g) = (ctx.sph(), ctx.half, ctx.settings.gravity_m_s2);
    let SphView { p, k, bc, .. } = s;
    let h = k.h;
    let fc = |i: usize| bc[p.body[i] as usize].fluid;
    theta.clear();
    theta.resize(p.len(), Vector::zeros());
    accel_and_theta(accel, theta)
        .par_tasks()
        .enumerate()
        .for_each(|(i, (acc, th))| {
            let Some(f) = fc(i) else { return };
            let (rho_a, (p_a, c_a), v_a) = (p.rho[i], state[i], p.vel[i]);
            let shao_lo = fluid::ShaoLo { nu: f.nu, h };
            // θ beside the total, each summed in the pairs' order: the total keeps the bits it
            // had before θ was split out.
            let (mut a, mut t) = (Vector::zeros(), Vector::zeros());
            for (j, pair) in pairs_of(s, hi, cache, i) {
                let (m_b, rho_b, (p_b, c_b)) = (p.mass[j], p.rho[j], state[j]);
                let grad = pair.xij * pair.dw_r;
                let v_ab = v_a - p.vel[j];
                let pressure = fluid::pressure_acceleration(m_b, p_a, rho_a, p_b, rho_b, grad);
                let laminar = shao_lo.acceleration(m_b, rho_a, rho_b, pair.xij, v_ab, grad);
                a += pressure;
                a += laminar;
                t += pressure + laminar;
                let pi =
                    f.av.pi_ab(pair.xij, v_ab, 0.5 * (c_a + c_b), 0.5 * (rho_a + rho_b), h);
                a += fluid::artificial_viscosity_acceleration(m_b, pi, grad);
            }
            *th = t;
            *acc = if p.flags[i] & KINEMATIC != 0 {
                a
            } else {
                a + g
            };
        });
}

/// The load of a fluid on one of its wall particles in a step (the AWJ paper eqs. 23, 25–27).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallLoad {
    /// The body of the wall particle.
    pub body: u32,
    /// Its position (m).
    pub position: Vector,
    /// The force of the fluid's pair terms on it, m a (N/m).
    pub force: Vector,
}

/// The force m a of the pair accelerations of [`fluid_accelerations`] on every kinematic fluid
/// particle (a fluid's walls), in particle order, so sums over them do not depend on the
/// thread count.
pub(crate) fn wall_forces(ctx: &StepCtx<'_>, accel: &[Vector], loads: &mut Vec<WallLoad>) {
    let (p, bc) = (&*ctx.p, ctx.bc);
    loads.clear();
    for (i, a) in accel.iter().enumerate().take(p.len()) {
        let b = p.body[i] as usize;
        if bc[b].fluid.is_some() && p.flags[i] & KINEMATIC != 0 {
            loads.push(WallLoad {
                body: b as u32,
                position: p.pos[i],
                force: a * p.mass[i],
            });
        }
    }
}

/// Advances the density ρ̄ of every fluid particle by the step's `dt` with the rates `drho` of
/// [`fluid_continuity`], before the accelerations read it (as the solid's stress stage
/// advances ρ before its forces).
pub(crate) fn fluid_density(ctx: &mut StepCtx<'_>, drho: &[f64]) {
    let (bc, dt) = (ctx.bc, ctx.dt);
    let p = &mut *ctx.p;
    p.rho
        .par_iter_mut()
        .zip(p.body.par_iter())
        .zip(drho.par_iter())
        .par_tasks()
        .for_each(|((rho, &b), &rate)| {
            if bc[b as usize].fluid.is_some() {
                *rho += rate * dt;
            }
        });
}

/// The smallest time step the fluid particles allow (s; ∞ without any): the CFL limit
/// `cfl` · h / max(c + |v|) with c the EOS's sound speed at each particle's density, and the
/// viscous diffusion limit 0.125 h²/ν of an explicit step (Morris, Fox & Zhu 1997).
pub(crate) fn fluid_dt(p: &Particles, bc: &[BodyConst], h: f64, cfl: f64) -> f64 {
    let fc = |i: usize| bc[p.body[i] as usize].fluid;
    let smax = (0..p.len())
        .into_par_iter()
        .par_tasks()
        .filter_map(|i| fc(i).map(|f| f.sound_speed(p.rho[i], EOS_POROSITY) + p.vel[i].norm()))
        .reduce(|| 0.0, f64::max);
    let nu_max = bc
        .iter()
        .filter_map(|c| c.fluid.map(|f| f.nu))
        .fold(0.0, f64::max);
    let mut dt = f64::INFINITY;
    if smax > 0.0 {
        dt = cfl * h / smax;
    }
    if nu_max > 0.0 {
        dt = dt.min(0.125 * h * h / nu_max);
    }
    dt
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_engine_s_pressure_is_the_fluid_s() {
        let w = Fluid::water();
        let c = FluidConst::of(&w);
        for rho in [990.0, 999.99, 1000.0, 1000.1, 1010.0, 1200.0] {
            assert_eq!(
                c.pressure(rho, 1.0).to_bits(),
                w.pressure(rho, 1.0, 0.0).to_bits()
            );
            assert_eq!(
                c.sound_speed(rho, 1.0).to_bits(),
                w.sound_speed(rho, 1.0).to_bits()
            );
        }
        // A law that turns singular: crushed beyond 0.9 of it, large, finite and no larger.
        let mut f = Fluid::water();
        f.eos.s2 = 0.0;
        f.eos.s3 = 0.0;
        let c = FluidConst::of(&f);
        let eta_s = f.eos.singular_compression();
        let crushed = c.pressure(1000.0 * (1.0 + 1.1 * eta_s), 1.0);
        assert!(crushed.is_finite() && crushed > 0.0);
        assert_eq!(crushed, c.pressure(1000.0 * (1.0 + 0.9 * eta_s), 1.0));
    }
}
