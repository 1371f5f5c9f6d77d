//! A sample is fully determined by its parameters and seed, and resumes from a checkpoint bit
//! for bit: the same seed gives the same sample, and resuming from a checkpoint equals the
//! uninterrupted run. Coarse scenes: these run real impacts.

use grit_erosion::{ImpactParams, ImpactRecord, Sample, SampleError, Shape};
use grit_sph::Particles;

/// The coarsest scene the validation accepts, on a small surface: an impact takes a second.
fn coarse(angle_deg: f64) -> ImpactParams {
    ImpactParams {
        spacing_m: 25e-6,
        surface_width_dg: 3.0,
        surface_depth_dg: 1.25,
        ..ImpactParams::paper(angle_deg, Shape::Hexagon)
    }
}

fn bits(p: &Particles) -> Vec<u64> {
    let mut v = Vec::new();
    for i in 0..p.len() {
        v.extend([p.pos[i].x, p.pos[i].y, p.vel[i].x, p.vel[i].y, p.rho[i]].map(f64::to_bits));
        v.extend(p.sdev[i].iter().map(|x| x.to_bits()));
        v.extend([p.eps_p[i], p.damage[i], p.temp[i]].map(f64::to_bits));
    }
    v
}

fn record_bits(r: &[ImpactRecord]) -> Vec<(u32, u64, u64, u64)> {
    r.iter()
        .map(|r| {
            (
                r.impact,
                r.mass_loss_kg.to_bits(),
                r.outcome.rebound_ratio.to_bits(),
                r.outcome.steps,
            )
        })
        .collect()
}

#[test]
fn same_seed_same_sample_and_checkpoint_resumes_bit_for_bit() {
    let params = coarse(45.0);
    let mut a = Sample::new(params.clone(), 11).unwrap();
    for _ in 0..3 {
        a.run_next().unwrap();
    }

    // Stop after the first impact, go through bytes, and carry on.
    let mut b = Sample::new(params.clone(), 11).unwrap();
    b.run_next().unwrap();
    let bytes = b.checkpoint();
    drop(b);
    let mut c = Sample::resume(&params, 11, &bytes).unwrap();
    assert_eq!(c.impacts_done(), 1);
    c.run_next().unwrap();
    c.run_next().unwrap();

    assert_eq!(record_bits(a.records()), record_bits(c.records()));
    assert_eq!(a.records(), c.records());
    assert_eq!(bits(a.surface()), bits(c.surface()));
    // The impacts did something: the surface deformed plastically.
    assert!(a.surface().eps_p.iter().any(|&e| e > 0.01));

    // Another seed aims and turns the grains differently.
    let mut d = Sample::new(params, 12).unwrap();
    d.run_next().unwrap();
    assert_ne!(
        a.records()[0].orientation_rad.to_bits(),
        d.records()[0].orientation_rad.to_bits()
    );
}

#[test]
fn checkpoint_of_another_job_or_garbage_is_refused() {
    let params = coarse(90.0);
    let s = Sample::new(params.clone(), 5).unwrap();
    let bytes = s.checkpoint();
    let other_seed = Sample::resume(&params, 6, &bytes).unwrap_err();
    assert!(matches!(other_seed, SampleError::Checkpoint(ref m) if m.contains("another job")));
    let other_angle = Sample::resume(&coarse(45.0), 5, &bytes).unwrap_err();
    assert!(matches!(other_angle, SampleError::Checkpoint(_)));
    let garbage = Sample::resume(&params, 5, &[1, 2, 3]).unwrap_err();
    assert!(matches!(garbage, SampleError::Checkpoint(ref m) if m.contains("decode")));
    // One bit flipped in a particle's state, or the checksum cut off: refused, not resumed
    // into other numbers.
    let refusal = |b: &[u8]| match Sample::from_checkpoint(b) {
        Err(SampleError::Checkpoint(m)) => m,
        other => panic!("expected a refusal, got {:?}", other.map(|_| ())),
    };
    let mut flipped = bytes.clone();
    let at = bytes.len() - 40;
    flipped[at] ^= 0x10;
    assert!(
        refusal(&flipped).starts_with("damaged"),
        "{}",
        refusal(&flipped)
    );
    assert!(refusal(&bytes[..bytes.len() - 5]).starts_with("truncated"));
    assert_eq!(
        bytes[0],
        grit_erosion::impact::sample::CHECKPOINT_VERSION as u8
    );
    // Checkpoints written before the surface had a state type of its own (version 6, `Particles`
    // in its own layout, then the checksum) and before the checksum (version 5) read, and go on
    // as the sample they were taken from.
    let mut s = s;
    s.run_next().unwrap();
    for version in [5u32, 6] {
        let old = old_checkpoint(&s, version);
        let mut back = Sample::from_checkpoint(&old).unwrap();
        assert_eq!(back.seed(), 5);
        assert_eq!(bits(back.surface()), bits(s.surface()));
        assert_eq!(record_bits(back.records()), record_bits(s.records()));
        assert!(back
            .records()
            .iter()
            .all(|r| r.outcome.damage_added_kg.is_none()));
        back.run_next().unwrap();
    }
}

#[test]
fn a_version_7_checkpoint_from_the_campaigns_binary_resumes_to_todays_bits() {
    // Written by the farm of commit deb87e0 (10 per Dg, 45°, seed 3, 72 impacts), whose
    // records postcard laid out without `damage_added_kg`. Impact 73 is what today's engine
    // gives from it by `grit sample --resume`: the library resuming the old layout gives the
    // command line's bits.
    let bytes = include_bytes!("data/checkpoint-v7.ckpt");
    let mut s = Sample::from_checkpoint(bytes).unwrap();
    assert_eq!(s.records().len(), 72);
    assert!(s
        .records()
        .iter()
        .all(|r| r.outcome.damage_added_kg.is_none()));
    let r = s.run_next().unwrap().clone();
    assert_eq!(r.impact, 73);
    assert_eq!(r.outcome.sim_time_s, 1.1003749682299804e-06);
    assert_eq!(r.outcome.steps, 159);
    assert_eq!(r.outcome.rebound_ratio, 0.5064199013719087);
    assert!(r.outcome.damage_added_kg.is_some());
    // And the new layout keeps both kinds of record.
    let again = Sample::from_checkpoint(&s.checkpoint()).unwrap();
    assert_eq!(again.records(), s.records());
}

/// `s`'s checkpoint as a build before `ParticlesState` wrote it: version 6 with its checksum,
/// version 5 without; the records in their layout of then, without the damage added.
fn old_checkpoint(s: &Sample, version: u32) -> Vec<u8> {
    use sha2::{Digest, Sha256};
    #[derive(serde::Serialize)]
    struct Old<'a> {
        version: u32,
        params_json: String,
        seed: u64,
        surface: &'a Particles,
        records: Vec<OldRecord>,
    }
    #[derive(serde::Serialize)]
    struct OldRecord {
        impact: u32,
        grain_mass_kg: f64,
        mass_loss_kg: f64,
        orientation_rad: f64,
        aim_x_m: f64,
        outcome: (f64, u32, f64, u32, f64, u64, f64, bool),
    }
    let records = s
        .records()
        .iter()
        .map(|r| {
            let o = &r.outcome;
            OldRecord {
                impact: r.impact,
                grain_mass_kg: r.grain_mass_kg,
                mass_loss_kg: r.mass_loss_kg,
                orientation_rad: r.orientation_rad,
                aim_x_m: r.aim_x_m,
                outcome: (
                    o.mass_loss_kg,
                    o.removed_particles,
                    o.detached_kg,
                    o.detached_particles,
                    o.sim_time_s,
                    o.steps,
                    o.rebound_ratio,
                    o.settled,
                ),
            }
        })
        .collect();
    let old = Old {
        version,
        params_json: serde_json::to_string(s.params()).unwrap(),
        seed: s.seed(),
        surface: s.surface(),
        records,
    };
    let mut bytes = postcard::to_stdvec(&old).unwrap();
    if version == 6 {
        let digest = Sha256::digest(&bytes);
        bytes.extend_from_slice(&digest);
    }
    bytes
}

#[test]
fn cancelled_impact_leaves_the_sample_unchanged() {
    let params = coarse(90.0);
    let mut s = Sample::new(params, 3).unwrap();
    let before = bits(s.surface());
    let polls = std::cell::Cell::new(0);
    let err = s
        .run_next_cancellable(&|| {
            polls.set(polls.get() + 1);
            polls.get() > 100
        })
        .unwrap_err();
    assert!(err.to_string().contains("cancelled"), "{err}");
    assert_eq!(s.impacts_done(), 0);
    assert_eq!(bits(s.surface()), before);
}

#[test]
fn bad_scene_names_the_field() {
    let cases: Vec<(ImpactParams, &str)> = vec![
        (ImpactParams::paper(0.0, Shape::Hexagon), "angle_deg"),
        (ImpactParams::paper(95.0, Shape::Hexagon), "angle_deg"),
        (
            ImpactParams {
                spacing_m: -1.0,
                ..Default::default()
            },
            "spacing_m",
        ),
        (
            ImpactParams {
                spacing_m: 100e-6,
                ..Default::default()
            },
            "spacing_m",
        ),
        (
            ImpactParams {
                velocity_m_s: f64::NAN,
                ..Default::default()
            },
            "velocity_m_s",
        ),
        (
            ImpactParams {
                grain_density_kg_m3: 0.0,
                ..Default::default()
            },
            "grain_density_kg_m3",
        ),
        (
            ImpactParams {
                surface_width_dg: 2.5,
                ..Default::default()
            },
            "surface_width_dg",
        ),
        (
            ImpactParams {
                friction: -0.1,
                ..Default::default()
            },
            "friction",
        ),
        (
            // 0.3 Dg at 8 µm is 9.4 layers, fewer than the 12 a surface needs.
            ImpactParams {
                surface_depth_dg: 0.3,
                ..Default::default()
            },
            "surface_depth_dg",
        ),
    ];
    for (p, field) in cases {
        let e = p.validate().unwrap_err();
        assert_eq!(e.field, field, "{e}");
        assert!(Sample::new(p, 1).is_err());
    }
    let mut m = ImpactParams::default();
    m.material.poisson_ratio = 0.5;
    assert!(m.validate().unwrap_err().field.starts_with("material."));
    let unknown = serde_json::from_str::<ImpactParams>(r#"{"angle": 45}"#).unwrap_err();
    assert!(unknown.to_string().contains("angle"), "{unknown}");
}

#[test]
fn one_impact_is_bitwise_the_same_on_1_and_2_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            // Fine enough that every stage splits into several rayon tasks.
            let params = ImpactParams {
                spacing_m: 16e-6,
                surface_width_dg: 3.0,
                ..ImpactParams::paper(45.0, Shape::Square)
            };
            let mut s = Sample::new(params, 21).unwrap();
            s.run_next().unwrap();
            (bits(s.surface()), record_bits(s.records()))
        })
    };
    let (one, two) = (run(1), run(2));
    assert!(one.0.len() > 1000);
    assert_eq!(one, two);
}

/// The grain-shell saving: dropping the grain's interior particles must change nothing,
/// at 45° and at 90°, over several impacts on the same seed.
#[test]
fn grain_shell_gives_the_full_grain_bit_for_bit() {
    for angle in [45.0, 90.0] {
        let run = |shell: bool| {
            let mut params = coarse(angle);
            params.numerics.engine.rigid_shell = shell;
            let mut s = Sample::new(params, 5).unwrap();
            for _ in 0..3 {
                s.run_next().unwrap();
            }
            let n = s.last_particles();
            (bits(s.surface()), record_bits(s.records()), n)
        };
        let (full, shell) = (run(false), run(true));
        assert_eq!(full.0, shell.0, "surface at {angle}°");
        assert_eq!(full.1, shell.1, "records at {angle}°");
        // The shell really is smaller: the hexagon's interior is gone.
        assert!(shell.2 + 20 < full.2, "{} vs {}", shell.2, full.2);
    }
}
