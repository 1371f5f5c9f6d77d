//! A sample (seed section 4): one fresh surface hit by N impacts in order, fully determined by
//! its parameters and seed, with a checkpoint after any impact that resumes bit for bit.

use grit_sph::{Particles, Timers};
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::aggregate::Impact;
use crate::impact::{run_impact, GrainStart, ImpactError, ImpactOutcome, ImpactParams};

/// Bumped whenever the checkpoint layout or the physics behind it changes, so an old
/// checkpoint is refused instead of resumed into different numbers.
pub const CHECKPOINT_VERSION: u32 = 2;

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
    surface: Particles,
    records: Vec<ImpactRecord>,
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
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        rng.set_stream(k as u64);
        let unit = |x: u64| (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
        (unit(rng.next_u64()), unit(rng.next_u64()))
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
        let k = self.impacts_done();
        let err = |error: ImpactError| SampleError::Impact {
            impact: k + 1,
            error,
        };
        let grain = self.next_grain().map_err(|e| err(e.into()))?;
        let run = run_impact(&self.params, &self.surface, &grain, cancel).map_err(err)?;
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

    /// The state after the last finished impact, as bytes (postcard; floats kept bit for bit).
    pub fn checkpoint(&self) -> Vec<u8> {
        let c = Checkpoint {
            version: CHECKPOINT_VERSION,
            params_json: serde_json::to_string(&self.params).expect("params serialise"),
            seed: self.seed,
            surface: self.surface.clone(),
            records: self.records.clone(),
        };
        postcard::to_stdvec(&c).expect("a checkpoint always serialises")
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

    /// Goes on from `checkpoint()` bytes with the parameters and seed stored in them (for
    /// replaying a job's checkpoint by hand; the farm uses `resume`).
    pub fn from_checkpoint(bytes: &[u8]) -> Result<Sample, SampleError> {
        let c: Checkpoint = postcard::from_bytes(bytes)
            .map_err(|e| SampleError::Checkpoint(format!("cannot decode: {e}")))?;
        if c.version != CHECKPOINT_VERSION {
            return Err(SampleError::Checkpoint(format!(
                "version {} but this build reads {CHECKPOINT_VERSION}",
                c.version
            )));
        }
        let saved: ImpactParams = serde_json::from_str(&c.params_json)
            .map_err(|e| SampleError::Checkpoint(format!("cannot decode parameters: {e}")))?;
        saved.validate()?;
        if !c.surface.is_consistent() {
            return Err(SampleError::Checkpoint(
                "surface arrays have different lengths".into(),
            ));
        }
        Ok(Sample {
            params: saved,
            seed: c.seed,
            surface: c.surface,
            records: c.records,
            last_timers: Timers::default(),
            last_particles: 0,
        })
    }
}
