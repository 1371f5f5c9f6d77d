//! `grit plot` on results files writes every chart their data allow, as PNGs that decode and
//! are not blank and SVGs with text; bad input ends with a clear error, never a panic.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use grit_erosion::impact::balance::history;
use grit_erosion::models::oka::{ModifiedOkaModel, OkaModel, ShapeExponents, ShapeReference};
use grit_erosion::{
    aggregate_campaign, CellInput, Impact, ImpactOutcome, ImpactRecord, SampleInput, Shape,
    SLOPE_WINDOW,
};
use grit_sph::lcg::Lcg;

fn grit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grit"))
        .args(args)
        .output()
        .expect("run grit")
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// Runs `grit plot` on `results` into a fresh folder; returns the folder and stdout.
fn plot(results: &Path) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let out = grit(&[
        "plot",
        results.to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "grit plot failed: {}\n{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    (dir, stdout)
}

fn stems(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect()
}

/// Every PNG decodes at the chart size and its plot area holds more than a background:
/// several distinct colours. Every SVG is an SVG with text (axis labels, legend).
fn check_images(dir: &Path) -> usize {
    let mut n = 0;
    for name in stems(dir) {
        let path = dir.join(&name);
        if name.ends_with(".png") {
            let img = image::open(&path)
                .unwrap_or_else(|e| panic!("{name} does not decode: {e}"))
                .to_rgb8();
            assert_eq!(img.dimensions(), (1100, 750), "{name}");
            let mut colours = BTreeSet::new();
            for y in 100..500 {
                for x in 120..1050 {
                    colours.insert(img.get_pixel(x, y).0);
                }
            }
            assert!(
                colours.len() > 3,
                "{name}: plot area has {} colours",
                colours.len()
            );
            n += 1;
        } else if name.ends_with(".svg") {
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text.contains("<svg") && text.contains("<text"), "{name}");
            assert!(text.contains("</svg>"), "{name} is cut short");
        }
    }
    n
}

fn assert_has(files: &BTreeSet<String>, stem: &str) {
    for ext in ["png", "svg"] {
        let f = format!("{stem}.{ext}");
        assert!(files.contains(&f), "{f} missing from {files:?}");
    }
}

#[test]
fn plot_writes_every_chart_for_the_quick_results() {
    let (dir, stdout) = plot(&data("quick-results.json"));
    let files = stems(dir.path());
    for stem in [
        "mass_loss_c00_45deg_hexagon",
        "mass_loss_c01_90deg_hexagon",
        "erosion_vs_angle",
        "erosion_normalised_45deg",
        "convergence",
    ] {
        assert_has(&files, stem);
    }
    // One shape, two angles: neither Oka's fit (3 angles) nor the modified model.
    assert!(!files.contains("modified_oka.png"), "{files:?}");
    assert!(stdout.contains("no Oka fit"), "{stdout}");
    assert!(stdout.contains("no modified-Oka chart"), "{stdout}");
    assert!(stdout.contains("no one-sample-per-angle chart"), "{stdout}");
    assert_eq!(check_images(dir.path()), 5);
    assert!(stdout.contains("hexagon") && stdout.contains("2.952e-3 ± 3.413e-4"));
    assert!(stdout.contains("wrote 10 files:"), "{stdout}");
}

/// Impact `k`'s record: its grain, loss and damage added (kg/m), the grain's orientation and aim.
fn record(
    k: u32,
    grain: f64,
    loss: f64,
    damage: Option<f64>,
    orientation_rad: f64,
    aim_x_m: f64,
) -> ImpactRecord {
    ImpactRecord {
        impact: k,
        grain_mass_kg: grain,
        mass_loss_kg: loss,
        orientation_rad,
        aim_x_m,
        outcome: ImpactOutcome {
            mass_loss_kg: loss,
            removed_particles: 0,
            detached_kg: 0.0,
            detached_particles: 0,
            sim_time_s: 1e-6,
            steps: 1000,
            rebound_ratio: 0.5,
            settled: true,
            damage_added_kg: damage,
        },
    }
}

/// A results file with raw series: three shapes at six angles, 3 samples of 30 impacts,
/// eroding at the seed's modified-Oka rates with noise after 5 impacts of incubation.
fn synthetic_results() -> serde_json::Value {
    let model = ModifiedOkaModel {
        oka: OkaModel::silica(1.8, 2e-3),
        reference: ShapeReference::HEXAGON,
        exponents: ShapeExponents::SEED,
    };
    // Deterministic noise in [−1, 1].
    let mut lcg = Lcg(7);
    let mut noise = move || lcg.next_unit() * 2.0 - 1.0;
    let (mut cells, mut raw) = (Vec::new(), Vec::new());
    for shape in [Shape::Octagon, Shape::Hexagon, Shape::Square] {
        let (an, e) = shape.factors().unwrap();
        for angle in [15.0, 30.0, 45.0, 60.0, 75.0, 90.0] {
            let cell = cells.len() as u32;
            let mut samples = Vec::new();
            for sample in 0..3u32 {
                let records: Vec<ImpactRecord> = (1..=30u32)
                    .map(|k| {
                        let grain = 1.2e-4 * (1.0 + 0.05 * noise());
                        let rate = model.erosion(angle, e, an) * (1.0 + 0.5 * noise());
                        let loss = if k > 5 { grain * rate } else { 0.0 };
                        record(k, grain, loss, None, noise(), 1e-5 * noise())
                    })
                    .collect();
                samples.push(SampleInput {
                    sample,
                    impacts: records
                        .iter()
                        .map(ImpactRecord::impact)
                        .collect::<Vec<Impact>>(),
                });
                raw.push(serde_json::json!({
                    "cell": cell, "sample": sample, "seed": 100 + sample, "state": "done",
                    "impacts": records,
                }));
            }
            cells.push(CellInput {
                angle_deg: angle,
                shape: shape.name().to_string(),
                swept: Default::default(),
                planned_samples: 3,
                planned_impacts: 30,
                samples,
            });
        }
    }
    let results = aggregate_campaign(&cells, SLOPE_WINDOW).unwrap();
    let mut v = serde_json::to_value(results).unwrap();
    v["raw"] = serde_json::Value::Array(raw);
    v
}

#[test]
fn plot_draws_raw_series_oka_fits_and_the_modified_model() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("results.json");
    std::fs::write(&path, synthetic_results().to_string()).unwrap();
    let (dir, stdout) = plot(&path);
    let files = stems(dir.path());
    for stem in [
        "mass_loss_c00_15deg_octagon",
        "mass_loss_c17_90deg_square",
        "erosion_vs_angle",
        "erosion_normalised_45deg",
        "modified_oka",
        "convergence",
    ] {
        assert_has(&files, stem);
    }
    // 18 cells, 4 angle/fit charts, and per shape two single-sample-at-every-angle charts.
    assert_eq!(check_images(dir.path()), 18 + 4 + 3 * 2);
    for shape in ["octagon", "hexagon", "square"] {
        assert_has(&files, &format!("sample_by_angle_{shape}_s0"));
        assert_has(&files, &format!("sample_by_angle_{shape}_s1"));
    }
    assert!(
        !files.contains("sample_by_angle_hexagon_s2.png"),
        "{files:?}"
    );
    // Fig. 9: sample 1 of every angle of the hexagon on one axes, one legend entry each.
    let svg = std::fs::read_to_string(dir.path().join("sample_by_angle_hexagon_s1.svg")).unwrap();
    assert!(svg.contains("hexagon, sample 1"), "not named as one sample");
    for angle in [15, 30, 45, 60, 75, 90] {
        assert!(
            svg.contains(&format!("\n{angle}°\n")),
            "{angle}° curve missing"
        );
    }
    for shape in ["octagon", "hexagon", "square"] {
        assert!(
            stdout.contains(&format!("{shape}: Oka fit n1 = ")),
            "{stdout}"
        );
    }
    assert!(stdout.contains("modified Oka fit: n3"), "{stdout}");
    // The raw series are drawn: the per-sample legend names their count.
    let svg = std::fs::read_to_string(dir.path().join("mass_loss_c07_30deg_hexagon.svg")).unwrap();
    assert!(svg.contains("each sample (3)"), "raw series not drawn");
}

/// Circles of `r` pixels in `svg` drawn in `colour` (`#RRGGBB`), hollow or filled.
fn circles(svg: &str, r: u32, colour: &str, hollow: bool) -> usize {
    let paint = if hollow {
        format!(r#"fill="none" stroke="{colour}""#)
    } else {
        format!(r#"fill="{colour}" stroke="none""#)
    };
    svg.split("<circle")
        .skip(1)
        .filter(|c| c.contains(&format!(r#"r="{r}""#)) && c.contains(&paint))
        .count()
}

#[test]
fn a_steady_cell_whose_loss_does_not_pay_for_its_damage_is_drawn_hollow() {
    let mut v = synthetic_results();
    for c in v["cells"].as_array_mut().unwrap() {
        c["steady_state"]["steady"] = serde_json::Value::Bool(true);
    }
    // Cell 8 (hexagon, 45°) loses 40 % of the damage its impacts add, 15 s.e. short.
    v["cells"][8]["damage_balance"] = serde_json::json!({
        "balanced": false, "damage_rate": 5e-3, "damage_rate_sem": 1e-4, "detectable_rel": 0.1,
        "difference_sem": 2e-4, "loss_rate": 2e-3, "loss_rate_sem": 1.7e-4, "points": 20,
        "ratio": 0.4, "samples": 3
    });
    v["steady"] = serde_json::Value::Bool(true);
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("results.json");
    std::fs::write(&path, v.to_string()).unwrap();
    let (dir, stdout) = plot(&path);
    let svg = std::fs::read_to_string(dir.path().join("erosion_vs_angle.svg")).unwrap();
    assert_eq!(
        circles(&svg, 5, "#FF7F0E", true),
        1,
        "the unbalanced cell hollow"
    );
    assert!(svg.contains("hollow: not steady or not balanced"), "legend");
    assert!(svg.contains("Hollow markers: 1 of 18 cells"), "note");
    let cell = std::fs::read_to_string(dir.path().join("mass_loss_c08_45deg_hexagon.svg")).unwrap();
    assert_eq!(
        circles(&cell, 3, "#000000", true),
        21,
        "window marks hollow"
    );
    assert!(cell.contains("Not balanced (docs/erosion.md, The damage balance)"));
    assert!(stdout.contains("(steady, not balanced)"), "{stdout}");
}

#[test]
fn unsteady_cells_are_drawn_hollow_with_a_note() {
    let mut v = synthetic_results();
    // Every cell steady but the hexagon's at 45° (cell 8), whatever the noise made of them.
    for (i, c) in v["cells"].as_array_mut().unwrap().iter_mut().enumerate() {
        c["steady_state"]["steady"] = serde_json::Value::Bool(i != 8);
    }
    assert_eq!(v["cells"][8]["shape"], "hexagon");
    assert_eq!(v["cells"][8]["angle_deg"], 45.0);
    v["cells"][8]["steady_state"]["reason"] = "only 1 of 3 samples lost mass by impact 11".into();
    v["steady"] = serde_json::Value::Bool(false);
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("results.json");
    std::fs::write(&path, v.to_string()).unwrap();
    let (dir, stdout) = plot(&path);
    let hexagon = "#FF7F0E";
    // The modified-Oka chart's legend key is a filled circle of the same size.
    for (chart, filled) in [
        ("erosion_vs_angle", 5),
        ("erosion_normalised_45deg", 5),
        ("modified_oka", 6),
    ] {
        let svg = std::fs::read_to_string(dir.path().join(format!("{chart}.svg"))).unwrap();
        assert_eq!(
            circles(&svg, 5, hexagon, true),
            1,
            "{chart}: one hollow cell"
        );
        assert_eq!(
            circles(&svg, 5, hexagon, false),
            filled,
            "{chart}: the others filled"
        );
        assert!(
            svg.contains("hollow: not steady or not balanced"),
            "{chart}: legend"
        );
        assert!(
            svg.contains("Hollow markers: 1 of 18 cells"),
            "{chart}: note"
        );
    }
    // Convergence: the cell's running mean at 1, 2, 3 samples, all hollow.
    let svg = std::fs::read_to_string(dir.path().join("convergence.svg")).unwrap();
    assert!(svg.contains("Hollow markers: 1 of 18 cells"));
    assert!(
        svg.split("<circle")
            .filter(|c| c.contains("fill=\"none\""))
            .count()
            >= 3
    );
    // The cell's own chart: window marks (and their legend key) hollow, the reason under it.
    let svg = std::fs::read_to_string(dir.path().join("mass_loss_c08_45deg_hexagon.svg")).unwrap();
    assert_eq!(circles(&svg, 3, "#000000", true), 21);
    assert!(svg.contains("Not at steady state (docs/erosion.md): only 1 of 3 samples"));
    let steady =
        std::fs::read_to_string(dir.path().join("mass_loss_c07_30deg_hexagon.svg")).unwrap();
    assert_eq!(circles(&steady, 3, "#000000", false), 21);
    assert!(stdout.contains("(not at steady state)"), "{stdout}");
    assert!(stdout.contains("Hollow markers: 1 of 18 cells"), "{stdout}");
    check_images(dir.path());
}

/// A two-cell results file whose raw series carry the damage each impact added: 4 samples of
/// 100 impacts adding 4 mg/g of damage per impact while their loss climbs from 0 to 4 mg/g over
/// the first 60 impacts (with ±20 % noise) and stays there.
fn balance_results() -> (serde_json::Value, Vec<Vec<SampleInput>>) {
    let mut lcg = Lcg(11);
    let mut noise = move || lcg.next_unit() * 2.0 - 1.0;
    let (mut cells, mut raw, mut inputs) = (Vec::new(), Vec::new(), Vec::new());
    for (cell, angle) in [45.0, 90.0].into_iter().enumerate() {
        let mut samples = Vec::new();
        for sample in 0..4u32 {
            let records: Vec<ImpactRecord> = (1..=100u32)
                .map(|k| {
                    let grain = 1.2e-4;
                    let rate = 4e-3 * (k as f64 / 60.0).min(1.0) * (1.0 + 0.2 * noise());
                    let damage = 4e-3 * grain * (1.0 + 0.05 * noise());
                    record(k, grain, grain * rate, Some(damage), 0.0, 0.0)
                })
                .collect();
            samples.push(SampleInput {
                sample,
                impacts: records.iter().map(ImpactRecord::impact).collect(),
            });
            raw.push(serde_json::json!({
                "cell": cell, "sample": sample, "seed": sample, "state": "done",
                "impacts": records,
            }));
        }
        inputs.push(samples.clone());
        cells.push(CellInput {
            angle_deg: angle,
            shape: "hexagon".to_string(),
            swept: Default::default(),
            planned_samples: 4,
            planned_impacts: 100,
            samples,
        });
    }
    let mut v = serde_json::to_value(aggregate_campaign(&cells, SLOPE_WINDOW).unwrap()).unwrap();
    v["raw"] = serde_json::Value::Array(raw);
    (v, inputs)
}

#[test]
fn plot_draws_each_cells_approach_to_its_damage_balance() {
    let (v, inputs) = balance_results();
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("results.json");
    std::fs::write(&path, v.to_string()).unwrap();
    let (dir, stdout) = plot(&path);
    let files = stems(dir.path());
    assert_has(&files, "damage_balance_c00_45deg_hexagon");
    assert_has(&files, "damage_balance_c01_90deg_hexagon");
    check_images(dir.path());
    for (i, name) in ["c00_45deg", "c01_90deg"].iter().enumerate() {
        let svg = std::fs::read_to_string(
            dir.path()
                .join(format!("damage_balance_{name}_hexagon.svg")),
        )
        .unwrap();
        // One loss marker per window, filled exactly where the window is balanced.
        let h = history(&inputs[i].iter().collect::<Vec<_>>());
        assert_eq!(h.len(), 5);
        let balanced = h.iter().filter(|w| w.balance.balanced).count();
        // The loss climbs for 60 impacts: the first windows are short of the floor.
        assert!(!h[0].balance.balanced && !h[1].balance.balanced, "{h:?}");
        assert!(balanced >= 1, "{h:?}");
        assert_eq!(circles(&svg, 4, "#1F77B4", false), balanced, "{name}");
        assert_eq!(circles(&svg, 4, "#1F77B4", true), 5 - balanced, "{name}");
        assert!(svg.contains("the balance"), "{name}: floor's legend");
        assert!(
            svg.contains("4 samples in every window"),
            "{name}: samples note"
        );
    }
    // A file without damage in its records says why it has no such chart.
    let (_dir, stdout_quick) = plot(&data("quick-raw-results.json"));
    assert!(
        stdout_quick.contains("no damage-balance chart"),
        "{stdout_quick}"
    );
    assert!(!stdout.contains("no damage-balance chart"), "{stdout}");
}

#[test]
fn plot_draws_the_committed_raw_results() {
    let (dir, stdout) = plot(&data("quick-raw-results.json"));
    let files = stems(dir.path());
    assert_has(&files, "mass_loss_c00_45deg_hexagon");
    assert_has(&files, "erosion_vs_angle");
    assert!(check_images(dir.path()) >= 4, "{stdout}");
    let svg = std::fs::read_to_string(dir.path().join("mass_loss_c00_45deg_hexagon.svg")).unwrap();
    assert!(svg.contains("each sample (2)"), "raw series not drawn");
    assert_has(&files, "sample_by_angle_hexagon_s0");
}

#[test]
fn plot_rejects_bad_input_with_a_clear_error() {
    let tmp = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let p = tmp.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let cases = [
        (tmp.path().join("absent.json"), "absent.json"),
        (write("broken.json", "{\"cells\": [ {"), "not valid JSON"),
        (
            write("other.json", "{\"name\": \"quick\"}"),
            "no `cells` array",
        ),
        (write("empty.json", "{\"cells\": []}"), "`cells` is empty"),
        (
            write("cell.json", "{\"cells\": [{\"shape\": 3}]}"),
            "not a results file",
        ),
    ];
    for (path, expected) in cases {
        let out = grit(&[
            "plot",
            path.to_str().unwrap(),
            "--out",
            tmp.path().to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{} succeeded", path.display());
        assert!(
            stderr.starts_with("error: ") && stderr.contains(expected),
            "{}: {stderr}",
            path.display()
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

#[test]
fn compare_prints_the_reference_tables_and_refuses_a_bad_file() {
    let reduced = data("reduced-2026-11-21-results.json");
    let out = grit(&["compare", reduced.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    // Oka's g(90°)/g(45°) at Hv 1.8 with silica exponents is 0.73 (docs/references.md).
    assert!(
        stdout.contains("| hexagon | 90° | 1.10 ± 0.37 | 0.43 ± 0.15 | 0.73 |"),
        "{stdout}"
    );
    let out = grit(&["compare", reduced.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["angles"].as_array().unwrap().len(), 6);
    let out = grit(&["compare", "no-such-results.json"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no-such-results.json"));
}

#[test]
fn a_fit_document_is_drawn_as_its_model_through_its_cells() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // Four speeds and three angles: both charts.
    let (dir, stdout) = plot(&root.join("docs/erosion/velocity-quick/fit.json"));
    let files = stems(dir.path());
    assert_has(&files, "fit_speed");
    assert_has(&files, "fit_angle");
    assert_eq!(check_images(dir.path()), 2, "{stdout}");
    // One speed: the speed chart is skipped, and says why.
    let (dir, stdout) = plot(&root.join("docs/erosion/size-quick/fit.json"));
    let files = stems(dir.path());
    assert_has(&files, "fit_angle");
    assert!(!files.contains("fit_speed.png"), "{files:?}");
    assert!(
        stdout.contains("fit_speed: the cells have one value of its axis"),
        "{stdout}"
    );
}

#[test]
fn the_resolution_ladder_places_each_file_by_its_spacing_and_judges_steadiness_now() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // `grit plot --resolution` on committed files into `out`; its stdout, the ladder's table.
    let ladder = |files: &[&str], out: &Path| {
        let mut args = vec!["plot".to_string(), "--resolution".into()];
        args.extend(
            files
                .iter()
                .map(|f| root.join(f).to_str().unwrap().to_string()),
        );
        args.extend(["--out".into(), out.to_str().unwrap().to_string()]);
        let out = grit(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(out.status.success(), "{stdout}");
        stdout
    };
    let dir = tempfile::tempdir().unwrap();
    let stdout = ladder(
        &[
            "docs/erosion/resolution/ppd16-seed-results.json",
            "docs/erosion/resolution24-results.json",
        ],
        dir.path(),
    );
    // The 16 rung's 45° cell passed the rule it ran under and fails the three-window rule.
    assert!(
        stdout.contains("| 45° hexagon | 16.0 | 15.62 | 30 × 160 | 1.60 ± 0.20 | **unsteady** |"),
        "{stdout}"
    );
    assert!(
        stdout.contains("| 90° hexagon | 24.0 | 10.42 | 10 × 100 | 3.11 ± 0.25 |"),
        "{stdout}"
    );
    assert_has(&stems(dir.path()), "erosion_vs_resolution");
    let svg = std::fs::read_to_string(dir.path().join("erosion_vs_resolution.svg")).unwrap();
    assert_eq!(
        circles(&svg, 5, "#1F77B4", true),
        2,
        "both 45° cells hollow"
    );
    // Steady is not stationary: the 16 rung capped at 400 impacts is steady by the three
    // windows, yet its loss is 78 % of the damage added, so both its points are hollow.
    let capped = tempfile::tempdir().unwrap();
    let stdout = ladder(
        &["docs/erosion/resolution/ppd16-balanced-results.json"],
        capped.path(),
    );
    assert!(
        stdout.contains(
            "| 45° hexagon | 16.0 | 15.62 | 15 × 260 | 3.02 ± 0.51 | steady, **unbalanced** |"
        ),
        "{stdout}"
    );
    let svg = std::fs::read_to_string(capped.path().join("erosion_vs_resolution.svg")).unwrap();
    assert_eq!(circles(&svg, 5, "#1F77B4", true), 1, "the 45° cell hollow");
    assert_eq!(circles(&svg, 5, "#1F77B4", false), 0, "no 45° cell filled");
    assert!(svg.contains("2 steady, not balanced"), "the note says why");
    // A file without a spacing in its spec is refused by name.
    let quick = data("quick-results.json");
    let bad = grit(&["plot", "--resolution", quick.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success());
    assert!(
        stderr.contains("quick-results.json") && stderr.contains("spacing_m"),
        "{stderr}"
    );
}
