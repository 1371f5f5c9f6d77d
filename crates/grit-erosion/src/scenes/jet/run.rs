//! One jet run, slice by slice: the world, the grain feed, the crater after each slice, and
//! its checkpoints.

use grit_sph::cracks::RockDamage;
use grit_sph::crater::{self, CraterOptions, CraterSample};
use grit_sph::world::GrainContacts;
use grit_sph::{InputError, SimError, Timers, World, WorldState};
use serde::{Deserialize, Serialize};
use sha2::Digest;

use super::feed::Feed;
use super::scene::{self, Layout};
use crate::campaign::{CellRecords, StoredJob};
use crate::scene::{Scene, SceneError};
use crate::stats::{stats, Stats};

use super::params::*;

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
    /// A rock target's detached mass and cracks at the slice's end (docs/jet.md#rock-targets),
    /// so a farm's stored slices carry them; absent for a metal, whose records keep their bytes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rock: Option<RockDamage>,
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
    /// Ids of the rock particles found detached so far, sorted (`rock::detach`).
    detached: Vec<u32>,
}

/// What a checkpoint holds; the world goes as JSON (its optional parts are skipped when
/// absent, which only a self-describing format reads back). A world written before
/// `WorldState` existed has no version of its own and reads as its version 1.
#[derive(Serialize, Deserialize)]
struct Checkpoint {
    version: u32,
    params: JetParams,
    seed: u64,
    world: WorldState,
    feed: Feed,
    slices: Vec<JetSlice>,
    /// A rock's damage per slice as checkpoints kept it before the slices carried it: read
    /// into the slices, never written.
    #[serde(default, skip_serializing)]
    rock: Vec<RockDamage>,
    /// Absent while no rock particle has been detached.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    detached: Vec<u32>,
}

/// Version of the checkpoint layout: the JSON, a newline and the SHA-256 of the JSON in hex.
const CHECKPOINT_VERSION: u32 = 4;
/// The layout before checkpoints carried a checksum: the JSON alone, still read.
const UNCHECKED_VERSION: u32 = 3;

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
            detached: Vec::new(),
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
    /// A rock target's detached mass and cracks after each slice (docs/jet.md#rock-targets),
    /// one per slice; empty for a metal.
    pub fn rock_damage(&self) -> Vec<RockDamage> {
        self.slices.iter().filter_map(|s| s.rock).collect()
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
        let rock = self.params.material.0.jh2().is_some();
        let every = super::rock::detach_every_s(self.params.spacing_m);
        while self.world.time() < t_end {
            if cancel() {
                return Ok(None);
            }
            let before = self.world.time();
            self.world.step()?;
            if rock && (self.world.time() / every).floor() > (before / every).floor() {
                super::rock::detach(
                    &self.world,
                    self.layout.target_body,
                    self.params.spacing_m,
                    &mut self.detached,
                )?;
            }
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
    /// target that still hangs together with its fixed particles. A rock keeps its fractured
    /// particles: its loss adds those found detached (`rock::measure`).
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
        let (sample, c, rock) = if self.params.material.0.jh2().is_some() {
            let (s, c, r) = super::rock::measure(
                w,
                target,
                self.layout.surface_y_m,
                self.params.spacing_m,
                loss,
                &self.detached,
            )?;
            (s, c, Some(r))
        } else {
            let (s, c) = crater::sample(
                w.time(),
                p,
                target as u32,
                loss,
                self.layout.surface_y_m,
                opts,
                None,
            )?;
            (s, c, None)
        };
        let slice = JetSlice {
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
            rock,
        };
        Ok(slice)
    }

    /// The state after the last finished slice, as bytes: JSON (floats kept bit for bit), a
    /// newline, and the SHA-256 of the JSON in hex (FIPS 180-4), so bytes damaged at rest are
    /// refused instead of resumed into other numbers.
    pub fn checkpoint(&self) -> Vec<u8> {
        let c = Checkpoint {
            version: CHECKPOINT_VERSION,
            params: self.params.clone(),
            seed: self.seed,
            world: self.world.state(),
            feed: self.feed.clone(),
            slices: self.slices.clone(),
            rock: Vec::new(),
            detached: self.detached.clone(),
        };
        let mut bytes = serde_json::to_vec(&c).expect("a checkpoint always serialises");
        let digest = format!("{:x}", sha2::Sha256::digest(&bytes));
        bytes.push(b'\n');
        bytes.extend_from_slice(digest.as_bytes());
        bytes
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
        let bad = |m: String| JetError::Checkpoint(m);
        // Compact JSON holds no newline: one separates the checksum of a checked layout.
        let (body, sum) = match bytes.iter().rposition(|&b| b == b'\n') {
            Some(i) => (&bytes[..i], Some(&bytes[i + 1..])),
            None => (bytes, None),
        };
        if let Some(sum) = sum {
            if sum.len() != 64 {
                return Err(bad(format!(
                    "truncated: {} of the 64 hex digits of its checksum are there",
                    sum.len().min(64)
                )));
            }
            if format!("{:x}", sha2::Sha256::digest(body)).as_bytes() != sum {
                return Err(bad(
                    "damaged: its bytes do not match their SHA-256 checksum".into(),
                ));
            }
        }
        let mut c: Checkpoint =
            serde_json::from_slice(body).map_err(|e| bad(format!("cannot decode: {e}")))?;
        let expected = if sum.is_some() {
            CHECKPOINT_VERSION
        } else {
            UNCHECKED_VERSION
        };
        if c.version != expected {
            return Err(bad(format!(
                "version {} but this build reads {UNCHECKED_VERSION} (no checksum) and \
                 {CHECKPOINT_VERSION} (with one)",
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
        if !c.rock.is_empty() {
            if c.rock.len() != c.slices.len() {
                return Err(JetError::Checkpoint(format!(
                    "holds {} rock damage records for its {} slices",
                    c.rock.len(),
                    c.slices.len()
                )));
            }
            for (s, r) in c.slices.iter_mut().zip(&c.rock) {
                s.rock = Some(*r);
            }
        }
        let rock = c.params.material.0.jh2().is_some();
        if let Some(s) = c.slices.iter().find(|s| s.rock.is_some() != rock) {
            return Err(JetError::Checkpoint(format!(
                "slice {} {} rock damage, but its target is {}",
                s.slice,
                if rock { "lacks" } else { "holds" },
                c.params.material.0.name
            )));
        }
        let world = World::from_state(c.world)
            .map_err(|e| JetError::Checkpoint(format!("cannot decode: {e}")))?;
        let n = c.slices.len() as u32;
        let t = world.time();
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
            world,
            feed: c.feed,
            slices: c.slices,
            detached: c.detached,
        })
    }
}
impl Scene for JetRun {
    const KIND: &'static str = "jet";
    const UNIT: &'static str = "slice";
    const RECORDS: &'static str = "slices";
    // A cancelled slice leaves the world mid-slice.
    const CHECKPOINT_EACH_UNIT: bool = true;
    type Params = JetParams;
    type Record = JetSlice;

    fn engine() -> Result<String, SceneError> {
        static FINGERPRINT: std::sync::OnceLock<Result<String, String>> =
            std::sync::OnceLock::new();
        crate::fingerprint::once(&FINGERPRINT, crate::fingerprint::jet_engine)
    }

    fn start(params: &JetParams, seed: u64) -> Result<JetRun, SceneError> {
        JetRun::new(params.clone(), seed).map_err(|e| SceneError::Run(e.to_string()))
    }

    fn resume(params: &JetParams, seed: u64, bytes: &[u8]) -> Result<JetRun, SceneError> {
        JetRun::resume(params, seed, bytes).map_err(|e| match e {
            JetError::Checkpoint(m) => SceneError::Checkpoint(m),
            e => SceneError::Run(e.to_string()),
        })
    }

    fn checkpoint(&self) -> Vec<u8> {
        JetRun::checkpoint(self)
    }

    fn units_done(&self) -> u32 {
        self.slices_done()
    }

    fn records(&self) -> Vec<JetSlice> {
        self.slices.clone()
    }

    fn unit_of(record: &JetSlice) -> u32 {
        record.slice
    }

    fn run_next(&mut self, cancel: &dyn Fn() -> bool) -> Result<Option<JetSlice>, SceneError> {
        self.run_next_slice_observed(cancel, None)
            .map(|s| s.cloned())
            .map_err(|e| SceneError::Run(e.to_string()))
    }

    /// A slice ends at the first step past its end time, so within one slice of the run's
    /// time; its mass loss, the run's so far, lies between 0 and the target's mass.
    fn check_record(
        params: &JetParams,
        record: &JetSlice,
        _lost_before_kg_m: f64,
    ) -> Result<f64, InputError> {
        let end = (params.time_ms + params.slice_ms) * 1e-3;
        let t = record.sample.t_s;
        if !(t.is_finite() && (0.0..=end).contains(&t)) {
            return Err(InputError::new(
                "sample.t_s",
                format!(
                    "must be finite and in [0, {end:e}] s (the run's time and one slice), got {t:e}"
                ),
            ));
        }
        let target = params.target_mass_kg_m();
        let loss = record.sample.mass_loss_kg_m;
        if !(loss.is_finite() && (0.0..=target).contains(&loss)) {
            return Err(InputError::new(
                "sample.mass_loss_kg_m",
                format!(
                    "must be finite, ≥ 0 and at most the target's mass {target:e} kg/m, got {loss:e}"
                ),
            ));
        }
        Ok(loss)
    }

    fn results(
        spec: &str,
        cells: Vec<CellRecords<JetSlice>>,
        raw: Option<Vec<StoredJob<JetSlice>>>,
    ) -> Result<String, SceneError> {
        super::stored::results(spec, cells, raw)
    }
}
