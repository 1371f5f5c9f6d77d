//! Charts of a full Oka fit (`grit fit -o FIT.json`; Oka & Yoshida 2005 eq. 4): the fitted
//! model's curves through the cells it was fitted to, against speed (log–log, one curve per
//! angle, grain size and shape) and against angle (one curve per speed, size and shape).

use std::collections::BTreeMap;
use std::path::Path;

use grit_erosion::models::fit::{CellResidual, FullOkaFit};
use grit_erosion::models::shapes::Shape;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::charts::legend_box;
use crate::draw::{
    axes, colour, de, error_bar, prepare_output, save, with_notes, DrawResult, Figure,
};
use crate::{PlotError, Report};

/// kg per kg to mg per g.
const MG_PER_G: f64 = 1e3;

/// The cells of `fit` grouped by what a curve holds fixed: `key` of a cell, in first-seen
/// order, with the cells in input order.
fn groups(
    fit: &FullOkaFit,
    key: impl Fn(&CellResidual) -> String,
) -> Vec<(String, Vec<&CellResidual>)> {
    let mut order: Vec<String> = Vec::new();
    let mut by: BTreeMap<String, Vec<&CellResidual>> = BTreeMap::new();
    for c in &fit.cells {
        let k = key(c);
        if !by.contains_key(&k) {
            order.push(k.clone());
        }
        by.entry(k).or_default().push(c);
    }
    order
        .into_iter()
        .map(|k| {
            let cells = by.remove(&k).unwrap_or_default();
            (k, cells)
        })
        .collect()
}

/// The model's erosion (mg/g) for a cell's grain at `angle`, `speed` and `diameter`.
fn model_at(fit: &FullOkaFit, c: &CellResidual, angle: f64, speed: f64, diameter: f64) -> f64 {
    let m = &fit.model;
    let e = match Shape::from_name(&c.cell.shape) {
        Some(Shape::Hexagon) | None => m.erosion(angle, speed, diameter),
        Some(_) => m.erosion_shaped(
            angle,
            speed,
            diameter,
            c.cell.aspect_ratio,
            c.cell.angularity,
        ),
    };
    e * MG_PER_G
}

/// Which axis a chart sweeps.
#[derive(Clone, Copy)]
enum Sweep {
    Speed,
    Angle,
}

struct FitChart<'a> {
    fit: &'a FullOkaFit,
    sweep: Sweep,
    notes: Vec<String>,
}

impl FitChart<'_> {
    fn key(&self, c: &CellResidual) -> String {
        let d = c.cell.diameter_m * 1e6;
        match self.sweep {
            Sweep::Speed => format!("{}°, {:.0} µm, {}", c.cell.angle_deg, d, c.cell.shape),
            Sweep::Angle => format!("{} m/s, {:.0} µm, {}", c.cell.velocity_m_s, d, c.cell.shape),
        }
    }

    fn x(&self, c: &CellResidual) -> f64 {
        match self.sweep {
            Sweep::Speed => c.cell.velocity_m_s,
            Sweep::Angle => c.cell.angle_deg,
        }
    }
}

impl Figure for FitChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let groups = groups(self.fit, |c| self.key(c));
        let xs = self.fit.cells.iter().map(|c| self.x(c));
        let (xmin, xmax) = xs.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
        // The curves run over the cells' range, a little beyond it on each side.
        let (lo, hi) = match self.sweep {
            Sweep::Speed => (0.8 * xmin, 1.25 * xmax),
            Sweep::Angle => (0.5, 90.0),
        };
        let curve = |c: &CellResidual| -> Vec<(f64, f64)> {
            (0..=120)
                .map(|k| {
                    let x = match self.sweep {
                        Sweep::Speed => lo * (hi / lo).powf(k as f64 / 120.0),
                        Sweep::Angle => lo + (hi - lo) * k as f64 / 120.0,
                    };
                    let (a, v) = match self.sweep {
                        Sweep::Speed => (c.cell.angle_deg, x),
                        Sweep::Angle => (x, c.cell.velocity_m_s),
                    };
                    (x, model_at(self.fit, c, a, v, c.cell.diameter_m))
                })
                .collect()
        };
        let values: Vec<f64> = groups
            .iter()
            .flat_map(|(_, cells)| {
                cells.iter().flat_map(|c| {
                    let e = c.cell.erosion * MG_PER_G;
                    let s = c.cell.erosion_sem * MG_PER_G;
                    let mut v = vec![e + s, (e - s).max(e / 3.0)];
                    v.extend(curve(c).into_iter().map(|p| p.1));
                    v
                })
            })
            .filter(|v| *v > 0.0 && v.is_finite())
            .collect();
        let ymax = values.iter().cloned().fold(0.0, f64::max) * 1.3;
        let caption = match self.sweep {
            Sweep::Speed => "Erosion against impact speed: the fitted Oka model and the cells",
            Sweep::Angle => "Erosion against impact angle: the fitted Oka model and the cells",
        };
        let x_desc = match self.sweep {
            Sweep::Speed => "impact speed v (m/s)",
            Sweep::Angle => "impact angle α (degrees from the surface)",
        };
        let y_desc = "erosion (mg surface lost per g of grains)";
        match self.sweep {
            Sweep::Speed => {
                let ymin = values.iter().cloned().fold(f64::INFINITY, f64::min) / 1.3;
                let x = ((lo..hi).log_scale(), x_desc);
                let y = ((ymin..ymax).log_scale(), y_desc);
                let mut chart = axes(&area, caption, x, y)?;
                self.draw_groups(&mut chart, &groups, &curve)?;
                legend_box(&mut chart, SeriesLabelPosition::UpperLeft)
            }
            Sweep::Angle => {
                let mut chart = axes(&area, caption, (0.0..95.0, x_desc), (0.0..ymax, y_desc))?;
                self.draw_groups(&mut chart, &groups, &curve)?;
                legend_box(&mut chart, SeriesLabelPosition::UpperLeft)
            }
        }
    }
}

impl FitChart<'_> {
    /// Each group's fitted curve and its cells with ±1 s.e. bars (the lower bar kept above a
    /// third of the value, for the log axes), on either axes.
    fn draw_groups<DB: DrawingBackend, X, Y>(
        &self,
        chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
        groups: &[(String, Vec<&CellResidual>)],
        curve: &dyn Fn(&CellResidual) -> Vec<(f64, f64)>,
    ) -> DrawResult
    where
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        for (i, (label, cells)) in groups.iter().enumerate() {
            let c = colour(i);
            chart
                .draw_series(LineSeries::new(curve(cells[0]), c.stroke_width(2)))
                .map_err(de)?
                .label(format!("{label}: fitted model"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 22, y)], c.stroke_width(2))
                });
            for cell in cells {
                let (x, e) = (self.x(cell), cell.cell.erosion * MG_PER_G);
                let s = cell.cell.erosion_sem * MG_PER_G;
                chart
                    .draw_series(error_bar(
                        x,
                        (e - s).max(e / 3.0),
                        e + s,
                        0.0,
                        c.stroke_width(1),
                    ))
                    .map_err(de)?;
                chart
                    .draw_series(std::iter::once(Circle::new((x, e), 5, c.filled())))
                    .map_err(de)?;
            }
        }
        Ok(())
    }
}

/// Writes the fit's charts into `out`: `fit_speed` (log–log, when the cells have two or more
/// speeds) and `fit_angle` (when they have two or more angles), PNG and SVG each.
pub fn plot_fit(fit: &FullOkaFit, out: &Path) -> Result<Report, PlotError> {
    prepare_output(out)?;
    let mut report = Report::default();
    let distinct = |f: &dyn Fn(&CellResidual) -> f64| {
        let mut v: Vec<u64> = fit.cells.iter().map(|c| f(c).to_bits()).collect();
        v.sort_unstable();
        v.dedup();
        v.len()
    };
    let summary = format!(
        "χ²/dof = {}; bars ±1 s.e. of each cell; curves: the fitted model at each cell's grain",
        fit.chi2_per_dof
            .map_or("– (no degrees of freedom)".into(), |x| format!("{x:.2}"))
    );
    for (sweep, stem, n) in [
        (
            Sweep::Speed,
            "fit_speed",
            distinct(&|c| c.cell.velocity_m_s),
        ),
        (Sweep::Angle, "fit_angle", distinct(&|c| c.cell.angle_deg)),
    ] {
        if n < 2 {
            report.notes.push(format!(
                "{stem}: the cells have one value of its axis; not drawn"
            ));
            continue;
        }
        let fig = FitChart {
            fit,
            sweep,
            notes: vec![summary.clone()],
        };
        report.files.extend(save(&fig, out, stem)?);
    }
    Ok(report)
}
