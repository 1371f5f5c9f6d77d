//! Charts of a jet campaign's results (`docs/jet-campaigns.md`): per cell the mean crater
//! profiles at several times (the V → U development); Cd, Cw and the mass loss against time
//! as the mean over samples with a ±1 std band (the mass loss with its stage-3 fit), and for a
//! rock the cracks and the deepest crack below the crater; and values at the run's end against
//! the jet speed or the abrasive mass flow, one series per combination of the other swept
//! values (the AWJ paper's Figs. 26-27).
//! Lengths are shown in µm, times in µs and mass loss in mg per metre of depth (the engine is
//! 2D).

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

use grit_erosion::jet::aggregate::{JetCampaignResults, JetCellResult, JetMeanPoint, RockStats};
use grit_erosion::stats::Stats;
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

/// The swept values other than the one on a chart's x axis: the series a cell belongs to.
fn group_key(c: &JetCellResult, against: Against) -> BTreeMap<String, u64> {
    c.swept
        .iter()
        .filter(|(k, _)| !against.is(k))
        .map(|(k, v)| (k.clone(), v.to_bits()))
        .collect()
}

fn group_label(c: &JetCellResult, against: Against) -> String {
    let parts: Vec<String> = c
        .swept
        .iter()
        .filter(|(k, _)| !against.is(k))
        .map(|(k, v)| swept_text(c, k, *v))
        .collect();
    if !parts.is_empty() {
        return parts.join(", ");
    }
    match against {
        Against::Speed => format!(
            "{}, {} kg/s, {} ms",
            c.material, c.mass_flow_kg_s, c.time_ms
        ),
        Against::MassFlow => format!("{}, {} m/s, {} ms", c.material, c.velocity_m_s, c.time_ms),
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

/// Which quantity a chart draws: against time from the mean series, against a swept value at
/// the run's end T.
#[derive(Clone, Copy, PartialEq)]
enum Quantity {
    Depth,
    Width,
    MassLoss,
    /// A rock's crack count (docs/jet.md#fractured-rock-loss-and-cracks).
    Cracks,
    /// How far the deepest crack reaches below the crater's bottom: the paper's bottom crack.
    CrackDepth,
}

/// The rock quantities, drawn only when a cell has a rock target.
const ROCK_QUANTITIES: [Quantity; 2] = [Quantity::Cracks, Quantity::CrackDepth];

impl Quantity {
    /// (mean, std) in the chart's unit at one point of the mean series; `None` for a rock
    /// quantity of a metal.
    fn of(self, p: &JetMeanPoint) -> Option<(f64, Option<f64>)> {
        let um = |m: f64, s: Option<f64>| (m * UM_PER_M, s.map(|s| s * UM_PER_M));
        match self {
            Quantity::Depth => Some(um(p.crater_depth_m, p.crater_depth_std_m)),
            Quantity::Width => Some(um(p.crater_width_m, p.crater_width_std_m)),
            Quantity::MassLoss => Some((
                p.mass_loss_kg_m * MG_PER_KG,
                p.mass_loss_std_kg_m.map(|s| s * MG_PER_KG),
            )),
            Quantity::Cracks | Quantity::CrackDepth => self.at_t_rock(p.rock.as_ref()),
        }
    }

    /// (mean, std) in the chart's unit at T over the samples that reached it.
    fn at_t(self, c: &JetCellResult) -> Option<(f64, Option<f64>)> {
        let scaled = |s: Option<Stats>, k: f64| s.map(|s| (s.mean * k, s.std.map(|d| d * k)));
        match self {
            Quantity::Depth => scaled(c.crater_depth_m, UM_PER_M),
            Quantity::Width => scaled(c.crater_width_m, UM_PER_M),
            Quantity::MassLoss => scaled(c.mass_loss_kg_m, MG_PER_KG),
            Quantity::Cracks | Quantity::CrackDepth => self.at_t_rock(c.rock.as_ref()),
        }
    }

    fn at_t_rock(self, r: Option<&RockStats>) -> Option<(f64, Option<f64>)> {
        let r = r?;
        let (s, k) = match self {
            Quantity::Cracks => (r.crack_count, 1.0),
            Quantity::CrackDepth => (r.crack_depth_below_crater_m, UM_PER_M),
            Quantity::Depth | Quantity::Width | Quantity::MassLoss => return None,
        };
        Some((s.mean * k, s.std.map(|d| d * k)))
    }

    fn axis(self) -> &'static str {
        match self {
            Quantity::Depth => "crater depth Cd (µm)",
            Quantity::Width => "crater width Cw (µm)",
            Quantity::MassLoss => "mass loss (mg per m of depth)",
            Quantity::Cracks => "cracks in the held rock",
            Quantity::CrackDepth => "deepest crack below the crater bottom (µm)",
        }
    }

    fn name(self) -> &'static str {
        match self {
            Quantity::Depth => "Crater depth Cd",
            Quantity::Width => "Crater width Cw",
            Quantity::MassLoss => "Mass loss",
            Quantity::Cracks => "Cracks",
            Quantity::CrackDepth => "Deepest crack below the crater",
        }
    }

    /// The quantity's part of a chart's file name, `jet_{key}_vs_{what}`.
    fn key(self) -> &'static str {
        match self {
            Quantity::Depth => "depth",
            Quantity::Width => "width",
            Quantity::MassLoss => "mass_loss",
            Quantity::Cracks => "cracks",
            Quantity::CrackDepth => "crack_depth",
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
        let series = |c: &JetCellResult| -> Vec<(f64, f64, Option<f64>)> {
            c.mean_series
                .iter()
                .filter_map(|p| self.what.of(p).map(|(m, s)| (p.t_s * US_PER_S, m, s)))
                .collect()
        };
        let all: Vec<(f64, f64, Option<f64>)> = cells.iter().flat_map(series).collect();
        let x = from_zero(all.iter().map(|p| p.0));
        let y = from_zero(all.iter().map(|p| p.1 + p.2.unwrap_or(0.0)));
        let y_top = all.iter().map(|p| p.1).fold(0.0, f64::max);
        let title = format!("{} against time", self.what.name());
        let mut chart = axes(
            &area,
            &title,
            (x, "simulated time (µs)"),
            (y, self.what.axis()),
        )?;
        for (i, c) in cells.iter().enumerate() {
            let col = colour(i);
            let pts = series(c);
            if pts.is_empty() {
                continue;
            }
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
            if ROCK_QUANTITIES.contains(&self.what) {
                // The first grain's arrival, from the samples' first touches: what came before
                // it is the water's alone.
                let first: Vec<f64> = c
                    .per_sample
                    .iter()
                    .filter_map(|s| s.first_grain_slice)
                    .filter_map(|k| c.mean_series.get(k as usize - 1))
                    .map(|p| p.t_s * US_PER_S)
                    .collect();
                if let Some(t) = first.iter().copied().reduce(f64::min) {
                    chart
                        .draw_series(DashedLineSeries::new(
                            [(t, 0.0), (t, y_top)],
                            4,
                            4,
                            col.mix(0.7).stroke_width(1),
                        ))
                        .map_err(de)?;
                }
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
    match what {
        Quantity::MassLoss => {
            notes.push(
                "Dashed: the stage-3 slope over the run's late half (markers); hollow markers: \
                 not steady (docs/jet-campaigns.md)."
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
        Quantity::Cracks | Quantity::CrackDepth => notes.push(
            "A crack: a connected set of held rock at D ≥ 0.9 (docs/jet.md). Thin dashed \
             verticals: the first grain touching the target, earliest over the samples."
                .to_string(),
        ),
        _ => {}
    }
    let fig = AgainstTime {
        results: r,
        what,
        notes,
    };
    let stem = format!("jet_{}_vs_time", what.key());
    report.files.extend(save(&fig, out, &stem)?);
    Ok(())
}

// ------------------------------------------------- a quantity at T against a swept value

/// The swept value a chart at T has on its x axis.
#[derive(Clone, Copy)]
enum Against {
    Speed,
    MassFlow,
}

impl Against {
    fn x(self, c: &JetCellResult) -> f64 {
        match self {
            Against::Speed => c.velocity_m_s,
            Against::MassFlow => c.mass_flow_kg_s,
        }
    }

    /// Whether `name` is this dimension's spec name.
    fn is(self, name: &str) -> bool {
        match self {
            Against::Speed => is_speed(name),
            Against::MassFlow => name == "mass_flow_kg_s",
        }
    }

    fn axis(self) -> &'static str {
        match self {
            Against::Speed => "jet speed v_jet (m/s)",
            Against::MassFlow => "abrasive mass flow M (kg/s)",
        }
    }

    fn name(self) -> &'static str {
        match self {
            Against::Speed => "the jet speed",
            Against::MassFlow => "the abrasive mass flow",
        }
    }

    fn key(self) -> &'static str {
        match self {
            Against::Speed => "speed",
            Against::MassFlow => "mass_flow",
        }
    }
}

struct AtTAgainst<'a> {
    against: Against,
    what: Quantity,
    /// Series of cells with the same other swept values, each sorted along `against`.
    groups: Vec<Vec<&'a JetCellResult>>,
    notes: Vec<String>,
}

impl Figure for AtTAgainst<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let points = |g: &[&JetCellResult]| -> Vec<(f64, f64, Option<f64>)> {
            g.iter()
                .filter_map(|c| self.what.at_t(c).map(|(m, s)| (self.against.x(c), m, s)))
                .collect()
        };
        let all: Vec<(f64, f64, Option<f64>)> =
            self.groups.iter().flat_map(|g| points(g)).collect();
        let x = padded(all.iter().map(|p| p.0));
        let y = from_zero(all.iter().map(|p| p.1 + p.2.unwrap_or(0.0)));
        let cap = 0.01 * (x.end - x.start);
        let title = format!(
            "{} at the run's end against {}",
            self.what.name(),
            self.against.name()
        );
        let y_axis = format!("{} at T", self.what.axis());
        let mut chart = axes(&area, &title, (x, self.against.axis()), (y, &y_axis))?;
        for (i, g) in self.groups.iter().enumerate() {
            let col = colour(i);
            let pts = points(g);
            if pts.is_empty() {
                continue;
            }
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
                .label(group_label(g[0], self.against))
                .legend(line_key(style));
            chart
                .draw_series(pts.iter().map(|p| Circle::new((p.0, p.1), 4, col.filled())))
                .map_err(de)?;
        }
        crate::charts::legend_box(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// Charts of `what` at T against `against`, one series per combination of the other swept
/// values; none when no cell has reached T.
fn at_t_against(
    r: &JetCampaignResults,
    against: Against,
    what: Quantity,
    out: &Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    let mut groups: Vec<(BTreeMap<String, u64>, Vec<&JetCellResult>)> = Vec::new();
    for c in r.cells.iter().filter(|c| what.at_t(c).is_some()) {
        let key = group_key(c, against);
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, g)) => g.push(c),
            None => groups.push((key, vec![c])),
        }
    }
    if groups.is_empty() {
        report.notes.push(format!(
            "no jet cell has a sample at its end time yet: no {} against {} chart",
            what.name(),
            against.name()
        ));
        return Ok(());
    }
    let mut groups: Vec<Vec<&JetCellResult>> = groups.into_iter().map(|(_, g)| g).collect();
    for g in &mut groups {
        g.sort_by(|a, b| against.x(a).total_cmp(&against.x(b)));
    }
    let notes = vec![format!(
        "Mean over the samples that reached T, error bars ±1 std; one line per combination of \
         the other swept values ({} series).",
        groups.len()
    )];
    let fig = AtTAgainst {
        against,
        what,
        groups,
        notes,
    };
    let stem = format!("jet_{}_vs_{}", what.key(), against.key());
    report.files.extend(save(&fig, out, &stem)?);
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
    let rock = results
        .cells
        .iter()
        .any(|c| c.mean_series.iter().any(|p| p.rock.is_some()));
    let rock_quantities: &[Quantity] = if rock { &ROCK_QUANTITIES } else { &[] };
    for &what in [Quantity::Depth, Quantity::Width, Quantity::MassLoss]
        .iter()
        .chain(rock_quantities)
    {
        against_time(results, what, out, &mut report)?;
    }
    at_t_against(results, Against::Speed, Quantity::Depth, out, &mut report)?;
    // The other charts at T only where their dimension is swept: the paper's trends, Cd and
    // Cw against v_jet (Fig. 26), Cd, mass loss and the bottom crack against M (Figs. 27-28).
    let swept = |against: Against| {
        let mut xs: Vec<f64> = results.cells.iter().map(|c| against.x(c)).collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        xs.len() > 1
    };
    if swept(Against::Speed) {
        at_t_against(results, Against::Speed, Quantity::Width, out, &mut report)?;
        if rock {
            at_t_against(results, Against::Speed, Quantity::Cracks, out, &mut report)?;
        }
    }
    if swept(Against::MassFlow) {
        for &what in [Quantity::Depth, Quantity::Width, Quantity::MassLoss]
            .iter()
            .chain(rock_quantities)
        {
            at_t_against(results, Against::MassFlow, what, out, &mut report)?;
        }
    }
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
        if let Some(line) = c.rock_summary() {
            out.push_str(&format!("      {line}\n"));
        }
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
