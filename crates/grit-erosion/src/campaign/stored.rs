//! A campaign as a farm has stored it, handed back to its scene: the cells as they stand now
//! (grown cells included), each with its samples' records, and the body of the results
//! endpoint the scene writes from them ([`crate::Scene::results`]).

use std::collections::BTreeMap;

use serde::ser::{SerializeStruct, Serializer};
use serde::Serialize;

use super::{TargetSem, UntilSteady};
use crate::{Scene, SceneError};

/// One cell as a farm stores it now: where it sits in the sweeps, its jobs' parameters and
/// its current plan.
#[derive(Debug, Clone, PartialEq)]
pub struct StoredCell {
    /// Index in the spec's expansion order.
    pub index: u32,
    /// An impact cell's angle (degrees); `None` for a scene without one.
    pub angle_deg: Option<f64>,
    /// An impact cell's grain shape; `None` for a scene without one.
    pub shape: Option<String>,
    /// Values of the other swept dimensions, by name with unit.
    pub swept: BTreeMap<String, f64>,
    /// The scene's parameters of every job of the cell, as JSON.
    pub params: String,
    /// Units (impacts, slices) every sample is planned for now.
    pub units: u32,
    /// Samples the cell has now.
    pub samples: u32,
    /// The rule growing the units until the cell is steady, if any.
    pub until_steady: Option<UntilSteady>,
    /// The rule adding samples until the error bar is small, if any.
    pub target_sem: Option<TargetSem>,
}

/// A stored cell with the records its samples reported: sample index to records in unit
/// order, samples without a record left out.
#[derive(Debug, Clone, PartialEq)]
pub struct CellRecords<R> {
    /// The cell.
    pub cell: StoredCell,
    /// The records by sample.
    pub samples: BTreeMap<u32, Vec<R>>,
}

/// What a cell's growth reads of one unit: the abrasive mass it brought and the target mass
/// it removed (kg/m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitMasses {
    /// Mass of the abrasive the unit brought (kg/m).
    pub grain_kg_m: f64,
    /// Target mass the unit removed (kg/m).
    pub loss_kg_m: f64,
    /// Damage the unit added to the target, Σ m ΔD (kg/m; seed paper eq. 19), which the
    /// impact scene's damage balance compares with the loss; `None` where not recorded.
    pub damage_kg_m: Option<f64>,
}

/// One job with the records it stored, as a raw results listing shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct StoredJob<R> {
    /// Cell index.
    pub cell: u32,
    /// Sample index within the cell.
    pub sample: u32,
    /// The job's seed.
    pub seed: u64,
    /// The job's state (`queued`, `leased`, `done`, ...).
    pub state: String,
    /// Every record stored, in unit order.
    pub records: Vec<R>,
}

/// The error of a stored part (`what`: the spec, a cell's scene, the aggregation) that does
/// not read back.
pub(crate) fn stored_error(what: &str, e: impl std::fmt::Display) -> SceneError {
    SceneError::Run(format!("{what}: {e}"))
}

/// A job of scene `S` written with its records under [`Scene::RECORDS`].
struct RawJob<'a, S: Scene>(&'a StoredJob<S::Record>);

impl<S: Scene> Serialize for RawJob<'_, S> {
    fn serialize<Z: Serializer>(&self, s: Z) -> Result<Z::Ok, Z::Error> {
        let j = self.0;
        let mut st = s.serialize_struct("RawJob", 5)?;
        st.serialize_field("cell", &j.cell)?;
        st.serialize_field("sample", &j.sample)?;
        st.serialize_field("seed", &j.seed)?;
        st.serialize_field("state", &j.state)?;
        st.serialize_field(S::RECORDS, &j.records)?;
        st.end()
    }
}

/// The results endpoint's JSON: scene `S`'s aggregate `results` (a JSON object) and, when
/// asked, every job's records under `"raw"`.
pub fn results_json<S: Scene, T: Serialize>(
    results: &T,
    raw: Option<&[StoredJob<S::Record>]>,
) -> Result<String, SceneError> {
    #[derive(Serialize)]
    struct Body<'a, T, J> {
        #[serde(flatten)]
        results: &'a T,
        #[serde(skip_serializing_if = "Option::is_none")]
        raw: Option<J>,
    }
    let raw: Option<Vec<RawJob<S>>> = raw.map(|jobs| jobs.iter().map(RawJob).collect());
    serde_json::to_string(&Body { results, raw })
        .map_err(|e| SceneError::Run(format!("results: {e}")))
}
