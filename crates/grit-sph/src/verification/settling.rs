//! A single abrasive settling in still water through the unresolved coupling (the water-jet
//! scene's checks 5 and 6, docs/jet.md): the DEM grain driven by `coupling::coupling_forces`
//! against `coupling::terminal_velocity`, with the coupling's action–reaction and porosity
//! volume checked at every step.

use super::{fail, CaseReport, Chart, Row, Series};
use crate::coupling::{
    coupling_forces, disc_area, find_pairs, porosity, sphere_force, stokes_relaxation_time,
    stokes_velocity, terminal_velocity, CouplingParams, FluidView,
};
use crate::dem::{Dem, DemParams, Grain};
use crate::error::SimError;
use crate::fluid::Fluid;
use crate::math::Vector;

/// Gravity (m/s²).
const G: f64 = 9.81;
/// The garnet-like abrasive of the AWJ paper: diameter (m) and density (kg/m³).
const D: f64 = 0.2e-3;
const RHO_P: f64 = 4120.0;
/// Fluid lattice spacing, the AWJ paper's d_ini (m).
const DX: f64 = 50e-6;
/// Length of the run and of the averaging window at its end, in Stokes relaxation times
/// τ = ρ_p d²/(18 μ) (9.2 ms).
const RUN_TAUS: f64 = 6.0;
const WINDOW_TAUS: f64 = 1.0;
/// Tolerances of the table: settling 5 %, coupling 1 %.
const TOL_SETTLING: f64 = 0.05;
const TOL_COUPLING: f64 = 0.01;

/// The largest of the per-step checks of the coupling.
#[derive(Debug, Default, Clone, Copy)]
struct Worst {
    /// |Σ_a F_fa + F_af| / |F_af|.
    momentum: f64,
    /// |Σ_a V_a (1 − ε_a) − V_i| / V_i.
    volume: f64,
    /// Fluid particles whose porosity hit the floor.
    floored: usize,
}

/// A garnet grain (d = 0.2 mm, ρ_p = 4120 kg/m³) released from rest in a block of still water
/// on the AWJ paper's lattice (Δx = 50 µm), R_c = 2 d, `steps_per_tau` DEM steps per Stokes
/// relaxation time τ, for 6 τ. The water is held at rest in its hydrostatic state as the grain
/// passes: ρ̄_a = ε_a ρ0 (eq. 21) and θ_a = −∇P/ρ̄_a = ρ0 g/ρ̄_a upwards, so the grain feels
/// buoyancy and drag and the water's reaction is computed but not applied. Rows: the mean
/// settling speed over the last τ against `terminal_velocity` at the grain's mean porosity ε_i
/// of the same window (bound 5 %); the largest |Σ F_fa + F_af| / |F_af| and
/// |Σ V_a (1 − ε_a) − V_i| / V_i over the steps (bound 1 % each).
pub fn settling(steps_per_tau: usize) -> Result<CaseReport, SimError> {
    if steps_per_tau < 10 {
        return Err(fail(format!(
            "settling: steps_per_tau = {steps_per_tau}, needs at least 10"
        )));
    }
    let water = Fluid::water();
    let rho0 = water.density();
    let params = CouplingParams::default();
    let tau = stokes_relaxation_time(RHO_P, D, &water);
    let dt = tau / steps_per_tau as f64;
    let steps = (RUN_TAUS * steps_per_tau as f64).round() as usize;
    let window_from = steps - (WINDOW_TAUS * steps_per_tau as f64).round() as usize;
    // The block reaches R_c past the grain sideways and above, and below where it will have
    // fallen at the Stokes speed, an upper bound.
    let rc = params.radius_factor * D;
    let fall = stokes_velocity(RHO_P, D, &water, G) * RUN_TAUS * tau;
    let (nx, y_lo, y_hi) = ((rc / DX).ceil() as i64 + 2, -(fall + rc), rc + 2.0 * DX);
    let mut pos = Vec::new();
    for j in (y_lo / DX).floor() as i64..=(y_hi / DX).ceil() as i64 {
        for i in -nx..=nx {
            // Offset by a quarter spacing so the grain crosses the lattice at no special place.
            pos.push(Vector::new((i as f64 + 0.25) * DX, (j as f64 + 0.25) * DX));
        }
    }
    let n = pos.len();
    let vel = vec![Vector::zeros(); n];
    let mass = vec![rho0 * DX * DX; n];
    let grain = Grain::sphere(Vector::zeros(), 0.5 * D, RHO_P);
    let mut dem = Dem::new(
        vec![grain],
        vec![],
        DemParams::default(),
        Vector::new(0.0, -G),
    )
    .map_err(|e| fail(e.to_string()))?;
    let v_i = disc_area(0.5 * D);
    let err = |step: usize, e: crate::error::InputError| SimError {
        step: step as u64,
        time_s: step as f64 * dt,
        what: format!("settling: {e}"),
    };
    let mut worst = Worst::default();
    let (mut sum_v, mut sum_eps, mut samples) = (0.0, 0.0, 0usize);
    let (mut eps_lo, mut eps_hi) = (f64::INFINITY, 0.0f64);
    let mut trace = (Vec::new(), Vec::new());
    for step in 0..steps {
        let grains = &dem.grains;
        let pairs = find_pairs(&params, &pos, grains).map_err(|e| err(step, e))?;
        let eps = porosity(&params, n, grains, &pairs);
        let rho_bar: Vec<f64> = eps.values.iter().map(|e| e * rho0).collect();
        let theta: Vec<Vector> = rho_bar
            .iter()
            .map(|r| Vector::new(0.0, rho0 * G / r))
            .collect();
        let view = FluidView {
            position: &pos,
            velocity: &vel,
            mass: &mass,
            rho_bar: &rho_bar,
        };
        let f = coupling_forces(&params, &water, view, &eps.values, &theta, grains, &pairs)
            .map_err(|e| err(step, e))?;
        // The sums are serial, in fluid order: the same bits on any thread count.
        let reaction: Vector = f.on_fluid.iter().sum();
        let on_grain = f.on_grains[0];
        worst.momentum = worst
            .momentum
            .max((reaction + on_grain).norm() / on_grain.norm());
        let displaced: f64 = eps.values.iter().map(|e| DX * DX * (1.0 - e)).sum();
        worst.volume = worst.volume.max((displaced - v_i).abs() / v_i);
        worst.floored = worst.floored.max(eps.floored);
        let eps_i = f.grain_fluid[0].porosity;
        dem.step(dt, &[sphere_force(on_grain, 0.5 * D)])
            .map_err(|e| err(step, e))?;
        let vy = dem.grains[0].vel.y;
        if step >= window_from {
            sum_v += -vy;
            sum_eps += eps_i;
            samples += 1;
            eps_lo = eps_lo.min(eps_i);
            eps_hi = eps_hi.max(eps_i);
        }
        if step % (steps_per_tau / 10).max(1) == 0 {
            trace.0.push((step + 1) as f64 * dt * 1e3);
            trace.1.push(-vy);
        }
    }
    let (v_mean, eps_mean) = (sum_v / samples as f64, sum_eps / samples as f64);
    let reference = terminal_velocity(RHO_P, D, eps_mean, &water, G, params.switch_porosity)
        .map_err(|e| fail(format!("settling: {e}")))?;
    let v_ref = reference.velocity_m_s;
    let res = format!("dx = {DX:.1e} m, R_c = 2 d, dt = tau/{steps_per_tau}");
    let mut rep = CaseReport::default();
    let e = (v_mean - v_ref).abs() / v_ref;
    rep.rows.push(Row {
        case: "jet_settling_garnet".into(),
        resolution: res.clone(),
        value: v_mean,
        reference: v_ref,
        error_rel: e,
        pass: e <= TOL_SETTLING,
        expected_fail: false,
        note: format!(
            "settling speed (m/s) of a d = 0.2 mm garnet grain in still water over the last tau \
             of {RUN_TAUS} tau (tau = {tau:.3e} s) against terminal_velocity at its mean \
             porosity {eps_mean:.5} (from {eps_lo:.5} to {eps_hi:.5}; Re {:.2}); 0.0414 m/s at \
             porosity 1; bound 5%",
            reference.reynolds
        ),
    });
    rep.rows.push(Row {
        case: "jet_coupling_momentum".into(),
        resolution: res.clone(),
        value: worst.momentum,
        reference: 0.0,
        error_rel: worst.momentum,
        pass: worst.momentum <= TOL_COUPLING,
        expected_fail: false,
        note: format!(
            "largest |sum F_fa + F_af| / |F_af| over the {steps} steps of the settling grain \
             ({n} fluid particles); bound 1%"
        ),
    });
    rep.rows.push(Row {
        case: "jet_coupling_porosity_volume".into(),
        resolution: res,
        value: worst.volume,
        reference: 0.0,
        error_rel: worst.volume,
        pass: worst.volume <= TOL_COUPLING && worst.floored == 0,
        expected_fail: false,
        note: format!(
            "largest |sum V_a (1 - eps_a) - V_i| / V_i over the same steps, V_a = dx^2, V_i the \
             disc's area; {} particles floored (must be 0); bound 1%",
            worst.floored
        ),
    });
    let ref_line = vec![v_ref; trace.0.len()];
    rep.charts.push(Chart {
        name: "jet_settling".into(),
        title: "Garnet grain d = 0.2 mm settling in still water, R_c = 2 d".into(),
        x_label: "t (ms)".into(),
        y_label: "settling speed (m/s)".into(),
        series: vec![
            Series {
                label: "DEM + coupling".into(),
                x: trace.0.clone(),
                y: trace.1,
                reference: false,
            },
            Series {
                label: "terminal_velocity at the window's porosity".into(),
                x: trace.0,
                y: ref_line,
                reference: true,
            },
        ],
    });
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grain_settles_at_its_terminal_speed_and_the_coupling_balances() {
        let rep = settling(100).unwrap();
        assert_eq!(rep.rows.len(), 3);
        for r in &rep.rows {
            eprintln!(
                "{} {:.5e} {:.5e} {:.3e} {}",
                r.case, r.value, r.reference, r.error_rel, r.note
            );
            assert!(
                r.pass,
                "{}: {} vs {} ({})",
                r.case, r.value, r.reference, r.note
            );
        }
    }
}
