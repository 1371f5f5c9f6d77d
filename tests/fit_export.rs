//! `grit fit` and `grit export` end to end: a fit of synthetic steady cells is exported in all
//! five formats, each output is parsed and the model re-evaluated from it at three (α, v, d)
//! points to within 1e-9 of `grit fit --eval`; the OpenFOAM function object passes the C++
//! compiler against stub headers; bad input exits with status 2 and says why.

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

const GRIT: &str = env!("CARGO_BIN_EXE_grit");

/// The model the synthetic cells follow (not the fit's result: the test reads that from grit).
fn truth(angle: f64, v: f64, d: f64) -> f64 {
    let s = angle.to_radians().sin();
    2.0e-3
        * s.powf(0.8)
        * (1.0 + 1.8 * (1.0 - s)).powf(1.2)
        * (v / 100.0).powf(2.6)
        * (d / 250e-6).powf(0.3)
}

fn cell(angle: f64, v: f64, d: f64, steady: bool, wobble: f64) -> String {
    let e = truth(angle, v, d) * (1.0 + wobble);
    format!(
        r#"{{"angle_deg": {angle}, "shape": "hexagon",
            "swept": {{"velocity_m_s": {v}, "grain_diameter_m": {d}}},
            "partial": false, "samples": 3, "samples_planned": 3, "samples_reported": 3,
            "samples_without_slope": 0, "impacts_planned": 100, "erosion_mean": {e},
            "erosion_std": {std}, "erosion_sem": {sem}, "per_sample": [], "mean_series": [],
            "convergence": [],
            "steady_state": {{"steady": {steady}, "reason": "slopes agree",
                "samples_without_loss": 0, "samples_incubated_by_window": 3}}}}"#,
        std = 0.1 * e,
        sem = 0.05 * e
    )
}

/// A results file of cells at every (angle, speed, size); `unsteady` marks the first unsteady.
fn results(dir: &Path, name: &str, speeds: &[f64], sizes: &[f64], unsteady: bool) -> String {
    let mut points = Vec::new();
    for a in [30.0, 45.0, 90.0] {
        for &v in speeds {
            for &d in sizes {
                points.push((a, v, d));
            }
        }
    }
    results_of(dir, name, &points, unsteady)
}

/// A results file of the given (angle, speed, size) cells, within ±3 % of [`truth`].
fn results_of(dir: &Path, name: &str, points: &[(f64, f64, f64)], unsteady: bool) -> String {
    let cells: Vec<String> = points
        .iter()
        .enumerate()
        .map(|(k, &(a, v, d))| {
            let wobble = 0.03 * (((k * 7) % 5) as f64 - 2.0) / 2.0;
            cell(a, v, d, !(unsteady && k == 0), wobble)
        })
        .collect();
    let speeds: Vec<f64> = points.iter().map(|p| p.1).collect();
    let sizes: Vec<f64> = points.iter().map(|p| p.2).collect();
    let text = format!(
        r#"{{"partial": false, "slope_window": 20, "cells": [{}], "steady": true,
            "spec": {{"velocity_m_s": {speeds:?}, "grain": {{"diameter_m": {sizes:?}}},
                      "spacing_m": 16e-6, "material": "aisi304"}}}}"#,
        cells.join(",")
    );
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

fn grit(args: &[&str]) -> Output {
    Command::new(GRIT).args(args).output().unwrap()
}

fn ok(out: Output) -> String {
    assert!(
        out.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn fails_with_2(out: Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(needle), "wanted `{needle}` in: {err}");
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// `NAME = value` or `"NAME": value,` in a text export.
fn number(text: &str, name: &str) -> f64 {
    for line in text.lines() {
        let l = line.trim().trim_start_matches('"');
        if let Some(rest) = l.strip_prefix(name) {
            let rest = rest.trim_start_matches('"').trim_start();
            let rest = rest.trim_start_matches(['=', ':']).trim_start();
            let end = rest.find([',', ';', ' ']).unwrap_or(rest.len());
            if let Ok(v) = rest[..end].parse() {
                return v;
            }
        }
    }
    panic!("no {name} in:\n{text}")
}

fn list(text: &str, name: &str) -> Vec<f64> {
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!("{name} = [")))
        .unwrap_or_else(|| panic!("no {name} list"));
    let inner = line.split_once('[').unwrap().1.trim_end_matches(']');
    inner
        .split(',')
        .map(|x| x.trim().parse().unwrap())
        .collect()
}

fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let k = xs.windows(2).position(|w| w[0] <= x && x <= w[1]).unwrap();
    let t = (x - xs[k]) / (xs[k + 1] - xs[k]);
    ys[k] + t * (ys[k + 1] - ys[k])
}

fn g(s: f64, hv: f64, n1: f64, n2: f64) -> f64 {
    s.powf(n1) * (1.0 + hv * (1.0 - s)).powf(n2)
}

#[test]
fn every_format_reevaluates_to_grit_fit_eval() {
    let dir = tempfile::tempdir().unwrap();
    let v = results(
        dir.path(),
        "v.json",
        &[50.0, 100.0, 150.0],
        &[250e-6],
        false,
    );
    let d = results(dir.path(), "d.json", &[100.0], &[150e-6, 400e-6], false);
    let fit = dir.path().join("fit.json");
    let fit_s = fit.display().to_string();
    // Points on the Fluent tables' nodes: whole degrees, and a diameter read from the table.
    let generic_probe = ok(grit(&["fit", &v, &d, "-o", &fit_s]));
    assert!(generic_probe.contains("| k2 |"), "{generic_probe}");
    let generic = ok(grit(&["export", &fit_s, "--format", "fluent-generic"]));
    let nodes_d = list(&generic, "DIAMETER_M");
    let points = [
        (30.0, 80.0, nodes_d[10]),
        (45.0, 100.0, nodes_d[16]),
        (72.0, 140.0, nodes_d[20]),
    ];
    let evals: Vec<String> = points
        .iter()
        .map(|(a, v, d)| format!("{a},{v},{d:e}"))
        .collect();
    let mut args = vec!["fit", &v, &d, "--json"];
    for e in &evals {
        args.extend(["--eval", e]);
    }
    let doc: Value = serde_json::from_str(&ok(grit(&args))).unwrap();
    let expected: Vec<f64> = doc["evaluations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["erosion"].as_f64().unwrap())
        .collect();
    assert_eq!(expected.len(), 3);
    // The fit is close to the truth the cells were made from (the cells wobble by ±3 %).
    for (&(a, vv, dd), e) in points.iter().zip(&expected) {
        assert!(
            rel(*e, truth(a, vv, dd)) < 0.05,
            "{e} vs {}",
            truth(a, vv, dd)
        );
    }

    // fluent-generic: C(d) f(α) v^b from the tables.
    let (f_a, f) = (list(&generic, "ANGLE_DEG"), list(&generic, "F"));
    let c = list(&generic, "C");
    let b = number(&generic, "B");
    for (&(a, vv, dd), e) in points.iter().zip(&expected) {
        let got = interp(&nodes_d, &c, dd) * interp(&f_a, &f, a) * vv.powf(b);
        assert!(rel(got, *e) < 1e-9, "fluent-generic {got} vs {e}");
    }
    assert!(generic.contains("WARNING: the level"));

    // fluent-oka: Fluent's Oka formula with its named constants.
    let oka = ok(grit(&["export", &fit_s, "--format", "fluent-oka"]));
    let p = |n: &str| number(&oka, n);
    for (&(a, vv, dd), e) in points.iter().zip(&expected) {
        let s = a.to_radians().sin();
        let got = p("reference_erosion_rate_e90")
            * g(
                s,
                p("wall_vickers_hardness_hv"),
                p("model_constant_n1"),
                p("model_constant_n2"),
            )
            * (vv / p("reference_velocity_vref")).powf(p("velocity_exponent_k2"))
            * (dd / p("reference_diameter_dref")).powf(p("diameter_exponent_k3"));
        assert!(rel(got, *e) < 1e-9, "fluent-oka {got} vs {e}");
    }

    // edem: volume per kg of particles times the wall density, D in mm.
    let edem_out = dir.path().join("edem.txt");
    ok(grit(&[
        "export",
        &fit_s,
        "--format",
        "edem",
        "-o",
        &edem_out.display().to_string(),
    ]));
    let edem = std::fs::read_to_string(&edem_out).unwrap();
    let p = |n: &str| number(&edem, n);
    for (&(a, vv, dd), e) in points.iter().zip(&expected) {
        let s = a.to_radians().sin();
        let got = p("e90_mm3_per_kg")
            * 1e-9
            * p("wall_density_kg_m3")
            * g(s, p("vickers_hardness_gpa"), p("n1"), p("n2"))
            * (vv / p("reference_velocity_m_s")).powf(p("k2"))
            * (dd * 1e3 / p("reference_diameter_mm")).powf(p("k3"));
        assert!(rel(got, *e) < 1e-9, "edem {got} vs {e}");
    }

    // json: the fit document, with standard errors of every fitted parameter.
    let json: Value =
        serde_json::from_str(&ok(grit(&["export", &fit_s, "--format", "json"]))).unwrap();
    let m = &json["fit"]["model"];
    let q = |n: &str| m[n].as_f64().unwrap();
    for (&(a, vv, dd), e) in points.iter().zip(&expected) {
        let got = q("e90_ref")
            * g(a.to_radians().sin(), q("hv_gpa"), q("n1"), q("n2"))
            * (vv / q("v_ref_m_s")).powf(q("k2"))
            * (dd / q("d_ref_m")).powf(q("k3"));
        assert!(rel(got, *e) < 1e-9, "json {got} vs {e}");
    }
    for p in json["fit"]["parameters"].as_array().unwrap() {
        assert!(p["std_error"].as_f64().unwrap() > 0.0, "{p}");
    }
    assert_eq!(json["sources"].as_array().unwrap().len(), 2);
    assert!(json["level_warning"].as_str().unwrap().contains("2D"));

    // openfoam: the dictionary entry, and the C++ model compiled and run on the same points.
    let of = dir.path().join("of");
    ok(grit(&[
        "export",
        &fit_s,
        "--format",
        "openfoam",
        "-o",
        &of.display().to_string(),
        "--wall",
        "walls",
    ]));
    let entry = std::fs::read_to_string(of.join("cloudProperties.gritOkaErosion")).unwrap();
    assert!(entry.contains("type    gritOkaErosion;") && entry.contains("patches (walls);"));
    let p = |n: &str| number(&entry, n);
    let coeffs = ["E90", "Hv", "n1", "n2", "k2", "k3", "vRef", "dRef"].map(p);
    for (&(a, vv, dd), e) in points.iter().zip(&expected) {
        let s = a.to_radians().sin();
        let got = coeffs[0]
            * g(s, coeffs[1], coeffs[2], coeffs[3])
            * (vv / coeffs[6]).powf(coeffs[4])
            * (dd / coeffs[7]).powf(coeffs[5]);
        assert!(rel(got, *e) < 1e-9, "openfoam entry {got} vs {e}");
    }
    openfoam_cpp(&of, &coeffs, &points, &expected);
}

/// Compiles the exported function object against the stub headers (syntax and instantiation)
/// and runs its model on the points. Fails without g++ (scripts/test installs it): an export
/// test that passed without compiling would hide a broken function object.
fn openfoam_cpp(of: &Path, c: &[f64; 8], points: &[(f64, f64, f64)], expected: &[f64]) {
    assert!(
        Command::new("g++").arg("--version").output().is_ok(),
        "g++ not found: the OpenFOAM export cannot be compiled; scripts/test installs g++"
    );
    let src = of.join("gritOkaErosion");
    let stubs = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/openfoam-stubs");
    let check = Command::new("g++")
        .args([
            "-std=c++17",
            "-DNoRepository",
            "-fsyntax-only",
            "-Wall",
            "-Werror",
            "-I",
        ])
        .arg(&stubs)
        .arg("-I")
        .arg(&src)
        .arg(src.join("makeGritOkaErosion.C"))
        .output()
        .unwrap();
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let driver = of.join("driver.cpp");
    let mut body = String::from("#include <cstdio>\n#include \"gritOkaModel.H\"\nint main() {\n");
    body += &format!(
        "grit::OkaCoeffs c{{{:e}, {:e}, {:e}, {:e}, {:e}, {:e}, {:e}, {:e}}};\n",
        c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]
    );
    for (a, v, d) in points {
        body += &format!("std::printf(\"%.17g\\n\", grit::okaErosion(c, {a:e}, {v:e}, {d:e}));\n");
    }
    body += "}\n";
    std::fs::write(&driver, body).unwrap();
    let exe = of.join("driver");
    let build = Command::new("g++")
        .args(["-std=c++17", "-O0", "-I"])
        .arg(&src)
        .arg(&driver)
        .arg("-o")
        .arg(&exe)
        .output()
        .unwrap();
    assert!(
        build.status.success(),
        "{}",
        String::from_utf8_lossy(&build.stderr)
    );
    let run = Command::new(&exe).output().unwrap();
    let got: Vec<f64> = String::from_utf8(run.stdout)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    for (g, e) in got.iter().zip(expected) {
        assert!(rel(*g, *e) < 1e-9, "OpenFOAM C++ model {g} vs {e}");
    }
}

#[test]
fn bad_input_exits_2_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let unsteady = results(
        dir.path(),
        "u.json",
        &[50.0, 100.0, 150.0],
        &[150e-6, 250e-6],
        true,
    );
    fails_with_2(
        grit(&["fit", &unsteady]),
        "is not at steady state (slopes agree)",
    );
    ok(grit(&["fit", &unsteady, "--drop-unsteady"]));
    let one_speed = results(dir.path(), "s.json", &[100.0], &[150e-6, 250e-6], false);
    fails_with_2(
        grit(&["fit", &one_speed]),
        "k2: every cell has the same speed (100 m/s)",
    );
    let fixed = ok(grit(&["fit", &one_speed, "--fix", "k2=oka"]));
    assert!(
        fixed.contains("| k2 | 2.351951 | fixed (not fitted) |"),
        "{fixed}"
    );
    // Three angles, two speeds, one size held: four parameters from three cells.
    let few = results_of(
        dir.path(),
        "f.json",
        &[
            (30.0, 50.0, 250e-6),
            (45.0, 100.0, 250e-6),
            (90.0, 50.0, 250e-6),
        ],
        false,
    );
    fails_with_2(
        grit(&["fit", &few, "--fix", "k3=oka"]),
        "too few points: 4 steady cells (one per fitted parameter) needed, got 3",
    );
    let fit = dir.path().join("fit.json").display().to_string();
    let both = results(
        dir.path(),
        "b.json",
        &[50.0, 100.0],
        &[150e-6, 250e-6],
        false,
    );
    ok(grit(&["fit", &both, "-o", &fit]));
    fails_with_2(
        grit(&["export", &fit, "--format", "ansys"]),
        "unknown format `ansys`",
    );
    fails_with_2(
        grit(&["export", &fit, "--format", "openfoam"]),
        "give -o FOLDER",
    );
    fails_with_2(
        grit(&["export", &both, "--format", "json"]),
        "not a fit document",
    );
    fails_with_2(grit(&["fit", &both, "--eval", "95,100,2e-4"]), "(0, 90]");
}
