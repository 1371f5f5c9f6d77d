//! Single `grit jet` runs gathered into cells, so their files chart and aggregate as a jet
//! campaign's (`grit plot run1.json run2.json …`): runs of equal parameters are one cell, their
//! seeds its samples.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::aggregate::{JetCellInput, JetSampleInput};
use super::{JetParams, JetSlice};
use crate::stats::AggregateError;

/// One run as `grit jet --json` or `-o` writes it (the fields the aggregation needs).
#[derive(Debug, Clone, Deserialize)]
pub struct JetRunRecord {
    /// The run's parameters.
    pub params: JetParams,
    /// Seed of its abrasive placement.
    pub seed: u64,
    /// Its slices in order.
    pub slices: Vec<JetSlice>,
}

/// Reads one numeric parameter of a run.
type Field = fn(&JetParams) -> f64;

/// The numeric parameters a set of runs may differ in, by spec name.
const SWEEPABLE: [(&str, Field); 5] = [
    ("velocity_m_s", |p| p.velocity_m_s),
    ("mass_flow_kg_s", |p| p.mass_flow_kg_s),
    ("time_ms", |p| p.time_ms),
    ("spacing_m", |p| p.spacing_m),
    ("coupling_radius_d", |p| p.coupling_radius_d),
];

/// Groups `runs` into cells in order of first appearance: runs whose parameters are equal
/// form one cell with a sample per seed (in seed order). A parameter that differs between
/// cells becomes a swept value of every cell; materials as `material_index`, their order of
/// first appearance. Two runs of one cell with the same seed are an error naming both.
pub fn cells_from_runs(runs: &[JetRunRecord]) -> Result<Vec<JetCellInput>, AggregateError> {
    let mut groups: Vec<(&JetParams, Vec<usize>)> = Vec::new();
    for (i, run) in runs.iter().enumerate() {
        match groups.iter_mut().find(|(p, _)| **p == run.params) {
            Some((_, members)) => {
                if let Some(&j) = members.iter().find(|&&j| runs[j].seed == run.seed) {
                    return Err(AggregateError::Invalid {
                        field: format!("runs[{i}].seed"),
                        rule: format!(
                            "seed {} of these parameters is already runs[{j}]: each seed is one sample",
                            run.seed
                        ),
                    });
                }
                members.push(i);
            }
            None => groups.push((&run.params, vec![i])),
        }
    }
    let mut materials: Vec<&str> = Vec::new();
    for (p, _) in &groups {
        if !materials.contains(&p.material.0.name.as_str()) {
            materials.push(&p.material.0.name);
        }
    }
    let varies = |f: Field| {
        groups
            .iter()
            .any(|(p, _)| f(p).to_bits() != f(groups[0].0).to_bits())
    };
    let swept_names: Vec<_> = SWEEPABLE.iter().filter(|(_, f)| varies(*f)).collect();
    Ok(groups
        .iter()
        .enumerate()
        .map(|(cell, (params, members))| {
            let mut swept: BTreeMap<String, f64> = swept_names
                .iter()
                .map(|(name, f)| (name.to_string(), f(params)))
                .collect();
            if materials.len() > 1 {
                let index = materials
                    .iter()
                    .position(|m| *m == params.material.0.name)
                    .unwrap_or(0);
                swept.insert("material_index".into(), index as f64);
            }
            let mut members = members.clone();
            members.sort_by_key(|&i| runs[i].seed);
            JetCellInput {
                cell: cell as u32,
                params: (*params).clone(),
                pump_pressure_mpa: None,
                swept,
                planned_samples: members.len(),
                planned_slices: params.slices() as usize,
                samples: members
                    .iter()
                    .enumerate()
                    .map(|(k, &i)| JetSampleInput {
                        sample: k as u32,
                        slices: runs[i].slices.clone(),
                    })
                    .collect(),
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::test_slice;

    fn run(velocity: f64, seed: u64, material: &str) -> JetRunRecord {
        let mut params = JetParams {
            velocity_m_s: velocity,
            time_ms: 0.002,
            slice_ms: 0.001,
            ..JetParams::default()
        };
        params.material.0 = grit_sph::Material::by_name(material).unwrap();
        let slices = (1..=2)
            .map(|k| test_slice(k, k as f64 * 1e-6, seed as f64 * 1e-6, 1e-5 * k as f64))
            .collect();
        JetRunRecord {
            params,
            seed,
            slices,
        }
    }

    #[test]
    fn runs_of_equal_parameters_are_one_cell_and_what_differs_is_swept() {
        let runs = [
            run(500.0, 2, "copper"),
            run(300.0, 1, "copper"),
            run(500.0, 1, "copper"),
            run(500.0, 1, "al6061"),
        ];
        let cells = cells_from_runs(&runs).unwrap();
        assert_eq!(cells.len(), 3);
        // The first cell's samples are in seed order: seed 1 (runs[2]) first.
        assert_eq!(cells[0].samples.len(), 2);
        assert_eq!(cells[0].samples[0].slices[0].sample.mass_loss_kg_m, 1e-6);
        assert_eq!(cells[0].planned_slices, 2);
        assert_eq!(cells[1].swept["velocity_m_s"], 300.0);
        assert_eq!(cells[2].swept["material_index"], 1.0);
        assert_eq!(cells[0].swept.len(), 2, "{:?}", cells[0].swept);
        let results = crate::jet::aggregate::aggregate_jet_campaign(&cells).unwrap();
        assert_eq!(results.cells[0].samples, 2);
    }

    #[test]
    fn one_seed_twice_in_a_cell_is_an_error_naming_both_runs() {
        let runs = [run(500.0, 1, "copper"), run(500.0, 1, "copper")];
        let e = cells_from_runs(&runs).unwrap_err().to_string();
        assert!(e.contains("runs[1].seed") && e.contains("runs[0]"), "{e}");
    }
}
