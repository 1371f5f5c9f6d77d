//! The steady-state check (seed paper section 4): incubating, steady and accelerating cells,
//! slopes and standard errors against hand-computed values, and older results files.
use std::collections::BTreeMap;

use grit_erosion::impact::aggregate::{aggregate_campaign, aggregate_cell, CellInput, SampleInput};
use grit_erosion::impact::steady::{reassess, Incubation, STEADY_POINTS};
use grit_erosion::stats::{slope_fit, SlopeFit};
use grit_erosion::{CampaignResults, Impact, SLOPE_WINDOW};
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

const GRAIN_KG: f64 = 1.2e-4;

/// A sample whose impact k (0-based) loses `loss(k)` × grain mass.
fn sample(index: u32, n: usize, loss: impl Fn(usize) -> f64) -> SampleInput {
    SampleInput {
        sample: index,
        impacts: (0..n)
            .map(|k| Impact {
                grain_mass_kg: GRAIN_KG,
                mass_loss_kg: loss(k) * GRAIN_KG,
                damage_added_kg: None,
            })
            .collect(),
    }
}

fn cell(impacts: usize, samples: Vec<SampleInput>) -> CellInput {
    CellInput {
        angle_deg: 45.0,
        shape: "hexagon".into(),
        swept: BTreeMap::new(),
        planned_samples: samples.len(),
        planned_impacts: impacts,
        samples,
    }
}

/// Rise of the rate per impact, relative, of the slow-rise test.
const RISE: f64 = 0.0016;

/// Deterministic scatter in [-1, 1] that differs between samples and impacts.
fn wiggle(s: u32, k: usize) -> f64 {
    (1.7 * k as f64 + 2.3 * s as f64).sin()
}

/// Five samples of 70 impacts: first loss at impacts 5..=9, then `rate(k)` with ±60 % scatter.
fn noisy_cell(rate: impl Fn(usize) -> f64) -> CellInput {
    let samples = (0..5u32)
        .map(|s| {
            let start = 4 + s as usize;
            sample(s, 70, |k| {
                if k < start {
                    0.0
                } else {
                    rate(k) * (1.0 + 0.6 * wiggle(s, k))
                }
            })
        })
        .collect();
    cell(70, samples)
}

#[test]
fn a_cell_still_in_incubation_is_not_steady() {
    // No loss until impacts 64..=68 of 70: the compared 40 impacts (from 31) are incubation.
    let samples = (0..5u32)
        .map(|s| {
            let start = 63 + s as usize;
            sample(s, 70, move |k| if k < start { 0.0 } else { 3e-3 })
        })
        .collect();
    let r = aggregate_cell(&cell(70, samples), SLOPE_WINDOW).unwrap();
    let s = r.steady_state.unwrap();
    assert!(!s.steady, "{}", s.reason);
    let inc = s.incubation_impacts.unwrap();
    assert_eq!((inc.min, inc.max, inc.mean), (64, 68, 66.0));
    assert_eq!(s.window_first_impact, Some(31));
    assert_eq!(
        (s.samples_incubated_by_window, s.samples_without_loss),
        (0, 0)
    );
    assert!(
        s.reason
            .contains("only 0 of 5 samples lost mass by impact 31"),
        "{}",
        s.reason
    );
    assert_eq!(s.slope_prev.unwrap().value, 0.0);
}

#[test]
fn a_linear_cell_with_scatter_after_early_incubation_is_steady() {
    let r = aggregate_cell(&noisy_cell(|_| 2e-3), SLOPE_WINDOW).unwrap();
    let s = r.steady_state.unwrap();
    assert!(s.steady, "{}", s.reason);
    let inc = s.incubation_impacts.unwrap();
    assert_eq!((inc.min, inc.max), (5, 9));
    assert_eq!(s.samples_incubated_by_window, 5);
    let (last, prev) = (s.slope_last.unwrap(), s.slope_prev.unwrap());
    assert!(last.sem > 0.0 && prev.sem > 0.0);
    for f in [last, prev] {
        assert!((f.value - 2e-3).abs() < 3.0 * f.sem, "{f:?}");
    }
    assert!(
        s.reason.contains("combined standard errors"),
        "{}",
        s.reason
    );
}

#[test]
fn a_rate_that_doubles_in_the_last_twenty_is_not_steady() {
    let r = aggregate_cell(
        &noisy_cell(|k| if k >= 50 { 4e-3 } else { 2e-3 }),
        SLOPE_WINDOW,
    )
    .unwrap();
    let s = r.steady_state.unwrap();
    assert!(!s.steady);
    assert!(s.reason.contains("at most 2 allowed"), "{}", s.reason);
    // Incubation is long over: the slopes alone break the rule.
    assert_eq!(s.samples_incubated_by_window, 5);
    assert!(s.slope_last.unwrap().value > 1.5 * s.slope_prev.unwrap().value);
}

#[test]
fn a_peak_after_incubation_is_not_steady() {
    // The rate doubles at impact 31 and holds: the last two windows (31-50, 51-70) agree with
    // each other, as two windows of a peak do, and the third (11-30) shows the rise.
    let r = aggregate_cell(
        &noisy_cell(|k| if k >= 30 { 4e-3 } else { 2e-3 }),
        SLOPE_WINDOW,
    )
    .unwrap();
    let s = r.steady_state.unwrap();
    assert!(!s.steady, "{}", s.reason);
    assert!(
        s.reason
            .contains("that previous slope against the 20 before's"),
        "{}",
        s.reason
    );
    let (last, prev, before) = (
        s.slope_last.unwrap(),
        s.slope_prev.unwrap(),
        s.slope_before.unwrap(),
    );
    assert!((last.value - prev.value).abs() <= 2.0 * last.sem.hypot(prev.sem));
    assert!(prev.value > 1.5 * before.value, "{prev:?} {before:?}");
}

#[test]
fn a_slow_rise_that_every_adjacent_pair_passes_is_not_steady() {
    // The rate climbs a little each window: no two neighbours differ by 2 combined standard
    // errors, the ends do (the seed's campaign at 45°: 2.97, 3.33, 3.70 mg/g).
    let r = aggregate_cell(
        &noisy_cell(|k| 2e-3 * (1.0 + RISE * k as f64)),
        SLOPE_WINDOW,
    )
    .unwrap();
    let s = r.steady_state.unwrap();
    let (last, prev, before) = (
        s.slope_last.unwrap(),
        s.slope_prev.unwrap(),
        s.slope_before.unwrap(),
    );
    let z = |a: SlopeFit, b: SlopeFit| (a.value - b.value).abs() / a.sem.hypot(b.sem);
    assert!(z(last, prev) < 2.0 && z(prev, before) < 2.0, "{}", s.reason);
    assert!(z(last, before) > 2.0);
    assert!(!s.steady);
    assert!(
        s.reason.contains("a trend across the three"),
        "{}",
        s.reason
    );
}

#[test]
fn a_cell_with_no_loss_in_its_last_twenty_is_not_steady() {
    let samples = vec![sample(0, 60, |k| if k < 35 { 2e-3 } else { 0.0 })];
    let s = aggregate_cell(&cell(60, samples), SLOPE_WINDOW)
        .unwrap()
        .steady_state
        .unwrap();
    assert!(!s.steady);
    assert!(
        s.reason.contains("no mass lost in the last 20"),
        "{}",
        s.reason
    );
}

#[test]
fn too_short_or_lossless_or_ragged_cells_say_why() {
    let short = aggregate_cell(&cell(59, vec![sample(0, 59, |_| 1e-3)]), SLOPE_WINDOW).unwrap();
    let s = short.steady_state.unwrap();
    assert!(!s.steady && s.slope_before.is_none() && s.window_first_impact.is_none());
    assert!(s.slope_last.is_some() && s.slope_prev.is_some());
    assert!(
        s.reason
            .contains("only 59 impacts; 3 20-impact slopes need 60"),
        "{}",
        s.reason
    );

    let lossless = aggregate_cell(&cell(30, vec![sample(0, 30, |_| 0.0)]), SLOPE_WINDOW).unwrap();
    let s = lossless.steady_state.unwrap();
    assert!(!s.steady);
    assert_eq!((s.incubation_impacts, s.samples_without_loss), (None, 1));

    // One of two samples has 45 of 60 impacts: the window's mean changes samples midway.
    let ragged = cell(60, vec![sample(0, 60, |_| 1e-3), sample(1, 45, |_| 1e-3)]);
    let s = aggregate_cell(&ragged, SLOPE_WINDOW)
        .unwrap()
        .steady_state
        .unwrap();
    assert!(!s.steady);
    assert!(s.reason.contains("average 1 to 2 samples"), "{}", s.reason);

    let empty = aggregate_cell(&cell(30, vec![]), SLOPE_WINDOW).unwrap();
    assert!(!empty.steady_state.unwrap().steady);
}

#[test]
fn eighty_percent_of_samples_must_be_past_incubation() {
    // Samples 0-3 lose from impact 2 on; sample 4 from `late` on (1-based impact late + 1).
    let with_late = |late: usize| {
        let mut samples: Vec<SampleInput> = (0..4u32)
            .map(|s| sample(s, 70, |k| if k < 1 { 0.0 } else { 2e-3 }))
            .collect();
        samples.push(sample(4, 70, move |k| if k < late { 0.0 } else { 2e-3 }));
        aggregate_cell(&cell(70, samples), SLOPE_WINDOW)
            .unwrap()
            .steady_state
            .unwrap()
    };
    // Four of five (80 %) incubated by impact 31 suffices, even when the fifth never loses.
    let s = with_late(70);
    assert_eq!(
        (s.samples_incubated_by_window, s.samples_without_loss),
        (4, 1)
    );
    assert!(s.steady, "{}", s.reason);
    // Three of five is too few, though the slopes agree.
    let mut samples: Vec<SampleInput> = (0..3u32)
        .map(|s| sample(s, 70, |k| if k < 1 { 0.0 } else { 2e-3 }))
        .collect();
    samples.extend((3..5u32).map(|s| sample(s, 70, |_| 0.0)));
    let s = aggregate_cell(&cell(70, samples), SLOPE_WINDOW)
        .unwrap()
        .steady_state
        .unwrap();
    assert!(!s.steady);
    assert!(s.reason.starts_with("only 3 of 5 samples"), "{}", s.reason);
    // The late sample's start shows in the slopes unless it falls before the three windows.
    let s = with_late(10);
    assert_eq!(
        s.samples_incubated_by_window, 5,
        "first loss at 11 is at the first window's start"
    );
    assert!(s.steady, "{}", s.reason);
    // At the start of the last two windows it counts as incubated, but the window before them
    // lacks its loss: the third window sees what the incubation share lets through.
    let s = with_late(30);
    assert_eq!(s.samples_incubated_by_window, 5);
    assert!(!s.steady, "{}", s.reason);
    assert!(s.reason.contains("that previous slope"), "{}", s.reason);
    // Later, its start raises the last slope by a quarter with no scatter to hide it.
    let s = with_late(50);
    assert_eq!(s.samples_incubated_by_window, 4);
    assert!(!s.steady, "{}", s.reason);
}

#[test]
fn slope_and_standard_error_match_hand_values() {
    // x = 1..4, y = 0, 1, 1, 3: x̄ = 2.5, Sxx = 5, Sxy = 4.5, so b = 0.9. The weights of the
    // increments (1, 0, 2) are 1.5/5, 2/5, 1.5/5 (Σw² = 0.34); their residuals 0.1, −0.9, 1.1
    // give σ² = 2.03/2, so se² = 1.015 × 0.34.
    let f = slope_fit(&[1.0, 2.0, 3.0, 4.0], &[0.0, 1.0, 1.0, 3.0]).unwrap();
    assert!((f.value - 0.9).abs() < 1e-12, "{f:?}");
    assert!((f.sem - (1.015f64 * 0.34).sqrt()).abs() < 1e-12, "{f:?}");
    assert!(slope_fit(&[1.0, 2.0], &[0.0, 1.0]).is_none());
    assert!(slope_fit(&[1.0, 1.0, 1.0], &[0.0, 1.0, 2.0]).is_none());

    // Through the cell: 40 impacts of one sample. The last 20 lose 1 grain-unit each except
    // impact 36, which loses 3; the 20 before lose 0.5 each. The cell's slopes are the
    // hand-checked fit above over the mean series' two halves.
    let g = 1e-3;
    let one = sample(0, 40, |k| match k {
        35 => 3.0 * g,
        20..=39 => g,
        _ => 0.5 * g,
    });
    let r = aggregate_cell(&cell(40, vec![one]), SLOPE_WINDOW).unwrap();
    let s = r.steady_state.clone().unwrap();
    let x: Vec<f64> = r.mean_series.iter().map(|p| p.grain_mass_kg).collect();
    let y: Vec<f64> = r.mean_series.iter().map(|p| p.mass_loss_kg).collect();
    assert_eq!(s.slope_last, slope_fit(&x[20..], &y[20..]));
    let last = s.slope_last.unwrap();
    assert!(last.value > g && last.sem > 0.0, "{last:?}");
    let prev = s.slope_prev.unwrap();
    assert!(
        (prev.value / g - 0.5).abs() < 1e-9 && prev.sem / g < 1e-9,
        "{prev:?}"
    );
    let sees = s.detectable_change_rel.unwrap();
    assert!((sees - 2.0 * last.sem.hypot(prev.sem) / last.value).abs() < 1e-12);
    assert_eq!(STEADY_POINTS, 20);
}

#[test]
fn the_standard_error_matches_the_scatter_of_slopes() {
    // 4000 series of 10 impacts, each losing one unit with probability 0.2 (a failing
    // particle): the rms standard error must match the spread of the fitted slopes. The
    // residual-based textbook error would come out about 3.5 times too small here.
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let x: Vec<f64> = (1..=10).map(f64::from).collect();
    let (mut slopes, mut se2) = (Vec::new(), 0.0);
    for _ in 0..4000 {
        let mut acc = 0.0;
        let y: Vec<f64> = (0..10)
            .map(|_| {
                if rng.next_u32() < u32::MAX / 5 {
                    acc += 1.0;
                }
                acc
            })
            .collect();
        let f = slope_fit(&x, &y).unwrap();
        slopes.push(f.value);
        se2 += f.sem * f.sem;
    }
    let n = slopes.len() as f64;
    let mean = slopes.iter().sum::<f64>() / n;
    let sd = (slopes.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let rms_se = (se2 / n).sqrt();
    assert!(
        (rms_se / sd - 1.0).abs() < 0.1,
        "rms se {rms_se} vs sd {sd}"
    );
}

#[test]
fn campaign_carries_steadiness_spec_and_version() {
    let cells = [
        noisy_cell(|_| 2e-3),
        noisy_cell(|k| if k >= 50 { 4e-3 } else { 2e-3 }),
    ];
    let r = aggregate_campaign(&cells, SLOPE_WINDOW)
        .unwrap()
        .with_spec(serde_json::json!({"samples": 5}));
    assert_eq!(r.steady, Some(false));
    assert_eq!(r.grit_version.as_deref(), Some(env!("CARGO_PKG_VERSION")));
    let warnings = r.unsteady_warnings();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].starts_with("warning: cell 45° hexagon is not at steady state: last-20"));
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["spec"]["samples"], 5);
    assert_eq!(json["cells"][0]["steady_state"]["steady"], true);
    let back: CampaignResults = serde_json::from_value(json).unwrap();
    assert_eq!(back, r);
    let steady_only = aggregate_campaign(&cells[..1], SLOPE_WINDOW).unwrap();
    assert_eq!(steady_only.steady, Some(true));
    assert!(steady_only.unsteady_warnings().is_empty());
    assert!(steady_only.spec.is_none());
}

#[test]
fn older_results_files_still_load() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    for file in [
        "tests/data/quick-results.json",
        "tests/data/quick-raw-results.json",
        "docs/erosion/reduced-5samples-results.json",
    ] {
        let text = std::fs::read_to_string(format!("{root}/{file}")).unwrap();
        let r: CampaignResults = serde_json::from_str(&text).unwrap();
        assert_eq!((r.steady, r.grit_version.as_ref()), (None, None), "{file}");
        assert!(r.cells.iter().all(|c| c.steady_state.is_none()), "{file}");
        let warnings = r.unsteady_warnings();
        assert_eq!(warnings.len(), r.cells.len(), "{file}");
        assert!(
            warnings[0].contains("steady state not checked"),
            "{warnings:?}"
        );
    }
}

#[test]
fn a_results_file_is_checked_again_under_the_current_rule() {
    let r = aggregate_cell(&noisy_cell(|_| 2e-3), SLOPE_WINDOW).unwrap();
    let again = reassess(&r).unwrap();
    assert!(again.incubation_known);
    assert_eq!(Some(&again.state), r.steady_state.as_ref());
    assert_eq!(again.steady(), Some(true));

    // A file written before the first losses were stored keeps only their range: 5–9 lies
    // before the window's start (31), so the check is still complete.
    let mut old = r.clone();
    old.steady_state
        .as_mut()
        .unwrap()
        .first_loss_impacts
        .clear();
    let again = reassess(&old).unwrap();
    assert!(
        again.incubation_known && again.state.steady,
        "{}",
        again.state.reason
    );
    // A last loss past the start leaves the incubation open; a failed slope still settles it.
    old.steady_state.as_mut().unwrap().incubation_impacts = Some(Incubation {
        min: 5,
        mean: 20.0,
        max: 45,
    });
    let again = reassess(&old).unwrap();
    assert_eq!(again.steady(), None, "{}", again.state.reason);
    let rising = aggregate_cell(
        &noisy_cell(|k| if k >= 50 { 4e-3 } else { 2e-3 }),
        SLOPE_WINDOW,
    )
    .unwrap();
    let mut old = rising;
    let st = old.steady_state.as_mut().unwrap();
    st.first_loss_impacts.clear();
    st.incubation_impacts = Some(Incubation {
        min: 5,
        mean: 20.0,
        max: 45,
    });
    assert_eq!(reassess(&old).unwrap().steady(), Some(false));
}
