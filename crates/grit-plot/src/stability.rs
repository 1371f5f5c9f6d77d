//! The stability map (docs/performance.md) as one chart of three panels: Courant number against
//! hourglass coefficient (eq. 16), and contact stiffness (eqs. 24–25) against the time step for
//! the seed's contact model and for the plain penetration model (seed Fig. 2b).

use std::path::{Path, PathBuf};

use grit_erosion::studies::stability::{
    levels, spring_limit_cfl, Failure, Panel, StabilityPoint, Verdict,
};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::draw::{de, prepare_output, save_sized, with_notes, DrawResult, Figure, FONT};
use crate::PlotError;

/// Size of the three-panel chart, pixels.
const MAP_SIZE: (u32, u32) = (1650, 640);

const STABLE: RGBColor = RGBColor(44, 160, 44);
const GAIN: RGBColor = RGBColor(255, 127, 14);
const UNSTABLE: RGBColor = RGBColor(214, 39, 40);

struct Map<'a> {
    points: &'a [StabilityPoint],
    notes: Vec<String>,
}

/// The label of a segmented-axis tick: the value of the level it marks.
fn tick(v: &SegmentValue<i32>, values: &[f64]) -> String {
    match v {
        SegmentValue::CenterOf(i) | SegmentValue::Exact(i) => values
            .get(*i as usize)
            .map(|x| format!("{x}"))
            .unwrap_or_default(),
        SegmentValue::Last => String::new(),
    }
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    which: Panel,
    points: &[&StabilityPoint],
) -> DrawResult {
    let (title, y_desc) = match which {
        Panel::CflHourglass => (
            "Courant number × hourglass α (seed contact)",
            "hourglass coefficient α (eq. 16)",
        ),
        Panel::StiffnessStep => (
            "contact stiffness × time step (seed contact)",
            "contact stiffness / default k (eqs. 24–25)",
        ),
        Panel::StiffnessStepPenetration => (
            "contact stiffness × time step (penetration contact)",
            "contact stiffness / default k (eqs. 24–25)",
        ),
    };
    let yv = |p: &StabilityPoint| which.y(p);
    let xs = levels(points.iter().map(|p| p.cfl));
    let ys = levels(points.iter().map(|p| yv(p)));
    let at = |v: &[f64], x: f64| v.iter().position(|&u| u == x).unwrap_or(0) as i32;
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 18))
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(70)
        // A segmented 0..n-1 has n segments: one per value.
        .build_cartesian_2d(
            (0..xs.len() as i32 - 1).into_segmented(),
            (0..ys.len() as i32 - 1).into_segmented(),
        )
        .map_err(de)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(xs.len())
        .y_labels(ys.len())
        .x_label_formatter(&|v| tick(v, &xs))
        .y_label_formatter(&|v| tick(v, &ys))
        .x_desc(match which {
            Panel::CflHourglass => "Courant number",
            _ => "time step as a Courant number, dt·c/h",
        })
        .y_desc(y_desc)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .draw()
        .map_err(de)?;
    if which != Panel::CflHourglass {
        // Cells where a spring alone would be unstable (dt > 2√(m/k)).
        let grey = BLACK.mix(0.12).filled();
        for (j, &k) in ys.iter().enumerate() {
            for (i, &c) in xs.iter().enumerate() {
                if c > spring_limit_cfl(k) {
                    let (i, j) = (i as i32, j as i32);
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [
                                (SegmentValue::Exact(i), SegmentValue::Exact(j)),
                                (SegmentValue::Exact(i + 1), SegmentValue::Exact(j + 1)),
                            ],
                            grey,
                        )))
                        .map_err(de)?;
                }
            }
        }
    }
    for p in points {
        let c = (
            SegmentValue::CenterOf(at(&xs, p.cfl)),
            SegmentValue::CenterOf(at(&ys, yv(p))),
        );
        match p.verdict {
            Verdict::Stable => {
                chart
                    .draw_series(std::iter::once(Circle::new(c, 8, STABLE.filled())))
                    .map_err(de)?;
            }
            Verdict::EnergyGain => {
                chart
                    .draw_series(std::iter::once(TriangleMarker::new(c, 10, GAIN.filled())))
                    .map_err(de)?;
            }
            Verdict::Unstable => {
                let style = TextStyle::from((FONT, 15).into_font()).color(&UNSTABLE);
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at(c)
                            + Cross::new((0, 0), 7, UNSTABLE.stroke_width(3))
                            + Text::new(p.failure.map_or("?", Failure::code), (10, -18), style),
                    ))
                    .map_err(de)?;
            }
        }
    }
    Ok(())
}

impl Figure for Map<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let area = with_notes(root, &self.notes)?;
        let panels = [
            Panel::CflHourglass,
            Panel::StiffnessStep,
            Panel::StiffnessStepPenetration,
        ];
        let shown: Vec<Panel> = panels
            .into_iter()
            .filter(|w| self.points.iter().any(|p| p.panel == *w))
            .collect();
        let cells = area.split_evenly((1, shown.len().max(1)));
        for (which, cell) in shown.iter().zip(&cells) {
            let pts: Vec<&StabilityPoint> =
                self.points.iter().filter(|p| p.panel == *which).collect();
            panel(cell, *which, &pts)?;
        }
        Ok(())
    }
}

/// Draws the stability map as `out/stem.png` and `.svg`; `notes` go under the legend.
pub fn stability_chart(
    points: &[StabilityPoint],
    out: &Path,
    stem: &str,
    notes: &[String],
) -> Result<Vec<PathBuf>, PlotError> {
    if points.is_empty() {
        return Err(PlotError::Input("no stability points to draw".into()));
    }
    let codes = Failure::legend();
    let mut all = vec![
        format!(
            "Green dot: stable. Orange triangle: ran to the end, but total energy rose above {}× \
             its start. Red cross: the engine stopped; the letter names its diagnostic ({codes}).",
            grit_erosion::studies::stability::ENERGY_GAIN_LIMIT
        ),
        "Grey cells: a contact spring alone is unstable there, dt > 2√(m/k), i.e. \
         Courant number > 2/√(k/default)."
            .to_string(),
    ];
    all.extend(notes.iter().cloned());
    prepare_output(out)?;
    save_sized(&Map { points, notes: all }, out, stem, MAP_SIZE)
}
