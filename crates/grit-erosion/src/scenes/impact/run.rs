//! One impact of the scene of seed section 4 (Fig. 7a): a rigid grain, randomly oriented and
//! aimed, hitting an AISI 304 surface at speed V and angle α, run until the grain has left and
//! the surface has settled.

use grit_sph::{
    cfl_matched_stiffness, neighbours, particles::KINEMATIC, ContactParams, InputError, Motion,
    Particles, SimError, Timers, Vector, World,
};
use serde::{Deserialize, Serialize};

use super::params::*;
use crate::models::shapes::Shape;

/// What one impact did, beside the surface state it leaves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactOutcome {
    /// Surface mass removed (kg/m): failed particles (D ≥ 1, eq. 19) plus fragments torn off
    /// the surface (`detached_kg`).
    pub mass_loss_kg: f64,
    /// Failed particles removed.
    pub removed_particles: u32,
    /// Mass of fragments no longer connected to the surface when the impact ends (kg/m): chips
    /// whose particles did not reach D = 1 but left all the same.
    pub detached_kg: f64,
    /// Particles in those fragments.
    pub detached_particles: u32,
    /// Simulated time of the impact (s), the skipped flight included.
    pub sim_time_s: f64,
    /// Steps computed (a skipped flight's steps are not).
    pub steps: u64,
    /// Grain speed after the impact over before.
    pub rebound_ratio: f64,
    /// True when the end criterion was met; false when the time limit ended the impact.
    pub settled: bool,
    /// Damage the impact added to the surface, Σ m ΔD over its free particles, a failed particle
    /// counted to D = 1 (kg/m; eq. 19): what a stationary surface's mass loss pays for
    /// (docs/erosion.md, *The damage balance*). `None` in records written before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damage_added_kg: Option<f64>,
}

/// Why an impact stopped without a result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// The scene was not valid.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The simulation went unstable (the engine's failure checks, docs/design.md).
    #[error(transparent)]
    Sim(#[from] SimError),
    /// Cancelled from outside; the surface state is untouched.
    #[error("impact cancelled")]
    Cancelled,
}

/// One finished impact: the surface it leaves, what it did, and where the time went.
#[derive(Debug, Clone)]
pub struct ImpactRun {
    /// Surface particles afterwards (the next impact's start).
    pub surface: Particles,
    /// Mass loss and engine figures.
    pub outcome: ImpactOutcome,
    /// Per-stage wall time (not part of any result: it differs between runs).
    pub timers: Timers,
    /// Particles in the scene at the start (surface and grain).
    pub particles: usize,
}

/// Runs one impact of `grain` on `surface` (seed section 4): temperature reset, surface at
/// rest, grain free; ends when the grain has left and the surface has settled. `cancel` is
/// polled every step.
pub fn run_impact(
    params: &ImpactParams,
    surface: &Particles,
    grain: &GrainStart,
    cancel: &dyn Fn() -> bool,
) -> Result<ImpactRun, ImpactError> {
    run_impact_observed(params, surface, grain, cancel, None)
}

/// Simulated time after which an impact is given up as never meeting its end criterion (s).
pub fn max_impact_time(params: &ImpactParams) -> f64 {
    MAX_TRANSITS * params.grain_diameter_m / params.velocity_m_s
}

/// The grain's body number in an impact's world (the surface is body 0).
pub const GRAIN_BODY: usize = 1;

/// The surface's body number in an impact's world.
pub const SURFACE_BODY: usize = 0;

/// The world of one impact before its first step (seed section 4): the surface at rest and at
/// room temperature, the grain free, and the seed's contact between them (eqs. 21–29).
pub fn impact_world(
    params: &ImpactParams,
    surface: &Particles,
    grain: &GrainStart,
) -> Result<World, InputError> {
    let mut world = World::new(params.settings())?;
    let mut state = surface.clone();
    // Grains arrive milliseconds apart in a blasting test: the surface is at rest and at room
    // temperature again by then (seed section 4), while stress, strain and damage remain.
    state.vel.iter_mut().for_each(|v| *v = Vector::zeros());
    let s = world.add_deformable_state("surface", params.material.clone(), state, Motion::Fixed)?;
    world.reset_temperature();
    let g = world.add_rigid(
        "grain",
        &grain.polygon,
        params.grain_density_kg_m3,
        grain.velocity_m_s,
        0.0,
        Motion::Free,
    )?;
    debug_assert_eq!(
        (s, g),
        (SURFACE_BODY, GRAIN_BODY),
        "the body numbers are documented"
    );
    world.add_contact(
        g,
        s,
        ContactParams {
            model: params.numerics.contact_model,
            friction: params.friction,
            normal_stiffness_pa: Some(
                params.numerics.contact_stiffness_scale
                    * cfl_matched_stiffness(&params.material, world.settings().h_over_dx),
            ),
            ..Default::default()
        },
    )?;
    Ok(world)
}

/// The reference impact (seed section 4: hexagon, 45°, 100 m/s, AISI 304) at `spacing_m` on a
/// fresh surface, stepped until the grain has pressed on it for `contact_steps` steps: the state
/// the stage benchmarks time (docs/performance.md).
pub fn mid_contact_world(spacing_m: f64, contact_steps: u32) -> Result<World, ImpactError> {
    let params = ImpactParams {
        spacing_m,
        ..ImpactParams::paper(45.0, Shape::Hexagon)
    };
    let surface = params.fresh_surface()?;
    let grain = params.grain_start(0.3, 0.5)?;
    let mut w = impact_world(&params, &surface, &grain)?;
    let mut touching = 0;
    while touching < contact_steps {
        w.step()?;
        if w.contact_forces().iter().any(|f| f.norm() > 0.0) {
            touching += 1;
        }
    }
    Ok(w)
}

/// A read-only look at the world after every step of an impact (surface body 0, grain body 1).
pub type StepObserver<'a> = &'a mut dyn FnMut(&World);

/// `run_impact`, calling `observe` after every step. The observer sees the world read-only, so
/// the impact's results are bit for bit those of `run_impact`.
pub fn run_impact_observed(
    params: &ImpactParams,
    surface: &Particles,
    grain: &GrainStart,
    cancel: &dyn Fn() -> bool,
    mut observe: Option<StepObserver>,
) -> Result<ImpactRun, ImpactError> {
    let mut world = impact_world(params, surface, grain)?;
    let mut skipped_steps = 0;
    if params.numerics.skip_flight {
        // Whole steps of the flight, each of the step the world would take (the surface is at
        // rest and the grain is rigid, so the step does not change in flight): the density
        // filter's passes then fall where they would without the skip.
        let dt = world.next_dt();
        let speed = grain.velocity_m_s.norm();
        let s = flight_to_contact(params, surface, grain);
        skipped_steps = (s / (speed * dt)).floor() as u64;
        if skipped_steps > 0 {
            let moved = GrainStart {
                polygon: grain
                    .polygon
                    .translated(grain.velocity_m_s * (skipped_steps as f64 * dt)),
                ..grain.clone()
            };
            world = impact_world(params, surface, &moved)?;
            world.count_skipped_steps(skipped_steps, dt);
        }
    }
    let (s, g) = (SURFACE_BODY, GRAIN_BODY);
    let damage_before = damage_stock(surface);
    let e0 = world.energy().kinetic;
    let particles = world.particles().len();
    let dg = params.grain_diameter_m;
    let half_width = 0.5 * params.surface_width_dg * dg;
    let t_max = max_impact_time(params);
    let mut quiet = 0u32;
    let (mut detached_kg, mut detached_particles, mut detached_damage) = (0.0, 0u32, 0.0);
    let mut settled = false;
    while world.time() < t_max {
        if cancel() {
            return Err(ImpactError::Cancelled);
        }
        world.step()?;
        if let Some(f) = observe.as_mut() {
            f(&world);
        }
        let touching = world
            .contact_forces()
            .iter()
            .any(|f| f.x != 0.0 || f.y != 0.0);
        quiet = if touching { 0 } else { quiet + 1 };
        let r = world.bodies()[g].rigid().expect("grain is rigid");
        // Past a side edge counts only while moving outward: a grazing grain can start
        // beyond the edge and fly in.
        let beyond = r.com_m.x.abs() > half_width + dg && r.com_m.x * r.velocity_m_s.x > 0.0;
        let away = r.velocity_m_s.y > 0.0 || beyond;
        if quiet >= SEPARATED_STEPS && away && quiet.is_multiple_of(10) {
            // Flying fragments would hold the surface's kinetic energy up forever.
            let keep = attached(&world, s, DETACH_LINK_DX * params.spacing_m);
            if keep.iter().any(|k| !k) {
                let p = world.particles();
                for (i, _) in keep.iter().enumerate().filter(|(_, k)| !**k) {
                    detached_kg += p.mass[i];
                    detached_particles += 1;
                    detached_damage += p.mass[i] * p.damage[i];
                }
                world.remove_particles(&keep)?;
            }
            let e = world.energy();
            let surface_ke = e.kinetic - grain_kinetic(&world, g);
            if surface_ke < params.settle_fraction * e0 {
                settled = true;
                break;
            }
        }
    }
    let r = world.bodies()[g].rigid().expect("grain is rigid");
    let after = world.body_state(s);
    // Failed particles left at D = 1 (eq. 19); fragments took the damage they had.
    let damage_added = damage_stock(&after) + world.bodies()[s].removed_mass_kg_m + detached_damage
        - damage_before;
    let outcome = ImpactOutcome {
        mass_loss_kg: world.bodies()[s].removed_mass_kg_m + detached_kg,
        removed_particles: world.bodies()[s].removed_particles as u32,
        detached_kg,
        detached_particles,
        sim_time_s: world.time(),
        steps: world.steps() - skipped_steps,
        rebound_ratio: r.velocity_m_s.norm() / params.velocity_m_s,
        settled,
        damage_added_kg: Some(damage_added),
    };
    Ok(ImpactRun {
        surface: after,
        outcome,
        timers: world.timers().clone(),
        particles,
    })
}

/// How far the grain can fly along its path before the contact of eqs. 21–24 (or the
/// penetration model) would first push on any surface particle (m), less a margin of
/// `FLIGHT_MARGIN_DX`; 0 when it starts within that margin. Searched in steps of
/// `FLIGHT_PROBE_DX` with the engine's own detection, over the grain's outline particles as the
/// world places them.
pub fn flight_to_contact(params: &ImpactParams, surface: &Particles, grain: &GrainStart) -> f64 {
    let dx = params.spacing_m;
    let settings = params.settings();
    let kernel = grit_sph::Kernel::new(settings.kernel, settings.h_over_dx * dx);
    let reach = kernel.radius();
    let (pts, boundary) = grain.polygon.fill_layered(dx);
    let outline: Vec<Vector> = pts
        .iter()
        .zip(boundary)
        .filter_map(|(x, b)| b.then_some(*x))
        .collect();
    let speed = grain.velocity_m_s.norm();
    if outline.is_empty() || surface.is_empty() || speed == 0.0 {
        return 0.0;
    }
    let dir = grain.velocity_m_s / speed;
    // Only surface particles that the outline can come within reach of along the path.
    let lowest = outline.iter().map(|x| x.y).fold(f64::INFINITY, f64::min);
    let top = surface
        .pos
        .iter()
        .map(|x| x.y)
        .fold(f64::NEG_INFINITY, f64::max);
    // The lowest outline particle sinks |dir.y| per metre of path. The search stops at `limit`,
    // where it is the reach below the highest surface particle: over a flat surface contact has
    // begun by then; over a crater it may not have, and the grain is left there, every probe
    // before it having been clear.
    let limit = if dir.y < 0.0 {
        (lowest - top + reach) / -dir.y
    } else {
        0.0
    };
    let touches = |s: f64| {
        let shift = dir * s;
        let moved: Vec<Vector> = outline.iter().map(|x| x + shift).collect();
        let (mut lo, mut hi) = (moved[0], moved[0]);
        for x in &moved {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        let near = |x: &Vector| {
            x.x > lo.x - reach && x.x < hi.x + reach && x.y > lo.y - reach && x.y < hi.y + reach
        };
        surface.pos.iter().filter(|x| near(x)).any(|&xi| {
            let js = (0..moved.len()).filter(|&j| (xi - moved[j]).norm() < reach);
            grit_sph::contact::Detector {
                model: params.numerics.contact_model,
                kernel: &kernel,
                dx,
                k_r: 1.0,
            }
            .detect(xi, js, &moved, |_| 1.0)
            .is_some_and(|d| d.penetration > 0.0)
        })
    };
    let step = FLIGHT_PROBE_DX * dx;
    let mut s = 0.0;
    while s <= limit.max(0.0) && !touches(s) {
        s += step;
    }
    (s - FLIGHT_MARGIN_DX * dx).max(0.0)
}

/// The grain at the step of an impact when its total contact force was largest: the moment a
/// picture of the eroded surface draws it at (seed Fig. 13 shows surface and grain together).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PeakContact {
    /// Grain outline at that step, counter-clockwise (m).
    pub outline_m: Vec<Vector>,
    /// Magnitude of the grain's total contact force then (N/m, eq. 17).
    pub force_n_m: f64,
    /// Simulated time of that step since the impact started (s).
    pub time_s: f64,
    /// Lowest point of the outline below the original surface line y = 0 (m; negative when
    /// the grain stayed above it).
    pub depth_m: f64,
}

/// Follows an impact step by step (an observer for `run_impact_observed`) and keeps the grain's
/// pose at the step of largest contact force: one force read and a comparison per step; the
/// outline is built only when a larger force is seen.
#[derive(Debug, Clone)]
pub struct PeakTracker {
    /// Outline vertices relative to the grain's starting centre of mass (m).
    offsets: Vec<Vector>,
    best_force_sq: f64,
    peak: Option<PeakContact>,
}

impl PeakTracker {
    /// A tracker for the impact that fires `grain`.
    pub fn new(grain: &GrainStart) -> Self {
        let c = grain.polygon.centroid();
        PeakTracker {
            offsets: grain.polygon.vertices().iter().map(|v| v - c).collect(),
            best_force_sq: 0.0,
            peak: None,
        }
    }

    /// Looks at the world after one step.
    pub fn observe(&mut self, world: &World) {
        let Some(r) = world.bodies().get(GRAIN_BODY).and_then(|b| b.rigid()) else {
            return;
        };
        let f2 = r.contact_force_n_m.norm_squared();
        if f2 > self.best_force_sq {
            self.best_force_sq = f2;
            // A rigid body's centre of mass starts at its polygon's centroid with angle 0
            // (World::add_rigid), so the outline follows from its pose alone.
            let outline_m: Vec<Vector> = self
                .offsets
                .iter()
                .map(|&o| r.com_m + grit_sph::math::rotate(o, r.angle_rad))
                .collect();
            let depth_m = -outline_m.iter().map(|v| v.y).fold(f64::INFINITY, f64::min);
            self.peak = Some(PeakContact {
                outline_m,
                force_n_m: f2.sqrt(),
                time_s: world.time(),
                depth_m,
            });
        }
    }

    /// The grain at the largest contact force seen; `None` if it never touched.
    pub fn peak(&self) -> Option<&PeakContact> {
        self.peak.as_ref()
    }

    /// The grain at the largest contact force seen, taken out.
    pub fn into_peak(self) -> Option<PeakContact> {
        self.peak
    }
}

/// Particles of the surface closer than this (in Δx) are connected; a lattice neighbour sits
/// at 1 Δx, a diagonal one at 1.41 Δx.
const DETACH_LINK_DX: f64 = 1.5;

/// Keep-mask over all particles: false for surface particles in a fragment that no chain of
/// neighbours closer than `link` joins to a fixed (kinematic) particle of body `s`.
fn attached(world: &World, s: usize, link: f64) -> Vec<bool> {
    let p = world.particles();
    let n = p.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let ours: Vec<bool> = (0..n).map(|i| p.body[i] as usize == s).collect();
    // The engine's cell grid, its radius a hair over `link` so that the strict test below,
    // not rounding in a squared distance, decides every pair.
    let near = neighbours::build(&p.pos, &ours, &ours, link * (1.0 + 1e-9), |i, j| {
        (p.pos[i] - p.pos[j]).norm() < link
    });
    for i in 0..n {
        for &j in near.of(i) {
            let (a, b) = (root(&mut parent, i), root(&mut parent, j as usize));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut anchored = vec![false; n];
    for i in (0..n).filter(|&i| p.body[i] as usize == s && p.flags[i] & KINEMATIC != 0) {
        let r = root(&mut parent, i);
        anchored[r] = true;
    }
    (0..n)
        .map(|i| p.body[i] as usize != s || anchored[root(&mut parent, i)])
        .collect()
}

/// Σ m D over a surface's free particles (kg/m): the damage stock (the fixed layers never
/// fail).
pub fn damage_stock(surface: &Particles) -> f64 {
    (0..surface.len())
        .filter(|&i| surface.flags[i] & KINEMATIC == 0)
        .map(|i| surface.mass[i] * surface.damage[i])
        .sum()
}

fn grain_kinetic(world: &World, g: usize) -> f64 {
    let r = world.bodies()[g].rigid().expect("grain is rigid");
    0.5 * r.mass_kg_m * r.velocity_m_s.norm_squared() + 0.5 * r.inertia_kg_m * r.omega_rad_s.powi(2)
}

/// Number of particles of a surface state that are free (not fixed boundary).
pub fn free_particles(surface: &Particles) -> usize {
    surface
        .flags
        .iter()
        .filter(|&&f| f & KINEMATIC == 0)
        .count()
}
