//! Zero-energy modes: the elastic impact with the small disc (`Disc::SMALL`, whose load sits on
//! one or two particles) run on without hourglass control and without the density filter develops
//! modes that the stress divergence does not see; once the disc has left,
//! nothing should add energy, yet theirs grows. With hourglass control (eq. 16) the same run loses
//! energy slowly instead.

use super::{elastic_impact, CaseReport, Chart, Row, Series};
use crate::error::SimError;
use crate::world::Settings;

/// How long the block is followed (s): ten times the contact duration.
pub const T_END: f64 = 1e-3;

/// Energy at the end over energy when the disc left, for hourglass coefficient `alpha` and no
/// density filter; infinite if the engine stopped the run as unstable.
pub fn growth_after_contact(n: usize, alpha: f64) -> Result<f64, SimError> {
    history(n, alpha).map(|h| growth(&h))
}

/// The run behind [`growth_after_contact`]: the elastic impact followed to `T_END` without the
/// density filter.
pub fn history(n: usize, alpha: f64) -> Result<elastic_impact::History, SimError> {
    let s = Settings {
        hourglass: alpha,
        shepard_interval: 0,
        ..Settings::default()
    };
    elastic_impact::simulate_with(n, s, elastic_impact::Disc::SMALL, Some(T_END))
}

/// E(end) / E(disc left) of a run.
pub fn growth(h: &elastic_impact::History) -> f64 {
    let left = h.in_contact.iter().rposition(|&c| c).unwrap_or(0);
    h.energy.last().copied().unwrap_or(f64::NAN) / h.energy[left]
}

/// Runs without and with control: growth means more than 5% gained after contact, bounded
/// means no gain.
pub fn run(n: usize, alpha: f64) -> Result<CaseReport, SimError> {
    let res = format!("{n} particles per block side, to t = {T_END} s");
    let mut rep = CaseReport::default();
    let mut chart = Chart {
        name: "zero_energy_modes".into(),
        title: format!("Zero-energy modes: elastic impact without density filter, {n} per side"),
        x_label: "time (s)".into(),
        y_label: "E / E0".into(),
        series: Vec::new(),
    };
    let mut curve = |label: String, h: &elastic_impact::History| {
        chart.series.push(Series {
            label,
            x: h.t.clone(),
            y: h.energy.clone(),
            reference: false,
        })
    };
    let (off, off_note) = match history(n, 0.0) {
        Ok(h) => {
            curve("without hourglass control".into(), &h);
            (
                growth(&h),
                "E(end)/E(disc left) without hourglass control; growth means > 1.05".to_string(),
            )
        }
        Err(e) => (
            f64::INFINITY,
            format!("without hourglass control the engine stopped the run: {e}"),
        ),
    };
    let h_on = history(n, alpha)?;
    curve(format!("hourglass coefficient {alpha}"), &h_on);
    let on = growth(&h_on);
    rep.rows.push(Row {
        case: "zero_energy_modes_without_control".into(),
        resolution: res.clone(),
        value: off,
        reference: 1.0,
        error_rel: off - 1.0,
        pass: off > 1.05,
        expected_fail: false,
        note: off_note,
    });
    rep.rows.push(Row {
        case: "zero_energy_modes_with_control".into(),
        resolution: res,
        value: on,
        reference: 1.0,
        error_rel: (on - 1.0).max(0.0),
        pass: on <= 1.0,
        expected_fail: false,
        note: format!("E(end)/E(disc left) with hourglass coefficient {alpha}; bounded means <= 1"),
    });
    rep.charts.push(chart);
    Ok(rep)
}
