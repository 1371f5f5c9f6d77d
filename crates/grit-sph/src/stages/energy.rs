//! The energy equation of the solids whose pressure law reads a specific internal energy e
//! (a Mie–Grüneisen EOS, AWJ paper eq. 24; docs/jet.md#energy): ρ ė = σ:D plus the heat the
//! solid's artificial viscosity dissipates (Monaghan 1992, eq. 2.27), gathered per particle in
//! the form that returns exactly the work its pair forces take from the motion.

use rayon::prelude::*;

use super::pairs::{pairs_of, PairCache};
use super::{BodyConst, ParTasks, SphView, StepCtx, MIN_SUPPORT_NEIGHBOURS};
use crate::fluid;
use crate::math::{Matrix, Vector};
use crate::particles::{Particles, KINEMATIC};

/// Whether some body integrates an energy: only then do its same-body pairs need a pass of
/// their own.
pub(crate) fn any_solid_energy(bc: &[BodyConst]) -> bool {
    bc.iter().any(BodyConst::has_energy)
}

/// Adds to `heat` (J/kg/s, one per particle) the energy rate of each particle that carries an
/// energy, from its same-body pairs at velocities `vel`: the stress power
/// −Σ_j m_j v_ij·(σ_i/(ρ_i² Γ_i)) ∇_i W_ij, particle i's share of the work of the forces' stress
/// term (seed eqs. 6, 9), and, with the solid's artificial viscosity
/// (`Settings::solid_viscosity`), the heat ½ m_j Π_ij v_ij·∇_i W_ij it dissipates. `sh` holds the
/// Shepard sums Γ; summed in row order.
/// A particle carries an energy when its body's pressure law reads one, it moves by its forces
/// (not kinematic: a target's fixed edge follows its prescribed motion) and it has a full
/// support (the forces' own test); every other particle's rate stays 0.
pub(crate) fn solid_energy_rates(
    ctx: &StepCtx<'_>,
    cache: &PairCache,
    sh: &[f64],
    vel: &[Vector],
    heat: &mut [f64],
) {
    let (s, hi, av) = (ctx.sph(), ctx.half, ctx.settings.solid_viscosity);
    let SphView { p, k, bc, .. } = s;
    let h = k.h;
    heat.par_iter_mut()
        .par_tasks()
        .enumerate()
        .for_each(|(i, q)| {
            let c = &bc[p.body[i] as usize];
            // A fragment (too few neighbours) takes no stress force and flies ballistically, so
            // no stress power either: its pairs would heat it through a vanishing Γ_i.
            let whole = cache.count[i] >= MIN_SUPPORT_NEIGHBOURS;
            if !(c.has_energy() && p.flags[i] & KINEMATIC == 0 && whole) {
                return;
            }
            let pr = c.pressure(p.rho[i], p.rho0[i], p.energy[i]);
            let a = (p.sdev[i] - Matrix::identity() * pr) / (p.rho[i] * p.rho[i] * sh[i]);
            for (j, pair) in pairs_of(s, hi, cache, i) {
                let vij = vel[i] - vel[j];
                let grad = pair.xij * pair.dw_r;
                *q -= p.mass[j] * vij.dot(&(a * grad));
                if let Some(av) = &av {
                    let rho_mean = 0.5 * (p.rho[i] + p.rho[j]);
                    let pi = av.pi_ab(pair.xij, vij, c.sound, rho_mean, h);
                    *q += fluid::viscous_heating(p.mass[j], pi, vij, grad);
                }
            }
        });
}

/// Adds `heat` · `dt` to every particle's internal energy (`heat` is 0 wherever
/// [`solid_energy_rates`] left a particle out).
pub(crate) fn add_heat(p: &mut Particles, heat: &[f64], dt: f64) {
    p.energy
        .par_iter_mut()
        .zip(heat.par_iter())
        .par_tasks()
        .for_each(|(e, &q)| *e += q * dt);
}
