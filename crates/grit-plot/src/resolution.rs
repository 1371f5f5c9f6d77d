//! The resolution ladder (seed paper section 3.1: a rate holds only once it holds under
//! refinement): each cell's erosion against particles per grain diameter, across results files
//! of the same scene run at several spacings, with ±1 s.e. bars; hollow markers for cells that
//! are no stationary rate under this build's rules, whatever rules the file ran under: not at
//! steady state, still running, or steady with a damage balance that does not hold.

use std::path::Path;

use grit_erosion::impact::steady::reassess;
use grit_erosion::models::compare::{balanced, spec_number, verdict};
use grit_erosion::{CampaignResults, Stationarity};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::charts::legend_box;
use crate::draw::{
    axes, colour, de, error_bar, hollow_notes, marker_style, prepare_output, save, top, with_notes,
    DrawResult, Figure,
};
use crate::{PlotError, Report};

/// kg per kg to mg per g.
const MG_PER_G: f64 = 1e3;

/// One cell of one results file on the ladder.
#[derive(Debug, Clone, PartialEq)]
pub struct LadderPoint {
    /// The file it came from, as given.
    pub file: String,
    /// Grain diameter over particle spacing, Dg/Δx.
    pub per_dg: f64,
    /// Particle spacing Δx (m).
    pub spacing_m: f64,
    /// What the series holds fixed: angle, shape and, where it is not the preset, material.
    pub series: String,
    /// Mean erosion over the samples (kg/kg).
    pub erosion: f64,
    /// Its standard error (kg/kg); 0 with one sample.
    pub sem: f64,
    /// Samples with a slope.
    pub samples: usize,
    /// Impacts per sample at the end.
    pub impacts: usize,
    /// The cell's steady-state verdict under this build's rule (`steady::reassess`); `None`
    /// where the file cannot settle it.
    pub steady: Option<bool>,
    /// Whether its last window's loss pays for the damage added, by this build's rule
    /// (`DamageBalance::holds`); `None` where the file has no balance.
    pub balanced: Option<bool>,
    /// Whether samples or impacts are missing against the plan (a campaign still running).
    pub partial: bool,
}

impl LadderPoint {
    /// Whether the point is a stationary rate, by the rule `CellResult::stationarity` applies,
    /// and only once its cell is finished.
    pub fn stationarity(&self) -> Stationarity {
        Stationarity::of(self.steady, self.balanced).unless_partial(self.partial)
    }
}

/// The material's name in the stored spec: a preset's name, or the `name` of a full material.
fn material_name(r: &CampaignResults) -> Option<String> {
    let m = r.spec.as_ref()?.get("material")?;
    let m = match m {
        serde_json::Value::Array(a) if a.len() == 1 => &a[0],
        m => m,
    };
    m.as_str()
        .or_else(|| m.get("name").and_then(|n| n.as_str()))
        .map(str::to_string)
}

/// Every cell with an erosion in `files`, placed by its file's spacing; an error names a file
/// whose spec does not give one spacing and one grain diameter, or that sweeps speed or size
/// (their cells would share a place on the ladder).
pub fn ladder(files: &[(String, CampaignResults)]) -> Result<Vec<LadderPoint>, PlotError> {
    let mut points = Vec::new();
    for (file, r) in files {
        let missing = |what: &str| {
            PlotError::Input(format!(
                "{file}: the results carry no single {what} in their `spec`; the resolution \
                 ladder needs one spacing and one grain diameter per file"
            ))
        };
        let dx =
            spec_number(r.spec.as_ref(), &["spacing_m"]).ok_or_else(|| missing("spacing_m"))?;
        let dg = spec_number(r.spec.as_ref(), &["grain", "diameter_m"])
            .ok_or_else(|| missing("grain diameter"))?;
        let material = material_name(r).filter(|m| m != "aisi304");
        for c in &r.cells {
            if !c.swept.is_empty() {
                return Err(PlotError::Input(format!(
                    "{file}: cell {} sweeps {:?}; the ladder compares one scene at several \
                     spacings, one file per spacing",
                    c.label(),
                    c.swept.keys().collect::<Vec<_>>()
                )));
            }
            let Some(erosion) = c.erosion_mean else {
                continue;
            };
            let mut series = format!("{}° {}", c.angle_deg, c.shape);
            if let Some(m) = &material {
                series.push_str(&format!(", {m}"));
            }
            points.push(LadderPoint {
                file: file.clone(),
                per_dg: dg / dx,
                spacing_m: dx,
                series,
                erosion,
                sem: c.erosion_sem.unwrap_or(0.0),
                samples: c.samples,
                impacts: c.per_sample.iter().map(|s| s.impacts).max().unwrap_or(0),
                steady: reassess(c).and_then(|r| r.steady()),
                balanced: balanced(c),
                partial: c.partial,
            });
        }
    }
    Ok(points)
}

/// The ladder as a Markdown table, one row per point, series by series in first-seen order.
pub fn ladder_table(points: &[LadderPoint]) -> String {
    let mut s = String::from(
        "| cell | per Dg | Δx (µm) | samples × impacts | erosion (mg/g) ± s.e. | verdict | file |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for name in series_names(points) {
        for p in points.iter().filter(|p| p.series == name) {
            s.push_str(&format!(
                "| {} | {:.1} | {:.2} | {} × {} | {:.2} ± {:.2} | {} | {} |\n",
                p.series,
                p.per_dg,
                p.spacing_m * 1e6,
                p.samples,
                p.impacts,
                p.erosion * MG_PER_G,
                p.sem * MG_PER_G,
                verdict(p.steady, p.balanced, p.partial),
                p.file
            ));
        }
    }
    s
}

fn series_names(points: &[LadderPoint]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for p in points {
        if !names.contains(&p.series) {
            names.push(p.series.clone());
        }
    }
    names
}

struct Ladder<'a> {
    points: &'a [LadderPoint],
    notes: Vec<String>,
}

impl Figure for Ladder<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let per_dg = || self.points.iter().map(|p| p.per_dg);
        let xmin = per_dg().fold(f64::INFINITY, f64::min) * 0.85;
        let xmax = per_dg().fold(0.0, f64::max) * 1.1;
        let ymax = top(self.points.iter().map(|p| (p.erosion + p.sem) * MG_PER_G));
        let mut chart = axes(
            &area,
            "Erosion against resolution",
            (xmin..xmax, "particles per grain diameter, Dg/Δx"),
            (0.0..ymax, "erosion (mg surface lost per g of grains)"),
        )?;
        for (i, name) in series_names(self.points).iter().enumerate() {
            let c = colour(i);
            let mut ps: Vec<&LadderPoint> =
                self.points.iter().filter(|p| &p.series == name).collect();
            ps.sort_by(|a, b| a.per_dg.total_cmp(&b.per_dg));
            for p in &ps {
                let (e, s) = (p.erosion * MG_PER_G, p.sem * MG_PER_G);
                chart
                    .draw_series(error_bar(p.per_dg, e - s, e + s, 0.6, c.stroke_width(1)))
                    .map_err(de)?;
                chart
                    .draw_series(std::iter::once(Circle::new(
                        (p.per_dg, e),
                        5,
                        marker_style(c, p.stationarity().is_rate()),
                    )))
                    .map_err(de)?;
            }
            let line = c.stroke_width(2);
            chart
                .draw_series(LineSeries::new(
                    ps.iter().map(|p| (p.per_dg, p.erosion * MG_PER_G)),
                    line,
                ))
                .map_err(de)?
                .label(format!("{name}, bars ±1 s.e."))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], line));
        }
        legend_box(&mut chart, SeriesLabelPosition::LowerRight)
    }
}

/// Writes `erosion_vs_resolution` (PNG and SVG) into `out` from the ladder's points.
pub fn plot_ladder(points: &[LadderPoint], out: &Path) -> Result<Report, PlotError> {
    prepare_output(out)?;
    let mut report = Report::default();
    if points.is_empty() {
        report
            .notes
            .push("no cell has an erosion yet: no resolution chart".into());
        return Ok(report);
    }
    let fig = Ladder {
        points,
        notes: hollow_notes(points.iter().map(LadderPoint::stationarity)),
    };
    report
        .files
        .extend(save(&fig, out, "erosion_vs_resolution")?);
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn results(spec: serde_json::Value) -> CampaignResults {
        let mut r: CampaignResults = serde_json::from_value(serde_json::json!({
            "partial": false, "slope_window": 20, "cells": []
        }))
        .unwrap();
        r.spec = Some(spec);
        r
    }

    #[test]
    fn a_file_without_a_spacing_is_refused_by_name() {
        let r = results(serde_json::json!({"grain": {"diameter_m": 2.5e-4}}));
        let e = ladder(&[("a.json".into(), r)]).unwrap_err().to_string();
        assert!(e.contains("a.json") && e.contains("spacing_m"), "{e}");
    }

    fn point(steady: Option<bool>, balanced: Option<bool>, partial: bool) -> LadderPoint {
        LadderPoint {
            file: "f.json".into(),
            per_dg: 32.0,
            spacing_m: 7.8125e-6,
            series: "45° hexagon".into(),
            erosion: 4e-3,
            sem: 2e-4,
            samples: 25,
            impacts: 420,
            steady,
            balanced,
            partial,
        }
    }

    #[test]
    fn only_a_finished_steady_cell_whose_balance_holds_is_a_stationary_rate() {
        use Stationarity::*;
        let of = |s, b, p| point(s, b, p).stationarity();
        assert_eq!(of(Some(true), Some(true), false), Rate);
        assert_eq!(of(Some(true), None, false), Rate);
        assert_eq!(of(Some(true), Some(false), false), Unbalanced);
        assert_eq!(of(Some(false), Some(true), false), Unsteady);
        assert_eq!(of(Some(true), Some(true), true), Running);
        assert_eq!(of(None, None, true), Running);
        assert_eq!(of(None, None, false), Unchecked);
        let table = ladder_table(&[point(Some(true), Some(false), false)]);
        assert!(table.contains("| steady, **unbalanced** |"), "{table}");
    }

    #[test]
    fn a_full_material_is_named_and_the_preset_is_not() {
        let preset = results(serde_json::json!({"material": "aisi304"}));
        assert_eq!(material_name(&preset).as_deref(), Some("aisi304"));
        let full = results(serde_json::json!({"material": [{"name": "aisi304-band"}]}));
        assert_eq!(material_name(&full).as_deref(), Some("aisi304-band"));
    }
}
