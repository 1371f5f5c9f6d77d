//! A JH-2 rock under the jet (docs/jet.md#rock-targets): `--material sandstone` runs, loses
//! mass, and a run resumed from its checkpoint (which keeps the bulking pressures beside the
//! particles) gives the bits of an unbroken one on one or two threads.

use grit_erosion::campaign::MaterialSpec;
use grit_erosion::jet::{JetParams, JetRun};

/// The small jet of `tests/jet.rs` on red sandstone at 400 m/s: 4 µs in slices of 1 µs.
fn tiny_rock() -> JetParams {
    JetParams {
        material: MaterialSpec(grit_sph::Material::by_name("sandstone").unwrap()),
        velocity_m_s: 400.0,
        spacing_m: 1e-4,
        jet_width_m: 6e-4,
        target_width_m: 3e-3,
        target_depth_m: 8e-4,
        standoff_m: 6e-4,
        grain_diameter_m: 2e-4,
        mass_flow_kg_s: 0.04,
        time_ms: 0.004,
        slice_ms: 0.001,
        ..JetParams::default()
    }
}

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn sandstone_loses_mass_and_resumes_bit_for_bit() {
    let whole = on_threads(2, || {
        let mut run = JetRun::new(tiny_rock(), 3).unwrap();
        while !run.finished() {
            run.run_next_slice().unwrap();
        }
        run
    });
    let last = &whole.slices()[whole.slices().len() - 1];
    assert!(
        last.sample.mass_loss_kg_m > 0.0,
        "the rock lost no mass: {:?}",
        last.sample
    );
    let p = whole.world().particles();
    assert!(p.bulking.iter().any(|&b| b > 0.0), "no particle bulked");
    let resumed = on_threads(1, || {
        let mut run = JetRun::new(tiny_rock(), 3).unwrap();
        run.run_next_slice().unwrap();
        run.run_next_slice().unwrap();
        let mut back = JetRun::resume(&tiny_rock(), 3, &run.checkpoint()).unwrap();
        while !back.finished() {
            back.run_next_slice().unwrap();
        }
        back
    });
    let state = |run: &JetRun| {
        let mut slices = run.slices().to_vec();
        slices.iter_mut().for_each(|s| s.wall_s = 0.0);
        let bulking: Vec<u64> = run
            .world()
            .particles()
            .bulking
            .iter()
            .map(|b| b.to_bits())
            .collect();
        serde_json::to_string(&(run.world(), slices, bulking)).unwrap()
    };
    assert!(state(&whole) == state(&resumed), "the resumed run differs");
}

#[test]
fn the_impact_scene_refuses_rock() {
    let p = grit_erosion::impact::ImpactParams {
        material: grit_sph::Material::granite(),
        ..Default::default()
    };
    let err = p.validate().unwrap_err();
    assert_eq!(err.field, "material");
    assert!(err.rule.contains("jet"), "{}", err.rule);
}
