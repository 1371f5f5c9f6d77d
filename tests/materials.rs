//! Surface materials by name on the command line (docs/jet.md, "Metal targets"): an unknown
//! name is refused naming the field, and a named preset reaches the engine with its own
//! pressure law.

use std::process::Command;

/// `grit sample` of one coarse impact with `extra` flags, writing its result to `out`.
fn sample(out: &std::path::Path, extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_grit"))
        .args(["sample", "--angle", "45", "--spacing-m", "25e-6"])
        .args(["--surface-width-dg", "3", "--surface-depth-dg", "1.3"])
        .args(["--impacts", "1", "--threads", "1", "-o"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn an_unknown_material_is_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let out = sample(&dir.path().join("r.json"), &["--material", "steel"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("material: unknown material `steel`"), "{err}");
    assert!(err.contains("copper") && err.contains("al6061"), "{err}");
}

#[test]
fn copper_by_name_runs_with_its_own_pressure_law() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str| -> serde_json::Value {
        let file = dir.path().join(format!("{name}.json"));
        let out = sample(&file, &["--material", name]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap()
    };
    let cu = run("copper");
    let steel = run("aisi304");
    assert_eq!(cu["params"]["material"]["name"], "copper");
    assert_eq!(cu["params"]["material"]["eos"]["kind"], "mie_gruneisen");
    // The same grain and aim: only the surface differs, and copper (E = 124 GPa, the EOS's
    // K = ρ0 c0² = 139 GPa, A = 90 MPa) takes the grain differently from AISI 304.
    assert_eq!(cu["impacts"][0]["aim_x_m"], steel["impacts"][0]["aim_x_m"]);
    assert_ne!(
        cu["impacts"][0]["outcome"]["steps"],
        steel["impacts"][0]["outcome"]["steps"]
    );
}
