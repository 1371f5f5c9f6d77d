//! `grit jet` at CI size: the JSON it prints holds the series the issue names, the snapshots
//! are written (pictures not blank, ParaView files readable as XML with every particle), and bad
//! input is refused with the field named and a non-zero exit.

mod common;

use common::png_ok;
use std::process::{Command, Output};

fn grit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grit"))
        .args(args)
        .output()
        .expect("run grit")
}

/// A small, fast scene: 6 particles across a 0.6 mm jet on a 3 × 0.8 mm copper target.
const TINY: &str = r#"{"spacing_m": 1e-4, "jet_width_m": 6e-4, "target_width_m": 3e-3,
    "target_depth_m": 8e-4, "standoff_m": 6e-4, "grain_diameter_m": 2e-4,
    "mass_flow_kg_s": 0.01, "time_ms": 0.003, "slice_ms": 0.001}"#;

/// Fails the test with the command's stderr unless it exited successfully.
fn succeeded(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The JSON a successful command printed.
fn json_of(out: &Output) -> serde_json::Value {
    succeeded(out);
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn a_small_jet_prints_its_series_and_writes_snapshots() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.json");
    std::fs::write(&scene, TINY).unwrap();
    let snaps = dir.path().join("snaps");
    let out = grit(&[
        "jet",
        "--scene",
        scene.to_str().unwrap(),
        "--seed",
        "3",
        "--json",
        "--snapshots",
        snaps.to_str().unwrap(),
        "--snapshot-every",
        "2",
    ]);
    let v = json_of(&out);
    let series = v["series"].as_array().unwrap();
    assert_eq!(series.len(), 3);
    for key in grit_sph::crater::CraterSample::FIELDS {
        assert!(series[2][key].is_number(), "{key} missing");
    }
    assert!((series[2]["t_s"].as_f64().unwrap() - 3e-6).abs() < 1e-8);
    assert_eq!(v["seed"], 3);
    assert_eq!(v["params"]["material"], "copper");
    // Slices 2 and 3 (the last) are snapshot.
    for tag in ["0002", "0003"] {
        for stem in ["phase", "pressure", "damage"] {
            png_ok(&snaps.join(format!("{stem}-{tag}.png")));
        }
        let vtu = std::fs::read_to_string(snaps.join(format!("scene-{tag}.vtu"))).unwrap();
        assert!(vtu.contains("pressure_pa") && vtu.contains("NumberOfPoints"));
        assert!(snaps.join(format!("grains-{tag}.vtu")).exists());
    }
    let pvd = std::fs::read_to_string(snaps.join("scene.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 2);
}

#[test]
fn bad_jet_input_names_the_field_and_exits_non_zero() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, r#"{"standoff_m": 1e-4}"#).unwrap();
    for (args, needle) in [
        (vec!["jet", "--material", "unobtainium"], "unobtainium"),
        (vec!["jet", "--velocity-m-s=-3"], "velocity_m_s"),
        (vec!["jet", "--spacing-m", "3e-4"], "jet_width_m"),
        (vec!["jet", "--scene", bad.to_str().unwrap()], "standoff_m"),
    ] {
        let out = grit(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn the_coupling_radius_study_rides_a_grain_and_refuses_bad_scenes() {
    let out = grit(&[
        "study",
        "rc",
        "--across",
        "8",
        "--jet-speed-m-s",
        "300",
        "--rc",
        "2",
        "--releases",
        "2",
        "--json",
    ]);
    let v = json_of(&out);
    assert_eq!(v["scene"]["jet_speed_m_s"], 300.0);
    assert_eq!(v["scene"]["releases"], 2);
    let rides = v["rides"].as_array().unwrap();
    assert_eq!(rides.len(), 1);
    assert_eq!(rides[0]["label"], "R_c = 2 d");
    // The grain is braked in the stagnation zone, never sped up past the jet.
    let speed = rides[0]["contact_speed_m_s"].as_f64().unwrap();
    assert!(speed > 0.0 && speed < 300.0, "{speed}");
    // The contact speed is the mean of the two releases, which land apart in a jet that is
    // not perfectly steady.
    let each: Vec<f64> = rides[0]["contact_speeds_m_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(each.len(), 2);
    assert!(
        (speed - 0.5 * (each[0] + each[1])).abs() < 1e-9 * speed,
        "{each:?}"
    );
    let std = rides[0]["contact_speed_std_m_s"].as_f64().unwrap();
    assert!(
        (std - (each[0] - each[1]).abs() / 2f64.sqrt()).abs() < 1e-9 * speed,
        "{std}"
    );
    // On its way in it was faster the farther from the wall, and at 0.125 d from contact
    // already near its contact speed.
    let before = rides[0]["speed_before_contact"].as_array().unwrap();
    let at = |k: usize| before[k]["speed_m_s"].as_f64().unwrap();
    assert_eq!(before.len(), 6);
    assert_eq!(before[0]["distance_d"], 4.0);
    assert!((1..6).all(|k| at(k) <= at(k - 1)), "{before:?}");
    assert!(at(0) < 300.0 && at(5) >= speed - 50.0, "{before:?}");
    for (args, needle) in [
        (vec!["--across", "7"], "--across"),
        (vec!["--jet-speed-m-s=-1"], "--jet-speed-m-s"),
        (vec!["--release-ratio", "3"], "--release-ratio"),
        (vec!["--switch-porosity", "1.5"], "--switch-porosity"),
        (vec!["--rc", "0"], "--rc"),
        (vec!["--cfl", "0"], "--cfl"),
        (vec!["--releases", "0"], "--releases"),
        (vec!["--release-at-b-over-v=-1"], "--release-at-b-over-v"),
        // 8 across is 0.125 mm per particle: too coarse to resolve a 0.2 mm grain.
        (
            vec!["--across", "8", "--rc", "2", "--resolved"],
            "finer spacing",
        ),
    ] {
        let out = grit(&[&["study", "rc"], &args[..]].concat());
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn grit_plot_gathers_jet_run_files_into_a_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.json");
    std::fs::write(&scene, TINY).unwrap();
    let mut files = Vec::new();
    for seed in ["1", "2"] {
        let file = dir.path().join(format!("run-{seed}.json"));
        let out = grit(&[
            "jet",
            "--scene",
            scene.to_str().unwrap(),
            "--time-ms",
            "0.002",
            "--seed",
            seed,
            "-o",
            file.to_str().unwrap(),
        ]);
        succeeded(&out);
        files.push(file.to_str().unwrap().to_string());
    }
    let charts = dir.path().join("charts");
    let mut args = vec!["plot", "--out", charts.to_str().unwrap()];
    args.extend(files.iter().map(String::as_str));
    let out = grit(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    succeeded(&out);
    // One cell (equal parameters) of two samples, the seeds.
    let row = stdout.lines().nth(1).unwrap_or_default();
    assert!(row.contains("500 m/s") && row.contains(" 2 "), "{stdout}");
    for chart in [
        "jet_depth_vs_time",
        "jet_mass_loss_vs_time",
        "jet_depth_vs_speed",
    ] {
        png_ok(&charts.join(format!("{chart}.png")));
    }
    // The same seed twice is refused, naming the run.
    let out = grit(&["plot", &files[0], &files[0]]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("runs[1].seed"), "{err}");
    // A run file beside another kind of file is refused, naming the other.
    let other = dir.path().join("scene-copy.json");
    std::fs::write(&other, TINY).unwrap();
    let out = grit(&["plot", &files[0], other.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("scene-copy.json"), "{err}");
}

/// A rock campaign swept over the abrasive mass flow: its results carry the cracks per slice
/// and at T and each sample's first grain, and `grit run` draws the rock's charts against
/// time and the AWJ paper's trend charts against M (Figs. 27-28).
#[test]
fn a_rock_campaign_charts_its_cracks_and_the_mass_flow_trend() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("rock.json");
    std::fs::write(
        &spec,
        r#"{"scene": "jet", "seed": 5, "samples": 1, "material": "sandstone",
            "velocity_m_s": 400, "mass_flow_kg_s": [0.01, 0.04], "time_ms": 0.004,
            "slice_ms": 0.001, "spacing_m": 1e-4, "jet_width_m": 6e-4,
            "target_width_m": 3e-3, "target_depth_m": 8e-4, "standoff_m": 6e-4,
            "grain_diameter_m": 2e-4}"#,
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    let out = grit(&[
        "run",
        spec.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
        "--workers",
        "1",
        "--quiet",
    ]);
    succeeded(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("cracks at T"), "{stdout}");
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("results.json")).unwrap()).unwrap();
    for cell in results["cells"].as_array().unwrap() {
        let at_t = &cell["rock"];
        assert!(at_t["crack_count"]["mean"].is_number(), "{cell}");
        assert!(
            at_t["fractured_particles"]["mean"].as_f64().unwrap() > 0.0,
            "{cell}"
        );
        let series = cell["mean_series"].as_array().unwrap();
        assert_eq!(series.len(), 4);
        assert!(series
            .iter()
            .all(|p| p["rock"]["crack_count"]["mean"].is_number()));
    }
    for stem in [
        "jet_cracks_vs_time",
        "jet_crack_depth_vs_time",
        "jet_depth_vs_mass_flow",
        "jet_width_vs_mass_flow",
        "jet_mass_loss_vs_mass_flow",
        "jet_crack_depth_vs_mass_flow",
        "jet_depth_vs_speed",
    ] {
        png_ok(&out_dir.join(format!("{stem}.png")));
    }
    // One jet speed: no width-against-speed chart.
    assert!(!out_dir.join("jet_width_vs_speed.png").exists());
}
