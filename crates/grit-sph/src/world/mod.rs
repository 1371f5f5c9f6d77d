//! The world: bodies, particles and contacts, and the explicit step that advances them
//! (docs/design.md "Engine step"; seed section 2 for the solid, section 3 for contact).
//!
//! `step` lists the stages in order; each stage is a free function in `crate::stages` that this
//! module hands the world's arrays. Building a world is in `build`, its settings in `settings`,
//! what it reports about itself in `diagnostics`.

mod abrasives;
mod build;
mod diagnostics;
mod flow;
mod settings;

pub use crate::stages::{CeilingPass, WallLoad, HG_MIN_SEPARATION_H, MIN_SUPPORT_NEIGHBOURS};
pub use abrasives::{plane_mass, Abrasives, GrainContacts, GrainHit, GrainOutflow, PenaltyParams};
pub use diagnostics::{Energy, NumericalWork};
pub use flow::{Inflow, Nozzle, Outflow};
pub use settings::{DensityFilter, Settings, MAX_CFL};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::body::Body;
use crate::contact::{ContactPair, ContactParams};
use crate::error::{InputError, SimError};
use crate::kernel::Kernel;
use crate::math::Vector;
use crate::neighbours::{self, WorldLists};
use crate::particles::Particles;
use crate::stages::{
    self, Blowup, BodyConst, KernelSums, PairCache, PairForce, ParTasks, PassedThrough, SphView,
};
use crate::timers::{Stage, Timers};

/// Scratch arrays rebuilt every step (not part of a checkpoint).
#[derive(Debug, Clone, Default)]
struct Scratch {
    /// Same-body pairs of this step with their kernel values (the kernel sums fill it).
    pairs: PairCache,
    /// The force terms each same-body pair's particles share (the forces fill it).
    pair_forces: Vec<PairForce>,
    /// Volumes, Shepard sums, correction matrices and velocity gradients of the kernel sums.
    sums: KernelSums,
    /// Particle volumes after the stress stage: read by the forces, the contact and the density
    /// filter, which all run before ρ changes again.
    vol: Vec<f64>,
    /// Each particle's zero-rate yield stress, kept while its ε_p and T stay (the stress stage).
    yield_memo: Vec<stages::YieldMemo>,
    /// Accelerations of the forces.
    acc: Vec<Vector>,
    /// Contact force on each particle.
    contact_force: Vec<Vector>,
    /// Continuity rates dρ̄/dt of the fluid particles (the fluid stage fills it).
    drho: Vec<f64>,
    /// The force the fluids' pair terms put on each of their kinematic particles.
    wall_loads: Vec<WallLoad>,
    /// Porosity ε of every particle (eq. 20; 1 away from grains), for the coupling's averages
    /// and drag (the fluid's EOS reads ρ̄ alone: docs/jet.md#porosity-and-the-eos).
    porosity: Vec<f64>,
    /// Pressure and sound speed of every particle this step (`stages::particle_state`).
    state: Vec<(f64, f64)>,
    /// θ_a of the AWJ paper eq. 43 per particle: the fluid's pressure and laminar acceleration.
    theta: Vec<Vector>,
    /// Energy rates per particle this step (J/kg/s): the solids' stress power and heating.
    heat: Vec<f64>,
    /// Velocities at the start of the integration, then the step's mean velocities, for the
    /// solids' energy at mid-step.
    vel_start: Vec<Vector>,
    /// The grains' pairs with the fluid at the step's start.
    frame: stages::CouplingFrame,
    /// Loads on the grains from the fluid and the target.
    loads: stages::GrainLoads,
}

/// A 2D SPH scene: bodies, their particles, contact pairs, time.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct World {
    settings: Settings,
    kernel: Kernel,
    bodies: Vec<Body>,
    contacts: Vec<ContactPair>,
    #[serde(deserialize_with = "crate::particles::deserialize_filled")]
    particles: Particles,
    time: f64,
    steps: u64,
    dt: f64,
    next_id: u32,
    work: NumericalWork,
    /// Positions at the last neighbour build.
    x_build: Vec<Vector>,
    /// Inflows and outflows of fluid bodies; absent from the JSON of a world without any.
    #[serde(default, skip_serializing_if = "flow::Flow::is_empty")]
    flow: flow::Flow,
    /// Abrasive grains and their coupling; absent from the JSON of a world without them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    abrasives: Option<Abrasives>,
    #[serde(skip)]
    nbrs: WorldLists,
    #[serde(skip)]
    nbrs_valid: bool,
    #[serde(skip)]
    scratch: Scratch,
    #[serde(skip)]
    timers: Timers,
    /// The bodies' constants (`stages::body_consts`), kept between steps: a fluid's EOS scans
    /// for its singular compression, thousands of evaluations. `None` whenever a body may have
    /// changed (`body_mut`, a body added).
    #[serde(skip)]
    consts: Option<Vec<BodyConst>>,
}

impl World {
    /// An empty world with validated settings.
    pub fn new(settings: Settings) -> Result<Self, InputError> {
        settings.validate()?;
        let kernel = Kernel::new(settings.kernel, settings.h_over_dx * settings.spacing_m);
        Ok(World {
            settings,
            kernel,
            bodies: Vec::new(),
            contacts: Vec::new(),
            particles: Particles::default(),
            time: 0.0,
            steps: 0,
            dt: 0.0,
            next_id: 0,
            work: NumericalWork::default(),
            x_build: Vec::new(),
            flow: flow::Flow::default(),
            abrasives: None,
            nbrs: WorldLists::default(),
            nbrs_valid: false,
            scratch: Scratch::default(),
            timers: Timers::default(),
            consts: None,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }
    /// The kernel in use.
    pub fn kernel(&self) -> &Kernel {
        &self.kernel
    }
    /// Smoothing length h (m).
    pub fn h(&self) -> f64 {
        self.kernel.h
    }
    /// All bodies.
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }
    /// One body, mutable (to change a rigid body's motion or external force between phases).
    pub fn body_mut(&mut self, b: usize) -> &mut Body {
        self.consts = None;
        &mut self.bodies[b]
    }
    /// All particles.
    pub fn particles(&self) -> &Particles {
        &self.particles
    }
    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// The time step the next step will take (s); 0 before the first step.
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// Per-stage timers.
    pub fn timers(&self) -> &Timers {
        &self.timers
    }
    /// Per-stage timers, mutable (to reset between measurements).
    pub fn timers_mut(&mut self) -> &mut Timers {
        &mut self.timers
    }
    /// Work of numerical devices so far.
    pub fn numerical_work(&self) -> NumericalWork {
        self.work
    }
    /// The contact pairs.
    pub fn contacts(&self) -> &[ContactPair] {
        &self.contacts
    }
    /// Parameters of contact pair `c`, mutable (to end a settling phase's damping, say).
    pub fn contact_params_mut(&mut self, c: usize) -> &mut ContactParams {
        &mut self.contacts[c].params
    }
    /// Contact force on each particle in the last step (N/m); empty before the first step.
    pub fn contact_forces(&self) -> &[Vector] {
        &self.scratch.contact_force
    }
    /// Force per unit depth (N/m) that the pair terms of the fluid (the AWJ paper eqs. 23,
    /// 25–27) put on the kinematic particles of body `b` in the last step: the load on a fluid's
    /// walls. Zero before the first step and for other bodies.
    pub fn wall_force(&self, b: usize) -> Vector {
        self.scratch
            .wall_loads
            .iter()
            .filter(|l| l.body as usize == b)
            .fold(Vector::zeros(), |sum, l| sum + l.force)
    }
    /// The fluids' loads on each of their wall particles in the last step (N/m), in particle
    /// order: the pressure distribution along a wall ([`World::wall_force`] is their sum per
    /// body).
    pub fn wall_loads(&self) -> &[WallLoad] {
        &self.scratch.wall_loads
    }
    /// Neighbour count of each particle as last built (for reports).
    pub fn neighbour_pairs(&self) -> usize {
        self.nbrs.pairs()
    }

    /// The bodies' constants, from the kept copy when there is one.
    pub(crate) fn body_consts(&self) -> Vec<BodyConst> {
        self.consts
            .clone()
            .unwrap_or_else(|| stages::body_consts(&self.bodies))
    }

    /// The bodies' constants, computed once and kept until a body changes.
    fn kept_body_consts(&mut self) -> Vec<BodyConst> {
        if self
            .consts
            .as_ref()
            .is_none_or(|c| c.len() != self.bodies.len())
        {
            self.consts = Some(stages::body_consts(&self.bodies));
        }
        self.body_consts()
    }

    /// Reach of the neighbour lists: the kernel support plus the Verlet skin.
    fn neighbour_reach(&self) -> f64 {
        self.kernel.radius() + self.settings.skin_over_dx * self.settings.spacing_m
    }

    /// Rebuilds neighbour lists (`neighbours::build_for_bodies`).
    fn rebuild_neighbours(&mut self) {
        let radius = self.neighbour_reach();
        self.nbrs = neighbours::build_for_bodies(
            &self.particles,
            &self.bodies,
            &self.contacts,
            radius,
            self.kernel.radius(),
        );
        self.x_build = self.particles.pos.clone();
        self.nbrs_valid = true;
    }

    fn needs_rebuild(&self) -> bool {
        if !self.nbrs_valid || self.x_build.len() != self.particles.len() {
            return true;
        }
        let half = 0.5 * self.settings.skin_over_dx * self.settings.spacing_m;
        neighbours::stale(&self.particles.pos, &self.x_build, half)
    }

    /// Stable time step: CFL on the material signal speed plus particle speed, and the
    /// contact springs' period.
    fn compute_dt(&self) -> f64 {
        let bc = self.body_consts();
        stages::stable_dt(
            &self.particles,
            &bc,
            self.kernel.h,
            &self.settings,
            &self.contacts,
        )
    }

    /// The time step the next `step` will take: CFL on the current state, and the contact
    /// springs' period.
    pub fn next_dt(&self) -> f64 {
        if self.dt == 0.0 {
            self.compute_dt()
        } else {
            self.dt
        }
    }

    /// Counts `steps` steps of `dt_s` as taken without computing them, for a stretch in which
    /// nothing but a rigid body's free flight would happen (an impact's approach). The
    /// clock and the phase of the work done every k steps (the density filter, eq. 12) then
    /// stay those of the full run.
    pub fn count_skipped_steps(&mut self, steps: u64, dt_s: f64) {
        self.steps += steps;
        self.time += steps as f64 * dt_s;
    }

    /// Advances the world by one explicit step (docs/design.md "Engine step").
    pub fn step(&mut self) -> Result<(), SimError> {
        if self.dt == 0.0 {
            self.dt = self.compute_dt();
        }
        let dt = self.dt;
        let n = self.particles.len();
        let bc = self.kept_body_consts();

        let mut timers = std::mem::take(&mut self.timers);
        if self.needs_rebuild() {
            timers.time(Stage::Neighbours, || self.rebuild_neighbours());
        }
        // The rates are summed in the kernel sums' pass; their timer stays at zero in a step.
        timers.time(Stage::KernelSums, || self.kernel_sums(&bc));
        if let Some(ab) = &self.abrasives {
            let sc = &mut self.scratch;
            // A grain set that `set_abrasives` accepted always gives pairs.
            sc.frame = stages::grain_porosity(&self.particles, ab, &mut sc.porosity)
                .expect("the grains and coupling were checked when set");
        }
        timers.time(Stage::Stress, || self.stress(&bc, dt));
        timers.time(Stage::Forces, || self.forces(&bc, dt));
        let contact = timers.time(Stage::Contact, || {
            self.contact(&bc, dt)?;
            self.grains(&bc, dt)
        });
        timers.time(Stage::Rigid, || self.rigid(dt));
        let checked = timers.time(Stage::Integrate, || self.integrate(&bc, dt));
        self.timers = timers;
        contact?;
        checked?;
        self.time += dt;
        self.steps += 1;
        let mut timers = std::mem::take(&mut self.timers);
        let r = timers.time(Stage::Housekeeping, || self.housekeeping(&bc));
        self.timers = timers;
        debug_assert!(self.particles.len() <= n || !self.flow.inflows.is_empty());
        r
    }

    /// Runs one stage of `step` (docs/design.md "Engine step") on the current state without
    /// advancing time, so a benchmark can time the hot loops one by one. Stages after
    /// `Contact` move particles and are only timed inside `step`.
    pub fn run_stage(&mut self, stage: Stage) -> Result<(), InputError> {
        if self.dt == 0.0 {
            self.dt = self.compute_dt();
        }
        let dt = self.dt;
        let bc = self.kept_body_consts();
        let ready = self.nbrs_valid && self.scratch.pairs.count.len() == self.particles.len();
        if stage != Stage::Neighbours && !ready {
            // Every later stage reads the neighbour lists and the kernel-sum caches.
            self.rebuild_neighbours();
            self.kernel_sums(&bc);
        }
        match stage {
            Stage::Neighbours => self.rebuild_neighbours(),
            // The rates are summed in the kernel sums' pass.
            Stage::KernelSums | Stage::Rates => self.kernel_sums(&bc),
            Stage::Stress => self.stress(&bc, dt),
            Stage::Forces => self.forces(&bc, dt),
            Stage::Contact => {
                stages::volumes(&self.particles, &mut self.scratch.vol);
                // A surface particle passing through is a result of the state, not of timing.
                let _ = self.contact(&bc, dt);
            }
            other => {
                return Err(InputError::new(
                    "stage",
                    format!("{other:?} moves particles; time it with step()"),
                ))
            }
        }
        Ok(())
    }

    /// The bare kernel sum Γ_i = Σ_j V_j W_ij (eq. 9 denominator) over the same-body pairs the
    /// last step used, on the calling thread: the floor under any pair loop of the step, for a
    /// benchmark to time beside it (docs/performance.md, "The ceiling"). None before the first
    /// step and after particles were deleted, when those pairs are gone.
    pub fn kernel_sum_ceiling(&self) -> Option<CeilingPass> {
        let n = self.particles.len();
        let sc = &self.scratch;
        let fresh = self.nbrs_valid && sc.pairs.count.len() == n && sc.sums.vol.len() == n;
        fresh.then(|| {
            stages::ceiling(
                &self.particles,
                &self.nbrs.same,
                &sc.pairs,
                &sc.sums.vol,
                &self.kernel,
            )
        })
    }

    /// Steps until `t_end` (s) or until `stop` says so; returns the number of steps.
    pub fn run_until(
        &mut self,
        t_end: f64,
        mut stop: impl FnMut(&World) -> bool,
    ) -> Result<u64, SimError> {
        let s0 = self.steps;
        while self.time < t_end && !stop(self) {
            self.step()?;
        }
        Ok(self.steps - s0)
    }

    /// Shepard density filter (eq. 12) every `shepard_interval` steps, deletion of particles with
    /// D ≥ 1 and of fluid particles out of their density range, and the next time step.
    fn housekeeping(&mut self, bc: &[BodyConst]) -> Result<(), SimError> {
        let every = self.settings.shepard_interval as u64;
        if every > 0 && self.steps.is_multiple_of(every) {
            self.filter_density_with(bc);
        }
        // Deleted: solids at D ≥ 1, free fluid particles outside their fluid's density range.
        let p = &self.particles;
        let failed: Vec<bool> = (0..p.len())
            .into_par_iter()
            .par_tasks()
            .map(|i| {
                let free_fluid = bc[p.body[i] as usize]
                    .fluid
                    .filter(|_| p.flags[i] & crate::particles::KINEMATIC == 0);
                p.damage[i] >= 1.0 || free_fluid.is_some_and(|f| f.out_of_range(p.rho[i]))
            })
            .collect();
        if failed.iter().any(|&f| f) {
            for (i, &f) in failed.iter().enumerate() {
                if f {
                    let b = self.particles.body[i] as usize;
                    self.bodies[b].removed_mass_kg_m += self.particles.mass[i];
                    self.bodies[b].removed_particles += 1;
                }
            }
            let keep: Vec<bool> = failed.iter().map(|f| !f).collect();
            self.retain_particles(&keep);
        }
        self.flow_step(self.dt);
        self.grain_outflow_step();
        self.dt = self.compute_dt();
        Ok(())
    }

    /// Runs the configured density filter now (eq. 12, or its MLS form) and books the change
    /// of elastic energy as the filter's work; `step` calls it every `shepard_interval` steps.
    pub fn filter_density(&mut self) {
        let bc = self.kept_body_consts();
        self.filter_density_with(&bc);
    }

    fn filter_density_with(&mut self, bc: &[BodyConst]) {
        let before = self.energy().elastic;
        if !self.nbrs_valid || self.nbrs.same.start.len() != self.particles.len() + 1 {
            self.rebuild_neighbours();
        }
        stages::volumes(&self.particles, &mut self.scratch.vol);
        let s = self.sph(bc);
        let vol = &self.scratch.vol;
        self.particles.rho = stages::filter_density(s, vol, self.settings.density_filter);
        self.work.density_filter += self.energy().elastic - before;
    }

    // The stage calls of `step` and `run_stage`: each hands one stage of `crate::stages` the
    // arrays it reads and writes, and books what it returns.

    /// What the SPH sums of the stages read.
    fn sph<'a>(&'a self, bc: &'a [BodyConst]) -> SphView<'a> {
        SphView {
            p: &self.particles,
            nl: &self.nbrs.same,
            k: &self.kernel,
            bc,
        }
    }

    fn kernel_sums(&mut self, bc: &[BodyConst]) {
        let s = SphView {
            p: &self.particles,
            nl: &self.nbrs.same,
            k: &self.kernel,
            bc,
        };
        let (hi, sc) = (&self.nbrs.half, &mut self.scratch);
        stages::kernel_sums(s, hi, &mut sc.pairs, &mut sc.sums);
    }

    fn stress(&mut self, bc: &[BodyConst], dt: f64) {
        let beta = self.settings.taylor_quinney;
        let plastic_work = stages::stress(
            &mut self.particles,
            &self.bodies,
            bc,
            &self.scratch.sums.gradv,
            beta,
            dt,
            &mut self.scratch.yield_memo,
        );
        self.work.plastic -= plastic_work;
        if stages::any_fluid(bc) {
            let s = SphView {
                p: &self.particles,
                nl: &self.nbrs.same,
                k: &self.kernel,
                bc,
            };
            let sc = &mut self.scratch;
            stages::fluid_continuity(s, &self.nbrs.half, &sc.pairs, &mut sc.drho);
            if self.nbrs.cross.pairs() > 0 {
                stages::interface_continuity(s, &self.nbrs.cross, &mut sc.drho);
            }
            stages::fluid_density(&mut self.particles, bc, &sc.drho, dt);
        }
    }

    fn forces(&mut self, bc: &[BodyConst], dt: f64) {
        let s = SphView {
            p: &self.particles,
            nl: &self.nbrs.same,
            k: &self.kernel,
            bc,
        };
        let sc = &mut self.scratch;
        stages::volumes(s.p, &mut sc.vol);
        let hg = stages::forces(
            s,
            &self.nbrs.half,
            &sc.pairs,
            &sc.vol,
            &sc.sums.shepard,
            &sc.sums.gradv,
            &self.settings,
            dt,
            &mut sc.acc,
            &mut sc.pair_forces,
        );
        self.work.hourglass += hg;
        if stages::any_fluid(bc) {
            let g = self.settings.gravity_m_s2;
            sc.state = stages::particle_state(s.p, bc);
            let (hi, state) = (&self.nbrs.half, &sc.state);
            stages::fluid_accelerations(s, hi, &sc.pairs, state, g, &mut sc.acc, &mut sc.theta);
            if self.nbrs.cross.pairs() > 0 {
                let av = self.settings.solid_viscosity;
                let cross = &self.nbrs.cross;
                stages::interface_forces(s, cross, state, av, &mut sc.acc, &mut sc.theta);
            }
            stages::wall_forces(s.p, bc, &sc.acc, &mut sc.wall_loads);
        }
    }

    fn contact(&mut self, bc: &[BodyConst], dt: f64) -> Result<(), SimError> {
        let s = SphView {
            p: &self.particles,
            nl: &self.nbrs.same,
            k: &self.kernel,
            bc,
        };
        let through = stages::contact(
            s,
            &mut self.nbrs.contact,
            &self.scratch.vol,
            self.settings.spacing_m,
            dt,
            &mut self.contacts,
            &mut self.bodies,
            &mut self.scratch.contact_force,
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
        Err(SimError {
            step: self.steps,
            time_s: self.time,
            what: format!(
                "particle {} of body '{}' passed through the surface of body '{}': distance {:.3e} m < 0",
                self.particles.id[i], self.bodies[c.secondary].name, self.bodies[c.primary].name, distance
            ),
        })
    }

    /// The grains' part of the step (`stages::abrasives`): coupling forces on grains and fluid,
    /// the penalty contact with the deformable particles, then the grains' DEM sub-steps.
    fn grains(&mut self, bc: &[BodyConst], dt: f64) -> Result<(), SimError> {
        let Some(ab) = self.abrasives.as_mut() else {
            return Ok(());
        };
        let sc = &mut self.scratch;
        stages::fresh_loads(ab, &mut sc.loads);
        let err = |e: crate::error::InputError| SimError {
            step: self.steps,
            time_s: self.time,
            what: format!("abrasives: {e}"),
        };
        if let Some(fb) = ab.fluid_body {
            let fluid = self.bodies[fb].fluid().expect("checked by set_abrasives");
            let p = &self.particles;
            let (frame, eps, theta) = (&sc.frame, &sc.porosity, &sc.theta);
            stages::coupling_forces(p, ab, fluid, frame, eps, theta, &mut sc.acc, &mut sc.loads)
                .map_err(err)?;
        }
        let d_ini = self.settings.spacing_m;
        let cf = &mut sc.contact_force;
        let touches = stages::penalty(&self.particles, bc, ab, d_ini, dt, cf, &mut sc.loads);
        let mut now = vec![false; ab.dem.grains.len()];
        for &(g, normal_speed_m_s) in &touches {
            now[g] = true;
            let grain = &mut ab.dem.grains[g];
            if !grain.in_contact {
                ab.hits.push(GrainHit {
                    t_s: self.time,
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
        ab.substeps = stages::advance(ab, dt, &sc.loads).map_err(err)?;
        Ok(())
    }

    fn rigid(&mut self, dt: f64) {
        let g = self.settings.gravity_m_s2;
        stages::rigid(&mut self.bodies, &mut self.particles, g, self.time, dt);
    }

    /// Advances the internal energy of the energy-carrying solids over the step just
    /// integrated, at the step's mean velocities: with them the stress forces' work on the
    /// motion is exactly what the particles' energy gains (docs/jet.md#energy).
    fn solid_energy(&mut self, bc: &[BodyConst], dt: f64) {
        let sc = &mut self.scratch;
        // The step's start velocities become its mean ones in place.
        for (v, end) in sc.vel_start.iter_mut().zip(&self.particles.vel) {
            *v = (*v + end) * 0.5;
        }
        let s = SphView {
            p: &self.particles,
            nl: &self.nbrs.same,
            k: &self.kernel,
            bc,
        };
        sc.heat.clear();
        sc.heat.resize(s.p.len(), 0.0);
        let (hi, sh, av) = (
            &self.nbrs.half,
            &sc.sums.shepard,
            self.settings.solid_viscosity,
        );
        let v_mid = &sc.vel_start;
        stages::solid_energy_rates(s, hi, &sc.pairs, sh, av, v_mid, &mut sc.heat);
        stages::add_heat(&mut self.particles, &sc.heat, dt);
    }

    fn integrate(&mut self, bc: &[BodyConst], dt: f64) -> Result<(), SimError> {
        let solid_energy = stages::any_solid_energy(bc);
        if solid_energy {
            self.scratch.vel_start.clone_from(&self.particles.vel);
        }
        let blowup = stages::integrate(
            &mut self.particles,
            &self.bodies,
            bc,
            self.kernel.h,
            &self.scratch.acc,
            &self.scratch.contact_force,
            self.time,
            dt,
        );
        let what = match blowup {
            None => {
                if solid_energy {
                    self.solid_energy(bc, dt);
                }
                return Ok(());
            }
            Some(Blowup::Particle { index: i, what }) => {
                let p = &self.particles;
                format!(
                    "particle {} of body '{}' at ({:.4e}, {:.4e}) m: {what}",
                    p.id[i], self.bodies[p.body[i] as usize].name, p.pos[i].x, p.pos[i].y
                )
            }
            Some(Blowup::Rigid { body }) => format!(
                "rigid body '{}': position or velocity is not finite",
                self.bodies[body].name
            ),
        };
        Err(SimError {
            step: self.steps,
            time_s: self.time,
            what,
        })
    }
}
