//! The AWJ paper's coupling-radius study (its Figs. 10–11, docs/jet.md#one-grain-in-the-jet):
//! one grain rides a steady plane jet down onto a rigid wall, and its speed when it touches the
//! wall is compared with the paper's 166 m/s at R_c = 2.0 d; the curves for larger R_c should
//! coincide.
//!
//! The jet is the jet on a wall of `super::jet_wall` (1 mm wide, nozzle 2 mm above the wall),
//! run until its flow is established; then a garnet grain (d = 0.2 mm, 4120 kg/m³) leaves the
//! nozzle on the jet's axis at the jet's speed. The wall is, for the grain, a DEM wall on the
//! wall particles' surface; the grain meets the water only through the coupling.

use super::jet_wall::{jet_wall_world, JET_B};
use super::{fail, CaseReport, Chart, Row, Series};
use crate::coupling::CouplingParams;
use crate::dem::{Dem, DemParams, Grain, Wall};
use crate::error::SimError;
use crate::fluid::Fluid;
use crate::math::Vector;
use crate::world::{Abrasives, PenaltyParams, World};

/// The paper's contact speed of the unresolved grain at R_c = 2.0 d (m/s; its Fig. 11).
pub const PAPER_CONTACT_SPEED: f64 = 166.0;
/// The paper's contact speed of the fully resolved grain (m/s; its Fig. 11).
pub const PAPER_RESOLVED_SPEED: f64 = 162.0;
/// Grain diameter (m) and density (kg/m³): the paper's garnet-like abrasive.
const GRAIN_D: f64 = 0.2e-3;
const GRAIN_RHO: f64 = 4120.0;
/// Time the jet runs before the grain is released, in transit times b/v after its head reaches
/// the wall: the jet on a wall's force has settled by then (`jet_wall`'s window opens at 6).
const SETTLE_B_OVER_V: f64 = 6.0;
/// The bound on the contact speed at R_c = 2.0 d.
const TOL_CONTACT: f64 = 0.05;

/// What one grain's ride measured.
#[derive(Debug, Clone)]
pub struct GrainRide {
    /// R_c / d.
    pub rc_over_d: f64,
    /// The grain's speed at its first contact with the wall (m/s).
    pub contact_speed_m_s: f64,
    /// Time since release (µs) and the grain's downward speed (m/s), every step.
    pub trace: (Vec<f64>, Vec<f64>),
}

/// A steady jet on a wall, `n` particles across, at `speed` m/s: the world the grains are
/// released into.
pub fn settled_jet(n: usize, speed: f64) -> Result<World, SimError> {
    let mut world = jet_wall_world(n, speed, Fluid::water())?;
    let t_b = JET_B / speed;
    let t_settled = (2.0 + SETTLE_B_OVER_V) * t_b;
    world.run_until(t_settled, |_| false)?;
    Ok(world)
}

/// Releases one grain into a copy of the settled jet `jet` with coupling radius `rc_over_d` d
/// and follows it to the wall.
pub fn ride(jet: &World, speed: f64, rc_over_d: f64) -> Result<GrainRide, SimError> {
    let mut w = jet.clone();
    let err = |e: crate::error::InputError| fail(format!("jet_grain: {e}"));
    let floor = Wall::new(Vector::zeros(), Vector::new(0.0, 1.0)).map_err(err)?;
    let dem = Dem::new(
        Vec::new(),
        vec![floor],
        DemParams::default(),
        Vector::zeros(),
    )
    .map_err(err)?;
    let coupling = CouplingParams {
        radius_factor: rc_over_d,
        ..CouplingParams::default()
    };
    w.set_abrasives(Abrasives::new(
        dem,
        coupling,
        PenaltyParams::default(),
        Some(0),
    ))
    .map_err(err)?;
    let r = 0.5 * GRAIN_D;
    let top = jet
        .inflows()
        .first()
        .map(|i| i.nozzle.centre_m.y)
        .ok_or_else(|| fail("jet_grain: the jet has no nozzle".into()))?;
    let mut g = Grain::sphere(Vector::new(0.0, top - r), r, GRAIN_RHO);
    g.vel = Vector::new(0.0, -speed);
    w.add_grain(g).map_err(err)?;
    let t0 = w.time();
    let mut trace = (Vec::new(), Vec::new());
    let t_max = t0 + 10.0 * top / speed;
    loop {
        w.step()?;
        let ab = w.abrasives().expect("set above");
        let Some(g) = ab.dem.grains.first() else {
            return Err(fail("jet_grain: the grain left the scene".into()));
        };
        trace.0.push((w.time() - t0) * 1e6);
        trace.1.push(-g.vel.y);
        if g.pos.y <= r {
            return Ok(GrainRide {
                rc_over_d,
                contact_speed_m_s: g.vel.norm(),
                trace,
            });
        }
        if w.time() > t_max {
            return Err(fail(format!(
                "jet_grain: no contact within {:.2e} s at R_c = {rc_over_d} d",
                t_max - t0
            )));
        }
    }
}

/// The coupling radii of the study, in grain diameters (the paper's Fig. 11).
pub const RC_FACTORS: [f64; 5] = [1.0, 1.5, 2.0, 2.5, 3.0];
/// Bound on the relative difference of the contact speeds at R_c = 2.5 d and 3.0 d for the
/// curves to count as coinciding (ours; the paper says only that they coincide).
const TOL_COINCIDE: f64 = 0.05;

/// The study's rows, on a jet `n` particles across at `speed` m/s: the contact speed at each
/// R_c of [`RC_FACTORS`] (2.0 d judged against the paper's 166 m/s within 5 %, and expected to
/// miss it: docs/jet.md#one-grain-in-the-jet), whether 2.5 d and 3.0 d coincide, and the chart
/// of the grains' speeds.
pub fn rc_study(n: usize, speed: f64) -> Result<CaseReport, SimError> {
    let jet = settled_jet(n, speed)?;
    let mut rep = CaseReport::default();
    let mut series = Vec::new();
    let mut contact = Vec::new();
    for f in RC_FACTORS {
        let ride = ride(&jet, speed, f)?;
        let v = ride.contact_speed_m_s;
        contact.push(v);
        let err = (v - PAPER_CONTACT_SPEED).abs() / PAPER_CONTACT_SPEED;
        let judged = (f - 2.0).abs() < 1e-9;
        rep.rows.push(Row {
            case: format!("jet_rc_contact_speed_{f:.1}d"),
            resolution: format!("b/dx={n}, v={speed} m/s"),
            value: v,
            reference: PAPER_CONTACT_SPEED,
            error_rel: err,
            pass: !judged || err <= TOL_CONTACT,
            expected_fail: judged,
            note: if judged {
                format!(
                    "grain speed (m/s) at wall contact, R_c = {f} d; paper 166 (resolved 162) at a jet speed its text does not give; bound 5%, missed"
                )
            } else {
                format!("grain speed (m/s) at wall contact, R_c = {f} d; reported, not judged")
            },
        });
        series.push(Series {
            label: format!("R_c = {f} d"),
            x: ride.trace.0,
            y: ride.trace.1,
            reference: false,
        });
    }
    let (v25, v30) = (contact[3], contact[4]);
    let diff = (v30 - v25).abs() / v25;
    rep.rows.push(Row {
        case: "jet_rc_coincide_2.5d_3.0d".into(),
        resolution: format!("b/dx={n}, v={speed} m/s"),
        value: diff,
        reference: 0.0,
        error_rel: diff,
        pass: diff <= TOL_COINCIDE,
        expected_fail: false,
        note: "|v(3.0 d) - v(2.5 d)| / v(2.5 d) at wall contact; bound 5%".into(),
    });
    rep.charts.push(Chart {
        name: "jet_rc_study".into(),
        title: format!("One grain in a {speed} m/s jet on a wall (b/dx = {n})"),
        x_label: "time since release (µs)".into(),
        y_label: "grain speed towards the wall (m/s)".into(),
        series,
    });
    Ok(rep)
}
