//! The results JSON: grit-erosion's `CampaignResults` with the farm's optional `raw` array, or
//! a jet campaign's `JetCampaignResults` (`"scene": "jet"`).

use std::path::Path;

use grit_erosion::jet::aggregate::{aggregate_jet_campaign, JetCampaignResults};
use grit_erosion::jet::runs::{cells_from_runs, JetRunRecord};
use grit_erosion::CampaignResults;
use serde::Deserialize;
use serde_json::Value;

use crate::PlotError;

/// One impact of a raw series; the farm's `ImpactRecord` carries more, which is ignored.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct RawImpact {
    /// 1-based impact number within the sample (0 when absent).
    #[serde(default)]
    pub impact: u32,
    /// Mass of the grain, kg (per metre of depth in 2D).
    pub grain_mass_kg: f64,
    /// Surface mass removed by the impact, kg (per metre of depth in 2D).
    pub mass_loss_kg: f64,
    /// What else the impact did; only the damage it added is read.
    #[serde(default)]
    pub outcome: Option<RawOutcome>,
}

/// The part of an impact's outcome the charts read.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
pub struct RawOutcome {
    /// Damage the impact added to the surface, Σ m ΔD (seed eq. 19), kg (per metre of depth in
    /// 2D); absent in records written before it was recorded.
    #[serde(default)]
    pub damage_added_kg: Option<f64>,
}

impl RawImpact {
    /// The impact as the aggregate counts it: grain, loss and the damage added, if recorded.
    pub fn as_impact(&self) -> grit_erosion::Impact {
        grit_erosion::Impact {
            grain_mass_kg: self.grain_mass_kg,
            mass_loss_kg: self.mass_loss_kg,
            damage_added_kg: self.outcome.and_then(|o| o.damage_added_kg),
        }
    }
}

/// One sample's per-impact series (`raw[]` of `grit run --raw` or `grit results --raw`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct RawSeries {
    /// Index of the cell in `cells`.
    pub cell: u32,
    /// Index of the sample within its cell.
    pub sample: u32,
    /// Impacts in the order they hit the surface.
    pub impacts: Vec<RawImpact>,
}

impl RawSeries {
    /// The sample's impacts in the order they hit the surface, as the aggregate counts them.
    pub fn impacts_in_order(&self) -> Vec<grit_erosion::Impact> {
        let mut impacts = self.impacts.clone();
        impacts.sort_by_key(|m| m.impact);
        impacts.iter().map(RawImpact::as_impact).collect()
    }
}

/// A results file ready to plot.
#[derive(Debug, Clone)]
pub struct PlotInput {
    /// The aggregated results.
    pub results: CampaignResults,
    /// Per-impact series of every sample, when the file has them.
    pub raw: Option<Vec<RawSeries>>,
}

/// Reads and checks a results JSON file.
pub fn load(path: &Path) -> Result<PlotInput, PlotError> {
    let text = std::fs::read_to_string(path).map_err(|error| PlotError::Read {
        path: path.to_path_buf(),
        error,
    })?;
    parse(&text).map_err(|e| PlotError::Input(format!("{}: {e}", path.display())))
}

/// A results file of either scene, ready to plot.
#[derive(Debug, Clone)]
pub enum AnyInput {
    /// An impact campaign's results.
    Impact(PlotInput),
    /// A jet campaign's results (their `raw` slices, if any, are not needed by its charts).
    Jet(JetCampaignResults),
}

/// Reads and checks a results JSON file of either scene.
pub fn load_any(path: &Path) -> Result<AnyInput, PlotError> {
    let text = std::fs::read_to_string(path).map_err(|error| PlotError::Read {
        path: path.to_path_buf(),
        error,
    })?;
    parse_any(&text).map_err(|e| PlotError::Input(format!("{}: {e}", path.display())))
}

/// Parses and checks results JSON text of either scene: `"scene": "jet"` marks a jet
/// campaign's.
pub fn parse_any(text: &str) -> Result<AnyInput, PlotError> {
    let value: Value =
        serde_json::from_str(text).map_err(|e| PlotError::Input(format!("not valid JSON: {e}")))?;
    if value.get("scene").and_then(Value::as_str) != Some("jet") {
        return parse(text).map(AnyInput::Impact);
    }
    let mut value = value;
    if let Some(obj) = value.as_object_mut() {
        obj.remove("raw");
    }
    let r: JetCampaignResults = serde_json::from_value(value)
        .map_err(|e| PlotError::Input(format!("not jet results grit can read: {e}")))?;
    if r.cells.is_empty() {
        return Err(PlotError::Input("`cells` is empty: nothing to plot".into()));
    }
    Ok(AnyInput::Jet(r))
}

/// Parses and checks results JSON text.
pub fn parse(text: &str) -> Result<PlotInput, PlotError> {
    let bad = |m: String| PlotError::Input(m);
    // Parse to a value first, so a syntax error names its line and column and a file of
    // the wrong kind is told apart from a broken one.
    let mut value: Value =
        serde_json::from_str(text).map_err(|e| bad(format!("not valid JSON: {e}")))?;
    let Some(obj) = value.as_object_mut() else {
        return Err(bad(
            "expected a JSON object with `cells` (the results of grit run or grit results)".into(),
        ));
    };
    if obj.get("scene").and_then(Value::as_str) == Some("jet") {
        return Err(bad(
            "a jet campaign's results (scene: jet), not an impact campaign's: they are drawn one file at a time"
                .into(),
        ));
    }
    match obj.get("cells") {
        None => {
            return Err(bad(
                "no `cells` array: not a results file (grit run writes OUT/results.json; \
                 grit results ID -o FILE fetches one)"
                    .into(),
            ))
        }
        Some(Value::Array(a)) if a.is_empty() => {
            return Err(bad("`cells` is empty: nothing to plot".into()))
        }
        Some(Value::Array(_)) => {}
        Some(_) => return Err(bad("`cells` is not an array".into())),
    }
    let raw = obj.remove("raw");
    let results: CampaignResults = serde_json::from_value(value)
        .map_err(|e| bad(format!("not a results file grit can read: {e}")))?;
    // A file edited by hand or by another tool: values no campaign can produce would draw
    // and compare as NaN.
    for (i, c) in results.cells.iter().enumerate() {
        if !(c.angle_deg > 0.0 && c.angle_deg <= 90.0) {
            return Err(bad(format!(
                "cells[{i}].angle_deg: must be in (0, 90] degrees, got {}",
                c.angle_deg
            )));
        }
        let checks = [
            ("erosion_mean", c.erosion_mean, false),
            ("erosion_std", c.erosion_std, true),
            ("erosion_sem", c.erosion_sem, true),
        ];
        for (name, v, non_negative) in checks {
            if let Some(v) = v {
                if !v.is_finite() || (non_negative && v < 0.0) {
                    let rule = if non_negative {
                        "finite and ≥ 0"
                    } else {
                        "finite"
                    };
                    return Err(bad(format!("cells[{i}].{name}: must be {rule}, got {v}")));
                }
            }
        }
    }
    let raw: Option<Vec<RawSeries>> = match raw {
        None | Some(Value::Null) => None,
        Some(r) => Some(serde_json::from_value(r).map_err(|e| bad(format!("raw: {e}")))?),
    };
    if let Some(raw) = &raw {
        for (i, r) in raw.iter().enumerate() {
            if r.cell as usize >= results.cells.len() {
                return Err(bad(format!(
                    "raw[{i}].cell: {} but there are {} cells",
                    r.cell,
                    results.cells.len()
                )));
            }
        }
    }
    Ok(PlotInput { results, raw })
}

/// Several results files as one: cells in file order, a cell whose angle, shape and swept
/// values an earlier file already has is left out (so a full campaign can be drawn with the
/// shapes of a smaller one beside it); `raw` is kept only when every file has it. Returns the
/// merged input and a note per cell left out.
pub fn merge(inputs: Vec<(String, PlotInput)>) -> Result<(PlotInput, Vec<String>), PlotError> {
    let mut iter = inputs.into_iter();
    let Some((first_name, first)) = iter.next() else {
        return Err(PlotError::Input("no results file given".into()));
    };
    let window = first.results.slope_window;
    let mut names = vec![first_name; first.results.cells.len()];
    let mut merged = first;
    let mut notes = Vec::new();
    for (name, input) in iter {
        if input.results.slope_window != window {
            return Err(PlotError::Input(format!(
                "{name}: slope_window {} but the first file has {window}; erosions over \
                 different windows cannot be drawn together",
                input.results.slope_window
            )));
        }
        let mut new_index = Vec::with_capacity(input.results.cells.len());
        for c in input.results.cells {
            let same = merged.results.cells.iter().position(|m| m.same_cell(&c));
            match same {
                Some(k) => {
                    notes.push(format!(
                        "{name}: cell {}° {} left out; {} has it",
                        c.angle_deg, c.shape, names[k]
                    ));
                    new_index.push(None);
                }
                None => {
                    new_index.push(Some(merged.results.cells.len() as u32));
                    names.push(name.clone());
                    merged.results.partial |= c.partial;
                    merged.results.cells.push(c);
                }
            }
        }
        merged.raw = match (merged.raw.take(), input.raw) {
            (Some(mut all), Some(more)) => {
                all.extend(more.into_iter().filter_map(|mut r| {
                    r.cell = new_index[r.cell as usize]?;
                    Some(r)
                }));
                Some(all)
            }
            _ => None,
        };
    }
    merged.results.steady = merged.results.cells_steady();
    Ok((merged, notes))
}

/// Whether parsed JSON is one `grit jet` run (`params`, `seed`, `slices`; no `scene`).
fn is_jet_run(value: &Value) -> bool {
    value.get("scene").is_none()
        && ["params", "seed", "slices"]
            .iter()
            .all(|k| value.get(k).is_some())
}

/// Reads `grit jet -o` run files as one jet campaign ([`grit_erosion::jet::runs`]): `None`
/// when none of them is a run file; an error naming the file when only some are, or when one
/// cannot be read.
pub fn load_jet_runs(
    paths: &[std::path::PathBuf],
) -> Result<Option<JetCampaignResults>, PlotError> {
    let mut runs = Vec::new();
    let mut others = Vec::new();
    for path in paths {
        let text = std::fs::read_to_string(path).map_err(|error| PlotError::Read {
            path: path.clone(),
            error,
        })?;
        let at = |e: String| PlotError::Input(format!("{}: {e}", path.display()));
        let value: Value =
            serde_json::from_str(&text).map_err(|e| at(format!("not valid JSON: {e}")))?;
        if !is_jet_run(&value) {
            others.push(path.display().to_string());
            continue;
        }
        let run: JetRunRecord = serde_path_to_error::deserialize(value)
            .map_err(|e| at(format!("{}: {}", e.path(), e.inner())))?;
        runs.push(run);
    }
    if runs.is_empty() {
        return Ok(None);
    }
    if let Some(other) = others.first() {
        return Err(PlotError::Input(format!(
            "{other}: not a `grit jet` run file, but the other files are; plot run files together and campaign results on their own"
        )));
    }
    let cells = cells_from_runs(&runs).map_err(|e| PlotError::Input(e.to_string()))?;
    let results = aggregate_jet_campaign(&cells).map_err(|e| PlotError::Input(e.to_string()))?;
    Ok(Some(results))
}

#[cfg(test)]
mod tests {
    use super::*;

    const CELL: &str = r#"{"angle_deg": 45.0, "shape": "hexagon", "partial": false,
        "samples": 0, "samples_planned": 1, "samples_reported": 0, "samples_without_slope": 0,
        "impacts_planned": 20, "erosion_mean": null, "erosion_std": null, "erosion_sem": null,
        "per_sample": [], "mean_series": [], "convergence": []}"#;

    fn err(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn wrong_files_are_told_apart() {
        assert!(err("{").starts_with("not valid JSON"));
        assert!(err("[1, 2]").starts_with("expected a JSON object"));
        assert!(err(r#"{"partial": false}"#).starts_with("no `cells` array"));
        assert!(err(r#"{"cells": []}"#).contains("empty"));
        assert!(err(r#"{"cells": 3}"#).contains("not an array"));
        assert!(err(r#"{"cells": [{}]}"#).starts_with("not a results file"));
    }

    #[test]
    fn raw_is_optional_and_checked() {
        let base = format!(r#"{{"partial": false, "slope_window": 20, "cells": [{CELL}]"#);
        let p = parse(&format!("{base}}}")).unwrap();
        assert!(p.raw.is_none());
        let with = format!(
            r#"{base}, "raw": [{{"cell": 0, "sample": 0, "seed": 9, "state": "done",
            "impacts": [{{"impact": 1, "grain_mass_kg": 1e-4, "mass_loss_kg": 0.0,
            "aim_x_m": 0.0}}]}}]}}"#
        );
        let p = parse(&with).unwrap();
        assert_eq!(p.raw.unwrap()[0].impacts[0].grain_mass_kg, 1e-4);
        let stray = with.replace(r#""cell": 0"#, r#""cell": 4"#);
        assert!(err(&stray).starts_with("raw[0].cell"));
    }

    #[test]
    fn merge_keeps_the_first_files_cells_and_reindexes_raw() {
        let cell90 = CELL.replace("45.0", "90.0");
        let raw = |cell: u32| {
            format!(
                r#"{{"cell": {cell}, "sample": 0, "impacts": [{{"grain_mass_kg": 1e-4,
                "mass_loss_kg": 0.0}}]}}"#
            )
        };
        let a = parse(&format!(
            r#"{{"partial": false, "slope_window": 20, "cells": [{CELL}], "raw": [{}]}}"#,
            raw(0)
        ))
        .unwrap();
        let b = parse(&format!(
            r#"{{"partial": false, "slope_window": 20, "cells": [{CELL}, {cell90}],
            "raw": [{}, {}]}}"#,
            raw(0),
            raw(1)
        ))
        .unwrap();
        let (m, notes) = merge(vec![("a".into(), a.clone()), ("b".into(), b)]).unwrap();
        assert_eq!(m.results.cells.len(), 2);
        assert_eq!(m.results.cells[1].angle_deg, 90.0);
        assert_eq!(notes.len(), 1);
        assert!(notes[0].contains("b: cell 45° hexagon left out; a has it"));
        let raw = m.raw.unwrap();
        assert_eq!(raw.iter().map(|r| r.cell).collect::<Vec<_>>(), vec![0, 1]);
        let other = a.clone();
        let mut c = other.clone();
        c.results.slope_window = 10;
        assert!(merge(vec![("a".into(), other), ("c".into(), c)]).is_err());
    }
}
