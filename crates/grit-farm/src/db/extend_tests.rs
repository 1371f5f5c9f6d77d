//! Cells that grow with their results, driven through the store with fabricated impacts (no
//! physics): extension by `step`, the stop at `max`, samples added for the error bar.

use std::path::Path;
use std::time::Duration;

use grit_erosion::campaign::{job_seed, AnySpec, CampaignSpec};
use grit_erosion::ImpactRecord;
use sqlx::Row;
use uuid::Uuid;

use super::{imp, impact_params, impact_results, Store};
use crate::api::{CampaignState, ClaimedJob, RaisedCell};
use crate::checkpoint::CheckpointBytes;
use crate::loadtest::placeholder_record;

async fn store(dir: &Path) -> Store {
    Store::open(&dir.join("t.db"), Duration::from_secs(60), 2)
        .await
        .unwrap()
}

/// The cells 90° and 45° of one shape, with `fields` added to the spec.
fn two_cells(fields: &str) -> CampaignSpec {
    CampaignSpec::from_json(&format!(
        r#"{{"seed": 5, "angles_deg": [90, 45], "shapes": ["hexagon"], "spacing_m": 25e-6,
            {fields}}}"#
    ))
    .unwrap()
}

/// Runs the next `n` jobs as claimed, each losing `loss(sample, k)`: their (cell, sample,
/// impacts planned) in claim order.
async fn claim_order(s: &Store, n: usize, loss: impl Fn(u32, u32) -> f64) -> Vec<(u32, u32, u32)> {
    let mut claimed = Vec::new();
    for _ in 0..n {
        let j = run_one(s, &loss).await;
        claimed.push((j.cell, j.sample, j.impacts_planned));
    }
    claimed
}

fn spec(impacts: &str, samples: &str) -> CampaignSpec {
    CampaignSpec::from_json(&format!(
        r#"{{"seed": 5, "angles_deg": [90], "shapes": ["hexagon"], "spacing_m": 25e-6,
            "impacts": {impacts}, "samples": {samples}}}"#
    ))
    .unwrap()
}

/// Impact `k` (1-based) of job `j`'s sample losing `loss` × its grain mass.
fn record(j: &ClaimedJob, k: u32, loss: f64) -> ImpactRecord {
    let grain = impact_params(j).grain_mass_kg_m();
    placeholder_record(k, grain, loss * grain)
}

/// A stand-in for the sample's state after its last impact.
fn checkpoint(j: &ClaimedJob) -> CheckpointBytes {
    CheckpointBytes::new(j.impacts_planned, vec![0; 3])
}

/// Claims the next job and completes it with impacts lost at `loss(sample, k)`, sending a
/// checkpoint when the claim asks for one. Returns the claim.
async fn run_one(s: &Store, loss: impl Fn(u32, u32) -> f64) -> ClaimedJob {
    run_one_adding(s, loss, None).await
}

/// [`run_one`] with every impact adding `added` × its grain mass of damage, when given.
async fn run_one_adding(
    s: &Store,
    loss: impl Fn(u32, u32) -> f64,
    added: Option<f64>,
) -> ClaimedJob {
    let j = s.claim("w").await.unwrap().expect("a queued job");
    let recs: Vec<ImpactRecord> = (j.impacts_done + 1..=j.impacts_planned)
        .map(|k| {
            let mut r = record(&j, k, loss(j.sample, k));
            r.outcome.damage_added_kg = added.map(|a| a * r.grain_mass_kg);
            r
        })
        .collect();
    let ckpt = j.extendable.then(|| checkpoint(&j));
    s.complete(j.job_id, j.lease_id, imp(&recs).with_checkpoint(ckpt))
        .await
        .unwrap();
    j
}

async fn checkpoints(s: &Store) -> i64 {
    sqlx::query("SELECT COUNT(*) FROM checkpoints")
        .fetch_one(&s.read)
        .await
        .unwrap()
        .get(0)
}

#[tokio::test]
async fn an_unsteady_cell_grows_by_step_and_stops_at_max_flagged() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = spec(
        r#"{"until_steady": {"min": 21, "max": 25, "step": 3}}"#,
        "2",
    );
    let id = s.create_campaign(&sp, None).await.unwrap().id;
    // Nothing is ever lost: never steady.
    let a = run_one(&s, |_, _| 0.0).await;
    assert!(a.extendable && a.impacts_planned == 21 && a.checkpoint.is_none());
    let st = s.status(id).await.unwrap();
    assert_eq!((st.jobs.done, st.jobs.queued, st.impacts_total), (1, 1, 42));
    assert_eq!(checkpoints(&s).await, 1, "kept: the cell may grow");
    run_one(&s, |_, _| 0.0).await;
    // The last job of the cell done: every sample is planned for 24 and queued again.
    let st = s.status(id).await.unwrap();
    assert_eq!(st.state, CampaignState::Running);
    assert_eq!(
        (st.jobs.queued, st.impacts_total, st.impacts_done),
        (2, 48, 42)
    );
    assert_eq!(st.cells[0].impacts_total, 48);
    let b = run_one(&s, |_, _| 0.0).await;
    assert_eq!((b.impacts_done, b.impacts_planned), (21, 24));
    assert!(b.extendable);
    assert_eq!(b.checkpoint.as_ref().map(|c| c.impacts_done), Some(21));
    run_one(&s, |_, _| 0.0).await;
    // 24 + 3 is capped at 25; the state after it is still asked for, should the cap be raised.
    let c = run_one(&s, |_, _| 0.0).await;
    assert_eq!((c.impacts_planned, c.extendable), (25, true));
    run_one(&s, |_, _| 0.0).await;
    let st = s.status(id).await.unwrap();
    assert_eq!(st.state, CampaignState::Done);
    assert_eq!((st.impacts_total, st.impacts_done), (50, 50));
    assert!(s.claim("w").await.unwrap().is_none());
    assert_eq!(
        checkpoints(&s).await,
        2,
        "kept: the cell stopped at its cap unsteady"
    );
    let r = impact_results(&s, id).await;
    let cell = &r.cells[0];
    assert_eq!(cell.impacts_planned, 25);
    assert!(!cell.partial);
    let ss = cell.steady_state.as_ref().unwrap();
    assert!(!ss.steady);
    assert!(
        ss.reason.starts_with("reached max 25 impacts; "),
        "{}",
        ss.reason
    );
    assert_eq!(r.steady, Some(false));
}

#[tokio::test]
async fn a_grown_cell_waits_for_the_other_cells_first_round() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = two_cells(
        r#""impacts": {"until_steady": {"min": 21, "max": 25, "step": 3}}, "samples": 2"#,
    );
    s.create_campaign(&sp, None).await.unwrap();
    // Sample 0 of both cells, then cell 0's sample 1: cell 0 is complete, never steady, and
    // grows to 24 while cell 1's sample 1 is still queued at 21.
    let claimed = claim_order(&s, 3, |_, _| 0.0).await;
    assert_eq!(claimed, [(0, 0, 21), (1, 0, 21), (0, 1, 21)]);
    let next = run_one(&s, |_, _| 0.0).await;
    assert_eq!(
        (next.cell, next.sample, next.impacts_planned),
        (1, 1, 21),
        "the other cell's first round before the grown cell's second"
    );
    let after = run_one(&s, |_, _| 0.0).await;
    assert_eq!((after.cell, after.impacts_planned), (0, 24));
}

#[tokio::test]
async fn a_campaign_queued_by_cell_finishes_one_cell_before_the_next_starts() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = two_cells(
        r#""impacts": {"until_steady": {"min": 21, "max": 24, "step": 3}}, "samples": 2,
            "queue": "cells""#,
    );
    s.create_campaign(&sp, None).await.unwrap();
    // Never steady: cell 0 grows to its max before cell 1 gets a job; in round order (the
    // test above) cell 1's first round would come second.
    let claimed = claim_order(&s, 8, |_, _| 0.0).await;
    assert_eq!(
        claimed,
        [
            (0, 0, 21),
            (0, 1, 21),
            (0, 0, 24),
            (0, 1, 24),
            (1, 0, 21),
            (1, 1, 21),
            (1, 0, 24),
            (1, 1, 24)
        ]
    );
    assert!(s.claim("w").await.unwrap().is_none());
}

#[tokio::test]
async fn samples_added_to_a_cell_queued_by_cell_come_before_the_next_cell() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = two_cells(
        r#""impacts": 21, "samples": {"target_sem_rel": 0.01, "min": 2, "max": 3},
            "queue": "cells""#,
    );
    s.create_campaign(&sp, None).await.unwrap();
    // Two samples far apart: the error bar is wide, so each cell gets a third sample, which
    // is handed out before the next cell's first.
    let claimed = claim_order(&s, 6, |sample, _| 0.1 + 0.2 * sample as f64).await;
    let samples: Vec<(u32, u32)> = claimed.iter().map(|c| (c.0, c.1)).collect();
    assert_eq!(samples, [(0, 0), (0, 1), (0, 2), (1, 0), (1, 1), (1, 2)]);
    // An added sample keeps its cell's rank, so that with several workers a later cell's
    // added samples cannot overtake an earlier cell's growth.
    let ranks: Vec<(i64, i64)> =
        sqlx::query_as("SELECT cell_index, queue_rank FROM jobs ORDER BY cell_index, sample_index")
            .fetch_all(&s.read)
            .await
            .unwrap();
    assert_eq!(ranks, [(0, 0), (0, 0), (0, 0), (1, 1), (1, 1), (1, 1)]);
}

#[tokio::test]
async fn a_steady_cell_is_not_extended() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = spec(
        r#"{"until_steady": {"min": 60, "max": 80, "step": 5}}"#,
        "2",
    );
    let id = s.create_campaign(&sp, None).await.unwrap().id;
    // The same loss from the first impact on: linear, past incubation, steady at the 60
    // impacts the steady check's three slopes need.
    run_one(&s, |_, _| 0.3).await;
    run_one(&s, |_, _| 0.3).await;
    let st = s.status(id).await.unwrap();
    assert_eq!(st.state, CampaignState::Done);
    assert_eq!(st.impacts_total, 120);
    assert_eq!(checkpoints(&s).await, 0);
    let r = impact_results(&s, id).await;
    assert_eq!(r.cells[0].impacts_planned, 60);
    assert_eq!(r.steady, Some(true));
}

#[tokio::test]
async fn a_cell_that_waits_for_the_balance_grows_until_its_loss_pays_for_its_damage() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = spec(
        r#"{"until_steady": {"min": 60, "max": 100, "step": 20, "balanced": true}}"#,
        "2",
    );
    let id = s.create_campaign(&sp, None).await.unwrap().id;
    // Steady loss (as in a_steady_cell_is_not_extended, done there at 60), but twice that
    // damage added: the stock grows, so the cell grows.
    let loss = |sample: u32, _| 0.1 + 0.01 * sample as f64;
    run_one_adding(&s, loss, Some(0.2)).await;
    run_one_adding(&s, loss, Some(0.2)).await;
    let r = impact_results(&s, id).await;
    assert_eq!(r.cells[0].impacts_planned, 80);
    assert!(!r.cells[0].damage_balance.unwrap().balanced);
    // Impacts 61–80, the next window, lose what they add: done at 80, below max.
    run_one_adding(&s, loss, Some(0.105)).await;
    run_one_adding(&s, loss, Some(0.105)).await;
    assert_eq!(s.status(id).await.unwrap().state, CampaignState::Done);
    let r = impact_results(&s, id).await;
    assert_eq!(r.cells[0].impacts_planned, 80);
    assert!(r.cells[0].damage_balance.unwrap().balanced);
    assert_eq!(r.spec.unwrap()["impacts"]["until_steady"]["balanced"], true);
}

#[tokio::test]
async fn samples_are_added_until_the_error_bar_or_max() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = spec("21", r#"{"target_sem_rel": 0.01, "min": 2, "max": 5}"#);
    let id = s.create_campaign(&sp, None).await.unwrap().id;
    // Samples erode at clearly different rates: the error bar is far above 1 %.
    let rate = |sample: u32, _| 0.1 + 0.1 * sample as f64;
    let a = run_one(&s, rate).await;
    assert!(!a.extendable);
    run_one(&s, rate).await;
    let st = s.status(id).await.unwrap();
    assert_eq!(
        (st.jobs.done, st.jobs.queued),
        (2, 3),
        "grown straight to max"
    );
    assert_eq!(st.impacts_total, 5 * 21);
    assert_eq!(st.cells[0].samples_total, 5);
    let mut seen = Vec::new();
    for _ in 0..3 {
        let j = run_one(&s, rate).await;
        assert_eq!(j.seed, job_seed(5, 0, j.sample), "seeds follow job_seed");
        assert_eq!(j.impacts_planned, 21);
        seen.push(j.sample);
    }
    assert_eq!(seen, [2, 3, 4]);
    let st = s.status(id).await.unwrap();
    assert_eq!(st.state, CampaignState::Done);
    let r = impact_results(&s, id).await;
    let cell = &r.cells[0];
    assert_eq!((cell.samples, cell.samples_planned), (5, 5));
    let rel = cell
        .erosion_sem_rel
        .expect("reported for a target_sem cell");
    assert!(rel > 0.01, "stopped at max above the target: {rel}");
}

#[tokio::test]
async fn samples_stop_once_the_target_is_met() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = spec("21", r#"{"target_sem_rel": 0.5, "min": 2, "max": 50}"#);
    let id = s.create_campaign(&sp, None).await.unwrap().id;
    // sem/mean = 0.5/√2·(0.2/0.3)... : with rates 0.2 and 0.4, sem = 0.1, mean = 0.3.
    let rate = |sample: u32, _| 0.2 + 0.2 * sample as f64;
    run_one(&s, rate).await;
    run_one(&s, rate).await;
    let st = s.status(id).await.unwrap();
    assert_eq!(st.state, CampaignState::Done, "1/3 ≤ 0.5: no sample added");
    let r = impact_results(&s, id).await;
    let rel = r.cells[0].erosion_sem_rel.unwrap();
    assert!((rel - 1.0 / 3.0).abs() < 1e-9, "{rel}");
}

#[tokio::test]
async fn a_repeated_complete_grows_nothing_twice() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = spec(
        r#"{"until_steady": {"min": 21, "max": 40, "step": 4}}"#,
        "1",
    );
    let id = s.create_campaign(&sp, None).await.unwrap().id;
    let j = run_one(&s, |_, _| 0.0).await;
    // The worker did not hear the answer and sends the same complete again.
    let e = s
        .complete(
            j.job_id,
            j.lease_id,
            imp(&[]).with_checkpoint(Some(checkpoint(&j))),
        )
        .await
        .unwrap_err();
    assert_eq!(e.status(), axum::http::StatusCode::CONFLICT);
    let st = s.status(id).await.unwrap();
    assert_eq!((st.jobs.queued, st.impacts_total), (1, 25));
    let e = s
        .complete(j.job_id, Uuid::new_v4(), imp(&[]))
        .await
        .unwrap_err();
    assert_eq!(e.status(), axum::http::StatusCode::CONFLICT);
    assert_eq!(s.status(id).await.unwrap().impacts_total, 25);
}

#[tokio::test]
async fn each_units_damage_added_is_stored_beside_its_masses_and_balances_the_cell() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let id = s.create_campaign(&spec("21", "2"), None).await.unwrap().id;
    for _ in 0..2 {
        run_one_adding(&s, |sample, _| 1e-3 * (1 + sample) as f64, Some(2e-3)).await;
    }
    let (units, damaged): (i64, i64) =
        sqlx::query("SELECT COUNT(*), COUNT(damage_kg_m) FROM units")
            .fetch_one(&s.read)
            .await
            .map(|r| (r.get(0), r.get(1)))
            .unwrap();
    assert_eq!((units, damaged), (42, 42));
    let b = impact_results(&s, id).await.cells[0]
        .damage_balance
        .unwrap();
    // Samples lost 1 and 2 mg/g against 2 mg/g of damage added each.
    assert_eq!(b.samples, 2);
    assert!((b.ratio.unwrap() - 0.75).abs() < 1e-9, "{b:?}");
}

/// [`spec`]'s never-steady cell of 2 samples capped at `max`, for [`Store::raise_caps`].
fn capped(max: u32) -> AnySpec {
    AnySpec::Impact(spec(
        &format!(r#"{{"until_steady": {{"min": 21, "max": {max}, "step": 3}}}}"#),
        "2",
    ))
}

#[tokio::test]
async fn a_raised_cap_runs_a_cell_stopped_there_on_from_its_last_states() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let id = s.create(&capped(24), Some("a")).await.unwrap().id;
    for _ in 0..4 {
        run_one(&s, |_, _| 0.0).await;
    }
    assert_eq!(s.status(id).await.unwrap().state, CampaignState::Done);
    assert_eq!(checkpoints(&s).await, 2);
    let raised = s.raise_caps(id, &capped(30), Some("b")).await.unwrap();
    assert_eq!(
        raised,
        [RaisedCell {
            cell: 0,
            from: 24,
            to: 30,
            reopened_to: Some(27),
            resumed: 2,
            samples: 2,
        }]
    );
    let st = s.status(id).await.unwrap();
    assert_eq!(st.state, CampaignState::Running);
    assert_eq!((st.jobs.queued, st.impacts_total), (2, 54));
    // The new spec now resumes the campaign; the old one is another campaign.
    assert!(s.has_key("b").await.unwrap() && !s.has_key("a").await.unwrap());
    let j = run_one(&s, |_, _| 0.0).await;
    assert_eq!((j.impacts_done, j.impacts_planned), (24, 27));
    assert_eq!(j.checkpoint.as_ref().map(|c| c.impacts_done), Some(24));
    for _ in 0..3 {
        run_one(&s, |_, _| 0.0).await;
    }
    assert!(s.claim("w").await.unwrap().is_none());
    let r = impact_results(&s, id).await;
    assert_eq!(r.cells[0].impacts_planned, 30);
    let ss = r.cells[0].steady_state.as_ref().unwrap();
    assert!(
        ss.reason.starts_with("reached max 30 impacts; "),
        "{}",
        ss.reason
    );
    assert_eq!(
        checkpoints(&s).await,
        2,
        "unsteady at the new cap: kept again"
    );
}

#[tokio::test]
async fn a_cell_steady_at_its_cap_keeps_no_state_and_stays_final_when_raised() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let rule = |max: u32| {
        AnySpec::Impact(spec(
            &format!(r#"{{"until_steady": {{"min": 60, "max": {max}, "step": 5}}}}"#),
            "2",
        ))
    };
    let id = s.create(&rule(60), None).await.unwrap().id;
    run_one(&s, |_, _| 0.3).await;
    run_one(&s, |_, _| 0.3).await;
    assert_eq!(
        checkpoints(&s).await,
        0,
        "steady at the cap: nothing to run on"
    );
    let raised = s.raise_caps(id, &rule(80), None).await.unwrap();
    assert_eq!((raised[0].reopened_to, raised[0].resumed), (None, 0));
    let st = s.status(id).await.unwrap();
    assert_eq!((st.state, st.impacts_total), (CampaignState::Done, 120));
}

#[tokio::test]
async fn only_higher_caps_of_the_same_campaign_are_raised() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let id = s.create(&capped(24), Some("a")).await.unwrap().id;
    let refused = |e: crate::Error| match e {
        crate::Error::Conflict(why) => why,
        other => panic!("{other}"),
    };
    let why = refused(s.raise_caps(id, &capped(24), Some("b")).await.unwrap_err());
    assert!(why.contains("raises no cell's until_steady.max"), "{why}");
    let why = refused(s.raise_caps(id, &capped(22), Some("b")).await.unwrap_err());
    assert!(
        why.contains("may only be raised, from 24 (got 22)"),
        "{why}"
    );
    let renamed = AnySpec::from_json(
        r#"{"name": "x", "seed": 5, "angles_deg": [90], "shapes": ["hexagon"], "spacing_m": 25e-6,
            "impacts": {"until_steady": {"min": 21, "max": 30, "step": 3}}, "samples": 2}"#,
    )
    .unwrap();
    let why = refused(s.raise_caps(id, &renamed, Some("b")).await.unwrap_err());
    assert!(why.contains("names or pinned engines differ"), "{why}");
    s.cancel(id).await.unwrap();
    let why = refused(s.raise_caps(id, &capped(30), Some("b")).await.unwrap_err());
    assert!(why.contains("cancelled"), "{why}");
    assert!(s.has_key("a").await.unwrap(), "nothing changed");
}

/// What judging a finished cell costs the writer, for a cell of 25 samples × 400 impacts:
/// its last completion (which judges it) against the others, and the read of its units'
/// masses from their columns against parsing every record. Run by hand, on an idle machine:
/// `cargo test --release -p grit-farm --lib settle_cost -- --ignored --nocapture`.
#[tokio::test]
#[ignore]
async fn settle_cost() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path()).await;
    let sp = spec(
        r#"{"until_steady": {"min": 400, "max": 420, "step": 20}}"#,
        "25",
    );
    s.create_campaign(&sp, None).await.unwrap();
    let mut took = Vec::new();
    for _ in 0..25 {
        let j = s.claim("w").await.unwrap().expect("a queued job");
        let recs: Vec<ImpactRecord> = (1..=400).map(|k| record(&j, k, 0.0)).collect();
        let ckpt = Some(checkpoint(&j));
        let t = std::time::Instant::now();
        s.complete(j.job_id, j.lease_id, imp(&recs).with_checkpoint(ckpt))
            .await
            .unwrap();
        took.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let others = took[..24].iter().sum::<f64>() / 24.0;
    println!(
        "completion of 400 impacts: {others:.2} ms; the last, which judges the cell: {:.2} ms",
        took[24]
    );
    let from = "FROM units u JOIN jobs j ON j.id = u.job_id
                WHERE j.cell_index = 0 ORDER BY j.sample_index, u.unit";
    let (mut columns, mut records) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..5 {
        let t = std::time::Instant::now();
        let rows = sqlx::query(&format!(
            "SELECT j.sample_index, u.grain_kg_m, u.loss_kg_m {from}"
        ))
        .fetch_all(&s.read)
        .await
        .unwrap();
        let sum: f64 = rows
            .iter()
            .map(|r| r.get::<f64, _>(1) + r.get::<f64, _>(2))
            .sum();
        columns = columns.min(t.elapsed().as_secs_f64() * 1e3);
        let t = std::time::Instant::now();
        let rows = sqlx::query(&format!("SELECT j.sample_index, u.record {from}"))
            .fetch_all(&s.read)
            .await
            .unwrap();
        let parsed: f64 = rows
            .iter()
            .map(|r| {
                let rec: ImpactRecord = serde_json::from_str(r.get::<&str, _>(1)).unwrap();
                rec.grain_mass_kg + rec.mass_loss_kg
            })
            .sum();
        records = records.min(t.elapsed().as_secs_f64() * 1e3);
        assert_eq!(sum, parsed);
    }
    println!("10000 units' masses: {columns:.2} ms from columns, {records:.2} ms from records");
}
