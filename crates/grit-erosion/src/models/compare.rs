//! A campaign's erosion beside the published references (Mohseni-Mofidi et al. 2022, section 4):
//! erosion normalised at 45° against Oka's g(α) with silica exponents (eq. 35; Oka et al. 2005),
//! the same g(α) with one scale fitted to all of a shape's angles,
//! and erosion of each shape over the hexagon's at the same angle against the seed's
//! shape-modified Oka h(e, An, α) (eqs. 37–38 with the exponents of Fig. 14).

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use crate::impact::aggregate::{CampaignResults, CellResult};
use crate::impact::balance::LONG_BALANCE_POINTS;
use crate::models::oka::{
    oka_g, oka_silica_exponents, shape_modification, ShapeExponents, ShapeReference, AISI304_HV_GPA,
};
use crate::models::shapes::Shape;

/// The project's goal for normalised erosion: within ±15 % of Oka's g(α)/g(45°).
pub const ANGLE_TOLERANCE: f64 = 0.15;
/// The project's goal for shape ratios: within ±25 % of the seed's modified Oka.
pub const SHAPE_TOLERANCE: f64 = 0.25;
/// The reference angle of the normalisation (seed Fig. 11b).
pub const REFERENCE_ANGLE_DEG: f64 = 45.0;
/// The reference shape of the shape ratios (seed eq. 38).
pub const REFERENCE_SHAPE: &str = "hexagon";

/// A simulated ratio of two cells with its standard error, beside a reference value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ratio {
    /// Simulated ratio; `null` when either cell has no erosion or the denominator is 0.
    pub value: Option<f64>,
    /// Its standard error from both cells' (independent samples): r √((s_a/a)² + (s_b/b)²).
    pub sem: Option<f64>,
    /// The published reference ratio.
    pub reference: f64,
    /// value / reference − 1.
    pub deviation: Option<f64>,
    /// (value − reference) / sem: how far the reference lies outside the sampling error.
    pub z: Option<f64>,
    /// Whether |deviation| is within the goal's tolerance.
    pub within_goal: Option<bool>,
    /// Whether both cells passed the steady-state check (`null`: one was not checked).
    pub steady: Option<bool>,
    /// Whether both cells' last window is balanced, their loss paying for the damage added
    /// (`damage_balance`; `null`: one has no balance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub balanced: Option<bool>,
    /// Whether either cell is partial (samples or impacts short of its plan: still running in
    /// an interim file), so its verdicts are not final.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub partial: bool,
}

/// One row of the angle table: a cell normalised by its shape's 45° cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleRow {
    /// Grain shape.
    pub shape: String,
    /// Impact angle (degrees).
    pub angle_deg: f64,
    /// Cell erosion (mass lost / grain mass) and its standard error.
    pub erosion: Option<f64>,
    /// Standard error of `erosion`.
    pub erosion_sem: Option<f64>,
    /// E(α)/E(45°) against Oka's g(α)/g(45°).
    pub ratio: Ratio,
}

/// One row of the shape table: a shape over the hexagon at the same angle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShapeRow {
    /// Impact angle (degrees).
    pub angle_deg: f64,
    /// Grain shape.
    pub shape: String,
    /// E(shape)/E(hexagon) against the seed's h(e, An, α).
    pub ratio: Ratio,
}

/// One cell against Oka's g(α) times the shape's fitted scale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRow {
    /// Impact angle (degrees).
    pub angle_deg: f64,
    /// Cell erosion (mass lost / grain mass).
    pub erosion: f64,
    /// Standard error of `erosion`.
    pub erosion_sem: f64,
    /// Oka's g(α) times the fitted scale.
    pub oka: f64,
    /// erosion / oka − 1.
    pub deviation: f64,
    /// (erosion − oka) / erosion_sem.
    pub z: f64,
    /// Whether |deviation| is within the angle goal's tolerance.
    pub within_goal: bool,
    /// Whether the cell passed the steady-state check (`null`: not checked).
    pub steady: Option<bool>,
    /// Whether the cell's last window is balanced (`damage_balance`; `null`: no balance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub balanced: Option<bool>,
    /// Whether the cell is partial, so its verdicts are not final.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub partial: bool,
}

/// One shape's angles against Oka's g(α) (eq. 35) with one scale fitted to all of them by
/// weighted least squares (weights 1/s.e.²), so no single cell is the reference: Oka's model
/// predicts the shape of E(α), not its size.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OkaFit {
    /// Grain shape.
    pub shape: String,
    /// The fitted scale E ≈ scale · g(α) (mass lost / grain mass).
    pub scale: f64,
    /// Σ z² over the rows.
    pub chi2: f64,
    /// Degrees of freedom: rows − 1 (the scale).
    pub dof: u32,
    /// The cells, by angle.
    pub rows: Vec<FitRow>,
}

/// Both tables and the angle of largest mean erosion per shape.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// Hardness the Oka reference uses (GPa).
    pub hv_gpa: f64,
    /// Oka's silica exponents n1, n2 at that hardness.
    pub oka_exponents: (f64, f64),
    /// Every cell that has its shape's 45° cell.
    pub angles: Vec<AngleRow>,
    /// Per shape with two or more cells that have erosion and a standard error: Oka's g(α)
    /// with a fitted scale.
    pub oka_fits: Vec<OkaFit>,
    /// Every non-hexagon cell that has a hexagon cell at its angle.
    pub shapes: Vec<ShapeRow>,
    /// Per shape with three or more angles: the angle of its largest mean erosion.
    pub max_angle_deg: Vec<(String, f64)>,
    /// Cells that several of the compared files have, side by side ([`repeated_cells`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub repeated: Vec<RepeatedCell>,
}

/// One results file's erosion of a cell that several files have.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RepeatRow {
    /// The results file, as named on the command line.
    pub file: String,
    /// Particle spacing Δx of its campaign (m), when its spec gives one value.
    pub spacing_m: Option<f64>,
    /// Grain diameter over Δx, when its spec gives both.
    pub particles_per_dg: Option<f64>,
    /// Samples whose slope enters the erosion.
    pub samples: usize,
    /// Cell erosion (mass lost / grain mass).
    pub erosion: Option<f64>,
    /// Standard error of `erosion`.
    pub erosion_sem: Option<f64>,
    /// Whether the cell passed the steady-state check (`null`: not checked).
    pub steady: Option<bool>,
    /// Whether the cell's last window is balanced (`damage_balance`; `null`: no balance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub balanced: Option<bool>,
    /// Whether the cell is partial, so its verdicts are not final.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub partial: bool,
    /// (erosion − the first file's) / √(s.e.² + the first file's s.e.²): independent samples.
    pub z_vs_first: Option<f64>,
    /// erosion / the first file's: with `z_vs_first`, whether a rate holds under refinement
    /// (seed section 3.1; the target in docs/design.md is 10 % and 1.5 combined s.e.).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio_vs_first: Option<f64>,
    /// Loss over each sample's last 60 impacts per grain mass (`long_balance`): a balanced
    /// cell's rate without the selection of the window that stopped it; absent where the file
    /// has no such balance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub long_loss: Option<f64>,
    /// Standard error of `long_loss`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub long_loss_sem: Option<f64>,
    /// long_loss / the first file's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub long_ratio_vs_first: Option<f64>,
}

/// A cell (shape, angle and swept values) found in two or more results files: the same cell
/// run at another resolution, on another box, or again, beside the first file's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RepeatedCell {
    /// Grain shape.
    pub shape: String,
    /// Impact angle (degrees).
    pub angle_deg: f64,
    /// One row per file that has the cell, in the files' order.
    pub rows: Vec<RepeatRow>,
}

/// The spec's single value of `key` (e.g. `["grain", "diameter_m"]`): a number, or a
/// one-element sweep.
pub fn spec_number(spec: Option<&serde_json::Value>, key: &[&str]) -> Option<f64> {
    let mut v = spec?;
    for k in key {
        v = v.get(k)?;
    }
    match v {
        serde_json::Value::Array(a) if a.len() == 1 => a[0].as_f64(),
        v => v.as_f64(),
    }
}

/// The results with every cell's erosion taken over the same impacts `first..=last` (1-based)
/// instead of each sample's last 20: the slope of the cell's mean series there (the mean of the
/// samples' slopes, since every sample has the same grain masses), with the standard error of
/// independent increments (`steady::slope_fit`). The seed compares cells at fixed impact counts
/// (section 4); this puts cells that ran to different counts on that basis. The cells'
/// steady-state checks are dropped, since they judge the last-20 window. A cell whose mean
/// series does not cover the window with all its samples is left out, with a note naming it.
pub fn on_window(
    r: &CampaignResults,
    first: usize,
    last: usize,
) -> Result<(CampaignResults, Vec<String>), String> {
    if first < 1 || last < first + 2 {
        return Err(format!(
            "--window {first}-{last}: needs 1 <= first and at least 3 impacts"
        ));
    }
    let mut out = r.clone();
    let mut notes = Vec::new();
    out.cells.retain(|c| {
        let covered = c
            .mean_series
            .get(first - 1..last)
            .is_some_and(|p| p.iter().all(|m| m.samples == c.samples_reported));
        if !covered {
            notes.push(format!(
                "cell {} left out: its mean series has {} impacts, not all of {first}-{last} with all {} samples",
                c.label(),
                c.mean_series.len(),
                c.samples_reported
            ));
        }
        covered
    });
    for c in &mut out.cells {
        let part = &c.mean_series[first - 1..last];
        let x: Vec<f64> = part.iter().map(|p| p.grain_mass_kg).collect();
        let y: Vec<f64> = part.iter().map(|p| p.mass_loss_kg).collect();
        let fit = crate::stats::slope_fit(&x, &y);
        c.erosion_mean = fit.map(|f| f.value);
        c.erosion_sem = fit.map(|f| f.sem);
        c.erosion_std = None;
        c.erosion_sem_rel = None;
        c.steady_state = None;
        c.damage_balance = None;
        c.long_balance = None;
    }
    out.steady = None;
    Ok((out, notes))
}

/// Every cell that two or more of `files` have, with each file's erosion against the first's:
/// how a cell moves with resolution, box or another run of the same campaign (seed section 4's
/// sampling error is the yardstick).
pub fn repeated_cells(files: &[(String, &CampaignResults)]) -> Vec<RepeatedCell> {
    let mut out: Vec<RepeatedCell> = Vec::new();
    let mut seen: Vec<&CellResult> = Vec::new();
    for (k, (_, first)) in files.iter().enumerate() {
        for c in &first.cells {
            if seen.iter().any(|s| s.same_cell(c)) {
                continue;
            }
            seen.push(c);
            let rows: Vec<RepeatRow> = files[k..]
                .iter()
                .filter_map(|(name, r)| {
                    let same = r.cells.iter().find(|d| d.same_cell(c))?;
                    let spec = r.spec.as_ref();
                    let spacing_m = spec_number(spec, &["spacing_m"]);
                    let dg = spec_number(spec, &["grain", "diameter_m"]);
                    Some(RepeatRow {
                        file: name.clone(),
                        spacing_m,
                        particles_per_dg: dg.zip(spacing_m).map(|(d, s)| d / s),
                        samples: same.samples,
                        erosion: same.erosion_mean,
                        erosion_sem: same.erosion_sem,
                        steady: steady(same),
                        balanced: balanced(same),
                        partial: same.partial,
                        z_vs_first: match (c.erosion_mean, c.erosion_sem) {
                            (Some(a), Some(sa)) => match (same.erosion_mean, same.erosion_sem) {
                                (Some(b), Some(sb)) if sa.hypot(sb) > 0.0 => {
                                    Some((b - a) / sa.hypot(sb))
                                }
                                _ => None,
                            },
                            _ => None,
                        },
                        ratio_vs_first: ratio_to(same.erosion_mean, c.erosion_mean),
                        long_loss: same.long_balance.map(|b| b.loss_rate),
                        long_loss_sem: same.long_balance.map(|b| b.loss_rate_sem),
                        long_ratio_vs_first: ratio_to(
                            same.long_balance.map(|b| b.loss_rate),
                            c.long_balance.map(|b| b.loss_rate),
                        ),
                    })
                })
                .collect();
            if rows.len() >= 2 {
                out.push(RepeatedCell {
                    shape: c.shape.clone(),
                    angle_deg: c.angle_deg,
                    rows,
                });
            }
        }
    }
    out
}

/// `value / first`, where both are known and `first` is positive.
fn ratio_to(value: Option<f64>, first: Option<f64>) -> Option<f64> {
    match (value, first) {
        (Some(v), Some(f)) if f > 0.0 => Some(v / f),
        _ => None,
    }
}

fn cell<'a>(r: &'a CampaignResults, shape: &str, angle: f64) -> Option<&'a CellResult> {
    r.cells
        .iter()
        .find(|c| c.shape == shape && (c.angle_deg - angle).abs() < 1e-9 && c.swept.is_empty())
}

fn steady(c: &CellResult) -> Option<bool> {
    c.steady_state.as_ref().map(|s| s.steady)
}

/// Whether a cell's last window is balanced (docs/erosion.md, *The damage balance*), by the
/// current rule whatever the file says: results written before the ratio floor called some
/// cells balanced that are not.
pub fn balanced(c: &CellResult) -> Option<bool> {
    c.damage_balance.as_ref().map(|b| b.holds())
}

/// Both cells' flag when both have one.
fn both(a: Option<bool>, b: Option<bool>) -> Option<bool> {
    a.zip(b).map(|(a, b)| a && b)
}

fn ratio(num: &CellResult, den: &CellResult, reference: f64, tolerance: f64) -> Ratio {
    let value = match (num.erosion_mean, den.erosion_mean) {
        (Some(a), Some(b)) if b != 0.0 => Some(a / b),
        _ => None,
    };
    let rel = |m: Option<f64>, s: Option<f64>| match (m, s) {
        (Some(m), Some(s)) if m != 0.0 => Some(s / m),
        _ => None,
    };
    let same = std::ptr::eq(num, den);
    let sem = match (
        value,
        rel(num.erosion_mean, num.erosion_sem),
        rel(den.erosion_mean, den.erosion_sem),
    ) {
        (Some(_), _, _) if same => Some(0.0),
        (Some(v), Some(a), Some(b)) => Some(v.abs() * a.hypot(b)),
        _ => None,
    };
    let deviation = value.map(|v| v / reference - 1.0);
    Ratio {
        value,
        sem,
        reference,
        deviation,
        z: match (value, sem) {
            (Some(v), Some(s)) if s > 0.0 => Some((v - reference) / s),
            _ => None,
        },
        within_goal: deviation.map(|d| d.abs() <= tolerance),
        steady: both(steady(num), steady(den)),
        balanced: both(balanced(num), balanced(den)),
        partial: num.partial || den.partial,
    }
}

/// Compares a campaign's cells (those without other swept values) with Oka's g(α) at AISI
/// 304's hardness and with the seed's shape-modified Oka.
pub fn compare(r: &CampaignResults) -> Comparison {
    let hv = AISI304_HV_GPA;
    let (n1, n2) = oka_silica_exponents(hv);
    let g45 = oka_g(REFERENCE_ANGLE_DEG, n1, n2, hv);
    let plain = || r.cells.iter().filter(|c| c.swept.is_empty());
    let angles = plain()
        .filter_map(|c| {
            let den = cell(r, &c.shape, REFERENCE_ANGLE_DEG)?;
            let reference = oka_g(c.angle_deg, n1, n2, hv) / g45;
            Some(AngleRow {
                shape: c.shape.clone(),
                angle_deg: c.angle_deg,
                erosion: c.erosion_mean,
                erosion_sem: c.erosion_sem,
                ratio: ratio(c, den, reference, ANGLE_TOLERANCE),
            })
        })
        .collect();
    let shapes = plain()
        .filter(|c| c.shape != REFERENCE_SHAPE)
        .filter_map(|c| {
            let den = cell(r, REFERENCE_SHAPE, c.angle_deg)?;
            let (angularity, aspect) = Shape::from_name(&c.shape)?.factors().ok()?;
            let reference = shape_modification(
                c.angle_deg,
                aspect,
                angularity,
                &ShapeReference::HEXAGON,
                &ShapeExponents::SEED,
            );
            Some(ShapeRow {
                angle_deg: c.angle_deg,
                shape: c.shape.clone(),
                ratio: ratio(c, den, reference, SHAPE_TOLERANCE),
            })
        })
        .collect();
    let mut names: Vec<&str> = plain().map(|c| c.shape.as_str()).collect();
    names.dedup();
    let oka_fits = names
        .iter()
        .filter_map(|s| {
            let cells: Vec<&CellResult> = plain().filter(|c| c.shape == *s).collect();
            oka_fit(s, &cells, |a| oka_g(a, n1, n2, hv))
        })
        .collect();
    let max_angle_deg = names
        .into_iter()
        .filter_map(|s| {
            let cells: Vec<_> = plain()
                .filter(|c| c.shape == s && c.erosion_mean.is_some())
                .collect();
            let best = cells
                .iter()
                .max_by(|a, b| a.erosion_mean.partial_cmp(&b.erosion_mean).unwrap())?;
            (cells.len() >= 3).then(|| (s.to_string(), best.angle_deg))
        })
        .collect();
    Comparison {
        hv_gpa: hv,
        oka_exponents: (n1, n2),
        angles,
        oka_fits,
        shapes,
        max_angle_deg,
        repeated: Vec::new(),
    }
}

/// Oka's g(α) scaled to `cells` by weighted least squares: scale = Σ E g/σ² / Σ g²/σ² over the
/// cells with erosion and a positive standard error; `None` below two such cells.
fn oka_fit(shape: &str, cells: &[&CellResult], g: impl Fn(f64) -> f64) -> Option<OkaFit> {
    let data: Vec<(&CellResult, f64, f64, f64)> = cells
        .iter()
        .filter_map(|c| match (c.erosion_mean, c.erosion_sem) {
            (Some(e), Some(s)) if s > 0.0 => Some((*c, e, s, g(c.angle_deg))),
            _ => None,
        })
        .collect();
    if data.len() < 2 {
        return None;
    }
    let num: f64 = data.iter().map(|(_, e, s, g)| e * g / (s * s)).sum();
    let den: f64 = data.iter().map(|(_, _, s, g)| g * g / (s * s)).sum();
    let scale = num / den;
    let rows: Vec<FitRow> = data
        .iter()
        .map(|&(c, e, s, g)| {
            let oka = scale * g;
            let deviation = e / oka - 1.0;
            FitRow {
                angle_deg: c.angle_deg,
                erosion: e,
                erosion_sem: s,
                oka,
                deviation,
                z: (e - oka) / s,
                within_goal: deviation.abs() <= ANGLE_TOLERANCE,
                steady: steady(c),
                balanced: balanced(c),
                partial: c.partial,
            }
        })
        .collect();
    Some(OkaFit {
        shape: shape.to_string(),
        scale,
        chi2: rows.iter().map(|r| r.z * r.z).sum(),
        dof: rows.len() as u32 - 1,
        rows,
    })
}

fn num(v: Option<f64>, digits: usize) -> String {
    v.map_or("–".into(), |v| format!("{v:.digits$}"))
}

/// `value ± s.e.` times `scale` to two decimals; "–" without a value, the value alone without
/// an error.
fn pm(v: Option<f64>, sem: Option<f64>, scale: f64) -> String {
    match (v, sem) {
        (None, _) => "–".into(),
        (Some(v), None) => format!("{:.2}", scale * v),
        (Some(v), Some(e)) => format!("{:.2} ± {:.2}", scale * v, scale * e),
    }
}

fn yes_no(v: Option<bool>, yes: &str, no: &str) -> String {
    v.map_or("not checked".into(), |b| (if b { yes } else { no }).into())
}

/// A cell's verdicts: the steady rule's, then, for a steady cell with a damage balance,
/// whether its loss pays for the damage added (docs/erosion.md, *The damage balance*). A
/// partial cell has none yet: its rule looked at samples that are still running.
pub fn verdict(steady: Option<bool>, balanced: Option<bool>, partial: bool) -> String {
    if partial {
        return "partial".into();
    }
    match (steady, balanced) {
        (Some(true), Some(true)) => "steady, balanced".into(),
        (Some(true), Some(false)) => "steady, **unbalanced**".into(),
        (s, _) => yes_no(s, "steady", "**unsteady**"),
    }
}

/// A ratio's table cells: value ± s.e., reference, deviation, z, goal and steadiness.
fn ratio_cells(r: &Ratio) -> [String; 6] {
    [
        pm(r.value, r.sem, 1.0),
        format!("{:.2}", r.reference),
        r.deviation
            .map_or("–".into(), |d| format!("{:+.0} %", 100.0 * d)),
        num(r.z, 1),
        yes_no(r.within_goal, "yes", "**no**"),
        verdict(r.steady, r.balanced, r.partial),
    ]
}

/// A Markdown table: `head` names the columns, each row gives their cells.
fn table(s: &mut String, head: &[&str], rows: impl IntoIterator<Item = Vec<String>>) {
    let _ = writeln!(s, "| {} |", head.join(" | "));
    let _ = writeln!(s, "|{}", "---|".repeat(head.len()));
    for row in rows {
        let _ = writeln!(s, "| {} |", row.join(" | "));
    }
}

/// The comparison as Markdown tables, for `docs/erosion.md` and the terminal.
pub fn markdown(c: &Comparison) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Erosion normalised at 45° against Oka's g(α)/g(45°) (silica exponents n1 = {:.3}, n2 = {:.3} at Hv = {} GPa; goal ±{:.0} %):\n",
        c.oka_exponents.0,
        c.oka_exponents.1,
        c.hv_gpa,
        100.0 * ANGLE_TOLERANCE
    );
    table(
        &mut s,
        &[
            "shape",
            "angle",
            "erosion (mg/g) ± s.e.",
            "E/E(45°) ± s.e.",
            "Oka",
            "deviation",
            "z",
            "within goal",
            "cells",
        ],
        c.angles.iter().map(|a| {
            let mut row = vec![
                a.shape.clone(),
                format!("{}°", a.angle_deg),
                pm(a.erosion, a.erosion_sem, 1e3),
            ];
            row.extend(ratio_cells(&a.ratio));
            row
        }),
    );
    if !c.max_angle_deg.is_empty() {
        s.push('\n');
    }
    for (shape, angle) in &c.max_angle_deg {
        let _ = writeln!(
            s,
            "{shape}: largest mean erosion at {angle}° (goal: between 30° and 45°)."
        );
    }
    for f in &c.oka_fits {
        let _ = writeln!(
            s,
            "\n{}: Oka's g(α) scaled to all its angles by weighted least squares (scale {:.2} mg/g; χ² = {:.1} for {} degrees of freedom):\n",
            f.shape,
            1e3 * f.scale,
            f.chi2,
            f.dof
        );
        table(
            &mut s,
            &[
                "angle",
                "erosion (mg/g) ± s.e.",
                "Oka, scaled",
                "deviation",
                "z",
                "within goal",
                "cell",
            ],
            f.rows.iter().map(|r| {
                vec![
                    format!("{}°", r.angle_deg),
                    format!("{:.2} ± {:.2}", 1e3 * r.erosion, 1e3 * r.erosion_sem),
                    format!("{:.2}", 1e3 * r.oka),
                    format!("{:+.0} %", 100.0 * r.deviation),
                    format!("{:.1}", r.z),
                    yes_no(Some(r.within_goal), "yes", "**no**"),
                    verdict(r.steady, r.balanced, r.partial),
                ]
            }),
        );
    }
    if !c.shapes.is_empty() {
        let _ = writeln!(
            s,
            "\nErosion over the hexagon's at the same angle against the seed's modified Oka h(e, An, α) (eq. 38, Fig. 14 exponents; goal ±{:.0} %):\n",
            100.0 * SHAPE_TOLERANCE
        );
        table(
            &mut s,
            &[
                "angle",
                "shape",
                "E/E(hexagon) ± s.e.",
                "seed",
                "deviation",
                "z",
                "within goal",
                "cells",
            ],
            c.shapes.iter().map(|r| {
                let mut row = vec![format!("{}°", r.angle_deg), r.shape.clone()];
                row.extend(ratio_cells(&r.ratio));
                row
            }),
        );
    }
    let long = format!("loss, last {LONG_BALANCE_POINTS} (mg/g) ± s.e.");
    for r in &c.repeated {
        let _ = writeln!(
            s,
            "\n{} at {}° in {} files (ratio: erosion over the first file's; z: their difference over both standard errors; last {LONG_BALANCE_POINTS}: loss per grain mass over each sample's last {LONG_BALANCE_POINTS} impacts, free of the selection of the window that stopped a balanced cell):\n",
            r.shape,
            r.angle_deg,
            r.rows.len()
        );
        table(
            &mut s,
            &[
                "file",
                "particles per Dg",
                "samples",
                "erosion (mg/g) ± s.e.",
                "ratio to the first",
                "z against the first",
                "cell",
                &long,
                "its ratio to the first",
            ],
            r.rows.iter().map(|w| {
                vec![
                    w.file.clone(),
                    num(w.particles_per_dg, 1),
                    w.samples.to_string(),
                    pm(w.erosion, w.erosion_sem, 1e3),
                    num(w.ratio_vs_first, 2),
                    num(w.z_vs_first, 1),
                    verdict(w.steady, w.balanced, w.partial),
                    pm(w.long_loss, w.long_loss_sem, 1e3),
                    num(w.long_ratio_vs_first, 2),
                ]
            }),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::impact::steady::SteadyState;

    fn cell(shape: &str, angle: f64, mean: f64, sem: f64, steady: bool) -> CellResult {
        let json = serde_json::json!({
            "angle_deg": angle, "shape": shape, "partial": false, "samples": 10,
            "samples_planned": 10, "samples_reported": 10, "samples_without_slope": 0,
            "impacts_planned": 100, "erosion_mean": mean, "erosion_std": sem * 10f64.sqrt(),
            "erosion_sem": sem, "per_sample": [], "mean_series": [], "convergence": [],
        });
        let mut c: CellResult = serde_json::from_value(json).unwrap();
        c.steady_state = Some(SteadyState {
            steady,
            reason: String::new(),
            incubation_impacts: None,
            samples_without_loss: 0,
            first_loss_impacts: Vec::new(),
            window_first_impact: None,
            samples_incubated_by_window: 0,
            points: 20,
            slope_last: None,
            slope_prev: None,
            slope_before: None,
            detectable_change_rel: None,
        });
        c
    }

    fn results(cells: Vec<CellResult>) -> CampaignResults {
        CampaignResults {
            partial: false,
            slope_window: 20,
            cells,
            steady: None,
            spec: None,
            grit_version: None,
            numerics: None,
            engine: None,
            commit: None,
        }
    }

    #[test]
    fn a_steady_cells_balance_is_its_verdicts_second_half() {
        // The verdict is the rule's on the numbers, not the file's flag: the 60° cell was
        // written as balanced (within 2 s.e.) before the ratio floor, at ratio 0.83.
        let with_balance = |angle, loss_rate: f64, stored: bool| {
            let mut c = cell("hexagon", angle, 1e-3, 1e-4, true);
            c.damage_balance = Some(crate::impact::balance::DamageBalance {
                points: 20,
                samples: 10,
                loss_rate,
                loss_rate_sem: 1e-4,
                damage_rate: 1.2e-3,
                damage_rate_sem: 1e-4,
                difference_sem: 1e-4,
                ratio: Some(loss_rate / 1.2e-3),
                balanced: stored,
                detectable_rel: Some(0.17),
            });
            c
        };
        let cells = vec![
            with_balance(45.0, 1.1e-3, false),
            with_balance(60.0, 1e-3, true),
            cell("hexagon", 75.0, 1e-3, 1e-4, true),
            cell("hexagon", 90.0, 1e-3, 1e-4, false),
        ];
        let c = compare(&results(cells));
        let flags: Vec<_> = c.angles.iter().map(|a| a.ratio.balanced).collect();
        assert_eq!(flags, [Some(true), Some(false), None, None]);
        let md = markdown(&c);
        assert!(
            md.contains(
                "| 45° | 1.00 ± 0.10 | 1.00 ± 0.00 | 1.00 | +0 % | – | yes | steady, balanced |"
            ),
            "{md}"
        );
        assert!(md.contains("| steady, **unbalanced** |"), "{md}");
        assert!(md.contains("| **unsteady** |"), "{md}");
        let fit = &c.oka_fits[0].rows;
        assert_eq!(
            fit.iter().map(|r| r.balanced).collect::<Vec<_>>(),
            [Some(true), Some(false), None, None]
        );
    }

    #[test]
    fn a_partial_cell_has_no_verdict_yet() {
        // An interim file's running cell: its steady rule looked at unfinished samples.
        let mut running = cell("hexagon", 90.0, 1e-3, 1e-4, false);
        running.partial = true;
        let cells = vec![cell("hexagon", 45.0, 1e-3, 1e-4, true), running];
        let c = compare(&results(cells));
        let partial: Vec<_> = c.angles.iter().map(|a| a.ratio.partial).collect();
        assert_eq!(partial, [false, true]);
        assert!(c.oka_fits[0].rows[1].partial);
        let md = markdown(&c);
        assert!(md.contains("| steady |"), "{md}");
        assert!(md.contains("| partial |"), "{md}");
        assert!(!md.contains("unsteady"), "{md}");
        let v = serde_json::to_value(&c.angles[0].ratio).unwrap();
        assert!(
            v.get("partial").is_none(),
            "a final cell's row keeps its old form: {v}"
        );
    }

    #[test]
    fn the_seeds_shape_ratios_come_out_of_eq_38() {
        // The values the seed's modified Oka gives (Mohseni-Mofidi et al. 2022, Fig. 14 exponents).
        let mut cells = vec![cell("hexagon", 45.0, 1e-3, 1e-4, true)];
        cells.push(cell("hexagon", 90.0, 1e-3, 1e-4, true));
        for s in ["octagon", "square", "rectangle"] {
            cells.push(cell(s, 45.0, 1e-3, 1e-4, true));
            cells.push(cell(s, 90.0, 1e-3, 1e-4, false));
        }
        let c = compare(&results(cells));
        let want = [
            (45.0, "octagon", 0.87),
            (90.0, "octagon", 0.75),
            (45.0, "square", 1.39),
            (90.0, "square", 2.00),
            (45.0, "rectangle", 1.11),
            (90.0, "rectangle", 1.49),
        ];
        assert_eq!(c.shapes.len(), 6);
        for (angle, shape, seed) in want {
            let row = c
                .shapes
                .iter()
                .find(|r| r.angle_deg == angle && r.shape == shape)
                .unwrap();
            assert!(
                (row.ratio.reference - seed).abs() < 0.006,
                "{shape} at {angle}: {} against {seed}",
                row.ratio.reference
            );
            assert_eq!(row.ratio.steady, Some(angle == 45.0));
        }
    }

    #[test]
    fn normalised_erosion_carries_both_cells_errors_and_oka_s_ratios() {
        let c = compare(&results(vec![
            cell("hexagon", 45.0, 2e-3, 2e-4, true),
            cell("hexagon", 90.0, 1.5e-3, 3e-4, true),
            cell("hexagon", 30.0, 3e-3, 0.0, true),
        ]));
        let row = |a: f64| c.angles.iter().find(|r| r.angle_deg == a).unwrap();
        // Oka's g(90)/g(45) at Hv 1.8 with silica exponents is 1/1.374 (docs/references.md).
        assert!((row(90.0).ratio.reference - 0.728).abs() < 0.002);
        assert_eq!(row(90.0).ratio.value, Some(0.75));
        let sem = 0.75 * (0.1f64.powi(2) + 0.2f64.powi(2)).sqrt();
        assert!((row(90.0).ratio.sem.unwrap() - sem).abs() < 1e-12);
        assert_eq!(row(90.0).ratio.within_goal, Some(true));
        assert_eq!(
            (row(45.0).ratio.value, row(45.0).ratio.sem),
            (Some(1.0), Some(0.0))
        );
        assert_eq!(row(30.0).ratio.within_goal, Some(false));
        assert_eq!(c.max_angle_deg, vec![("hexagon".to_string(), 30.0)]);
        let md = markdown(&c);
        assert!(
            md.contains("| hexagon | 90° | 1.50 ± 0.30 | 0.75 ± 0.17 | 0.73 |"),
            "{md}"
        );
    }

    #[test]
    fn oka_s_shape_with_a_fitted_scale_recovers_the_scale_and_weights_by_error() {
        let hv = AISI304_HV_GPA;
        let (n1, n2) = oka_silica_exponents(hv);
        let g = |a: f64| oka_g(a, n1, n2, hv);
        // Cells exactly on 2e-3 · g(α): the fit returns that scale with χ² = 0.
        let exact: Vec<CellResult> = [15.0, 45.0, 90.0]
            .iter()
            .map(|&a| cell("hexagon", a, 2e-3 * g(a), 1e-4, true))
            .collect();
        let f = &compare(&results(exact)).oka_fits[0];
        assert!((f.scale - 2e-3).abs() < 1e-15, "{f:?}");
        assert!(f.chi2 < 1e-20 && f.dof == 2);
        // One cell off by +20 % with a 10× larger error barely moves the scale.
        let mut cells: Vec<CellResult> = [30.0, 60.0]
            .iter()
            .map(|&a| cell("hexagon", a, 2e-3 * g(a), 1e-5, true))
            .collect();
        cells.push(cell("hexagon", 90.0, 1.2 * 2e-3 * g(90.0), 1e-4, false));
        let f = &compare(&results(cells)).oka_fits[0];
        assert!((f.scale / 2e-3 - 1.0).abs() < 0.01, "{f:?}");
        let off = f.rows.iter().find(|r| r.angle_deg == 90.0).unwrap();
        assert!((off.deviation - 0.2).abs() < 0.01 && !off.within_goal);
        assert_eq!(off.steady, Some(false));
        let md = markdown(&compare(&results(vec![
            cell("hexagon", 45.0, 2e-3, 2e-4, true),
            cell("hexagon", 90.0, 1.5e-3, 3e-4, true),
        ])));
        assert!(md.contains("Oka's g(α) scaled to all its angles"), "{md}");
    }

    #[test]
    fn a_cell_without_its_reference_is_left_out() {
        let c = compare(&results(vec![cell("square", 90.0, 1e-3, 1e-4, true)]));
        assert!(c.angles.is_empty() && c.shapes.is_empty());
    }

    #[test]
    fn a_cell_in_several_files_is_set_beside_the_first_with_its_resolution() {
        let spec =
            |dx: f64| serde_json::json!({"spacing_m": [dx], "grain": {"diameter_m": 250e-6}});
        // Both 45° cells carry their loss over the last 60 impacts.
        let long = |loss_rate: f64| crate::impact::balance::DamageBalance {
            points: LONG_BALANCE_POINTS,
            samples: 10,
            loss_rate,
            loss_rate_sem: 0.1e-3,
            damage_rate: loss_rate,
            damage_rate_sem: 0.1e-3,
            difference_sem: 0.1e-3,
            ratio: Some(1.0),
            balanced: true,
            detectable_rel: Some(0.1),
        };
        let mut coarse45 = cell("hexagon", 45.0, 3e-3, 0.3e-3, true);
        coarse45.long_balance = Some(long(2.75e-3));
        let coarse = results(vec![coarse45, cell("hexagon", 90.0, 2e-3, 0.2e-3, true)])
            .with_spec(spec(250e-6 / 16.0));
        let mut fine45 = cell("hexagon", 45.0, 3.5e-3, 0.4e-3, false);
        fine45.long_balance = Some(long(3.3e-3));
        let fine = results(vec![fine45, cell("hexagon", 15.0, 1e-3, 0.1e-3, true)])
            .with_spec(spec(250e-6 / 24.0));
        let files = [
            ("a.json".to_string(), &coarse),
            ("b.json".to_string(), &fine),
        ];
        let rep = repeated_cells(&files);
        // Only 45° is in both files; 90° and 15° are in one each.
        assert_eq!(rep.len(), 1);
        let r = &rep[0];
        assert_eq!((r.shape.as_str(), r.angle_deg), ("hexagon", 45.0));
        assert_eq!(r.rows.len(), 2);
        assert!((r.rows[0].particles_per_dg.unwrap() - 16.0).abs() < 1e-9);
        assert!((r.rows[1].particles_per_dg.unwrap() - 24.0).abs() < 1e-9);
        assert_eq!(r.rows[0].z_vs_first, Some(0.0));
        // 0.5e-3 apart over √(0.3² + 0.4²) = 0.5e-3: one combined standard error.
        assert!((r.rows[1].z_vs_first.unwrap() - 1.0).abs() < 1e-9);
        assert_eq!(r.rows[0].ratio_vs_first, Some(1.0));
        assert!((r.rows[1].ratio_vs_first.unwrap() - 3.5 / 3.0).abs() < 1e-12);
        assert_eq!(r.rows[1].steady, Some(false));
        let mut c = compare(&coarse);
        c.repeated = rep;
        let md = markdown(&c);
        assert!(
            md.contains(
                "| b.json | 24.0 | 10 | 3.50 ± 0.40 | 1.17 | 1.0 | **unsteady** | 3.30 ± 0.10 | 1.20 |"
            ),
            "{md}"
        );
        assert!(md.contains("| loss, last 60 (mg/g) ± s.e. | its ratio to the first |"));
    }

    #[test]
    fn a_common_window_takes_the_mean_series_slope_there() {
        let mut a = cell("hexagon", 45.0, 9.0, 9.0, true);
        let mut b = cell("square", 45.0, 9.0, 9.0, true);
        // Hexagon: nothing until impact 10, then 2 per impact; square: 3 per impact throughout.
        let series = |loss: &dyn Fn(f64) -> f64, n: usize| {
            (1..=n)
                .map(|k| crate::impact::aggregate::MeanPoint {
                    impact: k,
                    grain_mass_kg: k as f64,
                    mass_loss_kg: loss(k as f64),
                    mass_loss_std_kg: None,
                    samples: 10,
                })
                .collect::<Vec<_>>()
        };
        a.mean_series = series(&|k| 2.0 * (k - 10.0).max(0.0), 40);
        b.mean_series = series(&|k| 3.0 * k, 30);
        let (r, notes) = on_window(&results(vec![a, b]), 11, 30).unwrap();
        assert!(notes.is_empty());
        assert_eq!(r.cells[0].erosion_mean, Some(2.0));
        assert_eq!(r.cells[1].erosion_mean, Some(3.0));
        assert_eq!(r.cells[0].erosion_sem, Some(0.0));
        assert!(r.cells.iter().all(|c| c.steady_state.is_none()));
        // The square stops at 30 impacts: left out of 31-40, with a note naming it.
        let (short, notes) = on_window(&r, 31, 40).unwrap();
        assert_eq!(short.cells.len(), 1);
        assert_eq!(short.cells[0].shape, "hexagon");
        assert!(
            notes[0].starts_with("cell 45° square left out") && notes[0].contains("30 impacts")
        );
        assert!(on_window(&r, 5, 6).is_err());
    }
}
