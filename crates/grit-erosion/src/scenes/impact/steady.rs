//! Whether a cell's erosion was measured at steady state (seed paper section 4, Figs. 8, 10b).
//!
//! The paper takes erosion as the slope of the mass-loss curve once it is "rather steady and
//! linear", after the incubation period. A campaign that stops too early still yields a
//! last-20 slope, but one that mixes incubation with erosion, or one taken on a curve whose
//! rate still changes. This module checks the cell's mean series (Fig. 10b) against three
//! conditions, all of which must hold:
//!
//! 1. the least-squares slope over the last [`STEADY_POINTS`] impacts (the erosion window)
//!    agrees with the slope over the [`STEADY_POINTS`] before them, that one with the slope
//!    over the [`STEADY_POINTS`] before it, and the last with that first one, each pair within
//!    [`STEADY_SIGMAS`] combined standard errors ([`STEADY_WINDOWS`] windows);
//! 2. at least [`STEADY_INCUBATED_PERCENT`] % of the samples lost their first mass at or
//!    before the first impact of the last 2 × [`STEADY_POINTS`] impacts, so the last two slopes are past
//!    incubation;
//! 3. the last slope is positive.
//!
//! Three windows, not two: after incubation the rate can peak for 40 impacts and then fall by
//! half (the 16-per-Dg ladder rung, `docs/results.md`), and two windows of such a peak agree
//! with each other. The window before them, on the rise, does not. The ends are compared too
//! because a rate that rises by a little each window passes every adjacent pair (the seed's
//! campaign at 45°, 41–100 impacts: 2.97, 3.33, 3.70 mg/g, 1.3 combined standard errors a
//! step and 2.9 end to end). With three equally spaced windows the end-to-end difference is
//! twice the least-squares trend of the window slopes, so this is the slope-of-slopes test at
//! twice an adjacent pair's power.
//!
//! Each cell also reports the smallest change of rate the test can see,
//! [`SteadyState::detectable_change_rel`]: [`STEADY_SIGMAS`] combined standard errors over the
//! last slope. Comparing two 20-impact slopes instead of two 10-impact ones (the rule before
//! 2026-11-26) halves the variance of each slope; on the committed 16-per-Dg campaigns it
//! turns changes of 25–60 % of the rate visible that the 10-against-10 rule could not see
//! (`docs/erosion.md`, *Steady state*).
//!
//! The standard error of a slope assumes that the per-impact losses are independent, which
//! they are: each impact is its own random draw of aim and orientation. The cumulative series
//! is their running sum, so its residuals about a line are correlated, and the textbook
//! `SSR/(n − 2)/Sxx` understates the error several-fold; see [`slope_fit`] and
//! `docs/erosion.md` (*Steady state*).

use serde::{Deserialize, Serialize};

use super::aggregate::{CellResult, MeanPoint, SeriesPoint, SLOPE_WINDOW};
use crate::stats::{slope_fit, SlopeFit};

/// Impacts in each of the two slopes compared: the paper's last-20 window (section 4) and the
/// 20 impacts before it.
pub const STEADY_POINTS: usize = SLOPE_WINDOW;

/// Windows of [`STEADY_POINTS`] impacts whose adjacent slopes must agree.
pub const STEADY_WINDOWS: usize = 3;

/// Largest difference of two adjacent slopes, in combined standard errors
/// `√(se_last² + se_prev²)`, that still counts as agreement (about a 95 % two-sided test).
pub const STEADY_SIGMAS: f64 = 2.0;

/// Smallest share of samples, in percent, that must have lost mass by the first impact of
/// the last two compared slopes: one sample in five may still be incubating (see
/// `docs/erosion.md`).
pub const STEADY_INCUBATED_PERCENT: usize = 80;

/// Impact number of the first mass loss, over the samples that lost any (1-based).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Incubation {
    /// Earliest first loss.
    pub min: usize,
    /// Mean first loss.
    pub mean: f64,
    /// Latest first loss.
    pub max: usize,
}

/// A cell's steady-state check (seed paper section 4: erosion from the "rather steady and
/// linear" part of the mass-loss curve, after incubation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SteadyState {
    /// Whether all three conditions of the module documentation hold.
    pub steady: bool,
    /// Why, in words: every broken condition, or the evidence that none is.
    pub reason: String,
    /// First impact with mass loss, over samples that lost any; `null` when none did.
    pub incubation_impacts: Option<Incubation>,
    /// Reported samples that lost no mass at all: not incubated, left out of
    /// `incubation_impacts` and counted against condition 2.
    pub samples_without_loss: usize,
    /// Each reported sample's first lossy impact (1-based; `null` for none), in sample order,
    /// so the check can be made again from the file ([`reassess`]); empty in older files.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub first_loss_impacts: Vec<Option<usize>>,
    /// First impact of the last two compared slopes (1-based), where incubation is judged; `null`
    /// when the series is shorter than the three windows.
    pub window_first_impact: Option<usize>,
    /// Reported samples whose first loss came at or before `window_first_impact`.
    pub samples_incubated_by_window: usize,
    /// Impacts in each compared slope; files written before this field compared 10.
    #[serde(default = "older_points")]
    pub points: usize,
    /// Slope of the mean series over its last `points` impacts; `null` below 2 × `points`.
    #[serde(alias = "slope_last10")]
    pub slope_last: Option<SlopeFit>,
    /// Slope of the mean series over the `points` impacts before those.
    #[serde(alias = "slope_prev10")]
    pub slope_prev: Option<SlopeFit>,
    /// Slope of the mean series over the `points` impacts before `slope_prev`'s; `null` below
    /// [`STEADY_WINDOWS`] × `points` and in files checked under the two-window rule.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slope_before: Option<SlopeFit>,
    /// Smallest relative change of rate the check would flag: [`STEADY_SIGMAS`] combined
    /// standard errors over |last slope|; `null` where there are no slopes or the last is 0.
    #[serde(default)]
    pub detectable_change_rel: Option<f64>,
}

/// Impacts per compared slope in files written before `points` was recorded.
fn older_points() -> usize {
    10
}

/// The slopes of the steady-state check from a mean series (Fig. 10b), latest first: over the
/// last [`STEADY_POINTS`] impacts, the [`STEADY_POINTS`] before, and the [`STEADY_POINTS`]
/// before those; a window the series is too short for is `None`.
pub fn mean_series_slopes(mean: &[MeanPoint]) -> [Option<SlopeFit>; STEADY_WINDOWS] {
    let n = mean.len();
    let fit = |w: usize| {
        let end = n.checked_sub(w * STEADY_POINTS)?;
        let part = &mean[end.checked_sub(STEADY_POINTS)?..end];
        let x: Vec<f64> = part.iter().map(|p| p.grain_mass_kg).collect();
        let y: Vec<f64> = part.iter().map(|p| p.mass_loss_kg).collect();
        slope_fit(&x, &y)
    };
    std::array::from_fn(fit)
}

/// Whether slopes `a` (later) and `b` agree within [`STEADY_SIGMAS`] combined standard
/// errors, and the difference in words; the jet's stage-3 check uses it too.
pub(crate) fn compare(a: SlopeFit, b: SlopeFit) -> (bool, String) {
    let diff = (a.value - b.value).abs();
    let combined = a.sem.hypot(b.sem);
    // Rounding alone must not split two slopes of an exactly linear series.
    let rounding = 1e-9 * a.value.abs().max(b.value.abs());
    let z = if combined > 0.0 {
        format!("{:.1} combined standard errors", diff / combined)
    } else if diff <= rounding {
        "no difference".to_string()
    } else {
        "a difference with no scatter".to_string()
    };
    (diff <= STEADY_SIGMAS * combined + rounding, z)
}

/// Impact number (1-based) of a series' first mass loss; `None` when it lost nothing.
pub fn first_loss_impact(series: &[SeriesPoint]) -> Option<usize> {
    series
        .iter()
        .position(|p| p.mass_loss_kg > 0.0)
        .map(|k| k + 1)
}

/// Erosion in mg of surface per g of grains, the unit of `docs/erosion.md`.
fn mg_per_g(slope: f64) -> f64 {
    slope * 1e3
}

fn show(fit: SlopeFit) -> String {
    format!("{:.2} ± {:.2} mg/g", mg_per_g(fit.value), mg_per_g(fit.sem))
}

/// The steady-state check of one cell from its samples' cumulative series and their mean
/// series (seed paper section 4, Figs. 8 and 10b); see the module documentation.
pub fn assess(samples: &[Vec<SeriesPoint>], mean: &[MeanPoint]) -> SteadyState {
    let first: Vec<Option<usize>> = samples.iter().map(|s| first_loss_impact(s)).collect();
    assess_first_losses(&first, mean)
}

/// The steady-state check made again from a results file's cell under this build's rule.
#[derive(Debug, Clone, PartialEq)]
pub struct Reassessed {
    /// The check; for an older file whose incubation is unknown, made as if every sample had
    /// incubated, so that only the slope conditions can fail.
    pub state: SteadyState,
    /// Whether the file told whether 80 % of the samples had lost mass by the window's start.
    pub incubation_known: bool,
}

impl Reassessed {
    /// `Some(steady)` when the file settles it, `None` when only the incubation is unknown.
    pub fn steady(&self) -> Option<bool> {
        (self.incubation_known || !self.state.steady).then_some(self.state.steady)
    }
}

/// The steady-state check again from a results file's cell, under this build's rule: exact
/// where the file stored each sample's first loss; older files keep only the range of first
/// losses, which may not tell whether the samples had incubated by the start of this rule's
/// longer window. `None` for a cell without a stored check.
pub fn reassess(cell: &CellResult) -> Option<Reassessed> {
    let old = cell.steady_state.as_ref()?;
    let reported = cell.samples_reported;
    if old.first_loss_impacts.len() == reported && reported > 0 {
        return Some(Reassessed {
            state: assess_first_losses(&old.first_loss_impacts, &cell.mean_series),
            incubation_known: true,
        });
    }
    let start = (cell.mean_series.len() + 1).saturating_sub(2 * STEADY_POINTS);
    let lossy = reported - old.samples_without_loss.min(reported);
    // Every lossy sample had lost by `max`; those that lost by the old (later) window start
    // bound those that lost by the new one.
    let (first, known): (Vec<Option<usize>>, bool) = match old.incubation_impacts {
        Some(i) if i.max <= start => (
            (0..reported)
                .map(|k| (k < lossy).then_some(i.max))
                .collect(),
            true,
        ),
        _ if old.samples_incubated_by_window * 100 < STEADY_INCUBATED_PERCENT * reported => {
            (vec![None; reported], true)
        }
        _ => (vec![Some(1); reported], false),
    };
    let mut state = assess_first_losses(&first, &cell.mean_series);
    state.incubation_impacts = old.incubation_impacts;
    state.samples_without_loss = old.samples_without_loss;
    state.first_loss_impacts.clear();
    if !known {
        state.reason = format!(
            "incubation by impact {start} not stored in this file (first losses {}–{}); {}",
            old.incubation_impacts.map_or(0, |i| i.min),
            old.incubation_impacts.map_or(0, |i| i.max),
            state.reason
        );
    }
    Some(Reassessed {
        state,
        incubation_known: known,
    })
}

/// [`assess`] from each sample's first lossy impact (1-based, `None` for none).
fn assess_first_losses(first: &[Option<usize>], mean: &[MeanPoint]) -> SteadyState {
    let lost: Vec<usize> = first.iter().flatten().copied().collect();
    let incubation_impacts = match (lost.iter().min(), lost.iter().max()) {
        (Some(&min), Some(&max)) => Some(Incubation {
            min,
            mean: lost.iter().sum::<usize>() as f64 / lost.len() as f64,
            max,
        }),
        _ => None,
    };
    let samples_without_loss = first.len() - lost.len();
    let n = mean.len();
    // Incubation is judged at the start of the last two windows; all three must fit.
    let window = 2 * STEADY_POINTS;
    let needed = STEADY_WINDOWS * STEADY_POINTS;
    let window_first_impact = (n >= needed).then(|| n - window + 1);
    let samples_incubated_by_window =
        window_first_impact.map_or(0, |start| lost.iter().filter(|&&k| k <= start).count());
    let [slope_last, slope_prev, slope_before] = mean_series_slopes(mean);
    let detectable_change_rel = match (slope_last, slope_prev) {
        (Some(l), Some(p)) if l.value != 0.0 => {
            Some(STEADY_SIGMAS * l.sem.hypot(p.sem) / l.value.abs())
        }
        _ => None,
    };

    let mut broken = Vec::new();
    let mut held = Vec::new();
    if first.is_empty() {
        broken.push("no samples reported".to_string());
    } else if n < needed {
        broken.push(format!(
            "only {n} impacts; {STEADY_WINDOWS} {STEADY_POINTS}-impact slopes need {needed}"
        ));
    }
    if let Some(start) = window_first_impact {
        let counts = mean[n - needed..].iter().map(|p| p.samples);
        let (lo, hi) = (counts.clone().min(), counts.max());
        if lo != hi {
            broken.push(format!(
                "the last {needed} points average {} to {} samples: some are still running",
                lo.unwrap_or(0),
                hi.unwrap_or(0)
            ));
        }
        let share = format!(
            "{samples_incubated_by_window} of {} samples lost mass by impact {start}, where \
             the last two compared {STEADY_POINTS}-impact slopes start",
            first.len()
        );
        if samples_incubated_by_window * 100 >= STEADY_INCUBATED_PERCENT * first.len() {
            held.push(share);
        } else {
            broken.push(format!(
                "only {share} ({STEADY_INCUBATED_PERCENT} % needed)"
            ));
        }
    }
    match (slope_last, slope_prev, slope_before) {
        (Some(last), Some(prev), Some(before)) => {
            let sees = detectable_change_rel.map_or(String::new(), |d| {
                format!(" (the check sees changes of {:.0} % and more)", 100.0 * d)
            });
            let (agree, z) = compare(last, prev);
            let text = format!(
                "last-{STEADY_POINTS} slope {} against the previous {STEADY_POINTS}'s {}: {z}{sees}",
                show(last),
                show(prev)
            );
            if agree {
                held.push(text);
            } else {
                broken.push(format!("{text} (at most {STEADY_SIGMAS} allowed)"));
            }
            let (agree, z) = compare(prev, before);
            let text = format!(
                "that previous slope against the {STEADY_POINTS} before's {}: {z}",
                show(before)
            );
            if agree {
                held.push(text);
            } else {
                broken.push(format!("{text} (at most {STEADY_SIGMAS} allowed)"));
            }
            let (agree, z) = compare(last, before);
            let text = format!("the last slope against that first one: {z}");
            if agree {
                held.push(text);
            } else {
                broken.push(format!(
                    "{text}, a trend across the three (at most {STEADY_SIGMAS} allowed)"
                ));
            }
            if last.value <= 0.0 {
                broken.push(format!("no mass lost in the last {STEADY_POINTS} impacts"));
            }
        }
        _ if n >= needed => broken.push("the slopes could not be fitted".to_string()),
        _ => {}
    }
    let steady = broken.is_empty();
    SteadyState {
        steady,
        reason: if steady { held } else { broken }.join("; "),
        incubation_impacts,
        samples_without_loss,
        first_loss_impacts: first.to_vec(),
        window_first_impact,
        samples_incubated_by_window,
        points: STEADY_POINTS,
        slope_last,
        slope_prev,
        slope_before,
        detectable_change_rel,
    }
}
