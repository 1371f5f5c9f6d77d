//! Elastic impact: a rigid disc hits a free-floating elastic block (no fixed boundary), μ = 0,
//! no plasticity. Momentum must be conserved to round-off; kinetic plus elastic energy may not
//! rise, and after contact must be close to where it started. Hourglass control and the density
//! filter are the only sinks; their work is reported.

use super::{CaseReport, Chart, Row, Series};
use crate::body::Motion;
use crate::contact::ContactParams;
use crate::error::SimError;
use crate::geometry::Polygon;
use crate::material::Material;
use crate::math::Vector;
use crate::world::{NumericalWork, Settings, World};

/// Block side (m).
pub const BLOCK: f64 = 0.01;
/// Disc radius (m).
pub const RADIUS: f64 = 0.002;
/// Impact speed (m/s).
pub const SPEED: f64 = 20.0;

/// Time history of one run.
#[derive(Debug, Clone, Default)]
pub struct History {
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Total energy (kinetic + elastic + contact springs) (J/m).
    pub energy: Vec<f64>,
    /// Relative momentum drift |p − p0| / |p0|.
    pub momentum_drift: Vec<f64>,
    /// Whether the disc touched the block at the sample.
    pub in_contact: Vec<bool>,
    /// Numerical work at the end.
    pub work: NumericalWork,
}

/// Builds the scene with `n` particles along the block side.
pub fn scene(n: usize, settings: Settings) -> World {
    let dx = BLOCK / n as f64;
    let mut w = World::new(Settings {
        spacing_m: dx,
        ..settings
    })
    .expect("valid settings");
    let block = Polygon::rectangle(0.0, 0.0, BLOCK, BLOCK);
    let b = w
        .add_deformable_polygon(
            "block",
            Material::elastic_aluminium(),
            &block,
            Vector::zeros(),
            Vector::zeros(),
        )
        .expect("block");
    let disc =
        Polygon::regular(64, RADIUS, 0.0).translated(Vector::new(0.5 * BLOCK, BLOCK + RADIUS + dx));
    let d = w
        .add_rigid(
            "disc",
            &disc,
            7800.0,
            Vector::new(0.0, -SPEED),
            0.0,
            Motion::Free,
        )
        .expect("disc");
    w.add_contact(d, b, ContactParams::default())
        .expect("contact");
    w
}

/// Runs until the disc has left the block and travelled two further radii.
pub fn simulate(n: usize, settings: Settings) -> Result<History, SimError> {
    simulate_until(n, settings, None)
}

/// Runs to `t_end` (s) if given, else until the disc has left and travelled two radii.
pub fn simulate_until(
    n: usize,
    settings: Settings,
    t_end: Option<f64>,
) -> Result<History, SimError> {
    let mut w = scene(n, settings);
    let e0 = w.energy().total();
    let p0 = w.momentum();
    let mut h = History::default();
    let mut touched = false;
    let mut left_at = None;
    let t_max = t_end.unwrap_or(40.0 * RADIUS / SPEED);
    while w.time() < t_max {
        w.step()?;
        let touching = w.contact_forces().iter().any(|f| f.norm() > 0.0);
        touched |= touching;
        if touched && !touching && left_at.is_none() {
            left_at = Some(w.time());
        }
        if w.steps().is_multiple_of(10) {
            h.t.push(w.time());
            h.energy.push(w.energy().total() / e0);
            h.momentum_drift
                .push((w.momentum() - p0).norm() / p0.norm());
            h.in_contact.push(touching);
        }
        if let (Some(t), None) = (left_at, t_end) {
            if w.time() > t + 2.0 * RADIUS / SPEED {
                break;
            }
        }
    }
    h.work = w.numerical_work();
    h.work.hourglass /= e0;
    h.work.density_filter /= e0;
    Ok(h)
}

/// Runs the case at `n` particles per block side and reports the three checks.
pub fn run(n: usize) -> Result<CaseReport, SimError> {
    let h = simulate(n, Settings::default())?;
    let res = format!("{n} particles per block side");
    let max_e = h.energy.iter().cloned().fold(f64::MIN, f64::max);
    let last_contact = h.in_contact.iter().rposition(|&c| c).unwrap_or(0);
    let after = h.energy.get(last_contact + 1..).unwrap_or(&[]);
    let e_after = after.last().copied().unwrap_or(f64::NAN);
    let drift = h.momentum_drift.iter().cloned().fold(0.0, f64::max);
    let mut rep = CaseReport::default();
    rep.rows.push(Row {
        case: "elastic_impact_momentum".into(),
        resolution: res.clone(),
        value: drift,
        reference: 0.0,
        error_rel: drift,
        pass: drift <= 1e-8,
        note: "max |p - p0| / |p0| over the run; bound 1e-8".into(),
    });
    rep.rows.push(Row {
        case: "elastic_impact_energy_peak".into(),
        resolution: res.clone(),
        value: max_e,
        reference: 1.0,
        error_rel: (max_e - 1.0).max(0.0),
        pass: max_e <= 1.01,
        note: "max E/E0 (kinetic + elastic + contact springs); bound 1.01".into(),
    });
    rep.rows.push(Row {
        case: "elastic_impact_energy_after".into(),
        resolution: res,
        value: e_after,
        reference: 1.0,
        error_rel: (e_after - 1.0).abs(),
        pass: (e_after - 1.0).abs() <= 0.05,
        note: format!(
            "E/E0 after contact; bound 5%; hourglass work {:.2e} E0, density filter {:.2e} E0",
            h.work.hourglass, h.work.density_filter
        ),
    });
    rep.charts.push(Chart {
        name: "elastic_impact_energy".into(),
        title: "Elastic impact: energy and momentum".into(),
        x_label: "time (s)".into(),
        y_label: "E / E0".into(),
        series: vec![Series {
            label: "E/E0".into(),
            x: h.t.clone(),
            y: h.energy.clone(),
            reference: false,
        }],
    });
    Ok(rep)
}
