//! One step's hold on a world: the [`StepCtx`] its stages share, the scratch arrays they write,
//! and one method per stage of `World::step` that runs it and books what it returns.

use super::{Abrasives, GrainHit, NumericalWork, World};
use crate::contact::ContactPair;
use crate::error::{InputError, SimError};
use crate::math::Vector;
use crate::neighbours::ContactLists;
use crate::stages::{
    self, Blowup, BodyConst, KernelSums, PairCache, PairForce, PassedThrough, StepCtx,
};

/// Scratch arrays rebuilt every step (not part of a checkpoint).
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    /// Same-body pairs of this step with their kernel values (the kernel sums fill it).
    pub pairs: PairCache,
    /// The force terms each same-body pair's particles share (the forces fill it).
    pub pair_forces: Vec<PairForce>,
    /// Volumes, Shepard sums, correction matrices and velocity gradients of the kernel sums.
    pub sums: KernelSums,
    /// Particle volumes after the stress stage: read by the forces, the contact and the density
    /// filter, which all run before ρ changes again.
    pub vol: Vec<f64>,
    /// Each particle's zero-rate yield stress, kept while its ε_p and T stay (the stress stage).
    pub yield_memo: Vec<stages::YieldMemo>,
    /// Accelerations of the forces.
    pub acc: Vec<Vector>,
    /// Contact force on each particle.
    pub contact_force: Vec<Vector>,
    /// Continuity rates dρ̄/dt of the fluid particles (the fluid stage fills it).
    pub drho: Vec<f64>,
    /// The force the fluids' pair terms put on each of their kinematic particles.
    pub wall_loads: Vec<stages::WallLoad>,
    /// Porosity ε of every particle (eq. 20; 1 away from grains), for the coupling's averages
    /// and drag (the fluid's EOS reads ρ̄ alone: docs/jet.md#porosity-and-the-eos).
    pub porosity: Vec<f64>,
    /// Pressure and sound speed of every particle this step (`stages::particle_state`).
    pub state: Vec<(f64, f64)>,
    /// θ_a of the AWJ paper eq. 43 per particle: the fluid's pressure and laminar acceleration.
    pub theta: Vec<Vector>,
    /// Energy rates per particle this step (J/kg/s): the solids' stress power and heating.
    pub heat: Vec<f64>,
    /// Velocities at the start of the integration, then the step's mean velocities, for the
    /// solids' energy at mid-step.
    pub vel_start: Vec<Vector>,
    /// The grains' pairs with the fluid at the step's start.
    pub frame: stages::CouplingFrame,
    /// Loads on the grains from the fluid and the target.
    pub loads: stages::GrainLoads,
}

/// A world lent to one step: the context its stages share, and what each stage writes besides
/// the particles and bodies.
pub(super) struct Step<'a> {
    pub ctx: StepCtx<'a>,
    /// Steps taken before this one (for error reports).
    steps: u64,
    pub scratch: &'a mut Scratch,
    contacts: &'a mut [ContactPair],
    /// Contact pair c's candidate primary particles (`WorldLists::contact`).
    lists: &'a mut [ContactLists],
    work: &'a mut NumericalWork,
    abrasives: Option<&'a mut Abrasives>,
}

impl World {
    /// Lends the world to one step with the bodies' constants `bc`; the neighbour lists must be
    /// built.
    pub(super) fn begin_step<'a>(&'a mut self, bc: &'a [BodyConst]) -> Step<'a> {
        let World {
            settings,
            kernel,
            bodies,
            contacts,
            particles,
            time,
            steps,
            dt,
            work,
            abrasives,
            nbrs,
            scratch,
            ..
        } = self;
        Step {
            ctx: StepCtx {
                p: particles,
                bodies,
                bc,
                settings,
                kernel,
                same: &nbrs.same,
                half: &nbrs.half,
                cross: &nbrs.cross,
                time: *time,
                dt: *dt,
            },
            steps: *steps,
            scratch,
            contacts,
            lists: &mut nbrs.contact,
            work,
            abrasives: abrasives.as_mut(),
        }
    }
}

impl Step<'_> {
    /// A failure of this step, reported at its start.
    fn failure(&self, what: String) -> SimError {
        SimError {
            step: self.steps,
            time_s: self.ctx.time,
            what,
        }
    }

    /// Shepard sums, correction matrices and velocity gradients, and the pair cache.
    pub fn kernel_sums(&mut self) {
        let sc = &mut *self.scratch;
        stages::kernel_sums(&self.ctx, &mut sc.pairs, &mut sc.sums);
    }

    /// The grains' porosity field and their pairs with the fluid, at the step's start.
    pub fn grain_porosity(&mut self) {
        let Some(ab) = &self.abrasives else { return };
        let sc = &mut *self.scratch;
        // A grain set that `set_abrasives` accepted always gives pairs.
        sc.frame = stages::grain_porosity(self.ctx.p, ab, &mut sc.porosity)
            .expect("the grains and coupling were checked when set");
    }

    /// The solids' stress update; books the plastic work.
    pub fn stress(&mut self) {
        let sc = &mut *self.scratch;
        let plastic_work = stages::stress(&mut self.ctx, &sc.sums.gradv, &mut sc.yield_memo);
        self.work.plastic -= plastic_work;
    }

    /// The fluid's continuity rates, with the target's particles in them, and its new density.
    pub fn fluid_density(&mut self) {
        if !stages::any_fluid(self.ctx.bc) {
            return;
        }
        let sc = &mut *self.scratch;
        stages::fluid_continuity(&self.ctx, &sc.pairs, &mut sc.drho);
        if self.ctx.cross.pairs() > 0 {
            stages::interface_continuity(&self.ctx, &mut sc.drho);
        }
        stages::fluid_density(&mut self.ctx, &sc.drho);
    }

    /// The solids' accelerations; books the hourglass work.
    pub fn forces(&mut self) {
        let sc = &mut *self.scratch;
        stages::volumes(self.ctx.p, &mut sc.vol);
        let (pairs, sums, vol) = (&sc.pairs, &sc.sums, &sc.vol);
        let hg = stages::forces(
            &self.ctx,
            pairs,
            sums,
            vol,
            &mut sc.acc,
            &mut sc.pair_forces,
        );
        self.work.hourglass += hg;
    }

    /// The fluid's accelerations, the fluid–solid pairs' on both sides, and the wall loads.
    pub fn fluid_forces(&mut self) {
        let ctx = &self.ctx;
        if !stages::any_fluid(ctx.bc) {
            return;
        }
        let sc = &mut *self.scratch;
        sc.state = stages::particle_state(ctx.p, ctx.bc);
        let (pairs, state) = (&sc.pairs, &sc.state);
        stages::fluid_accelerations(ctx, pairs, state, &mut sc.acc, &mut sc.theta);
        if ctx.cross.pairs() > 0 {
            stages::interface_forces(ctx, state, &mut sc.acc, &mut sc.theta);
        }
        stages::wall_forces(ctx, &sc.acc, &mut sc.wall_loads);
    }

    /// Contact between bodies; books the dashpots' work. Fails when a particle has passed
    /// through a surface.
    pub fn contact(&mut self) -> Result<(), SimError> {
        let sc = &mut *self.scratch;
        let through = stages::contact(
            &mut self.ctx,
            self.lists,
            &sc.vol,
            self.contacts,
            &mut sc.contact_force,
            &mut self.work.contact_damping,
        );
        let Some(PassedThrough {
            pair,
            particle: i,
            distance,
        }) = through
        else {
            return Ok(());
        };
        let c = &self.contacts[pair];
        let bodies = &self.ctx.bodies;
        Err(self.failure(format!(
            "particle {} of body '{}' passed through the surface of body '{}': distance {:.3e} m < 0",
            self.ctx.p.id[i], bodies[c.secondary].name, bodies[c.primary].name, distance
        )))
    }

    /// A grain stage's failure as the step's.
    fn grain_failure(&self, e: InputError) -> SimError {
        self.failure(format!("abrasives: {e}"))
    }

    /// Fresh loads on the grains, then the fluid's coupling forces on them and theirs on it.
    pub fn grain_coupling(&mut self) -> Result<(), SimError> {
        let Some(ab) = self.abrasives.as_deref() else {
            return Ok(());
        };
        let sc = &mut *self.scratch;
        stages::fresh_loads(ab, &mut sc.loads);
        let (frame, eps, theta) = (&sc.frame, &sc.porosity, &sc.theta);
        let coupled =
            stages::coupling_forces(&self.ctx, ab, frame, eps, theta, &mut sc.acc, &mut sc.loads);
        coupled.map_err(|e| self.grain_failure(e))
    }

    /// The penalty contact between grains and deformable particles, and the log of the grains'
    /// contact starts.
    pub fn grain_contact(&mut self) {
        let Some(ab) = self.abrasives.as_deref_mut() else {
            return;
        };
        let sc = &mut *self.scratch;
        let touches = stages::penalty(&self.ctx, ab, &mut sc.contact_force, &mut sc.loads);
        let mut now = vec![false; ab.dem.grains.len()];
        for &(g, normal_speed_m_s) in &touches {
            now[g] = true;
            let grain = &mut ab.dem.grains[g];
            if !grain.in_contact {
                ab.hits.push(GrainHit {
                    t_s: self.ctx.time,
                    speed_m_s: grain.vel.norm(),
                    normal_speed_m_s,
                    first: !grain.touched,
                });
            }
            grain.touched = true;
        }
        for (grain, now) in ab.dem.grains.iter_mut().zip(now) {
            grain.in_contact = now;
        }
        ab.steps_in_contact += touches.len() as u64;
    }

    /// The grains' DEM sub-steps under this step's loads.
    pub fn grain_dem(&mut self) -> Result<(), SimError> {
        let Some(ab) = self.abrasives.as_deref_mut() else {
            return Ok(());
        };
        match stages::advance(ab, self.ctx.dt, &self.scratch.loads) {
            Ok(n) => {
                ab.substeps = n;
                Ok(())
            }
            Err(e) => Err(self.grain_failure(e)),
        }
    }

    /// The rigid bodies' motion, and their particles'.
    pub fn rigid(&mut self) {
        stages::rigid(&mut self.ctx);
    }

    /// Integrates the particles, then the solids' energy; fails when the step has blown up.
    pub fn integrate(&mut self) -> Result<(), SimError> {
        let solid_energy = stages::any_solid_energy(self.ctx.bc);
        let sc = &mut *self.scratch;
        if solid_energy {
            sc.vel_start.clone_from(&self.ctx.p.vel);
        }
        let blowup = stages::integrate(&mut self.ctx, &sc.acc, &sc.contact_force);
        let what = match blowup {
            None => {
                if solid_energy {
                    self.solid_energy();
                }
                return Ok(());
            }
            Some(Blowup::Particle { index: i, what }) => {
                let p = &self.ctx.p;
                format!(
                    "particle {} of body '{}' at ({:.4e}, {:.4e}) m: {what}",
                    p.id[i], self.ctx.bodies[p.body[i] as usize].name, p.pos[i].x, p.pos[i].y
                )
            }
            Some(Blowup::Rigid { body }) => format!(
                "rigid body '{}': position or velocity is not finite",
                self.ctx.bodies[body].name
            ),
        };
        Err(self.failure(what))
    }

    /// Advances the internal energy of the energy-carrying solids over the step just
    /// integrated, at the step's mean velocities: with them the stress forces' work on the
    /// motion is exactly what the particles' energy gains (docs/jet.md#energy).
    fn solid_energy(&mut self) {
        let sc = &mut *self.scratch;
        // The step's start velocities become its mean ones in place.
        for (v, end) in sc.vel_start.iter_mut().zip(&self.ctx.p.vel) {
            *v = (*v + end) * 0.5;
        }
        sc.heat.clear();
        sc.heat.resize(self.ctx.p.len(), 0.0);
        let (pairs, sh, v_mid) = (&sc.pairs, &sc.sums.shepard, &sc.vel_start);
        stages::solid_energy_rates(&self.ctx, pairs, sh, v_mid, &mut sc.heat);
        stages::add_heat(self.ctx.p, &sc.heat, self.ctx.dt);
    }
}
