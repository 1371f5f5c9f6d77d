//! The abrasive water-jet scene (docs/jet.md; the AWJ paper, Sci. Rep. 14, 26115, 2024): a
//! plane jet of water carrying DEM grains hits a metal target straight on, and the crater's
//! depth Cd, width Cw, the mass loss and the largest plastic strain are sampled against time.
//!
//! A run advances in slices of simulated time (`slice_ms`), the farm's unit of progress: after
//! each slice the crater is measured and the whole state can be checkpointed, so a killed run
//! loses at most one slice.

pub mod aggregate;
mod feed;
pub mod runs;
mod scene;

use grit_sph::crater::{self, CraterOptions, CraterSample};
use grit_sph::dem::DemParams;
use grit_sph::world::GrainContacts;
use grit_sph::{InputError, PenaltyParams, SimError, Timers, World};
use serde::{Deserialize, Serialize};

use crate::aggregate::{stats, Stats};
use crate::campaign::MaterialSpec;
pub use feed::{grain_spacing_m, Feed};
pub use scene::{Layout, FIXED_SIDE_LAYERS, WATER_DENSITY_DIFFUSION, WATER_DENSITY_RANGE};

/// Everything that defines one jet run (one sample of a jet campaign's cell); SI units except
/// where the name says. Defaults: the paper's copper case at 500 m/s on a reduced scene
/// (docs/jet.md#the-scene).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct JetParams {
    /// Target material: a preset name (`copper`, `al6061`, `aisi304`) or a full object.
    pub material: MaterialSpec,
    /// Jet speed v_jet at the nozzle (m/s).
    pub velocity_m_s: f64,
    /// Abrasive mass flow M (kg/s, the paper's eq. 55); 0 is a pure water jet.
    pub mass_flow_kg_s: f64,
    /// Simulated time T (ms).
    pub time_ms: f64,
    /// Length of one slice of simulated time, the unit of progress and checkpoints (ms).
    pub slice_ms: f64,
    /// Particle spacing Δx of water and target (m); the paper's d_ini is 50 µm.
    pub spacing_m: f64,
    /// Coupling radius over grain diameter, R_c/d (the paper settles on 2.0).
    pub coupling_radius_d: f64,
    /// Jet width d_jet (m; the paper's 1 mm); a whole number of spacings.
    pub jet_width_m: f64,
    /// Height of the nozzle's exit above the target's top (m; the paper gives none).
    pub standoff_m: f64,
    /// Target width (m).
    pub target_width_m: f64,
    /// Target depth (m).
    pub target_depth_m: f64,
    /// Hold the target's bottom layers fixed, as its sides (the default: the target is a window
    /// into a thick plate); false leaves the bottom free, as the paper does
    /// (docs/jet.md#the-scene). Written out only when false, so default scenes keep their bytes.
    #[serde(skip_serializing_if = "is_true")]
    pub fixed_bottom: bool,
    /// Grain diameter d (m; the paper's 0.2 mm garnet).
    pub grain_diameter_m: f64,
    /// Grain density (kg/m³; garnet 4120).
    pub grain_density_kg_m3: f64,
    /// A grain's speed as it leaves the nozzle over v_jet, in (0, 1] (the paper gives none; 1:
    /// grains move with the water; docs/jet.md#one-grain-in-the-jet). The feed keeps the mass
    /// flow M of eq. 55 whatever the ratio.
    pub grain_speed_ratio: f64,
    /// The porosity at and below which a grain's drag is Ergun's, above it Wen–Yu's (the AWJ
    /// paper's eq. 44 switch, 0.8 after Gidaspow; in (0, 1); docs/jet.md#one-grain-in-the-jet).
    pub drag_switch_porosity: f64,
    /// The grains' contact constants (E, ν, restitution e, friction μ).
    pub dem: DemParams,
    /// The grain–target penalty contact (χ, μ).
    pub penalty: PenaltyParams,
}

/// Serde's test for a field written out only when false.
pub(crate) fn is_true(b: &bool) -> bool {
    *b
}

impl Default for JetParams {
    fn default() -> Self {
        JetParams {
            material: MaterialSpec(grit_sph::Material::copper()),
            velocity_m_s: 500.0,
            mass_flow_kg_s: 0.02,
            time_ms: 1.0,
            slice_ms: 0.05,
            spacing_m: 50e-6,
            coupling_radius_d: 2.0,
            jet_width_m: 1e-3,
            standoff_m: 2e-3,
            target_width_m: 6e-3,
            target_depth_m: 2e-3,
            fixed_bottom: true,
            grain_diameter_m: 0.2e-3,
            grain_density_kg_m3: 4120.0,
            grain_speed_ratio: 1.0,
            drag_switch_porosity: grit_sph::coupling::DEFAULT_SWITCH_POROSITY,
            dem: DemParams::default(),
            penalty: PenaltyParams::default(),
        }
    }
}

/// Most slices one run may have: a guard against a typo that asks for years of steps.
pub const MAX_SLICES: u32 = 100_000;
/// Longest run (ms): past the seed's longest (60 ms), a guard against a typo in the units.
pub const MAX_TIME_MS: f64 = 1000.0;
/// Fastest jet (m/s): above any pump's (a 600 MPa pump gives about 770 m/s, AWJ eq. v = 0.7 √(2P/ρ)).
pub const MAX_JET_SPEED_M_S: f64 = 2000.0;
/// Most particles of the target and the jet's column: a guard against a spacing or size typo
/// that would exhaust a worker's memory.
pub const MAX_SCENE_PARTICLES: f64 = 5e5;

impl JetParams {
    /// Checks every field; the error names the field and the rule.
    pub fn validate(&self) -> Result<(), InputError> {
        self.material.0.validate()?;
        for (name, v) in [
            ("velocity_m_s", self.velocity_m_s),
            ("time_ms", self.time_ms),
            ("slice_ms", self.slice_ms),
            ("spacing_m", self.spacing_m),
            ("coupling_radius_d", self.coupling_radius_d),
            ("jet_width_m", self.jet_width_m),
            ("standoff_m", self.standoff_m),
            ("target_width_m", self.target_width_m),
            ("target_depth_m", self.target_depth_m),
            ("grain_diameter_m", self.grain_diameter_m),
            ("grain_density_kg_m3", self.grain_density_kg_m3),
        ] {
            InputError::require_positive(name, v)?;
        }
        crate::impact::check_grain_density(self.grain_density_kg_m3)?;
        // The paper studies 1.0 to 3.0 d; the pair search grows as R_c².
        if !(0.5..=10.0).contains(&self.coupling_radius_d) {
            return Err(InputError::new(
                "coupling_radius_d",
                format!(
                    "must lie in [0.5, 10] grain diameters (the paper's study spans 1 to 3), got {}",
                    InputError::shown(self.coupling_radius_d)
                ),
            ));
        }
        if !(self.grain_speed_ratio > 0.0 && self.grain_speed_ratio <= 1.0) {
            return Err(InputError::new(
                "grain_speed_ratio",
                format!("must lie in (0, 1], got {}", self.grain_speed_ratio),
            ));
        }
        if !(self.drag_switch_porosity > 0.0 && self.drag_switch_porosity < 1.0) {
            return Err(InputError::new(
                "drag_switch_porosity",
                format!("must lie in (0, 1), got {}", self.drag_switch_porosity),
            ));
        }
        if !(self.mass_flow_kg_s.is_finite() && self.mass_flow_kg_s >= 0.0) {
            return Err(InputError::new(
                "mass_flow_kg_s",
                format!(
                    "must be a finite number >= 0, got {}",
                    InputError::shown(self.mass_flow_kg_s)
                ),
            ));
        }
        self.dem.validate()?;
        self.penalty.validate("penalty")?;
        let cells = |len: f64| len / self.spacing_m;
        let across = cells(self.jet_width_m);
        if (across - across.round()).abs() > 1e-6 || across.round() < 2.0 {
            return Err(InputError::new(
                "jet_width_m",
                format!(
                    "must be a whole number (at least 2) of spacings {} m, got {} m ({across:.4} spacings)",
                    self.spacing_m, self.jet_width_m
                ),
            ));
        }
        if self.target_width_m < self.jet_width_m + 2.0 * FIXED_SIDE_LAYERS as f64 * self.spacing_m
        {
            return Err(InputError::new(
                "target_width_m",
                format!(
                    "must exceed the jet width {} m plus the fixed sides, got {} m",
                    self.jet_width_m, self.target_width_m
                ),
            ));
        }
        if cells(self.target_depth_m) < 2.0 * FIXED_SIDE_LAYERS as f64 + 1.0 {
            return Err(InputError::new(
                "target_depth_m",
                format!(
                    "must be at least {} spacings deep (the fixed bottom and free material)",
                    2 * FIXED_SIDE_LAYERS + 1
                ),
            ));
        }
        if self.standoff_m < self.jet_width_m {
            return Err(InputError::new(
                "standoff_m",
                format!(
                    "must be at least the jet width {} m, got {} m: the stagnation zone, about a jet width deep, would reach the nozzle, whose rows have no buffer, and break the jet (docs/jet.md#the-scene)",
                    self.jet_width_m, self.standoff_m
                ),
            ));
        }
        if self.grain_diameter_m >= self.jet_width_m {
            return Err(InputError::new(
                "grain_diameter_m",
                format!(
                    "must be smaller than the jet width {} m, got {} m",
                    self.jet_width_m, self.grain_diameter_m
                ),
            ));
        }
        if self.slice_ms > self.time_ms {
            return Err(InputError::new(
                "slice_ms",
                format!(
                    "must not exceed time_ms ({}), got {}",
                    self.time_ms, self.slice_ms
                ),
            ));
        }
        if self.slices() > MAX_SLICES {
            return Err(InputError::new(
                "slice_ms",
                format!(
                    "time_ms / slice_ms gives {:.4e} slices; at most {MAX_SLICES}",
                    (self.time_ms / self.slice_ms).ceil()
                ),
            ));
        }
        InputError::require_at_most(
            "time_ms",
            self.time_ms,
            MAX_TIME_MS,
            "ms",
            "the seed's longest run is 60 ms",
        )?;
        InputError::require_at_most(
            "mass_flow_kg_s",
            self.mass_flow_kg_s,
            1.0,
            "kg/s",
            "the paper's runs go to 0.07 kg/s",
        )?;
        InputError::require_at_most(
            "velocity_m_s",
            self.velocity_m_s,
            MAX_JET_SPEED_M_S,
            "m/s",
            "abrasive water jets run at 300-900 m/s",
        )?;
        let arrival_ms = self.standoff_m / self.velocity_m_s * 1e3;
        if arrival_ms >= self.time_ms {
            return Err(InputError::new(
                "velocity_m_s",
                format!(
                    "is too slow for the run: the jet's head needs standoff_m / velocity_m_s = {} ms to reach the target, and the run lasts time_ms = {} ms",
                    InputError::shown(arrival_ms),
                    InputError::shown(self.time_ms)
                ),
            ));
        }
        let area = self.target_width_m * self.target_depth_m + self.jet_width_m * self.standoff_m;
        let particles = area / (self.spacing_m * self.spacing_m);
        if particles > MAX_SCENE_PARTICLES {
            return Err(InputError::new(
                "spacing_m",
                format!(
                    "gives {particles:.3e} particles in the target and the jet (target_width_m × target_depth_m + jet_width_m × standoff_m, over spacing_m²), more than the limit of {MAX_SCENE_PARTICLES:.0e}; the default scene has about 1 800"
                ),
            ));
        }
        Ok(())
    }

    /// Parses and checks a JSON object of parameters (fields left out keep their defaults);
    /// the error names the field at fault.
    pub fn from_json(text: &str) -> Result<JetParams, InputError> {
        let p: JetParams = crate::impact::scene_from_json(text, "JetParams")?;
        p.validate()?;
        Ok(p)
    }

    /// Target mass per unit depth (kg/m): density × width × depth, the most a run can lose
    /// (AWJ paper's target, reduced as `docs/jet.md` says).
    pub fn target_mass_kg_m(&self) -> f64 {
        self.material.0.density_kg_m3 * self.target_width_m * self.target_depth_m
    }

    /// Number of slices: ⌈T / slice⌉ (the last may be shorter).
    pub fn slices(&self) -> u32 {
        let n = (self.time_ms / self.slice_ms - 1e-9).ceil();
        if n.is_finite() && n >= 1.0 {
            n.min(u32::MAX as f64) as u32
        } else {
            1
        }
    }

    /// End time of slice `k` (0-based), s.
    pub fn slice_end_s(&self, k: u32) -> f64 {
        (((k + 1) as f64) * self.slice_ms).min(self.time_ms) * 1e-3
    }
}

/// One finished slice: the crater and the run's state at its end.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JetSlice {
    /// Slice number, from 1.
    pub slice: u32,
    /// Time, mass loss, Cd, Cw and the largest plastic strain at the slice's end.
    pub sample: CraterSample,
    /// Width of the crater at half its depth (m): ½ Cw for a V, → Cw for a U.
    pub half_depth_width_m: f64,
    /// The target's surface profile (x, y) in m, one point per column, left to right.
    pub profile: Vec<[f64; 2]>,
    /// Engine steps taken in the slice.
    pub steps: u64,
    /// Particles (water and target) at the slice's end.
    pub particles: usize,
    /// Grains in the scene at the slice's end.
    pub grains: usize,
    /// Grains fed into the jet so far.
    pub grains_fed: u64,
    /// Water deleted so far for leaving its density range (`WATER_DENSITY_RANGE`), per metre
    /// of depth (kg/m): against the water fed, what the scene's spray cut costs.
    #[serde(default)]
    pub water_deleted_kg_m: f64,
    /// Water fed through the nozzle so far (kg/m).
    #[serde(default)]
    pub water_fed_kg_m: f64,
    /// Wall-clock seconds the slice took.
    pub wall_s: f64,
    /// How the grains met the target in the slice: first touches and how fast they came,
    /// returns, time in contact; absent when no grain touched it (and from runs stored before
    /// it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grain_hits: Option<GrainHits>,
}

/// The grains' contacts with the target in one slice (`World::take_grain_contacts`): how fast
/// the jet delivers its grains, beside the AWJ paper's single grain in a jet, and how long they
/// stay (docs/jet.md#how-fast-the-grains-arrive).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GrainHits {
    /// Grains that touched the target for the first time.
    pub count: usize,
    /// Their speed |v| at the touch (m/s); absent when none touched first in the slice.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_m_s: Option<Stats>,
    /// Their approach speed along the normal of the first contact (m/s); absent likewise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_speed_m_s: Option<Stats>,
    /// The fastest of them, |v| (m/s): a grain faster than the jet has been thrown by a contact.
    pub fastest_m_s: f64,
    /// Contact starts of grains that had touched the target before: returns after leaving it.
    #[serde(default)]
    pub returns: usize,
    /// Σ |v|² over every contact start, first touches and returns (m²/s²): the kinetic energy
    /// per unit mass the grains bring to their contacts.
    #[serde(default)]
    pub start_speed_sq_sum_m2_s2: f64,
    /// Grain-steps in contact: over the slice's steps, the number of grains touching in each.
    #[serde(default)]
    pub steps_in_contact: u64,
}

impl GrainHits {
    /// The statistics of a slice's `contacts`; `None` when no grain touched the target.
    pub fn of(contacts: &GrainContacts) -> Option<GrainHits> {
        if contacts.starts.is_empty() && contacts.steps_in_contact == 0 {
            return None;
        }
        let first: Vec<_> = contacts.starts.iter().filter(|h| h.first).collect();
        let speeds: Vec<f64> = first.iter().map(|h| h.speed_m_s).collect();
        let normal: Vec<f64> = first.iter().map(|h| h.normal_speed_m_s).collect();
        Some(GrainHits {
            count: first.len(),
            speed_m_s: stats(&speeds),
            normal_speed_m_s: stats(&normal),
            fastest_m_s: speeds.iter().copied().fold(0.0, f64::max),
            returns: contacts.starts.len() - first.len(),
            start_speed_sq_sum_m2_s2: contacts.starts.iter().map(|h| h.speed_m_s.powi(2)).sum(),
            steps_in_contact: contacts.steps_in_contact,
        })
    }
}

/// Why a jet run could not go on.
#[derive(Debug, thiserror::Error)]
pub enum JetError {
    /// The parameters are not usable.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The simulation blew up.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// A checkpoint could not be read or belongs to another run.
    #[error("checkpoint {0}")]
    Checkpoint(String),
}

/// A jet run in progress: the world, the grain feed, and the slices done.
#[derive(Debug, Clone)]
pub struct JetRun {
    params: JetParams,
    seed: u64,
    layout: Layout,
    world: World,
    feed: Feed,
    slices: Vec<JetSlice>,
}

/// What a checkpoint holds; the world goes as JSON (its optional parts are skipped when
/// absent, which only a self-describing format reads back).
#[derive(Serialize, Deserialize)]
struct Checkpoint {
    version: u32,
    params: JetParams,
    seed: u64,
    world: World,
    feed: Feed,
    slices: Vec<JetSlice>,
}

/// Version of the checkpoint layout; a build reads only its own.
const CHECKPOINT_VERSION: u32 = 3;

impl JetRun {
    /// A fresh run of `params` whose grains are placed from `seed`.
    pub fn new(params: JetParams, seed: u64) -> Result<JetRun, JetError> {
        params.validate()?;
        let (world, layout) = scene::build(&params)?;
        let feed = Feed::new(&params);
        Ok(JetRun {
            params,
            seed,
            layout,
            world,
            feed,
            slices: Vec::new(),
        })
    }

    /// The parameters.
    pub fn params(&self) -> &JetParams {
        &self.params
    }
    /// The seed of the grain placement.
    pub fn seed(&self) -> u64 {
        self.seed
    }
    /// The world as it is now.
    pub fn world(&self) -> &World {
        &self.world
    }
    /// Where the scene's parts are.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }
    /// Slices finished.
    pub fn slices(&self) -> &[JetSlice] {
        &self.slices
    }
    /// Slices finished so far.
    pub fn slices_done(&self) -> u32 {
        self.slices.len() as u32
    }
    /// Slices in the whole run.
    pub fn slices_total(&self) -> u32 {
        self.params.slices()
    }
    /// True when every slice is done.
    pub fn finished(&self) -> bool {
        self.slices_done() >= self.slices_total()
    }
    /// The engine's per-stage timers over the last slice.
    pub fn timers(&self) -> &Timers {
        self.world.timers()
    }

    /// Runs on to `time_ms` in all (a resumed run made longer); its slices so far stay, so
    /// `time_ms` must not cut into them.
    pub fn extend(&mut self, time_ms: f64) -> Result<(), JetError> {
        // Slices end on the step past their planned time, so the reached time may exceed the
        // planned one by a step: the plan, not the clock, says what has been run.
        let done = self.slices_done();
        let done_ms = (f64::from(done) * self.params.slice_ms).min(self.params.time_ms);
        let mut p = self.params.clone();
        p.time_ms = time_ms;
        p.validate()?;
        if time_ms < done_ms * (1.0 - 1e-9) || p.slices() < done {
            return Err(JetError::Input(InputError::new(
                "time_ms",
                format!("the run has reached {done_ms} ms; it cannot end at {time_ms} ms"),
            )));
        }
        let short_last = f64::from(done) * self.params.slice_ms > done_ms * (1.0 + 1e-9);
        if short_last && time_ms > done_ms * (1.0 + 1e-9) {
            return Err(JetError::Input(InputError::new(
                "time_ms",
                format!(
                    "the run's last slice ended short, at {done_ms} ms; only a run of whole slices of {} ms can be made longer",
                    self.params.slice_ms
                ),
            )));
        }
        self.params = p;
        Ok(())
    }

    /// Runs the next slice; returns it.
    pub fn run_next_slice(&mut self) -> Result<&JetSlice, JetError> {
        self.run_next_slice_observed(&|| false, None)?
            .ok_or_else(|| JetError::Checkpoint("cancelled without a cancel request".into()))
    }

    /// Runs the next slice, calling `observe` after every step (snapshots, progress) and
    /// giving up (`None`, state as at the slice's start is lost: resume from a checkpoint)
    /// when `cancel` says so between steps.
    pub fn run_next_slice_observed(
        &mut self,
        cancel: &dyn Fn() -> bool,
        mut observe: Option<&mut dyn FnMut(&World)>,
    ) -> Result<Option<&JetSlice>, JetError> {
        let k = self.slices_done();
        if k >= self.slices_total() {
            return Err(JetError::Input(InputError::new(
                "slice",
                format!("the run has all its {k} slices"),
            )));
        }
        let t_end = self.params.slice_end_s(k);
        let t0 = std::time::Instant::now();
        let steps0 = self.world.steps();
        self.world.timers_mut().reset();
        // A slice abandoned by `cancel` may have left touches of its own in the log.
        self.world.take_grain_contacts();
        while self.world.time() < t_end {
            if cancel() {
                return Ok(None);
            }
            self.world.step()?;
            self.feed
                .release(&mut self.world, &self.params, &self.layout, self.seed)?;
            if let Some(f) = observe.as_mut() {
                f(&self.world);
            }
        }
        let contacts = self.world.take_grain_contacts();
        let slice = self.measure(
            k + 1,
            self.world.steps() - steps0,
            t0.elapsed().as_secs_f64(),
            &contacts,
        )?;
        self.slices.push(slice);
        Ok(self.slices.last())
    }

    /// The crater and state now, as slice `slice`. The mass loss is the target's deleted
    /// particles (D ≥ 1) and the fragments that left the scene; the crater is measured on the
    /// target that still hangs together with its fixed particles.
    fn measure(
        &self,
        slice: u32,
        steps: u64,
        wall_s: f64,
        contacts: &GrainContacts,
    ) -> Result<JetSlice, JetError> {
        let w = &self.world;
        let opts = CraterOptions::for_spacing(self.params.spacing_m);
        let target = self.layout.target_body;
        let fragments: f64 = w
            .outflows()
            .iter()
            .filter(|o| o.body == target)
            .map(|o| o.mass_kg_m)
            .sum();
        let loss = w.bodies()[target].removed_mass_kg_m + fragments;
        let p = w.particles();
        let (sample, c) = crater::sample(
            w.time(),
            p,
            target as u32,
            loss,
            self.layout.surface_y_m,
            opts,
        )?;
        Ok(JetSlice {
            slice,
            sample,
            half_depth_width_m: c.half_depth_width_m,
            profile: c.profile.iter().map(|x| [x.x, x.y]).collect(),
            steps,
            particles: p.len(),
            grains: w.abrasives().map_or(0, |a| a.dem.grains.len()),
            grains_fed: self.feed.fed(),
            water_deleted_kg_m: w.bodies()[self.layout.fluid_body].removed_mass_kg_m,
            water_fed_kg_m: w.inflows().iter().map(|i| i.mass_kg_m).sum(),
            wall_s,
            grain_hits: GrainHits::of(contacts),
        })
    }

    /// The state after the last finished slice, as bytes (JSON; floats kept bit for bit).
    pub fn checkpoint(&self) -> Vec<u8> {
        let c = Checkpoint {
            version: CHECKPOINT_VERSION,
            params: self.params.clone(),
            seed: self.seed,
            world: self.world.clone(),
            feed: self.feed.clone(),
            slices: self.slices.clone(),
        };
        serde_json::to_vec(&c).expect("a checkpoint always serialises")
    }

    /// Goes on from `checkpoint()` bytes; the parameters and seed must be the run's own.
    pub fn resume(params: &JetParams, seed: u64, bytes: &[u8]) -> Result<JetRun, JetError> {
        let run = JetRun::from_checkpoint(bytes)?;
        if run.params != *params || run.seed != seed {
            return Err(JetError::Checkpoint(
                "belongs to another run (parameters or seed differ)".into(),
            ));
        }
        Ok(run)
    }

    /// Goes on from `checkpoint()` bytes with the parameters and seed stored in them.
    pub fn from_checkpoint(bytes: &[u8]) -> Result<JetRun, JetError> {
        let c: Checkpoint = serde_json::from_slice(bytes)
            .map_err(|e| JetError::Checkpoint(format!("cannot decode: {e}")))?;
        if c.version != CHECKPOINT_VERSION {
            return Err(JetError::Checkpoint(format!(
                "version {} but this build reads {CHECKPOINT_VERSION}",
                c.version
            )));
        }
        c.params.validate()?;
        // The slices must be the world's own: numbered 1, 2, … and as many as the world's
        // clock has passed the ends of (a slice ends on the first step past its end).
        if let Some(i) = (0..c.slices.len()).find(|&i| c.slices[i].slice as usize != i + 1) {
            return Err(JetError::Checkpoint(format!(
                "slices[{i}] is numbered {}, not {}",
                c.slices[i].slice,
                i + 1
            )));
        }
        let n = c.slices.len() as u32;
        let t = c.world.time();
        let from = if n == 0 {
            0.0
        } else {
            c.params.slice_end_s(n - 1)
        };
        let to = (n < c.params.slices()).then(|| c.params.slice_end_s(n));
        if t < from || to.is_some_and(|to| t >= to) {
            return Err(JetError::Checkpoint(format!(
                "holds {n} slices but its world is at t = {t:e} s, outside the span from the end of slice {n} ({from:e} s) to the end of the next{}",
                to.map_or(String::new(), |to| format!(" ({to:e} s)"))
            )));
        }
        let layout = Layout::of(&c.params);
        Ok(JetRun {
            params: c.params,
            seed: c.seed,
            layout,
            world: c.world,
            feed: c.feed,
            slices: c.slices,
        })
    }
}
