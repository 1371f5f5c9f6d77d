//! An impact campaign's results and its cells' growth, from what a farm stored
//! ([`crate::campaign::StoredCell`]): the cells as they stand now, with the impacts each
//! sample reported.

use std::collections::BTreeMap;

use crate::campaign::{
    annotate, next_step, results_json, stored_error, CellRecords, NextStep, StoredJob,
};
use crate::campaign::{StoredCell, UnitMasses};
use crate::impact::aggregate::{aggregate_campaign, aggregate_cell, CellInput, Impact};
use crate::impact::aggregate::{SampleInput, SLOPE_WINDOW};
use crate::{ImpactParams, ImpactRecord, Sample, SceneError};

/// The aggregation's input of stored cell `cell` whose samples reported `samples`.
fn input(cell: &StoredCell, samples: Vec<SampleInput>) -> CellInput {
    CellInput {
        angle_deg: cell.angle_deg.unwrap_or_default(),
        shape: cell.shape.clone().unwrap_or_default(),
        swept: cell.swept.clone(),
        planned_samples: cell.samples as usize,
        planned_impacts: cell.units as usize,
        samples,
    }
}

/// An impact's grain mass, loss and damage added, all the aggregation reads of it.
pub(crate) fn masses(r: &ImpactRecord) -> UnitMasses {
    UnitMasses {
        grain_kg_m: r.grain_mass_kg,
        loss_kg_m: r.mass_loss_kg,
        damage_kg_m: r.outcome.damage_added_kg,
    }
}

/// The samples of a cell as the aggregation reads them, from each unit's masses.
fn samples<'a, I>(samples: impl Iterator<Item = (u32, I)>) -> Vec<SampleInput>
where
    I: Iterator<Item = UnitMasses> + 'a,
{
    samples
        .map(|(sample, units)| SampleInput {
            sample,
            impacts: units
                .map(|m| Impact {
                    grain_mass_kg: m.grain_kg_m,
                    mass_loss_kg: m.loss_kg_m,
                    damage_added_kg: m.damage_kg_m,
                })
                .collect(),
        })
        .collect()
}

/// [`crate::Scene::results`] of the impact scene.
pub(crate) fn results(
    spec: &str,
    cells: Vec<CellRecords<ImpactRecord>>,
    raw: Option<Vec<StoredJob<ImpactRecord>>>,
) -> Result<String, SceneError> {
    let inputs: Vec<CellInput> = cells
        .iter()
        .map(|c| {
            let units = c.samples.iter().map(|(&s, r)| (s, r.iter().map(masses)));
            input(&c.cell, samples(units))
        })
        .collect();
    // The stored spec is the parsed one written back, every default filled in, so a reader
    // of the results can rerun exactly this campaign.
    let spec: serde_json::Value =
        serde_json::from_str(spec).map_err(|e| stored_error("stored spec", e))?;
    let mut results = aggregate_campaign(&inputs, SLOPE_WINDOW)
        .map_err(|e| stored_error("aggregation", e))?
        .with_spec(spec);
    // The cells' stored scenes, not today's defaults, say how the impacts ran.
    if let Some(c) = cells.first() {
        let p: ImpactParams = serde_json::from_str(&c.cell.params)
            .map_err(|e| stored_error("stored cell scene", e))?;
        results.numerics = Some(p.numerics);
    }
    for (result, c) in results.cells.iter_mut().zip(&cells) {
        annotate(result, c.cell.until_steady, c.cell.target_sem);
    }
    results_json::<Sample, _>(&results, raw.as_deref())
}

/// [`crate::Scene::next_step`] of the impact scene: the cell's erosion against its rules.
pub(crate) fn grow(
    cell: &StoredCell,
    units: &BTreeMap<u32, Vec<UnitMasses>>,
) -> Result<NextStep, SceneError> {
    let units = units.iter().map(|(&s, m)| (s, m.iter().copied()));
    let result = aggregate_cell(&input(cell, samples(units)), SLOPE_WINDOW)
        .map_err(|e| stored_error(&format!("assessing cell {}", cell.index), e))?;
    Ok(next_step(&result, cell.until_steady, cell.target_sem))
}
