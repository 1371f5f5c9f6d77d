//! Controlled sliding on a flat surface (seed section 3.3.2): a rigid slider pressed down by Fn
//! and pulled by Ft(t) = 0.8 Fn min(t / 1 s, 1), μ = 0.5. It sticks until Ft = μ Fn at 0.625 s,
//! then accelerates ever faster until 1 s and at a constant rate after (docs/references.md#verification).

use super::slope::{spring_stiffness, TANGENTIAL_OVER_NORMAL};
use super::{CaseReport, Chart, Row, Series};
use crate::body::ExternalForce;
use crate::body::Motion;
use crate::contact::{ContactModel, ContactParams};
use crate::error::SimError;
use crate::geometry::Polygon;
use crate::math::Vector;
use crate::world::{Settings, World};

/// Friction coefficient.
pub const MU: f64 = 0.5;
/// Normal force (N/m).
pub const FN: f64 = 100.0;
/// Nominal slider width (m); the particle spacing is SIDE / n.
pub const SIDE: f64 = 0.1;
/// Slider height (m): low, so that the friction torque Ft·HEIGHT/2 never unloads the trailing
/// edge (a square slider lifts it once Ft > Fn/3 and tilts on its springs).
pub const HEIGHT: f64 = 0.02;
/// Slider mass (kg/m); the density is set from the slider's area to keep it.
pub const MASS: f64 = 10.0;
/// End of the run (s).
pub const DURATION: f64 = 1.5;
/// Analytic onset of sliding (s): 0.8 Fn t = μ Fn.
pub const ONSET: f64 = MU / 0.8;
/// Speed above which the slider counts as sliding (m/s): ten times the speed at which the
/// loaded springs of a sticking slider yield elastically (about 1e-6 m/s, measured), reached by
/// the analytic solution 1.6 ms after the onset, well inside the ±10 ms bound.
pub const SLIDE_SPEED: f64 = 1e-5;
/// Settling time under Fn alone before the clock starts (s).
pub const SETTLE_S: f64 = 0.1;
/// Friction while settling: holds the slider still while its springs load.
pub const SETTLE_FRICTION: f64 = 1.0;

/// Analytic slider speed (m/s): a = (Ft(t) − μ Fn)/M after the onset, integrated (seed 3.3.2).
pub fn analytic_speed(t: f64) -> f64 {
    let a = FN / MASS;
    if t <= ONSET {
        0.0
    } else if t <= 1.0 {
        a * (0.4 * (t * t - ONSET * ONSET) - MU * (t - ONSET))
    } else {
        a * (0.4 * (1.0 - ONSET * ONSET) - MU * (1.0 - ONSET)) + a * (0.8 - MU) * (t - 1.0)
    }
}

/// The slider, a HEIGHT-high rectangle whose bottom edge is split in two collinear edges of
/// (m + f) Δx each, f = m / (2m + 1), so that its 2m + 1 bottom particles sit at evenly spread
/// phases of the floor's particle period.
///
/// The extrapolated normal above a row of particles tilts by up to 4e-3 rad between them
/// (eq. 22); with both rows spaced Δx every slider particle sees the same tilt, and the slider
/// rides a washboard of ±0.4 % Fn that advances the onset and leaves a speed offset of several
/// percent. Spread over a full period the tilts cancel.
pub fn slider_polygon(n_side: usize) -> Polygon {
    let dx = SIDE / n_side as f64;
    let m = (n_side - 1) / 2;
    let f = m as f64 / (2 * m + 1) as f64;
    let edge = (m as f64 + f) * dx;
    let w = 2.0 * edge + dx;
    Polygon::new(
        &[
            [0.0, 0.0],
            [0.5 * dx + edge, 0.0],
            [w, 0.0],
            [w, HEIGHT],
            [0.0, HEIGHT],
        ],
        "slider",
    )
    .expect("valid slider")
}

/// Simulated (t, tangential speed) samples every `sample_dt`, with `n_side` particles across the
/// slider, and the slider's speed left at the end of the settling phase (m/s).
pub fn simulate(n_side: usize, sample_dt: f64) -> Result<(Vec<(f64, f64)>, f64), SimError> {
    let dx = SIDE / n_side as f64;
    let settings = Settings {
        spacing_m: dx,
        shepard_interval: 0,
        hourglass: 0.0,
        dt_max_s: 1e-3,
        ..Settings::default()
    };
    let mut w = World::new(settings).expect("valid settings");
    // Distance slid is under v(1.5 s) · 1.5 s.
    let travel = analytic_speed(DURATION) * DURATION + 2.0 * SIDE;
    let floor = Polygon::rectangle(-SIDE, -3.0 * dx, travel + SIDE, 0.0);
    let slider = slider_polygon(n_side);
    let floor_b = w
        .add_rigid(
            "floor",
            &floor,
            MASS / slider.area(),
            Vector::zeros(),
            0.0,
            Motion::Fixed,
        )
        .expect("floor");
    let slider_b = w
        .add_rigid(
            "slider",
            &slider,
            MASS / slider.area(),
            Vector::zeros(),
            0.0,
            Motion::Free,
        )
        .expect("slider");
    // The long straight floor is the primary: the slider's particles then see its exact normal
    // everywhere, corners included. Springs as in the slope case (slope.rs says why).
    let k = spring_stiffness(FN, n_side, dx);
    let ci = w
        .add_contact(
            floor_b,
            slider_b,
            ContactParams {
                model: ContactModel::Extrapolated,
                friction: SETTLE_FRICTION,
                normal_stiffness_pa: Some(k),
                tangential_stiffness_pa: Some(TANGENTIAL_OVER_NORMAL * k),
                damping_ratio: 0.5,
            },
        )
        .expect("contact");
    let force = ExternalForce {
        constant_n_m: Vector::new(0.0, -FN),
        ramp_n_m: Vector::new(0.8 * FN, 0.0),
        ramp_s: 1.0,
        ramp_start_s: SETTLE_S,
    };
    w.set_external_force(slider_b, force).expect("rigid");
    w.run_until(SETTLE_S, |_| false)?;
    w.contact_params_mut(ci).friction = MU;
    // The analytic solution starts from rest: drop what is left of the settling motion.
    let r = w.body_mut(slider_b).rigid_mut().expect("rigid");
    let settled_speed = r.velocity_m_s.norm();
    r.velocity_m_s = Vector::zeros();
    r.omega_rad_s = 0.0;
    let t0 = w.time();
    let mut out = vec![(0.0, 0.0)];
    let mut next = sample_dt;
    while w.time() - t0 < DURATION - 1e-12 {
        w.step()?;
        if w.time() - t0 >= next - 1e-12 {
            let v = w.bodies()[slider_b].rigid().expect("rigid").velocity_m_s;
            out.push((w.time() - t0, v.x));
            next += sample_dt;
        }
    }
    Ok((out, settled_speed))
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
    let (sm, settled) = simulate(n_side, 0.001)?;
    let (onset, rel, abs) = errors(&sm);
    let creep = sm
        .iter()
        .filter(|s| s.0 < 0.6)
        .map(|s| s.1.abs())
        .fold(0.0, f64::max);
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
        pass: (onset - ONSET).abs() <= 0.01 && settled <= 0.1 * SLIDE_SPEED,
        expected_fail: false,
        note: format!(
            "time (s) the speed first exceeds {SLIDE_SPEED} m/s; bound ±0.01 s; largest speed before 0.6 s {creep:.1e} m/s; speed left after settling {settled:.1e} m/s, bound {:.0e}",
            0.1 * SLIDE_SPEED
        ),
    });
    rep.rows.push(Row {
        case: "controlled_sliding_speed".into(),
        resolution: res,
        value: sm.last().map(|s| s.1).unwrap_or(0.0),
        reference: analytic_speed(DURATION),
        error_rel: rel,
        pass: rel <= 0.03,
        expected_fail: false,
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
