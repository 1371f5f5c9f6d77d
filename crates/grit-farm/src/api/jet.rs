//! The API bodies of jet campaigns' results (docs/jet-campaigns.md). A jet job's heartbeat,
//! complete, fail and release are an impact job's, its units being slices.

use grit_erosion::jet::aggregate::JetCampaignResults;
use grit_erosion::jet::JetSlice;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::ResultsResponse;

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

    /// Drops every sample's per-impact series or slices (`?raw=true`'s part), leaving what the
    /// results endpoint serves without it.
    pub fn strip_raw(&mut self) {
        match self {
            AnyResults::Jet(r) => r.raw = None,
            AnyResults::Impact(r) => r.raw = None,
        }
    }

    /// Whether some cell still lacks samples, impacts or slices.
    pub fn partial(&self) -> bool {
        match self {
            AnyResults::Jet(r) => r.results.partial,
            AnyResults::Impact(r) => r.results.partial,
        }
    }

    /// Cells with all their samples, impacts or slices, and cells in all.
    pub fn cells_complete(&self) -> (usize, usize) {
        let count = |partial: &mut dyn Iterator<Item = bool>| {
            partial.fold((0, 0), |(done, all), p| (done + usize::from(!p), all + 1))
        };
        match self {
            AnyResults::Jet(r) => count(&mut r.results.cells.iter().map(|c| c.partial)),
            AnyResults::Impact(r) => count(&mut r.results.cells.iter().map(|c| c.partial)),
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
