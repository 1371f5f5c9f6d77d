//! Every campaign spec the repository ships (examples/ and the specs under docs/ and
//! notebook/) parses,
//! validates and expands into jobs, so a command quoted in the README or docs cannot fail on
//! its own input.

use std::path::{Path, PathBuf};

use grit_erosion::campaign::AnySpec;

/// Impact specs name their angles, jet specs their scene; results files have cells.
fn specs_in(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            specs_in(&path, out);
        } else if path.extension().is_some_and(|e| e == "json") {
            let text = std::fs::read_to_string(&path).unwrap();
            let spec = text.contains("\"angles_deg\"") || text.contains("\"scene\": \"jet\"");
            if spec && !text.contains("\"cells\"") {
                out.push(path);
            }
        }
    }
}

#[test]
fn every_shipped_campaign_spec_parses_validates_and_expands() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut specs = Vec::new();
    specs_in(&root.join("examples"), &mut specs);
    let in_examples = specs.len();
    specs_in(&root.join("docs"), &mut specs);
    specs_in(&root.join("notebook"), &mut specs);
    assert!(in_examples >= 12, "examples/ has {in_examples} specs");
    for path in &specs {
        let text = std::fs::read_to_string(path).unwrap();
        let fail = |e: &dyn std::fmt::Display| -> ! { panic!("{}: {e}", path.display()) };
        let spec = AnySpec::from_json(&text).unwrap_or_else(|e| fail(&e));
        let jobs = spec.plan().unwrap_or_else(|e| fail(&e)).jobs.len();
        assert!(jobs > 0, "{}: no jobs", path.display());
    }
}
