//! grit-plot: charts of campaign results as PNG and SVG, after the seed paper's section 4
//! figures: mass loss against grain mass (Figs. 8, 10b), one sample at every angle
//! (Fig. 9), erosion against impact angle with Oka's model (Figs. 11a, 12a), erosion
//! normalised at 45° (Fig. 12b), the shape-modified Oka model (Fig. 14), convergence
//! with the number of samples (Fig. 10a), and each cell's loss against the damage its impacts
//! added, window by window (eq. 19; the damage balance of docs/erosion.md).
//!
//! It reads the results JSON that `grit run` and `grit results` write (grit-erosion's
//! `CampaignResults`, plus the optional `raw` per-impact series) and knows nothing of the
//! farm, so the farm's `grit run` and the `grit plot` command share it. Text is drawn with
//! DejaVu Sans embedded in the binary: no system font is needed.
//!
//! A jet campaign's results (`"scene": "jet"`) get their own charts (`jet`): crater profiles
//! over time, Cd, Cw and mass loss against time, and Cd against the jet speed.
#![warn(missing_docs)]

mod analysis;
mod balance;
mod charts;
mod draw;
mod fit;
mod fonts;
mod input;
mod jet;
mod jet_picture;
mod resolution;
mod stability;
mod surface;
mod sweep;

use std::path::{Path, PathBuf};

use grit_erosion::{CampaignResults, Stationarity};

pub use draw::colour;
pub use fit::plot_fit;
pub use fonts::register_fonts;
pub use input::{
    load, load_any, load_jet_runs, merge, parse, parse_any, AnyInput, PlotInput, RawImpact,
    RawOutcome, RawSeries,
};
pub use jet::{jet_summary_table, plot_jet};
pub use jet_picture::{jet_png, JetField, JetPicture};
pub use resolution::{ladder, ladder_table, plot_ladder, LadderPoint};
pub use stability::stability_chart;
pub use surface::{surface_png, viridis, SurfaceField, SurfacePicture};
pub use sweep::sweep_chart;

/// Why charts could not be made: unreadable or invalid input, or an unwritable output.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The results file cannot be read.
    #[error("{path}: {error}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What the system said.
        error: std::io::Error,
    },
    /// The input is not a results file grit can plot; says what is wrong.
    #[error("{0}")]
    Input(String),
    /// The output folder cannot be made.
    #[error("--out {path}: {error}")]
    Output {
        /// The folder.
        path: PathBuf,
        /// What the system said.
        error: std::io::Error,
    },
    /// A chart could not be drawn or written.
    #[error("chart {path}: {message}")]
    Draw {
        /// The file being written.
        path: PathBuf,
        /// What plotters said.
        message: String,
    },
}

/// What `plot` wrote, and what it left out or fitted, in words.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Every file written, PNG and SVG.
    pub files: Vec<PathBuf>,
    /// Fit results and the reasons a chart or curve was skipped.
    pub notes: Vec<String>,
}

/// Writes every chart the results allow into `out` (created if missing), PNG and SVG each.
pub fn plot(input: &PlotInput, out: &Path) -> Result<Report, PlotError> {
    draw::prepare_output(out)?;
    let analysis = analysis::Analysis::new(&input.results);
    let mut report = Report::default();
    charts::mass_loss(input, out, &mut report)?;
    charts::sample_by_angle(input, out, &mut report)?;
    charts::erosion_vs_angle(&analysis, out, &mut report)?;
    charts::normalised(&analysis, out, &mut report)?;
    charts::modified_oka(&analysis, out, &mut report)?;
    charts::convergence(&input.results, out, &mut report)?;
    balance::damage_balance(input, out, &mut report)?;
    report.notes.extend(analysis.hollow_notes.iter().cloned());
    Ok(report)
}

/// Reads a results JSON file of either scene and writes its charts into `out`.
pub fn plot_file(results: &Path, out: &Path) -> Result<Report, PlotError> {
    plot_any(&load_any(results)?, out)
}

/// Writes the charts of results of either scene into `out`.
pub fn plot_any(input: &AnyInput, out: &Path) -> Result<Report, PlotError> {
    match input {
        AnyInput::Impact(input) => plot(input, out),
        AnyInput::Jet(r) => plot_jet(r, out),
    }
}

/// A short table of the cells: angle, shape, samples, erosion mean ± std.
pub fn summary_table(results: &CampaignResults) -> String {
    let fmt = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{x:.3e}"));
    let mut s = format!(
        "{:>7}  {:<24} {:>7}  {}\n",
        "angle", "shape", "samples", "erosion (mean ± std, mass lost / grain mass)"
    );
    for c in &results.cells {
        s.push_str(&format!(
            "{:>6.1}°  {:<24} {:>7}  {} ± {}{}{}\n",
            c.angle_deg,
            analysis::series_label(&c.shape, &c.swept),
            c.samples,
            fmt(c.erosion_mean),
            fmt(c.erosion_std),
            if c.partial { "  (partial)" } else { "" },
            match c.stationarity() {
                Stationarity::Unsteady => "  (not at steady state)",
                Stationarity::Unbalanced => "  (steady, not balanced)",
                _ => "",
            }
        ));
    }
    s
}
