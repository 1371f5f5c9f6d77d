//! The same bits on any worker machine: a sample run with the CPU's FMA and AVX2 hidden from
//! glibc, as on an older x86-64 worker, writes the same bytes as one that sees them. glibc picks
//! its pow, exp, log, sin and cos by CPU at load time, so this holds only because the engine
//! takes those from one software libm (docs/design.md, "Rules the engine keeps").

use std::process::Command;

const GRIT: &str = env!("CARGO_BIN_EXE_grit");

/// The bytes of one impact of the reference scene at 45° (Johnson–Cook plasticity and fracture,
/// the grain's rotation), with `tunables` as GLIBC_TUNABLES. The build that took these from the
/// system libm wrote different bytes the two ways here (its rebound ratio already parted in the
/// last digits); a coarser scene did not show it.
fn sample(tunables: &str) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sample.json");
    let o = Command::new(GRIT)
        .env("GLIBC_TUNABLES", tunables)
        .args([
            "sample",
            "--angle",
            "45",
            "--impacts",
            "1",
            "--seed",
            "3",
            "--json",
            "-o",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read(&out).unwrap()
}

#[test]
fn a_sample_has_the_same_bytes_whether_glibc_sees_fma_or_not() {
    let seen = sample("");
    let hidden = sample("glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F");
    assert!(!seen.is_empty());
    assert!(
        seen == hidden,
        "the sample's bytes depend on the CPU features glibc sees"
    );
}
