//! A sample (seed section 4): one fresh surface hit by N impacts in order, fully determined by
//! its parameters and seed, with a checkpoint after any impact that resumes bit for bit.

use grit_sph::{InputError, Particles, ParticlesState, Timers};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use std::collections::BTreeMap;

use crate::campaign::{CellRecords, NextStep, StoredCell, StoredJob, UnitMasses};
use crate::impact::aggregate::Impact;
use crate::impact::{
    run_impact_observed, GrainStart, ImpactError, ImpactOutcome, ImpactParams, StepObserver,
};
use crate::scene::{stream_draws, Scene, SceneError};

/// Bumped whenever the checkpoint layout or the physics behind it changes, so an old
/// checkpoint is refused instead of resumed into different numbers.
pub const CHECKPOINT_VERSION: u32 = 8;
/// The last version whose records were postcard in their layout before `damage_added_kg`;
/// still read.
const POSTCARD_RECORDS_VERSION: u32 = 7;
/// The last version whose surface was `Particles`' own serde layout; still read.
const PARTICLES_VERSION: u32 = 6;
/// The version before checkpoints carried their checksum; still read.
const UNCHECKED_VERSION: u32 = 5;
/// Bytes of the SHA-256 checksum after a checkpoint's body.
const SHA256_LEN: usize = 32;

/// One impact of a sample as reported to the farm and printed by `grit sample`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactRecord {
    /// 1-based impact number within the sample.
    pub impact: u32,
    /// Grain mass of this impact (kg/m).
    pub grain_mass_kg: f64,
    /// Surface mass removed by this impact (kg/m).
    pub mass_loss_kg: f64,
    /// Random orientation of the grain (rad).
    pub orientation_rad: f64,
    /// Aim point along the surface (m).
    pub aim_x_m: f64,
    /// Engine outcome: time, steps, rebound, whether the end criterion was met.
    pub outcome: ImpactOutcome,
}

impl ImpactRecord {
    /// The pair aggregation needs (grain mass, mass loss).
    pub fn impact(&self) -> Impact {
        Impact {
            grain_mass_kg: self.grain_mass_kg,
            mass_loss_kg: self.mass_loss_kg,
            damage_added_kg: self.outcome.damage_added_kg,
        }
    }
}

/// Why a sample could not be created, resumed or advanced.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SampleError {
    /// An impact failed (bad input or an unstable simulation).
    #[error("impact {impact}: {error}")]
    Impact {
        /// 1-based impact number.
        impact: u32,
        /// The engine's error (its text is in this error's own message).
        error: ImpactError,
    },
    /// The scene parameters are invalid.
    #[error(transparent)]
    Input(#[from] grit_sph::InputError),
    /// A checkpoint that cannot be resumed here.
    #[error("checkpoint: {0}")]
    Checkpoint(String),
}

/// What a checkpoint holds: enough to go on as if never stopped.
#[derive(Serialize, Deserialize)]
struct Checkpoint {
    version: u32,
    /// JSON, because shapes and materials deserialise by looking at the data, which postcard
    /// (not self-describing) cannot do.
    params_json: String,
    seed: u64,
    surface: ParticlesState,
    /// JSON too: a record gains optional fields (read as absent from older records), and
    /// postcard, which writes fields by position, cannot skip one.
    records_json: String,
}

/// A checkpoint of version 7: the records in postcard.
#[derive(Deserialize)]
struct CheckpointV7 {
    _version: u32,
    params_json: String,
    seed: u64,
    surface: ParticlesState,
    records: Vec<RecordV7>,
}

/// A checkpoint of versions 5 and 6: the surface in `Particles`' own serde layout.
#[derive(Deserialize)]
struct CheckpointV6 {
    _version: u32,
    params_json: String,
    seed: u64,
    #[serde(deserialize_with = "grit_sph::particles::deserialize_filled")]
    surface: Particles,
    records: Vec<RecordV7>,
}

/// An [`ImpactRecord`] as postcard laid it out in checkpoints of versions 5 to 7.
#[derive(Deserialize)]
struct RecordV7 {
    impact: u32,
    grain_mass_kg: f64,
    mass_loss_kg: f64,
    orientation_rad: f64,
    aim_x_m: f64,
    outcome: OutcomeV7,
}

/// An [`ImpactOutcome`] before it recorded the damage added.
#[derive(Deserialize)]
struct OutcomeV7 {
    mass_loss_kg: f64,
    removed_particles: u32,
    detached_kg: f64,
    detached_particles: u32,
    sim_time_s: f64,
    steps: u64,
    rebound_ratio: f64,
    settled: bool,
}

impl From<RecordV7> for ImpactRecord {
    fn from(r: RecordV7) -> ImpactRecord {
        let o = r.outcome;
        ImpactRecord {
            impact: r.impact,
            grain_mass_kg: r.grain_mass_kg,
            mass_loss_kg: r.mass_loss_kg,
            orientation_rad: r.orientation_rad,
            aim_x_m: r.aim_x_m,
            outcome: ImpactOutcome {
                mass_loss_kg: o.mass_loss_kg,
                removed_particles: o.removed_particles,
                detached_kg: o.detached_kg,
                detached_particles: o.detached_particles,
                sim_time_s: o.sim_time_s,
                steps: o.steps,
                rebound_ratio: o.rebound_ratio,
                settled: o.settled,
                damage_added_kg: None,
            },
        }
    }
}

/// Records of a checkpoint before version 8, as today's.
fn records_v7(records: Vec<RecordV7>) -> Vec<ImpactRecord> {
    records.into_iter().map(ImpactRecord::from).collect()
}

/// N impacts on one surface, deterministic in (params, seed).
#[derive(Debug, Clone)]
pub struct Sample {
    params: ImpactParams,
    seed: u64,
    surface: Particles,
    records: Vec<ImpactRecord>,
    last_timers: Timers,
    last_particles: usize,
}

impl Sample {
    /// Particles (surface and grain) at the start of the last impact run by this process.
    pub fn last_particles(&self) -> usize {
        self.last_particles
    }

    /// Per-stage wall time of the last impact run by this process (for benchmarks).
    pub fn last_timers(&self) -> &Timers {
        &self.last_timers
    }

    /// A fresh surface for `params`; impacts will draw their randomness from `seed`.
    pub fn new(params: ImpactParams, seed: u64) -> Result<Sample, SampleError> {
        let surface = params.fresh_surface()?;
        Ok(Sample {
            params,
            seed,
            surface,
            records: Vec::new(),
            last_timers: Timers::default(),
            last_particles: 0,
        })
    }

    /// The scene parameters.
    pub fn params(&self) -> &ImpactParams {
        &self.params
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Impacts done so far.
    pub fn impacts_done(&self) -> u32 {
        self.records.len() as u32
    }

    /// Every impact so far, in order.
    pub fn records(&self) -> &[ImpactRecord] {
        &self.records
    }

    /// The surface particles as they are now.
    pub fn surface(&self) -> &Particles {
        &self.surface
    }

    /// Two uniform numbers in [0, 1) for impact `k` (0-based): a ChaCha stream per impact, so
    /// impact k's grain does not depend on how earlier impacts went or where a run resumed.
    fn draws(&self, k: u32) -> (f64, f64) {
        stream_draws(self.seed, k as u64)
    }

    /// The grain the next impact will fire (its random orientation and aim point).
    pub fn next_grain(&self) -> Result<GrainStart, grit_sph::InputError> {
        let (u_angle, u_aim) = self.draws(self.impacts_done());
        self.params.grain_start(u_angle, u_aim)
    }

    /// Runs the next impact; see `run_next_cancellable`.
    pub fn run_next(&mut self) -> Result<&ImpactRecord, SampleError> {
        self.run_next_cancellable(&|| false)
    }

    /// Runs the next impact, polling `cancel` every step. On any error, cancellation
    /// included, the sample is unchanged, so it can be checkpointed and resumed.
    pub fn run_next_cancellable(
        &mut self,
        cancel: &dyn Fn() -> bool,
    ) -> Result<&ImpactRecord, SampleError> {
        self.run_next_observed(cancel, None)
    }

    /// `run_next_cancellable`, with `observe` called after every step of the impact (to catch
    /// the grain at its peak contact force for a picture, say: `PeakTracker`). The observer
    /// reads only, so the sample goes on bit for bit as without it.
    pub fn run_next_observed(
        &mut self,
        cancel: &dyn Fn() -> bool,
        observe: Option<StepObserver>,
    ) -> Result<&ImpactRecord, SampleError> {
        let k = self.impacts_done();
        let err = |error: ImpactError| SampleError::Impact {
            impact: k + 1,
            error,
        };
        let grain = self.next_grain().map_err(|e| err(e.into()))?;
        let run = run_impact_observed(&self.params, &self.surface, &grain, cancel, observe)
            .map_err(err)?;
        self.last_timers = run.timers;
        self.last_particles = run.particles;
        let outcome = run.outcome;
        self.surface = run.surface;
        self.records.push(ImpactRecord {
            impact: k + 1,
            grain_mass_kg: self.params.grain_mass_kg_m(),
            mass_loss_kg: outcome.mass_loss_kg,
            orientation_rad: grain.orientation_rad,
            aim_x_m: grain.aim_x_m,
            outcome,
        });
        Ok(self.records.last().expect("just pushed"))
    }

    /// The state after the last finished impact, as bytes (postcard; floats kept bit for bit),
    /// followed by the SHA-256 of those bytes, so a file damaged at rest is refused instead of
    /// resumed into different numbers.
    pub fn checkpoint(&self) -> Vec<u8> {
        let c = Checkpoint {
            version: CHECKPOINT_VERSION,
            params_json: serde_json::to_string(&self.params).expect("params serialise"),
            seed: self.seed,
            surface: self.surface.state(),
            records_json: serde_json::to_string(&self.records).expect("records serialise"),
        };
        let mut bytes = postcard::to_stdvec(&c).expect("a checkpoint always serialises");
        let digest = Sha256::digest(&bytes);
        bytes.extend_from_slice(&digest);
        bytes
    }

    /// Goes on from `checkpoint()` bytes. The parameters and seed must be the job's own:
    /// resuming a different job's surface would give silently wrong numbers.
    pub fn resume(params: &ImpactParams, seed: u64, bytes: &[u8]) -> Result<Sample, SampleError> {
        let s = Sample::from_checkpoint(bytes)?;
        if s.params != *params || s.seed != seed {
            return Err(SampleError::Checkpoint(
                "belongs to another job (parameters or seed differ)".into(),
            ));
        }
        Ok(s)
    }

    /// The same surface and seed going on under other scene parameters (for studies of one
    /// constant's effect from a worn surface). The lattice must stay the one the surface was
    /// built on: spacing, box and grain size are refused, naming the field.
    pub fn with_params(mut self, params: ImpactParams) -> Result<Sample, SampleError> {
        params.validate()?;
        let old = &self.params;
        let fixed = [
            ("spacing_m", old.spacing_m, params.spacing_m),
            (
                "surface_width_dg",
                old.surface_width_dg,
                params.surface_width_dg,
            ),
            (
                "surface_depth_dg",
                old.surface_depth_dg,
                params.surface_depth_dg,
            ),
            (
                "grain_diameter_m",
                old.grain_diameter_m,
                params.grain_diameter_m,
            ),
        ];
        if let Some((field, _, _)) = fixed.iter().find(|(_, a, b)| a != b) {
            return Err(grit_sph::InputError::new(
                *field,
                "cannot change on a worn surface: it was built on the checkpoint's lattice",
            )
            .into());
        }
        self.params = params;
        Ok(self)
    }

    /// Goes on from `checkpoint()` bytes with the parameters and seed stored in them (for
    /// replaying a job's checkpoint by hand; the farm uses `resume`).
    pub fn from_checkpoint(bytes: &[u8]) -> Result<Sample, SampleError> {
        let undecodable = |e| {
            SampleError::Checkpoint(match e {
                postcard::Error::DeserializeUnexpectedEnd => {
                    "truncated: the bytes end before the checkpoint does, so it cannot decode"
                        .into()
                }
                e => format!("cannot decode: {e}"),
            })
        };
        let surface_of = |state| {
            Particles::from_state(state)
                .map_err(|e| SampleError::Checkpoint(format!("surface: {e}")))
        };
        // The version comes first in every layout, and says how to read the rest.
        let (version, _) = postcard::take_from_bytes::<u32>(bytes).map_err(undecodable)?;
        let (c, rest) = match version {
            CHECKPOINT_VERSION => {
                let (c, rest): (Checkpoint, &[u8]) =
                    postcard::take_from_bytes(bytes).map_err(undecodable)?;
                let surface = surface_of(c.surface)?;
                let records = serde_json::from_str(&c.records_json).map_err(|e| {
                    SampleError::Checkpoint(format!("cannot decode records: {e}"))
                })?;
                ((c.params_json, c.seed, surface, records), rest)
            }
            POSTCARD_RECORDS_VERSION => {
                let (c, rest): (CheckpointV7, &[u8]) =
                    postcard::take_from_bytes(bytes).map_err(undecodable)?;
                let surface = surface_of(c.surface)?;
                ((c.params_json, c.seed, surface, records_v7(c.records)), rest)
            }
            PARTICLES_VERSION | UNCHECKED_VERSION => {
                let (c, rest): (CheckpointV6, &[u8]) =
                    postcard::take_from_bytes(bytes).map_err(undecodable)?;
                ((c.params_json, c.seed, c.surface, records_v7(c.records)), rest)
            }
            v => {
                return Err(SampleError::Checkpoint(format!(
                    "cannot decode version {v}: this build reads {UNCHECKED_VERSION} to {CHECKPOINT_VERSION}"
                )))
            }
        };
        match version {
            CHECKPOINT_VERSION | POSTCARD_RECORDS_VERSION | PARTICLES_VERSION => {
                let body = &bytes[..bytes.len() - rest.len()];
                if rest.len() != SHA256_LEN {
                    return Err(SampleError::Checkpoint(format!(
                        "truncated: {} of the {SHA256_LEN} bytes of its checksum are there",
                        rest.len().min(SHA256_LEN)
                    )));
                }
                if Sha256::digest(body).as_slice() != rest {
                    return Err(SampleError::Checkpoint(
                        "damaged: its bytes do not match their SHA-256 checksum".into(),
                    ));
                }
            }
            // Written before checkpoints carried a checksum: read as they are.
            _ if rest.is_empty() => {}
            v => {
                return Err(SampleError::Checkpoint(format!(
                    "version {v} holds {} bytes after its end",
                    rest.len()
                )))
            }
        }
        let (params_json, seed, surface, records) = c;
        let saved: ImpactParams = serde_json::from_str(&params_json)
            .map_err(|e| SampleError::Checkpoint(format!("cannot decode parameters: {e}")))?;
        saved.validate()?;
        if !surface.is_consistent() {
            return Err(SampleError::Checkpoint(
                "surface arrays have different lengths".into(),
            ));
        }
        Ok(Sample {
            params: saved,
            seed,
            surface,
            records,
            last_timers: Timers::default(),
            last_particles: 0,
        })
    }
}

impl Scene for Sample {
    const KIND: &'static str = "impact";
    const UNIT: &'static str = "impact";
    const RECORDS: &'static str = "impacts";
    // A cancelled impact leaves the sample as it was after the last one.
    const CHECKPOINT_EACH_UNIT: bool = false;
    type Params = ImpactParams;
    type Record = ImpactRecord;

    fn engine() -> Result<String, SceneError> {
        static FINGERPRINT: std::sync::OnceLock<Result<String, String>> =
            std::sync::OnceLock::new();
        crate::fingerprint::once(&FINGERPRINT, crate::fingerprint::impact_engine)
    }

    fn start(params: &ImpactParams, seed: u64) -> Result<Sample, SceneError> {
        Sample::new(params.clone(), seed).map_err(|e| SceneError::Run(e.to_string()))
    }

    fn resume(params: &ImpactParams, seed: u64, bytes: &[u8]) -> Result<Sample, SceneError> {
        Sample::resume(params, seed, bytes).map_err(SceneError::from)
    }

    fn checkpoint(&self) -> Vec<u8> {
        Sample::checkpoint(self)
    }

    fn units_done(&self) -> u32 {
        self.impacts_done()
    }

    fn records(&self) -> Vec<ImpactRecord> {
        self.records.clone()
    }

    fn unit_of(record: &ImpactRecord) -> u32 {
        record.impact
    }

    fn run_next(&mut self, cancel: &dyn Fn() -> bool) -> Result<Option<ImpactRecord>, SceneError> {
        match self.run_next_cancellable(cancel) {
            Ok(r) => Ok(Some(r.clone())),
            Err(SampleError::Impact {
                error: ImpactError::Cancelled,
                ..
            }) => Ok(None),
            Err(e) => Err(SceneError::Run(e.to_string())),
        }
    }

    /// The loss is stated once (the record's and its outcome's agree to the bit), the grain
    /// mass is the cell's to the bit (the worker computes it from these very parameters), the
    /// loss is finite and ≥ 0, and the sample's total stays within the surface's mass.
    fn check_record(
        params: &ImpactParams,
        record: &ImpactRecord,
        lost_before_kg_m: f64,
    ) -> Result<f64, InputError> {
        // The record says the loss twice; both come from one number in a worker.
        if record.mass_loss_kg.to_bits() != record.outcome.mass_loss_kg.to_bits() {
            return Err(InputError::new(
                "mass_loss_kg",
                format!(
                    "must equal outcome.mass_loss_kg ({:e}), got {:e}",
                    record.outcome.mass_loss_kg, record.mass_loss_kg
                ),
            ));
        }
        let grain = params.grain_mass_kg_m();
        if record.grain_mass_kg.to_bits() != grain.to_bits() {
            return Err(InputError::new(
                "grain_mass_kg",
                format!(
                    "must be the cell's grain mass {grain:e} kg/m, got {:e}",
                    record.grain_mass_kg
                ),
            ));
        }
        if !(record.mass_loss_kg.is_finite() && record.mass_loss_kg >= 0.0) {
            return Err(InputError::new(
                "mass_loss_kg",
                format!("must be finite and ≥ 0, got {:e}", record.mass_loss_kg),
            ));
        }
        let after = lost_before_kg_m + record.mass_loss_kg;
        let surface = params.surface_mass_kg_m();
        if after > surface {
            return Err(InputError::new(
                "mass_loss_kg",
                format!(
                    "brings the sample's loss to {after:e} kg/m, more than the surface's mass {surface:e} kg/m"
                ),
            ));
        }
        Ok(after)
    }

    fn results(
        spec: &str,
        cells: Vec<CellRecords<ImpactRecord>>,
        raw: Option<Vec<StoredJob<ImpactRecord>>>,
    ) -> Result<String, SceneError> {
        super::stored::results(spec, cells, raw)
    }

    fn masses(record: &ImpactRecord) -> Option<UnitMasses> {
        Some(super::stored::masses(record))
    }

    fn next_step(
        cell: &StoredCell,
        samples: &BTreeMap<u32, Vec<UnitMasses>>,
    ) -> Result<NextStep, SceneError> {
        super::stored::grow(cell, samples)
    }
}

impl From<SampleError> for SceneError {
    fn from(e: SampleError) -> SceneError {
        match e {
            SampleError::Checkpoint(m) => SceneError::Checkpoint(m),
            e => SceneError::Run(e.to_string()),
        }
    }
}

#[cfg(test)]
mod tests {
    //! Watching a sample's impacts (for snapshots) leaves its results bit for bit unchanged.

    use super::*;
    use crate::impact::PeakTracker;

    /// A coarse scene (10 particles per Dg, 2 × 1.25 Dg surface) that runs in seconds.
    fn coarse() -> ImpactParams {
        ImpactParams {
            spacing_m: 25e-6,
            surface_width_dg: 2.0,
            surface_depth_dg: 1.25,
            distribution_range_dg: 0.0,
            ..ImpactParams::default()
        }
    }

    #[test]
    fn observing_impacts_changes_no_bit() {
        let mut plain = Sample::new(coarse(), 7).unwrap();
        let mut watched = Sample::new(coarse(), 7).unwrap();
        for k in 1..=2 {
            plain.run_next().unwrap();
            let grain = watched.next_grain().unwrap();
            let mut tracker = PeakTracker::new(&grain);
            let mut steps = 0u64;
            watched
                .run_next_observed(
                    &|| false,
                    Some(&mut |w| {
                        steps += 1;
                        tracker.observe(w)
                    }),
                )
                .unwrap();
            let rec = &watched.records()[k - 1];
            assert_eq!(steps, rec.outcome.steps, "observer runs once a step");
            let peak = tracker.into_peak().expect("the grain touched the surface");
            assert!(peak.force_n_m > 0.0 && peak.time_s > 0.0);
            assert!(peak.time_s <= rec.outcome.sim_time_s);
            assert_eq!(peak.outline_m.len(), 6, "hexagon");
            // At peak force a normal impact has pushed the grain into the surface.
            assert!(peak.depth_m > 0.0, "depth {:e}", peak.depth_m);
            let centre = peak.outline_m.iter().sum::<grit_sph::Vector>() / 6.0;
            assert!(centre.x.abs() < 0.1 * plain.params().grain_diameter_m);
        }
        assert_eq!(plain.records(), watched.records());
        assert_eq!(
            plain.checkpoint(),
            watched.checkpoint(),
            "surface state differs"
        );
    }

    #[test]
    fn records_from_before_the_damage_field_read_and_write_back_unchanged() {
        let old = r#"{"impact":1,"grain_mass_kg":0.0001227184630308513,"mass_loss_kg":0.0,"orientation_rad":3.790436142777147,"aim_x_m":0.000045968645586082495,"outcome":{"mass_loss_kg":0.0,"removed_particles":0,"detached_kg":0.0,"detached_particles":0,"sim_time_s":8.707224782726366e-7,"steps":395,"rebound_ratio":0.6120364083264578,"settled":true}}"#;
        let r: ImpactRecord = serde_json::from_str(old).unwrap();
        assert_eq!(r.outcome.damage_added_kg, None);
        assert_eq!(serde_json::to_string(&r).unwrap(), old);
        let mut s = Sample::new(coarse(), 7).unwrap();
        let added = s.run_next().unwrap().outcome.damage_added_kg;
        assert!(added.is_some_and(|d| d > 0.0), "{added:?}");
    }
}
