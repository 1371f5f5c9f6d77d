//! The six chart kinds. Masses are shown in g (grains) and mg (surface) per metre of
//! depth, since the engine is 2D and its masses are per metre; erosion is shown in mg of
//! surface lost per g of grains (10⁻³ of the dimensionless erosion), so the slope of the
//! mass-loss chart reads directly as erosion.

use std::ops::Range;

use grit_erosion::impact::aggregate::cumulative_series;
use grit_erosion::{CampaignResults, CellResult, Stationarity};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::analysis::{series_label, Analysis, Series, HV_GPA};
use crate::draw::{
    chart_on, colour, de, draw_mesh, error_bar, file_safe, hollow_notes, line_key, marker_style,
    save, top, with_notes, Axes, DrawResult, Figure, FONT,
};
use crate::{PlotError, PlotInput, RawSeries, Report};

/// Erosion (dimensionless) to mg per g.
const MG_PER_G: f64 = 1e3;
/// kg to g, for grain mass.
const G_PER_KG: f64 = 1e3;
/// kg to mg, for mass loss.
const MG_PER_KG: f64 = 1e6;
const EROSION_AXIS: &str = "erosion (mg surface lost per g of grains)";
/// Angles at which model curves are evaluated: (0°, 90°] in half degrees.
fn curve_angles() -> impl Iterator<Item = f64> {
    (1..=180).map(|k| 0.5 * k as f64)
}

/// File stem of cell `i`'s chart of `kind`: `kind_cNN_<angle>deg_<shape and swept values>`.
pub(crate) fn cell_stem(kind: &str, i: usize, c: &CellResult) -> String {
    format!(
        "{kind}_c{i:02}_{}deg_{}",
        c.angle_deg,
        file_safe(&series_label(&c.shape, &c.swept))
    )
}

fn cell_label(c: &CellResult) -> String {
    format!("{}°, {}", c.angle_deg, series_label(&c.shape, &c.swept))
}

/// Lower end of a value axis: 0, or 10 % below the lowest value when that is negative.
fn bottom(values: impl Iterator<Item = f64>) -> f64 {
    let m = values.filter(|v| v.is_finite()).fold(0.0, f64::min);
    1.1 * m
}

pub(crate) fn legend_box<'a, DB: DrawingBackend + 'a, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    pos: SeriesLabelPosition,
) -> DrawResult
where
    X: plotters::coord::ranged1d::Ranged<ValueType = f64>,
    Y: plotters::coord::ranged1d::Ranged<ValueType = f64>,
{
    chart
        .configure_series_labels()
        .position(pos)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font((FONT, 14))
        .draw()
        .map_err(de)
}

/// Axes of cumulative surface mass loss against cumulative grain mass, from 0.
fn mass_axes<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: String,
    xmax: f64,
    ymax: f64,
) -> Result<Axes<'_, DB>, String> {
    let mut chart = chart_on(area, caption, 0.0..xmax, 0.0..ymax)?;
    draw_mesh(
        chart
            .configure_mesh()
            .x_desc("cumulative grain mass (g per m of depth)")
            .y_desc("cumulative surface mass loss (mg per m of depth)"),
    )?;
    Ok(chart)
}

/// Axes of a value (`y`, described by `y_desc`) against the impact angle, 0° to 95°.
fn angle_axes<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    y: Range<f64>,
    y_desc: &str,
) -> Result<Axes<'a, DB>, String> {
    let mut chart = chart_on(area, caption, 0.0..95.0, y)?;
    draw_mesh(
        chart
            .configure_mesh()
            .x_desc("impact angle α (degrees from the surface)")
            .x_labels(20)
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_desc(y_desc),
    )?;
    Ok(chart)
}

fn dash_key(
    style: ShapeStyle,
    dash: i32,
    gap: i32,
) -> impl Fn((i32, i32)) -> DashedPathElement<std::vec::IntoIter<(i32, i32)>, i32> {
    move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 22, y)], dash, gap, style)
}

/// A legend entry for the hollow markers of cells whose erosion is no stationary rate, when any
/// is drawn.
fn hollow_key<DB: DrawingBackend>(chart: &mut Axes<'_, DB>, any: bool) -> DrawResult {
    if any {
        let style = marker_style(RGBColor(90, 90, 90), Some(false));
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(de)?
            .label("hollow: not steady or not balanced (docs/erosion.md)")
            .legend(move |(x, y)| Circle::new((x + 11, y), 5, style));
    }
    Ok(())
}

/// Whether any of `cells` is a cell whose erosion is no stationary rate.
fn any_hollow(mut cells: impl Iterator<Item = Stationarity>) -> bool {
    cells.any(|s| s.is_rate() == Some(false))
}

/// A sample's cumulative (grain g/m, loss mg/m), in impact order.
fn sample_curve(r: &RawSeries) -> Vec<(f64, f64)> {
    cumulative_series(&r.impacts_in_order())
        .iter()
        .map(|p| (p.grain_mass_kg * G_PER_KG, p.mass_loss_kg * MG_PER_KG))
        .collect()
}

// ---------------------------------------------------------------- mass loss (Figs. 8, 10b)

struct MassLoss<'a> {
    cell: &'a CellResult,
    /// Each sample's cumulative (grain g/m, loss mg/m); empty without raw series.
    samples: Vec<Vec<(f64, f64)>>,
    window: usize,
    notes: Vec<String>,
}

impl Figure for MassLoss<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let c = self.cell;
        let col = colour(0);
        let mean: Vec<(f64, f64, Option<f64>)> = c
            .mean_series
            .iter()
            .map(|p| {
                (
                    p.grain_mass_kg * G_PER_KG,
                    p.mass_loss_kg * MG_PER_KG,
                    p.mass_loss_std_kg.map(|s| s * MG_PER_KG),
                )
            })
            .collect();
        let all = || self.samples.iter().flatten().copied();
        let xmax = top(all().map(|p| p.0).chain(mean.iter().map(|p| p.0)));
        let ymax = top(all()
            .map(|p| p.1)
            .chain(mean.iter().map(|p| p.1 + p.2.unwrap_or(0.0))));
        let caption = format!(
            "Mass loss against grain mass: {} ({} samples)",
            cell_label(c),
            c.samples_reported
        );
        let mut chart = mass_axes(&area, caption, xmax, ymax)?;
        if !self.samples.is_empty() {
            let faint = col.mix(0.45).stroke_width(1);
            for (k, s) in self.samples.iter().enumerate() {
                let drawn = chart
                    .draw_series(LineSeries::new(s.iter().copied(), faint))
                    .map_err(de)?;
                if k == 0 {
                    drawn
                        .label(format!("each sample ({})", self.samples.len()))
                        .legend(line_key(faint));
                }
            }
        } else if mean.iter().any(|p| p.2.is_some()) {
            let band: Vec<(f64, f64)> = mean
                .iter()
                .map(|p| (p.0, p.1 + p.2.unwrap_or(0.0)))
                .chain(
                    mean.iter()
                        .rev()
                        .map(|p| (p.0, (p.1 - p.2.unwrap_or(0.0)).max(0.0))),
                )
                .collect();
            let fill = col.mix(0.2).filled();
            chart
                .draw_series(std::iter::once(Polygon::new(band, fill)))
                .map_err(de)?
                .label("mean ± 1 std over samples")
                .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 22, y + 6)], fill));
        }
        let bold = col.stroke_width(3);
        chart
            .draw_series(LineSeries::new(mean.iter().map(|p| (p.0, p.1)), bold))
            .map_err(de)?
            .label("mean of the samples")
            .legend(line_key(bold));
        if mean.len() >= self.window && self.window >= 2 {
            let tail = &mean[mean.len() - self.window..];
            let stationary = c.stationary();
            let marks = marker_style(BLACK, stationary);
            chart
                .draw_series(tail.iter().map(|p| Circle::new((p.0, p.1), 3, marks)))
                .map_err(de)?
                .label(format!(
                    "last {} points (erosion window){}",
                    self.window,
                    if stationary == Some(false) {
                        ", hollow: not steady or not balanced"
                    } else {
                        ""
                    }
                ))
                .legend(move |(x, y)| Circle::new((x + 11, y), 3, marks));
            if let Some(e) = c.erosion_mean {
                // The cell's erosion is the mean of the samples' slopes; drawn through the
                // centroid of the mean series' window it shows that slope in place.
                let n = tail.len() as f64;
                let xc = tail.iter().map(|p| p.0).sum::<f64>() / n;
                let yc = tail.iter().map(|p| p.1).sum::<f64>() / n;
                let slope = e * MG_PER_G;
                let (x0, x1) = (tail[0].0, tail[tail.len() - 1].0);
                let x0 = x0 - 0.15 * (x1 - x0);
                let line = BLACK.stroke_width(2);
                chart
                    .draw_series(DashedLineSeries::new(
                        [x0, x1].map(|x| (x, yc + slope * (x - xc))),
                        8,
                        5,
                        line,
                    ))
                    .map_err(de)?
                    .label(format!(
                        "last-{} fit: slope = erosion = {:.3} mg/g (mean of sample slopes)",
                        self.window, slope
                    ))
                    .legend(dash_key(line, 6, 4));
            }
        }
        legend_box(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// One mass-loss chart per cell with impacts: faint samples (or a ±std band), bold mean,
/// the erosion window and its fit line.
pub fn mass_loss(
    input: &PlotInput,
    out: &std::path::Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    let results = &input.results;
    for (i, c) in results.cells.iter().enumerate() {
        if c.mean_series.is_empty() {
            report.notes.push(format!(
                "cell {i} ({}): no impacts, no mass-loss chart",
                cell_label(c)
            ));
            continue;
        }
        let samples: Vec<Vec<(f64, f64)>> = input
            .raw
            .iter()
            .flatten()
            .filter(|r| r.cell as usize == i && !r.impacts.is_empty())
            .map(sample_curve)
            .collect();
        let mut notes = Vec::new();
        if input.raw.is_none() {
            notes.push(
                "No per-impact series in this file (grit run --raw or grit results --raw \
                 give them): the band is ±1 std of the samples' cumulative mass loss."
                    .to_string(),
            );
        }
        if c.samples_without_slope > 0 {
            notes.push(format!(
                "{} of {} samples have fewer than {} impacts and no slope.",
                c.samples_without_slope, c.samples_reported, results.slope_window
            ));
        }
        if c.erosion_mean.is_none() {
            notes.push("No sample has a slope yet: no erosion, no fit line.".to_string());
        }
        if c.partial {
            notes.push(format!(
                "Partial: {} of {} samples reported.",
                c.samples_reported, c.samples_planned
            ));
        }
        // One line per condition: a reason can list three, too long for one line.
        match &c.steady_state {
            Some(s) => {
                let head = if s.steady {
                    "At steady state:"
                } else {
                    "Not at steady state (docs/erosion.md):"
                };
                for (k, part) in s.reason.split("; ").enumerate() {
                    notes.push(if k == 0 {
                        format!("{head} {part}")
                    } else {
                        format!("    {part}")
                    });
                }
            }
            None => {
                notes.push("Steady state not checked (results written before the check).".into())
            }
        }
        if let Some(b) = c.damage_balance.filter(|b| !b.holds()) {
            notes.push(format!(
                "Not balanced (docs/erosion.md, The damage balance): {}",
                b.describe()
            ));
        }
        let fig = MassLoss {
            cell: c,
            samples,
            window: results.slope_window,
            notes,
        };
        report
            .files
            .extend(save(&fig, out, &cell_stem("mass_loss", i, c))?);
    }
    Ok(())
}

// ----------------------------------------------- one sample at every angle (Fig. 9)

/// One sample's mass-loss curve in a cell of the Fig. 9 chart.
struct AngleCurve {
    angle_deg: f64,
    /// Cumulative (grain g/m, loss mg/m).
    points: Vec<(f64, f64)>,
    /// Whether the cell's erosion is a stationary rate, and if not, why.
    stationarity: Stationarity,
}

struct SampleAngles {
    label: String,
    sample: u32,
    /// One curve per angle, by angle.
    curves: Vec<AngleCurve>,
    window: usize,
    notes: Vec<String>,
}

impl Figure for SampleAngles {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let all = || self.curves.iter().flat_map(|c| c.points.iter().copied());
        let xmax = top(all().map(|p| p.0));
        let ymax = top(all().map(|p| p.1));
        let caption = format!(
            "Mass loss of one surface sample at each angle: {}, sample {}",
            self.label, self.sample
        );
        let mut chart = mass_axes(&area, caption, xmax, ymax)?;
        for (i, curve) in self.curves.iter().enumerate() {
            let (angle, pts) = (curve.angle_deg, &curve.points);
            let line = colour(i).stroke_width(2);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), line))
                .map_err(de)?
                .label(format!("{angle}°"))
                .legend(line_key(line));
            if pts.len() >= self.window && self.window >= 2 {
                let marks = marker_style(colour(i), curve.stationarity.is_rate());
                chart
                    .draw_series(
                        pts[pts.len() - self.window..]
                            .iter()
                            .map(|p| Circle::new(*p, 3, marks)),
                    )
                    .map_err(de)?;
            }
        }
        hollow_key(
            &mut chart,
            any_hollow(self.curves.iter().map(|c| c.stationarity)),
        )?;
        legend_box(&mut chart, SeriesLabelPosition::UpperLeft)
    }
}

/// How many sample numbers get a one-sample-at-every-angle chart (the seed's Fig. 9 has 2).
const SAMPLES_BY_ANGLE: usize = 2;

/// Per series and for its two lowest sample numbers: that sample's mass-loss curve at every
/// angle on one axes, the seed's Fig. 9 (a, b). Needs raw series at two angles or more.
pub fn sample_by_angle(
    input: &PlotInput,
    out: &std::path::Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    let Some(raw) = &input.raw else {
        report.notes.push(
            "no per-impact series (grit run --raw or grit results --raw give them): \
             no one-sample-per-angle chart"
                .into(),
        );
        return Ok(());
    };
    let cells = &input.results.cells;
    let mut labels: Vec<String> = Vec::new();
    for c in cells {
        let l = series_label(&c.shape, &c.swept);
        if !labels.contains(&l) {
            labels.push(l);
        }
    }
    let window = input.results.slope_window;
    for label in labels {
        let in_series = |r: &&RawSeries| {
            let c = &cells[r.cell as usize];
            series_label(&c.shape, &c.swept) == label && !r.impacts.is_empty()
        };
        let numbers: std::collections::BTreeSet<u32> =
            raw.iter().filter(in_series).map(|r| r.sample).collect();
        let mut drawn = 0;
        for &k in numbers.iter().take(SAMPLES_BY_ANGLE) {
            let mut curves: Vec<AngleCurve> = raw
                .iter()
                .filter(in_series)
                .filter(|r| r.sample == k)
                .map(|r| {
                    let c = &cells[r.cell as usize];
                    AngleCurve {
                        angle_deg: c.angle_deg,
                        points: sample_curve(r),
                        stationarity: c.stationarity(),
                    }
                })
                .collect();
            if curves.len() < 2 {
                continue;
            }
            curves.sort_by(|a, b| a.angle_deg.total_cmp(&b.angle_deg));
            let mut notes = vec![format!(
                "Dots: the last {window} impacts, whose slope is the sample's erosion."
            )];
            notes.extend(hollow_notes(curves.iter().map(|c| c.stationarity)));
            let fig = SampleAngles {
                label: label.clone(),
                sample: k,
                curves,
                window,
                notes,
            };
            let stem = format!("sample_by_angle_{}_s{k}", file_safe(&label));
            report.files.extend(save(&fig, out, &stem)?);
            drawn += 1;
        }
        if drawn == 0 {
            report.notes.push(format!(
                "{label}: no sample has per-impact series at two angles or more, \
                 no one-sample-per-angle chart"
            ));
        }
    }
    Ok(())
}

// --------------------------------------------------- erosion against angle (Figs. 11a, 12a)

struct Angle<'a> {
    an: &'a Analysis,
    notes: Vec<String>,
}

/// A model curve: (angle in degrees, erosion in mg/g).
type Curve = Vec<(f64, f64)>;

/// The fitted and the published-exponent Oka curves of a series; empty when absent.
fn oka_points(s: &Series) -> (Curve, Curve) {
    let curve = |m: &grit_erosion::OkaModel| -> Curve {
        curve_angles()
            .map(|a| (a, m.erosion(a) * MG_PER_G))
            .collect()
    };
    (
        s.oka
            .fit
            .as_ref()
            .map(|f| curve(&f.model))
            .unwrap_or_default(),
        s.oka.published.as_ref().map(curve).unwrap_or_default(),
    )
}

impl Figure for Angle<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let curves: Vec<_> = self.an.series.iter().map(oka_points).collect();
        let bars = || {
            self.an.series.iter().flat_map(|s| {
                s.points.iter().flat_map(|p| {
                    let d = p.std.unwrap_or(0.0);
                    [(p.mean + d) * MG_PER_G, (p.mean - d) * MG_PER_G]
                })
            })
        };
        let model = || {
            curves
                .iter()
                .flat_map(|(f, p)| f.iter().chain(p).map(|q| q.1))
        };
        let ymax = top(bars().chain(model()));
        let ymin = bottom(bars());
        let mut chart = angle_axes(
            &area,
            "Erosion against impact angle, with Oka's model",
            ymin..ymax,
            EROSION_AXIS,
        )?;
        for (i, (s, (fit, published))) in self.an.series.iter().zip(&curves).enumerate() {
            let c = colour(i);
            let bar = c.stroke_width(1);
            for p in &s.points {
                if let Some(d) = p.std {
                    let (lo, hi) = ((p.mean - d) * MG_PER_G, (p.mean + d) * MG_PER_G);
                    chart
                        .draw_series(error_bar(p.angle_deg, lo, hi, 1.2, bar))
                        .map_err(de)?;
                }
            }
            let line = c.stroke_width(2);
            chart
                .draw_series(s.points.iter().map(|p| {
                    Circle::new(
                        (p.angle_deg, p.mean * MG_PER_G),
                        5,
                        marker_style(c, p.stationarity.is_rate()),
                    )
                }))
                .map_err(de)?;
            chart
                .draw_series(LineSeries::new(
                    s.points.iter().map(|p| (p.angle_deg, p.mean * MG_PER_G)),
                    line,
                ))
                .map_err(de)?
                .label(format!("{}: simulated, bars ±1 std over samples", s.label))
                .legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (22, 0)], line)
                        + Circle::new((11, 0), 4, c.filled())
                });
            if !fit.is_empty() {
                chart
                    .draw_series(DashedLineSeries::new(fit.clone(), 9, 5, line))
                    .map_err(de)?
                    .label(format!("{}: Oka fit (n1, n2, E90 fitted)", s.label))
                    .legend(dash_key(line, 7, 4));
            }
            if !published.is_empty() {
                chart
                    .draw_series(DashedLineSeries::new(published.clone(), 2, 4, line))
                    .map_err(de)?
                    .label(format!("{}: Oka silica exponents × simulated E90", s.label))
                    .legend(dash_key(line, 2, 3));
            }
        }
        let drawn = self.an.series.iter().flat_map(|s| &s.points);
        hollow_key(&mut chart, any_hollow(drawn.map(|p| p.stationarity)))?;
        legend_box(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Erosion against angle per series, with error bars and both Oka curves.
pub fn erosion_vs_angle(
    an: &Analysis,
    out: &std::path::Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    if an.series.is_empty() {
        report.notes.push(
            "no cell has an erosion yet (every sample is short of the slope window): \
             no angle charts"
                .into(),
        );
        return Ok(());
    }
    let fig = Angle {
        an,
        notes: an
            .notes
            .iter()
            .filter(|n| !n.starts_with("modified Oka") && !n.starts_with("no modified"))
            .chain(&an.hollow_notes)
            .cloned()
            .collect(),
    };
    report.files.extend(save(&fig, out, "erosion_vs_angle")?);
    report.notes.extend(an.notes.iter().cloned());
    Ok(())
}

// ------------------------------------------------------------ normalised at 45° (Fig. 12b)

struct Normalised<'a> {
    an: &'a Analysis,
    /// (series index, erosion at 45°).
    shown: Vec<(usize, f64)>,
    notes: Vec<String>,
}

impl Figure for Normalised<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let reference = grit_erosion::OkaModel::silica(HV_GPA, 1.0);
        let g45 = reference.g(45.0);
        let oka: Vec<(f64, f64)> = curve_angles().map(|a| (a, reference.g(a) / g45)).collect();
        let scaled = |i: usize, e45: f64| {
            self.an.series[i].points.iter().map(move |p| {
                let d = p.std.unwrap_or(0.0);
                (
                    p.angle_deg,
                    p.mean / e45,
                    d / e45,
                    p.std.is_some(),
                    p.stationarity.is_rate(),
                )
            })
        };
        let values = || {
            self.shown
                .iter()
                .flat_map(|&(i, e)| scaled(i, e).flat_map(|p| [p.1 + p.2, p.1 - p.2]))
        };
        let ymax = top(values().chain(oka.iter().map(|p| p.1)));
        let ymin = bottom(values());
        let mut chart = angle_axes(
            &area,
            "Erosion normalised by its value at 45°",
            ymin..ymax,
            "erosion / erosion at 45° (dimensionless)",
        )?;
        let grey = BLACK.mix(0.6).stroke_width(2);
        chart
            .draw_series(DashedLineSeries::new(oka, 9, 5, grey))
            .map_err(de)?
            .label("Oka, silica exponents: g(α)/g(45°)")
            .legend(dash_key(grey, 7, 4));
        for &(i, e45) in &self.shown {
            let c = colour(i);
            for (a, m, d, has, _) in scaled(i, e45) {
                if has {
                    chart
                        .draw_series(error_bar(a, m - d, m + d, 1.2, c.stroke_width(1)))
                        .map_err(de)?;
                }
            }
            let line = c.stroke_width(2);
            chart
                .draw_series(
                    scaled(i, e45).map(|p| Circle::new((p.0, p.1), 5, marker_style(c, p.4))),
                )
                .map_err(de)?;
            chart
                .draw_series(LineSeries::new(scaled(i, e45).map(|p| (p.0, p.1)), line))
                .map_err(de)?
                .label(format!(
                    "{}: simulated, bars ±1 std / E(45°)",
                    self.an.series[i].label
                ))
                .legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (22, 0)], line)
                        + Circle::new((11, 0), 4, c.filled())
                });
        }
        let drawn = self
            .shown
            .iter()
            .flat_map(|&(i, _)| &self.an.series[i].points);
        hollow_key(&mut chart, any_hollow(drawn.map(|p| p.stationarity)))?;
        legend_box(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Erosion divided by the erosion at 45°, per series that has a positive 45° value.
pub fn normalised(
    an: &Analysis,
    out: &std::path::Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    let mut shown = Vec::new();
    let mut notes = Vec::new();
    for (i, s) in an.series.iter().enumerate() {
        match s.points.iter().find(|p| p.angle_deg == 45.0) {
            Some(p) if p.mean > 0.0 => shown.push((i, p.mean)),
            Some(_) => notes.push(format!("{}: erosion at 45° is zero, not drawn", s.label)),
            None => notes.push(format!("{}: no 45° cell, not drawn", s.label)),
        }
    }
    if shown.is_empty() {
        if !an.series.is_empty() {
            report
                .notes
                .push("no series has a positive erosion at 45°: no normalised chart".into());
        }
        return Ok(());
    }
    let mut chart_notes = notes.clone();
    chart_notes.extend(hollow_notes(
        shown
            .iter()
            .flat_map(|&(i, _)| an.series[i].points.iter().map(|p| p.stationarity)),
    ));
    let fig = Normalised {
        an,
        shown,
        notes: chart_notes,
    };
    report
        .files
        .extend(save(&fig, out, "erosion_normalised_45deg")?);
    report.notes.extend(notes);
    Ok(())
}

// -------------------------------------------------------------- modified Oka (Fig. 14)

struct ModifiedChart<'a> {
    an: &'a Analysis,
    notes: Vec<String>,
}

impl Figure for ModifiedChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let Ok(m) = &self.an.modified else {
            return Err("no modified-Oka model".into());
        };
        let curve = |model: &grit_erosion::ModifiedOkaModel, (e, an): (f64, f64)| -> Curve {
            curve_angles()
                .map(|a| (a, model.erosion(a, e, an) * MG_PER_G))
                .collect()
        };
        let seeds: Vec<_> = m.factors.iter().map(|&f| curve(&m.seed, f)).collect();
        let fits: Vec<_> = match &m.fitted {
            Ok(model) => m.factors.iter().map(|&f| curve(model, f)).collect(),
            Err(_) => Vec::new(),
        };
        let points = || {
            m.series.iter().flat_map(|&i| {
                self.an.series[i].points.iter().flat_map(|p| {
                    let d = p.std.unwrap_or(0.0);
                    [(p.mean + d) * MG_PER_G, (p.mean - d) * MG_PER_G]
                })
            })
        };
        let ymax = top(points().chain(seeds.iter().chain(&fits).flatten().map(|p| p.1)));
        let ymin = bottom(points());
        let mut chart = angle_axes(
            &area,
            "Shape-modified Oka model (hexagon reference) against the simulation",
            ymin..ymax,
            EROSION_AXIS,
        )?;
        for (k, &i) in m.series.iter().enumerate() {
            let s = &self.an.series[i];
            let c = colour(i);
            for p in &s.points {
                if let Some(d) = p.std {
                    let (lo, hi) = ((p.mean - d) * MG_PER_G, (p.mean + d) * MG_PER_G);
                    chart
                        .draw_series(error_bar(p.angle_deg, lo, hi, 1.2, c.stroke_width(1)))
                        .map_err(de)?;
                }
            }
            chart
                .draw_series(s.points.iter().map(|p| {
                    Circle::new(
                        (p.angle_deg, p.mean * MG_PER_G),
                        5,
                        marker_style(c, p.stationarity.is_rate()),
                    )
                }))
                .map_err(de)?
                .label(format!("{}: simulated, bars ±1 std", s.label))
                .legend(move |(x, y)| Circle::new((x + 11, y), 5, c.filled()));
            let line = c.stroke_width(2);
            if let Some(f) = fits.get(k) {
                chart
                    .draw_series(LineSeries::new(f.iter().copied(), line))
                    .map_err(de)?
                    .label(format!("{}: modified Oka, fitted n3..n6", s.label))
                    .legend(line_key(line));
            }
            chart
                .draw_series(DashedLineSeries::new(seeds[k].iter().copied(), 9, 5, line))
                .map_err(de)?
                .label(format!("{}: modified Oka, seed's n3..n6", s.label))
                .legend(dash_key(line, 7, 4));
        }
        let drawn = m.series.iter().flat_map(|&i| &self.an.series[i].points);
        hollow_key(&mut chart, any_hollow(drawn.map(|p| p.stationarity)))?;
        legend_box(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// The shape-modified Oka model against the simulated points, when there is one.
pub fn modified_oka(
    an: &Analysis,
    out: &std::path::Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    if an.modified.is_err() {
        return Ok(());
    }
    let mut notes: Vec<String> = an
        .notes
        .iter()
        .filter(|n| n.starts_with("modified Oka") || n.contains("Oka fit n1"))
        .cloned()
        .collect();
    if let Ok(m) = &an.modified {
        notes.extend(hollow_notes(
            m.series
                .iter()
                .flat_map(|&i| an.series[i].points.iter().map(|p| p.stationarity)),
        ));
    }
    let fig = ModifiedChart { an, notes };
    report.files.extend(save(&fig, out, "modified_oka")?);
    Ok(())
}

// ----------------------------------------------------------------- convergence (Fig. 10a)

struct Convergence<'a> {
    results: &'a CampaignResults,
}

impl Figure for Convergence<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let cells = || {
            self.results
                .cells
                .iter()
                .filter(|c| !c.convergence.is_empty())
        };
        let stationarity = |c: &CellResult| c.stationarity();
        let area = with_notes(root, &hollow_notes(cells().map(stationarity)))?;
        let values = || {
            cells().flat_map(|c| {
                c.convergence.iter().flat_map(|p| {
                    let d = p.erosion_std.unwrap_or(0.0);
                    [
                        (p.erosion_mean + d) * MG_PER_G,
                        (p.erosion_mean - d) * MG_PER_G,
                    ]
                })
            })
        };
        let nmax = cells()
            .flat_map(|c| c.convergence.iter().map(|p| p.samples))
            .max()
            .unwrap_or(1);
        let (ymin, ymax) = (bottom(values()), top(values()));
        let mut chart = chart_on(
            &area,
            "Convergence of erosion with the number of samples",
            0.5..(nmax as f64 + 0.5),
            ymin..ymax,
        )?;
        draw_mesh(
            chart
                .configure_mesh()
                .x_desc("number of samples k (the first k with a slope)")
                .y_desc(EROSION_AXIS)
                .x_labels((nmax + 1).min(26))
                // Sample counts are whole numbers: ticks between them stay blank.
                .x_label_formatter(&|v| {
                    if (v - v.round()).abs() < 1e-9 {
                        format!("{v:.0}")
                    } else {
                        String::new()
                    }
                }),
        )?;
        for (i, c) in cells().enumerate() {
            let col = colour(i);
            let bar = col.mix(0.5).stroke_width(1);
            for p in &c.convergence {
                if let Some(d) = p.erosion_std {
                    let m = p.erosion_mean;
                    chart
                        .draw_series(error_bar(
                            p.samples as f64,
                            (m - d) * MG_PER_G,
                            (m + d) * MG_PER_G,
                            0.01 * nmax as f64,
                            bar,
                        ))
                        .map_err(de)?;
                }
            }
            let line = col.stroke_width(2);
            let points = || {
                c.convergence
                    .iter()
                    .map(|p| (p.samples as f64, p.erosion_mean * MG_PER_G))
            };
            let marks = marker_style(col, stationarity(c).is_rate());
            chart
                .draw_series(points().map(|p| Circle::new(p, 4, marks)))
                .map_err(de)?;
            chart
                .draw_series(LineSeries::new(points(), line))
                .map_err(de)?
                .label(format!(
                    "{}: mean of the first k, bars ±1 std",
                    cell_label(c)
                ))
                .legend(line_key(line));
        }
        hollow_key(&mut chart, any_hollow(cells().map(stationarity)))?;
        legend_box(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Running erosion mean (±std) against the number of samples, one line per cell.
pub fn convergence(
    results: &CampaignResults,
    out: &std::path::Path,
    report: &mut Report,
) -> Result<(), PlotError> {
    if results.cells.iter().all(|c| c.convergence.is_empty()) {
        report
            .notes
            .push("no cell has a sample with a slope: no convergence chart".into());
        return Ok(());
    }
    report
        .files
        .extend(save(&Convergence { results }, out, "convergence")?);
    Ok(())
}
