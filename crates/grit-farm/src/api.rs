//! JSON bodies of the REST API under `/api/v1`, shared by the coordinator and its clients.
//! Names marked "scripts rely on" are a stable interface: they are never renamed.

use std::collections::BTreeMap;

use grit_erosion::campaign::Scene;
use grit_erosion::{CampaignResults, ImpactRecord};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;
use uuid::Uuid;

mod jet;
pub use jet::*;

/// Whether `scene` is the impact scene, which the API leaves unsaid so impact answers stay as
/// they were before jets.
fn is_impact(scene: &Scene) -> bool {
    *scene == Scene::Impact
}

/// Answer to `POST /campaigns`.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct CampaignCreated {
    /// The campaign id.
    pub id: Uuid,
    /// Jobs the campaign expanded into.
    pub jobs: u64,
    /// Impacts planned in all.
    pub impacts_total: u64,
    /// False when an `Idempotency-Key` matched an earlier submit and nothing new was created.
    pub created: bool,
}

/// Campaign state (scripts rely on these names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum CampaignState {
    /// No job has started.
    Queued,
    /// Some job has started and some remain.
    Running,
    /// Every job is done.
    Done,
    /// Nothing remains to run and at least one job failed for good.
    Failed,
    /// Cancelled by a user.
    Cancelled,
}

impl CampaignState {
    /// Whether no more work will happen without a user's action.
    pub fn is_final(self) -> bool {
        !matches!(self, CampaignState::Queued | CampaignState::Running)
    }
}

/// One row of `GET /campaigns`.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct CampaignSummary {
    /// The campaign id.
    pub id: Uuid,
    /// Its name, if given.
    pub name: Option<String>,
    /// Its state.
    pub state: CampaignState,
    /// Impacts reported so far (slices, for a jet campaign).
    pub impacts_done: u64,
    /// Impacts planned (slices, for a jet campaign).
    pub impacts_total: u64,
    /// Submit time, Unix milliseconds.
    pub created_ms: i64,
    /// The scene it runs, `jet` or `impact` (left out for impact).
    #[serde(default, skip_serializing_if = "is_impact")]
    #[schema(value_type = Option<String>)]
    pub scene: Scene,
}

/// Jobs per state.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct JobCounts {
    /// Waiting for a worker.
    pub queued: u64,
    /// Held by a worker.
    pub leased: u64,
    /// Finished.
    pub done: u64,
    /// Failed after the maximum number of attempts.
    pub failed: u64,
    /// Cancelled before finishing.
    pub cancelled: u64,
}

/// Progress of one cell.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct CellProgress {
    /// Cell index.
    pub cell: u32,
    /// Impact angle of an impact cell, degrees; absent for a scene without one (the jet).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_deg: Option<f64>,
    /// Grain shape of an impact cell; absent for a scene without one (the jet).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<String>,
    /// Other swept values of the cell.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub swept: BTreeMap<String, f64>,
    /// Samples finished.
    pub samples_done: u64,
    /// Samples planned.
    pub samples_total: u64,
    /// Impacts reported.
    pub impacts_done: u64,
    /// Impacts planned.
    pub impacts_total: u64,
}

/// The most recent error of a failed job.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct JobError {
    /// Job id.
    pub job_id: i64,
    /// Cell index.
    pub cell: u32,
    /// Sample index.
    pub sample: u32,
    /// Attempts lost (expired or failed leases).
    pub attempts: u32,
    /// The error message the worker reported.
    pub error: String,
}

/// `GET /campaigns/{id}`: progress of one campaign (scripts rely on `id`, `state`,
/// `impacts_done`, `impacts_total`).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct CampaignStatus {
    /// The campaign id.
    pub id: Uuid,
    /// Its name, if given.
    pub name: Option<String>,
    /// Its state.
    pub state: CampaignState,
    /// Impacts reported so far.
    pub impacts_done: u64,
    /// Impacts planned.
    pub impacts_total: u64,
    /// Jobs per state.
    pub jobs: JobCounts,
    /// Impacts per second over the last 2 minutes, or over the last 20 impacts when fewer came
    /// in 2 minutes (at most 30 minutes back); `null` with fewer than two impacts in that time.
    pub rate_impacts_per_s: Option<f64>,
    /// Seconds to finish at that rate; `null` when unknown.
    pub eta_s: Option<f64>,
    /// Running jobs that are computing stored units again (resumed from an older checkpoint,
    /// or from the start without one) before they can add new ones; left out when none is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replaying: Option<Replaying>,
    /// Per-cell progress, in cell order.
    pub cells: Vec<CellProgress>,
    /// The last error of any failed job.
    pub last_error: Option<JobError>,
    /// Submit time, Unix milliseconds.
    pub created_ms: i64,
    /// The scene it runs, `jet` or `impact` (left out for impact). A jet campaign counts
    /// slices where an impact campaign counts impacts: in `impacts_done`, `impacts_total`,
    /// `rate_impacts_per_s` and the cells' `impacts_*`.
    #[serde(default, skip_serializing_if = "is_impact")]
    #[schema(value_type = Option<String>)]
    pub scene: Scene,
    /// The engine fingerprint the campaign is pinned to; `null` for a campaign created before
    /// pins, which any engine may run.
    #[serde(default)]
    pub engine: Option<String>,
    /// Whether a worker with the pinned engine claimed or reported within the last lease
    /// period; `null` for an unpinned campaign. `false` with jobs queued means they wait for
    /// an engine no running worker has.
    #[serde(default)]
    pub engine_seen: Option<bool>,
}

/// Replay of a campaign's running jobs: units already stored that their workers compute
/// again, bit for bit, to rebuild a state no checkpoint kept. The campaign's count and rate
/// stand still meanwhile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
pub struct Replaying {
    /// Running jobs still behind their stored units.
    pub jobs: u64,
    /// Stored units those jobs have yet to compute again.
    pub units_left: u64,
}

/// Job state (the `state` column of the jobs table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum JobState {
    /// Waiting for a worker.
    Queued,
    /// Held by a worker.
    Leased,
    /// Finished.
    Done,
    /// Failed after the maximum number of attempts.
    Failed,
    /// Cancelled with its campaign.
    Cancelled,
}

impl JobState {
    /// Every state, in the order a job passes through them.
    pub const ALL: [JobState; 5] = [
        JobState::Queued,
        JobState::Leased,
        JobState::Done,
        JobState::Failed,
        JobState::Cancelled,
    ];

    /// The name used in JSON, SQL and query strings.
    pub fn as_str(self) -> &'static str {
        match self {
            JobState::Queued => "queued",
            JobState::Leased => "leased",
            JobState::Done => "done",
            JobState::Failed => "failed",
            JobState::Cancelled => "cancelled",
        }
    }

    /// The state named `s`, if any.
    pub fn parse(s: &str) -> Option<JobState> {
        JobState::ALL.into_iter().find(|j| j.as_str() == s)
    }
}

/// One row of `GET /campaigns/{id}/jobs`.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct JobInfo {
    /// Job id.
    pub job_id: i64,
    /// Cell index.
    pub cell: u32,
    /// Sample index within the cell.
    pub sample: u32,
    /// Job state.
    pub state: JobState,
    /// Attempts lost (expired or failed leases).
    pub attempts: u32,
    /// Impacts stored.
    pub impacts_done: u32,
    /// Impacts planned.
    pub impacts_planned: u32,
    /// The worker holding it (leased), or the one that finished it (done).
    pub worker: Option<String>,
    /// Lease expiry while leased, Unix milliseconds.
    pub lease_expires_ms: Option<i64>,
    /// Last change of state, claim or heartbeat, Unix milliseconds.
    pub updated_ms: i64,
    /// The last error a worker reported for it, or why its lease was lost.
    pub last_error: Option<String>,
}

/// A job a worker holds, as `GET /workers` shows it.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct HeldJob {
    /// Job id.
    pub job_id: i64,
    /// Campaign id.
    pub campaign_id: Uuid,
    /// The campaign's name, if given.
    pub campaign_name: Option<String>,
    /// Cell index.
    pub cell: u32,
    /// Impact angle of an impact cell, degrees; absent for a scene without one (the jet).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_deg: Option<f64>,
    /// Grain shape of an impact cell; absent for a scene without one (the jet).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<String>,
    /// Sample index within the cell.
    pub sample: u32,
    /// Impacts stored.
    pub impacts_done: u32,
    /// Impacts planned.
    pub impacts_planned: u32,
    /// The lease's last claim or heartbeat, Unix milliseconds.
    pub last_heartbeat_ms: i64,
    /// Lease expiry, Unix milliseconds.
    pub lease_expires_ms: i64,
}

/// A worker seen recently.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct WorkerInfo {
    /// The name it claims with (`grit work --name`, by default `host:pid`).
    pub name: String,
    /// First claim, Unix milliseconds.
    pub first_seen_ms: i64,
    /// Last claim or heartbeat, Unix milliseconds.
    pub last_seen_ms: i64,
    /// Jobs it holds now (one for `grit work`; more only if two workers share a name).
    pub jobs: Vec<HeldJob>,
}

/// `GET /workers`: workers heard from within the window, most recently seen first.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct WorkersResponse {
    /// The coordinator's lease length, seconds: a worker silent for longer has lost its job.
    pub lease_ttl_s: f64,
    /// The window asked for, seconds.
    pub seen_within_s: f64,
    /// The workers, most recently seen first.
    pub workers: Vec<WorkerInfo>,
}

/// The per-impact series of one sample (`?raw=true`).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct RawSample {
    /// Cell index.
    pub cell: u32,
    /// Sample index within the cell.
    pub sample: u32,
    /// The sample's seed.
    pub seed: u64,
    /// Job state.
    pub state: String,
    /// Every impact reported, in order.
    #[schema(value_type = Vec<Object>)]
    pub impacts: Vec<ImpactRecord>,
}

/// `GET /campaigns/{id}/results`: the science crate's aggregate (scripts rely on `partial`
/// and `cells[].{angle_deg, shape, samples, erosion_mean, erosion_std}`), plus the raw series
/// when asked.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct ResultsResponse {
    /// Aggregated results.
    #[serde(flatten)]
    #[schema(value_type = Object)]
    pub results: CampaignResults,
    /// Per-impact series of every sample, with `?raw=true`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub raw: Option<Vec<RawSample>>,
}

/// Answer to cancel and retry-failed: how many jobs changed state.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct JobsChanged {
    /// Jobs whose state changed.
    pub jobs: u64,
}

/// A cell whose `until_steady.max` `POST /campaigns/{id}/raise-caps` (or `grit run` with the
/// raised spec) raised (`docs/erosion.md`, "Raising the cap").
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
pub struct RaisedCell {
    /// The cell's index.
    pub cell: u32,
    /// Its cap so far (impacts per sample).
    pub from: u32,
    /// Its new cap.
    pub to: u32,
    /// Impacts per sample the cell was planned for anew, when it had stopped at its old cap
    /// short of its rule; `null` for a cell still running or one that had met its rule.
    pub reopened_to: Option<u32>,
    /// Of its samples, how many run on from their state at the old cap; the others run their
    /// impacts again from their last checkpoint or the start (the same bits, at their cost).
    pub resumed: u32,
    /// Its samples.
    pub samples: u32,
}

impl RaisedCell {
    /// One line for a person.
    pub fn describe(&self) -> String {
        let head = format!(
            "cell {}: until_steady.max raised from {} to {}",
            self.cell, self.from, self.to
        );
        match self.reopened_to {
            Some(to) => format!(
                "{head}; reopened for {to} impacts per sample, {} of {} samples from their state at {}",
                self.resumed, self.samples, self.from
            ),
            None => head,
        }
    }
}

/// Answer to `POST /campaigns/{id}/raise-caps`.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct CapsRaised {
    /// Every cell whose cap was raised, in cell order.
    pub raised: Vec<RaisedCell>,
}

/// `POST /worker/claim` body.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ClaimRequest {
    /// A name for the worker (host and process), shown in logs.
    pub worker: String,
    /// The worker's engine fingerprints (`grit version --json`): an object from scene kind to
    /// fingerprint, or one fingerprint for every scene. Only jobs of campaigns pinned to the
    /// worker's fingerprint for their scene are leased to it (`docs/operations.md`, "Mixed
    /// machines").
    #[schema(value_type = Object)]
    pub engine: WorkerEngine,
}

/// A worker's engine fingerprints in a claim: one per scene it runs, or one for all.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum WorkerEngine {
    /// The same fingerprint for every scene.
    One(String),
    /// The fingerprint of each scene, by kind.
    PerScene(std::collections::BTreeMap<String, String>),
}

impl WorkerEngine {
    /// The fingerprints as the store matches them: a JSON object by scene kind, with `*` for
    /// one fingerprint of every scene; the error names the bad field.
    pub fn to_json(&self) -> Result<String, (String, String)> {
        let bad = |field: String, fp: &str| {
            (
                field,
                format!("`{fp}` is no engine fingerprint: 16 lowercase hex digits, as `grit version --json` prints"),
            )
        };
        let map = match self {
            WorkerEngine::One(fp) => {
                if !grit_erosion::campaign::is_fingerprint(fp) {
                    return Err(bad("engine".into(), fp));
                }
                std::collections::BTreeMap::from([("*".to_string(), fp.clone())])
            }
            WorkerEngine::PerScene(m) => {
                if m.is_empty() {
                    return Err((
                        "engine".into(),
                        "must name at least one scene's fingerprint".into(),
                    ));
                }
                for (kind, fp) in m {
                    if !grit_erosion::campaign::is_fingerprint(fp) {
                        return Err(bad(format!("engine.{kind}"), fp));
                    }
                }
                m.clone()
            }
        };
        Ok(serde_json::to_string(&map).expect("a map of strings serialises"))
    }
}

/// A checkpoint of a sample's surface after `impacts_done` impacts, with the job it belongs
/// to, its length and its checksum; `grit_farm::checkpoint::verify` checks all of them.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct Checkpoint {
    /// The job whose sample this is.
    pub job_id: i64,
    /// Impacts the checkpoint contains.
    pub impacts_done: u32,
    /// Length of the checkpoint bytes (before base64): fewer bytes mean it was cut short.
    pub size_bytes: u64,
    /// SHA-256 of the checkpoint bytes (before base64), 64 hexadecimal digits.
    pub sha256: String,
    /// `grit_erosion::Sample::checkpoint` bytes, base64 (standard alphabet, padded).
    pub data_b64: String,
}

/// A leased job: everything a worker needs to run (or resume) it, whatever its scene: the
/// scene's kind, its parameters as JSON, and counts in its units (impacts, slices).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct ClaimedJob {
    /// Job id.
    pub job_id: i64,
    /// Lease id; every write about this job must carry it.
    pub lease_id: Uuid,
    /// Seconds until the lease expires unless renewed.
    pub lease_ttl_s: f64,
    /// Campaign id.
    pub campaign_id: Uuid,
    /// Cell index.
    pub cell: u32,
    /// Sample index.
    pub sample: u32,
    /// Seed of the sample.
    pub seed: u64,
    /// Impacts planned (slices, for a jet job).
    pub impacts_planned: u32,
    /// Impacts already stored by earlier attempts (slices, for a jet job).
    pub impacts_done: u32,
    /// The job's scene, by kind (`impact`, `jet`): how to read `params` and what to run.
    #[serde(default = "impact_kind")]
    pub scene: String,
    /// The scene's parameters (`ImpactParams` for `impact`, `JetParams` for `jet`).
    #[schema(value_type = Object)]
    pub params: Value,
    /// Whether the job's cell may later ask for more impacts (`until_steady`, whose cap a
    /// later spec may raise): then send a checkpoint after the last impact with `complete`, so
    /// the job can resume from it.
    #[serde(default)]
    pub extendable: bool,
    /// The latest checkpoint, if any.
    pub checkpoint: Option<Checkpoint>,
}

/// The scene of a claim from a coordinator that did not name it: impacts were its only one.
fn impact_kind() -> String {
    "impact".into()
}

/// Heartbeat: renews the lease and delivers finished units (impacts of an impact job, slices
/// of a jet job) and optionally a checkpoint.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HeartbeatRequest {
    /// The lease id from the claim.
    pub lease_id: Uuid,
    /// Units finished since the last acknowledged heartbeat, in order, as the job's scene
    /// records them (`ImpactRecord`, `JetSlice`); units already stored are ignored, so a
    /// retried heartbeat is harmless. Also read under the names `impacts` and `slices`.
    #[serde(default, alias = "impacts", alias = "slices")]
    #[schema(value_type = Vec<Object>)]
    pub units: Vec<Value>,
    /// A checkpoint to keep as the job's latest.
    #[serde(default)]
    pub checkpoint: Option<Checkpoint>,
}

/// Answer to a heartbeat.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct HeartbeatResponse {
    /// Units now stored for the job (scripts rely on the name `impacts_done`).
    pub impacts_done: u32,
    /// New lease expiry, Unix milliseconds.
    pub lease_expires_ms: i64,
}

/// Completion: the last units; the job must then have all its planned units.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CompleteRequest {
    /// The lease id from the claim.
    pub lease_id: Uuid,
    /// Units not yet acknowledged (also read as `impacts` and `slices`).
    #[serde(default, alias = "impacts", alias = "slices")]
    #[schema(value_type = Vec<Object>)]
    pub units: Vec<Value>,
    /// The state after the last unit, for a job claimed `extendable`; kept until its cell is
    /// final.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub checkpoint: Option<Checkpoint>,
}

/// Failure report.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FailRequest {
    /// The lease id from the claim.
    pub lease_id: Uuid,
    /// What went wrong.
    pub error: String,
    /// Units finished before the failure (also read as `impacts` and `slices`).
    #[serde(default, alias = "impacts", alias = "slices")]
    #[schema(value_type = Vec<Object>)]
    pub units: Vec<Value>,
}

/// Release: give the job back without counting an attempt (a worker shutting down). Its body
/// is a heartbeat's: the units not yet acknowledged and a checkpoint to resume from.
pub type ReleaseRequest = HeartbeatRequest;

/// Records as the JSON values a worker's requests carry (every f64 kept to the bit).
pub fn units<R: Serialize>(records: &[R]) -> Vec<Value> {
    records
        .iter()
        .map(|r| serde_json::to_value(r).expect("a scene's record always serialises"))
        .collect()
}

/// Every error body: a message, and the offending field when there is one.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct ErrorBody {
    /// What went wrong.
    pub error: String,
    /// Path of the offending field, when the request had one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<String>,
}

/// `GET /healthz`.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct Health {
    /// Always "ok" when the database answers.
    pub status: String,
    /// Crate version.
    pub version: String,
}
