//! Drawing shared by the charts: one figure drawn on both backends, the charts' axes and legend
//! keys, a strip of notes under the plot, colours, error bars and axis ranges.

use std::path::{Path, PathBuf};

use grit_erosion::Stationarity;
use plotters::chart::MeshStyle;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::PlotError;

/// Size of every chart, pixels.
pub const SIZE: (u32, u32) = (1100, 750);
/// Font family of all text (registered by `register_fonts`).
pub const FONT: &str = "sans-serif";

/// Ten distinguishable colours (the usual "tab10" hues).
pub const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Colour number `i`, cycling.
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Errors of plotters as text (their types differ per backend).
pub type DrawResult = Result<(), String>;

/// Turns any plotters error into text.
pub fn de(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// Axes with linear coordinates on both sides, as most charts draw on.
pub type Axes<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A chart over the coordinates that the ranges `X` and `Y` give (linear or log).
pub type ChartOf<'a, DB, X, Y> = ChartContext<
    'a,
    DB,
    Cartesian2d<<X as AsRangedCoord>::CoordDescType, <Y as AsRangedCoord>::CoordDescType>,
>;

/// A chart on `area` over `x` × `y` (linear or log coordinates) with the common caption size,
/// margin and label areas.
pub fn chart_on<'a, DB: DrawingBackend, X: AsRangedCoord, Y: AsRangedCoord>(
    area: &'a DrawingArea<DB, Shift>,
    caption: impl AsRef<str>,
    x: X,
    y: Y,
) -> Result<ChartOf<'a, DB, X, Y>, String> {
    ChartBuilder::on(area)
        .caption(caption, (FONT, 22))
        .margin(15)
        .x_label_area_size(55)
        .y_label_area_size(85)
        .build_cartesian_2d(x, y)
        .map_err(de)
}

/// Draws `mesh`, its descriptions and labels set by the chart, in the common fonts.
pub fn draw_mesh<DB, X, Y>(mesh: &mut MeshStyle<'_, '_, X, Y, DB>) -> DrawResult
where
    DB: DrawingBackend,
    X: Ranged + ValueFormatter<X::ValueType>,
    Y: Ranged + ValueFormatter<Y::ValueType>,
{
    mesh.label_style((FONT, 14))
        .axis_desc_style((FONT, 17))
        .draw()
        .map_err(de)
}

/// A chart as [`chart_on`] makes it, its mesh drawn and its axes described by `x_desc` and
/// `y_desc`.
pub fn axes<'a, DB, X, Y>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    (x, x_desc): (X, &str),
    (y, y_desc): (Y, &str),
) -> Result<ChartOf<'a, DB, X, Y>, String>
where
    DB: DrawingBackend,
    X: AsRangedCoord,
    Y: AsRangedCoord,
    X::CoordDescType: ValueFormatter<X::Value>,
    Y::CoordDescType: ValueFormatter<Y::Value>,
{
    let mut chart = chart_on(area, caption, x, y)?;
    draw_mesh(chart.configure_mesh().x_desc(x_desc).y_desc(y_desc))?;
    Ok(chart)
}

/// A legend key of a line drawn in `style`.
pub fn line_key(style: ShapeStyle) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], style)
}

/// A chart that can be drawn on any backend.
pub trait Figure {
    /// Draws the whole chart on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult;
}

/// Registers the fonts and creates `out` if missing, as every chart-writing entry point must
/// before it draws.
pub fn prepare_output(out: &Path) -> Result<(), PlotError> {
    crate::register_fonts();
    std::fs::create_dir_all(out).map_err(|error| PlotError::Output {
        path: out.to_path_buf(),
        error,
    })
}

/// Draws `fig` as `out/stem.png` and `out/stem.svg`; returns both paths.
pub fn save(fig: &impl Figure, out: &Path, stem: &str) -> Result<Vec<PathBuf>, PlotError> {
    save_sized(fig, out, stem, SIZE)
}

/// `save` at `size` pixels instead of the common chart size.
pub fn save_sized(
    fig: &impl Figure,
    out: &Path,
    stem: &str,
    size: (u32, u32),
) -> Result<Vec<PathBuf>, PlotError> {
    let png = out.join(format!("{stem}.png"));
    let svg = out.join(format!("{stem}.svg"));
    let failed = |path: &Path| {
        let path = path.to_path_buf();
        move |message| PlotError::Draw { path, message }
    };
    {
        let root = BitMapBackend::new(&png, size).into_drawing_area();
        fig.draw(&root).map_err(failed(&png))?;
        root.present().map_err(de).map_err(failed(&png))?;
    }
    {
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        fig.draw(&root).map_err(failed(&svg))?;
        root.present().map_err(de).map_err(failed(&svg))?;
    }
    Ok(vec![png, svg])
}

/// Fills `root` white and splits off a strip at the bottom with `notes`, one per line;
/// returns the area above for the plot.
pub fn with_notes<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    notes: &[String],
) -> Result<DrawingArea<DB, Shift>, String> {
    root.fill(&WHITE).map_err(de)?;
    if notes.is_empty() {
        return Ok(root.clone());
    }
    let line = 19;
    let height = root.dim_in_pixel().1 as i32;
    let (plot, strip) = root.split_vertically(height - line * notes.len() as i32 - 10);
    let grey = BLACK.mix(0.8);
    let style = TextStyle::from((FONT, 14).into_font()).color(&grey);
    for (i, n) in notes.iter().enumerate() {
        strip
            .draw_text(n, &style, (14, 2 + line * i as i32))
            .map_err(de)?;
    }
    Ok(plot)
}

/// Upper end of a value axis from 0: 10 % above the largest value, 1 when all are ≤ 0.
pub fn top(values: impl Iterator<Item = f64>) -> f64 {
    let m = values.filter(|v| v.is_finite()).fold(0.0, f64::max);
    if m > 0.0 {
        1.1 * m
    } else {
        1.0
    }
}

/// Vertical error bar from `lo` to `hi` at `x`, with caps `cap` wide (data units).
pub fn error_bar(
    x: f64,
    lo: f64,
    hi: f64,
    cap: f64,
    style: ShapeStyle,
) -> [PathElement<(f64, f64)>; 3] {
    [
        PathElement::new(vec![(x, lo), (x, hi)], style),
        PathElement::new(vec![(x - cap, lo), (x + cap, lo)], style),
        PathElement::new(vec![(x - cap, hi), (x + cap, hi)], style),
    ]
}

/// A file-name-safe version of `s`.
pub fn file_safe(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Width of a hollow marker's outline, pixels.
const HOLLOW_STROKE: u32 = 2;

/// A cell's marker: hollow (outline only) when its value is no rate (`Some(false)`): an
/// impact cell not at steady state or not balanced (`CellResult::stationary`; seed paper
/// section 4, `docs/erosion.md`), a jet cell whose stage-3 slope is not steady; filled
/// otherwise, or when the file predates the check (`None`).
pub fn marker_style(c: RGBColor, rate: Option<bool>) -> ShapeStyle {
    if rate == Some(false) {
        c.stroke_width(HOLLOW_STROKE)
    } else {
        c.filled()
    }
}

/// The note under a chart of per-cell erosion saying which cells are drawn hollow because they
/// are no stationary rate (`CellResult::stationarity`), why, and which were never checked;
/// empty when every cell drawn is one.
pub fn hollow_notes(cells: impl Iterator<Item = Stationarity>) -> Vec<String> {
    let (mut total, mut running, mut unsteady, mut unbalanced, mut unchecked) = (0, 0, 0, 0, 0);
    for s in cells {
        total += 1;
        match s {
            Stationarity::Rate => {}
            Stationarity::Running => running += 1,
            Stationarity::Unsteady => unsteady += 1,
            Stationarity::Unbalanced => unbalanced += 1,
            Stationarity::Unchecked => unchecked += 1,
        }
    }
    let why: Vec<String> = [
        (running, "still running"),
        (unsteady, "not steady"),
        (unbalanced, "steady, not balanced"),
    ]
    .iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| format!("{n} {what}"))
    .collect();
    let mut notes = Vec::new();
    if !why.is_empty() {
        notes.push(format!(
            "Hollow markers: {} of {total} cells are no stationary rate yet: {} \
             (docs/erosion.md, The damage balance).",
            running + unsteady + unbalanced,
            why.join(", ")
        ));
    }
    if unchecked > 0 {
        notes.push(format!(
            "Steady state not checked for {unchecked} of {total} cells (results written \
             before the check): drawn filled."
        ));
    }
    notes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_cells_that_are_no_rate_are_hollow() {
        let c = colour(1);
        let hollow = marker_style(c, Some(false));
        assert!(!hollow.filled && hollow.stroke_width == HOLLOW_STROKE);
        assert!(marker_style(c, Some(true)).filled);
        assert!(
            marker_style(c, None).filled,
            "files before the check draw as before"
        );
    }

    #[test]
    fn notes_count_hollow_and_unchecked_cells() {
        use Stationarity::*;
        assert!(hollow_notes([Rate, Rate].into_iter()).is_empty());
        let n = hollow_notes([Rate, Unsteady, Unchecked].into_iter());
        assert_eq!(n.len(), 2);
        assert!(n[0].starts_with(
            "Hollow markers: 1 of 3 cells are no stationary rate yet: 1 not steady ("
        ));
        assert!(n[1].starts_with("Steady state not checked for 1 of 3 cells"));
        let n = hollow_notes([Running, Unbalanced, Unbalanced, Rate].into_iter());
        assert_eq!(
            n,
            [
                "Hollow markers: 3 of 4 cells are no stationary rate yet: 1 still running, 2 \
              steady, not balanced (docs/erosion.md, The damage balance)."
            ]
        );
    }
}
