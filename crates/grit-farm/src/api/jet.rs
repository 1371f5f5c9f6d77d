//! The API bodies of jet campaigns (docs/jet-campaigns.md): what a worker reports for a jet
//! job, whose unit of progress is a slice of simulated time, and a jet campaign's results.
//! A jet job's heartbeat, complete, fail and release go to the same endpoints as an impact
//! job's, with `slices` where an impact job sends `impacts`.

use grit_erosion::jet::aggregate::JetCampaignResults;
use grit_erosion::jet::JetSlice;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;
use uuid::Uuid;

use super::{Checkpoint, ResultsResponse};

/// A jet job's heartbeat: renews the lease, delivers finished slices and maybe a checkpoint.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct JetHeartbeatRequest {
    /// The lease id from the claim.
    pub lease_id: Uuid,
    /// Slices finished since the last acknowledged heartbeat, in order; slices already
    /// stored are ignored, so a retried heartbeat is harmless.
    #[serde(default)]
    #[schema(value_type = Vec<Object>)]
    pub slices: Vec<JetSlice>,
    /// A checkpoint (`grit_erosion::jet::JetRun::checkpoint` bytes) to keep as the latest.
    #[serde(default)]
    pub checkpoint: Option<Checkpoint>,
}

/// A jet job's completion: the last slices; the job must then have all its planned slices.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct JetCompleteRequest {
    /// The lease id from the claim.
    pub lease_id: Uuid,
    /// Slices not yet acknowledged.
    #[serde(default)]
    #[schema(value_type = Vec<Object>)]
    pub slices: Vec<JetSlice>,
}

/// A jet job's failure report.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct JetFailRequest {
    /// The lease id from the claim.
    pub lease_id: Uuid,
    /// What went wrong.
    pub error: String,
    /// Slices finished before the failure.
    #[serde(default)]
    #[schema(value_type = Vec<Object>)]
    pub slices: Vec<JetSlice>,
}

/// A jet job given back without counting an attempt (a worker shutting down).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct JetReleaseRequest {
    /// The lease id from the claim.
    pub lease_id: Uuid,
    /// Slices not yet acknowledged.
    #[serde(default)]
    #[schema(value_type = Vec<Object>)]
    pub slices: Vec<JetSlice>,
    /// The checkpoint after the last finished slice, to resume from.
    #[serde(default)]
    pub checkpoint: Option<Checkpoint>,
}

/// The slices of one jet sample (`?raw=true`).
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct RawJetSample {
    /// Cell index.
    pub cell: u32,
    /// Sample index within the cell.
    pub sample: u32,
    /// The sample's seed.
    pub seed: u64,
    /// Job state.
    pub state: String,
    /// Every slice reported, in order.
    #[schema(value_type = Vec<Object>)]
    pub slices: Vec<JetSlice>,
}

/// `GET /campaigns/{id}/results` of a jet campaign: grit-erosion's `JetCampaignResults`, plus
/// the slices of every sample when asked.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
pub struct JetResultsResponse {
    /// Aggregated results.
    #[serde(flatten)]
    #[schema(value_type = Object)]
    pub results: JetCampaignResults,
    /// Every sample's slices, with `?raw=true`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub raw: Option<Vec<RawJetSample>>,
}

/// The results of a campaign of either scene, as the results endpoint serves them.
#[derive(Debug, Clone, Serialize, Deserialize, ToSchema)]
#[serde(untagged)]
pub enum AnyResults {
    /// A jet campaign's (they carry `"scene": "jet"`).
    Jet(JetResultsResponse),
    /// An impact campaign's, as before jets.
    Impact(ResultsResponse),
}

impl AnyResults {
    /// The impact results, if these are an impact campaign's.
    pub fn impact(&self) -> Option<&ResultsResponse> {
        match self {
            AnyResults::Impact(r) => Some(r),
            AnyResults::Jet(_) => None,
        }
    }

    /// The jet results, if these are a jet campaign's.
    pub fn jet(&self) -> Option<&JetResultsResponse> {
        match self {
            AnyResults::Jet(r) => Some(r),
            AnyResults::Impact(_) => None,
        }
    }

    /// Whether some cell still lacks samples, impacts or slices.
    pub fn partial(&self) -> bool {
        match self {
            AnyResults::Jet(r) => r.results.partial,
            AnyResults::Impact(r) => r.results.partial,
        }
    }

    /// One warning line per cell whose rate is not a steady one.
    pub fn unsteady_warnings(&self) -> Vec<String> {
        match self {
            AnyResults::Jet(r) => r.results.unsteady_warnings(),
            AnyResults::Impact(r) => r.results.unsteady_warnings(),
        }
    }
}
