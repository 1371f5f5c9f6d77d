//! `grit bench impact`, `grit bench stability` and `grit bench sweep` at CI size: they run, mark
//! what fails, write their CSV, JSON and charts, resume without redoing points, and refuse bad
//! input clearly.

mod common;

use common::png_ok;
use std::process::{Command, Output};

use grit_erosion::studies::settle::SettleRow;
use grit_erosion::studies::stability::{Failure, Panel, StabilityPoint, Verdict};
use grit_erosion::studies::sweep::SweepRow;
use grit_erosion::{ImpactParams, Sample};

fn grit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grit"))
        .args(args)
        .output()
        .expect("run grit")
}

fn ok(out: &Output) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "stdout: {stdout}\nstderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// 8 particles per Dg (31.25 µm): the coarsest scene the validation accepts, seconds a point.
const COARSE: &str = "3.125e-5";

#[test]
fn stability_map_marks_the_spring_limit_and_writes_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let stdout = ok(&grit(&[
        "bench",
        "stability",
        "--spacing-m",
        COARSE,
        "--cfl",
        "0.3,2.0",
        "--hourglass",
        "0.1",
        "--stiffness",
        "1,256",
        "--out",
        out,
        "--threads",
        "2",
    ]));
    assert!(
        stdout.contains("stiffness × step, penetration contact"),
        "{stdout}"
    );
    let points: Vec<StabilityPoint> =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("stability.json")).unwrap())
            .unwrap();
    assert_eq!(points.len(), 2 + 2 * 4);
    let at = |panel: Panel, cfl: f64, k: f64| {
        points
            .iter()
            .find(|p| p.panel == panel && p.cfl == cfl && p.stiffness_scale == k)
            .unwrap()
    };
    for panel in [Panel::StiffnessStep, Panel::StiffnessStepPenetration] {
        // The seed's numerics: the CFL-matched spring at Courant number 0.3 is stable.
        let seed = at(panel, 0.3, 1.0);
        assert_eq!(seed.verdict, Verdict::Stable, "{seed:?}");
        assert!(seed.mass_loss_kg.is_some() && seed.rebound_ratio.is_some());
        // 256 times stiffer with twice the material step: far beyond the spring's 2√(m/k).
        let wild = at(panel, 2.0, 256.0);
        assert_eq!(wild.verdict, Verdict::Unstable, "{wild:?}");
        assert!(wild.diagnostic.as_deref().unwrap_or("").contains("step"));
        assert_ne!(wild.failure, None);
        assert!(wild.steps < 1000, "{wild:?}");
    }
    let csv = std::fs::read_to_string(dir.path().join("stability.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + points.len());
    assert!(csv.starts_with("panel,contact_model,cfl,hourglass,stiffness_scale"));
    png_ok(&dir.path().join("stability.png"));
    let svg = std::fs::read_to_string(dir.path().join("stability.svg")).unwrap();
    assert!(svg.contains("penetration contact") && svg.contains(Failure::PassedThrough.label()));
}

#[test]
fn sweep_runs_two_variants_resumes_and_charts() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let common = [
        "bench",
        "sweep",
        "--samples",
        "2",
        "--impacts",
        "21",
        "--variants",
        "seed,cfl=0.5",
        "--out",
        out,
        "--threads",
        "2",
    ];
    let first = ok(&grit(&[&common[..], &["--ppd", "8"]].concat()));
    assert!(first.contains("CFL 0.5"), "{first}");
    // Resuming with one resolution more runs only the missing points.
    let second = ok(&grit(
        &[&common[..], &["--ppd", "8,9", "--resume"]].concat(),
    ));
    let rows: Vec<SweepRow> =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("sweep.json")).unwrap())
            .unwrap();
    assert_eq!(rows.len(), 4, "{second}");
    let seed8: Vec<&SweepRow> = rows.iter().filter(|r| r.particles_per_dg == 8.0).collect();
    assert_eq!(seed8.len(), 2);
    for r in &rows {
        assert_eq!((r.samples, r.impacts), (2, 21));
        assert!(r.wall_per_impact_s > 0.0 && r.steps_per_impact > 0.0);
        assert!(r.cpu_per_impact_s.is_some_and(|c| c > 0.0), "{r:?}");
        assert!(
            r.erosion_mean.is_some(),
            "every sample has 21 impacts: {r:?}"
        );
        // 1.25 Dg is 10–11 layers at 8–9 per Dg: deepened to the 12 the scene needs.
        assert!(r.surface_depth_dg > 1.25, "{r:?}");
        assert!(
            (r.surface_depth_dg * r.particles_per_dg - 12.0).abs() < 1e-6,
            "{r:?}"
        );
        let e = r.hertz_p0_error.expect("Hertz runs at 8–9 per radius");
        assert!(e > 0.0 && e < 1.0, "{r:?}");
    }
    // A larger Courant number takes fewer steps for the same impacts.
    let steps = |v: &str| {
        rows.iter()
            .find(|r| r.variant == v && r.particles_per_dg == 8.0)
            .unwrap()
            .steps_per_impact
    };
    assert!(steps("CFL 0.5") < steps("seed (quintic, CFL 0.3)"));
    // Resuming with nothing left to do rewrites every file from the rows it has.
    std::fs::remove_file(dir.path().join("sweep.csv")).unwrap();
    std::fs::remove_file(dir.path().join("speed-accuracy.png")).unwrap();
    ok(&grit(
        &[&common[..], &["--ppd", "8,9", "--resume"]].concat(),
    ));
    let csv = std::fs::read_to_string(dir.path().join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5);
    png_ok(&dir.path().join("speed-accuracy.png"));
}

#[test]
fn the_budget_study_charges_each_impact_and_groups_by_angle() {
    let stdout = ok(&grit(&[
        "study",
        "budget",
        "--angle",
        "60",
        "--spacing-m",
        COARSE,
        "--seeds",
        "1,2",
        "--impacts",
        "2",
        "--patch",
        r#"{"friction": 0.3}"#,
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4, "two samples of two impacts");
    assert!(rows.iter().all(|r| r["plastic_kg"].as_f64().unwrap() > 0.0));
    let a = &v["by_angle"][0];
    assert_eq!(
        (a["angle_deg"].as_f64(), a["impacts"].as_u64()),
        (Some(60.0), Some(4))
    );
}

/// From a worn surface, the settle study's reference path is the sample's own (the same impacts,
/// bit for bit), and a looser end stops each impact no later, from the same state.
#[test]
fn the_settle_study_resumes_a_checkpoint_and_a_looser_end_stops_sooner() {
    let dir = tempfile::tempdir().unwrap();
    let params = ImpactParams {
        angle_deg: 45.0,
        spacing_m: COARSE.parse().unwrap(),
        ..ImpactParams::default()
    };
    let mut s = Sample::new(params, 3).unwrap();
    s.run_next().unwrap();
    let ckpt = dir.path().join("worn.ckpt");
    std::fs::write(&ckpt, s.checkpoint()).unwrap();
    let stdout = ok(&grit(&[
        "study",
        "settle",
        "--resume",
        ckpt.to_str().unwrap(),
        "--impacts",
        "2",
        "--other-fraction",
        "0.2",
        "--threads",
        "1",
        "--json",
    ]));
    let rows: Vec<SettleRow> = serde_json::from_str(&stdout).unwrap();
    s.run_next().unwrap();
    s.run_next().unwrap();
    let own = &s.records()[1..];
    assert_eq!(rows.len(), 2);
    for (row, rec) in rows.iter().zip(own) {
        assert_eq!(row.impact, rec.impact);
        assert_eq!(row.mass_loss_kg.to_bits(), rec.mass_loss_kg.to_bits());
        assert_eq!(row.steps, rec.outcome.steps);
        assert!(row.steps_other <= row.steps && row.sim_time_other_s <= row.sim_time_s);
    }
    assert!(
        rows.iter().any(|r| r.steps_other < r.steps),
        "a five times looser end shortened no impact: {rows:?}"
    );
}

#[test]
fn studies_refuse_bad_input_naming_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let cases: [(&[&str], &str); 30] = [
        (
            &["bench", "impact", "--repeat", "0"],
            "'--repeat <REPEAT>': must be a whole number from 1 to 1000",
        ),
        (
            &["bench", "impact", "--threads", "0"],
            "'--threads <THREADS>': must be a whole number from 1 to 1024",
        ),
        (
            &["bench", "sweep", "--ppd", "16,1000", "--out", out],
            "--ppd: give resolutions of 6 to 128",
        ),
        (
            &["study", "settle", "--angle", "45", "--other-fraction", "0.02"],
            "--other-fraction: must be > 0, below 1 and not the scene's settle_fraction 0.02",
        ),
        (&["study", "budget"], "angle: required"),
        (
            &["study", "budget", "no-such.ckpt", "--angle", "30"],
            "--angle: a checkpoint carries its own scene",
        ),
        (&["study", "budget", "no-such.ckpt"], "no-such.ckpt: cannot read"),
        (
            &["study", "budget", "--angle", "45", "--patch", "[1]"],
            "--patch: must be a JSON object",
        ),
        (
            &[
                "study",
                "budget",
                "--angle",
                "45",
                "--patch",
                r#"{"spacing_m": 1e-5}"#,
            ],
            "--patch: spacing_m: cannot change on a worn surface",
        ),
        (
            &["study", "rc", "--jet-speed-m-s", "1e5"],
            "--jet-speed-m-s: must be > 0 and at most 2000",
        ),
        (
            &["verify", "--only", "nosuchcase"],
            "--only: `nosuchcase` is in no case's name",
        ),
        (
            &["sample", "--angle", "45", "--impacts", "1000000000"],
            "must be a whole number from 1 to 100000",
        ),
        (
            &["sample", "--angle", "45", "--spacing-m", "1e-9"],
            "spacing_m: must be at most 512 particles per grain diameter",
        ),
        (
            &["sample", "--angle", "45", "--velocity-m-s", "1e6"],
            "velocity_m_s: must be at most 1000 m/s",
        ),
        (
            &["sample", "--resume", "no-such.ckpt", "--angle", "30"],
            "--angle: --resume runs the scene and seed stored in the checkpoint",
        ),
        (
            &["sample", "--angle", "45", "--impacts", "2", "-o", "/proc/no/x.json"],
            "--out /proc/no/x.json: cannot write there",
        ),
        (
            &["jet", "--velocity-m-s", "1e308"],
            "velocity_m_s: must be at most 2000 m/s (abrasive water jets run at 300-900 m/s), got 1e308",
        ),
        (
            &["jet", "--time-ms", "1e308"],
            "time_ms: must be at most 1000 ms",
        ),
        (&["work", "--poll-s", "1e20"], "must be a number of seconds > 0"),
        (
            &["serve", "--lease-ttl-s", "18446744073709551615"],
            "must be a number of seconds > 0",
        ),
        (
            &["run", "examples/quick.json", "--workers", "100000"],
            "'--workers <WORKERS>': must be a whole number from 1 to 1024",
        ),
        (
            &["compare", "tests/data/quick-results.json", "--window", "81-100000"],
            "--window 81-100000: no cell of tests/data/quick-results.json has those impacts",
        ),
        (
            &["sample", "--angle", "-5"],
            "angle_deg: must be in (0, 90], got -5",
        ),
        (&["shapes", "--diameter-m", "1e300"], "--diameter-m: must lie in [1e-6, 1] m, got 1e300"),
        (
            &["bench", "stability", "--cfl", "0.3,3", "--out", out],
            "--cfl: 3",
        ),
        (
            &["bench", "stability", "--stiffness", "0", "--out", out],
            "--stiffness: 0",
        ),
        (
            &["bench", "stability", "--spacing-m", "1e-4", "--out", out],
            "spacing_m",
        ),
        (
            &["bench", "sweep", "--variants", "cubic", "--out", out],
            "unknown variant `cubic`",
        ),
        (
            &["bench", "sweep", "--impacts", "5", "--out", out],
            "--impacts: at least 21",
        ),
        (&["bench", "sweep", "--ppd", "4", "--out", out], "--ppd"),
    ];
    for (args, expected) in cases {
        let o = grit(args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

/// The figures and JSON names the impact bench promises, from a coarse impact timed twice each way; the
/// grain shell and flight skip are on by default and can be turned off.
#[test]
fn impact_bench_prints_its_fields_with_medians_of_repeats() {
    let run = |extra: &[&str]| -> serde_json::Value {
        let args = [
            &["bench", "impact", "--spacing-m", COARSE, "--json"][..],
            extra,
        ]
        .concat();
        serde_json::from_str(&ok(&grit(&args))).expect("JSON")
    };
    let v = run(&["--repeat", "2"]);
    for key in [
        "particles",
        "steps",
        "wall_s",
        "particle_steps_per_s",
        "particle_steps_per_s_per_thread",
        "threads",
        "speedup_1_to_2",
        "stages",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    assert_eq!(v["repeats"], 2);
    let runs = v["wall_s_runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    let (a, b) = (runs[0].as_f64().unwrap(), runs[1].as_f64().unwrap());
    assert!((v["wall_s"].as_f64().unwrap() - 0.5 * (a + b)).abs() < 1e-12);
    for stage in ["kernel_sums", "forces", "stress", "contact", "neighbours"] {
        assert!(v["stages"][stage].as_f64().unwrap() > 0.0, "{stage}: {v}");
        // The same stage on 1 thread, so each stage's speed-up can be read off.
        assert!(
            v["stages_1_thread"][stage].as_f64().unwrap() > 0.0,
            "{stage} on 1 thread: {v}"
        );
    }
    // The bare kernel-sum loop over the same pairs, timed in the same run.
    let c = &v["ceiling"];
    for key in [
        "s_per_step",
        "pair_terms_per_step",
        "pair_terms_per_s",
        "particle_steps_per_s",
        "full_step_over_ceiling",
    ] {
        assert!(c[key].as_f64().unwrap() > 0.0, "ceiling {key}: {v}");
    }
    // The same impact again, so the same steps: the ceiling times the pairs the run used.
    assert_eq!(c["steps"], v["steps"], "{v}");
    // Which path the pair pass took, so that two machines' figures are compared knowingly.
    assert!(
        ["four at a time (AVX2)", "pair by pair"].contains(&v["pair_pass"].as_str().unwrap()),
        "{v}"
    );
    // The old model: every grain particle, and the flight simulated step by step.
    let full = run(&["--full-grain", "--full-flight"]);
    assert!(full["particles"].as_u64() > v["particles"].as_u64());
    assert!(full["steps"].as_u64() > v["steps"].as_u64());
}
