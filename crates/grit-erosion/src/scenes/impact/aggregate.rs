//! Aggregation of per-impact mass losses into erosion (seed paper section 4, Figs. 8–10).
//!
//! A sample's erosion is the least-squares slope of its cumulative mass loss against the
//! cumulative mass of the grains that hit it, over its last `SLOPE_WINDOW` impacts (Fig. 8;
//! "only the last 20 data points of the mass loss evolution are considered"). A cell's
//! erosion is the mean over its samples, with the sample standard deviation and standard
//! error of the mean (Fig. 10a), beside the mean mass-loss series (Fig. 10b).
//!
//! In 2D the engine's masses are per metre of depth (kg/m); erosion is a ratio of masses, so
//! only consistency matters and the fields keep the `_kg` name.
//!
//! Partial data (a campaign still running) aggregates the same way and is marked
//! `partial: true`; every sum runs in sample-index order so results are reproducible.
//!
//! Each cell also carries a steady-state check of its mean series ([`crate::impact::steady`]), and
//! the campaign says whether every cell passed it.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::balance::{self, DamageBalance};
use super::steady::{self, SteadyState};
use crate::stats::{invalid, least_squares_slope, stats, AggregateError};

/// Number of final impacts whose slope is a sample's erosion (seed paper section 4).
pub const SLOPE_WINDOW: usize = 20;

/// The outcome of one impact (seed paper section 4: mass of removed particles).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Impact {
    /// Mass of the grain that hit the surface, kg (per metre of depth in 2D).
    pub grain_mass_kg: f64,
    /// Surface mass removed by this impact (failed particles), kg (per metre in 2D).
    pub mass_loss_kg: f64,
    /// Damage the impact added to the surface, Σ m ΔD (eq. 19), kg (per metre in 2D);
    /// absent where it was not recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damage_added_kg: Option<f64>,
}

/// One point of a cumulative series: after impact k, the totals so far (Fig. 8).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SeriesPoint {
    /// Cumulative mass of grains that have hit the surface, kg.
    pub grain_mass_kg: f64,
    /// Cumulative surface mass loss, kg.
    pub mass_loss_kg: f64,
}

/// The impacts one sample has reported, in order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleInput {
    /// Index of the sample within its cell (0-based).
    pub sample: u32,
    /// Impacts in the order they hit the surface.
    pub impacts: Vec<Impact>,
}

/// Everything stored for one cell: its parameters, its plan and the samples reported so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CellInput {
    /// Impact angle, degrees from the surface.
    pub angle_deg: f64,
    /// Grain shape name.
    pub shape: String,
    /// Other swept values of this cell, by name with unit (e.g. `velocity_m_s`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub swept: BTreeMap<String, f64>,
    /// Number of samples the campaign plans for this cell.
    pub planned_samples: usize,
    /// Number of impacts each sample of this cell is planned to receive.
    pub planned_impacts: usize,
    /// Samples with at least one reported impact; absent samples have none yet.
    pub samples: Vec<SampleInput>,
}

/// One sample's erosion, or why it has none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleResult {
    /// Index of the sample within its cell.
    pub sample: u32,
    /// Impacts reported.
    pub impacts: usize,
    /// Least-squares slope over the last `slope_window` impacts; `null` when too few.
    pub erosion: Option<f64>,
    /// Why the sample contributes no slope, when it does not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// One point of a cell's mean mass-loss series (Fig. 10b), over the samples that reached it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeanPoint {
    /// Impact number, 1-based.
    pub impact: usize,
    /// Mean cumulative grain mass, kg.
    pub grain_mass_kg: f64,
    /// Mean cumulative mass loss, kg.
    pub mass_loss_kg: f64,
    /// Sample standard deviation (n − 1) of the cumulative mass loss, kg; `null` below 2.
    pub mass_loss_std_kg: Option<f64>,
    /// Number of samples that reached this impact.
    pub samples: usize,
}

/// Cell erosion from the first k samples with a slope (Fig. 10a).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConvergencePoint {
    /// Number of samples k.
    pub samples: usize,
    /// Mean erosion of the first k samples.
    pub erosion_mean: f64,
    /// Sample standard deviation (n − 1) of the first k; `null` for k = 1.
    pub erosion_std: Option<f64>,
}

/// Erosion of one cell (seed paper Figs. 10–12): mean, spread, series and convergence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CellResult {
    /// Impact angle, degrees from the surface.
    pub angle_deg: f64,
    /// Grain shape name.
    pub shape: String,
    /// Other swept values of this cell.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub swept: BTreeMap<String, f64>,
    /// Whether samples or impacts are missing against the plan.
    pub partial: bool,
    /// Number of samples whose slope enters the erosion.
    pub samples: usize,
    /// Number of samples planned.
    pub samples_planned: usize,
    /// Number of samples with at least one impact.
    pub samples_reported: usize,
    /// Number of reported samples with too few impacts for a slope.
    pub samples_without_slope: usize,
    /// Impacts planned per sample.
    pub impacts_planned: usize,
    /// Mean erosion over samples (dimensionless); `null` when no sample has a slope.
    pub erosion_mean: Option<f64>,
    /// Sample standard deviation (n − 1) of sample erosions; `null` below 2 samples.
    pub erosion_std: Option<f64>,
    /// Standard error of the mean, std/√n; `null` below 2 samples.
    pub erosion_sem: Option<f64>,
    /// Standard error over |mean| reached, for a cell whose samples grow until it is small
    /// (`samples.target_sem_rel` of the campaign spec); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub erosion_sem_rel: Option<f64>,
    /// Each reported sample's erosion, by sample index.
    pub per_sample: Vec<SampleResult>,
    /// Mean cumulative mass loss against grain mass (Fig. 10b).
    pub mean_series: Vec<MeanPoint>,
    /// Running erosion mean and std with the number of samples (Fig. 10a).
    pub convergence: Vec<ConvergencePoint>,
    /// Whether the last-20 window is past incubation and linear (section 4); `null` in
    /// results files written before the check existed.
    #[serde(default)]
    pub steady_state: Option<SteadyState>,
    /// Loss against damage added over the last window ([`crate::impact::balance`]); absent
    /// where the records carry no damage.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damage_balance: Option<DamageBalance>,
    /// The same over each sample's last [`balance::LONG_BALANCE_POINTS`] impacts
    /// ([`balance::assess_long`]): what a balanced cell's loss is without the selection of the
    /// window that stopped it; absent below that many impacts or where there is no damage.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub long_balance: Option<DamageBalance>,
}

impl CellResult {
    /// Whether `other` is the same cell (angle, shape and other swept values), from another
    /// results file.
    pub fn same_cell(&self, other: &CellResult) -> bool {
        self.angle_deg == other.angle_deg && self.shape == other.shape && self.swept == other.swept
    }

    /// Whether the cell's erosion is a stationary rate by the current rules, and if not, why
    /// (docs/erosion.md, *The damage balance*).
    pub fn stationarity(&self) -> Stationarity {
        Stationarity::of(
            self.steady_state.as_ref().map(|s| s.steady),
            self.damage_balance.as_ref().map(DamageBalance::holds),
        )
    }

    /// Whether the cell's erosion is a stationary rate ([`Stationarity::is_rate`]); `None`
    /// where steadiness was not checked.
    pub fn stationary(&self) -> Option<bool> {
        self.stationarity().is_rate()
    }

    /// The cell's name in messages: angle, shape and any other swept values.
    pub fn label(&self) -> String {
        let mut label = format!("{}° {}", self.angle_deg, self.shape);
        for (name, value) in &self.swept {
            label.push_str(&format!(" {name}={value}"));
        }
        label
    }
}

/// Whether a cell's erosion is a stationary rate (docs/erosion.md, *The damage balance*): at
/// steady state and, where the records carry damage, with its loss paying for the damage its
/// impacts add; otherwise the first rule it fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stationarity {
    /// Steady and, where there is a balance, balanced: a stationary rate.
    Rate,
    /// Samples or impacts still missing against the plan (a campaign still running).
    Running,
    /// The steady-state check fails.
    Unsteady,
    /// Steady, but the last window's loss does not pay for the damage added.
    Unbalanced,
    /// Written before the steady-state check existed: nothing to judge it by.
    Unchecked,
}

impl Stationarity {
    /// The verdict from the steady check and the damage balance, each `None` where the file has
    /// none; a missing balance does not count against the cell.
    pub fn of(steady: Option<bool>, balanced: Option<bool>) -> Self {
        match (steady, balanced) {
            (None, _) => Self::Unchecked,
            (Some(false), _) => Self::Unsteady,
            (Some(true), Some(false)) => Self::Unbalanced,
            (Some(true), _) => Self::Rate,
        }
    }

    /// `Running` in place of any verdict for a cell that is still missing samples or impacts.
    pub fn unless_partial(self, partial: bool) -> Self {
        if partial {
            Self::Running
        } else {
            self
        }
    }

    /// Whether this is a stationary rate; `None` where it was never checked.
    pub fn is_rate(self) -> Option<bool> {
        match self {
            Self::Rate => Some(true),
            Self::Unchecked => None,
            _ => Some(false),
        }
    }
}

/// Results of a campaign, complete or not (`GET /api/v1/campaigns/{id}/results`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignResults {
    /// Whether any cell is partial.
    pub partial: bool,
    /// Number of final impacts each sample's slope is taken over.
    pub slope_window: usize,
    /// One result per cell, in input order.
    pub cells: Vec<CellResult>,
    /// Whether every cell passed the steady-state check; `null` when some cell was not
    /// checked (results files written before the check existed).
    #[serde(default)]
    pub steady: Option<bool>,
    /// The campaign spec as run, defaults filled in, when the caller supplied it
    /// ([`CampaignResults::with_spec`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spec: Option<serde_json::Value>,
    /// Version of grit that aggregated these results; `null` in older files.
    #[serde(default)]
    pub grit_version: Option<String>,
    /// The numerics every cell's impacts ran with, as stored with the cells when the campaign
    /// was created (the spec does not set them: they are the defaults of that day's grit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub numerics: Option<crate::impact::Numerics>,
    /// The engine fingerprint the farm pinned the campaign to, which computed every unit;
    /// absent in files from before pins and outside a farm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub engine: Option<String>,
    /// The commit of the grit that created the campaign, beside `engine`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub commit: Option<String>,
}

impl CampaignResults {
    /// These results with the campaign spec that produced them, for a reader to rerun it.
    pub fn with_spec(mut self, spec: serde_json::Value) -> Self {
        self.spec = Some(spec);
        self
    }

    /// Whether every cell is steady: `None` when some cell carries no check.
    pub fn cells_steady(&self) -> Option<bool> {
        self.cells
            .iter()
            .map(|c| c.steady_state.as_ref().map(|s| s.steady))
            .try_fold(true, |all, s| s.map(|s| all && s))
    }

    /// One line per cell whose last window's loss does not pay for the damage its impacts
    /// added ([`crate::impact::balance`]): its rate is steady, perhaps, but not yet stationary.
    pub fn unbalanced_notes(&self) -> Vec<String> {
        self.cells
            .iter()
            .filter_map(|c| {
                let b = c.damage_balance.filter(|b| !b.holds())?;
                let what = if b.loss_rate < b.damage_rate {
                    "still stores damage; its stationary rate lies between the two"
                } else {
                    "loses more than its impacts damage"
                };
                Some(format!(
                    "note: cell {}: {}: the surface {what} (docs/erosion.md, The damage balance)",
                    c.label(),
                    b.describe()
                ))
            })
            .collect()
    }

    /// One line per cell that is not at steady state, or was not checked, saying why
    /// (seed paper section 4: erosion from the steady, linear part of the curve).
    pub fn unsteady_warnings(&self) -> Vec<String> {
        self.cells
            .iter()
            .filter_map(|c| match &c.steady_state {
                Some(s) if s.steady => None,
                Some(s) => Some(format!(
                    "warning: cell {} is not at steady state: {}",
                    c.label(),
                    s.reason
                )),
                None => Some(format!(
                    "warning: cell {}: steady state not checked (results written before the check)",
                    c.label()
                )),
            })
            .collect()
    }
}

/// Cumulative mass loss against cumulative grain mass after each impact (Fig. 8).
pub fn cumulative_series(impacts: &[Impact]) -> Vec<SeriesPoint> {
    let (mut grain, mut loss) = (0.0, 0.0);
    impacts
        .iter()
        .map(|i| {
            grain += i.grain_mass_kg;
            loss += i.mass_loss_kg;
            SeriesPoint {
                grain_mass_kg: grain,
                mass_loss_kg: loss,
            }
        })
        .collect()
}

/// A sample's erosion: slope of its series over the last `window` points (Fig. 8);
/// `None` when the series is shorter than the window.
pub fn sample_erosion(series: &[SeriesPoint], window: usize) -> Option<f64> {
    if series.len() < window {
        return None;
    }
    let tail = &series[series.len() - window..];
    let x: Vec<f64> = tail.iter().map(|p| p.grain_mass_kg).collect();
    let y: Vec<f64> = tail.iter().map(|p| p.mass_loss_kg).collect();
    least_squares_slope(&x, &y)
}

/// Running mean and std of the first k values for k = 1..n (Fig. 10a).
pub fn convergence(values: &[f64]) -> Vec<ConvergencePoint> {
    (1..=values.len())
        .filter_map(|k| {
            stats(&values[..k]).map(|s| ConvergencePoint {
                samples: k,
                erosion_mean: s.mean,
                erosion_std: s.std,
            })
        })
        .collect()
}

fn check_sample(s: &SampleInput, planned_impacts: usize) -> Result<(), AggregateError> {
    let field = format!("samples[{}]", s.sample);
    if s.impacts.len() > planned_impacts {
        return Err(invalid(
            format!("{field}.impacts"),
            format!(
                "{} impacts reported, more than the {planned_impacts} planned",
                s.impacts.len()
            ),
        ));
    }
    for (j, i) in s.impacts.iter().enumerate() {
        if !(i.grain_mass_kg.is_finite() && i.grain_mass_kg > 0.0) {
            return Err(invalid(
                format!("{field}.impacts[{j}].grain_mass_kg"),
                format!("must be finite and > 0, got {}", i.grain_mass_kg),
            ));
        }
        if !(i.mass_loss_kg.is_finite() && i.mass_loss_kg >= 0.0) {
            return Err(invalid(
                format!("{field}.impacts[{j}].mass_loss_kg"),
                format!("must be finite and ≥ 0, got {}", i.mass_loss_kg),
            ));
        }
    }
    Ok(())
}

/// Erosion of one cell: per-sample slopes over the last `window` impacts, their mean, std
/// and standard error, the mean series and the convergence with sample count (Figs. 8–10).
pub fn aggregate_cell(cell: &CellInput, window: usize) -> Result<CellResult, AggregateError> {
    if window < 2 {
        return Err(invalid(
            "slope_window".into(),
            format!("must be at least 2, got {window}"),
        ));
    }
    let mut samples: Vec<&SampleInput> = cell.samples.iter().collect();
    samples.sort_by_key(|s| s.sample);
    for pair in samples.windows(2) {
        if pair[0].sample == pair[1].sample {
            return Err(invalid(
                format!("samples[{}]", pair[0].sample),
                "reported twice",
            ));
        }
    }
    if let Some(s) = samples
        .iter()
        .find(|s| s.sample as usize >= cell.planned_samples)
    {
        return Err(invalid(
            format!("samples[{}]", s.sample),
            format!("beyond the {} planned samples", cell.planned_samples),
        ));
    }
    for s in &samples {
        check_sample(s, cell.planned_impacts)?;
    }
    // A sample leased but not yet past its first impact carries no information.
    samples.retain(|s| !s.impacts.is_empty());

    let series: Vec<Vec<SeriesPoint>> = samples
        .iter()
        .map(|s| cumulative_series(&s.impacts))
        .collect();
    let mut per_sample = Vec::with_capacity(samples.len());
    let mut slopes = Vec::with_capacity(samples.len());
    for (s, ser) in samples.iter().zip(&series) {
        let erosion = sample_erosion(ser, window);
        let note = match erosion {
            Some(e) => {
                slopes.push(e);
                None
            }
            None => Some(format!(
                "fewer than {window} impacts ({} of {} planned); contributes no slope",
                ser.len(),
                cell.planned_impacts
            )),
        };
        per_sample.push(SampleResult {
            sample: s.sample,
            impacts: ser.len(),
            erosion,
            note,
        });
    }

    let longest = series.iter().map(Vec::len).max().unwrap_or(0);
    let mean_series: Vec<MeanPoint> = (0..longest)
        .map(|k| {
            let reached: Vec<&SeriesPoint> = series.iter().filter_map(|s| s.get(k)).collect();
            let n = reached.len() as f64;
            let losses: Vec<f64> = reached.iter().map(|p| p.mass_loss_kg).collect();
            let loss = stats(&losses).expect("at least one sample reaches every k < longest");
            MeanPoint {
                impact: k + 1,
                grain_mass_kg: reached.iter().map(|p| p.grain_mass_kg).sum::<f64>() / n,
                mass_loss_kg: loss.mean,
                mass_loss_std_kg: loss.std,
                samples: reached.len(),
            }
        })
        .collect();

    let damage_balance = balance::assess(&samples);
    let long_balance = balance::assess_long(&samples);
    let steady_state = steady::assess(&series, &mean_series);
    let summary = stats(&slopes);
    let partial = samples.len() < cell.planned_samples
        || series.iter().any(|s| s.len() < cell.planned_impacts);
    Ok(CellResult {
        angle_deg: cell.angle_deg,
        shape: cell.shape.clone(),
        swept: cell.swept.clone(),
        partial,
        samples: slopes.len(),
        samples_planned: cell.planned_samples,
        samples_reported: samples.len(),
        samples_without_slope: samples.len() - slopes.len(),
        impacts_planned: cell.planned_impacts,
        erosion_mean: summary.map(|s| s.mean),
        erosion_std: summary.and_then(|s| s.std),
        erosion_sem: summary.and_then(|s| s.sem),
        erosion_sem_rel: None,
        per_sample,
        mean_series,
        convergence: convergence(&slopes),
        steady_state: Some(steady_state),
        damage_balance,
        long_balance,
    })
}

/// Results of every cell of a campaign, `partial` when any cell is.
pub fn aggregate_campaign(
    cells: &[CellInput],
    window: usize,
) -> Result<CampaignResults, AggregateError> {
    let cells = cells
        .iter()
        .enumerate()
        .map(|(i, c)| aggregate_cell(c, window).map_err(|e| e.within(&format!("cells[{i}]"))))
        .collect::<Result<Vec<_>, _>>()?;
    let mut results = CampaignResults {
        partial: cells.iter().any(|c| c.partial),
        slope_window: window,
        cells,
        steady: None,
        spec: None,
        grit_version: Some(env!("CARGO_PKG_VERSION").to_string()),
        numerics: None,
        engine: None,
        commit: None,
    };
    results.steady = results.cells_steady();
    Ok(results)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A sample whose loss per impact is `rate` × grain mass after `incubation` impacts.
    fn sample(index: u32, n: usize, incubation: usize, rate: f64) -> SampleInput {
        let impacts = (0..n)
            .map(|k| Impact {
                grain_mass_kg: 1e-4,
                mass_loss_kg: if k < incubation { 0.0 } else { rate * 1e-4 },
                damage_added_kg: None,
            })
            .collect();
        SampleInput {
            sample: index,
            impacts,
        }
    }

    fn cell(
        planned_samples: usize,
        planned_impacts: usize,
        samples: Vec<SampleInput>,
    ) -> CellInput {
        CellInput {
            angle_deg: 45.0,
            shape: "hexagon".into(),
            swept: BTreeMap::new(),
            planned_samples,
            planned_impacts,
            samples,
        }
    }

    #[test]
    fn steady_rate_after_incubation_is_the_erosion() {
        let r = aggregate_cell(&cell(1, 60, vec![sample(0, 60, 30, 2e-3)]), SLOPE_WINDOW).unwrap();
        let e = r.erosion_mean.unwrap();
        assert!((e - 2e-3).abs() < 1e-12 * 2e-3, "{e}");
        assert!(!r.partial);
        assert_eq!(r.samples, 1);
        assert_eq!((r.erosion_std, r.erosion_sem), (None, None));
        assert_eq!(r.mean_series.len(), 60);
        assert_eq!(r.mean_series[0].mass_loss_kg, 0.0);
    }

    #[test]
    fn cell_statistics_use_n_minus_1() {
        let samples = vec![
            sample(0, 30, 0, 1.0e-3),
            sample(1, 30, 0, 2.0e-3),
            sample(2, 30, 0, 3.0e-3),
        ];
        let r = aggregate_cell(&cell(3, 30, samples), SLOPE_WINDOW).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12 * b.abs();
        assert!(close(r.erosion_mean.unwrap(), 2.0e-3));
        assert!(close(r.erosion_std.unwrap(), 1.0e-3));
        assert!(close(r.erosion_sem.unwrap(), 1.0e-3 / 3f64.sqrt()));
        assert_eq!(r.convergence.len(), 3);
        assert!(close(r.convergence[0].erosion_mean, 1.0e-3));
        assert_eq!(r.convergence[0].erosion_std, None);
        assert!(close(r.convergence[1].erosion_mean, 1.5e-3));
        let last = r.convergence[2];
        assert_eq!(
            (last.erosion_mean, last.erosion_std),
            (r.erosion_mean.unwrap(), r.erosion_std)
        );
    }

    #[test]
    fn partial_data_aggregates_and_is_marked() {
        // 3 of 5 samples reported; sample 4 has 12 of 60 impacts: too few for a slope.
        let samples = vec![
            sample(4, 12, 0, 5e-3),
            sample(0, 60, 10, 1e-3),
            sample(2, 45, 10, 3e-3),
        ];
        let r = aggregate_campaign(&[cell(5, 60, samples)], SLOPE_WINDOW).unwrap();
        assert!(r.partial);
        let c = &r.cells[0];
        assert!(c.partial);
        assert_eq!(
            (c.samples, c.samples_reported, c.samples_without_slope),
            (2, 3, 1)
        );
        let ids: Vec<u32> = c.per_sample.iter().map(|s| s.sample).collect();
        assert_eq!(ids, vec![0, 2, 4]);
        let short = &c.per_sample[2];
        assert_eq!(short.erosion, None);
        assert!(short
            .note
            .as_deref()
            .unwrap()
            .contains("fewer than 20 impacts (12 of 60"));
        assert!((c.erosion_mean.unwrap() - 2e-3).abs() < 1e-12);
        // The mean series runs to the longest sample, over fewer samples as they run out.
        assert_eq!(c.mean_series.len(), 60);
        assert_eq!(c.mean_series[11].samples, 3);
        assert_eq!(c.mean_series[12].samples, 2);
        assert_eq!(c.mean_series[59].samples, 1);
        assert_eq!(c.mean_series[59].mass_loss_std_kg, None);
    }

    #[test]
    fn fewer_impacts_only_is_partial_and_complete_is_not() {
        let short = cell(2, 60, vec![sample(0, 60, 0, 1e-3), sample(1, 59, 0, 1e-3)]);
        assert!(aggregate_cell(&short, SLOPE_WINDOW).unwrap().partial);
        let full = cell(2, 60, vec![sample(0, 60, 0, 1e-3), sample(1, 60, 0, 1e-3)]);
        let r = aggregate_campaign(&[full], SLOPE_WINDOW).unwrap();
        assert!(!r.partial && !r.cells[0].partial);
    }

    #[test]
    fn empty_cell_is_partial_with_null_erosion() {
        let r = aggregate_cell(&cell(25, 60, vec![]), SLOPE_WINDOW).unwrap();
        assert!(r.partial);
        assert_eq!((r.samples, r.erosion_mean), (0, None));
        assert!(r.mean_series.is_empty() && r.convergence.is_empty());
        let json = serde_json::to_value(&r).unwrap();
        assert!(json["erosion_mean"].is_null());
    }

    #[test]
    fn bad_data_names_the_field() {
        let mut bad = sample(3, 30, 0, 1e-3);
        bad.impacts[7].mass_loss_kg = f64::NAN;
        let err = aggregate_campaign(&[cell(5, 60, vec![]), cell(5, 60, vec![bad])], 20)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("cells[1].samples[3].impacts[7].mass_loss_kg:"),
            "{err}"
        );

        let mut bad = sample(0, 30, 0, 1e-3);
        bad.impacts[0].grain_mass_kg = 0.0;
        let err = aggregate_cell(&cell(1, 60, vec![bad]), 20)
            .unwrap_err()
            .to_string();
        assert!(err.contains("impacts[0].grain_mass_kg"), "{err}");

        let twice = cell(5, 60, vec![sample(1, 3, 0, 0.0), sample(1, 3, 0, 0.0)]);
        assert!(aggregate_cell(&twice, 20)
            .unwrap_err()
            .to_string()
            .contains("reported twice"));
        let beyond = cell(1, 60, vec![sample(1, 3, 0, 0.0)]);
        assert!(aggregate_cell(&beyond, 20).is_err());
        let over = cell(1, 10, vec![sample(0, 11, 0, 0.0)]);
        assert!(aggregate_cell(&over, 20).is_err());
        assert!(aggregate_cell(&cell(1, 10, vec![]), 1).is_err());
    }

    #[test]
    fn json_names_are_stable() {
        let r = aggregate_campaign(&[cell(1, 30, vec![sample(0, 30, 0, 1e-3)])], 20).unwrap();
        let json = serde_json::to_value(&r).unwrap();
        assert_eq!(json["partial"], false);
        let c = &json["cells"][0];
        for key in [
            "angle_deg",
            "shape",
            "samples",
            "erosion_mean",
            "erosion_std",
            "erosion_sem",
            "mean_series",
            "convergence",
            "per_sample",
        ] {
            assert!(c.get(key).is_some(), "{key}");
        }
        let back: CampaignResults = serde_json::from_value(json).unwrap();
        assert_eq!(back, r);
    }

    proptest! {
        #[test]
        fn slope_of_linear_plus_noise_is_recovered(
            rate in 1e-5..1e-1f64,
            offset in -1e-3..1e-3f64,
            masses in prop::collection::vec(0.5e-4..2e-4f64, 20..80),
            noise in prop::collection::vec(-1.0..1.0f64, 80),
            amplitude in 0.0..1e-6f64,
        ) {
            let mut x = Vec::new();
            let mut acc = 0.0;
            for m in &masses {
                acc += m;
                x.push(acc);
            }
            let y: Vec<f64> = x
                .iter()
                .zip(&noise)
                .map(|(xi, e)| rate * xi + offset + amplitude * e)
                .collect();
            let slope = least_squares_slope(&x, &y).unwrap();
            // Exact bound on the slope error from noise bounded by `amplitude`.
            let xm = x.iter().sum::<f64>() / x.len() as f64;
            let sxx: f64 = x.iter().map(|xi| (xi - xm).powi(2)).sum();
            let sabs: f64 = x.iter().map(|xi| (xi - xm).abs()).sum();
            let bound = amplitude * sabs / sxx + 1e-9 * rate;
            prop_assert!((slope - rate).abs() <= bound, "{slope} vs {rate}, bound {bound}");
        }

        #[test]
        fn sample_erosion_sees_only_the_last_window(
            early in prop::collection::vec(0.0..1e-6f64, 0..50),
            rate in 1e-4..1e-1f64,
        ) {
            let mut impacts: Vec<Impact> = early
                .iter()
                .map(|&l| Impact { grain_mass_kg: 1e-4, mass_loss_kg: l, damage_added_kg: None })
                .collect();
            impacts.extend((0..SLOPE_WINDOW).map(|_| Impact { grain_mass_kg: 1e-4, mass_loss_kg: rate * 1e-4, damage_added_kg: None }));
            let e = sample_erosion(&cumulative_series(&impacts), SLOPE_WINDOW).unwrap();
            prop_assert!((e - rate).abs() <= 1e-9 * rate);
        }

        #[test]
        fn aggregation_ignores_sample_order(
            rates in prop::collection::vec(1e-4..1e-2f64, 1..8),
            rotate in 0usize..8,
        ) {
            let samples: Vec<SampleInput> = rates
                .iter()
                .enumerate()
                .map(|(i, &r)| sample(i as u32, 25, 3, r))
                .collect();
            let mut shuffled = samples.clone();
            let k = rotate % shuffled.len();
            shuffled.rotate_left(k);
            let n = rates.len();
            let a = aggregate_cell(&cell(n, 25, samples), SLOPE_WINDOW).unwrap();
            let b = aggregate_cell(&cell(n, 25, shuffled), SLOPE_WINDOW).unwrap();
            prop_assert_eq!(a, b);
        }

        #[test]
        fn partial_iff_data_missing(
            lens in prop::collection::vec(1usize..=30, 0..6),
            planned_samples in 0usize..6,
        ) {
            let planned_samples = planned_samples.max(lens.len());
            let samples: Vec<SampleInput> =
                lens.iter().enumerate().map(|(i, &n)| sample(i as u32, n, 0, 1e-3)).collect();
            let r = aggregate_cell(&cell(planned_samples, 30, samples), SLOPE_WINDOW).unwrap();
            let missing = lens.len() < planned_samples || lens.iter().any(|&n| n < 30);
            prop_assert_eq!(r.partial, missing);
            prop_assert_eq!(r.samples, lens.iter().filter(|&&n| n >= SLOPE_WINDOW).count());
        }
    }
}
