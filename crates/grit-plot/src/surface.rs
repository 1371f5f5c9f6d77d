//! Pictures of an eroded surface after an impact, after the seed's Fig. 13: every particle a
//! disc of its spacing coloured by damage or plastic strain (fixed boundary particles pale),
//! the grain's outline over it, axes in µm at equal scale, and a colour bar.

use std::path::Path;

use grit_sph::particles::KINEMATIC;
use grit_sph::{Particles, Vector};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::draw::{de, DrawResult, FONT};
use crate::PlotError;

/// µm per metre, for the axes.
const UM: f64 = 1e6;
/// Width of the plot area in pixels; the height follows from the data at equal scale.
const PLOT_W: u32 = 1000;
/// Tallest plot area in pixels (a deep surface is drawn narrower instead).
const PLOT_H_MAX: u32 = 800;
const TITLE_H: u32 = 44;
const LEFT_LABELS: u32 = 92;
const BOTTOM_LABELS: u32 = 56;
const TOP_PAD: u32 = 8;
const RIGHT_PAD: u32 = 16;
const BAR_AREA_W: u32 = 150;
const NOTE_LINE: u32 = 19;
/// Plastic strain colours saturate at this quantile of the strained particles, so a few
/// extreme particles under the grain's corners do not wash out the rest.
const STRAIN_QUANTILE: f64 = 0.995;
/// ... when the largest strain exceeds that quantile by this factor.
const SATURATE_ABOVE: f64 = 1.5;

/// The particle field a surface picture is coloured by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SurfaceField {
    /// Johnson–Cook damage D (seed eq. 19), 0 to 1.
    Damage,
    /// Equivalent plastic strain.
    PlasticStrain,
}

impl SurfaceField {
    /// Both fields, in the order pictures are made.
    pub const ALL: [SurfaceField; 2] = [SurfaceField::Damage, SurfaceField::PlasticStrain];

    /// File-name stem: `damage` or `plastic-strain`.
    pub fn stem(self) -> &'static str {
        match self {
            SurfaceField::Damage => "damage",
            SurfaceField::PlasticStrain => "plastic-strain",
        }
    }

    /// Name as the picture's title and colour bar show it.
    pub fn label(self) -> &'static str {
        match self {
            SurfaceField::Damage => "damage D",
            SurfaceField::PlasticStrain => "plastic strain",
        }
    }

    fn values(self, p: &Particles) -> &[f64] {
        match self {
            SurfaceField::Damage => &p.damage,
            SurfaceField::PlasticStrain => &p.eps_p,
        }
    }
}

/// What one surface picture shows.
#[derive(Debug, Clone)]
pub struct SurfacePicture<'a> {
    /// The surface's particles (positions in m).
    pub particles: &'a Particles,
    /// Particle spacing Δx (m): each particle is a disc of this diameter.
    pub spacing_m: f64,
    /// Grain outline drawn over the surface (m), if any.
    pub outline_m: Option<&'a [Vector]>,
    /// Title line; the field's name is put in front of it.
    pub title: String,
    /// Lines of notes under the plot.
    pub notes: Vec<String>,
}

/// The viridis colour map at a few stops, interpolated linearly: perceptually even and
/// readable in grey, so damage gradients are not invented by the palette.
const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// Viridis colour of `t` in [0, 1] (clamped).
pub fn viridis(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - k as f64;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    let mix = |a: u8, b: u8| (a as f64 + f * (b as f64 - a as f64)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Colour range of `field` over `values`, and a note when the top colour saturates.
fn range(field: SurfaceField, values: &[f64]) -> (f64, Option<String>) {
    match field {
        SurfaceField::Damage => (1.0, None),
        SurfaceField::PlasticStrain => {
            let mut pos: Vec<f64> = values
                .iter()
                .copied()
                .filter(|v| v.is_finite() && *v > 0.0)
                .collect();
            if pos.is_empty() {
                return (1.0, None);
            }
            pos.sort_by(f64::total_cmp);
            let max = pos[pos.len() - 1];
            let q = pos[((pos.len() - 1) as f64 * STRAIN_QUANTILE).round() as usize];
            // Saturate only for real outliers: a top colour that stands for a wide range.
            if max > SATURATE_ABOVE * q {
                let above = pos.iter().filter(|&&v| v > q).count();
                let note = format!(
                    "plastic strain above {q:.3} ({above} particles, up to {max:.3}) is drawn in the top colour"
                );
                (q, Some(note))
            } else {
                (max, None)
            }
        }
    }
}

/// Where a picture of particles goes: data extent (µm), plot and image size (px), and the
/// radius of a particle's disc (px).
pub(crate) struct Layout {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub plot: (u32, u32),
    pub size: (u32, u32),
    pub radius_px: f64,
}

/// The layout of a picture of the points `pts` (m) of spacing `spacing_m` with `notes` lines of
/// notes: data extent in µm with a margin of one spacing, pixel sizes at equal scale.
pub(crate) fn layout(pts: impl Iterator<Item = Vector>, spacing_m: f64, notes: usize) -> Layout {
    let dx = spacing_m * UM;
    let pts = pts.map(|v| (v.x * UM, v.y * UM));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (-1.0, 1.0, -1.0, 1.0);
    }
    let (x, y) = ((x0 - dx, x1 + dx), (y0 - dx, y1 + dx));
    let mut scale = PLOT_W as f64 / (x.1 - x.0);
    if (y.1 - y.0) * scale > PLOT_H_MAX as f64 {
        scale = PLOT_H_MAX as f64 / (y.1 - y.0);
    }
    let plot = (
        ((x.1 - x.0) * scale).round().max(1.0) as u32,
        ((y.1 - y.0) * scale).round().max(1.0) as u32,
    );
    let size = (
        LEFT_LABELS + plot.0 + RIGHT_PAD + BAR_AREA_W,
        TITLE_H + TOP_PAD + plot.1 + BOTTOM_LABELS + NOTE_LINE * notes as u32 + 8,
    );
    Layout {
        x,
        y,
        plot,
        size,
        radius_px: (0.5 * dx * scale).max(1.0),
    }
}

/// Draws `pic` coloured by `field` as a PNG at `path`.
pub fn surface_png(
    pic: &SurfacePicture,
    field: SurfaceField,
    path: &Path,
) -> Result<(), PlotError> {
    let failed = |message| PlotError::Draw {
        path: path.to_path_buf(),
        message,
    };
    let values = field.values(pic.particles);
    let (vmax, saturated) = range(field, values);
    let mut notes = pic.notes.clone();
    notes.extend(saturated);
    let pts = pic
        .particles
        .pos
        .iter()
        .chain(pic.outline_m.unwrap_or(&[]))
        .copied();
    let l = layout(pts, pic.spacing_m, notes.len());
    let root = BitMapBackend::new(path, l.size).into_drawing_area();
    let title = format!("{}: {}", capitalised(field.label()), pic.title);
    let bar = Some((field.label(), 0.0, vmax));
    draw_frame(&root, &title, &notes, &l, bar, |chart| {
        draw_particles(chart, pic, field, vmax, &l)
    })
    .map_err(failed)?;
    root.present().map_err(de).map_err(failed)
}

/// The chart a picture of particles draws on: µm against µm.
pub(crate) type Frame<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Everything of a picture of particles but the particles: the title, axes in µm at equal scale
/// (`plot` draws into them), a colour bar of (label, min, max) if any, and the notes.
pub(crate) fn draw_frame<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    notes: &[String],
    l: &Layout,
    bar: Option<(&str, f64, f64)>,
    plot: impl FnOnce(&mut Frame<'_, DB>) -> DrawResult,
) -> DrawResult {
    root.fill(&WHITE).map_err(de)?;
    root.draw_text(
        title,
        &TextStyle::from((FONT, 21).into_font()).color(&BLACK),
        (14, 12),
    )
    .map_err(de)?;
    let (_, body) = root.split_vertically(TITLE_H);
    let chart_h = TOP_PAD + l.plot.1 + BOTTOM_LABELS;
    let (charts, strip) = body.split_vertically(chart_h);
    let (main, bar_area) = charts.split_horizontally(LEFT_LABELS + l.plot.0 + RIGHT_PAD);

    let mut chart = ChartBuilder::on(&main)
        .margin_top(TOP_PAD)
        .margin_right(RIGHT_PAD)
        .x_label_area_size(BOTTOM_LABELS)
        .y_label_area_size(LEFT_LABELS)
        .build_cartesian_2d(l.x.0..l.x.1, l.y.0..l.y.1)
        .map_err(de)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x (µm)")
        .y_desc("y (µm)")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .draw()
        .map_err(de)?;
    plot(&mut chart)?;
    if let Some((label, lo, hi)) = bar {
        colour_bar(&bar_area, label, (lo, hi), l.plot.1)?;
    }
    let grey = BLACK.mix(0.8);
    let style = TextStyle::from((FONT, 14).into_font()).color(&grey);
    for (i, n) in notes.iter().enumerate() {
        strip
            .draw_text(n, &style, (14, 2 + (NOTE_LINE as i32) * i as i32))
            .map_err(de)?;
    }
    Ok(())
}

/// The surface's particles coloured by `field` up to `vmax`, and the grain's outline.
fn draw_particles<DB: DrawingBackend>(
    chart: &mut Frame<'_, DB>,
    pic: &SurfacePicture,
    field: SurfaceField,
    vmax: f64,
    l: &Layout,
) -> DrawResult {
    // Low values first, so damaged particles are drawn over their undamaged neighbours.
    let p = pic.particles;
    let values = field.values(p);
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let r = l.radius_px;
    chart
        .draw_series(order.iter().map(|&i| {
            let c = viridis(values[i] / vmax);
            // Fixed boundary particles pale, so the free material stands out.
            let style = if p.flags[i] & KINEMATIC != 0 {
                c.mix(0.45).filled()
            } else {
                c.filled()
            };
            Circle::new((p.pos[i].x * UM, p.pos[i].y * UM), r, style)
        }))
        .map_err(de)?;
    if let Some(outline) = pic.outline_m {
        let pts: Vec<(f64, f64)> = outline.iter().map(|v| (v.x * UM, v.y * UM)).collect();
        chart
            .draw_series(std::iter::once(Polygon::new(
                pts.clone(),
                RGBColor(150, 150, 150).mix(0.45).filled(),
            )))
            .map_err(de)?;
        let mut closed = pts;
        closed.push(closed[0]);
        chart
            .draw_series(std::iter::once(PathElement::new(
                closed,
                RGBColor(20, 20, 20).stroke_width(2),
            )))
            .map_err(de)?;
    }
    Ok(())
}

/// A vertical bar of the colour map from `lo` to `hi` beside the plot, `label` on top.
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    label: &str,
    (lo, hi): (f64, f64),
    plot_h: u32,
) -> DrawResult {
    // The bar is shorter than the plot by its caption, and never taller than 320 px.
    let label_h = 30;
    let h = plot_h.saturating_sub(label_h).clamp(60, 320);
    let (top, _) = area.split_vertically(TOP_PAD + label_h + h);
    top.draw_text(
        label,
        &TextStyle::from((FONT, 15).into_font()).color(&BLACK),
        (8, TOP_PAD as i32 + 4),
    )
    .map_err(de)?;
    let (_, bar) = top.split_vertically(TOP_PAD + label_h);
    let mut c = ChartBuilder::on(&bar)
        .margin_left(8)
        .y_label_area_size(0)
        .right_y_label_area_size(60)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(de)?;
    c.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(6)
        .y_label_formatter(&|v| trim_number(*v))
        .label_style((FONT, 13))
        .draw()
        .map_err(de)?;
    let n = 200;
    let at = |f: f64| lo + f * (hi - lo);
    c.draw_series((0..n).map(|k| {
        let (a, b) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
        Rectangle::new(
            [(0.0, at(a)), (1.0, at(b))],
            viridis(0.5 * (a + b)).filled(),
        )
    }))
    .map_err(de)?;
    c.draw_series(std::iter::once(Rectangle::new(
        [(0.0, lo), (1.0, hi)],
        BLACK.mix(0.6).stroke_width(1),
    )))
    .map_err(de)?;
    Ok(())
}

/// A tick label without trailing zeros: 0, 0.2, 0.25, 1.
fn trim_number(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends_and_clamps() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(-3.0), viridis(0.0));
        assert_eq!(viridis(7.0), viridis(1.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
    }

    #[test]
    fn strain_range_saturates_only_outliers() {
        let mut v: Vec<f64> = (0..1000).map(|k| k as f64 * 1e-3).collect();
        assert_eq!(range(SurfaceField::PlasticStrain, &v), (0.999, None));
        v[999] = 3.0;
        let (top, note) = range(SurfaceField::PlasticStrain, &v);
        assert!(top < 0.999 && top > 0.99, "{top}");
        assert!(note.unwrap().contains("up to 3.000"));
        v.truncate(3);
        assert_eq!(range(SurfaceField::PlasticStrain, &v), (0.002, None));
        assert_eq!(range(SurfaceField::PlasticStrain, &[0.0, 0.0]).0, 1.0);
        assert_eq!(range(SurfaceField::Damage, &v), (1.0, None));
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(trim_number(0.0), "0");
        assert_eq!(trim_number(0.25), "0.25");
        assert_eq!(trim_number(1.0), "1");
    }
}
