//! The store's side of jet campaigns (docs/jet-campaigns.md): their results from the stored
//! slices.

use grit_erosion::campaign::JetCampaignSpec;
use grit_erosion::jet::aggregate::{aggregate_jet_campaign, JetCellInput, JetSampleInput};
use grit_erosion::jet::JetSlice;
use uuid::Uuid;

use super::Store;
use crate::api::{JetResultsResponse, RawJetSample};
use crate::error::{Error, Result};

impl Store {
    /// A jet campaign's results (partial while jobs remain) from its stored spec and slices;
    /// with `raw`, every sample's slices.
    pub(super) async fn jet_results(
        &self,
        id: Uuid,
        spec_text: &str,
        raw: bool,
    ) -> Result<JetResultsResponse> {
        let spec = JetCampaignSpec::from_json(spec_text)?;
        let cells = spec.cells()?;
        let per_cell = self.cell_records::<JetSlice>(id, cells.len()).await?;
        let inputs: Vec<JetCellInput> = cells
            .iter()
            .zip(per_cell)
            .map(|(cell, samples)| JetCellInput {
                cell: cell.index,
                params: cell.params.clone(),
                pump_pressure_mpa: cell.pump_pressure_mpa,
                swept: cell.swept.clone(),
                planned_samples: spec.samples as usize,
                planned_slices: cell.slices as usize,
                samples: samples
                    .into_iter()
                    .map(|(sample, slices)| JetSampleInput { sample, slices })
                    .collect(),
            })
            .collect();
        let spec_value: serde_json::Value = serde_json::from_str(spec_text)
            .map_err(|e| Error::Internal(format!("stored spec: {e}")))?;
        let results = aggregate_jet_campaign(&inputs)
            .map_err(|e| Error::Internal(format!("aggregation: {e}")))?
            .with_spec(spec_value);
        let raw = if raw {
            Some(self.raw_slices(id).await?)
        } else {
            None
        };
        Ok(JetResultsResponse { results, raw })
    }

    async fn raw_slices(&self, id: Uuid) -> Result<Vec<RawJetSample>> {
        let jobs = self.job_records::<JetSlice>(id).await?;
        Ok(jobs
            .into_iter()
            .map(|(j, slices)| RawJetSample {
                cell: j.cell,
                sample: j.sample,
                seed: j.seed,
                state: j.state,
                slices,
            })
            .collect())
    }
}
