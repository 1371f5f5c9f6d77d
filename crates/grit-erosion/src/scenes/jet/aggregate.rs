//! Results of a jet campaign per cell (`docs/jet-campaigns.md`): the crater depth Cd, width
//! Cw and mass loss at the run's end T as mean ± std (and standard error) over the samples;
//! the mean series over samples against time, and mean surface profiles at a few times (the
//! V → U development); and the stage-3 slope of mass loss against time with its steadiness
//! check.
//!
//! # The stage-3 window
//! With n points in a cell's mean series (slices 1..n), the window is the late half of the
//! run: the last ⌊n/2⌋ points, slices n − ⌊n/2⌋ + 1 … n. The stage-3 slope is the least-squares
//! slope of the mean mass loss against time over it, with the standard error of
//! [`crate::impact::steady::slope_fit`] (independent increments per slice). The cell is *steady* when
//! all of these hold, in the spirit of the impact scene's check ([`crate::impact::steady`]):
//!
//! 1. the window has at least [`STAGE3_MIN_POINTS`] points (n ≥ 12), so each half has 3;
//! 2. every point of the window averages the same number of samples (none still running);
//! 3. at least [`STEADY_INCUBATED_PERCENT`] % of the reported samples lost their first mass
//!    (the onset of loss) at or before the window's first slice;
//! 4. the slopes over the window's first ⌊w/2⌋ points and its last w − ⌊w/2⌋ points agree
//!    within [`STEADY_SIGMAS`] combined standard errors;
//! 5. the slope over the last part is positive.
//!
//! Every sum runs in sample order, so results are reproducible bit for bit.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::{JetParams, JetSlice, Layout};
use crate::campaign::Scene;
use crate::impact::steady::{compare, Incubation, STEADY_INCUBATED_PERCENT, STEADY_SIGMAS};
use crate::stats::{slope_fit, SlopeFit};
use crate::stats::{stats, AggregateError, Stats};
use grit_sph::cracks::RockDamage;

/// Fewest points of the stage-3 window: two halves of three, the fewest a slope with a
/// standard error needs.
pub const STAGE3_MIN_POINTS: usize = 6;

/// Times at which mean surface profiles are kept per cell: slices ⌈i·n/5⌉ for i = 1..5.
pub const PROFILE_TIMES: usize = 5;

/// The slices one sample of a cell has reported.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JetSampleInput {
    /// Index of the sample within its cell (0-based).
    pub sample: u32,
    /// Slices in order, from slice 1.
    pub slices: Vec<JetSlice>,
}

/// Everything stored for one jet cell: its run, its plan and the samples reported so far.
#[derive(Debug, Clone, PartialEq)]
pub struct JetCellInput {
    /// Index of the cell in the campaign.
    pub cell: u32,
    /// The run every sample of the cell makes.
    pub params: JetParams,
    /// The pump pressure the jet speed came from, when the spec gave pressures (MPa).
    pub pump_pressure_mpa: Option<f64>,
    /// Values of the swept dimensions, by spec name.
    pub swept: BTreeMap<String, f64>,
    /// Samples planned.
    pub planned_samples: usize,
    /// Slices each sample is planned to run.
    pub planned_slices: usize,
    /// Samples with at least one slice; absent samples have none yet.
    pub samples: Vec<JetSampleInput>,
}

/// One sample's state at its last reported slice.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JetSampleResult {
    /// Index of the sample within its cell.
    pub sample: u32,
    /// Slices reported.
    pub slices: usize,
    /// Time of the last slice (s).
    pub t_s: f64,
    /// Cd at the last slice (m).
    pub crater_depth_m: f64,
    /// Cw at the last slice (m).
    pub crater_width_m: f64,
    /// Width at half depth at the last slice (m).
    pub half_depth_width_m: f64,
    /// Mass loss at the last slice (kg per m of depth).
    pub mass_loss_kg_m: f64,
    /// Largest plastic strain at the last slice.
    pub max_plastic_strain: f64,
    /// First slice with mass loss (the onset); `null` when it lost nothing.
    pub onset_slice: Option<u32>,
    /// Its own least-squares slope of mass loss against time over the cell's stage-3 window
    /// (kg/m/s); `null` when the window is too short or the sample has not reached its end.
    pub stage3_slope_kg_m_s: Option<f64>,
    /// A rock target's detached mass and cracks at the last slice (docs/jet.md#rock-targets);
    /// absent for a metal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rock: Option<RockDamage>,
    /// The first slice in which a grain touched the target; absent when none has (a pure
    /// water jet, or grains still in flight): what the target saw before it came from the
    /// water alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_grain_slice: Option<u32>,
}

/// One point of a cell's mean series: the mean over the samples that reached the slice.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JetMeanPoint {
    /// Slice number, from 1.
    pub slice: u32,
    /// Mean time at the slice's end (s).
    pub t_s: f64,
    /// Samples that reached this slice.
    pub samples: usize,
    /// Mean Cd (m).
    pub crater_depth_m: f64,
    /// Sample standard deviation (n − 1) of Cd (m); `null` below 2 samples.
    pub crater_depth_std_m: Option<f64>,
    /// Mean Cw (m).
    pub crater_width_m: f64,
    /// Sample standard deviation of Cw (m); `null` below 2 samples.
    pub crater_width_std_m: Option<f64>,
    /// Mean width at half depth (m).
    pub half_depth_width_m: f64,
    /// Mean mass loss (kg per m of depth).
    pub mass_loss_kg_m: f64,
    /// Sample standard deviation of the mass loss (kg/m); `null` below 2 samples.
    pub mass_loss_std_kg_m: Option<f64>,
    /// A rock target's cracks and damage over the samples at this slice; absent for a metal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rock: Option<RockStats>,
}

/// A rock target's cracks and damage ([`RockDamage`], docs/jet.md#rock-targets) over the
/// samples at one slice: mean, std and standard error of each.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RockStats {
    /// Cracks in the held rock.
    pub crack_count: Stats,
    /// Their lengths summed (m).
    pub crack_length_m: Stats,
    /// The deepest crack tip below the crater's bottom (m): the AWJ paper's bottom crack.
    pub crack_depth_below_crater_m: Stats,
    /// Held rock at D ≥ 0.9 in the 2D section (m²).
    pub damaged_area_m2: Stats,
    /// Target particles at D = 1.
    pub fractured_particles: Stats,
    /// Detached rock still in the scene (kg/m).
    pub detached_kg_m: Stats,
}

impl RockStats {
    /// The statistics over the slices that carry rock damage; `None` when none does.
    pub fn of(slices: &[&JetSlice]) -> Option<RockStats> {
        let rock: Vec<RockDamage> = slices.iter().filter_map(|s| s.rock).collect();
        let of = |f: &dyn Fn(&RockDamage) -> f64| stats(&rock.iter().map(f).collect::<Vec<_>>());
        Some(RockStats {
            crack_count: of(&|r| r.crack_count as f64)?,
            crack_length_m: of(&|r| r.crack_length_m)?,
            crack_depth_below_crater_m: of(&|r| r.crack_depth_below_crater_m)?,
            damaged_area_m2: of(&|r| r.damaged_area_m2)?,
            fractured_particles: of(&|r| r.fractured_particles as f64)?,
            detached_kg_m: of(&|r| r.detached_kg_m)?,
        })
    }
}

/// A cell's mean surface profile at one slice: each sample's profile interpolated linearly at
/// the target's column centres (held at its end value beyond its ends), then averaged.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JetProfile {
    /// Slice number.
    pub slice: u32,
    /// Mean time at the slice's end (s).
    pub t_s: f64,
    /// Samples averaged.
    pub samples: usize,
    /// Column centres (m).
    pub x_m: Vec<f64>,
    /// Mean surface height at each column (m; the original surface is the cell's
    /// `surface_y_m`).
    pub y_m: Vec<f64>,
}

/// The stage-3 slope of a cell's mass loss against time and its steadiness check (module
/// documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Stage3 {
    /// Whether all five conditions of the module documentation hold.
    pub steady: bool,
    /// Why, in words: every broken condition, or the evidence that none is.
    pub reason: String,
    /// First slice of the window; `null` when the series is empty.
    pub window_first_slice: Option<u32>,
    /// Points in the window.
    pub window_points: usize,
    /// Time of the window's first point (s).
    pub window_start_t_s: Option<f64>,
    /// Time of the window's last point (s).
    pub window_end_t_s: Option<f64>,
    /// Least-squares slope of the mean mass loss over the window (kg/m/s) with its standard
    /// error; `null` below 3 points.
    pub slope_kg_m_s: Option<SlopeFit>,
    /// The slope over the window's first half.
    pub slope_first_half_kg_m_s: Option<SlopeFit>,
    /// The slope over the window's last half.
    pub slope_last_half_kg_m_s: Option<SlopeFit>,
    /// The samples' own window slopes: mean, std and standard error over the samples that
    /// reached the window's end.
    pub per_sample_slope_kg_m_s: Option<Stats>,
    /// Slice of the first mass loss over the samples that lost any.
    pub onset_slices: Option<Incubation>,
    /// Reported samples that lost no mass at all.
    pub samples_without_loss: usize,
    /// Reported samples whose first loss came at or before the window's first slice.
    pub samples_past_onset: usize,
}

/// The results of one jet cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JetCellResult {
    /// Index of the cell in the campaign.
    pub cell: u32,
    /// Jet speed v_jet (m/s).
    pub velocity_m_s: f64,
    /// The pump pressure the speed came from (MPa), when the spec gave pressures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pump_pressure_mpa: Option<f64>,
    /// Abrasive mass flow (kg/s).
    pub mass_flow_kg_s: f64,
    /// Target material's name.
    pub material: String,
    /// Simulated time T (ms).
    pub time_ms: f64,
    /// Particle spacing (m).
    pub spacing_m: f64,
    /// Coupling radius over grain diameter.
    pub coupling_radius_d: f64,
    /// Values of the swept dimensions, by spec name (a swept material as `material_index`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub swept: BTreeMap<String, f64>,
    /// The original surface line the profiles' depths are measured from (m).
    pub surface_y_m: f64,
    /// Whether samples or slices are missing against the plan.
    pub partial: bool,
    /// Samples that reached T, over which the values at T are taken.
    pub samples: usize,
    /// Samples planned.
    pub samples_planned: usize,
    /// Samples with at least one slice.
    pub samples_reported: usize,
    /// Slices planned per sample.
    pub slices_planned: usize,
    /// Cd at T over the samples that reached it (m); `null` when none has.
    pub crater_depth_m: Option<Stats>,
    /// Cw at T (m).
    pub crater_width_m: Option<Stats>,
    /// Width at half depth at T (m).
    pub half_depth_width_m: Option<Stats>,
    /// Mass loss per metre of depth at T (kg/m).
    pub mass_loss_kg_m: Option<Stats>,
    /// Largest plastic strain at T.
    pub max_plastic_strain: Option<Stats>,
    /// A rock target's cracks and damage at T; absent for a metal or before any sample
    /// reached T.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rock: Option<RockStats>,
    /// Every reported sample at its last slice.
    pub per_sample: Vec<JetSampleResult>,
    /// The mean over samples of every slice (for charts against time).
    pub mean_series: Vec<JetMeanPoint>,
    /// Mean surface profiles at up to [`PROFILE_TIMES`] slices.
    pub profiles: Vec<JetProfile>,
    /// The stage-3 slope of mass loss against time and whether it is steady.
    pub stage3: Stage3,
}

impl JetCellResult {
    /// A rock cell's cracks and fracture at T in one line; `None` for a metal or before any
    /// sample reached T.
    pub fn rock_summary(&self) -> Option<String> {
        let r = self.rock?;
        Some(format!(
            "cracks at T {:.1} ± {}, their length {:.2} mm, the deepest {:.0} µm below the crater, \
             {:.0} of the target's particles fractured",
            r.crack_count.mean,
            r.crack_count.std.map_or("–".into(), |d| format!("{d:.1}")),
            r.crack_length_m.mean * 1e3,
            r.crack_depth_below_crater_m.mean * 1e6,
            r.fractured_particles.mean
        ))
    }

    /// The cell's name in messages: its index and swept values.
    pub fn label(&self) -> String {
        let mut label = format!("#{}", self.cell);
        for (name, value) in &self.swept {
            label.push_str(&format!(" {name}={value}"));
        }
        label
    }
}

/// Results of a jet campaign, complete or not.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JetCampaignResults {
    /// Always `jet`: tells these results from an impact campaign's.
    pub scene: Scene,
    /// Whether any cell is partial.
    pub partial: bool,
    /// Whether every cell's stage-3 slope passed its check.
    pub steady: bool,
    /// One result per cell, in cell order.
    pub cells: Vec<JetCellResult>,
    /// The campaign spec as run, defaults filled in, when the caller supplied it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spec: Option<serde_json::Value>,
    /// Version of grit that aggregated these results.
    #[serde(default)]
    pub grit_version: Option<String>,
    /// The engine fingerprint the farm pinned the campaign to, which computed every unit;
    /// absent in files from before pins and outside a farm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub engine: Option<String>,
    /// The commit of the grit that created the campaign, beside `engine`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub commit: Option<String>,
}

impl JetCampaignResults {
    /// These results with the campaign spec that produced them.
    pub fn with_spec(mut self, spec: serde_json::Value) -> Self {
        self.spec = Some(spec);
        self
    }

    /// One line per cell whose stage-3 slope is not steady, saying why.
    pub fn unsteady_warnings(&self) -> Vec<String> {
        self.cells
            .iter()
            .filter(|c| !c.stage3.steady)
            .map(|c| {
                format!(
                    "warning: cell {} has no steady stage-3 slope: {}",
                    c.label(),
                    c.stage3.reason
                )
            })
            .collect()
    }
}

fn invalid(field: String, rule: impl Into<String>) -> AggregateError {
    AggregateError::Invalid {
        field,
        rule: rule.into(),
    }
}

fn check_sample(s: &JetSampleInput, planned: usize) -> Result<(), AggregateError> {
    let field = format!("samples[{}]", s.sample);
    if s.slices.len() > planned {
        return Err(invalid(
            format!("{field}.slices"),
            format!(
                "{} slices reported, more than the {planned} planned",
                s.slices.len()
            ),
        ));
    }
    for (j, x) in s.slices.iter().enumerate() {
        let at = |name: &str| format!("{field}.slices[{j}].{name}");
        if x.slice as usize != j + 1 {
            return Err(invalid(
                at("slice"),
                format!("expected {}, got {}", j + 1, x.slice),
            ));
        }
        let c = &x.sample;
        for (name, v) in [
            ("t_s", c.t_s),
            ("crater_depth_m", c.crater_depth_m),
            ("crater_width_m", c.crater_width_m),
            ("half_depth_width_m", x.half_depth_width_m),
            ("max_plastic_strain", c.max_plastic_strain),
        ] {
            if !v.is_finite() {
                return Err(invalid(at(name), format!("must be finite, got {v}")));
            }
        }
        if !(c.mass_loss_kg_m.is_finite() && c.mass_loss_kg_m >= 0.0) {
            return Err(invalid(
                at("mass_loss_kg_m"),
                format!("must be finite and ≥ 0, got {}", c.mass_loss_kg_m),
            ));
        }
    }
    Ok(())
}

/// The stage-3 window of a series of `n` points: (index of its first point, points); the
/// last ⌊n/2⌋ points.
pub fn stage3_window(n: usize) -> (usize, usize) {
    let w = n / 2;
    (n - w, w)
}

/// Least-squares slope of `y` against `t` with its standard error (`steady::slope_fit`).
fn fit(points: &[(f64, f64)]) -> Option<SlopeFit> {
    let t: Vec<f64> = points.iter().map(|p| p.0).collect();
    let y: Vec<f64> = points.iter().map(|p| p.1).collect();
    slope_fit(&t, &y)
}

/// Mass loss in mg per m of depth per ms, the unit of the reasons' numbers.
fn show(f: SlopeFit) -> String {
    // kg/m/s → mg/m/ms: × 1e6 / 1e3.
    format!("{:.4} ± {:.4} mg/m/ms", f.value * 1e3, f.sem * 1e3)
}

/// The stage-3 slope and its check from the cell's mean series and its samples' slices
/// (module documentation).
pub fn assess_stage3(mean: &[JetMeanPoint], samples: &[JetSampleInput]) -> Stage3 {
    let n = mean.len();
    let (start, w) = stage3_window(n);
    let window = &mean[start..];
    let first_slice = window.first().map(|p| p.slice);
    let onsets: Vec<Option<u32>> = samples.iter().map(|s| onset(&s.slices)).collect();
    let lost: Vec<u32> = onsets.iter().flatten().copied().collect();
    let onset_slices = match (lost.iter().min(), lost.iter().max()) {
        (Some(&min), Some(&max)) => Some(Incubation {
            min: min as usize,
            mean: lost.iter().map(|&k| k as f64).sum::<f64>() / lost.len() as f64,
            max: max as usize,
        }),
        _ => None,
    };
    let samples_past_onset = first_slice.map_or(0, |f| lost.iter().filter(|&&k| k <= f).count());
    let pts: Vec<(f64, f64)> = window.iter().map(|p| (p.t_s, p.mass_loss_kg_m)).collect();
    let half = w / 2;
    let (slope, first, last) = (fit(&pts), fit(&pts[..half]), fit(&pts[half..]));
    let per_sample: Vec<f64> = samples
        .iter()
        .filter_map(|s| sample_slope(s, first_slice, n))
        .collect();

    let mut broken = Vec::new();
    let mut held = Vec::new();
    if samples.is_empty() {
        broken.push("no samples reported".to_string());
    } else if w < STAGE3_MIN_POINTS {
        broken.push(format!(
            "only {n} slices; the window (the last half) needs {STAGE3_MIN_POINTS} points, so \
             at least {} slices",
            2 * STAGE3_MIN_POINTS
        ));
    }
    if let (Some(lo), Some(hi)) = (
        window.iter().map(|p| p.samples).min(),
        window.iter().map(|p| p.samples).max(),
    ) {
        if lo != hi {
            broken.push(format!(
                "the window's points average {lo} to {hi} samples: some samples stopped short (still running or failed)"
            ));
        }
    }
    if let Some(f) = first_slice.filter(|_| !samples.is_empty()) {
        let share = format!(
            "{samples_past_onset} of {} samples lost mass by slice {f}, where the window starts",
            samples.len()
        );
        if samples_past_onset * 100 >= STEADY_INCUBATED_PERCENT * samples.len() {
            held.push(share);
        } else {
            broken.push(format!(
                "only {share} ({STEADY_INCUBATED_PERCENT} % needed): the window is not past \
                 the onset of loss"
            ));
        }
    }
    if w >= STAGE3_MIN_POINTS {
        match (first, last) {
            (Some(a), Some(b)) => {
                let (agree, z) = compare(b, a);
                let text = format!(
                    "last-half slope {} against the first half's {}: {z}",
                    show(b),
                    show(a)
                );
                if agree {
                    held.push(text);
                } else {
                    broken.push(format!("{text} (at most {STEADY_SIGMAS} allowed)"));
                }
                if b.value <= 0.0 {
                    broken.push("no mass lost over the window's last half".to_string());
                }
            }
            _ => broken.push("the slopes could not be fitted (constant time?)".to_string()),
        }
    }
    let steady = broken.is_empty();
    Stage3 {
        steady,
        reason: if steady { held } else { broken }.join("; "),
        window_first_slice: first_slice,
        window_points: w,
        window_start_t_s: window.first().map(|p| p.t_s),
        window_end_t_s: window.last().map(|p| p.t_s),
        slope_kg_m_s: slope,
        slope_first_half_kg_m_s: first,
        slope_last_half_kg_m_s: last,
        per_sample_slope_kg_m_s: stats(&per_sample),
        onset_slices,
        samples_without_loss: samples.len() - lost.len(),
        samples_past_onset,
    }
}

/// First slice with mass loss.
fn onset(slices: &[JetSlice]) -> Option<u32> {
    slices
        .iter()
        .find(|s| s.sample.mass_loss_kg_m > 0.0)
        .map(|s| s.slice)
}

/// A sample's own slope over the window from `first` to slice `n`, when it reached slice `n`
/// and the window has its minimum length.
fn sample_slope(s: &JetSampleInput, first: Option<u32>, n: usize) -> Option<f64> {
    let first = first? as usize;
    if s.slices.len() < n || n + 1 - first < STAGE3_MIN_POINTS {
        return None;
    }
    let pts: Vec<(f64, f64)> = s.slices[first - 1..n]
        .iter()
        .map(|x| (x.sample.t_s, x.sample.mass_loss_kg_m))
        .collect();
    fit(&pts).map(|f| f.value)
}

/// The column centres of the target of `params`: where profiles are averaged.
fn columns(params: &JetParams) -> Vec<f64> {
    let dx = params.spacing_m;
    let nx = (params.target_width_m / dx).round() as usize;
    let x0 = -0.5 * nx as f64 * dx;
    (0..nx).map(|i| x0 + (i as f64 + 0.5) * dx).collect()
}

/// The height of `profile` (points left to right) at `x`: linear between its points, held at
/// its end values beyond them; `None` for an empty profile.
pub fn profile_at(profile: &[[f64; 2]], x: f64) -> Option<f64> {
    let (first, last) = (profile.first()?, profile.last()?);
    if x <= first[0] {
        return Some(first[1]);
    }
    if x >= last[0] {
        return Some(last[1]);
    }
    let k = profile.partition_point(|p| p[0] <= x);
    let (a, b) = (profile[k - 1], profile[k]);
    let span = b[0] - a[0];
    Some(if span > 0.0 {
        a[1] + (b[1] - a[1]) * (x - a[0]) / span
    } else {
        a[1]
    })
}

/// The slices whose mean profiles are kept for `planned` slices: ⌈i·planned/5⌉, i = 1..5,
/// without repeats.
pub fn profile_slices(planned: usize) -> Vec<u32> {
    let mut out: Vec<u32> = (1..=PROFILE_TIMES)
        .map(|i| (i * planned).div_ceil(PROFILE_TIMES) as u32)
        .filter(|&k| k >= 1)
        .collect();
    out.dedup();
    out
}

fn mean_point(k: usize, reached: &[&JetSlice]) -> JetMeanPoint {
    let of =
        |f: &dyn Fn(&JetSlice) -> f64| stats(&reached.iter().map(|s| f(s)).collect::<Vec<_>>());
    let t = of(&|s| s.sample.t_s).map_or(0.0, |s| s.mean);
    let cd = of(&|s| s.sample.crater_depth_m);
    let cw = of(&|s| s.sample.crater_width_m);
    let hd = of(&|s| s.half_depth_width_m);
    let ml = of(&|s| s.sample.mass_loss_kg_m);
    JetMeanPoint {
        slice: k as u32 + 1,
        t_s: t,
        samples: reached.len(),
        crater_depth_m: cd.map_or(0.0, |s| s.mean),
        crater_depth_std_m: cd.and_then(|s| s.std),
        crater_width_m: cw.map_or(0.0, |s| s.mean),
        crater_width_std_m: cw.and_then(|s| s.std),
        half_depth_width_m: hd.map_or(0.0, |s| s.mean),
        mass_loss_kg_m: ml.map_or(0.0, |s| s.mean),
        mass_loss_std_kg_m: ml.and_then(|s| s.std),
        rock: RockStats::of(reached),
    }
}

/// The results of one cell; errors name the field (`samples[2].slices[4].t_s`).
pub fn aggregate_jet_cell(input: &JetCellInput) -> Result<JetCellResult, AggregateError> {
    let mut samples: Vec<&JetSampleInput> = input.samples.iter().collect();
    samples.sort_by_key(|s| s.sample);
    for s in &samples {
        check_sample(s, input.planned_slices)?;
    }
    let longest = samples.iter().map(|s| s.slices.len()).max().unwrap_or(0);
    let mean_series: Vec<JetMeanPoint> = (0..longest)
        .map(|k| {
            let reached: Vec<&JetSlice> = samples.iter().filter_map(|s| s.slices.get(k)).collect();
            mean_point(k, &reached)
        })
        .collect();
    let xs = columns(&input.params);
    let profiles = profile_slices(input.planned_slices)
        .into_iter()
        .filter(|&k| (k as usize) <= longest)
        .map(|k| {
            let reached: Vec<&JetSlice> = samples
                .iter()
                .filter_map(|s| s.slices.get(k as usize - 1))
                .filter(|s| !s.profile.is_empty())
                .collect();
            let y_m = xs
                .iter()
                .map(|&x| {
                    let sum: f64 = reached
                        .iter()
                        .filter_map(|s| profile_at(&s.profile, x))
                        .sum();
                    sum / reached.len().max(1) as f64
                })
                .collect();
            JetProfile {
                slice: k,
                t_s: mean_series[k as usize - 1].t_s,
                samples: reached.len(),
                x_m: xs.clone(),
                y_m,
            }
        })
        .filter(|p| p.samples > 0)
        .collect();
    let owned: Vec<JetSampleInput> = samples.iter().map(|s| (*s).clone()).collect();
    let stage3 = assess_stage3(&mean_series, &owned);
    let first = stage3.window_first_slice;
    let per_sample = samples
        .iter()
        .filter_map(|s| {
            let last = s.slices.last()?;
            Some(JetSampleResult {
                sample: s.sample,
                slices: s.slices.len(),
                t_s: last.sample.t_s,
                crater_depth_m: last.sample.crater_depth_m,
                crater_width_m: last.sample.crater_width_m,
                half_depth_width_m: last.half_depth_width_m,
                mass_loss_kg_m: last.sample.mass_loss_kg_m,
                max_plastic_strain: last.sample.max_plastic_strain,
                onset_slice: onset(&s.slices),
                stage3_slope_kg_m_s: sample_slope(s, first, mean_series.len()),
                rock: last.rock,
                first_grain_slice: s
                    .slices
                    .iter()
                    .find(|x| x.grain_hits.is_some_and(|h| h.count > 0))
                    .map(|x| x.slice),
            })
        })
        .collect();
    let done: Vec<&JetSlice> = samples
        .iter()
        .filter(|s| s.slices.len() == input.planned_slices)
        .filter_map(|s| s.slices.last())
        .collect();
    let at_t = |f: &dyn Fn(&JetSlice) -> f64| stats(&done.iter().map(|s| f(s)).collect::<Vec<_>>());
    let p = &input.params;
    Ok(JetCellResult {
        cell: input.cell,
        velocity_m_s: p.velocity_m_s,
        pump_pressure_mpa: input.pump_pressure_mpa,
        mass_flow_kg_s: p.mass_flow_kg_s,
        material: p.material.0.name.clone(),
        time_ms: p.time_ms,
        spacing_m: p.spacing_m,
        coupling_radius_d: p.coupling_radius_d,
        swept: input.swept.clone(),
        surface_y_m: Layout::of(p).surface_y_m,
        partial: done.len() < input.planned_samples,
        samples: done.len(),
        samples_planned: input.planned_samples,
        samples_reported: samples.iter().filter(|s| !s.slices.is_empty()).count(),
        slices_planned: input.planned_slices,
        crater_depth_m: at_t(&|s| s.sample.crater_depth_m),
        crater_width_m: at_t(&|s| s.sample.crater_width_m),
        half_depth_width_m: at_t(&|s| s.half_depth_width_m),
        mass_loss_kg_m: at_t(&|s| s.sample.mass_loss_kg_m),
        max_plastic_strain: at_t(&|s| s.sample.max_plastic_strain),
        rock: RockStats::of(&done),
        per_sample,
        mean_series,
        profiles,
        stage3,
    })
}

/// The results of every cell, in input order; errors name the cell (`cells[1].samples[0]…`).
pub fn aggregate_jet_campaign(
    cells: &[JetCellInput],
) -> Result<JetCampaignResults, AggregateError> {
    let cells = cells
        .iter()
        .enumerate()
        .map(|(i, c)| {
            aggregate_jet_cell(c).map_err(|e| match e {
                AggregateError::Invalid { field, rule } => AggregateError::Invalid {
                    field: format!("cells[{i}].{field}"),
                    rule,
                },
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(JetCampaignResults {
        scene: Scene::Jet,
        partial: cells.iter().any(|c| c.partial),
        steady: cells.iter().all(|c| c.stage3.steady),
        cells,
        spec: None,
        grit_version: Some(env!("CARGO_PKG_VERSION").to_string()),
        engine: None,
        commit: None,
    })
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::jet::test_slice as slice;
    use crate::jet::GrainHits;

    /// A sample of `n` slices of `dt` s losing `rate` kg/m/s after slice `onset` (from 1),
    /// plus `wiggle(k)`.
    fn sample(index: u32, n: usize, dt: f64, onset: usize, rate: f64) -> JetSampleInput {
        JetSampleInput {
            sample: index,
            slices: (1..=n)
                .map(|k| {
                    let t = k as f64 * dt;
                    let loss = if k >= onset {
                        rate * (k + 1 - onset) as f64 * dt
                    } else {
                        0.0
                    };
                    slice(k as u32, t, loss, 1e-5 * k as f64 * (1.0 + index as f64))
                })
                .collect(),
        }
    }

    fn cell(samples: Vec<JetSampleInput>, planned: usize) -> JetCellInput {
        JetCellInput {
            cell: 0,
            params: JetParams {
                spacing_m: 1e-4,
                target_width_m: 3e-3,
                ..JetParams::default()
            },
            pump_pressure_mpa: None,
            swept: BTreeMap::new(),
            planned_samples: 2,
            planned_slices: planned,
            samples,
        }
    }

    #[test]
    fn a_rock_cell_carries_its_cracks_per_slice_and_at_t_and_each_samples_first_grain() {
        let rock = |cracks: usize, depth: f64| RockDamage {
            detached_kg_m: 1e-4,
            fractured_particles: 10 * cracks,
            crack_count: cracks,
            crack_length_m: 1e-3 * cracks as f64,
            crack_depth_below_crater_m: depth,
            damaged_area_m2: 1e-7,
        };
        let mut samples = vec![sample(0, 3, 1e-6, 1, 1.0), sample(1, 3, 1e-6, 1, 3.0)];
        for (i, s) in samples.iter_mut().enumerate() {
            for x in &mut s.slices {
                // Sample 0: 1, 2, 3 cracks; sample 1: 3, 4, 5; the bottom crack 0.1 mm deeper
                // each slice.
                x.rock = Some(rock(x.slice as usize + 2 * i, 1e-4 * x.slice as f64));
            }
        }
        // Sample 1's first grain lands in slice 2; sample 0's never does.
        samples[1].slices[1].grain_hits = Some(GrainHits {
            count: 1,
            speed_m_s: None,
            normal_speed_m_s: None,
            fastest_m_s: 300.0,
            returns: 0,
            start_speed_sq_sum_m2_s2: 9e4,
            steps_in_contact: 3,
        });
        let c = aggregate_jet_cell(&cell(samples, 3)).unwrap();
        let first = c.mean_series[0].rock.unwrap();
        assert_eq!(first.crack_count.mean, 2.0);
        assert_eq!(first.crack_count.std, Some(2f64.sqrt()));
        assert_eq!(first.crack_depth_below_crater_m.mean, 1e-4);
        let at_t = c.rock.unwrap();
        assert_eq!(at_t.crack_count.mean, 4.0);
        assert_eq!(at_t.fractured_particles.mean, 40.0);
        assert!((at_t.crack_depth_below_crater_m.mean - 3e-4).abs() < 1e-18);
        let grains: Vec<Option<u32>> = c.per_sample.iter().map(|s| s.first_grain_slice).collect();
        assert_eq!(grains, [None, Some(2)]);
        // A metal keeps its results' fields: no rock anywhere.
        let metal = aggregate_jet_cell(&cell(vec![sample(0, 3, 1e-6, 1, 1.0)], 3)).unwrap();
        assert!(metal.rock.is_none() && metal.mean_series.iter().all(|p| p.rock.is_none()));
        let json = serde_json::to_string(&metal).unwrap();
        assert!(
            !json.contains("rock") && !json.contains("first_grain"),
            "{json}"
        );
    }

    #[test]
    fn values_at_t_are_mean_std_and_sem_over_samples() {
        let c = aggregate_jet_cell(&cell(
            vec![sample(0, 4, 1e-6, 1, 1.0), sample(1, 4, 1e-6, 1, 3.0)],
            4,
        ))
        .unwrap();
        assert!(!c.partial);
        assert_eq!(c.samples, 2);
        let cd = c.crater_depth_m.unwrap();
        // 4e-5 and 8e-5.
        assert!((cd.mean - 6e-5).abs() < 1e-18);
        assert!((cd.std.unwrap() - 2f64.sqrt() * 2e-5).abs() < 1e-18);
        assert!((cd.sem.unwrap() - 2e-5).abs() < 1e-18);
        let ml = c.mass_loss_kg_m.unwrap();
        assert!((ml.mean - 8e-6).abs() < 1e-18, "{ml:?}");
        assert_eq!(c.mean_series.len(), 4);
        assert_eq!(c.mean_series[3].samples, 2);
        assert!((c.mean_series[1].crater_width_m - 6e-5).abs() < 1e-18);
        assert_eq!(c.per_sample[1].onset_slice, Some(1));
        // Four slices: too few for a stage-3 window.
        assert!(!c.stage3.steady);
        assert!(
            c.stage3.reason.contains("only 4 slices"),
            "{}",
            c.stage3.reason
        );
        assert_eq!(c.surface_y_m, -0.5e-4);
        // Profiles at slices 1..4 (⌈i·4/5⌉ = 1, 2, 3, 4, 4), on the 30 column centres.
        assert_eq!(
            c.profiles.iter().map(|p| p.slice).collect::<Vec<_>>(),
            [1, 2, 3, 4]
        );
        let p = &c.profiles[3];
        assert_eq!(p.x_m.len(), 30);
        assert!((p.x_m[0] + 1.45e-3).abs() < 1e-15);
        let mid = profile_at(&[[-1e-3, -4e-5], [0.0, -8e-5], [1e-3, -4e-5]], 0.5e-4).unwrap();
        assert!((mid + 7.8e-5).abs() < 1e-15);
    }

    #[test]
    fn a_partial_sample_is_in_the_series_but_not_at_t() {
        let c = aggregate_jet_cell(&cell(
            vec![sample(0, 4, 1e-6, 1, 1.0), sample(1, 2, 1e-6, 1, 3.0)],
            4,
        ))
        .unwrap();
        assert!(c.partial);
        assert_eq!((c.samples, c.samples_reported), (1, 2));
        assert_eq!(c.crater_depth_m.unwrap().std, None);
        assert_eq!(c.mean_series[1].samples, 2);
        assert_eq!(c.mean_series[2].samples, 1);
    }

    #[test]
    fn bad_slices_are_named() {
        let mut s = sample(3, 4, 1e-6, 1, 1.0);
        s.slices[2].sample.t_s = f64::NAN;
        let e = aggregate_jet_campaign(&[cell(vec![s], 4)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "cells[0].samples[3].slices[2].t_s: must be finite, got NaN"
        );
        let mut s = sample(0, 4, 1e-6, 1, 1.0);
        s.slices[1].slice = 5;
        assert!(aggregate_jet_cell(&cell(vec![s], 4))
            .unwrap_err()
            .to_string()
            .contains("slices[1].slice"));
        let s = sample(0, 5, 1e-6, 1, 1.0);
        assert!(
            aggregate_jet_cell(&cell(vec![s], 4)).is_err(),
            "more than planned"
        );
    }

    #[test]
    fn a_linear_loss_past_its_onset_is_steady_with_its_rate() {
        let rate = 2.5e-3;
        let c = aggregate_jet_cell(&cell(
            vec![sample(0, 20, 1e-6, 3, rate), sample(1, 20, 1e-6, 4, rate)],
            20,
        ))
        .unwrap();
        let s = &c.stage3;
        assert!(s.steady, "{}", s.reason);
        assert_eq!((s.window_first_slice, s.window_points), (Some(11), 10));
        assert!((s.slope_kg_m_s.unwrap().value / rate - 1.0).abs() < 1e-9);
        let per = s.per_sample_slope_kg_m_s.unwrap();
        assert!((per.mean / rate - 1.0).abs() < 1e-9);
        assert_eq!(s.samples_past_onset, 2);
        assert_eq!(s.onset_slices.unwrap().max, 4);
        assert!(c.steady_warning_free());
    }

    #[test]
    fn a_window_before_the_onset_is_not_steady_and_says_why() {
        let c = aggregate_jet_cell(&cell(
            vec![sample(0, 20, 1e-6, 15, 1e-3), sample(1, 20, 1e-6, 15, 1e-3)],
            20,
        ))
        .unwrap();
        assert!(!c.stage3.steady);
        assert!(
            c.stage3.reason.contains("not past the onset of loss"),
            "{}",
            c.stage3.reason
        );
        let none = aggregate_jet_cell(&cell(vec![sample(0, 20, 1e-6, 99, 1e-3)], 20)).unwrap();
        assert_eq!(none.stage3.samples_without_loss, 1);
        assert!(none.stage3.reason.contains("0 of 1 samples lost mass"));
    }

    #[test]
    fn a_rate_that_changes_within_the_window_is_not_steady() {
        // Loss ∝ t² (an accelerating stage 2) with a little scatter.
        let s = |index: u32, noise: f64| JetSampleInput {
            sample: index,
            slices: (1..=24)
                .map(|k| {
                    let t = k as f64 * 1e-6;
                    let wobble = if k % 2 == 0 { noise } else { -noise };
                    slice(k as u32, t, 1e3 * t * t * (1.0 + wobble), 1e-5)
                })
                .collect(),
        };
        let c = aggregate_jet_cell(&cell(vec![s(0, 1e-3), s(1, 2e-3)], 24)).unwrap();
        assert!(!c.stage3.steady);
        assert!(
            c.stage3.reason.contains("combined standard errors"),
            "{}",
            c.stage3.reason
        );
    }

    impl JetCellResult {
        fn steady_warning_free(&self) -> bool {
            JetCampaignResults {
                scene: Scene::Jet,
                partial: false,
                steady: true,
                cells: vec![self.clone()],
                spec: None,
                grit_version: None,
                engine: None,
                commit: None,
            }
            .unsteady_warnings()
            .is_empty()
        }
    }

    proptest! {
        #[test]
        fn the_window_is_the_late_half(n in 0usize..500) {
            let (start, w) = stage3_window(n);
            prop_assert_eq!(start + w, n, "it ends at the last point");
            prop_assert_eq!(w, n / 2);
            prop_assert!(start >= w, "it lies in the late half");
        }

        #[test]
        fn any_linear_loss_past_onset_is_steady_at_its_rate(
            n in 12usize..60,
            rate in 1e-6f64..1e3,
            dt in 1e-8f64..1e-4,
            onset_frac in 0.0f64..1.0,
            samples in 1usize..4,
        ) {
            let (start, _) = stage3_window(n);
            // Onset anywhere from slice 1 to the window's first slice.
            let onset = 1 + (onset_frac * start as f64) as usize;
            let input: Vec<_> = (0..samples as u32).map(|i| sample(i, n, dt, onset, rate)).collect();
            let c = aggregate_jet_cell(&cell(input, n)).unwrap();
            prop_assert!(c.stage3.steady, "{}", c.stage3.reason);
            let slope = c.stage3.slope_kg_m_s.unwrap().value;
            prop_assert!((slope / rate - 1.0).abs() < 1e-6, "slope {} rate {}", slope, rate);
        }

        #[test]
        fn an_onset_inside_the_window_is_never_steady(
            n in 12usize..60,
            after in 1usize..6,
        ) {
            let (start, _) = stage3_window(n);
            let onset = (start + 1 + after).min(n);
            let input = vec![sample(0, n, 1e-6, onset, 1.0)];
            let c = aggregate_jet_cell(&cell(input, n)).unwrap();
            prop_assert!(!c.stage3.steady);
        }

        #[test]
        fn profiles_are_interpolated_within_their_points(
            ys in proptest::collection::vec(-1e-3f64..0.0, 2..20),
            frac in 0.0f64..1.0,
        ) {
            let pts: Vec<[f64; 2]> = ys.iter().enumerate().map(|(i, &y)| [i as f64 * 1e-4, y]).collect();
            let x = frac * (pts.len() - 1) as f64 * 1e-4;
            let y = profile_at(&pts, x).unwrap();
            let lo = ys.iter().cloned().fold(f64::MAX, f64::min);
            let hi = ys.iter().cloned().fold(f64::MIN, f64::max);
            prop_assert!(y >= lo - 1e-18 && y <= hi + 1e-18);
        }
    }
}
