//! `grit version --json` names the build and measures both engine fingerprints: 16 hex digits
//! each, the same on every call, and a commit (or "unknown" outside a git checkout).

use std::process::Command;

mod common;
use common::{succeeds, GRIT};

fn version() -> serde_json::Value {
    let out = succeeds(Command::new(GRIT).args(["version", "--json"]));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn version_json_names_the_build_and_both_engines() {
    let v = version();
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
    let commit = v["commit"].as_str().unwrap();
    assert!(!commit.is_empty());
    for key in ["engine", "jet_engine"] {
        let f = v[key].as_str().unwrap();
        assert_eq!(f.len(), 16, "{key}: {f}");
        assert!(f.chars().all(|c| c.is_ascii_hexdigit()), "{key}: {f}");
    }
    assert!(v["seconds"].as_f64().unwrap() > 0.0);
    let again = version();
    assert_eq!(
        (&v["engine"], &v["jet_engine"]),
        (&again["engine"], &again["jet_engine"])
    );
}
