//! Results the process-level tests compare: `grit run`'s results.json, the per-impact raw
//! series (or jet slices) of a results document, and their bit-for-bit equality.

use std::path::Path;
use std::process::Command;

use grit_erosion::jet::JetSlice;
use grit_erosion::ImpactRecord;
use serde_json::Value;

use super::GRIT;

/// The per-impact series of a results document with `raw`: (cell, sample, records).
pub fn raw_series(results: &Value) -> Vec<(u64, u64, Vec<ImpactRecord>)> {
    results["raw"]
        .as_array()
        .expect("raw series present")
        .iter()
        .map(|s| {
            (
                s["cell"].as_u64().unwrap(),
                s["sample"].as_u64().unwrap(),
                serde_json::from_value(s["impacts"].clone()).unwrap(),
            )
        })
        .collect()
}

/// Bit-for-bit equality of two sets of per-impact series.
pub fn assert_bitwise_equal(
    a: &[(u64, u64, Vec<ImpactRecord>)],
    b: &[(u64, u64, Vec<ImpactRecord>)],
) {
    assert_eq!(a.len(), b.len());
    for ((ca, sa, ra), (cb, sb, rb)) in a.iter().zip(b) {
        assert_eq!((ca, sa), (cb, sb));
        assert_eq!(ra.len(), rb.len(), "cell {ca} sample {sa}: impact counts");
        for (x, y) in ra.iter().zip(rb) {
            assert_eq!(
                x.mass_loss_kg.to_bits(),
                y.mass_loss_kg.to_bits(),
                "impact {}",
                x.impact
            );
            assert_eq!(x.grain_mass_kg.to_bits(), y.grain_mass_kg.to_bits());
            assert_eq!(x.orientation_rad.to_bits(), y.orientation_rad.to_bits());
            assert_eq!(x.aim_x_m.to_bits(), y.aim_x_m.to_bits());
            assert_eq!(
                x.outcome.sim_time_s.to_bits(),
                y.outcome.sim_time_s.to_bits()
            );
            // A record stored before impacts recorded their damage added has none; the rest
            // is the same record.
            let (mut x, mut y) = (x.clone(), y.clone());
            if x.outcome.damage_added_kg.is_none() || y.outcome.damage_added_kg.is_none() {
                x.outcome.damage_added_kg = None;
                y.outcome.damage_added_kg = None;
            }
            assert_eq!(x, y);
        }
    }
}

/// `grit run` of `spec` into `out`; returns results.json.
pub fn grit_run(dir: &Path, spec: &str, out: &str, raw: bool) -> Value {
    let file = dir.join(format!("{out}.json"));
    std::fs::write(&file, spec).unwrap();
    let out_dir = dir.join(out);
    let mut cmd = Command::new(GRIT);
    cmd.arg("run")
        .arg(&file)
        .args(["--workers", "1", "--threads", "1", "--quiet", "--out"])
        .arg(&out_dir);
    if raw {
        cmd.arg("--raw");
    }
    let status = cmd.status().expect("grit run starts");
    assert!(status.success(), "grit run failed");
    serde_json::from_str(&std::fs::read_to_string(out_dir.join("results.json")).unwrap()).unwrap()
}

/// Every sample's slices of a results document with `raw`: (cell, sample, slices), each
/// slice's wall-clock seconds zeroed (the one field that is not a result).
pub fn raw_slices(results: &Value) -> Vec<(u64, u64, Vec<JetSlice>)> {
    results["raw"]
        .as_array()
        .expect("raw slices present")
        .iter()
        .map(|s| {
            let mut slices: Vec<JetSlice> = serde_json::from_value(s["slices"].clone()).unwrap();
            slices.iter_mut().for_each(|x| x.wall_s = 0.0);
            (
                s["cell"].as_u64().unwrap(),
                s["sample"].as_u64().unwrap(),
                slices,
            )
        })
        .collect()
}
