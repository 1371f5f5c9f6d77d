//! Inflow and outflow of a fluid body (docs/jet.md#inflow-and-outflow): rows released at the
//! expected times and places, deletion and its booking, mass balance, determinism, input errors.

mod common;

use grit_sph::particles::KINEMATIC;
use grit_sph::verification::jet_wall::jet_wall_world;
use grit_sph::{Fluid, Motion, Nozzle, Settings, Vector, World};

const DX: f64 = 1e-4;
const SPEED: f64 = 50.0;
const PER_ROW: usize = 4;

/// A fluid body of one fixed anchor particle behind a nozzle at the origin that shoots
/// `PER_ROW` particles per row along +x; no gravity.
fn nozzle_world() -> World {
    let settings = Settings::water_jet(DX, Vector::zeros());
    let mut w = World::new(settings).unwrap();
    let anchor = [Vector::new(-20.0 * DX, 0.0)];
    let b = w
        .add_fluid(
            "water",
            Fluid::water(),
            &anchor,
            &[DX * DX],
            &[0.0],
            Vector::zeros(),
        )
        .unwrap();
    w.set_kinematic(b, Motion::Fixed, |_| true).unwrap();
    w.add_inflow(
        b,
        Nozzle {
            centre_m: Vector::zeros(),
            direction: Vector::new(2.0, 0.0),
            width_m: PER_ROW as f64 * DX,
            speed_m_s: SPEED,
        },
    )
    .unwrap();
    w
}

fn free_mass(w: &World) -> f64 {
    let p = w.particles();
    (0..p.len())
        .filter(|&i| p.flags[i] & KINEMATIC == 0)
        .map(|i| p.mass[i])
        .sum()
}

#[test]
fn rows_leave_the_nozzle_one_spacing_apart() {
    let mut w = nozzle_world();
    let rho0 = Fluid::water().density();
    assert_eq!(w.inflows()[0].rows, 1);
    assert_eq!(w.inflows()[0].per_row, PER_ROW);
    assert_eq!(w.particles().len(), 1 + PER_ROW);
    let mut seen_times = 0;
    // About 120 steps per row at this speed and spacing.
    for _ in 0..1500 {
        w.step().unwrap();
        let rows = w.inflows()[0].rows as usize;
        // A row for the start and one for each spacing the jet has moved since.
        let moved = w.time() * SPEED / DX;
        if (moved - moved.round()).abs() > 1e-6 {
            assert_eq!(rows, 1 + moved.floor() as usize, "t = {:e}", w.time());
            seen_times += 1;
        }
        let p = w.particles();
        assert_eq!(p.len(), 1 + rows * PER_ROW);
        // Ids in release order, rows in order across the nozzle, on the lattice.
        assert!(p.id.windows(2).all(|x| x[0] < x[1]));
        for r in 0..rows {
            let first = 1 + r * PER_ROW;
            let s = p.pos[first].x;
            let s_expected = (moved - r as f64) * DX;
            assert!(
                (s - s_expected).abs() < 1e-6 * DX,
                "row {r}: {s:e} vs {s_expected:e}"
            );
            for k in 0..PER_ROW {
                let x = p.pos[first + k];
                assert_eq!(x.x.to_bits(), s.to_bits());
                let across = (k as f64 + 0.5 - 0.5 * PER_ROW as f64) * DX;
                assert!((x.y - across).abs() < 1e-12 * DX);
                assert_eq!(p.vel[first + k], Vector::new(SPEED, 0.0));
                assert_eq!(p.mass[first + k], rho0 * DX * DX);
            }
        }
        // The newest row is within one spacing of the exit.
        let newest = p.pos[p.len() - 1].x;
        assert!((0.0..DX).contains(&newest), "newest row at {newest:e}");
        let mass = w.inflows()[0].mass_kg_m;
        assert!((mass - free_mass(&w)).abs() <= 1e-12 * mass);
    }
    assert!(w.inflows()[0].rows > 10 && seen_times > 1400);
}

#[test]
fn outflow_deletes_books_and_balances_the_mass() {
    let mut w = nozzle_world();
    let end = 6.5 * DX;
    w.add_outflow(0, Vector::new(-1.0, -1.0), Vector::new(end, 1.0))
        .unwrap();
    let held0 = free_mass(&w) - w.inflows()[0].mass_kg_m;
    for _ in 0..3000 {
        w.step().unwrap();
        let p = w.particles();
        for i in 0..p.len() {
            assert!(
                p.pos[i].x <= end,
                "particle {} at {:e}",
                p.id[i],
                p.pos[i].x
            );
        }
        let (inflow, outflow) = (&w.inflows()[0], &w.outflows()[0]);
        let held = free_mass(&w) - held0;
        let balance = inflow.mass_kg_m - outflow.mass_kg_m - held;
        assert!(balance.abs() <= 1e-12 * inflow.mass_kg_m, "{balance:e}");
        let free = p.len() as u64 - 1;
        assert_eq!(inflow.rows * PER_ROW as u64, free + outflow.particles);
        let booked = outflow.particles as f64 * Fluid::water().density() * DX * DX;
        assert!((outflow.mass_kg_m - booked).abs() <= 1e-12 * booked);
    }
    // Rows have left, and at most the rows inside the box remain.
    assert!(w.outflows()[0].particles >= 3 * PER_ROW as u64);
    assert!(w.particles().len() <= 1 + 7 * PER_ROW);
    // The anchor, a wall particle outside the box, stays.
    assert_eq!(w.particles().flags[0] & KINEMATIC, KINEMATIC);
}

fn jet_on_wall(threads: usize) -> World {
    common::stepped_on(threads, 600, || {
        jet_wall_world(4, 400.0, Fluid::water()).unwrap()
    })
}

#[test]
fn a_jet_on_a_wall_gives_identical_bits_on_one_and_two_threads() {
    let (a, b) = (jet_on_wall(1), jet_on_wall(2));
    let bits = |w: &World| -> Vec<u64> {
        let p = w.particles();
        common::flow_bits(w)
            .into_iter()
            .chain(p.id.iter().map(|&i| i as u64))
            .chain([w.wall_force(0).y.to_bits()])
            .collect()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.inflows(), b.inflows());
    assert_eq!(a.outflows(), b.outflows());
    // The jet reached the wall and its sheets left the box.
    assert!(a.wall_force(0).y < 0.0);
    assert!(a.outflows()[0].particles > 0);
}

#[test]
fn bad_inflow_and_outflow_input_names_its_field() {
    let mut w = nozzle_world();
    let good = w.inflows()[0].nozzle;
    let err = |r: Result<usize, grit_sph::InputError>| r.unwrap_err().field;
    let with = |f: &dyn Fn(&mut Nozzle)| {
        let mut n = good;
        f(&mut n);
        n
    };
    assert_eq!(
        err(w.add_inflow(0, with(&|n| n.width_m = 2.5 * DX))),
        "nozzle.width_m"
    );
    assert_eq!(
        err(w.add_inflow(0, with(&|n| n.direction = Vector::zeros()))),
        "nozzle.direction"
    );
    assert_eq!(
        err(w.add_inflow(0, with(&|n| n.speed_m_s = 0.0))),
        "nozzle.speed_m_s"
    );
    assert_eq!(
        err(w.add_inflow(0, with(&|n| n.centre_m.x = f64::NAN))),
        "nozzle.centre_m"
    );
    assert_eq!(err(w.add_inflow(3, good)), "nozzle.body");
    assert_eq!(
        err(w.add_outflow(0, Vector::new(1.0, 0.0), Vector::new(0.0, 1.0))),
        "outflow.max_m"
    );
    assert_eq!(
        err(w.add_outflow(0, Vector::new(f64::NAN, 0.0), Vector::new(1.0, 1.0))),
        "outflow.min_m"
    );
    assert_eq!(
        err(w.add_outflow(7, Vector::zeros(), Vector::new(1.0, 1.0))),
        "outflow.body"
    );
    // Nothing was added by the failed calls.
    assert_eq!(w.inflows().len(), 1);
    assert!(w.outflows().is_empty());
}

#[test]
fn a_jet_resumed_from_json_continues_bit_for_bit() {
    let mut a = jet_wall_world(4, 400.0, Fluid::water()).unwrap();
    for _ in 0..300 {
        a.step().unwrap();
    }
    let json = serde_json::to_string(&a).unwrap();
    assert!(json.contains("\"inflows\""));
    let mut b: World = serde_json::from_str(&json).unwrap();
    for _ in 0..300 {
        a.step().unwrap();
        b.step().unwrap();
    }
    let p = (a.particles(), b.particles());
    assert_eq!(p.0.pos, p.1.pos);
    assert_eq!(p.0.rho, p.1.rho);
    assert_eq!(p.0.id, p.1.id);
    assert_eq!(a.inflows(), b.inflows());
    assert_eq!(a.outflows(), b.outflows());
    // A world without open boundaries writes no key for them.
    let plain = World::new(Settings::default()).unwrap();
    assert!(!serde_json::to_string(&plain).unwrap().contains("inflows"));
}
