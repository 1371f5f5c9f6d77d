//! The step and what a checkpoint keeps of it. Each stage books its own time. A world resumed
//! from its state (`WorldState`, `ParticlesState`) steps on bit for bit; the JSON `World` wrote
//! before the state types existed reads as version 1; a layout this build does not know, or
//! arrays that do not fit together, are refused by name.

mod common;

use common::copper_under_water;
use grit_sph::coupling::CouplingParams;
use grit_sph::dem::{Dem, DemParams, Grain};
use grit_sph::particles::{ParticlesState, PARTICLES_STATE_VERSION};
use grit_sph::verification::elastic_impact;
use grit_sph::world::WORLD_STATE_VERSION;
use grit_sph::{
    Abrasives, InputError, Nozzle, Particles, PenaltyParams, Settings, Stage, Timers, Vector,
    World, WorldState,
};
use serde_json::Value;

const DX: f64 = 1e-4;

/// Every part a state holds: a copper target (Mie–Grüneisen, so its particles carry an energy),
/// water falling onto it from a nozzle, an outflow, and two garnet grains coupled to the water.
fn jet_on_copper() -> World {
    let mut w = World::new(Settings::water_jet(DX, Vector::new(0.0, -9.81))).unwrap();
    let b = copper_under_water(&mut w, DX, 4, Vector::new(0.0, -100.0));
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

/// A rigid disc on an elastic block, in contact: the contact springs are in the state.
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

/// The world's JSON: every bit of its state, floats written to round-trip.
fn json(w: &World) -> String {
    serde_json::to_string(w).unwrap()
}

/// The world's JSON without the positions at its last neighbour build: a resumed world builds
/// its lists at its first step, a world that ran on at its own time, and the lists are the
/// same either way.
fn json_without_build(w: &World) -> String {
    let mut v = serde_json::to_value(w).unwrap();
    v.as_object_mut().unwrap().remove("x_build");
    v.to_string()
}

/// Asserts two worlds' states are the same bit for bit, naming where they first differ.
fn assert_same(a: &World, b: &World) {
    let (a, b) = (json_without_build(a), json_without_build(b));
    if let Some(k) = a.bytes().zip(b.bytes()).position(|(x, y)| x != y) {
        let at = |s: &str| s[k.saturating_sub(80)..(k + 80).min(s.len())].to_string();
        panic!("states differ at byte {k}:\n{}\n{}", at(&a), at(&b));
    }
    assert_eq!(a.len(), b.len(), "one state is longer");
}

fn resumed(state: &WorldState) -> World {
    let text = serde_json::to_string(state).unwrap();
    World::from_state(serde_json::from_str(&text).unwrap()).unwrap()
}

#[test]
fn a_world_resumed_from_its_state_steps_on_bit_for_bit() {
    for (scene, before) in [(jet_on_copper as fn() -> World, 150), (disc_on_block, 400)] {
        let mut a = stepped(scene(), before);
        let mut b = resumed(&a.state());
        assert_same(&a, &b);
        for _ in 0..150 {
            a.step().unwrap();
            b.step().unwrap();
        }
        assert_same(&a, &b);
        assert_eq!(a.dt().to_bits(), b.dt().to_bits());
    }
    // The scenes hold what they are meant to: energies, open boundaries, grains, springs.
    let jet = stepped(jet_on_copper(), 150);
    assert!(jet.particles().energy.iter().any(|&e| e != 0.0));
    assert!(!jet.inflows().is_empty() && !jet.outflows().is_empty());
    assert_eq!(jet.abrasives().map(|a| a.dem.grains.len()), Some(2));
    let disc = stepped(disc_on_block(), 400);
    assert!(disc.contacts()[0].penetration.iter().any(|&p| p > 0.0));
}

#[test]
fn the_json_of_a_world_reads_as_its_state_and_back() {
    for w in [stepped(jet_on_copper(), 100), stepped(disc_on_block(), 300)] {
        // Bytes `World` wrote before the state types existed: they read as version 1.
        let old = json(&w);
        let state: WorldState = serde_json::from_str(&old).unwrap();
        assert_eq!(state.version(), 1);
        assert_eq!(state.time().to_bits(), w.time().to_bits());
        let mut back = World::from_state(state).unwrap();
        assert!(json(&back) == old, "the state changed the world");
        // A state is the world's JSON with the two versions added, so a build that reads
        // `World` reads it too.
        let mut state = serde_json::to_value(w.state()).unwrap();
        assert_eq!(state["version"], WORLD_STATE_VERSION);
        assert_eq!(state["particles"]["version"], PARTICLES_STATE_VERSION);
        state.as_object_mut().unwrap().remove("version");
        state["particles"]
            .as_object_mut()
            .unwrap()
            .remove("version");
        assert_eq!(state, serde_json::to_value(&w).unwrap());
        let mut w = w;
        back.step().unwrap();
        w.step().unwrap();
        assert_same(&back, &w);
    }
}

/// `state` as JSON, changed by `edit`, read back.
fn edited(state: &WorldState, edit: impl FnOnce(&mut Value)) -> Result<World, InputError> {
    let mut v = serde_json::to_value(state).unwrap();
    edit(&mut v);
    World::from_state(serde_json::from_value(v).unwrap())
}

#[test]
fn unknown_layouts_and_misfits_are_refused_by_name() {
    let state = stepped(disc_on_block(), 300).state();
    let err = edited(&state, |v| v["version"] = 2.into()).unwrap_err();
    assert_eq!(err.field, "world.version");
    assert!(err.rule.contains('2') && err.rule.contains('1'), "{err}");
    let err = edited(&state, |v| v["particles"]["version"] = 9.into()).unwrap_err();
    assert_eq!(err.field, "world.particles.version");
    let err = edited(&state, |v| {
        v["particles"]["rho"].as_array_mut().unwrap().pop();
    })
    .unwrap_err();
    assert_eq!(err.field, "world.particles");
    let err = edited(&state, |v| {
        v["contacts"][0]["spring"].as_array_mut().unwrap().pop();
    })
    .unwrap_err();
    assert_eq!(err.field, "world.contacts[0]");
    let err = edited(&state, |v| v["contacts"][0]["primary"] = 5.into()).unwrap_err();
    assert_eq!(err.field, "world.contacts[0]");
    let err = edited(&state, |v| v["particles"]["body"][3] = 2.into()).unwrap_err();
    assert_eq!(err.field, "world.particles.body[3]");
}

#[test]
fn particles_come_back_bit_for_bit_and_zero_energies_stay_empty() {
    let jet = stepped(jet_on_copper(), 100);
    let disc = stepped(disc_on_block(), 300);
    for p in [jet.particles(), disc.particles()] {
        let state = p.state();
        assert_eq!(state.version(), PARTICLES_STATE_VERSION);
        assert_eq!(state.len(), p.len());
        let text = serde_json::to_string(&state).unwrap();
        let back = Particles::from_state(serde_json::from_str(&text).unwrap()).unwrap();
        assert_eq!(
            serde_json::to_string(&back).unwrap(),
            serde_json::to_string(p).unwrap()
        );
        assert_eq!(back.energy.len(), p.len());
    }
    // The elastic block has no energy equation: its state writes none, as `Particles` did.
    let v = serde_json::to_value(disc.particles().state()).unwrap();
    assert_eq!(v["energy"], Value::Array(Vec::new()));
    // Particles written before energies existed (no key at all) read with zero energies.
    let mut old = serde_json::to_value(disc.particles()).unwrap();
    old.as_object_mut().unwrap().remove("energy");
    let state: ParticlesState = serde_json::from_value(old).unwrap();
    assert_eq!(state.version(), 1);
    let back = Particles::from_state(state).unwrap();
    assert!(back.energy.iter().all(|&e| e == 0.0) && back.energy.len() == back.len());
}

/// The field names of `v`'s JSON object, in the order they were written.
fn keys_in_order(text: &str) -> Vec<String> {
    let v: serde_json::Map<String, Value> = serde_json::from_str(text).unwrap();
    let mut keys: Vec<(usize, String)> = v
        .keys()
        .map(|k| (text.find(&format!("\"{k}\":")).unwrap(), k.clone()))
        .collect();
    keys.sort();
    keys.into_iter().map(|(_, k)| k).collect()
}

/// The layouts are pinned: postcard reads a `ParticlesState` by position, and every checkpoint
/// reads its fields by these names. A change here is a new version (`PARTICLES_STATE_VERSION`,
/// `WORLD_STATE_VERSION`), with a way to read the old one.
#[test]
fn the_state_layouts_are_the_versioned_ones() {
    let disc = stepped(disc_on_block(), 10);
    let particles = serde_json::to_string(&disc.particles().state()).unwrap();
    assert_eq!(
        keys_in_order(&particles),
        [
            "version",
            "id",
            "body",
            "flags",
            "pos",
            "vel",
            "mass",
            "rho",
            "rho0",
            "sdev",
            "eps_p",
            "eps_p_rate",
            "temp",
            "energy",
            "damage",
            "def_grad",
            "x_ref",
            "local"
        ]
    );
    assert_eq!(PARTICLES_STATE_VERSION, 1);
    let world = serde_json::to_string(&jet_on_copper().state()).unwrap();
    let v: serde_json::Map<String, Value> = serde_json::from_str(&world).unwrap();
    let mut keys: Vec<&str> = v.keys().map(String::as_str).collect();
    keys.sort_unstable();
    assert_eq!(
        keys,
        [
            "abrasives",
            "bodies",
            "contacts",
            "dt",
            "flow",
            "kernel",
            "next_id",
            "particles",
            "settings",
            "steps",
            "time",
            "version",
            "work",
            "x_build"
        ]
    );
    assert_eq!(WORLD_STATE_VERSION, 1);
}
