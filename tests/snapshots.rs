//! `grit sample --snapshots DIR` writes, for each chosen impact, PNG pictures of the surface
//! (damage and plastic strain, with the grain) that decode and show more than a background,
//! and ParaView files holding exactly the surface the sample reached; bad flags end with an
//! error that names the flag, before any impact runs.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::{Command, Output};

use grit_erosion::{ImpactParams, Sample};

/// The coarse scene of the runs here: 10 particles per Dg on a 2 × 1.25 Dg surface.
const SCENE: [&str; 10] = [
    "--angle",
    "90",
    "--spacing-m",
    "25e-6",
    "--surface-width-dg",
    "2",
    "--surface-depth-dg",
    "1.25",
    "--distribution-range-dg",
    "0",
];

fn grit(extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grit"))
        .arg("sample")
        .args(SCENE)
        .args(extra)
        .output()
        .expect("run grit")
}

fn params() -> ImpactParams {
    ImpactParams {
        angle_deg: 90.0,
        spacing_m: 25e-6,
        surface_width_dg: 2.0,
        surface_depth_dg: 1.25,
        distribution_range_dg: 0.0,
        ..ImpactParams::default()
    }
}

/// The numbers of the `DataArray` called `name` in a `.vtu` file.
fn vtu_array(text: &str, name: &str) -> Vec<f64> {
    let tag = format!(r#"Name="{name}""#);
    let start = text.find(&tag).unwrap_or_else(|| panic!("no array {name}"));
    let body = &text[start..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    body.split_whitespace()
        .map(|v| v.parse().unwrap_or_else(|_| panic!("{name}: `{v}`")))
        .collect()
}

fn check_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{path:?} is no PNG"
    );
    let img = image::load_from_memory(&bytes)
        .unwrap_or_else(|e| panic!("{path:?} does not decode: {e}"))
        .to_rgb8();
    let (w, h) = img.dimensions();
    assert!(w >= 600 && h >= 300, "{path:?} is {w}x{h}");
    let colours: BTreeSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(colours.len() > 20, "{path:?} has {} colours", colours.len());
    // Undamaged, unstrained free particles are the colour map's bottom (viridis dark purple).
    assert!(
        colours.contains(&[68, 1, 84]),
        "{path:?}: no particle at the bottom colour"
    );
}

#[test]
fn snapshots_write_pictures_and_paraview_files_of_the_surface() {
    let dir = tempfile::tempdir().unwrap();
    let snap = dir.path().join("snap");
    let out = grit(&["--impacts", "2", "--snapshots", snap.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "grit sample failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );

    // The default set takes the first and the last impact.
    let names: BTreeSet<String> = std::fs::read_dir(&snap)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    let want: BTreeSet<String> = [
        "damage-0001.png",
        "damage-0002.png",
        "plastic-strain-0001.png",
        "plastic-strain-0002.png",
        "surface-0001.vtu",
        "surface-0002.vtu",
        "grain-0001.vtu",
        "grain-0002.vtu",
        "surface.pvd",
        "grain.pvd",
    ]
    .map(String::from)
    .into();
    assert_eq!(names, want);
    for n in names.iter().filter(|n| n.ends_with(".png")) {
        check_png(&snap.join(n));
    }

    // The files hold the surface the same sample reaches in-process, bit for bit.
    let mut s = Sample::new(params(), 1).unwrap();
    s.run_next().unwrap();
    s.run_next().unwrap();
    let text = std::fs::read_to_string(snap.join("surface-0002.vtu")).unwrap();
    let n = s.surface().len();
    assert!(text.contains(&format!(r#"NumberOfPoints="{n}""#)));
    for (name, want) in [
        ("damage", &s.surface().damage),
        ("plastic_strain", &s.surface().eps_p),
        ("density_kg_m3", &s.surface().rho),
    ] {
        let got = vtu_array(&text, name);
        assert_eq!(got.len(), n, "{name}");
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&got),
            bits(want),
            "{name} differs from the sample's surface"
        );
    }
    assert_eq!(vtu_array(&text, "velocity_m_s").len(), 3 * n);
    assert_eq!(vtu_array(&text, "stress_pa").len(), 9 * n);
    assert!(vtu_array(&text, "damage").iter().any(|&d| d > 0.0));
    let grain = std::fs::read_to_string(snap.join("grain-0002.vtu")).unwrap();
    assert!(grain.contains(r#"NumberOfPoints="6" NumberOfCells="1""#));
    let pvd = std::fs::read_to_string(snap.join("surface.pvd")).unwrap();
    assert!(pvd.contains(r#"timestep="1" part="0" file="surface-0001.vtu""#));
    assert!(pvd.contains(r#"timestep="2" part="0" file="surface-0002.vtu""#));
}

#[test]
fn snapshot_at_picks_the_impacts() {
    let dir = tempfile::tempdir().unwrap();
    let out = grit(&[
        "--impacts",
        "2",
        "--snapshots",
        dir.path().to_str().unwrap(),
        "--snapshot-at",
        "2",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.path().join("damage-0002.png").exists());
    assert!(!dir.path().join("damage-0001.png").exists());
    // --json keeps stdout one JSON document.
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
    assert_eq!(v["series"].as_array().unwrap().len(), 2);
}

/// Runs `grit sample` with `extra` and expects a failure whose message contains `needles`.
fn fails(extra: &[&str], needles: &[&str]) {
    let out = grit(extra);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "succeeded with {extra:?}");
    for n in needles {
        assert!(err.contains(n), "error for {extra:?} lacks `{n}`: {err}");
    }
}

#[test]
fn bad_snapshot_flags_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    fails(
        &["--impacts", "2", "--snapshots", d, "--snapshot-at", "0"],
        &["--snapshot-at", "impact 0", "--impacts"],
    );
    fails(
        &["--impacts", "2", "--snapshots", d, "--snapshot-at", "1,3"],
        &["--snapshot-at", "impact 3", "1..=2"],
    );
    fails(&["--impacts", "2", "--snapshot-at", "1"], &["--snapshots"]);
    let file = dir.path().join("a-file");
    std::fs::write(&file, "not a folder").unwrap();
    let under_file = file.join("snap");
    fails(
        &[
            "--impacts",
            "2",
            "--snapshots",
            under_file.to_str().unwrap(),
        ],
        &["--snapshots", "cannot create the folder"],
    );
    assert!(
        std::fs::read_dir(dir.path()).unwrap().count() == 1,
        "a refused run wrote files"
    );
}

#[test]
fn resumed_sample_snapshots_only_impacts_still_to_run() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Sample::new(params(), 1).unwrap();
    s.run_next().unwrap();
    let ckpt = dir.path().join("ckpt.bin");
    std::fs::write(&ckpt, s.checkpoint()).unwrap();
    let snap = dir.path().join("snap");
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_grit"))
            .args([
                "sample",
                "--resume",
                ckpt.to_str().unwrap(),
                "--impacts",
                "2",
            ])
            .args(["--snapshots", snap.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap()
    };
    let out = run(&["--snapshot-at", "1"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--snapshot-at: impact 1 was finished before the checkpoint"),
        "{err}"
    );
    // The default set (first and last) keeps only the impact this run makes.
    let out = run(&[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(snap.join("damage-0002.png").exists());
    assert!(!snap.join("damage-0001.png").exists());
}
