//! An impact campaign's results and its cells' growth, from what a farm stored
//! ([`crate::campaign::StoredCell`]): the cells as they stand now, with the impacts each
//! sample reported.

use crate::campaign::{annotate, next_step, results_json, CellRecords, NextStep, StoredJob};
use crate::impact::aggregate::{aggregate_campaign, aggregate_cell, CellInput, Impact};
use crate::impact::aggregate::{SampleInput, SLOPE_WINDOW};
use crate::{ImpactParams, ImpactRecord, Sample, SceneError};

/// The aggregation's input of a stored cell: an impact's grain mass and loss are all it reads.
fn input(c: &CellRecords<ImpactRecord>) -> CellInput {
    CellInput {
        angle_deg: c.cell.angle_deg.unwrap_or_default(),
        shape: c.cell.shape.clone().unwrap_or_default(),
        swept: c.cell.swept.clone(),
        planned_samples: c.cell.samples as usize,
        planned_impacts: c.cell.units as usize,
        samples: c
            .samples
            .iter()
            .map(|(&sample, records)| SampleInput {
                sample,
                impacts: records
                    .iter()
                    .map(|r| Impact {
                        grain_mass_kg: r.grain_mass_kg,
                        mass_loss_kg: r.mass_loss_kg,
                    })
                    .collect(),
            })
            .collect(),
    }
}

fn stored(what: &str, e: impl std::fmt::Display) -> SceneError {
    SceneError::Run(format!("{what}: {e}"))
}

/// [`crate::Scene::results`] of the impact scene.
pub(crate) fn results(
    spec: &str,
    cells: Vec<CellRecords<ImpactRecord>>,
    raw: Option<Vec<StoredJob<ImpactRecord>>>,
) -> Result<String, SceneError> {
    let inputs: Vec<CellInput> = cells.iter().map(input).collect();
    // The stored spec is the parsed one written back, every default filled in, so a reader
    // of the results can rerun exactly this campaign.
    let spec: serde_json::Value =
        serde_json::from_str(spec).map_err(|e| stored("stored spec", e))?;
    let mut results = aggregate_campaign(&inputs, SLOPE_WINDOW)
        .map_err(|e| stored("aggregation", e))?
        .with_spec(spec);
    // The cells' stored scenes, not today's defaults, say how the impacts ran.
    if let Some(c) = cells.first() {
        let p: ImpactParams =
            serde_json::from_str(&c.cell.params).map_err(|e| stored("stored cell scene", e))?;
        results.numerics = Some(p.numerics);
    }
    for (result, c) in results.cells.iter_mut().zip(&cells) {
        annotate(result, c.cell.until_steady, c.cell.target_sem);
    }
    results_json::<Sample, _>(&results, raw.as_deref())
}

/// [`crate::Scene::next_step`] of the impact scene: the cell's erosion against its rules.
pub(crate) fn grow(c: &CellRecords<ImpactRecord>) -> Result<NextStep, SceneError> {
    let result = aggregate_cell(&input(c), SLOPE_WINDOW)
        .map_err(|e| stored(&format!("assessing cell {}", c.cell.index), e))?;
    Ok(next_step(&result, c.cell.until_steady, c.cell.target_sem))
}
