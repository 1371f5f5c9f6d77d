//! The jet scene's run (docs/jet.md#the-scene): a resumed run gives the bits of an unbroken
//! one, one and two threads agree, the feed delivers the mass flow, and bad parameters are
//! named; on a JH-2 rock target too (docs/jet.md#rock-targets).

use grit_erosion::campaign::MaterialSpec;
use grit_erosion::jet::{grain_spacing_m, JetParams, JetRun};
use sha2::Digest;

/// The small jet (`JetParams::small`): 4 µs in slices of 1 µs on copper.
fn tiny() -> JetParams {
    JetParams::small()
}

/// The small jet on red sandstone at 400 m/s and 0.04 kg/s, for 8 µs: the rock first loses
/// mass after 6–7 µs (seed 3).
fn tiny_rock() -> JetParams {
    JetParams {
        material: MaterialSpec(grit_sph::Material::by_name("sandstone").unwrap()),
        velocity_m_s: 400.0,
        mass_flow_kg_s: 0.04,
        time_ms: 0.008,
        ..JetParams::small()
    }
}

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Checkpoint bytes around `json`: the JSON, a newline and the JSON's SHA-256 in hex.
fn sealed(json: &[u8]) -> Vec<u8> {
    let mut b = json.to_vec();
    b.push(b'\n');
    b.extend_from_slice(format!("{:x}", sha2::Sha256::digest(json)).as_bytes());
    b
}

/// Run `p` seeded `seed` whole on two threads, and again on one thread resumed from its
/// checkpoint after two slices.
fn whole_and_resumed(p: &JetParams, seed: u64) -> (JetRun, JetRun) {
    let whole = on_threads(2, || {
        let mut run = JetRun::new(p.clone(), seed).unwrap();
        while !run.finished() {
            run.run_next_slice().unwrap();
        }
        run
    });
    let resumed = on_threads(1, || {
        let mut run = JetRun::new(p.clone(), seed).unwrap();
        run.run_next_slice().unwrap();
        run.run_next_slice().unwrap();
        let mut back = JetRun::resume(p, seed, &run.checkpoint()).unwrap();
        while !back.finished() {
            back.run_next_slice().unwrap();
        }
        back
    });
    (whole, resumed)
}

#[test]
fn a_resumed_run_gives_the_bits_of_an_unbroken_one_on_any_thread_count() {
    let (whole, resumed) = whole_and_resumed(&tiny(), 5);
    assert_eq!(whole.slices().len(), 4);
    let last = &whole.slices()[3];
    assert!(last.grains_fed > 0, "no grain was fed");
    assert!(last.sample.max_plastic_strain > 0.0, "the jet left no mark");
    // Everything but the wall-clock seconds of each slice.
    let state = |run: &JetRun| {
        let mut slices = run.slices().to_vec();
        slices.iter_mut().for_each(|s| s.wall_s = 0.0);
        serde_json::to_string(&(run.world(), slices)).unwrap()
    };
    assert!(state(&whole) == state(&resumed), "the resumed run differs");
    // Another seed places other grains.
    let other = JetRun::resume(&tiny(), 6, &whole.checkpoint());
    assert!(other.is_err(), "a checkpoint resumed under another seed");
    // The bytes are the JSON, a newline and the JSON's SHA-256 in hex.
    let bytes = whole.checkpoint();
    let cut = bytes.iter().rposition(|&b| b == b'\n').unwrap();
    let json = &bytes[..cut];
    assert_eq!(sealed(json), bytes);
    let refused = |b: &[u8]| JetRun::from_checkpoint(b).err().unwrap().to_string();
    let mut flipped = bytes.clone();
    flipped[cut / 2] ^= 0x01;
    assert!(
        refused(&flipped).contains("damaged"),
        "{}",
        refused(&flipped)
    );
    let short = &bytes[..bytes.len() - 10];
    assert!(refused(short).contains("truncated"), "{}", refused(short));
    assert!(refused(&bytes[..cut / 2]).contains("cannot decode"));
    // A checkpoint written before the checksum (version 3, the JSON alone) still resumes.
    let mut v: serde_json::Value = serde_json::from_slice(json).unwrap();
    v["version"] = 3.into();
    let old = JetRun::resume(&tiny(), 5, &serde_json::to_vec(&v).unwrap()).unwrap();
    assert!(
        state(&old) == state(&whole),
        "a version-3 checkpoint reads as it was"
    );
    v["version"] = 4.into();
    let unsealed = refused(&serde_json::to_vec(&v).unwrap());
    assert!(unsealed.contains("version 4 but"), "{unsealed}");
    // Slices that are not the world's own: dropped, renumbered or one too few.
    let edited = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut v: serde_json::Value = serde_json::from_slice(json).unwrap();
        edit(&mut v);
        JetRun::from_checkpoint(&sealed(&serde_json::to_vec(&v).unwrap()))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let e = edited(&|v| v["slices"] = serde_json::json!([]));
    assert!(e.contains("holds 0 slices but its world is at"), "{e}");
    let e = edited(&|v| v["slices"][1]["slice"] = 7.into());
    assert!(e.contains("slices[1] is numbered 7, not 2"), "{e}");
    let e = edited(&|v| {
        v["slices"].as_array_mut().unwrap().pop();
    });
    assert!(e.contains("holds 3 slices"), "{e}");
}

#[test]
fn the_feed_spaces_grains_for_the_mass_flow() {
    // Eq. 55: M = ρ v V_a / y_dis.
    let p = tiny();
    let y = grain_spacing_m(&p);
    let v_a = std::f64::consts::PI * 2e-4f64.powi(3) / 6.0;
    assert!((p.grain_density_kg_m3 * p.velocity_m_s * v_a / y - p.mass_flow_kg_s).abs() < 1e-15);
    // After t the jet has run v t: about v t / y_dis grains are out (one per column).
    let mut run = JetRun::new(p.clone(), 9).unwrap();
    run.run_next_slice().unwrap();
    let fed = run.slices()[0].grains_fed as f64;
    let expected = p.velocity_m_s * 1e-6 / y;
    assert!(
        (fed - expected).abs() <= 1.0,
        "fed {fed}, expected {expected:.2}"
    );
    // Grains leaving slower than the water: the same grains at the same times, so the same M,
    // each at half the speed and half as far from the nozzle.
    let half = JetParams {
        grain_speed_ratio: 0.5,
        ..p.clone()
    };
    let mut slow = JetRun::new(half, 9).unwrap();
    slow.run_next_slice().unwrap();
    assert_eq!(slow.slices()[0].grains_fed as f64, fed);
    let speeds = |r: &JetRun| -> Vec<f64> {
        r.world()
            .abrasives()
            .map(|a| a.dem.grains.iter().map(|g| -g.vel.y).collect())
            .unwrap_or_default()
    };
    let (fast_v, slow_v) = (speeds(&run), speeds(&slow));
    assert!(!fast_v.is_empty() && !slow_v.is_empty());
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(
        mean(&slow_v) < 0.75 * mean(&fast_v),
        "{slow_v:?} against {fast_v:?}"
    );
}

#[test]
fn bad_parameters_are_named() {
    let field = |p: JetParams| JetRun::new(p, 1).unwrap_err().to_string();
    let mut p = tiny();
    p.jet_width_m = 6.5e-4;
    assert!(field(p).contains("jet_width_m"));
    let mut p = tiny();
    p.grain_diameter_m = 1e-3;
    assert!(field(p).contains("grain_diameter_m"));
    let mut p = tiny();
    p.mass_flow_kg_s = -1.0;
    assert!(field(p).contains("mass_flow_kg_s"));
    let mut p = tiny();
    p.standoff_m = 3e-4;
    assert!(field(p).contains("standoff_m"));
    let mut p = tiny();
    p.slice_ms = 1.0;
    assert!(field(p).contains("slice_ms"));
    let mut p = tiny();
    p.target_width_m = 7e-4;
    assert!(field(p).contains("target_width_m"));
    let mut p = tiny();
    p.grain_speed_ratio = 0.0;
    assert!(field(p).contains("grain_speed_ratio"));
    let mut p = tiny();
    p.drag_switch_porosity = 1.0;
    assert!(field(p).contains("drag_switch_porosity"));
    let err = serde_json::from_str::<JetParams>(r#"{"velocity": 400}"#).unwrap_err();
    assert!(err.to_string().contains("velocity"), "{err}");
    let named: JetParams = serde_json::from_str(r#"{"material": "al6061"}"#).unwrap();
    assert_eq!(named.material.0.name, "al6061");
}

#[test]
fn a_run_extends_to_its_own_end_or_later_but_not_into_its_slices() {
    let mut p = tiny();
    p.time_ms = 0.002;
    let mut run = JetRun::new(p, 5).unwrap();
    while !run.finished() {
        run.run_next_slice().unwrap();
    }
    // The clock stops on the step past 2 µs; asking for exactly 2 µs again is no error.
    assert!(run.slices()[1].sample.t_s >= 2e-6);
    run.extend(0.002).unwrap();
    assert!(run.finished());
    let e = run.extend(0.0015).unwrap_err().to_string();
    assert!(e.contains("time_ms") && e.contains("cannot end"), "{e}");
    run.extend(0.003).unwrap();
    assert!(!run.finished());
    run.run_next_slice().unwrap();
    assert!(run.finished());
    // A run whose last slice was short cannot be made longer.
    let mut p = tiny();
    p.time_ms = 0.0015;
    let mut short = JetRun::new(p, 5).unwrap();
    while !short.finished() {
        short.run_next_slice().unwrap();
    }
    let e = short.extend(0.003).unwrap_err().to_string();
    assert!(e.contains("ended short"), "{e}");
}

// A JH-2 rock under the jet (docs/jet.md#rock-targets): `--material sandstone` runs, keeps its
// fractured particles, loses mass (what no longer holds to the rock) and reports cracks, and a
// run resumed from its checkpoint (which keeps the bulking pressures beside the particles and
// the damage records beside the slices) gives the bits of an unbroken one on one or two threads.

#[test]
fn sandstone_keeps_fractured_rock_loses_mass_and_resumes_bit_for_bit() {
    let (whole, resumed) = whole_and_resumed(&tiny_rock(), 3);
    let n = whole.slices().len();
    let last = &whole.slices()[n - 1];
    let rock = whole.rock_damage();
    assert_eq!(rock.len(), n, "one damage record per slice");
    assert!(
        last.sample.mass_loss_kg_m > 0.0,
        "the rock lost no mass: {:?}",
        last.sample
    );
    // Nothing of the rock is deleted: what is fractured stays, held or detached.
    let p = whole.world().particles();
    let target = whole.layout().target_body as u32;
    let fractured = (0..p.len())
        .filter(|&i| p.body[i] == target && p.damage[i] >= 1.0)
        .count();
    assert!(fractured > 0, "nothing fractured");
    assert_eq!(fractured, rock[n - 1].fractured_particles);
    assert_eq!(whole.world().bodies()[target as usize].removed_particles, 0);
    assert!(rock[n - 1].crack_count > 0, "no crack: {:?}", rock[n - 1]);
    assert!(rock[n - 1].crack_length_m > 0.0);
    // The loss is the detached mass and what left the scene, never more than the target.
    assert!(last.sample.mass_loss_kg_m >= rock[n - 1].detached_kg_m);
    assert!(last.sample.mass_loss_kg_m < tiny_rock().target_mass_kg_m());
    assert!(p.bulking.iter().any(|&b| b > 0.0), "no particle bulked");
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
        let rock: Vec<String> = run.rock_damage().iter().map(|r| format!("{r:?}")).collect();
        serde_json::to_string(&(run.world(), slices, bulking, rock)).unwrap()
    };
    assert!(state(&whole) == state(&resumed), "the resumed run differs");
}

// Detachment is checked on a clock of its own, not at slice ends, so the loss of a rock run at
// a given time does not depend on how the run was cut into slices.
#[test]
fn a_rock_loses_the_same_mass_whatever_its_slice_length() {
    let run = |slice_ms: f64| {
        let mut run = JetRun::new(
            JetParams {
                slice_ms,
                ..tiny_rock()
            },
            3,
        )
        .unwrap();
        while !run.finished() {
            run.run_next_slice().unwrap();
        }
        run
    };
    let (coarse, fine) = (run(0.001), run(0.00025));
    assert_eq!(fine.slices().len(), 4 * coarse.slices().len());
    for (k, c) in coarse.slices().iter().enumerate() {
        let f = &fine.slices()[4 * k + 3];
        assert_eq!(c.sample, f.sample, "slice {}", k + 1);
        assert_eq!(c.rock, f.rock, "slice {}", k + 1);
    }
    let last = coarse.slices().last().unwrap();
    assert!(last.rock.unwrap().detached_kg_m > 0.0, "{last:?}");
}

// A rock checkpoint written before the slices carried their damage kept it in a list beside
// them: it reads into the slices, and a list of the wrong length is refused.
#[test]
fn an_older_rock_checkpoint_reads_its_damage_into_the_slices() {
    let p = tiny_rock();
    let mut run = JetRun::new(p.clone(), 3).unwrap();
    run.run_next_slice().unwrap();
    run.run_next_slice().unwrap();
    let bytes = run.checkpoint();
    let body = &bytes[..bytes.iter().rposition(|&b| b == b'\n').unwrap()];
    let mut v: serde_json::Value = serde_json::from_slice(body).unwrap();
    let rock: Vec<serde_json::Value> = v["slices"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .map(|s| s.as_object_mut().unwrap().remove("rock").unwrap())
        .collect();
    v["rock"] = serde_json::Value::Array(rock);
    let written = |v: &serde_json::Value| sealed(&serde_json::to_vec(v).unwrap());
    let back = JetRun::resume(&p, 3, &written(&v)).unwrap();
    assert_eq!(back.slices(), run.slices());
    v["rock"].as_array_mut().unwrap().pop();
    assert!(JetRun::resume(&p, 3, &written(&v)).is_err());
}

#[test]
fn a_metal_run_keeps_no_rock_records() {
    let mut run = JetRun::new(tiny(), 5).unwrap();
    run.run_next_slice().unwrap();
    assert!(run.rock_damage().is_empty());
    let json = String::from_utf8(run.checkpoint()).unwrap();
    assert!(!json.contains("\"rock\""), "a metal checkpoint names rock");
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
