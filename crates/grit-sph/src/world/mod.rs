//! The world: bodies, particles and contacts, and the explicit step that advances them
//! (docs/design.md "Engine step"; seed section 2 for the solid, section 3 for contact).

mod build;
mod diagnostics;
mod settings;

pub use crate::stages::{HG_MIN_SEPARATION_H, MIN_SUPPORT_NEIGHBOURS};
pub use diagnostics::{Energy, NumericalWork};
pub use settings::{DensityFilter, Settings, MAX_CFL};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::body::{Absorber, Body, BodyKind, Motion};
use crate::contact::{self, ContactPair, ContactParams};
use crate::error::{InputError, SimError};
use crate::kernel::Kernel;
use crate::math::{cross, omega_cross, rotate, Matrix, Vector};
use crate::neighbours::{self, body_pairs, NeighbourLists, Pair, PairCache};
use crate::particles::{Particles, KINEMATIC};
use crate::stages::{self, BodyConst, KernelSums, ParTasks, SphView};
use crate::timers::{Stage, Timers};

/// One secondary particle's contact: (force on it, nearest primary particle, distance,
/// dashpot work).
type Hit = (Vector, usize, f64, f64);

/// Scratch arrays rebuilt every step (not part of a checkpoint).
#[derive(Debug, Clone, Default)]
struct Scratch {
    /// Same-body pairs of this step with their kernel values (the kernel sums fill it).
    pairs: PairCache,
    /// Volumes, Shepard sums and correction matrices of the kernel sums.
    sums: KernelSums,
    /// Velocity gradients of the rates.
    gradv: Vec<Matrix>,
    /// Accelerations of the forces.
    acc: Vec<Vector>,
    /// Contact force on each particle.
    contact_force: Vec<Vector>,
}

/// A 2D SPH scene: bodies, their particles, contact pairs, time.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct World {
    settings: Settings,
    kernel: Kernel,
    bodies: Vec<Body>,
    contacts: Vec<ContactPair>,
    particles: Particles,
    time: f64,
    steps: u64,
    dt: f64,
    next_id: u32,
    work: NumericalWork,
    /// Positions at the last neighbour build.
    x_build: Vec<Vector>,
    #[serde(skip)]
    nbrs: NeighbourLists,
    #[serde(skip)]
    nbrs_valid: bool,
    #[serde(skip)]
    scratch: Scratch,
    #[serde(skip)]
    timers: Timers,
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
            nbrs: NeighbourLists::default(),
            nbrs_valid: false,
            scratch: Scratch::default(),
            timers: Timers::default(),
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
    /// Neighbour count of each particle as last built (for reports).
    pub fn neighbour_pairs(&self) -> usize {
        self.nbrs.pairs()
    }

    /// Reach of the neighbour lists, and the cell size of the cell order: the kernel support
    /// plus the Verlet skin.
    fn neighbour_reach(&self) -> f64 {
        self.kernel.radius() + self.settings.skin_over_dx * self.settings.spacing_m
    }

    /// Rebuilds neighbour lists (`neighbours::build_for_bodies`), first putting the particles in
    /// cell order where `Settings::cell_order` asks for it.
    fn rebuild_neighbours(&mut self) {
        if self.settings.cell_order {
            let cell = self.neighbour_reach();
            if let Some(order) = neighbours::cell_order(&self.particles, &self.bodies, cell) {
                self.reorder_particles(&order);
            }
        }
        let radius = self.neighbour_reach();
        self.nbrs =
            neighbours::build_for_bodies(&self.particles, &self.bodies, &self.contacts, radius);
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
        let bc = stages::body_consts(&self.bodies);
        let p = &self.particles;
        let h = self.kernel.h;
        let smax = (0..p.len())
            .into_par_iter()
            .par_tasks()
            .filter(|&i| bc[p.body[i] as usize].deformable)
            .map(|i| bc[p.body[i] as usize].sound + p.vel[i].norm())
            .reduce(|| 0.0, f64::max);
        let mut dt = self.settings.dt_max_s;
        if smax > 0.0 {
            dt = dt.min(self.settings.cfl * h / smax);
        }
        for c in self
            .contacts
            .iter()
            .filter(|_| self.settings.contact_limits_dt)
        {
            if c.min_mass.is_finite() {
                dt = dt.min(self.settings.cfl * (c.min_mass / (c.k_r + c.k_f)).sqrt() * 2.0);
            }
        }
        dt
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
        let bc = stages::body_consts(&self.bodies);

        let mut timers = std::mem::take(&mut self.timers);
        if self.needs_rebuild() {
            timers.time(Stage::Neighbours, || self.rebuild_neighbours());
        }
        timers.time(Stage::KernelSums, || self.kernel_sums(&bc));
        timers.time(Stage::Rates, || self.rates(&bc));
        timers.time(Stage::Stress, || self.stress(&bc, dt));
        timers.time(Stage::Forces, || self.forces(&bc, dt));
        let contact = timers.time(Stage::Contact, || self.contact(dt));
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
        debug_assert!(self.particles.len() <= n);
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
        let bc = stages::body_consts(&self.bodies);
        let ready = self.nbrs_valid && self.scratch.pairs.count.len() == self.particles.len();
        if stage != Stage::Neighbours && !ready {
            // Every later stage reads the neighbour lists and the kernel-sum caches.
            self.rebuild_neighbours();
            self.kernel_sums(&bc);
            self.rates(&bc);
        }
        match stage {
            Stage::Neighbours => self.rebuild_neighbours(),
            Stage::KernelSums => self.kernel_sums(&bc),
            Stage::Rates => self.rates(&bc),
            Stage::Stress => self.stress(&bc, dt),
            Stage::Forces => self.forces(&bc, dt),
            Stage::Contact => {
                // A surface particle passing through is a result of the state, not of timing.
                let _ = self.contact(dt);
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

    /// What the SPH sums of the stages read.
    fn sph<'a>(&'a self, bc: &'a [BodyConst]) -> SphView<'a> {
        SphView {
            p: &self.particles,
            nl: &self.nbrs,
            k: &self.kernel,
            bc,
        }
    }

    fn kernel_sums(&mut self, bc: &[BodyConst]) {
        let s = SphView {
            p: &self.particles,
            nl: &self.nbrs,
            k: &self.kernel,
            bc,
        };
        stages::kernel_sums(s, &mut self.scratch.pairs, &mut self.scratch.sums);
    }

    fn rates(&mut self, bc: &[BodyConst]) {
        let gradv =
            stages::velocity_gradients(self.sph(bc), &self.scratch.pairs, &self.scratch.sums);
        self.scratch.gradv = gradv;
    }

    fn stress(&mut self, bc: &[BodyConst], dt: f64) {
        let beta = self.settings.taylor_quinney;
        let plastic_work = stages::stress(
            &mut self.particles,
            &self.bodies,
            bc,
            &self.scratch.gradv,
            beta,
            dt,
        );
        self.work.plastic -= plastic_work;
    }

    fn forces(&mut self, bc: &[BodyConst], dt: f64) {
        let s = SphView {
            p: &self.particles,
            nl: &self.nbrs,
            k: &self.kernel,
            bc,
        };
        let sc = &mut self.scratch;
        let hg = stages::forces(
            s,
            &sc.pairs,
            &sc.sums.shepard,
            &sc.gradv,
            &self.settings,
            dt,
            &mut sc.acc,
        );
        self.work.hourglass += hg;
    }

    /// Contact detection and forces for every pair (eqs. 21–29); reactions collected per rigid
    /// body in particle order, so the sums do not depend on the thread count.
    fn contact(&mut self, dt: f64) -> Result<(), SimError> {
        let n = self.particles.len();
        let s = &mut self.scratch;
        s.contact_force.clear();
        s.contact_force.resize(n, Vector::zeros());
        for b in &mut self.bodies {
            if let Some(r) = b.rigid_mut() {
                r.contact_force_n_m = Vector::zeros();
                r.contact_torque_n = 0.0;
            }
        }
        let dx = self.settings.spacing_m;
        for ci in 0..self.contacts.len() {
            let c = &mut self.contacts[ci];
            let p = &self.particles;
            let nl = &self.nbrs;
            let k = &self.kernel;
            let (prim, sec) = (c.primary as u32, c.secondary as u32);
            let (k_r, k_f, mu, zeta, model) = (
                c.k_r,
                c.k_f,
                c.params.friction,
                c.params.damping_ratio,
                c.params.model,
            );
            let prim_fixed = matches!(
                self.bodies[c.primary].rigid().map(|r| r.motion),
                Some(Motion::Fixed)
            );
            let sec_fixed = matches!(
                self.bodies[c.secondary].rigid().map(|r| r.motion),
                Some(Motion::Fixed)
            );
            let hits: Vec<Option<Hit>> = c
                .spring
                .par_iter_mut()
                .zip(c.penetration.par_iter_mut())
                .par_tasks()
                .enumerate()
                .map(|(i, (dl, pen_prev))| {
                    if p.body[i] != sec {
                        return None;
                    }
                    let js = nl
                        .of(i)
                        .iter()
                        .map(|&j| j as usize)
                        .filter(|&j| p.body[j] == prim);
                    let det = contact::detect(model, k, dx, k_r, p.pos[i], js, &p.pos, |j| {
                        p.mass[j] / p.rho[j]
                    });
                    let det = match det {
                        Some(d) if d.penetration > 0.0 => d,
                        _ => {
                            *dl = Vector::zeros();
                            *pen_prev = 0.0;
                            return None;
                        }
                    };
                    let pen_rate = (det.penetration - *pen_prev) / dt;
                    *pen_prev = det.penetration;
                    let j = det.nearest;
                    let vrel = p.vel[i] - p.vel[j];
                    let fr = det.repulsion;
                    let m_eff = match (sec_fixed, prim_fixed) {
                        (true, _) => p.mass[j],
                        (_, true) => p.mass[i],
                        _ => p.mass[i] * p.mass[j] / (p.mass[i] + p.mass[j]),
                    };
                    let c_t = 2.0 * zeta * (k_f * m_eff).sqrt();
                    let ff = contact::friction(dl, vrel, det.normal, dt, k_f, c_t, mu, fr.norm());
                    let cdamp = 2.0 * zeta * (k_r * m_eff).sqrt();
                    let fd = det.normal * (cdamp * pen_rate);
                    let work = -fd.norm() * pen_rate.abs() * dt;
                    Some((fr + ff + fd, j, det.distance, work))
                })
                .collect();
            // Sequential gather: eq. 29 reactions and eq. 17 sums in particle order.
            let s = &mut self.scratch;
            let mut damp = 0.0;
            let mut through = None;
            for (i, h) in hits.into_iter().enumerate() {
                let Some((f, j, dist, work)) = h else {
                    continue;
                };
                s.contact_force[i] += f;
                s.contact_force[j] -= f;
                damp += work;
                if dist < 0.0 && through.is_none() {
                    through = Some((i, dist));
                }
                let bj = &mut self.bodies[c.primary];
                if let Some(r) = bj.rigid_mut() {
                    r.contact_force_n_m -= f;
                    r.contact_torque_n += cross(p.pos[j] - r.com_m, -f);
                }
                if let Some(r) = self.bodies[c.secondary].rigid_mut() {
                    r.contact_force_n_m += f;
                    r.contact_torque_n += cross(p.pos[i] - r.com_m, f);
                }
            }
            self.work.contact_damping += damp;
            if let Some((i, dist)) = through {
                return Err(SimError {
                    step: self.steps,
                    time_s: self.time,
                    what: format!(
                        "particle {} of body '{}' passed through the surface of body '{}': distance {:.3e} m < 0",
                        p.id[i], self.bodies[c.secondary].name, self.bodies[c.primary].name, dist
                    ),
                });
            }
        }
        Ok(())
    }

    /// Rigid-body motion from total force and torque (eq. 17), semi-implicit Euler.
    fn rigid(&mut self, dt: f64) {
        let g = self.settings.gravity_m_s2;
        let t_next = self.time + dt;
        for b in &mut self.bodies {
            let Some(r) = b.rigid_mut() else { continue };
            match r.motion.velocity(t_next) {
                None => {
                    let f = r.contact_force_n_m + r.external.at(self.time) + g * r.mass_kg_m;
                    r.velocity_m_s += f * (dt / r.mass_kg_m);
                    r.omega_rad_s += r.contact_torque_n * dt / r.inertia_kg_m;
                }
                Some(v) => {
                    r.velocity_m_s = v;
                    r.omega_rad_s = 0.0;
                }
            }
            r.com_m += r.velocity_m_s * dt;
            r.angle_rad += r.omega_rad_s * dt;
        }
        let bodies = &self.bodies;
        let p = &mut self.particles;
        // Fixed bodies never move: skip their particles.
        let moving: Vec<bool> = bodies
            .iter()
            .map(|b| b.rigid().is_some_and(|r| r.motion != Motion::Fixed))
            .collect();
        if !moving.iter().any(|&m| m) {
            return;
        }
        p.pos
            .par_iter_mut()
            .zip(p.vel.par_iter_mut())
            .zip(p.body.par_iter())
            .zip(p.local.par_iter())
            .par_tasks()
            .for_each(|(((x, v), &b), l)| {
                if !moving[b as usize] {
                    return;
                }
                if let Some(r) = bodies[b as usize].rigid() {
                    let rl = rotate(*l, r.angle_rad);
                    *x = r.com_m + rl;
                    *v = r.velocity_m_s + omega_cross(r.omega_rad_s, rl);
                }
            });
    }

    /// Integrates deformable particles (semi-implicit Euler) and runs the failure checks.
    fn integrate(&mut self, bc: &[BodyConst], dt: f64) -> Result<(), SimError> {
        let t_next = self.time + dt;
        let motions: Vec<Option<Vector>> = self
            .bodies
            .iter()
            .map(|b| match &b.kind {
                BodyKind::Deformable {
                    boundary_motion, ..
                } => boundary_motion.velocity(t_next),
                _ => None,
            })
            .collect();
        let absorbers: Vec<Option<Absorber>> = self
            .bodies
            .iter()
            .map(|b| match &b.kind {
                BodyKind::Deformable { absorber, .. } => *absorber,
                _ => None,
            })
            .collect();
        let h = self.kernel.h;
        let acc = &self.scratch.acc;
        let cf = &self.scratch.contact_force;
        let p = &mut self.particles;
        let out: Vec<(Option<String>, f64)> = p
            .pos
            .par_iter_mut()
            .zip(p.vel.par_iter_mut())
            .par_tasks()
            .enumerate()
            .map(|(i, (x, v))| {
                let b = p.body[i] as usize;
                if !bc[b].deformable {
                    return (None, 0.0);
                }
                let mut absorbed = 0.0;
                if p.flags[i] & KINEMATIC != 0 {
                    *v = motions[b].unwrap_or_else(Vector::zeros);
                } else {
                    let free = *v + (acc[i] + cf[i] / p.mass[i]) * dt;
                    // Implicit in the damping, so any σ dt is stable.
                    let sigma = absorbers[b].map_or(0.0, |a| a.sigma(*x));
                    *v = free / (1.0 + sigma * dt);
                    // The work of the damping force −mσv over the step's displacement v dt.
                    absorbed = -p.mass[i] * sigma * v.norm_squared() * dt;
                }
                let dxs = *v * dt;
                *x += dxs;
                if !(x.x.is_finite() && x.y.is_finite() && v.x.is_finite() && v.y.is_finite()) {
                    return (
                        Some("position or velocity is not finite".to_string()),
                        absorbed,
                    );
                }
                if !(p.sdev[i].iter().all(|s| s.is_finite()) && p.rho[i].is_finite()) {
                    return (
                        Some("stress or density is not finite".to_string()),
                        absorbed,
                    );
                }
                if p.rho[i] <= 0.0 {
                    let what = format!("density {:.4e} kg/m³ is not positive", p.rho[i]);
                    return (Some(what), absorbed);
                }
                let step = dxs.norm();
                if step > h {
                    let what = format!("moved {step:.3e} m in one step, more than h = {h:.3e} m");
                    return (Some(what), absorbed);
                }
                (None, absorbed)
            })
            .collect();
        // Serial, in particle order: the first failure and the absorbed work do not depend on
        // the thread count.
        let mut bad = None;
        for (i, (what, w)) in out.into_iter().enumerate() {
            self.work.absorbed += w;
            if bad.is_none() {
                bad = what.map(|w| (i, w));
            }
        }
        if let Some((i, what)) = bad {
            let p = &self.particles;
            return Err(SimError {
                step: self.steps,
                time_s: self.time,
                what: format!(
                    "particle {} of body '{}' at ({:.4e}, {:.4e}) m: {what}",
                    p.id[i], self.bodies[p.body[i] as usize].name, p.pos[i].x, p.pos[i].y
                ),
            });
        }
        for b in &self.bodies {
            if let Some(r) = b.rigid() {
                let ok = r
                    .com_m
                    .iter()
                    .chain(r.velocity_m_s.iter())
                    .all(|x| x.is_finite())
                    && r.omega_rad_s.is_finite();
                if !ok {
                    return Err(SimError {
                        step: self.steps,
                        time_s: self.time,
                        what: format!(
                            "rigid body '{}': position or velocity is not finite",
                            b.name
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Shepard density filter (eq. 12) every `shepard_interval` steps, deletion of particles with
    /// D ≥ 1, and the next time step.
    fn housekeeping(&mut self, bc: &[BodyConst]) -> Result<(), SimError> {
        let every = self.settings.shepard_interval as u64;
        if every > 0 && self.steps.is_multiple_of(every) {
            self.filter_density_with(bc);
        }
        let failed: Vec<bool> = self.particles.damage.iter().map(|&d| d >= 1.0).collect();
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
        self.dt = self.compute_dt();
        Ok(())
    }

    /// Runs the configured density filter now (eq. 12, or its MLS form) and books the change
    /// of elastic energy as the filter's work; `step` calls it every `shepard_interval` steps.
    pub fn filter_density(&mut self) {
        let bc = stages::body_consts(&self.bodies);
        self.filter_density_with(&bc);
    }

    fn filter_density_with(&mut self, bc: &[BodyConst]) {
        let before = self.energy().elastic;
        self.shepard_filter(bc);
        self.work.density_filter += self.energy().elastic - before;
    }

    /// ρ_i = Σ m_j W_ij / Σ V_j W_ij over the body, self included (eq. 12), or its MLS form.
    fn shepard_filter(&mut self, bc: &[BodyConst]) {
        if !self.nbrs_valid || self.nbrs.start.len() != self.particles.len() + 1 {
            self.rebuild_neighbours();
        }
        let p = &self.particles;
        let nl = &self.nbrs;
        let k = &self.kernel;
        let w0 = k.w(0.0);
        let mls = self.settings.density_filter == DensityFilter::Mls;
        let rho: Vec<f64> = (0..p.len())
            .into_par_iter()
            .par_tasks()
            .map(|i| {
                let bi = p.body[i];
                if !bc[bi as usize].deformable {
                    return p.rho[i];
                }
                if mls {
                    if let Some(r) = mls_density(p, nl, k, i) {
                        return r;
                    }
                }
                let (mut num, mut den) = (p.mass[i] * w0, p.mass[i] / p.rho[i] * w0);
                for Pair { j, w, .. } in body_pairs(p, nl, k, i) {
                    num += p.mass[j] * w;
                    den += p.mass[j] / p.rho[j] * w;
                }
                num / den
            })
            .collect();
        self.particles.rho = rho;
    }
}

/// First-order MLS density at particle `i` (Colagrossi & Landrini 2003): ρ_i = Σ_j m_j W_ij
/// (β0 + β·x_ji), with β solving the moment system Σ_j V_j W_ij [1 x_ji]ᵀ[1 x_ji] β = e1, so a
/// linear density field comes back exactly. None where the system is near-singular (a particle
/// with neighbours on a line), which then falls back to eq. 12.
fn mls_density(p: &Particles, nl: &NeighbourLists, k: &Kernel, i: usize) -> Option<f64> {
    use nalgebra::{Matrix3, Vector3};
    // Offsets in units of h keep the moment matrix well scaled.
    let inv_h = 1.0 / k.h;
    let w0 = k.w(0.0);
    // ρ_i is linear in β, so one pass gathers both the moments A and b = Σ_j m_j W_ij q_j,
    // and ρ_i = β·b.
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    a[(0, 0)] = p.mass[i] / p.rho[i] * w0;
    b[0] = p.mass[i] * w0;
    for Pair { j, xij, w, .. } in body_pairs(p, nl, k, i) {
        let q = Vector3::new(1.0, -xij.x * inv_h, -xij.y * inv_h);
        a += q * q.transpose() * (p.mass[j] / p.rho[j] * w);
        b += q * (p.mass[j] * w);
    }
    // Relative to the zeroth moment: below this the linear terms are not determined.
    if a.determinant() <= 1e-6 * a[(0, 0)].powi(3) {
        return None;
    }
    let beta = a.try_inverse()?.column(0).into_owned();
    let rho = beta.dot(&b);
    (rho.is_finite() && rho > 0.0).then_some(rho)
}
