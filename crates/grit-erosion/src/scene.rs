//! What the farm needs of a scene (`docs/design.md`, "Scenes"): a simulation that a job runs
//! unit by unit (an impact of a sample, a slice of a jet run), reporting a record per unit,
//! checkpointed between units and resumed bit for bit. The farm is written once against the
//! [`Scene`] trait; each scene (`crate::scenes`) implements it.

use grit_sph::InputError;

use std::collections::BTreeMap;

use crate::campaign::{CellRecords, NextStep, StoredCell, StoredJob, UnitMasses};
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};
use serde::de::DeserializeOwned;
use serde::Serialize;

/// One job's simulation, run one unit at a time (seed paper section 4: a sample's impacts;
/// the AWJ paper: a jet's time slices).
pub trait Scene: Sized + Send + Sync + 'static {
    /// The name a campaign of this scene is stored under (`impact`, `jet`).
    const KIND: &'static str;
    /// The unit, in words, for logs and errors (`impact`, `slice`).
    const UNIT: &'static str;
    /// The key a raw results listing gives a job's records under (`impacts`, `slices`).
    const RECORDS: &'static str = "units";
    /// Whether a cancelled unit leaves the state mid-unit. Such a scene is checkpointed after
    /// every unit and hands back the last of those when it stops; otherwise the state after
    /// the last finished unit is always at hand and checkpoints are taken every few units.
    const CHECKPOINT_EACH_UNIT: bool;
    /// What defines one job's simulation; stored with its cell and sent with every lease.
    type Params: Clone + PartialEq + Serialize + DeserializeOwned + Send + Sync + 'static;
    /// What one unit reports.
    type Record: Clone + Serialize + DeserializeOwned + Send + Sync + 'static;

    /// The engine fingerprint of this scene (`crate::fingerprint`): 16 hex digits of a hash
    /// of a canonical run's final bits, equal for engines that compute the same bits. A farm
    /// leases a campaign's jobs only to workers whose fingerprint matches the campaign's.
    fn engine() -> Result<String, SceneError>;
    /// A fresh simulation of `params` seeded `seed`.
    fn start(params: &Self::Params, seed: u64) -> Result<Self, SceneError>;
    /// Goes on from [`Scene::checkpoint`] bytes, which must be this job's own (its
    /// parameters and seed): another job's state would give silently wrong numbers.
    fn resume(params: &Self::Params, seed: u64, bytes: &[u8]) -> Result<Self, SceneError>;
    /// The state after the last finished unit, as bytes.
    fn checkpoint(&self) -> Vec<u8>;
    /// Units finished.
    fn units_done(&self) -> u32;
    /// The records of the units finished so far, in order (those before a resume included).
    fn records(&self) -> Vec<Self::Record>;
    /// The number (1-based) of the unit a record reports.
    fn unit_of(record: &Self::Record) -> u32;
    /// Runs the next unit; `Ok(None)` when `cancel` returned true before it ended, the state
    /// then being as [`Scene::CHECKPOINT_EACH_UNIT`] says.
    fn run_next(&mut self, cancel: &dyn Fn() -> bool) -> Result<Option<Self::Record>, SceneError>;
    /// Checks a record a worker reports against its job's parameters and the job's mass loss
    /// before it (kg/m, as this method returned for the record before; 0 for the first): the
    /// scene's own rules on masses and times, the error naming the record's field. Returns the
    /// job's mass loss after the record.
    fn check_record(
        params: &Self::Params,
        record: &Self::Record,
        lost_before_kg_m: f64,
    ) -> Result<f64, InputError>;

    /// The results endpoint's JSON of a campaign from its stored spec (`spec`, JSON) and its
    /// cells as they stand now with their records; `raw`, when asked for, lists every job's
    /// records ([`crate::campaign::results_json`] writes the body).
    fn results(
        spec: &str,
        cells: Vec<CellRecords<Self::Record>>,
        raw: Option<Vec<StoredJob<Self::Record>>>,
    ) -> Result<String, SceneError>;

    /// What a cell's growth ([`Scene::next_step`]) reads of a record, which a farm stores
    /// beside it so that judging a cell need not parse every record; `None` for a scene whose
    /// cells do not grow.
    fn masses(_record: &Self::Record) -> Option<UnitMasses> {
        None
    }

    /// What a farm does with `cell` once every sample has its planned units, from its growth
    /// rules and its samples' units ([`Scene::masses`], in unit order, by sample)
    /// (`docs/erosion.md`, "Extending a cell"). A scene without such rules leaves every cell
    /// as planned.
    fn next_step(
        _cell: &StoredCell,
        _samples: &BTreeMap<u32, Vec<UnitMasses>>,
    ) -> Result<NextStep, SceneError> {
        Ok(NextStep::Final)
    }
}

/// Something done with a scene picked at run time by its [`Scene::KIND`], as the farm does
/// with a stored job: the farm's code is generic over [`Scene`] and never names a scene.
pub trait SceneVisitor {
    /// What the visit gives.
    type Output;
    /// Does it with scene `S`.
    fn visit<S: Scene>(self) -> Self::Output;
}

/// The engine fingerprint of every scene of `Z`, by kind ([`Scene::engine`]).
pub fn engines<Z: SceneSet>() -> Result<std::collections::BTreeMap<String, String>, SceneError> {
    struct Engine;
    impl SceneVisitor for Engine {
        type Output = Result<String, SceneError>;
        fn visit<S: Scene>(self) -> Self::Output {
            S::engine()
        }
    }
    Z::kinds()
        .iter()
        .map(|&k| {
            let fp = Z::visit(k, Engine).expect("a kind the set lists is one it visits")?;
            Ok((k.to_string(), fp))
        })
        .collect()
}

/// Which scenes a farm runs, by kind: grit's own ([`Scenes`]), or those and more.
pub trait SceneSet: Send + Sync + 'static {
    /// The kinds the set holds.
    fn kinds() -> &'static [&'static str];
    /// Runs `v` with the scene stored as `kind`; `None` for a kind the set does not hold.
    fn visit<V: SceneVisitor>(kind: &str, v: V) -> Option<V::Output>;
}

/// grit's scenes: single-grain impacts (`impact`) and the abrasive water jet (`jet`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Scenes;

impl SceneSet for Scenes {
    fn kinds() -> &'static [&'static str] {
        use crate::{jet::JetRun, Sample};
        &[Sample::KIND, JetRun::KIND]
    }

    fn visit<V: SceneVisitor>(kind: &str, v: V) -> Option<V::Output> {
        use crate::{jet::JetRun, Sample};
        if kind == Sample::KIND {
            Some(v.visit::<Sample>())
        } else if kind == JetRun::KIND {
            Some(v.visit::<JetRun>())
        } else {
            None
        }
    }
}

/// Why a scene could not start, resume or run a unit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// Checkpoint bytes that cannot be resumed: damaged, cut short, another job's.
    #[error("checkpoint: {0}")]
    Checkpoint(String),
    /// The simulation failed (bad parameters, an unstable step).
    #[error("{0}")]
    Run(String),
}

/// A scene (`ImpactParams`, `JetParams`: `kind`) read from a JSON object, fields left out at
/// their defaults, the error naming the field at fault. Not validated: flags may still
/// override fields. Serde would read a JSON array as the struct's fields in order, so only an
/// object is a scene.
pub fn scene_from_json<T: serde::de::DeserializeOwned>(
    text: &str,
    kind: &str,
) -> Result<T, InputError> {
    if !text.trim_start().starts_with('{') {
        return Err(InputError::new(
            "(scene)",
            format!("must be a JSON object of {kind} fields"),
        ));
    }
    let de = &mut serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(de)
        .map_err(|e| InputError::new(e.path().to_string(), e.inner().to_string()))
}

/// Two uniform numbers in [0, 1) from ChaCha8 stream `k` of `seed`: draw k of a run does not
/// depend on the draws before it, so a resumed run draws what an unbroken one would.
pub(crate) fn stream_draws(seed: u64, k: u64) -> (f64, f64) {
    let mut units = stream_units(seed, k);
    let u = units.next().expect("the stream is endless");
    (u, units.next().expect("the stream is endless"))
}

/// The uniform draws in [0, 1) of ChaCha8 stream `k` of `seed`, in order, without end (53 bits
/// each); the first two are [`stream_draws`].
pub(crate) fn stream_units(seed: u64, k: u64) -> impl Iterator<Item = f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(k);
    std::iter::repeat_with(move || (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64))
}
