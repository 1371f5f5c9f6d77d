//! Checks of the water-jet scene's building blocks with analytic references (docs/jet.md):
//! the copper Hugoniot of the Mie–Grüneisen EOS, the DEM drop of the AWJ paper's Fig. 4, the
//! head-on restitution of two grains, the water column at rest (`super::hydrostatic`), a
//! grain settling through the coupling (`super::settling`), a jet on a wall
//! (`super::jet_wall`) and one grain riding that jet onto the wall (`super::jet_grain`).

use super::{fail, CaseReport, Chart, Row, Series};
use crate::dem::{contact_time, damping_ratio, Dem, DemParams, Grain, Wall};
use crate::eos::EquationOfState;
use crate::error::SimError;
use crate::material::Material;
use crate::math::Vector;

/// Gravity of the drop (m/s²).
pub const G: f64 = 9.81;
/// Drop: grain radius (m) and initial centre height (m), the AWJ paper's Fig. 4.
pub const DROP_R: f64 = 5e-3;
/// Drop: initial centre height (m).
pub const DROP_H0: f64 = 50e-3;
/// Restitution of the drop.
pub const DROP_E: f64 = 0.8;
/// Copper Hugoniot reference: particle speed (m/s) and published pressure (Pa).
pub const HUGONIOT_UP: f64 = 200.0;
/// Reference pressure behind the shock at `HUGONIOT_UP` (Pa).
pub const HUGONIOT_P: f64 = 7.59e9;

/// Tolerances of the verification table: hugoniot 2 %, dem_drop 1 %, restitution 2 %.
const TOL_HUGONIOT: f64 = 0.02;
const TOL_DROP: f64 = 0.01;
const TOL_RESTITUTION: f64 = 0.02;

/// Runs all rows; the DEM steps are `dt_scale` × `Dem::time_step()`, the water column is
/// `hydro_n` particles high, the settling grain takes `settle_steps` steps per Stokes time, and
/// the jet on a wall has `wall_n` particles across at `wall_speed` m/s, and the grain's jet
/// (the coupling-radius study) is `rc`.
pub fn run(
    dt_scale: f64,
    hydro_n: usize,
    settle_steps: usize,
    (wall_n, wall_speed): (usize, f64),
    rc: super::jet_grain::RcScene,
) -> Result<CaseReport, SimError> {
    let mut rep = hugoniot()?;
    rep.extend(dem_drop(dt_scale)?);
    for e in [0.3, 0.8, 0.95] {
        rep.extend(restitution(e, dt_scale)?);
    }
    rep.extend(super::hydrostatic::hydrostatic(hydro_n)?);
    rep.extend(super::settling::settling(settle_steps)?);
    rep.extend(super::jet_wall::jet_wall(wall_n, wall_speed)?);
    rep.extend(super::jet_grain::rc_study(rc)?);
    Ok(rep)
}

/// Copper on its Hugoniot at up = 200 m/s: the EOS at the shocked density and the
/// Rankine–Hugoniot energy against 7.59 GPa; and the same without the energy term (e = 0), a row
/// meant to miss, showing what a cold EOS loses.
pub fn hugoniot() -> Result<CaseReport, SimError> {
    let cu = Material::copper();
    let Some(EquationOfState::MieGruneisen(g)) = &cu.eos else {
        return Err(fail("copper preset lost its Mie-Grüneisen EOS".into()));
    };
    let h = g.hugoniot(HUGONIOT_UP);
    let mut rep = CaseReport::default();
    for (case, e, expected_fail) in [
        ("jet_hugoniot_copper_up200", h.energy_j_kg, false),
        ("jet_hugoniot_copper_up200_cold", 0.0, true),
    ] {
        let p = g.pressure(h.rho_kg_m3, e);
        let err = (p - HUGONIOT_P).abs() / HUGONIOT_P;
        rep.rows.push(Row {
            case: case.into(),
            resolution: "single point".into(),
            value: p,
            reference: HUGONIOT_P,
            error_rel: err,
            pass: err <= TOL_HUGONIOT,
            expected_fail,
            note: format!(
                "EOS pressure (Pa) at rho = {:.1} kg/m3 (Us = {:.0} m/s), e = {e:.0} J/kg; bound 2%{}",
                h.rho_kg_m3,
                h.shock_speed_m_s,
                if expected_fail {
                    "; without the energy term, meant to miss"
                } else {
                    ""
                }
            ),
        });
    }
    Ok(rep)
}

/// A grain dropped in a DEM scene, followed to its third apex.
pub(crate) struct DropRun {
    /// Time of the first contact (s).
    pub first_contact: Option<f64>,
    /// Centre heights at the apexes after each bounce (m).
    pub apexes: Vec<f64>,
    /// Time (s) and centre height (mm), every `every` steps.
    pub trace: (Vec<f64>, Vec<f64>),
    /// Time of the third apex, where the run stopped (s).
    pub end_s: f64,
}

/// Steps grain 0 of `dem` by `dt` until its third apex after a bounce (an error past 1 s or a
/// non-finite height), noting the first contact and the apexes.
pub(crate) fn drop_to_third_apex(dem: &mut Dem, dt: f64, every: u64) -> Result<DropRun, SimError> {
    let (mut t, mut step) = (0.0, 0u64);
    let mut first_contact = None;
    let mut apexes = Vec::new();
    let mut prev_vy = 0.0;
    let mut trace = (Vec::new(), Vec::new());
    while apexes.len() < 3 {
        dem.step(dt, &[]).map_err(|e| fail(e.to_string()))?;
        t += dt;
        step += 1;
        if first_contact.is_none() && !dem.contacts().is_empty() {
            first_contact = Some(t);
        }
        let g = &dem.grains[0];
        if prev_vy > 0.0 && g.vel.y <= 0.0 {
            apexes.push(g.pos.y);
        }
        prev_vy = g.vel.y;
        if step % every == 0 {
            trace.0.push(t);
            trace.1.push(g.pos.y * 1e3);
        }
        if t > 1.0 || !g.pos.y.is_finite() {
            return Err(SimError {
                step,
                time_s: t,
                what: format!("dem_drop: {} apexes within 1 s", apexes.len()),
            });
        }
    }
    Ok(DropRun {
        first_contact,
        apexes,
        trace,
        end_s: t,
    })
}

/// The AWJ paper's Fig. 4 drop: R = 5 mm from a centre height of 50 mm onto a rigid floor,
/// garnet-like grain, e = 0.8. First contact at √(2 (h0 − R)/g), apex n at R + e^{2n} (h0 − R).
pub fn dem_drop(dt_scale: f64) -> Result<CaseReport, SimError> {
    let floor =
        Wall::new(Vector::zeros(), Vector::new(0.0, 1.0)).map_err(|e| fail(e.to_string()))?;
    let params = DemParams {
        restitution: DROP_E,
        ..DemParams::default()
    };
    let grain = Grain::sphere(Vector::new(0.0, DROP_H0), DROP_R, 4120.0);
    let mut dem = Dem::new(vec![grain], vec![floor], params, Vector::new(0.0, -G))
        .map_err(|e| fail(e.to_string()))?;
    let dt = dt_scale * dem.time_step();
    let every = ((2e-4 / dt).ceil() as u64).max(1);
    let DropRun {
        first_contact,
        apexes,
        trace,
        end_s: t,
    } = drop_to_third_apex(&mut dem, dt, every)?;
    let res = format!("dt = {dt:.3e} s ({dt_scale} x the DEM limit)");
    let mut rep = CaseReport::default();
    let t_ref = (2.0 * (DROP_H0 - DROP_R) / G).sqrt();
    let tc = first_contact.unwrap_or(f64::NAN);
    let err = (tc - t_ref).abs() / t_ref;
    rep.rows.push(Row {
        case: "jet_dem_drop_first_contact".into(),
        resolution: res.clone(),
        value: tc,
        reference: t_ref,
        error_rel: err,
        pass: err <= TOL_DROP,
        expected_fail: false,
        note: "time of first contact (s), free fall; the AWJ paper reads ~0.096 s; bound 1%".into(),
    });
    for (n, y) in apexes.iter().enumerate() {
        let reference = DROP_R + DROP_E.powi(2 * (n as i32 + 1)) * (DROP_H0 - DROP_R);
        let err = (y - reference).abs() / reference;
        rep.rows.push(Row {
            case: format!("jet_dem_drop_apex{}", n + 1),
            resolution: res.clone(),
            value: *y,
            reference,
            error_rel: err,
            pass: err <= TOL_DROP,
            expected_fail: false,
            note: format!(
                "centre height (m) at apex {} after a bounce, R + e^{} (h0 - R), e = {DROP_E}; bound 1%",
                n + 1,
                2 * (n + 1)
            ),
        });
    }
    let ts: Vec<f64> = (0..=400).map(|k| k as f64 * t / 400.0).collect();
    let ys = ts.iter().map(|&s| ballistic_height(s) * 1e3).collect();
    rep.charts.push(Chart {
        name: "jet_dem_drop".into(),
        title: format!("DEM drop, R = 5 mm from 50 mm, e = {DROP_E}"),
        x_label: "t (s)".into(),
        y_label: "centre height (mm)".into(),
        series: vec![
            Series {
                label: "DEM".into(),
                x: trace.0,
                y: trace.1,
                reference: false,
            },
            Series {
                label: "free flight, instant bounces".into(),
                x: ts,
                y: ys,
                reference: true,
            },
        ],
    });
    Ok(rep)
}

/// Centre height of the drop with instantaneous bounces of restitution e (m).
fn ballistic_height(t: f64) -> f64 {
    let t0 = (2.0 * (DROP_H0 - DROP_R) / G).sqrt();
    if t <= t0 {
        return DROP_H0 - 0.5 * G * t * t;
    }
    let mut v = G * t0 * DROP_E;
    let mut start = t0;
    loop {
        let flight = 2.0 * v / G;
        if t <= start + flight || flight < 1e-9 {
            let s = t - start;
            return DROP_R + v * s - 0.5 * G * s * s;
        }
        start += flight;
        v *= DROP_E;
    }
}

/// The grains of `restitution`, about to meet head-on.
pub(crate) fn head_on_grains() -> [Grain; 2] {
    [
        Grain {
            vel: Vector::new(5.0, 0.0),
            ..Grain::sphere(Vector::new(0.0, 0.0), 1e-4, 4120.0)
        },
        Grain {
            vel: Vector::new(-3.0, 0.0),
            ..Grain::sphere(Vector::new(1.7e-4, 0.0), 0.6e-4, 4120.0)
        },
    ]
}

/// Two unequal garnet-like grains head-on (radii 0.1 and 0.06 mm, 5 and −3 m/s): the relative
/// rebound speed over the approach speed against e, and the contact time against
/// π/(ω0 √(1 − ξ²)), ω0 = √(k_n/m*).
pub fn restitution(e: f64, dt_scale: f64) -> Result<CaseReport, SimError> {
    let [a, b] = head_on_grains();
    let params = DemParams {
        restitution: e,
        ..DemParams::default()
    };
    let mut dem =
        Dem::new(vec![a, b], vec![], params, Vector::zeros()).map_err(|e| fail(e.to_string()))?;
    let dt = dt_scale * dem.time_step();
    let v0 = dem.grains[1].vel.x - dem.grains[0].vel.x;
    let p0 = dem.momentum();
    let (mut t, mut step, mut start, mut end) = (0.0, 0u64, None, None);
    while end.is_none() {
        dem.step(dt, &[]).map_err(|e| fail(e.to_string()))?;
        t += dt;
        step += 1;
        match (start, dem.contacts().is_empty()) {
            (None, false) => start = Some(t - dt),
            (Some(_), true) => end = Some(t - dt),
            _ => {}
        }
        if t > 1e-5 {
            return Err(SimError {
                step,
                time_s: t,
                what: "restitution: the grains did not part within 10 µs".into(),
            });
        }
    }
    let (ga, gb) = (&dem.grains[0], &dem.grains[1]);
    let ratio = -(gb.vel.x - ga.vel.x) / v0;
    let law = dem.params.pair_law(ga, gb);
    let m_star = ga.mass_kg * gb.mass_kg / (ga.mass_kg + gb.mass_kg);
    let tc_ref = contact_time(law.k_n, m_star, damping_ratio(e));
    let duration = end.unwrap_or(f64::NAN) - start.unwrap_or(f64::NAN);
    let dp = (dem.momentum() - p0).norm() / (ga.mass_kg * 5.0 + gb.mass_kg * 3.0);
    let res = format!("dt = {dt:.3e} s ({dt_scale} x the DEM limit)");
    let mut rep = CaseReport::default();
    let err = (ratio - e).abs() / e;
    rep.rows.push(Row {
        case: format!("jet_restitution_e{e}"),
        resolution: res.clone(),
        value: ratio,
        reference: e,
        error_rel: err,
        pass: err <= TOL_RESTITUTION && dp < 1e-12,
        expected_fail: false,
        note: format!("relative rebound speed / approach speed; bound 2%; momentum change {dp:.1e} of the total |p|, bound 1e-12"),
    });
    let err = (duration - tc_ref).abs() / tc_ref;
    rep.rows.push(Row {
        case: format!("jet_restitution_contact_time_e{e}"),
        resolution: res,
        value: duration,
        reference: tc_ref,
        error_rel: err,
        pass: err <= TOL_RESTITUTION,
        expected_fail: false,
        note: "contact duration (s) against pi/(w0 sqrt(1 - xi^2)); bound 2%".into(),
    });
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_row_meets_its_tolerance() {
        let rc = super::super::jet_grain::RcScene::new(16, 500.0, 1.0);
        let rep = run(1.0, 12, 100, (16, 400.0), rc).unwrap();
        assert_eq!(rep.rows.len(), 2 + 4 + 6 + 2 + 3 + 3 + 6);
        for r in &rep.rows {
            assert!(
                r.pass != r.expected_fail,
                "{}: {} vs {}",
                r.case,
                r.value,
                r.reference
            );
            assert!(r.case.starts_with("jet_"));
        }
        assert_eq!(rep.charts.len(), 6);
    }

    #[test]
    fn ballistic_reference_bounces() {
        assert!((ballistic_height(0.0) - DROP_H0).abs() < 1e-15);
        let t0 = (2.0 * (DROP_H0 - DROP_R) / G).sqrt();
        assert!((ballistic_height(t0) - DROP_R).abs() < 1e-12);
        let v1 = G * t0 * DROP_E;
        let apex = ballistic_height(t0 + v1 / G);
        assert!((apex - (DROP_R + DROP_E.powi(2) * (DROP_H0 - DROP_R))).abs() < 1e-12);
    }
}
