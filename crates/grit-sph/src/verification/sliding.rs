//! Controlled sliding on a flat surface (seed section 3.3.2): a rigid slider pressed down by Fn
//! and pulled by Ft(t) = 0.8 Fn min(t / 1 s, 1), μ = 0.5. It sticks until Ft = μ Fn at 0.625 s,
//! then accelerates ever faster until 1 s and at a constant rate after (NOTES.md).

use super::{CaseReport, Chart, Row, Series};
use crate::body::ExternalForce;
use crate::contact::ContactModel;
use crate::error::SimError;
use crate::geometry::Polygon;
use crate::math::Vector;
use crate::world::{Settings, World};

/// Friction coefficient.
pub const MU: f64 = 0.5;
/// Normal force (N/m).
pub const FN: f64 = 100.0;
/// Slider side (m).
pub const SIDE: f64 = 0.1;
/// Slider density (kg/m³).
pub const RHO: f64 = 1000.0;
/// End of the run (s).
pub const DURATION: f64 = 1.5;
/// Analytic onset of sliding (s): 0.8 Fn t = μ Fn.
pub const ONSET: f64 = MU / 0.8;
/// Speed above which the slider counts as sliding (m/s): the analytic speed reaches it 5 ms
/// after the onset, while a sticking contact creeps at under 1e-6 m/s.
pub const SLIDE_SPEED: f64 = 1e-4;
/// Settling time under Fn alone before the clock starts (s).
pub const SETTLE_S: f64 = 0.1;

/// Analytic slider speed (m/s).
pub fn analytic_speed(t: f64) -> f64 {
    let a = FN / (RHO * SIDE * SIDE);
    if t <= ONSET {
        0.0
    } else if t <= 1.0 {
        a * (0.4 * (t * t - ONSET * ONSET) - MU * (t - ONSET))
    } else {
        a * (0.4 * (1.0 - ONSET * ONSET) - MU * (1.0 - ONSET)) + a * (0.8 - MU) * (t - 1.0)
    }
}

/// Simulated (t, tangential speed) samples.
pub fn simulate(n_side: usize, sample_dt: f64) -> Result<Vec<(f64, f64)>, SimError> {
    let dx = SIDE / n_side as f64;
    let settings = Settings {
        spacing_m: dx,
        shepard_interval: 0,
        hourglass: 0.0,
        dt_max_s: 1e-3,
        ..Settings::default()
    };
    let mut w = World::new(settings).expect("valid settings");
    let travel = analytic_speed(DURATION) * DURATION + 2.0 * SIDE;
    let floor = Polygon::rectangle(-SIDE, -3.0 * dx, travel + SIDE, 0.0);
    let slider = Polygon::rectangle(0.0, 0.0, SIDE, SIDE);
    let (_, slider_b, _) = super::slope::slider_on_floor(
        &mut w,
        &floor,
        &slider,
        RHO,
        FN,
        n_side,
        ContactModel::Extrapolated,
        MU,
    );
    let force = ExternalForce {
        constant_n_m: Vector::new(0.0, -FN),
        ramp_n_m: Vector::new(0.8 * FN, 0.0),
        ramp_s: 1.0,
        ramp_start_s: SETTLE_S,
    };
    w.set_external_force(slider_b, force).expect("rigid");
    w.run_until(SETTLE_S, |_| false)?;
    super::slope::release_and_sample(&mut w, slider_b, Vector::new(1.0, 0.0), DURATION, sample_dt)
}

/// (onset time, worst relative speed error from 0.75 s on, worst absolute error after onset).
pub fn errors(samples: &[(f64, f64)]) -> (f64, f64, f64) {
    let onset = samples
        .iter()
        .find(|s| s.1 > SLIDE_SPEED)
        .map(|s| s.0)
        .unwrap_or(f64::INFINITY);
    let rel = samples
        .iter()
        .filter(|s| s.0 >= 0.75)
        .map(|&(t, v)| (v - analytic_speed(t)).abs() / analytic_speed(t))
        .fold(0.0, f64::max);
    let abs = samples
        .iter()
        .filter(|s| s.0 >= ONSET)
        .map(|&(t, v)| (v - analytic_speed(t)).abs())
        .fold(0.0, f64::max);
    (onset, rel, abs)
}

/// Runs the case and reports onset and speed error.
pub fn run(n_side: usize) -> Result<CaseReport, SimError> {
    let sm = simulate(n_side, 0.001)?;
    let (onset, rel, abs) = errors(&sm);
    let res = format!(
        "{n_side} particles per side (dx={:.4} m)",
        SIDE / n_side as f64
    );
    let mut rep = CaseReport::default();
    rep.rows.push(Row {
        case: "controlled_sliding_onset".into(),
        resolution: res.clone(),
        value: onset,
        reference: ONSET,
        error_rel: (onset - ONSET).abs() / ONSET,
        pass: (onset - ONSET).abs() <= 0.01,
        note: format!("time (s) the speed first exceeds {SLIDE_SPEED} m/s; bound ±0.01 s"),
    });
    rep.rows.push(Row {
        case: "controlled_sliding_speed".into(),
        resolution: res,
        value: sm.last().map(|s| s.1).unwrap_or(0.0),
        reference: analytic_speed(DURATION),
        error_rel: rel,
        pass: rel <= 0.03,
        note: format!("speed at 1.5 s (m/s); error = max relative error from 0.75 s to 1.5 s, bound 3%; max absolute error after onset {abs:.2e} m/s"),
    });
    let ts: Vec<f64> = (0..=150).map(|k| k as f64 * 0.01).collect();
    let thin: Vec<&(f64, f64)> = sm.iter().step_by(20).collect();
    rep.charts.push(Chart {
        name: "controlled_sliding".into(),
        title: "Controlled sliding, mu = 0.5 (seed 3.3.2)".into(),
        x_label: "time (s)".into(),
        y_label: "slider speed (m/s)".into(),
        series: vec![
            Series {
                label: "simulation".into(),
                x: thin.iter().map(|s| s.0).collect(),
                y: thin.iter().map(|s| s.1).collect(),
                reference: false,
            },
            Series {
                label: "analytic".into(),
                y: ts.iter().map(|&t| analytic_speed(t)).collect(),
                x: ts,
                reference: true,
            },
        ],
    });
    Ok(rep)
}
