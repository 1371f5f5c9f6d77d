//! Charts of a jet campaign's results (`docs/jet-campaigns.md`): per cell the mean crater
//! profiles at several times (the V → U development); Cd, Cw and the mass loss against time
//! as the mean over samples with a ±1 std band (the mass loss with its stage-3 fit); and Cd at
//! the run's end against the jet speed, one series per combination of the other swept values.
//! Lengths are shown in µm, times in µs and mass loss in mg per metre of depth (the engine is
//! 2D).

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

use grit_erosion::jet::aggregate::{JetCampaignResults, JetCellResult, JetMeanPoint};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::draw::{
    axes, colour, de, error_bar, file_safe, line_key, marker_style, prepare_output, save,
    with_notes, DrawResult, Figure,
};
use crate::{PlotError, Report};

/// m to µm.
const UM_PER_M: f64 = 1e6;
/// s to µs.
const US_PER_S: f64 = 1e6;
/// kg to mg.
const MG_PER_KG: f64 = 1e6;

/// A range around `values` with 8 % padding on each side (a unit span when they are all
/// equal, ±1 when there are none).
fn padded(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return -1.0..1.0;
    }
    let pad = if hi > lo {
        0.08 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1.0)
    };
    (lo - pad)..(hi + pad)
}

/// `0..` the largest value plus 10 % (1 when all are ≤ 0).
fn from_zero(values: impl Iterator<Item = f64>) -> Range<f64> {
    0.0..crate::draw::top(values)
}

/// The cell's name in legends: its jet speed and its other swept values.
pub fn cell_label(c: &JetCellResult) -> String {
    let mut s = match c.pump_pressure_mpa {
        Some(p) => format!("{p} MPa ({:.1} m/s)", c.velocity_m_s),
        None => format!("{} m/s", c.velocity_m_s),
    };
    for (k, v) in c.swept.iter().filter(|(k, _)| !is_speed(k)) {
        s.push_str(&format!(", {}", swept_text(c, k, *v)));
    }
    s
}

/// A swept value in words: a swept material by its name, not its index in the spec.
fn swept_text(c: &JetCellResult, name: &str, value: f64) -> String {
    if name == "material_index" {
        c.material.clone()
    } else {
        format!("{name} {}", four_digits(value))
    }
}

/// `v` to four significant digits without trailing zeros (`8.333e-5`, `0.02`, `500`).
fn four_digits(v: f64) -> String {
    let trim = |s: String| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    let a = v.abs();
    if a == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    if (1e-3..1e6).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        trim(format!("{v:.decimals$}"))
    } else {
        let s = format!("{v:.3e}");
        let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
        format!("{}e{exp}", trim(mantissa.to_string()))
    }
}

fn is_speed(name: &str) -> bool {
    name == "velocity_m_s" || name == "pump_pressure_mpa"
}

/// The swept values other than the jet speed: the series a cell belongs to in the
/// speed chart.
fn group_key(c: &JetCellResult) -> BTreeMap<String, u64> {
    c.swept
        .iter()
        .filter(|(k, _)| !is_speed(k))
        .map(|(k, v)| (k.clone(), v.to_bits()))
        .collect()
}

fn group_label(c: &JetCellResult) -> String {
    let parts: Vec<String> = c
        .swept
        .iter()
        .filter(|(k, _)| !is_speed(k))
        .map(|(k, v)| swept_text(c, k, *v))
        .collect();
    if parts.is_empty() {
        format!(
            "{}, {} kg/s, {} ms",
            c.material, c.mass_flow_kg_s, c.time_ms
        )
    } else {
        parts.join(", ")
    }
}

// ------------------------------------------------------------ crater profiles over time

struct Profiles<'a> {
    cell: &'a JetCellResult,
    notes: Vec<String>,
}

impl Figure for Profiles<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let c = self.cell;
        let s0 = c.surface_y_m;
        let pts = || {
            c.profiles.iter().flat_map(move |p| {
                p.x_m
                    .iter()
                    .zip(&p.y_m)
                    .map(move |(x, y)| (x * 1e3, (y - s0) * UM_PER_M))
            })
        };
        let x = padded(pts().map(|p| p.0));
        let y = padded(pts().map(|p| p.1).chain([0.0]));
        let caption = format!(
            "Crater profiles over time: cell {} ({})",
            c.cell,
            cell_label(c)
        );
        let mut chart = axes(
            &area,
            &caption,
            (x.clone(), "x across the target (mm)"),
            (y, "surface height above the original surface (µm)"),
        )?;
        let zero = BLACK.mix(0.5).stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new(
                [(x.start, 0.0), (x.end, 0.0)],
                6,
                4,
                zero,
            ))
            .map_err(de)?
            .label("original surface")
            .legend(line_key(zero));
        for (i, p) in c.profiles.iter().enumerate() {
            let style = colour(i).stroke_width(2);
            let line = p
                .x_m
                .iter()
                .zip(&p.y_m)
                .map(|(x, y)| (x * 1e3, (y - s0) * UM_PER_M));
            chart
                .draw_series(LineSeries::new(line, style))
                .map_err(de)?
                .label(format!(
                    "t = {:.3} µs (slice {}, {} samples)",
                    p.t_s * US_PER_S,
                    p.slice,
                    p.samples
                ))
                .legend(line_key(style));
        }
        crate::charts::legend_box(&mut chart, SeriesLabelPosition::LowerRight)
    }
}

fn profiles(r: &JetCampaignResults, out: &Path, report: &mut Report) -> Result<(), PlotError> {
    for c in &r.cells {
        if c.profiles.is_empty() {
            report.notes.push(format!(
                "jet cell {}: no slices yet, no profile chart",
                c.cell
            ));
            continue;
        }
        let notes = vec![
            "Mean over samples of each sample's surface profile, interpolated at the target's \
             column centres (docs/jet-campaigns.md)."
                .to_string(),
            format!(
                "Cd at T {}; Cw at T {}; width at half depth {} (a V has about Cw/2, a U about Cw).",
                show_um(c.crater_depth_m.map(|s| s.mean)),
                show_um(c.crater_width_m.map(|s| s.mean)),
                show_um(c.half_depth_width_m.map(|s| s.mean)),
            ),
        ];
        let fig = Profiles { cell: c, notes };
        let stem = format!("jet_profiles_c{:02}_{}", c.cell, file_safe(&cell_label(c)));
        report.files.extend(save(&fig, out, &stem)?);
    }
    Ok(())
}

fn show_um(v: Option<f64>) -> String {
    v.map_or("–".to_string(), |v| format!("{:.1} µm", v * UM_PER_M))
}

// ------------------------------------------------------- a quantity against time

/// Which series of the mean points a time chart draws.
#[derive(Clone, Copy)]
enum Quantity {
    Depth,
    Width,
    MassLoss,
}

impl Quantity {
    /// (mean, std) in the chart's unit.
    fn of(self, p: &JetMeanPoint) -> (f64, Option<f64>) {
        match self {
            Quantity::Depth => (
                p.crater_depth_m * UM_PER_M,
                p.crater_depth_std_m.map(|s| s * UM_PER_M),
            ),
            Quantity::Width => (
                p.crater_width_m * UM_PER_M,
                p.crater_width_std_m.map(|s| s * UM_PER_M),
            ),
            Quantity::MassLoss => (
                p.mass_loss_kg_m * MG_PER_KG,
                p.mass_loss_std_kg_m.map(|s| s * MG_PER_KG),
            ),
        }
    }

    fn axis(self) -> &'static str {
        match self {
            Quantity::Depth => "crater depth Cd (µm)",
            Quantity::Width => "crater width Cw (µm)",
            Quantity::MassLoss => "mass loss (mg per m of depth)",
        }
    }

    fn title(self) -> &'static str {
        match self {
            Quantity::Depth => "Crater depth Cd against time",
            Quantity::Width => "Crater width Cw against time",
            Quantity::MassLoss => "Mass loss against time",
        }
    }

    fn stem(self) -> &'static str {
        match self {
            Quantity::Depth => "jet_depth_vs_time",
            Quantity::Width => "jet_width_vs_time",
            Quantity::MassLoss => "jet_mass_loss_vs_time",
        }
    }
}

struct AgainstTime<'a> {
    results: &'a JetCampaignResults,
    what: Quantity,
    notes: Vec<String>,
}

impl Figure for AgainstTime<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let cells = &self.results.cells;
        let all = || cells.iter().flat_map(|c| c.mean_series.iter());
        let x = from_zero(all().map(|p| p.t_s * US_PER_S));
        let y = from_zero(all().map(|p| {
            let (m, s) = self.what.of(p);
            m + s.unwrap_or(0.0)
        }));
        let mut chart = axes(
            &area,
            self.what.title(),
            (x, "simulated time (µs)"),
            (y, self.what.axis()),
        )?;
        for (i, c) in cells.iter().enumerate() {
            let col = colour(i);
            let pts: Vec<(f64, f64, Option<f64>)> = c
                .mean_series
                .iter()
                .map(|p| {
                    let (m, s) = self.what.of(p);
                    (p.t_s * US_PER_S, m, s)
                })
                .collect();
            if pts.iter().any(|p| p.2.is_some()) {
                let band: Vec<(f64, f64)> = pts
                    .iter()
                    .map(|p| (p.0, p.1 + p.2.unwrap_or(0.0)))
                    .chain(
                        pts.iter()
                            .rev()
                            .map(|p| (p.0, (p.1 - p.2.unwrap_or(0.0)).max(0.0))),
                    )
                    .collect();
                chart
                    .draw_series(std::iter::once(Polygon::new(band, col.mix(0.18).filled())))
                    .map_err(de)?;
            }
            let style = col.stroke_width(2);
            chart
                .draw_series(LineSeries::new(pts.iter().map(|p| (p.0, p.1)), style))
                .map_err(de)?
                .label(cell_label(c))
                .legend(line_key(style));
            if let (Quantity::MassLoss, Some(fit), Some(t0), Some(t1)) = (
                self.what,
                c.stage3.slope_kg_m_s,
                c.stage3.window_start_t_s,
                c.stage3.window_end_t_s,
            ) {
                // The stage-3 slope through the centroid of the mean series' window.
                let first = c.stage3.window_first_slice.unwrap_or(1) as usize;
                let window = &c.mean_series[first.saturating_sub(1)..];
                let n = window.len().max(1) as f64;
                let tc = window.iter().map(|p| p.t_s).sum::<f64>() / n;
                let mc = window.iter().map(|p| p.mass_loss_kg_m).sum::<f64>() / n;
                let at = |t: f64| (t * US_PER_S, (mc + fit.value * (t - tc)) * MG_PER_KG);
                let dash = BLACK.stroke_width(2);
                chart
                    .draw_series(DashedLineSeries::new([at(t0), at(t1)], 8, 5, dash))
                    .map_err(de)?;
                let marks = marker_style(col, Some(c.stage3.steady));
                chart
                    .draw_series(window.iter().map(|p| {
                        Circle::new((p.t_s * US_PER_S, p.mass_loss_kg_m * MG_PER_KG), 3, marks)
                    }))
                    .map_err(de)?;
            }
        }
        crate::charts::legend_box(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

fn against_time(
    r: &JetCampaignResults,
    what: Quantity,
    out: &Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    let mut notes =
        vec!["Lines: mean over the samples that reached each slice; bands: ±1 std.".to_string()];
    if let Quantity::MassLoss = what {
        notes.push(
            "Dashed: the stage-3 slope over the run's late half (markers); hollow markers: not \
             steady (docs/jet-campaigns.md)."
                .to_string(),
        );
        for c in r.cells.iter().filter(|c| !c.stage3.steady) {
            notes.push(format!(
                "cell {}: no steady stage-3 slope: {}",
                c.cell,
                c.stage3.reason.split("; ").next().unwrap_or_default()
            ));
        }
    }
    let fig = AgainstTime {
        results: r,
        what,
        notes,
    };
    report.files.extend(save(&fig, out, what.stem())?);
    Ok(())
}

// ------------------------------------------------------------- Cd against jet speed

struct DepthVsSpeed<'a> {
    /// Series of cells with the same other swept values, each sorted by speed.
    groups: Vec<Vec<&'a JetCellResult>>,
    notes: Vec<String>,
}

impl Figure for DepthVsSpeed<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let cells = || self.groups.iter().flatten();
        let x = padded(cells().map(|c| c.velocity_m_s));
        let y = from_zero(cells().filter_map(|c| {
            c.crater_depth_m
                .map(|s| (s.mean + s.std.unwrap_or(0.0)) * UM_PER_M)
        }));
        let cap = 0.01 * (x.end - x.start);
        let mut chart = axes(
            &area,
            "Crater depth Cd at the run's end against the jet speed",
            (x, "jet speed v_jet (m/s)"),
            (y, "crater depth Cd at T (µm)"),
        )?;
        for (i, g) in self.groups.iter().enumerate() {
            let col = colour(i);
            let pts: Vec<(f64, f64, Option<f64>)> = g
                .iter()
                .filter_map(|c| {
                    c.crater_depth_m.map(|s| {
                        (
                            c.velocity_m_s,
                            s.mean * UM_PER_M,
                            s.std.map(|d| d * UM_PER_M),
                        )
                    })
                })
                .collect();
            for p in &pts {
                if let Some(s) = p.2 {
                    chart
                        .draw_series(error_bar(p.0, p.1 - s, p.1 + s, cap, col.stroke_width(1)))
                        .map_err(de)?;
                }
            }
            let style = col.stroke_width(2);
            chart
                .draw_series(LineSeries::new(pts.iter().map(|p| (p.0, p.1)), style))
                .map_err(de)?
                .label(group_label(g[0]))
                .legend(line_key(style));
            chart
                .draw_series(pts.iter().map(|p| Circle::new((p.0, p.1), 4, col.filled())))
                .map_err(de)?;
        }
        crate::charts::legend_box(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

fn depth_vs_speed(
    r: &JetCampaignResults,
    out: &Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    let mut groups: Vec<(BTreeMap<String, u64>, Vec<&JetCellResult>)> = Vec::new();
    for c in r.cells.iter().filter(|c| c.crater_depth_m.is_some()) {
        let key = group_key(c);
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, g)) => g.push(c),
            None => groups.push((key, vec![c])),
        }
    }
    if groups.is_empty() {
        report
            .notes
            .push("no jet cell has a sample at its end time yet: no Cd against speed chart".into());
        return Ok(());
    }
    let mut groups: Vec<Vec<&JetCellResult>> = groups.into_iter().map(|(_, g)| g).collect();
    for g in &mut groups {
        g.sort_by(|a, b| a.velocity_m_s.total_cmp(&b.velocity_m_s));
    }
    let notes = vec![format!(
        "Mean over the samples that reached T, error bars ±1 std; one line per combination of \
         the other swept values ({} series).",
        groups.len()
    )];
    let fig = DepthVsSpeed { groups, notes };
    report.files.extend(save(&fig, out, "jet_depth_vs_speed")?);
    Ok(())
}

/// Writes every jet chart the results allow into `out` (created if missing), PNG and SVG each:
/// one profile chart per cell, Cd, Cw and mass loss against time, and Cd against jet speed.
pub fn plot_jet(results: &JetCampaignResults, out: &Path) -> Result<Report, PlotError> {
    prepare_output(out)?;
    let mut report = Report::default();
    if results.cells.iter().all(|c| c.mean_series.is_empty()) {
        report
            .notes
            .push("no jet cell has a slice yet: nothing to draw".into());
        return Ok(report);
    }
    profiles(results, out, &mut report)?;
    for what in [Quantity::Depth, Quantity::Width, Quantity::MassLoss] {
        against_time(results, what, out, &mut report)?;
    }
    depth_vs_speed(results, out, &mut report)?;
    report.notes.extend(
        results
            .unsteady_warnings()
            .iter()
            .map(|w| w.trim_start_matches("warning: ").to_string()),
    );
    Ok(report)
}

/// A short table of the jet cells: speed and other swept values, samples, Cd, Cw and mass
/// loss at T (mean ± std) and the stage-3 slope.
pub fn jet_summary_table(results: &JetCampaignResults) -> String {
    let pm = |s: Option<grit_erosion::stats::Stats>, scale: f64| {
        s.map_or("–".to_string(), |s| {
            format!(
                "{:.2} ± {}",
                s.mean * scale,
                s.std.map_or("–".into(), |d| format!("{:.2}", d * scale))
            )
        })
    };
    let mut out = format!(
        "{:>4}  {:<36} {:>7}  {:<18} {:<18} {:<18} {}\n",
        "cell",
        "cell",
        "samples",
        "Cd at T (µm)",
        "Cw at T (µm)",
        "loss at T (mg/m)",
        "stage-3 slope"
    );
    for c in &results.cells {
        out.push_str(&format!(
            "{:>4}  {:<36} {:>7}  {:<18} {:<18} {:<18} {}{}\n",
            c.cell,
            cell_label(c),
            c.samples,
            pm(c.crater_depth_m, UM_PER_M),
            pm(c.crater_width_m, UM_PER_M),
            pm(c.mass_loss_kg_m, MG_PER_KG),
            c.stage3.slope_kg_m_s.map_or("–".to_string(), |f| format!(
                "{:.3e} ± {:.1e} kg/m/s{}",
                f.value,
                f.sem,
                if c.stage3.steady { "" } else { " (not steady)" }
            )),
            if c.partial { "  (partial)" } else { "" }
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn swept_values_are_shown_to_four_digits() {
        assert_eq!(four_digits(1e-4 / 1.2), "8.333e-5");
        assert_eq!(four_digits(0.02), "0.02");
        assert_eq!(four_digits(500.0), "500");
        assert_eq!(four_digits(6.25e-5), "6.25e-5");
        assert_eq!(four_digits(1.0 / 3.0), "0.3333");
    }
}
