//! The seed's verification cases (sections 3.3.1–3.3.3) and the engine's own checks
//! (zero-energy modes, elastic impact, determinism). Each case takes a resolution and returns
//! rows (case, resolution, value, reference, error, pass) and the series to chart; tests run
//! them coarse, `grit verify` runs them at full resolution.

use serde::{Deserialize, Serialize};

pub mod elastic_impact;
pub mod hertz;
pub mod hourglass;
pub mod hydrostatic;
pub mod jet;
pub mod jet_grain;
pub mod jet_wall;
pub mod rock;
pub mod settling;
pub mod sliding;
pub mod slope;

/// A case that could not be set up or run, as the error the cases return.
pub(crate) fn fail(what: String) -> crate::error::SimError {
    crate::error::SimError {
        step: 0,
        time_s: 0.0,
        what,
    }
}

/// A failure found while stepping `w`, at its step and time.
pub(crate) fn fail_at(w: &crate::world::World, what: String) -> crate::error::SimError {
    crate::error::SimError {
        step: w.steps(),
        time_s: w.time(),
        what,
    }
}

/// One line of the verification table. Field names are read by scripts: keep them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Case name, e.g. `slope_slider_mu0.2`.
    pub case: String,
    /// Resolution, e.g. `dx=0.01 m`.
    pub resolution: String,
    /// The measured value.
    pub value: f64,
    /// The reference (analytic or published) value.
    pub reference: f64,
    /// Relative error |value − reference| / |reference| (or the case's own error measure).
    pub error_rel: f64,
    /// Whether the case's tolerance is met.
    pub pass: bool,
    /// True for rows that show where a method fails (the penetration contact of Fig. 2b, the
    /// density filter in the Hertz case): they are meant to miss the tolerance, and `grit verify`
    /// leaves them out of its exit status.
    #[serde(default)]
    pub expected_fail: bool,
    /// What the value is and what tolerance applies.
    pub note: String,
}

/// A curve for a chart: x and y with a label; `reference` curves are drawn dashed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// x values.
    pub x: Vec<f64>,
    /// y values.
    pub y: Vec<f64>,
    /// True for analytic references.
    pub reference: bool,
}

/// A chart: title, axis labels with units, curves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Chart {
    /// File stem for the chart.
    pub name: String,
    /// Title.
    pub title: String,
    /// x-axis label with unit.
    pub x_label: String,
    /// y-axis label with unit.
    pub y_label: String,
    /// Curves.
    pub series: Vec<Series>,
}

/// Rows and charts of one case.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CaseReport {
    /// Table rows.
    pub rows: Vec<Row>,
    /// Charts.
    pub charts: Vec<Chart>,
}

impl CaseReport {
    /// Appends another report.
    pub fn extend(&mut self, other: CaseReport) {
        self.rows.extend(other.rows);
        self.charts.extend(other.charts);
    }
}
