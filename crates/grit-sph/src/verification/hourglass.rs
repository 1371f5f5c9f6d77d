//! Zero-energy modes: the elastic impact run on without hourglass control and without the
//! density filter develops modes that the stress divergence does not see; once the disc has left,
//! nothing should add energy, yet theirs grows. With hourglass control (eq. 16) the same run loses
//! energy slowly instead.

use super::{elastic_impact, CaseReport, Row};
use crate::error::SimError;
use crate::world::Settings;

/// How long the block is followed (s): ten times the contact duration.
pub const T_END: f64 = 1e-3;

/// Energy at the end over energy when the disc left, for hourglass coefficient `alpha` and no
/// density filter; infinite if the engine stopped the run as unstable.
pub fn growth_after_contact(n: usize, alpha: f64) -> Result<f64, SimError> {
    let s = Settings {
        hourglass: alpha,
        shepard_interval: 0,
        ..Settings::default()
    };
    let h = elastic_impact::simulate_until(n, s, Some(T_END))?;
    let left = h.in_contact.iter().rposition(|&c| c).unwrap_or(0);
    Ok(h.energy.last().copied().unwrap_or(f64::NAN) / h.energy[left])
}

/// Runs without and with control: growth means more than 5% gained after contact, bounded
/// means no gain.
pub fn run(n: usize, alpha: f64) -> Result<CaseReport, SimError> {
    let res = format!("{n} particles per block side, to t = {T_END} s");
    let mut rep = CaseReport::default();
    let (off, off_note) = match growth_after_contact(n, 0.0) {
        Ok(g) => (
            g,
            "E(end)/E(disc left) without hourglass control; growth means > 1.05".to_string(),
        ),
        Err(e) => (
            f64::INFINITY,
            format!("without hourglass control the engine stopped the run: {e}"),
        ),
    };
    let on = growth_after_contact(n, alpha)?;
    rep.rows.push(Row {
        case: "zero_energy_modes_without_control".into(),
        resolution: res.clone(),
        value: off,
        reference: 1.0,
        error_rel: off - 1.0,
        pass: off > 1.05,
        note: off_note,
    });
    rep.rows.push(Row {
        case: "zero_energy_modes_with_control".into(),
        resolution: res,
        value: on,
        reference: 1.0,
        error_rel: (on - 1.0).max(0.0),
        pass: on <= 1.0,
        note: format!("E(end)/E(disc left) with hourglass coefficient {alpha}; bounded means <= 1"),
    });
    Ok(rep)
}
