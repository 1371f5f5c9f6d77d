//! The farm's view of the scenes it runs: what the coordinator does with a job's reported
//! units and uploaded checkpoints, a campaign's stored records and a finished cell, for a
//! scene it knows only by its stored kind. Built once
//! from a [`SceneSet`] (grit's own [`grit_erosion::Scenes`] by default), so a new scene
//! reaches the farm without a change to it.

use std::collections::BTreeMap;
use std::marker::PhantomData;
use std::sync::Arc;

use grit_erosion::campaign::{CellRecords, NextStep, StoredCell, StoredJob, UnitMasses};
use grit_erosion::{Scene, SceneSet, SceneVisitor};
use serde_json::Value;

use crate::api::Checkpoint;
use crate::checkpoint::{verify_upload, CheckpointBytes, CheckpointError};
use crate::db::{self, Reported};
use crate::error::{Error, Result};

/// What the coordinator does with one scene's jobs, its type erased.
pub trait FarmScene: Send + Sync {
    /// Reported `units` (JSON values) as the scene's records; a unit that is not one is a 422
    /// naming `units[i]…`.
    fn decode(&self, units: Vec<Value>) -> Result<Reported>;
    /// [`verify_upload`] of checkpoint `c` as the stored `job`'s, against its parameters and
    /// seed: the checked bytes for the store.
    fn verify_upload(
        &self,
        c: &Checkpoint,
        job: &db::StoredJob,
    ) -> std::result::Result<CheckpointBytes, CheckpointError>;
    /// [`Scene::results`] of a campaign whose spec is `spec`, its records as stored (JSON).
    fn results(
        &self,
        spec: &str,
        cells: Vec<CellRecords<String>>,
        raw: Option<Vec<StoredJob<String>>>,
    ) -> Result<String>;
    /// [`Scene::masses`] of a record as stored (JSON).
    fn masses(&self, record: &str) -> Result<Option<UnitMasses>>;
    /// [`Scene::next_step`] of a cell whose samples have their planned units.
    fn next_step(
        &self,
        cell: &StoredCell,
        samples: &BTreeMap<u32, Vec<UnitMasses>>,
    ) -> Result<NextStep>;
}

/// A stored record (JSON) as scene `S`'s.
fn record<S: Scene>(text: &str) -> Result<S::Record> {
    serde_json::from_str(text).map_err(|e| Error::Internal(format!("stored unit record: {e}")))
}

/// Stored records (JSON) as scene `S`'s, in their order.
fn records<S: Scene>(texts: &[String]) -> Result<Vec<S::Record>> {
    texts.iter().map(|t| record::<S>(t)).collect()
}

/// A stored cell's records (JSON) as scene `S`'s.
fn cell_records<S: Scene>(c: CellRecords<String>) -> Result<CellRecords<S::Record>> {
    let samples = c
        .samples
        .into_iter()
        .map(|(sample, texts)| Ok((sample, records::<S>(&texts)?)))
        .collect::<Result<_>>()?;
    Ok(CellRecords {
        cell: c.cell,
        samples,
    })
}

fn scene_error(e: grit_erosion::SceneError) -> Error {
    Error::Internal(e.to_string())
}

/// [`FarmScene`] of scene `S`.
struct Ops<S>(PhantomData<fn() -> S>);

impl<S: Scene> FarmScene for Ops<S> {
    fn decode(&self, units: Vec<Value>) -> Result<Reported> {
        let records: Vec<S::Record> = units
            .into_iter()
            .enumerate()
            .map(|(i, v)| {
                serde_path_to_error::deserialize(v).map_err(|e| {
                    let path = e.path().to_string();
                    let at = if path == "." {
                        format!("units[{i}]")
                    } else {
                        format!("units[{i}].{path}")
                    };
                    Error::invalid(at, e.into_inner().to_string())
                })
            })
            .collect::<Result<_>>()?;
        Reported::of::<S>(&records)
    }

    fn verify_upload(
        &self,
        c: &Checkpoint,
        job: &db::StoredJob,
    ) -> std::result::Result<CheckpointBytes, CheckpointError> {
        let params: S::Params = serde_json::from_str(&job.params).map_err(|e| CheckpointError {
            field: "checkpoint",
            rule: format!("the job's stored parameters do not read: {e}"),
        })?;
        verify_upload::<S>(c, job.id, &params, job.seed).map(|(_, bytes)| bytes)
    }

    fn results(
        &self,
        spec: &str,
        cells: Vec<CellRecords<String>>,
        raw: Option<Vec<StoredJob<String>>>,
    ) -> Result<String> {
        let cells = cells
            .into_iter()
            .map(cell_records::<S>)
            .collect::<Result<_>>()?;
        let raw = raw
            .map(|jobs| {
                jobs.into_iter()
                    .map(|j| {
                        Ok(StoredJob {
                            records: records::<S>(&j.records)?,
                            cell: j.cell,
                            sample: j.sample,
                            seed: j.seed,
                            state: j.state,
                        })
                    })
                    .collect::<Result<_>>()
            })
            .transpose()?;
        S::results(spec, cells, raw).map_err(scene_error)
    }

    fn masses(&self, text: &str) -> Result<Option<UnitMasses>> {
        Ok(S::masses(&record::<S>(text)?))
    }

    fn next_step(
        &self,
        cell: &StoredCell,
        samples: &BTreeMap<u32, Vec<UnitMasses>>,
    ) -> Result<NextStep> {
        S::next_step(cell, samples).map_err(scene_error)
    }
}

/// The scenes a coordinator runs, by kind.
#[derive(Clone)]
pub struct SceneRegistry(Arc<BTreeMap<&'static str, Arc<dyn FarmScene>>>);

/// Makes the [`FarmScene`] of the visited scene.
struct MakeOps;

impl SceneVisitor for MakeOps {
    type Output = (&'static str, Arc<dyn FarmScene>);
    fn visit<S: Scene>(self) -> Self::Output {
        (S::KIND, Arc::new(Ops::<S>(PhantomData)))
    }
}

impl SceneRegistry {
    /// Every scene of set `Z`.
    pub fn of<Z: SceneSet>() -> SceneRegistry {
        SceneRegistry(Arc::new(
            Z::kinds()
                .iter()
                .filter_map(|kind| Z::visit(kind, MakeOps))
                .collect(),
        ))
    }

    /// The scene stored as `kind`; an internal error for one this coordinator does not run
    /// (a database written by a build with more scenes).
    pub fn get(&self, kind: &str) -> Result<Arc<dyn FarmScene>> {
        self.0.get(kind).cloned().ok_or_else(|| {
            Error::Internal(format!(
                "stored scene {kind:?} is not one this coordinator runs"
            ))
        })
    }
}

impl Default for SceneRegistry {
    fn default() -> Self {
        SceneRegistry::of::<grit_erosion::Scenes>()
    }
}
