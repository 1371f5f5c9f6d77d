//! The world: bodies, particles and contacts, and the explicit step that advances them
//! (docs/design.md "Engine step"; seed section 2 for the solid, section 3 for contact).
//!
//! `step` lists the stages in order; each stage is a free function in `crate::stages`, which
//! `step::Step` hands the step's context and the arrays the stage writes. Building a world is in
//! `build`, its settings in `settings`, what it reports about itself in `diagnostics`.

mod abrasives;
mod build;
mod diagnostics;
mod flow;
mod settings;
mod state;
mod step;

pub use crate::stages::{CeilingPass, WallLoad, HG_MIN_SEPARATION_H, MIN_SUPPORT_NEIGHBOURS};
pub use abrasives::{plane_mass, Abrasives, GrainContacts, GrainHit, GrainOutflow, PenaltyParams};
pub use diagnostics::{Energy, NumericalWork};
pub use flow::{Inflow, Nozzle, Outflow};
pub use settings::{DensityFilter, Settings, MAX_CFL};
pub use state::{WorldState, WORLD_STATE_VERSION};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::body::Body;
use crate::contact::{ContactPair, ContactParams};
use crate::error::{InputError, SimError};
use crate::kernel::Kernel;
use crate::math::Vector;
use crate::neighbours::{self, WorldLists};
use crate::particles::Particles;
use crate::stages::{self, BodyConst, ParTasks};
use crate::timers::{Stage, Timers};
use step::Scratch;

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
        let t = &mut timers;
        if self.needs_rebuild() {
            t.time(Stage::Neighbours, || self.rebuild_neighbours());
        }
        // The stages of what a scene lacks are not run, and their counters stay at zero.
        let (fluid, grains) = (stages::any_fluid(&bc), self.abrasives.is_some());
        let flow = self.has_open_boundaries();
        let mut s = self.begin_step(&bc);
        t.time(Stage::KernelSums, || s.kernel_sums());
        if grains {
            t.time(Stage::GrainPorosity, || s.grain_porosity());
        }
        t.time(Stage::Stress, || s.stress());
        if fluid {
            t.time(Stage::FluidDensity, || s.fluid_density());
        }
        t.time(Stage::Forces, || s.forces());
        if fluid {
            t.time(Stage::FluidForces, || s.fluid_forces());
        }
        // A failed contact skips the grains but not the integration, and is the failure reported.
        let contact = t.time(Stage::Contact, || s.contact()).and_then(|()| {
            if grains {
                t.time(Stage::GrainCoupling, || s.grain_coupling())?;
                t.time(Stage::GrainContact, || s.grain_contact());
                t.time(Stage::GrainDem, || s.grain_dem())?;
            }
            Ok(())
        });
        t.time(Stage::Rigid, || s.rigid());
        let checked = t.time(Stage::Integrate, || s.integrate());
        if let Err(e) = contact.and(checked) {
            self.timers = timers;
            return Err(e);
        }
        self.time += dt;
        self.steps += 1;
        let t = &mut timers;
        t.time(Stage::Housekeeping, || self.filter_and_delete(&bc));
        if flow {
            t.time(Stage::Flow, || {
                self.flow_step(dt);
                self.grain_outflow_step();
            });
        }
        t.time(Stage::Housekeeping, || self.dt = self.compute_dt());
        self.timers = timers;
        debug_assert!(self.particles.len() <= n || !self.flow.inflows.is_empty());
        Ok(())
    }

    /// Runs one stage of `step` (docs/design.md "Engine step") on the current state without
    /// advancing time, so a benchmark can time the hot loops one by one. The stages from
    /// `GrainCoupling` on read what the stages before them wrote in the same step, or move grains
    /// and particles: they are timed inside `step` only.
    pub fn run_stage(&mut self, stage: Stage) -> Result<(), InputError> {
        if self.dt == 0.0 {
            self.dt = self.compute_dt();
        }
        let bc = self.kept_body_consts();
        let ready = self.nbrs_valid && self.scratch.pairs.count.len() == self.particles.len();
        if stage != Stage::Neighbours && !ready {
            // Every later stage reads the neighbour lists and the kernel-sum caches.
            self.rebuild_neighbours();
            self.begin_step(&bc).kernel_sums();
        }
        if stage == Stage::Neighbours {
            self.rebuild_neighbours();
            return Ok(());
        }
        let mut s = self.begin_step(&bc);
        match stage {
            Stage::KernelSums => s.kernel_sums(),
            Stage::GrainPorosity => s.grain_porosity(),
            Stage::Stress => s.stress(),
            Stage::FluidDensity => s.fluid_density(),
            Stage::Forces => s.forces(),
            Stage::FluidForces => s.fluid_forces(),
            Stage::Contact => {
                stages::volumes(s.ctx.p, &mut s.scratch.vol);
                // A surface particle passing through is a result of the state, not of timing.
                let _ = s.contact();
            }
            other => {
                return Err(InputError::new(
                    "stage",
                    format!("{other:?} runs inside a step only; time it with step()"),
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
                &self.nbrs.half,
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

    /// Whether fluid or grains may enter or leave: inflows, outflows, a grain outflow.
    fn has_open_boundaries(&self) -> bool {
        !self.flow.is_empty() || self.abrasives.as_ref().is_some_and(|a| a.outflow.is_some())
    }

    /// Shepard density filter (eq. 12) every `shepard_interval` steps, and deletion of ductile
    /// particles with D ≥ 1 and of fluid particles out of their density range.
    fn filter_and_delete(&mut self, bc: &[BodyConst]) {
        let every = self.settings.shepard_interval as u64;
        if every > 0 && self.steps.is_multiple_of(every) {
            self.filter_density_with(bc);
        }
        // Deleted: ductile solids at D ≥ 1, free fluid particles outside their fluid's density
        // range. Fractured JH-2 rock stays, carrying its fractured strength (the AWJ paper
        // deletes only ductile particles; docs/jet.md#rock-targets).
        let p = &self.particles;
        let failed: Vec<bool> = (0..p.len())
            .into_par_iter()
            .par_tasks()
            .map(|i| {
                let c = &bc[p.body[i] as usize];
                let free_fluid = c
                    .fluid
                    .filter(|_| p.flags[i] & crate::particles::KINEMATIC == 0);
                (p.damage[i] >= 1.0 && c.jh2.is_none())
                    || free_fluid.is_some_and(|f| f.out_of_range(p.rho[i]))
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
        let filter = self.settings.density_filter;
        let s = self.begin_step(bc);
        stages::volumes(s.ctx.p, &mut s.scratch.vol);
        let rho = stages::filter_density(s.ctx.sph(), &s.scratch.vol, filter);
        self.particles.rho = rho;
        self.work.density_filter += self.energy().elastic - before;
    }
}
