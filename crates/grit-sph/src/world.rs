//! The world: bodies, particles and contacts, and the explicit step that advances them
//! (DESIGN.md "Engine step"; seed section 2 for the solid, section 3 for contact).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::body::{Absorber, Body, BodyKind, ExternalForce, Motion, Rigid};
use crate::contact::{self, ContactPair, ContactParams};
use crate::error::{InputError, SimError};
use crate::geometry::Polygon;
use crate::kernel::{Kernel, KernelKind};
use crate::material::Material;
use crate::math::{cross, omega_cross, outer, rotate, Matrix, Vector};
use crate::neighbours::{self, NeighbourLists};
use crate::particles::{dev_contract, von_mises, Particles, BOUNDARY, KINEMATIC};
use crate::physics;
use crate::timers::{Stage, Timers};

/// Numerical settings of a world; defaults are the seed's choices.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Settings {
    /// Initial particle spacing Δx (m); also the contact equilibrium distance (section 3.1).
    pub spacing_m: f64,
    /// Smoothing length over spacing, h/Δx (seed: 1.3).
    pub h_over_dx: f64,
    /// Kernel function (seed: quintic spline, eq. 4).
    pub kernel: KernelKind,
    /// Courant number of the time step dt = CFL · h / max(c + |v|).
    pub cfl: f64,
    /// Gravity (m/s²).
    pub gravity_m_s2: Vector,
    /// Hourglass coefficient α of eq. 16 (0 switches hourglass control off).
    pub hourglass: f64,
    /// Steps between Shepard density filters (eq. 12; seed: 40; 0 switches it off).
    pub shepard_interval: u32,
    /// Which density filter runs every `shepard_interval` steps (seed: Shepard, eq. 12).
    pub density_filter: DensityFilter,
    /// Verlet skin over Δx: lists are rebuilt once a particle has moved half of it.
    pub skin_over_dx: f64,
    /// Upper bound of the time step (s).
    pub dt_max_s: f64,
    /// Fraction of plastic work turned into heat (Taylor–Quinney coefficient).
    pub taylor_quinney: f64,
    /// Initial temperature of deformable bodies (K).
    pub temperature_k: f64,
    /// Whether the contact springs may shorten the time step below the material's CFL step.
    /// Off, a stiff spring is integrated with too long a step: the stability map needs that.
    pub contact_limits_dt: bool,
    /// Rigid bodies keep only their outline layer of particles (issue 5, "model no more"):
    /// interior particles of a rigid body are never searched, touched or summed, and its mass
    /// and inertia come from the polygon, so dropping them changes no result.
    pub rigid_shell: bool,
    /// Deformable particles are re-sorted along a Z-order curve of neighbour cells at every
    /// neighbour rebuild, so a particle's neighbours sit close to it in memory (issue 5, "model
    /// no more"). Results change by rounding only: the sums run in another order.
    pub cell_order: bool,
}

/// The largest Courant number `Settings` accepts.
pub const MAX_CFL: f64 = 2.0;

impl Default for Settings {
    fn default() -> Self {
        Settings {
            spacing_m: 8e-6,
            h_over_dx: 1.3,
            kernel: KernelKind::Quintic,
            cfl: 0.3,
            gravity_m_s2: Vector::zeros(),
            hourglass: 0.1,
            shepard_interval: 40,
            density_filter: DensityFilter::Shepard,
            skin_over_dx: 0.5,
            dt_max_s: 1e-3,
            taylor_quinney: 0.9,
            temperature_k: 293.0,
            contact_limits_dt: true,
            rigid_shell: false,
            cell_order: false,
        }
    }
}

impl Settings {
    /// Checks that every setting is usable; the error names the field.
    pub fn validate(&self) -> Result<(), InputError> {
        let pos = |f: &str, v: f64| InputError::require_positive(f, v);
        pos("spacing_m", self.spacing_m)?;
        pos("h_over_dx", self.h_over_dx)?;
        pos("cfl", self.cfl)?;
        // Above 1 the step is unstable in every case `grit bench stability` maps; up to 2 is
        // allowed so that the map can show where.
        if self.cfl > MAX_CFL {
            return Err(InputError::new(
                "cfl",
                format!(
                    "must be at most {MAX_CFL} for an explicit step, got {}",
                    self.cfl
                ),
            ));
        }
        pos("skin_over_dx", self.skin_over_dx)?;
        pos("dt_max_s", self.dt_max_s)?;
        pos("temperature_k", self.temperature_k)?;
        if !(self.hourglass.is_finite() && self.hourglass >= 0.0) {
            return Err(InputError::new(
                "hourglass",
                format!("must be >= 0, got {}", self.hourglass),
            ));
        }
        if !(self.taylor_quinney.is_finite() && (0.0..=1.0).contains(&self.taylor_quinney)) {
            return Err(InputError::new(
                "taylor_quinney",
                format!("must lie in [0, 1], got {}", self.taylor_quinney),
            ));
        }
        if !(self.gravity_m_s2.x.is_finite() && self.gravity_m_s2.y.is_finite()) {
            return Err(InputError::new("gravity_m_s2", "must be finite"));
        }
        Ok(())
    }
}

/// The periodic density re-initialisation: the seed's zeroth-order Shepard average (eq. 12), or
/// its first-order moving-least-squares form (Colagrossi & Landrini 2003, Dilts 1999).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum DensityFilter {
    /// Eq. 12: a kernel-weighted average. It flattens any density gradient over a kernel
    /// width, so it also damps resolved elastic waves, and most at a free surface.
    #[default]
    Shepard,
    /// Eq. 12 with the kernel corrected to reproduce linear fields, at free surfaces too: it
    /// removes particle-scale noise and leaves resolved strain gradients almost untouched.
    Mls,
}

/// Energy of the world and what the numerics have added or taken (J/m, per unit depth).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Energy {
    /// Kinetic energy of deformable particles and rigid bodies.
    pub kinetic: f64,
    /// Elastic strain energy: V (p²/2K + s:s/4G) summed over deformable particles.
    pub elastic: f64,
    /// Energy stored in the contact repulsion springs.
    pub contact: f64,
    /// Potential energy in gravity.
    pub gravity: f64,
}

impl Energy {
    /// Kinetic plus elastic plus contact plus gravity.
    pub fn total(&self) -> f64 {
        self.kinetic + self.elastic + self.contact + self.gravity
    }
}

/// Running totals of work done by numerical devices (J/m); negative means dissipated.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct NumericalWork {
    /// Work of the hourglass forces (eq. 16).
    pub hourglass: f64,
    /// Change of elastic energy at the Shepard density filter (eq. 12).
    pub density_filter: f64,
    /// Work of the contact dashpots.
    pub contact_damping: f64,
    /// Plastic work (heat and stored work of plasticity).
    pub plastic: f64,
    /// Work of the absorbing layers (`Absorber`).
    #[serde(default)]
    pub absorbed: f64,
}

/// Smallest number of particles one rayon task takes: below it the per-task overhead costs more
/// than the work (small verification scenes ran slower on 2 threads than on 1 without it).
const MIN_LEN: usize = 64;

/// Largest number of particles one rayon task takes. The work of a step is uneven along the
/// index (the grain's particles and the free surface do less, the few hundred particles under
/// the grain do the contact), and rayon's adaptive splitting can leave a few large tasks, so one
/// thread sat idle while the other finished. Tasks of at most 256 particles let the idle thread
/// steal: the full step's speed-up from 1 to 2 threads rose from 1.66 to 1.86
/// (median of 4–5, `cargo run --release -p grit-erosion --example stage_scaling`).
const MAX_LEN: usize = 256;

/// A deformable particle with fewer same-body neighbours inside the kernel support than this is
/// a fragment torn off its body: its kernel sums no longer describe a continuum (the Shepard
/// normalisation of eq. 9 divides by a near-empty sum and blows up), so it flies ballistically,
/// keeping its stress, until it rejoins material. A particle inside a body has about 44.
pub const MIN_SUPPORT_NEIGHBOURS: u32 = 6;

/// Pair separation (in h) below which the hourglass force of eq. 16 stops growing as 1/r².
pub const HG_MIN_SEPARATION_H: f64 = 0.4;

/// Per-body constants the stages need, looked up by particle.
#[derive(Debug, Clone, Copy, Default)]
struct BodyConst {
    deformable: bool,
    bulk: f64,
    shear: f64,
    youngs: f64,
    sound: f64,
}

/// One secondary particle's contact: (force on it, nearest primary particle, distance,
/// dashpot work).
type Hit = (Vector, usize, f64, f64);

/// Scratch arrays rebuilt every step (not part of a checkpoint).
#[derive(Debug, Clone, Default)]
struct Scratch {
    /// Same-body pairs of this step with their kernel values, in each particle's slice of the
    /// neighbour rows (first `pair_count[i]` entries used): computed once in the kernel sums,
    /// read by the rates and the forces, so each pair's kernel is evaluated once per step.
    pairs: Vec<Pair>,
    pair_count: Vec<u32>,
    /// Particle volumes m/ρ at the kernel sums, computed once instead of once per pair; valid
    /// until the stress stage updates ρ.
    vol: Vec<f64>,
    shepard: Vec<f64>,
    lcorr: Vec<Matrix>,
    gradv: Vec<Matrix>,
    acc: Vec<Vector>,
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

    #[allow(clippy::too_many_arguments)]
    fn push_particle(
        &mut self,
        body: usize,
        x: Vector,
        v: Vector,
        mass: f64,
        rho: f64,
        flags: u8,
        local: Vector,
    ) {
        let p = &mut self.particles;
        p.id.push(self.next_id);
        self.next_id += 1;
        p.body.push(body as u32);
        p.flags.push(flags);
        p.pos.push(x);
        p.vel.push(v);
        p.mass.push(mass);
        p.rho.push(rho);
        p.rho0.push(rho);
        p.sdev.push(Matrix::zeros());
        p.eps_p.push(0.0);
        p.eps_p_rate.push(0.0);
        p.temp.push(self.settings.temperature_k);
        p.damage.push(0.0);
        p.def_grad.push(Matrix::identity());
        p.x_ref.push(x);
        p.local.push(local);
        for c in &mut self.contacts {
            c.spring.push(Vector::zeros());
            c.penetration.push(0.0);
            if c.touches(body, flags) {
                c.min_mass = c.min_mass.min(mass);
            }
        }
        self.nbrs_valid = false;
    }

    /// Adds a deformable body of particles at `points`, each standing for `volume_m2` (area per
    /// unit depth); returns its index. The body's surface particles are found geometrically.
    pub fn add_deformable(
        &mut self,
        name: &str,
        material: Material,
        points: &[Vector],
        volume_m2: &[f64],
        velocity_m_s: Vector,
    ) -> Result<usize, InputError> {
        material.validate()?;
        if points.is_empty() {
            return Err(InputError::new(
                format!("{name}.points"),
                "a body needs at least one particle",
            ));
        }
        if points.len() != volume_m2.len() {
            return Err(InputError::new(
                format!("{name}.volume_m2"),
                "needs one volume per point",
            ));
        }
        if let Some(k) = volume_m2.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(InputError::new(
                format!("{name}.volume_m2[{k}]"),
                "must be a finite number > 0",
            ));
        }
        let b = self.bodies.len();
        let rho = material.density_kg_m3;
        self.bodies.push(Body {
            name: name.to_string(),
            kind: BodyKind::Deformable {
                material,
                boundary_motion: Motion::Fixed,
                absorber: None,
            },
            removed_mass_kg_m: 0.0,
            removed_particles: 0,
        });
        for (x, v) in points.iter().zip(volume_m2) {
            self.push_particle(b, *x, velocity_m_s, rho * v, rho, 0, Vector::zeros());
        }
        Ok(b)
    }

    /// Adds a deformable body filling `polygon` on a square lattice of the world's spacing.
    pub fn add_deformable_polygon(
        &mut self,
        name: &str,
        material: Material,
        polygon: &Polygon,
        lattice_origin: Vector,
        velocity_m_s: Vector,
    ) -> Result<usize, InputError> {
        let dx = self.settings.spacing_m;
        let pts = polygon.fill_lattice(dx, lattice_origin);
        let vols = vec![dx * dx; pts.len()];
        self.add_deformable(name, material, &pts, &vols, velocity_m_s)
    }

    /// Adds a deformable body from a saved particle state (`body_state` of an earlier world):
    /// stress, strain, damage and flags carry over unchanged, so a sample can go on from one
    /// impact to the next in a fresh world (seed section 4).
    pub fn add_deformable_state(
        &mut self,
        name: &str,
        material: Material,
        mut state: Particles,
        boundary_motion: Motion,
    ) -> Result<usize, InputError> {
        material.validate()?;
        if state.is_empty() || !state.is_consistent() {
            return Err(InputError::new(
                format!("{name}.state"),
                "needs at least one particle and equal lengths of every per-particle array",
            ));
        }
        let finite = state
            .pos
            .iter()
            .chain(&state.vel)
            .all(|v| v.iter().all(|x| x.is_finite()))
            && state
                .mass
                .iter()
                .chain(&state.rho)
                .all(|&x| x.is_finite() && x > 0.0);
        if !finite {
            return Err(InputError::new(
                format!("{name}.state"),
                "positions and velocities must be finite, masses and densities > 0",
            ));
        }
        let b = self.bodies.len();
        self.bodies.push(Body {
            name: name.to_string(),
            kind: BodyKind::Deformable {
                material,
                boundary_motion,
                absorber: None,
            },
            removed_mass_kg_m: 0.0,
            removed_particles: 0,
        });
        let n = state.len();
        state.body.iter_mut().for_each(|x| *x = b as u32);
        self.next_id = self.next_id.max(state.id.iter().max().map_or(0, |m| m + 1));
        for c in &mut self.contacts {
            c.spring.resize(self.particles.len() + n, Vector::zeros());
            c.penetration.resize(self.particles.len() + n, 0.0);
        }
        self.particles.append(state);
        self.refresh_contact_masses();
        self.nbrs_valid = false;
        Ok(b)
    }

    /// A copy of body `b`'s particles, in loop order (for `add_deformable_state`).
    pub fn body_state(&self, b: usize) -> Particles {
        let keep: Vec<bool> = self
            .particles
            .body
            .iter()
            .map(|&x| x as usize == b)
            .collect();
        self.particles.select(&keep)
    }

    /// Makes the particles of deformable body `b` that satisfy `select` kinematic: they move
    /// with `motion` (a prescribed-motion boundary) and take no forces.
    pub fn set_kinematic(
        &mut self,
        b: usize,
        motion: Motion,
        select: impl Fn(Vector) -> bool,
    ) -> Result<usize, InputError> {
        match &mut self.bodies[b].kind {
            BodyKind::Deformable {
                boundary_motion, ..
            } => *boundary_motion = motion,
            BodyKind::Rigid(_) => {
                return Err(InputError::new(
                    "kinematic",
                    "only deformable bodies have kinematic particles",
                ))
            }
        }
        let mut n = 0;
        for i in 0..self.particles.len() {
            if self.particles.body[i] as usize == b && select(self.particles.pos[i]) {
                self.particles.flags[i] |= KINEMATIC;
                n += 1;
            }
        }
        Ok(n)
    }

    /// Gives deformable body `b` an absorbing layer (a sponge along its edges, `Absorber`).
    pub fn set_absorber(&mut self, b: usize, layer: Absorber) -> Result<(), InputError> {
        InputError::require_positive("absorber.thickness_m", layer.thickness_m)?;
        if !(layer.sigma_max_per_s.is_finite() && layer.sigma_max_per_s >= 0.0) {
            return Err(InputError::new(
                "absorber.sigma_max_per_s",
                format!(
                    "must be a finite number >= 0, got {}",
                    layer.sigma_max_per_s
                ),
            ));
        }
        let corners = [layer.inner_lo, layer.inner_hi];
        if !corners.iter().all(|c| c.x.is_finite() && c.y.is_finite())
            || layer.inner_lo.x > layer.inner_hi.x
            || layer.inner_lo.y > layer.inner_hi.y
        {
            return Err(InputError::new(
                "absorber.inner_lo",
                "the undamped box needs finite corners with inner_lo below and left of inner_hi",
            ));
        }
        match self.bodies.get_mut(b).map(|body| &mut body.kind) {
            Some(BodyKind::Deformable { absorber, .. }) => {
                *absorber = Some(layer);
                Ok(())
            }
            _ => Err(InputError::new(
                "absorber",
                "only deformable bodies take an absorbing layer",
            )),
        }
    }

    /// Adds a rigid polygon of `density_kg_m3` (mass and inertia from the polygon itself),
    /// filled with boundary-conforming particle layers; returns its index.
    pub fn add_rigid(
        &mut self,
        name: &str,
        polygon: &Polygon,
        density_kg_m3: f64,
        velocity_m_s: Vector,
        omega_rad_s: f64,
        motion: Motion,
    ) -> Result<usize, InputError> {
        if !(density_kg_m3.is_finite() && density_kg_m3 > 0.0) {
            return Err(InputError::new(
                format!("{name}.density_kg_m3"),
                format!("must be > 0, got {density_kg_m3}"),
            ));
        }
        let dx = self.settings.spacing_m;
        let (pts, boundary) = polygon.fill_layered(dx);
        if pts.is_empty() {
            return Err(InputError::new(
                format!("{name}.vertices_m"),
                "polygon is too small for the particle spacing",
            ));
        }
        let mass = density_kg_m3 * polygon.area();
        let inertia = density_kg_m3 * polygon.polar_moment();
        let com = polygon.centroid();
        let b = self.bodies.len();
        self.bodies.push(Body {
            name: name.to_string(),
            kind: BodyKind::Rigid(Rigid {
                mass_kg_m: mass,
                inertia_kg_m: inertia,
                com_m: com,
                angle_rad: 0.0,
                velocity_m_s,
                omega_rad_s,
                motion,
                external: ExternalForce::default(),
                contact_force_n_m: Vector::zeros(),
                contact_torque_n: 0.0,
            }),
            removed_mass_kg_m: 0.0,
            removed_particles: 0,
        });
        // The particle mass of the full fill in either case: the contact's time-step limit and
        // stiffness read it, so a shell must not change it.
        let mp = mass / pts.len() as f64;
        let shell = self.settings.rigid_shell;
        for (x, isb) in pts.iter().zip(boundary) {
            if shell && !isb {
                continue;
            }
            let r = x - com;
            let v = velocity_m_s + omega_cross(omega_rad_s, r);
            self.push_particle(
                b,
                *x,
                v,
                mp,
                density_kg_m3,
                if isb { BOUNDARY } else { 0 },
                r,
            );
        }
        Ok(b)
    }

    /// Sets the external force on rigid body `b`.
    pub fn set_external_force(&mut self, b: usize, f: ExternalForce) -> Result<(), InputError> {
        match self.bodies[b].rigid_mut() {
            Some(r) => {
                r.external = f;
                Ok(())
            }
            None => Err(InputError::new(
                "external_force",
                "only rigid bodies take an external force",
            )),
        }
    }

    /// Declares that rigid `primary` and `secondary` touch with the seed's contact (section 3).
    pub fn add_contact(
        &mut self,
        primary: usize,
        secondary: usize,
        params: ContactParams,
    ) -> Result<usize, InputError> {
        if primary >= self.bodies.len() || secondary >= self.bodies.len() || primary == secondary {
            return Err(InputError::new(
                "contact",
                "primary and secondary must be two different existing bodies",
            ));
        }
        if !self.bodies[primary].is_rigid() {
            return Err(InputError::new(
                "contact.primary",
                "the primary body must be rigid: its surface gives the normal",
            ));
        }
        if !(params.friction.is_finite() && params.friction >= 0.0) {
            return Err(InputError::new(
                "contact.friction",
                format!("must be >= 0, got {}", params.friction),
            ));
        }
        if !(params.damping_ratio.is_finite() && params.damping_ratio >= 0.0) {
            return Err(InputError::new("contact.damping_ratio", "must be >= 0"));
        }
        let k_r = match params.normal_stiffness_pa {
            Some(k) => k,
            None => match self.bodies[secondary].material() {
                Some(m) => contact::cfl_matched_stiffness(m, self.settings.h_over_dx),
                None => {
                    return Err(InputError::new(
                        "contact.normal_stiffness_pa",
                        "must be given when both bodies are rigid",
                    ))
                }
            },
        };
        let k_f = params.tangential_stiffness_pa.unwrap_or(k_r);
        if !(k_r.is_finite() && k_r > 0.0 && k_f.is_finite() && k_f > 0.0) {
            return Err(InputError::new(
                "contact.normal_stiffness_pa",
                "stiffnesses must be > 0",
            ));
        }
        self.contacts.push(ContactPair {
            primary,
            secondary,
            params,
            k_r,
            k_f,
            spring: vec![Vector::zeros(); self.particles.len()],
            penetration: vec![0.0; self.particles.len()],
            min_mass: f64::INFINITY,
        });
        self.refresh_contact_masses();
        self.nbrs_valid = false;
        Ok(self.contacts.len() - 1)
    }

    fn body_consts(&self) -> Vec<BodyConst> {
        self.bodies
            .iter()
            .map(|b| match b.material() {
                Some(m) => BodyConst {
                    deformable: true,
                    bulk: m.bulk_modulus(),
                    shear: m.shear_modulus(),
                    youngs: m.youngs_modulus_pa,
                    sound: m.sound_speed(),
                },
                None => BodyConst::default(),
            })
            .collect()
    }

    /// Kinetic, elastic, contact-spring and gravity energy (J/m).
    pub fn energy(&self) -> Energy {
        let bc = self.body_consts();
        let p = &self.particles;
        let mut e = Energy::default();
        for i in 0..p.len() {
            let b = p.body[i] as usize;
            if !bc[b].deformable {
                continue;
            }
            e.kinetic += 0.5 * p.mass[i] * p.vel[i].norm_squared();
            let vol = p.mass[i] / p.rho[i];
            let pr = p.pressure(i, bc[b].bulk);
            e.elastic += vol
                * (pr * pr / (2.0 * bc[b].bulk) + dev_contract(&p.sdev[i]) / (4.0 * bc[b].shear));
            e.gravity -= p.mass[i] * self.settings.gravity_m_s2.dot(&p.pos[i]);
        }
        for b in &self.bodies {
            if let Some(r) = b.rigid() {
                if r.motion == Motion::Free {
                    e.kinetic += 0.5 * r.mass_kg_m * r.velocity_m_s.norm_squared()
                        + 0.5 * r.inertia_kg_m * r.omega_rad_s * r.omega_rad_s;
                    e.gravity -= r.mass_kg_m * self.settings.gravity_m_s2.dot(&r.com_m);
                }
            }
        }
        for c in &self.contacts {
            for (i, &pen) in c.penetration.iter().enumerate() {
                if pen > 0.0 {
                    e.contact += 0.5 * c.k_r * pen * pen + 0.5 * c.spring[i].norm_squared() * c.k_f;
                }
            }
        }
        e
    }

    /// Total linear momentum of deformable particles and free rigid bodies (kg·m/s per m).
    pub fn momentum(&self) -> Vector {
        let p = &self.particles;
        let mut m = Vector::zeros();
        for i in 0..p.len() {
            if self.bodies[p.body[i] as usize].material().is_some() {
                m += p.vel[i] * p.mass[i];
            }
        }
        for b in &self.bodies {
            if let Some(r) = b.rigid() {
                if r.motion == Motion::Free {
                    m += r.velocity_m_s * r.mass_kg_m;
                }
            }
        }
        m
    }

    /// Resets temperature of deformable bodies to the initial one (between impacts, section 4).
    pub fn reset_temperature(&mut self) {
        let t = self.settings.temperature_k;
        for x in &mut self.particles.temp {
            *x = t;
        }
    }

    /// Removes every particle of body `b` and the body's contacts (the old grain, section 4).
    /// Body indices of other bodies stay valid: the body entry remains, empty.
    pub fn clear_body(&mut self, b: usize) {
        let keep: Vec<bool> = self
            .particles
            .body
            .iter()
            .map(|&x| x as usize != b)
            .collect();
        self.retain_particles(&keep);
        self.contacts.retain(|c| c.primary != b && c.secondary != b);
        self.nbrs_valid = false;
    }

    /// Removes the particles with `keep[i] == false` (fragments a scene no longer follows),
    /// keeping the order of the rest; removed mass is not booked as failed.
    pub fn remove_particles(&mut self, keep: &[bool]) -> Result<(), InputError> {
        if keep.len() != self.particles.len() {
            return Err(InputError::new("keep", "needs one flag per particle"));
        }
        self.retain_particles(keep);
        Ok(())
    }

    fn retain_particles(&mut self, keep: &[bool]) {
        self.reorder_particles(&crate::particles::kept(keep));
        self.refresh_contact_masses();
    }

    /// Puts particle `order[k]` at index k, dropping those not listed: every per-particle array
    /// and the contact springs move together, and the neighbour lists are stale.
    fn reorder_particles(&mut self, order: &[usize]) {
        use crate::particles::gather;
        self.particles = self.particles.permuted(order);
        for c in &mut self.contacts {
            c.spring = gather(&c.spring, order);
            c.penetration = gather(&c.penetration, order);
        }
        self.nbrs_valid = false;
    }

    /// Smallest particle mass each contact's springs act on, for the contact time step; kept
    /// here so the step does not scan every particle for it.
    fn refresh_contact_masses(&mut self) {
        let p = &self.particles;
        for c in &mut self.contacts {
            c.min_mass = (0..p.len())
                .filter(|&i| c.touches(p.body[i] as usize, p.flags[i]))
                .map(|i| p.mass[i])
                .fold(f64::INFINITY, f64::min);
        }
    }

    /// Rebuilds neighbour lists: deformable particles see their own body and the primary
    /// boundary particles they can touch; rigid secondary boundary particles see their primaries.
    fn rebuild_neighbours(&mut self) {
        if self.settings.cell_order {
            self.sort_by_cell();
        }
        let nb = self.bodies.len();
        // relation[a * nb + b]: can a particle of body a list one of body b?
        let mut relation = vec![false; nb * nb];
        let mut is_secondary = vec![false; nb];
        let mut is_primary = vec![false; nb];
        for (a, body) in self.bodies.iter().enumerate() {
            if !body.is_rigid() {
                relation[a * nb + a] = true;
            }
        }
        for c in &self.contacts {
            relation[c.secondary * nb + c.primary] = true;
            is_secondary[c.secondary] = true;
            is_primary[c.primary] = true;
        }
        let p = &self.particles;
        let n = p.len();
        let rigid: Vec<bool> = self.bodies.iter().map(|b| b.is_rigid()).collect();
        let searcher: Vec<bool> = (0..n)
            .map(|i| {
                let b = p.body[i] as usize;
                !rigid[b] || (is_secondary[b] && p.flags[i] & BOUNDARY != 0)
            })
            .collect();
        let candidate: Vec<bool> = (0..n)
            .map(|i| {
                let b = p.body[i] as usize;
                !rigid[b] || (is_primary[b] && p.flags[i] & BOUNDARY != 0)
            })
            .collect();
        let radius = self.kernel.radius() + self.settings.skin_over_dx * self.settings.spacing_m;
        let body = &p.body;
        self.nbrs = neighbours::build(&p.pos, &searcher, &candidate, radius, |i, j| {
            relation[body[i] as usize * nb + body[j] as usize]
        });
        self.x_build = p.pos.clone();
        self.nbrs_valid = true;
    }

    /// Reorders the particles by body, then deformable ones by the Z-order (Morton) index of
    /// their neighbour-search cell, ties by current index; rigid bodies keep their order. Every
    /// per-particle array moves with them (`Settings::cell_order`).
    fn sort_by_cell(&mut self) {
        let p = &self.particles;
        let n = p.len();
        if n == 0 {
            return;
        }
        let cell = self.kernel.radius() + self.settings.skin_over_dx * self.settings.spacing_m;
        let lo = p.pos.iter().fold(p.pos[0], |a, x| a.inf(x));
        let deformable: Vec<bool> = self.bodies.iter().map(|b| !b.is_rigid()).collect();
        let key = |i: usize| -> u64 {
            if !deformable[p.body[i] as usize] {
                return 0;
            }
            let c = (p.pos[i] - lo) / cell;
            // Cells past 2^31 along an axis (a particle flung far off) share the last one.
            let ix = c.x.clamp(0.0, u32::MAX as f64 / 2.0) as u32;
            let iy = c.y.clamp(0.0, u32::MAX as f64 / 2.0) as u32;
            morton(ix, iy)
        };
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by_key(|&i| (p.body[i], key(i), i));
        if order.iter().enumerate().all(|(k, &i)| k == i) {
            return;
        }
        self.reorder_particles(&order);
    }

    fn needs_rebuild(&self) -> bool {
        if !self.nbrs_valid || self.x_build.len() != self.particles.len() {
            return true;
        }
        let half = 0.5 * self.settings.skin_over_dx * self.settings.spacing_m;
        let lim = half * half;
        self.particles
            .pos
            .par_iter()
            .zip(&self.x_build)
            .any(|(x, x0)| (x - x0).norm_squared() > lim)
    }

    /// Stable time step: CFL on the material signal speed plus particle speed, and the
    /// contact springs' period.
    fn compute_dt(&self) -> f64 {
        let bc = self.body_consts();
        let p = &self.particles;
        let h = self.kernel.h;
        let smax = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_LEN)
            .with_max_len(MAX_LEN)
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
    /// nothing but a rigid body's free flight would happen (an impact's approach, issue 5). The
    /// clock and the phase of the work done every k steps (the density filter, eq. 12) then
    /// stay those of the full run.
    pub fn count_skipped_steps(&mut self, steps: u64, dt_s: f64) {
        self.steps += steps;
        self.time += steps as f64 * dt_s;
    }

    /// Advances the world by one explicit step (DESIGN.md "Engine step").
    pub fn step(&mut self) -> Result<(), SimError> {
        if self.dt == 0.0 {
            self.dt = self.compute_dt();
        }
        let dt = self.dt;
        let n = self.particles.len();
        let bc = self.body_consts();

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

    /// Runs one stage of `step` (DESIGN.md "Engine step") on the current state without
    /// advancing time, so a benchmark can time the hot loops one by one. Stages after
    /// `Contact` move particles and are only timed inside `step`.
    pub fn run_stage(&mut self, stage: Stage) -> Result<(), InputError> {
        if self.dt == 0.0 {
            self.dt = self.compute_dt();
        }
        let dt = self.dt;
        let bc = self.body_consts();
        let ready = self.nbrs_valid && self.scratch.pair_count.len() == self.particles.len();
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

    /// Shepard sums Γ_i = Σ V_j W_ij (eq. 9 denominator) and Bonet–Lok matrices L_i (eq. 8).
    fn kernel_sums(&mut self, bc: &[BodyConst]) {
        let p = &self.particles;
        let nl = &self.nbrs;
        let k = &self.kernel;
        let w0 = k.w(0.0);
        let n = p.len();
        let mut vol = std::mem::take(&mut self.scratch.vol);
        vol.clear();
        vol.par_extend(
            p.mass
                .par_iter()
                .zip(&p.rho)
                .with_min_len(MIN_LEN)
                .with_max_len(MAX_LEN)
                .map(|(m, r)| m / r),
        );
        let mut buf = std::mem::take(&mut self.scratch.pairs);
        // Rows are overwritten before they are read: grow, never clear (a memset per step).
        if buf.len() < nl.list.len() {
            buf.resize(nl.list.len(), Pair::default());
        }
        // One mutable slice per particle, so the rows fill in parallel, each by its own owner.
        let mut rows: Vec<&mut [Pair]> = Vec::with_capacity(n);
        let mut rest = buf.as_mut_slice();
        for i in 0..n {
            let (row, tail) = rest.split_at_mut(nl.of(i).len());
            rows.push(row);
            rest = tail;
        }
        let out: Vec<(f64, Matrix, u32)> = rows
            .into_par_iter()
            .with_min_len(MIN_LEN)
            .with_max_len(MAX_LEN)
            .enumerate()
            .map(|(i, row)| {
                let bi = p.body[i];
                if !bc[bi as usize].deformable {
                    return (1.0, Matrix::identity(), 0);
                }
                let mut g = p.mass[i] / p.rho[i] * w0;
                let mut m = Matrix::zeros();
                let mut cnt = 0;
                for pair in body_pairs(p, nl, k, i) {
                    // Listed within the skin but outside the support: contributes nothing.
                    if pair.w == 0.0 && pair.dw == 0.0 {
                        continue;
                    }
                    let vj = vol[pair.j];
                    g += vj * pair.w;
                    if pair.r > 0.0 {
                        let grad = pair.xij * (pair.dw / pair.r);
                        m += outer(-pair.xij, grad) * vj;
                    }
                    row[cnt] = pair;
                    cnt += 1;
                }
                (g, correction(m), cnt as u32)
            })
            .collect();
        let s = &mut self.scratch;
        s.pairs = buf;
        s.vol = vol;
        s.shepard.clear();
        s.lcorr.clear();
        s.pair_count.clear();
        for (g, l, c) in out {
            s.shepard.push(g);
            s.lcorr.push(l);
            s.pair_count.push(c);
        }
    }

    /// Velocity gradient with the corrected kernel gradient (eq. 15, 7).
    fn rates(&mut self, bc: &[BodyConst]) {
        let p = &self.particles;
        let nl = &self.nbrs;
        let lc = &self.scratch.lcorr;
        let pairs = &self.scratch;
        let out: Vec<Matrix> = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_LEN)
            .with_max_len(MAX_LEN)
            .map(|i| {
                let bi = p.body[i];
                if !bc[bi as usize].deformable || pairs.pair_count[i] < MIN_SUPPORT_NEIGHBOURS {
                    return Matrix::zeros();
                }
                let vi = p.vel[i];
                let mut gv = Matrix::zeros();
                for &Pair { j, xij, r, dw, .. } in pairs.cached(nl, i) {
                    if r == 0.0 {
                        continue;
                    }
                    gv += outer(p.vel[j] - vi, xij * (dw / r)) * pairs.vol[j];
                }
                gv * lc[i].transpose()
            })
            .collect();
        self.scratch.gradv = out;
    }

    /// Continuity (eq. 5 as ρ̇ = −ρ tr ∇v), Jaumann rate (eq. 13), radial return with Johnson–Cook
    /// yield (eq. 18), adiabatic heating, damage (eqs. 19–20), and the deformation gradient the
    /// hourglass stiffness compares against.
    fn stress(&mut self, bc: &[BodyConst], dt: f64) {
        let gv = &self.scratch.gradv;
        let bodies = &self.bodies;
        let beta = self.settings.taylor_quinney;
        let p = &mut self.particles;
        let plastic_work: f64 = p
            .rho
            .par_iter_mut()
            .zip(p.sdev.par_iter_mut())
            .zip(p.eps_p.par_iter_mut())
            .zip(p.eps_p_rate.par_iter_mut())
            .zip(p.temp.par_iter_mut())
            .zip(p.damage.par_iter_mut())
            .zip(p.def_grad.par_iter_mut())
            .zip(p.body.par_iter())
            .zip(p.mass.par_iter())
            .zip(p.rho0.par_iter())
            .with_min_len(MIN_LEN)
            .with_max_len(MAX_LEN)
            .enumerate()
            .map(
                |(i, (((((((((rho, s), ep), epr), temp), dmg), fdef), &b), &m), &rho0))| {
                    let c = bc[b as usize];
                    if !c.deformable {
                        return 0.0;
                    }
                    let l = gv[i];
                    let d = (l + l.transpose()) * 0.5;
                    let w = (l - l.transpose()) * 0.5;
                    let trd = d.trace();
                    *rho *= 1.0 - dt * trd;
                    *fdef += l * *fdef * dt;
                    let dev = d - Matrix::identity() * (trd / 3.0);
                    let s_trial = *s + (dev * (2.0 * c.shear) + w * *s - *s * w) * dt;
                    let mat = bodies[b as usize]
                        .material()
                        .expect("deformable body has a material");
                    match &mat.plasticity {
                        None => {
                            *s = s_trial;
                            0.0
                        }
                        Some(jc) => {
                            let r = physics::radial_return(s_trial, c.shear, jc, *ep, dt, *temp);
                            *s = r.sdev;
                            *epr = r.d_eps / dt;
                            if r.d_eps > 0.0 {
                                let wp = r.sigma_y * r.d_eps; // plastic work per volume
                                if let Some(dm) = &mat.damage {
                                    let seq = von_mises(&r.sdev);
                                    let pr = c.bulk * (*rho / rho0 - 1.0);
                                    let triax = if seq > 0.0 { -pr / seq } else { 0.0 };
                                    let ef = physics::fracture_strain(dm, jc, triax, *epr, *temp);
                                    *dmg += r.d_eps / ef;
                                }
                                *ep += r.d_eps;
                                *temp += beta * wp / (*rho * mat.heat_capacity_j_kgk);
                                wp * m / *rho
                            } else {
                                0.0
                            }
                        }
                    }
                },
            )
            .collect::<Vec<f64>>()
            .iter()
            .sum();
        self.work.plastic -= plastic_work;
    }

    /// Accelerations from the stress divergence with the normalised gradient (eq. 6, 9), the
    /// hourglass force (eq. 16) and gravity.
    fn forces(&mut self, bc: &[BodyConst], dt: f64) {
        let p = &self.particles;
        let nl = &self.nbrs;
        let k = &self.kernel;
        let alpha = self.settings.hourglass;
        let g = self.settings.gravity_m_s2;
        let h = k.h;
        let radius = k.radius();
        let sh = &self.scratch.shepard;
        let gv = &self.scratch.gradv;
        let cache = &self.scratch;
        // σ_i / (ρ_i² Γ_i): the factor of eq. 6 with eq. 9's normalisation.
        let sig: Vec<Matrix> = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_LEN)
            .with_max_len(MAX_LEN)
            .map(|i| {
                let c = bc[p.body[i] as usize];
                if !c.deformable {
                    return Matrix::zeros();
                }
                let pr = p.pressure(i, c.bulk);
                (p.sdev[i] - Matrix::identity() * pr) / (p.rho[i] * p.rho[i] * sh[i])
            })
            .collect();
        let out: Vec<(Vector, f64)> = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_LEN)
            .with_max_len(MAX_LEN)
            .map(|i| {
                let bi = p.body[i];
                let c = bc[bi as usize];
                // Kinematic particles follow their prescribed motion: their force is never used.
                if !c.deformable || p.flags[i] & KINEMATIC != 0 {
                    return (Vector::zeros(), 0.0);
                }
                if cache.pair_count[i] < MIN_SUPPORT_NEIGHBOURS {
                    return (g, 0.0);
                }
                let vi = p.vel[i];
                let voli = p.mass[i] / p.rho[i];
                let mut a = Vector::zeros();
                let mut fhg = Vector::zeros();
                for &Pair { j, xij, r, w, dw } in cache.cached(nl, i) {
                    if r == 0.0 {
                        continue;
                    }
                    let grad = xij * (dw / r);
                    a += (sig[i] + sig[j]) * grad * p.mass[j];
                    if alpha > 0.0 && w > 0.0 {
                        let e = xij / r;
                        // Not cache.vol: the stress stage has moved ρ since (continuity), and
                        // both volumes must be the same step's for a symmetric pair force.
                        let volj = p.mass[j] / p.rho[j];
                        // Heavily sheared material can bring two particles almost on top of
                        // each other; 1/r² then makes the pair force stiff enough to blow the
                        // explicit step up (seen at 75°, impact 70). Below 0.4 h the weight stops
                        // growing; lattice neighbours (r ≈ 0.77 h) are untouched.
                        let rr = r.max(HG_MIN_SEPARATION_H * h);
                        let cij = alpha * voli * volj * w / (rr * rr);
                        // Viscous part: velocity error against the mean velocity gradient.
                        let vij = vi - p.vel[j];
                        let dv = (vij - (gv[i] + gv[j]) * xij * 0.5).dot(&e);
                        let visc = 0.5 * (p.rho[i] + p.rho[j]) * c.sound * h * dv;
                        // Stiffness part: separation error against the mean deformation gradient.
                        let xr = p.x_ref[i] - p.x_ref[j];
                        let stiff = if xr.norm() < radius {
                            let ds = (xij - (p.def_grad[i] + p.def_grad[j]) * xr * 0.5).dot(&e);
                            c.youngs * ds.clamp(-0.5 * r, 0.5 * r)
                        } else {
                            0.0
                        };
                        fhg -= e * (cij * 0.5 * (stiff + visc));
                    }
                }
                let acc = a + fhg / p.mass[i] + g;
                (acc, fhg.dot(&vi) * dt)
            })
            .collect();
        let s = &mut self.scratch;
        s.acc.clear();
        let mut hg = 0.0;
        for (a, wk) in out {
            s.acc.push(a);
            hg += wk;
        }
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
                .with_min_len(MIN_LEN)
                .with_max_len(MAX_LEN)
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
            .with_min_len(MIN_LEN)
            .with_max_len(MAX_LEN)
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
            .with_min_len(MIN_LEN)
            .with_max_len(MAX_LEN)
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
        let bc = self.body_consts();
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
            .with_min_len(MIN_LEN)
            .with_max_len(MAX_LEN)
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

impl Scratch {
    /// The cached same-body pairs of particle `i` (filled by the kernel sums this step).
    #[inline]
    fn cached<'a>(&'a self, nl: &NeighbourLists, i: usize) -> &'a [Pair] {
        let s = nl.start[i] as usize;
        &self.pairs[s..s + self.pair_count[i] as usize]
    }
}

/// A neighbour j of particle i in i's own body, with x_ij = x_i − x_j, r = |x_ij|, W_ij and dW/dr.
#[derive(Debug, Clone, Copy, Default)]
struct Pair {
    j: usize,
    xij: Vector,
    r: f64,
    w: f64,
    dw: f64,
}

/// The same-body neighbours of `i` with their kernel values: the loop every SPH sum of the
/// deformable solid runs over (eqs. 8, 9, 12, 15, 6, 16), in the lists' fixed order.
fn body_pairs<'a>(
    p: &'a Particles,
    nl: &'a NeighbourLists,
    k: &'a Kernel,
    i: usize,
) -> impl Iterator<Item = Pair> + 'a {
    let (bi, xi) = (p.body[i], p.pos[i]);
    let r2max = k.radius() * k.radius();
    nl.of(i)
        .iter()
        .map(|&j| j as usize)
        .filter(move |&j| p.body[j] == bi)
        .filter_map(move |j| {
            let xij = xi - p.pos[j];
            let r2 = xij.norm_squared();
            // The lists reach a skin beyond the support; those pairs would add exact zeros.
            if r2 >= r2max {
                return None;
            }
            let r = r2.sqrt();
            let (w, dw) = k.w_dw(r);
            Some(Pair { j, xij, r, w, dw })
        })
}

/// Interleaves the bits of `x` and `y` (x in the even bits): the Z-order curve index of a cell.
fn morton(x: u32, y: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = v as u64;
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        v = (v | (v << 1)) & 0x5555_5555_5555_5555;
        v
    }
    spread(x) | (spread(y) << 1)
}

/// Inverts the Bonet–Lok moment matrix (eq. 8); where a particle has too few neighbours for a
/// well-conditioned inverse (an isolated fragment), the uncorrected gradient is used instead.
fn correction(m: Matrix) -> Matrix {
    let tr = m.trace();
    let det = m.determinant();
    // Smallest eigenvalue of the symmetric part relative to the mean: a conditioning measure.
    let disc = ((tr * 0.5).powi(2) - det).max(0.0).sqrt();
    let lmin = tr * 0.5 - disc;
    if tr > 0.0 && lmin > 0.05 * tr * 0.5 {
        m.try_inverse().unwrap_or_else(Matrix::identity)
    } else {
        Matrix::identity()
    }
}
