//! How each cell approaches its damage balance (seed eq. 19; `docs/erosion.md`, *The damage
//! balance*): loss and damage added per gram of grain over each 20-impact window, with the
//! 0.9 floor under which a window is not stationary.

use grit_erosion::impact::aggregate::SampleInput;
use grit_erosion::impact::balance::{history, DamageBalance, WindowBalance, BALANCE_MIN_RATIO};
use grit_erosion::CellResult;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::analysis::series_label;
use crate::charts::{cell_stem, legend_box};
use crate::draw::{
    chart_on, colour, de, draw_mesh, error_bar, line_key, marker_style, save, top, with_notes,
    Axes, DrawResult, Figure,
};
use crate::{PlotError, PlotInput, Report};

/// Rates (dimensionless) to mg per g.
const MG_PER_G: f64 = 1e3;

struct BalanceChart<'a> {
    cell: &'a CellResult,
    windows: Vec<WindowBalance>,
    notes: Vec<String>,
}

impl Figure for BalanceChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let w = &self.windows;
        let points = w.first().map_or(20, |x| x.balance.points) as f64;
        let xmax = w.last().map_or(1.0, |x| x.end as f64) + 0.5 * points;
        let ymax = top(w.iter().flat_map(|x| {
            let b = &x.balance;
            [
                b.loss_rate + b.loss_rate_sem,
                b.damage_rate + b.damage_rate_sem,
            ]
            .map(|v| v * MG_PER_G)
        }));
        let caption = format!(
            "Loss against damage added, {}°, {}",
            self.cell.angle_deg,
            series_label(&self.cell.shape, &self.cell.swept)
        );
        let mut chart = chart_on(&area, caption, 0.0..xmax, 0.0..ymax)?;
        draw_mesh(
            chart
                .configure_mesh()
                .x_desc("impacts (each point: the 20-impact window ending there)")
                .x_label_formatter(&|v| format!("{v:.0}"))
                .y_desc("mg per g of grains over the window"),
        )?;
        let cap = 0.15 * points;
        let (loss_col, damage_col) = (colour(0), colour(1));
        // (window end, mg/g) per window, of one rate of its balance.
        let series = |f: fn(&DamageBalance) -> f64| -> Vec<(f64, f64)> {
            w.iter()
                .map(|x| (x.end as f64, f(&x.balance) * MG_PER_G))
                .collect()
        };
        let damage = series(|b| b.damage_rate);
        let loss = series(|b| b.loss_rate);
        let floor = series(|b| BALANCE_MIN_RATIO * b.damage_rate);
        for x in w {
            let b = &x.balance;
            let e = x.end as f64;
            for (m, s, col) in [
                (b.damage_rate, b.damage_rate_sem, damage_col),
                (b.loss_rate, b.loss_rate_sem, loss_col),
            ] {
                chart
                    .draw_series(error_bar(
                        e,
                        (m - s) * MG_PER_G,
                        (m + s) * MG_PER_G,
                        cap,
                        col.mix(0.6).stroke_width(1),
                    ))
                    .map_err(de)?;
            }
        }
        line_with_marks(
            &mut chart,
            damage,
            damage_col,
            "damage added, Σ m ΔD per g of grains (±1 s.e.)",
            |_| (3, damage_col.filled()),
        )?;
        let dashed = damage_col.mix(0.7).stroke_width(1);
        chart
            .draw_series(std::iter::once(DashedPathElement::new(floor, 6, 4, dashed)))
            .map_err(de)?
            .label(format!(
                "{BALANCE_MIN_RATIO} × damage added: the balance's floor"
            ))
            .legend(move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 20, y)], 4, 3, dashed));
        line_with_marks(
            &mut chart,
            loss,
            loss_col,
            "mass loss per g of grains (±1 s.e.); filled: balanced window",
            |k| (4, marker_style(loss_col, Some(w[k].balance.balanced))),
        )?;
        legend_box(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// A labelled line through `pts` with a circle at each, of the radius and style `mark(k)` gives
/// point `k`.
fn line_with_marks<DB: DrawingBackend>(
    chart: &mut Axes<'_, DB>,
    pts: Vec<(f64, f64)>,
    col: RGBColor,
    label: &str,
    mark: impl Fn(usize) -> (i32, ShapeStyle),
) -> DrawResult {
    let line = col.stroke_width(2);
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), line))
        .map_err(de)?
        .label(label)
        .legend(line_key(line));
    chart
        .draw_series(pts.iter().enumerate().map(|(k, p)| {
            let (r, style) = mark(k);
            Circle::new(*p, r, style)
        }))
        .map_err(de)?;
    Ok(())
}

/// One chart per cell whose raw series carry the damage each impact added: loss and damage
/// added over each whole 20-impact window (`balance::history`), so the approach to the
/// stationary rate can be seen. Needs the raw series (`--raw`).
pub fn damage_balance(
    input: &PlotInput,
    out: &std::path::Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    let Some(raw) = &input.raw else {
        report
            .notes
            .push("no per-impact series (--raw): no damage-balance charts".to_string());
        return Ok(());
    };
    for (i, c) in input.results.cells.iter().enumerate() {
        let samples: Vec<SampleInput> = raw
            .iter()
            .filter(|r| r.cell as usize == i)
            .map(|r| SampleInput {
                sample: r.sample,
                impacts: r.impacts_in_order(),
            })
            .collect();
        let windows = history(&samples.iter().collect::<Vec<_>>());
        if windows.is_empty() {
            report.notes.push(format!(
                "cell {i} ({}°, {}): no 20-impact window of two samples with their damage \
                 recorded, no damage-balance chart",
                c.angle_deg, c.shape
            ));
            continue;
        }
        let (first, last) = (
            windows[0].balance.samples,
            windows[windows.len() - 1].balance.samples,
        );
        let counts = if first == last {
            format!("{first} samples in every window")
        } else {
            format!("from {first} samples down to {last}")
        };
        let mut notes = vec![format!(
            "Per window: the mean over the samples that reached its end ({counts})."
        )];
        if let Some(b) = &c.damage_balance {
            notes.push(format!(
                "The cell: {}, {}.",
                b.describe(),
                if b.balanced {
                    "balanced"
                } else {
                    "not balanced"
                }
            ));
        }
        let fig = BalanceChart {
            cell: c,
            windows,
            notes,
        };
        report
            .files
            .extend(save(&fig, out, &cell_stem("damage_balance", i, c))?);
    }
    Ok(())
}
