//! The speed–accuracy chart (docs/performance.md): erosion (seed section 4) and the Hertz p0 error
//! (eq. 31) of each resolution and variant against its wall time per impact.

use std::path::{Path, PathBuf};

use grit_erosion::studies::sweep::{Cost, SweepRow};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::charts::legend_box;
use crate::draw::{
    colour, de, error_bar, prepare_output, save_sized, with_notes, DrawResult, Figure, FONT,
};
use crate::PlotError;

/// Size of the two-panel chart, pixels.
const SWEEP_SIZE: (u32, u32) = (1500, 700);
/// Erosion (dimensionless) to mg per g.
const MG_PER_G: f64 = 1e3;

struct Sweep<'a> {
    rows: &'a [SweepRow],
    cost: Cost,
    variants: Vec<String>,
    notes: Vec<String>,
}

/// A variant's line through `pts` (x, y, resolution) in colour `c`, named `label` in the
/// legend with `key` as its mark, and its dots, each labelled with its resolution.
fn variant_line<'a, DB: DrawingBackend + 'a, X, Y, L: std::fmt::Display, E>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    pts: &[(f64, f64, L)],
    c: RGBColor,
    label: String,
    key: impl Fn((i32, i32)) -> E + 'a,
) -> DrawResult
where
    X: plotters::coord::ranged1d::Ranged<ValueType = f64>,
    Y: plotters::coord::ranged1d::Ranged<ValueType = f64>,
    E: IntoDynElement<'a, DB, (i32, i32)>,
{
    chart
        .draw_series(LineSeries::new(
            pts.iter().map(|p| (p.0, p.1)),
            c.stroke_width(2),
        ))
        .map_err(de)?
        .label(label)
        .legend(key);
    let text = TextStyle::from((FONT, 14).into_font()).color(&c);
    chart
        .draw_series(pts.iter().map(|p| {
            EmptyElement::at((p.0, p.1))
                + Circle::new((0, 0), 5, c.filled())
                + Text::new(format!("{}", p.2), (7, -18), text.clone())
        }))
        .map_err(de)?;
    Ok(())
}

/// A log-axis tick as a short number: two significant digits, no float noise.
fn short(v: &f64) -> String {
    let digits = (1.0 - v.abs().log10().floor()).max(0.0) as usize;
    format!("{v:.digits$}")
}

/// Log axis bounds around `v`, a little beyond the extremes.
fn log_range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(l, h), x| (l.min(x), h.max(x)));
    if lo.is_finite() {
        (lo / 1.6, hi * 1.6)
    } else {
        (0.1, 10.0)
    }
}

impl Sweep<'_> {
    fn erosion<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult {
        let rows = self.rows;
        let (x0, x1) = log_range(rows.iter().map(|r| self.cost.get(r)));
        let bars = || {
            rows.iter().filter_map(|r| {
                let e = r.erosion_mean?;
                let s = r.erosion_std.unwrap_or(0.0);
                Some(((e - s) * MG_PER_G, (e + s) * MG_PER_G))
            })
        };
        let ymax = bars().map(|b| b.1).fold(0.0, f64::max).max(1e-3) * 1.15;
        let ymin = bars().map(|b| b.0).fold(0.0, f64::min) * 1.15;
        let mut chart = ChartBuilder::on(area)
            .caption("Erosion against cost", (FONT, 20))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(80)
            .build_cartesian_2d((x0..x1).log_scale(), ymin..ymax)
            .map_err(de)?;
        chart
            .configure_mesh()
            .x_desc(self.cost.label())
            .x_label_formatter(&short)
            .light_line_style(BLACK.mix(0.04))
            .y_desc("erosion (mg per g of grains), bars ±1 std over samples")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(de)?;
        // The finest resolution of the first variant: the band the others are judged by.
        if let Some(f) = rows
            .iter()
            .filter(|r| r.variant == self.variants[0])
            .max_by(|a, b| a.particles_per_dg.total_cmp(&b.particles_per_dg))
        {
            if let Some(e) = f.erosion_mean {
                let s = f.erosion_std.unwrap_or(0.0);
                let band = BLACK.mix(0.08).filled();
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(x0, (e - s) * MG_PER_G), (x1, (e + s) * MG_PER_G)],
                        band,
                    )))
                    .map_err(de)?
                    .label(format!("finest ({} per Dg) ±1 std", f.particles_per_dg))
                    .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 22, y + 6)], band));
            }
        }
        for (k, v) in self.variants.iter().enumerate() {
            let c = colour(k);
            let mine: Vec<&SweepRow> = rows.iter().filter(|r| &r.variant == v).collect();
            for r in &mine {
                if let (Some(e), Some(s)) = (r.erosion_mean, r.erosion_std) {
                    let x = self.cost.get(r);
                    chart
                        .draw_series(error_bar(
                            x,
                            (e - s) * MG_PER_G,
                            (e + s) * MG_PER_G,
                            0.0,
                            c.stroke_width(2),
                        ))
                        .map_err(de)?;
                }
            }
            let pts: Vec<(f64, f64, f64)> = mine
                .iter()
                .filter_map(|r| {
                    Some((
                        self.cost.get(r),
                        r.erosion_mean? * MG_PER_G,
                        r.particles_per_dg,
                    ))
                })
                .collect();
            variant_line(&mut chart, &pts, c, v.clone(), move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (22, 0)], c.stroke_width(2))
                    + Circle::new((11, 0), 4, c.filled())
            })?;
        }
        legend_box(&mut chart, SeriesLabelPosition::UpperRight)
    }

    fn hertz<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult {
        let rows = self.rows;
        let (x0, x1) = log_range(rows.iter().map(|r| self.cost.get(r)));
        let errs = || {
            rows.iter()
                .filter_map(|r| r.hertz_p0_error.map(|e| e * 100.0))
        };
        let (y0, y1) = log_range(errs().chain([5.0]));
        let mut chart = ChartBuilder::on(area)
            .caption("Hertz p0 error (eq. 31) against cost", (FONT, 20))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(80)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(de)?;
        chart
            .configure_mesh()
            .x_desc(format!("{} of the erosion scene", self.cost.label()))
            .x_label_formatter(&short)
            .y_label_formatter(&short)
            .light_line_style(BLACK.mix(0.04))
            .y_desc("largest p0 error over 10–50 MN/m (%)")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(de)?;
        let grey = BLACK.mix(0.5).stroke_width(1);
        chart
            .draw_series(std::iter::once(DashedPathElement::new(
                vec![(x0, 5.0), (x1, 5.0)],
                6,
                4,
                grey,
            )))
            .map_err(de)?
            .label("5 % bound of the Hertz check")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], grey));
        for (k, v) in self.variants.iter().enumerate() {
            let c = colour(k);
            let pts: Vec<(f64, f64, usize)> = rows
                .iter()
                .filter(|r| &r.variant == v)
                .filter_map(|r| {
                    Some((
                        self.cost.get(r),
                        r.hertz_p0_error? * 100.0,
                        r.hertz_per_radius,
                    ))
                })
                .collect();
            let label = format!("{v} (label: particles per radius)");
            variant_line(&mut chart, &pts, c, label, move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 22, y)], c.stroke_width(2))
            })?;
        }
        legend_box(&mut chart, SeriesLabelPosition::LowerLeft)
    }
}

impl Figure for Sweep<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let (left, right) = area.split_horizontally(SWEEP_SIZE.0 as i32 / 2);
        self.erosion(&left)?;
        self.hertz(&right)
    }
}

/// Draws the speed–accuracy chart as `out/stem.png` and `.svg`; `notes` go under the panels.
pub fn sweep_chart(
    rows: &[SweepRow],
    out: &Path,
    stem: &str,
    notes: &[String],
) -> Result<Vec<PathBuf>, PlotError> {
    if rows.is_empty() {
        return Err(PlotError::Input("no sweep rows to draw".into()));
    }
    let mut variants: Vec<String> = Vec::new();
    for r in rows {
        if !variants.contains(&r.variant) {
            variants.push(r.variant.clone());
        }
    }
    let mut all = vec![
        "Labels: particles per grain diameter (left) and per Hertz cylinder radius (right). \
         Cost: all samples side by side over the impacts, on the run's threads."
            .to_string(),
    ];
    all.extend(notes.iter().cloned());
    prepare_output(out)?;
    save_sized(
        &Sweep {
            rows,
            cost: Cost::of(rows),
            variants,
            notes: all,
        },
        out,
        stem,
        SWEEP_SIZE,
    )
}
