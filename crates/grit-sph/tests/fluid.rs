//! The fluid body kind in the world (docs/jet.md#water-in-the-engine): momentum of the pair
//! forces, determinism across thread counts, the time step, and input errors.

mod common;

use grit_sph::verification::hydrostatic::{hydrostatic_water, tank};
use grit_sph::{Fluid, KernelKind, Motion, Settings, Vector, World};

/// A free block of water, no walls and no gravity, with a converging and shearing velocity
/// field (so every pair term works: pressure, Shao–Lo and the artificial viscosity).
fn free_block(n: usize) -> World {
    let dx = 1e-4;
    let settings = Settings {
        spacing_m: dx,
        h_over_dx: 1.25,
        kernel: KernelKind::CubicSpline,
        cfl: 0.2,
        ..Settings::default()
    };
    let mut w = World::new(settings).unwrap();
    let mut pts = Vec::new();
    for j in 0..n {
        for i in 0..n {
            pts.push(Vector::new(i as f64 * dx, j as f64 * dx));
        }
    }
    let vols = vec![dx * dx; pts.len()];
    let pres = vec![0.0; pts.len()];
    w.add_fluid("water", Fluid::water(), &pts, &vols, &pres, Vector::zeros())
        .unwrap();
    let c = Vector::new(0.5, 0.5) * ((n - 1) as f64 * dx);
    let size = n as f64 * dx;
    w.set_fluid_velocity(0, |x| {
        let r = (x - c) / size;
        Vector::new(-2.0 * r.x + 3.0 * r.y, -2.0 * r.y)
    })
    .unwrap();
    w
}

#[test]
fn the_pair_forces_conserve_momentum() {
    let mut w = free_block(16);
    let p0 = w.momentum();
    let scale: f64 = {
        let p = w.particles();
        (0..p.len()).map(|i| p.mass[i] * p.vel[i].norm()).sum()
    };
    assert!(scale > 0.0);
    let e0 = w.energy().kinetic;
    for _ in 0..200 {
        w.step().unwrap();
    }
    let dp = (w.momentum() - p0).norm() / scale;
    assert!(dp < 1e-12, "momentum drift {dp:e} of sum m|v|");
    // The converging flow is braked by the pressure it builds and by the viscosities.
    assert!(w.energy().kinetic < e0);
}

fn dam_break(threads: usize) -> World {
    common::stepped_on(threads, 400, || tank(12, 24).unwrap())
}

#[test]
fn a_dam_break_gives_identical_bits_on_one_and_two_threads() {
    let (a, b) = (dam_break(1), dam_break(2));
    assert_eq!(common::flow_bits(&a), common::flow_bits(&b));
    // The front has run out along the floor: the flow really moved.
    let front = a
        .particles()
        .pos
        .iter()
        .zip(&a.particles().flags)
        .filter(|(_, &f)| f & grit_sph::particles::KINEMATIC == 0)
        .map(|(x, _)| x.x)
        .fold(f64::MIN, f64::max);
    assert!(front > 10e-3 + 1e-3, "front at {front:e} m");
}

#[test]
fn the_time_step_is_the_fluid_s_cfl_limit() {
    let mut w = tank(12, 12).unwrap();
    w.step().unwrap();
    let water = hydrostatic_water();
    let h = w.h();
    let p = w.particles();
    let smax = (0..p.len())
        .map(|i| water.sound_speed(p.rho[i], 1.0) + p.vel[i].norm())
        .fold(0.0, f64::max);
    let dt = 0.2 * h / smax;
    assert!((w.dt() - dt).abs() <= 1e-12 * dt, "{} vs {dt}", w.dt());
    // The speed of sound is the reduced one of the check, c0 = 10 sqrt(g H).
    assert!(smax > water.eos.c0_m_s && smax < 1.05 * water.eos.c0_m_s);
}

#[test]
fn bad_fluid_input_names_its_field() {
    let mut w = World::new(Settings::default()).unwrap();
    let pts = [Vector::zeros(), Vector::new(1e-5, 0.0)];
    let water = Fluid::water;
    let cases: [(&[f64], &[f64], &str); 5] = [
        (&[1e-10], &[0.0; 2], "w.volume_m2"),
        (&[1e-10; 2], &[0.0], "w.pressure_pa"),
        (&[1e-10, -1.0], &[0.0; 2], "w.volume_m2[1]"),
        (&[1e-10; 2], &[0.0, -2e5], "w.pressure_pa[1]"),
        (&[1e-10; 2], &[f64::NAN, 0.0], "w.pressure_pa[0]"),
    ];
    for (volumes, pressures, field) in cases {
        let r = w.add_fluid("w", water(), &pts, volumes, pressures, Vector::zeros());
        assert_eq!(r.unwrap_err().field, field);
    }
    let mut bad = water();
    bad.dynamic_viscosity_pa_s = -1.0;
    let r = w.add_fluid("w", bad, &pts, &[1e-10; 2], &[0.0; 2], Vector::zeros());
    assert_eq!(r.unwrap_err().field, "w.fluid.dynamic_viscosity_pa_s");
    assert!(w.bodies().is_empty());
    // A fluid may start empty, for an inflow to fill.
    let mut fed = World::new(w.settings().clone()).unwrap();
    let empty = fed.add_fluid("w", water(), &[], &[], &[], Vector::zeros());
    assert_eq!(empty.unwrap(), 0);
    // A fluid body takes kinematic walls.
    let b = w
        .add_fluid("w", water(), &pts, &[1e-10; 2], &[0.0; 2], Vector::zeros())
        .unwrap();
    assert_eq!(w.set_kinematic(b, Motion::Fixed, |x| x.x > 0.0).unwrap(), 1);
    assert_eq!(
        w.set_fluid_velocity(b, |_| Vector::new(f64::INFINITY, 0.0))
            .unwrap_err()
            .field,
        "w.velocity_m_s"
    );
    // Walls keep their prescribed motion: only the free particle takes the field.
    assert_eq!(
        w.set_fluid_velocity(b, |_| Vector::new(1.0, 0.0)).unwrap(),
        1
    );
    assert_eq!(w.particles().vel[1], Vector::zeros());
}
