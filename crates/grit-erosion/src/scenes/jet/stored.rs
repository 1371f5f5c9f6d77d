//! A jet campaign's results from what a farm stored ([`crate::campaign::StoredCell`]): the
//! cells as they stand now, with the slices each run reported.

use super::aggregate::{aggregate_jet_campaign, JetCellInput, JetSampleInput};
use super::{JetParams, JetRun, JetSlice};
use crate::campaign::{results_json, stored_error, CellRecords, JetCampaignSpec, StoredJob};
use crate::SceneError;

/// [`crate::Scene::results`] of the jet scene.
pub(crate) fn results(
    spec_text: &str,
    cells: Vec<CellRecords<JetSlice>>,
    raw: Option<Vec<StoredJob<JetSlice>>>,
) -> Result<String, SceneError> {
    let spec = JetCampaignSpec::from_json(spec_text).map_err(|e| stored_error("stored spec", e))?;
    // A cell keeps no pump pressure of its own: a swept one is among its swept values, a
    // single one the spec's.
    let pressure = spec
        .pump_pressure_mpa
        .as_ref()
        .and_then(|p| p.0.first().copied());
    let inputs = cells
        .into_iter()
        .map(|c| {
            let params: JetParams = serde_json::from_str(&c.cell.params)
                .map_err(|e| stored_error("stored cell scene", e))?;
            Ok(JetCellInput {
                cell: c.cell.index,
                params,
                pump_pressure_mpa: pressure
                    .map(|p| c.cell.swept.get("pump_pressure_mpa").copied().unwrap_or(p)),
                planned_samples: c.cell.samples as usize,
                planned_slices: c.cell.units as usize,
                swept: c.cell.swept,
                samples: c
                    .samples
                    .into_iter()
                    .map(|(sample, slices)| JetSampleInput { sample, slices })
                    .collect(),
            })
        })
        .collect::<Result<Vec<_>, SceneError>>()?;
    let spec: serde_json::Value =
        serde_json::from_str(spec_text).map_err(|e| stored_error("stored spec", e))?;
    let results = aggregate_jet_campaign(&inputs)
        .map_err(|e| stored_error("aggregation", e))?
        .with_spec(spec);
    results_json::<JetRun, _>(&results, raw.as_deref())
}
