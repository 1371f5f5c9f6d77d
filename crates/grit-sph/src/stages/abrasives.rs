//! The grains' part of a step (docs/jet.md#grains-in-the-world): the fluid's porosity from the
//! grains (the AWJ paper eq. 20), the coupling forces between grains and fluid (eqs. 42–50), the
//! penalty contact between grains and target particles (eqs. 12–14), and the DEM advance of the
//! grains (eq. 1) in as many sub-steps of the SPH step as the DEM's own limit asks.
//!
//! Every loop runs in grain order and then particle order on one thread: a scene holds tens of
//! grains and a few hundred particles near them, and the sums stay independent of the thread
//! count.

use super::StepCtx;
use crate::coupling::{self, sphere_force, FluidView, Pair};
use crate::dem::penalty_force;
use crate::error::InputError;
use crate::math::{cross, Vector};
use crate::particles::Particles;
use crate::world::Abrasives;

/// The coupled fluid's particles and their pairs with the grains, found once a step at the
/// step's starting positions and used by both the porosity and the forces.
#[derive(Debug, Clone, Default)]
pub(crate) struct CouplingFrame {
    /// World indices of the coupled fluid body's particles, in order; the pairs' fluid indices
    /// point into this list.
    pub fluid: Vec<usize>,
    /// Grain–fluid pairs within R_c (`coupling::find_pairs`).
    pub pairs: Vec<Pair>,
}

/// Forces and torques on each grain from the fluid and the target, in the plane model's units
/// (N/m and N·m/m) until [`advance`] turns them into the sphere's.
#[derive(Debug, Clone, Default)]
pub(crate) struct GrainLoads {
    pub force: Vec<Vector>,
    pub torque: Vec<f64>,
}

impl GrainLoads {
    fn reset(&mut self, n: usize) {
        self.force.clear();
        self.force.resize(n, Vector::zeros());
        self.torque.clear();
        self.torque.resize(n, 0.0);
    }
}

/// The porosity ε of every particle into `porosity` (eq. 20 for the coupled fluid's particles,
/// 1 for every other), and the frame the coupling forces reuse.
pub(crate) fn grain_porosity(
    p: &Particles,
    ab: &Abrasives,
    porosity: &mut Vec<f64>,
) -> Result<CouplingFrame, InputError> {
    porosity.clear();
    porosity.resize(p.len(), 1.0);
    let Some(fb) = ab.fluid_body else {
        return Ok(CouplingFrame::default());
    };
    let fluid: Vec<usize> = (0..p.len()).filter(|&i| p.body[i] as usize == fb).collect();
    if ab.dem.grains.is_empty() || fluid.is_empty() {
        return Ok(CouplingFrame {
            fluid,
            pairs: Vec::new(),
        });
    }
    let pos: Vec<Vector> = fluid.iter().map(|&i| p.pos[i]).collect();
    let pairs = coupling::find_pairs(&ab.coupling, &pos, &ab.dem.grains)?;
    let eps = coupling::porosity(&ab.coupling, fluid.len(), &ab.dem.grains, &pairs);
    for (&i, &e) in fluid.iter().zip(&eps.values) {
        porosity[i] = e;
    }
    Ok(CouplingFrame { fluid, pairs })
}

/// The coupling of eqs. 42–50 at the particles' present state: the coupled fluid's particles
/// of `frame` gathered into a [`FluidView`] with their `porosity` and θ_a (`theta`, pressure
/// and laminar parts of the fluid's acceleration), both per world particle. None when no
/// grain has fluid within R_c.
pub(crate) fn evaluate_coupling(
    p: &Particles,
    ab: &Abrasives,
    fluid_props: &crate::fluid::Fluid,
    frame: &CouplingFrame,
    porosity: &[f64],
    theta: &[Vector],
) -> Result<Option<coupling::CouplingForces>, InputError> {
    if frame.pairs.is_empty() {
        return Ok(None);
    }
    let idx = &frame.fluid;
    let gather_v = |a: &[Vector]| -> Vec<Vector> { idx.iter().map(|&i| a[i]).collect() };
    let gather_s = |a: &[f64]| -> Vec<f64> { idx.iter().map(|&i| a[i]).collect() };
    let (pos, vel, theta_f) = (gather_v(&p.pos), gather_v(&p.vel), gather_v(theta));
    let (mass, rho_bar, eps) = (gather_s(&p.mass), gather_s(&p.rho), gather_s(porosity));
    let view = FluidView {
        position: &pos,
        velocity: &vel,
        mass: &mass,
        rho_bar: &rho_bar,
    };
    coupling::coupling_forces(
        &ab.coupling,
        fluid_props,
        view,
        &eps,
        &theta_f,
        &ab.dem.grains,
        &frame.pairs,
    )
    .map(Some)
}

/// The coupling forces of eqs. 42–50 ([`evaluate_coupling`]) with the fluid body of `ab`, if it
/// has one: F_af onto `loads` of each grain, and the reaction F_fa/m_a onto the acceleration
/// `acc` of each fluid particle.
pub(crate) fn coupling_forces(
    ctx: &StepCtx<'_>,
    ab: &Abrasives,
    frame: &CouplingFrame,
    porosity: &[f64],
    theta: &[Vector],
    acc: &mut [Vector],
    loads: &mut GrainLoads,
) -> Result<(), InputError> {
    let Some(fb) = ab.fluid_body else {
        return Ok(());
    };
    let p = &*ctx.p;
    let fluid_props = ctx.bodies[fb].fluid().expect("checked by set_abrasives");
    let Some(f) = evaluate_coupling(p, ab, fluid_props, frame, porosity, theta)? else {
        return Ok(());
    };
    for (load, on) in loads.force.iter_mut().zip(&f.on_grains) {
        *load += on;
    }
    for (&i, on) in frame.fluid.iter().zip(&f.on_fluid) {
        acc[i] += on / p.mass[i];
    }
    Ok(())
}

/// The penalty contact (eqs. 12–14) between every grain and the deformable particles within
/// d_ini of its surface: the force on each particle into `contact_force`, the reaction and its
/// torque about the grain's centre into `loads`. d_ini is the particle spacing, and Δt the SPH
/// step. Returns every grain that touches now, in grain order, with its approach speed along the
/// normal of its first contact in particle order.
pub(crate) fn penalty(
    ctx: &StepCtx<'_>,
    ab: &Abrasives,
    contact_force: &mut [Vector],
    loads: &mut GrainLoads,
) -> Vec<(usize, f64)> {
    let (p, bc, d_ini, dt) = (&*ctx.p, ctx.bc, ctx.settings.spacing_m, ctx.dt);
    let grains = &ab.dem.grains;
    let mut touches = Vec::new();
    if grains.is_empty() {
        return touches;
    }
    // The deformable particles sorted on x; each grain scans its window.
    let mut order: Vec<usize> = (0..p.len())
        .filter(|&i| bc[p.body[i] as usize].deformable)
        .collect();
    order.sort_by(|&a, &b| p.pos[a].x.total_cmp(&p.pos[b].x).then(a.cmp(&b)));
    let xs: Vec<f64> = order.iter().map(|&i| p.pos[i].x).collect();
    let mut near = Vec::new();
    for (g, grain) in grains.iter().enumerate() {
        let reach = grain.radius_m + d_ini;
        let lo = xs.partition_point(|&x| x < grain.pos.x - reach);
        let hi = xs.partition_point(|&x| x <= grain.pos.x + reach);
        near.clear();
        near.extend(
            order[lo..hi]
                .iter()
                .copied()
                .filter(|&i| (p.pos[i] - grain.pos).norm() < reach),
        );
        near.sort_unstable();
        for &i in &near {
            let Some(c) =
                penalty_force(p.pos[i], p.vel[i], p.mass[i], grain, d_ini, ab.penalty, dt)
            else {
                continue;
            };
            if touches.last().is_none_or(|&(t, _)| t != g) {
                let n = (c.point - grain.pos) / grain.radius_m;
                touches.push((g, (grain.vel - p.vel[i]).dot(&n)));
            }
            contact_force[i] += c.force_on_particle;
            loads.force[g] -= c.force_on_particle;
            loads.torque[g] += cross(c.point - grain.pos, -c.force_on_particle);
        }
    }
    touches
}

/// Advances the grains by the SPH step `dt` in n = ⌈dt / Δt_dem⌉ equal DEM sub-steps
/// (`Dem::time_step`, the paper's (2π/α_tn)√(m/k_n)), holding the fluid's and the target's loads
/// of this step; the grain–grain and grain–wall contacts are re-evaluated each sub-step. The
/// loads arrive per metre of depth and act on the sphere each grain stands for as
/// `sphere_force` of them. Returns n.
pub(crate) fn advance(ab: &mut Abrasives, dt: f64, loads: &GrainLoads) -> Result<u32, InputError> {
    let dem = &mut ab.dem;
    if dem.grains.is_empty() {
        return Ok(0);
    }
    let n = (dt / dem.time_step()).ceil().max(1.0) as u32;
    let force: Vec<Vector> = dem
        .grains
        .iter()
        .zip(&loads.force)
        .map(|(g, &f)| sphere_force(f, g.radius_m))
        .collect();
    let torque: Vec<f64> = dem
        .grains
        .iter()
        .zip(&loads.torque)
        .map(|(g, &t)| t * (4.0 / 3.0 * g.radius_m))
        .collect();
    let sub = dt / n as f64;
    for _ in 0..n {
        dem.step_loaded(sub, &force, &torque)?;
    }
    Ok(n)
}

/// Zeroed loads for the grains of `ab`.
pub(crate) fn fresh_loads(ab: &Abrasives, loads: &mut GrainLoads) {
    loads.reset(ab.dem.grains.len());
}
