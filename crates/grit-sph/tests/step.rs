//! The step: each stage books its own time, and the stages that stand alone run alone.

use grit_sph::coupling::CouplingParams;
use grit_sph::dem::{Dem, DemParams, Grain};
use grit_sph::verification::elastic_impact;
use grit_sph::{
    Abrasives, Fluid, Material, Nozzle, PenaltyParams, Settings, Stage, Timers, Vector, World,
};

const DX: f64 = 1e-4;

fn lattice(nx: usize, ny: usize, origin: Vector) -> Vec<Vector> {
    let mut pts = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            pts.push(origin + Vector::new((i as f64 + 0.5) * DX, (j as f64 + 0.5) * DX));
        }
    }
    pts
}

/// Every part a state holds: a copper target (Mie–Grüneisen, so its particles carry an energy),
/// water falling onto it from a nozzle, an outflow, and two garnet grains coupled to the water.
fn jet_on_copper() -> World {
    let mut w = World::new(Settings::water_jet(DX, Vector::new(0.0, -9.81))).unwrap();
    let target = lattice(20, 8, Vector::new(0.0, -8.0 * DX));
    let vols = vec![DX * DX; target.len()];
    w.add_deformable(
        "target",
        Material::copper(),
        &target,
        &vols,
        Vector::zeros(),
    )
    .unwrap();
    let water = lattice(12, 4, Vector::new(4.0 * DX, 0.0));
    let (vols, pres) = (vec![DX * DX; water.len()], vec![0.0; water.len()]);
    let b = w
        .add_fluid(
            "water",
            Fluid::water(),
            &water,
            &vols,
            &pres,
            Vector::new(0.0, -100.0),
        )
        .unwrap();
    w.add_inflow(
        b,
        Nozzle {
            centre_m: Vector::new(10.0 * DX, 6.0 * DX),
            direction: Vector::new(0.0, -1.0),
            width_m: 4.0 * DX,
            speed_m_s: 100.0,
        },
    )
    .unwrap();
    w.add_outflow(
        b,
        Vector::new(-DX, -9.0 * DX),
        Vector::new(21.0 * DX, 8.0 * DX),
    )
    .unwrap();
    let dem = Dem::new(
        Vec::new(),
        Vec::new(),
        DemParams::default(),
        Vector::zeros(),
    )
    .unwrap();
    let ab = Abrasives::new(
        dem,
        CouplingParams::default(),
        PenaltyParams::default(),
        Some(b),
    );
    w.set_abrasives(ab).unwrap();
    for x in [6.0, 12.0] {
        let mut g = Grain::sphere(Vector::new(x * DX, 2.0 * DX), 1e-4, 4120.0);
        g.vel = Vector::new(0.0, -150.0);
        w.add_grain(g).unwrap();
    }
    w
}

/// A rigid disc on an elastic block, in contact.
fn disc_on_block() -> World {
    elastic_impact::scene(12, Settings::default())
}

fn stepped(mut w: World, steps: usize) -> World {
    for _ in 0..steps {
        w.step().unwrap();
    }
    w
}

/// The stages whose counters `timers` left at zero.
fn idle(timers: &Timers) -> Vec<Stage> {
    Stage::ALL
        .into_iter()
        .filter(|&s| timers.seconds(s) == 0.0)
        .collect()
}

#[test]
fn each_stage_books_its_own_time() {
    // Water, grains and open boundaries: every stage runs. The neighbour lists of a few hundred
    // slow particles may last all 20 steps, so that one counter may stay at zero.
    let jet = stepped(jet_on_copper(), 20);
    let left: Vec<Stage> = idle(jet.timers())
        .into_iter()
        .filter(|&s| s != Stage::Neighbours)
        .collect();
    assert!(left.is_empty(), "{left:?} booked no time");
    // A solid scene has no fluid, grain or flow stage to time.
    let disc = stepped(disc_on_block(), 20);
    let mut left = idle(disc.timers());
    left.retain(|&s| s != Stage::Neighbours);
    assert_eq!(
        left,
        [
            Stage::GrainPorosity,
            Stage::FluidDensity,
            Stage::FluidForces,
            Stage::GrainCoupling,
            Stage::GrainContact,
            Stage::GrainDem,
            Stage::Flow,
        ]
    );
}

#[test]
fn run_stage_runs_the_stages_that_stand_alone() {
    let mut w = stepped(jet_on_copper(), 5);
    let before = w.time();
    for stage in Stage::ALL {
        let alone = Stage::ALL
            .iter()
            .position(|&s| s == stage)
            .is_some_and(|k| k <= 7);
        assert_eq!(w.run_stage(stage).is_ok(), alone, "{stage:?}");
    }
    assert_eq!(w.time(), before, "run_stage advanced the clock");
    w.step().unwrap();
}
