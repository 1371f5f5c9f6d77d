//! Water on the target (docs/jet.md#water-on-the-target): the fluid–solid pairs of the AWJ
//! paper's "interaction force F_fs solved by SPH integration". The target's particles stand in
//! the water's continuity as moving neighbours (eq. 22 over every neighbour), and each pair
//! pushes both particles apart with the two-phase pressure term of Colagrossi & Landrini (2003),
//! −V_a V_b (P_a + P_b) ∇_a W_ab, plus Monaghan's artificial viscosity (eq. 26). The solid's own
//! sums (kernel sums, stress, forces) stay same-body: the water loads its surface from outside.

use rayon::prelude::*;

use super::{accel_and_theta, BodyConst, ParTasks, SphView, StepCtx};
use crate::fluid::{self, ArtificialViscosity};
use crate::math::Vector;
use crate::neighbours::NeighbourLists;

/// The fluid–solid pairs of particle `i` within the kernel's support: (j, x_ij, ∇_i W_ij), in
/// its row's order. x_ji = −x_ij bit for bit, so both ends see the same pair turned round.
fn cross_pairs<'a>(
    s: SphView<'a>,
    cross: &'a NeighbourLists,
    i: usize,
) -> impl Iterator<Item = (usize, Vector, Vector)> + 'a {
    let (p, k) = (s.p, s.k);
    let support2 = k.radius() * k.radius();
    cross.of(i).iter().filter_map(move |&j| {
        let j = j as usize;
        let xij = p.pos[i] - p.pos[j];
        let r2 = xij.norm_squared();
        if r2 >= support2 || r2 == 0.0 {
            return None;
        }
        let r = r2.sqrt();
        let (_, dw) = k.w_dw(r);
        Some((j, xij, xij * (dw / r)))
    })
}

/// Adds to the continuity rates `drho` of the fluid particles (eq. 22) the terms of their solid
/// neighbours: ρ̄_a (m_b/ρ_b) v_ab·∇_a W_ab, so the target bounds the water as a moving wall.
pub(crate) fn interface_continuity(ctx: &StepCtx<'_>, drho: &mut [f64]) {
    let (s, cross) = (ctx.sph(), ctx.cross);
    let p = s.p;
    drho.par_iter_mut()
        .par_tasks()
        .enumerate()
        .for_each(|(i, rate)| {
            if s.bc[p.body[i] as usize].fluid.is_none() {
                return;
            }
            let (rho_a, v_a) = (p.rho[i], p.vel[i]);
            let add: f64 = cross_pairs(s, cross, i)
                .map(|(j, _, grad)| {
                    fluid::continuity_rate(rho_a, p.mass[j], p.rho[j], v_a - p.vel[j], grad)
                })
                .sum();
            *rate += add;
        });
}

/// The artificial-viscosity coefficients of a fluid–solid pair: the mean of the two phases'
/// (the fluid's, and `solid` or else the fluid's again), as the pair takes the mean of their
/// sound speeds and densities.
fn pair_viscosity(
    fluid: ArtificialViscosity,
    solid: Option<ArtificialViscosity>,
) -> ArtificialViscosity {
    let solid = solid.unwrap_or(fluid);
    ArtificialViscosity {
        alpha: 0.5 * (fluid.alpha + solid.alpha),
        beta: 0.5 * (fluid.beta + solid.beta),
    }
}

/// Adds the fluid–solid pair accelerations to `accel` of both sides, and their pressure part to
/// `theta` of the fluid side (θ_a of eq. 43 then holds the whole pressure gradient a fluid
/// particle feels). Per pair (a fluid, b solid, ρ̄ the fluid's porosity-weighted density, ρ the
/// solid's), on a: −(m_b/(ρ̄_a ρ_b))(P_a + P_b)∇_a W_ab − m_b Π_ab ∇_a W_ab, and b gets the same
/// with a and b swapped, so the pair's forces cancel; Π_ab with the mean of the fluid's and the
/// solid's viscosity (`Settings::solid_viscosity`). `state` holds each particle's pressure and
/// sound speed (`particle_state`); the solid's pressure is cut at the fluid's lowest, since the
/// water cannot pull harder on the surface than it can hold together. Each particle gathers in
/// its own row's order.
pub(crate) fn interface_forces(
    ctx: &StepCtx<'_>,
    state: &[(f64, f64)],
    accel: &mut [Vector],
    theta: &mut [Vector],
) {
    let (s, cross, solid_viscosity) = (ctx.sph(), ctx.cross, ctx.settings.solid_viscosity);
    let SphView { p, k, bc, .. } = s;
    let h = k.h;
    accel_and_theta(accel, theta)
        .par_tasks()
        .enumerate()
        .for_each(|(i, (acc, th))| {
            let ci = &bc[p.body[i] as usize];
            if cross.of(i).is_empty() || !(ci.deformable || ci.fluid.is_some()) {
                return;
            }
            let (rho_i, v_i) = (p.rho[i], p.vel[i]);
            let (mut a, mut pressure) = (Vector::zeros(), Vector::zeros());
            for (j, xij, grad) in cross_pairs(s, cross, i) {
                let cj = &bc[p.body[j] as usize];
                let fc = ci
                    .fluid
                    .or(cj.fluid)
                    .expect("a cross pair has a fluid side");
                let floor = fc.min_pressure();
                let side = |k: usize, c: &BodyConst| {
                    let (pr, snd) = state[k];
                    (if c.fluid.is_some() { pr } else { pr.max(floor) }, snd)
                };
                let ((p_i, c_i), (p_j, c_j)) = (side(i, ci), side(j, cj));
                let rho_j = p.rho[j];
                let f_p = -grad * (p.mass[j] / (rho_i * rho_j) * (p_i + p_j));
                let av = pair_viscosity(fc.av(), solid_viscosity);
                let pi = av.pi_ab(
                    xij,
                    v_i - p.vel[j],
                    0.5 * (c_i + c_j),
                    0.5 * (rho_i + rho_j),
                    h,
                );
                pressure += f_p;
                a += f_p + fluid::artificial_viscosity_acceleration(p.mass[j], pi, grad);
            }
            *acc += a;
            if ci.fluid.is_some() {
                *th += pressure;
            }
        });
}
