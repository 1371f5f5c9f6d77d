//! Water and grains on a target in one world (docs/jet.md#water-on-the-target and
//! #grains-in-the-world): the fluid–solid pairs, the grains' coupling and their penalty contact
//! conserve momentum, and the bits do not depend on the thread count.

mod common;

use common::{copper_under_water, flow_bits, stepped_on};
use grit_sph::coupling::CouplingParams;
use grit_sph::dem::{Dem, DemParams, Grain};
use grit_sph::{Abrasives, PenaltyParams, Settings, Vector, World};

const DX: f64 = 1e-4;

/// A grain set without grains or walls, garnet constants, no gravity.
fn no_grains() -> Dem {
    Dem::new(
        Vec::new(),
        Vec::new(),
        DemParams::default(),
        Vector::zeros(),
    )
    .unwrap()
}

/// A free copper block (no fixed particles, no gravity) with a block of water above it moving
/// down onto it at `speed`, and, with `grains`, garnet grains in the water coupled to it.
fn water_on_copper(speed: f64, grains: bool) -> World {
    let mut w = World::new(Settings::water_jet(DX, Vector::zeros())).unwrap();
    let b = copper_under_water(&mut w, DX, 8, Vector::new(0.0, -speed));
    if grains {
        let dem = no_grains();
        w.set_abrasives(Abrasives::new(
            dem,
            CouplingParams::default(),
            PenaltyParams::default(),
            Some(b),
        ))
        .unwrap();
        for x in [6.0, 12.0] {
            let mut g = Grain::sphere(Vector::new(x * DX, 2.0 * DX), 1e-4, 4120.0);
            // Faster than the water, so drag and pressure both act.
            g.vel = Vector::new(0.0, -1.5 * speed);
            w.add_grain(g).unwrap();
        }
    }
    w
}

/// Σ m |v| over everything that moves, the scale of the momentum drift.
fn momentum_scale(w: &World) -> f64 {
    let p = w.particles();
    let grains: f64 = w.abrasives().map_or(0.0, |a| {
        a.dem
            .grains
            .iter()
            .map(|g| grit_sph::world::plane_mass(g) * g.vel.norm())
            .sum()
    });
    (0..p.len())
        .map(|i| p.mass[i] * p.vel[i].norm())
        .sum::<f64>()
        + grains
}

#[test]
fn water_hitting_a_free_block_conserves_momentum_and_stays_out_of_it() {
    let mut w = water_on_copper(100.0, false);
    let (p0, scale) = (w.momentum(), momentum_scale(&w));
    for _ in 0..300 {
        w.step().unwrap();
    }
    let drift = (w.momentum() - p0).norm() / scale;
    assert!(drift < 1e-12, "momentum drift {drift:e} of sum m|v|");
    // The block took the water's momentum: it moves down, and the water has been braked.
    let p = w.particles();
    let (mut target_py, mut water_below) = (0.0, 0);
    let top = (0..p.len())
        .filter(|&i| p.body[i] == 0)
        .map(|i| p.pos[i].y)
        .fold(f64::NEG_INFINITY, f64::max);
    for i in 0..p.len() {
        if p.body[i] == 0 {
            target_py += p.mass[i] * p.vel[i].y;
        } else if p.pos[i].y < top - DX {
            water_below += 1;
        }
    }
    assert!(target_py < 0.0, "the target was not pushed: {target_py:e}");
    assert_eq!(water_below, 0, "water particles got into the target");
}

#[test]
fn grains_in_the_water_and_on_the_target_conserve_momentum() {
    let mut w = water_on_copper(100.0, true);
    let (p0, scale) = (w.momentum(), momentum_scale(&w));
    let mut touched = false;
    for _ in 0..600 {
        w.step().unwrap();
        touched |= w.contact_forces().iter().any(|f| f.norm() > 0.0);
    }
    assert!(touched, "no grain reached the target");
    let drift = (w.momentum() - p0).norm() / scale;
    assert!(drift < 1e-12, "momentum drift {drift:e} of sum m|v|");
    let ab = w.abrasives().unwrap();
    assert_eq!(ab.dem.grains.len(), 2);
    assert!(ab.substeps >= 1);
}

#[test]
fn each_grain_logs_each_contact_start_with_its_speed_then_and_flags_its_first() {
    let mut w = water_on_copper(100.0, true);
    let (mut starts, mut steps_in_contact) = (Vec::new(), 0);
    for _ in 0..600 {
        let grains = &w.abrasives().unwrap().dem.grains;
        let before: Vec<(Vector, bool)> = grains.iter().map(|g| (g.vel, g.in_contact)).collect();
        w.step().unwrap();
        let c = w.take_grain_contacts();
        let grains = &w.abrasives().unwrap().dem.grains;
        // A start is logged for each grain that touches now and did not in the step before.
        let begun = grains
            .iter()
            .zip(&before)
            .filter(|(g, b)| g.in_contact && !b.1)
            .count();
        assert_eq!(c.starts.len(), begun);
        let touching = grains.iter().filter(|g| g.in_contact).count() as u64;
        assert_eq!(c.steps_in_contact, touching);
        for h in &c.starts {
            // The logged speed is a grain's speed at the start of the step it touched in.
            assert!(
                before.iter().any(|b| b.0.norm() == h.speed_m_s),
                "{h:?} is no grain's speed at the step's start"
            );
            assert!(
                h.normal_speed_m_s > 0.0 && h.normal_speed_m_s <= h.speed_m_s,
                "{h:?}"
            );
        }
        starts.extend(c.starts);
        steps_in_contact += c.steps_in_contact;
    }
    let first = starts.iter().filter(|h| h.first).count();
    assert_eq!(first, 2, "one first touch per grain: {starts:?}");
    assert!(
        steps_in_contact > 2,
        "the grains stayed in contact for {steps_in_contact} grain-steps"
    );
    assert!(w.abrasives().unwrap().dem.grains.iter().all(|g| g.touched));
    // An untouched grain keeps the bytes it had before the flags existed.
    let fresh = serde_json::to_string(&Grain::sphere(Vector::zeros(), 1e-4, 4120.0)).unwrap();
    assert!(
        !fresh.contains("touched") && !fresh.contains("in_contact"),
        "{fresh}"
    );
}

#[test]
fn water_grains_and_target_give_the_same_bits_on_one_and_two_threads() {
    let one = stepped_on(1, 300, || water_on_copper(100.0, true));
    let two = stepped_on(2, 300, || water_on_copper(100.0, true));
    assert_eq!(flow_bits(&one), flow_bits(&two));
    let grain_bits = |w: &World| -> Vec<u64> {
        w.abrasives()
            .unwrap()
            .dem
            .grains
            .iter()
            .flat_map(|g| [g.pos.x, g.pos.y, g.vel.x, g.vel.y, g.omega])
            .map(f64::to_bits)
            .collect()
    };
    assert_eq!(grain_bits(&one), grain_bits(&two));
}

#[test]
fn abrasive_inputs_are_checked() {
    let mut w = water_on_copper(10.0, false);
    let g = Grain::sphere(Vector::zeros(), 1e-4, 4120.0);
    assert_eq!(w.add_grain(g).unwrap_err().field, "grain");
    let dem = no_grains();
    let bad_body = Abrasives::new(
        dem.clone(),
        CouplingParams::default(),
        PenaltyParams::default(),
        Some(0),
    );
    assert_eq!(
        w.set_abrasives(bad_body).unwrap_err().field,
        "abrasives.fluid_body"
    );
    let bad_chi = Abrasives::new(
        dem,
        CouplingParams::default(),
        PenaltyParams {
            chi: 1.0,
            ..PenaltyParams::default()
        },
        Some(1),
    );
    assert_eq!(
        w.set_abrasives(bad_chi).unwrap_err().field,
        "abrasives.penalty.chi"
    );
    assert_eq!(
        w.set_grain_outflow(Vector::zeros(), Vector::new(1.0, 1.0))
            .unwrap_err()
            .field,
        "grain_outflow"
    );
}
