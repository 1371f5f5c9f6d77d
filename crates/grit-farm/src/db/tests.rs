//! The store's lease, failure and workers bookkeeping, without HTTP.

use std::path::Path;
use std::time::Duration;

use grit_erosion::campaign::CampaignSpec;
use uuid::Uuid;

use super::{imp, impact_params, impact_results, Store};
use crate::api::{CampaignState, JobState};
use crate::error::Error;
use crate::loadtest::placeholder_record;

const TINY: &str = r#"{"angles_deg": [90], "shapes": ["hexagon"], "samples": 2, "impacts": 2,
    "allow_short_samples": true, "spacing_m": 25e-6}"#;

/// TINY with one sample of `impacts` impacts.
fn one_sample(impacts: u32) -> CampaignSpec {
    CampaignSpec::from_json(
        &TINY
            .replace(r#""samples": 2"#, r#""samples": 1"#)
            .replace(r#""impacts": 2"#, &format!(r#""impacts": {impacts}"#)),
    )
    .unwrap()
}

/// Impacts 1..=n of `spec`'s first cell, each losing 1e-7 k kg/m.
fn records(spec: &CampaignSpec, n: u32) -> Vec<grit_erosion::ImpactRecord> {
    let grain = spec.cells().unwrap()[0].params.grain_mass_kg_m();
    (1..=n)
        .map(|k| placeholder_record(k, grain, 1e-7 * f64::from(k)))
        .collect()
}

async fn store(dir: &Path, ttl_ms: u64) -> Store {
    Store::open(&dir.join("t.db"), Duration::from_millis(ttl_ms), 2)
        .await
        .unwrap()
}

#[tokio::test]
async fn expired_leases_count_attempts_until_the_job_fails() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 1).await;
    let spec = CampaignSpec::from_json(TINY).unwrap();
    let id = s.create_campaign(&spec, None).await.unwrap().id;
    // Sample 0 first (claim order), then the other.
    let a = s.claim("w").await.unwrap().unwrap();
    assert_eq!(a.sample, 0);
    tokio::time::sleep(Duration::from_millis(5)).await;
    let b = s.claim("w").await.unwrap().unwrap();
    assert_eq!(
        b.job_id, a.job_id,
        "the expired job is first in the queue again"
    );
    tokio::time::sleep(Duration::from_millis(5)).await;
    s.reap_expired().await.unwrap();
    let st = s.status(id).await.unwrap();
    assert_eq!(st.jobs.failed, 1);
    assert_eq!(st.jobs.queued, 1);
    let e = st.last_error.unwrap();
    assert_eq!(e.attempts, 2);
    assert!(e.error.contains("lease expired"), "{}", e.error);
    assert_eq!(s.retry_failed(id).await.unwrap(), 1);
    assert_eq!(s.status(id).await.unwrap().jobs.queued, 2);
}

#[tokio::test]
async fn workers_are_listed_idle_or_with_the_job_they_hold() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 60_000).await;
    assert!(s.claim("idle").await.unwrap().is_none());
    let spec = CampaignSpec::from_json(TINY).unwrap();
    let id = s.create_campaign(&spec, None).await.unwrap().id;
    let j = s.claim("busy").await.unwrap().unwrap();
    tokio::time::sleep(Duration::from_millis(5)).await;
    s.heartbeat(j.job_id, j.lease_id, imp(&[])).await.unwrap();
    let w = s.workers(Duration::from_secs(60)).await.unwrap();
    let names: Vec<&str> = w.workers.iter().map(|w| w.name.as_str()).collect();
    assert_eq!(names, ["busy", "idle"], "most recently seen first");
    let held = &w.workers[0].jobs;
    assert_eq!(held.len(), 1);
    assert_eq!((held[0].job_id, held[0].campaign_id), (j.job_id, id));
    assert_eq!(held[0].last_heartbeat_ms, w.workers[0].last_seen_ms);
    assert!(w.workers[1].jobs.is_empty());
    // A failed attempt clears the job's worker, but the worker stays listed.
    s.fail(j.job_id, j.lease_id, "boom", imp(&[]))
        .await
        .unwrap();
    let w = s.workers(Duration::from_secs(60)).await.unwrap();
    assert!(w.workers.iter().all(|w| w.jobs.is_empty()));
    let queued = s.jobs(id, Some(JobState::Queued), 10).await.unwrap();
    assert_eq!(queued.len(), 2);
    assert_eq!(queued[0].last_error.as_deref(), Some("boom"));
    assert_eq!(s.jobs(id, None, 1).await.unwrap().len(), 1);
    let e = s.jobs(Uuid::new_v4(), None, 10).await.unwrap_err();
    assert_eq!(e.status(), axum::http::StatusCode::NOT_FOUND);
}

#[tokio::test]
async fn failure_reports_keep_the_error_and_stale_leases_get_409() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 60_000).await;
    let spec = CampaignSpec::from_json(TINY).unwrap();
    let id = s.create_campaign(&spec, None).await.unwrap().id;
    let j = s.claim("w").await.unwrap().unwrap();
    let e = s
        .heartbeat(j.job_id, Uuid::new_v4(), imp(&[]))
        .await
        .unwrap_err();
    assert_eq!(e.status(), axum::http::StatusCode::CONFLICT);
    s.fail(j.job_id, j.lease_id, "impact 1: unstable", imp(&[]))
        .await
        .unwrap();
    let e = s
        .fail(j.job_id, j.lease_id, "again", imp(&[]))
        .await
        .unwrap_err();
    assert_eq!(
        e.status(),
        axum::http::StatusCode::CONFLICT,
        "the lease ended"
    );
    let j2 = s.claim("w").await.unwrap().unwrap();
    s.fail(j2.job_id, j2.lease_id, "impact 1: unstable", imp(&[]))
        .await
        .unwrap();
    let st = s.status(id).await.unwrap();
    assert_eq!(st.jobs.failed + st.jobs.queued, 2);
    assert_eq!(
        st.last_error.map(|e| e.error).as_deref(),
        Some("impact 1: unstable")
    );
    assert_eq!(s.cancel(id).await.unwrap(), 2);
    assert!(s.claim("w").await.unwrap().is_none());
    assert_eq!(s.status(id).await.unwrap().state, CampaignState::Cancelled);
}

#[tokio::test]
async fn results_carry_the_spec_as_run_the_version_and_the_steady_check() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 60_000).await;
    let spec = CampaignSpec::from_json(TINY).unwrap();
    let id = s.create_campaign(&spec, None).await.unwrap().id;
    let r = impact_results(&s, id).await;
    // Defaults the submitted JSON left out are filled in, so the spec reruns as it ran.
    let run = r.spec.as_ref().expect("spec");
    assert_eq!(run["samples"], 2);
    assert_eq!(run["seed"], 0);
    assert_eq!(
        CampaignSpec::from_json(&run.to_string()).unwrap(),
        spec,
        "the spec reads back as the one submitted"
    );
    for key in ["friction", "surface_width_dg", "grain", "material"] {
        assert!(run.get(key).is_some(), "{key} filled in: {run}");
    }
    assert_eq!(r.grit_version.as_deref(), Some(env!("CARGO_PKG_VERSION")));
    // No impact yet: no cell is steady, and each says why.
    assert_eq!(r.steady, Some(false));
    let check = r.cells[0].steady_state.as_ref().unwrap();
    assert!(
        !check.steady && check.reason.contains("no samples"),
        "{check:?}"
    );
    assert_eq!(r.unsteady_warnings().len(), r.cells.len());
    let json: serde_json::Value =
        serde_json::from_str(&s.results_json(id, false).await.unwrap()).unwrap();
    for key in ["spec", "grit_version", "steady"] {
        assert!(json.get(key).is_some(), "{key} in {json}");
    }
}

/// Some errors (`SQLITE_FULL` among them) make SQLite roll the transaction back by itself;
/// the writer must still take the next transaction.
#[tokio::test]
async fn a_transaction_rolled_back_by_sqlite_does_not_wedge_the_writer() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 60_000).await;
    {
        let mut tx = s.begin().await.unwrap();
        // What SQLite does on its own after such an error.
        sqlx::query("ROLLBACK").execute(&mut *tx).await.unwrap();
    }
    let spec = CampaignSpec::from_json(TINY).unwrap();
    s.create_campaign(&spec, None).await.unwrap();
}

/// A write that finds no space is a 503 naming the cause, stores nothing, and the same write
/// succeeds once there is space again.
#[tokio::test]
async fn a_full_database_is_503_and_recovers() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 60_000).await;
    let big =
        CampaignSpec::from_json(&TINY.replace(r#""samples": 2"#, r#""samples": 5000"#)).unwrap();
    // SQLite's cap on the database's pages stands in for a full disk: the same SQLITE_FULL.
    sqlx::query("PRAGMA max_page_count = 1")
        .execute(&s.write)
        .await
        .unwrap();
    let e = s.create_campaign(&big, None).await.unwrap_err();
    assert!(e.is_disk_full(), "{e}");
    assert_eq!(e.status(), axum::http::StatusCode::SERVICE_UNAVAILABLE);
    assert!(e.to_string().contains("database or disk is full"), "{e}");
    assert!(s.list_campaigns().await.unwrap().is_empty());
    sqlx::query("PRAGMA max_page_count = 1073741823")
        .execute(&s.write)
        .await
        .unwrap();
    s.create_campaign(&big, None).await.unwrap();
    assert_eq!(s.list_campaigns().await.unwrap().len(), 1);
}

/// A report of more impacts than one insert statement takes stores every record bit for bit;
/// a checkpoint stored by a heartbeat is handed back whole to the next lease holder, and
/// dropped when a job of a fixed plan completes.
#[tokio::test]
async fn long_reports_and_checkpoints_round_trip_and_a_done_jobs_checkpoint_is_dropped() {
    use crate::api::Checkpoint;
    use crate::checkpoint::CheckpointBytes;

    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 60_000).await;
    let spec = one_sample(400);
    s.create_campaign(&spec, None).await.unwrap();
    let grain = spec.cells().unwrap()[0].params.grain_mass_kg_m();
    let records: Vec<_> = (1..=400)
        .map(|k| placeholder_record(k, grain, 1e-7 * f64::from(k).sqrt()))
        .collect();
    let j = s.claim("w").await.unwrap().unwrap();
    let bytes: Vec<u8> = (0..=255).cycle().take(1000).collect();
    let beat = s
        .heartbeat(
            j.job_id,
            j.lease_id,
            imp(&records[..350]).with_checkpoint(Some(CheckpointBytes::new(350, bytes.clone()))),
        )
        .await
        .unwrap();
    assert_eq!(beat.impacts_done, 350);
    s.release(j.job_id, j.lease_id, imp(&[])).await.unwrap();
    let again = s.claim("w").await.unwrap().unwrap();
    assert_eq!(again.impacts_done, 350);
    assert_eq!(
        serde_json::to_value(&again.checkpoint).unwrap(),
        serde_json::to_value(Some(Checkpoint::from_bytes(j.job_id, 350, &bytes))).unwrap()
    );
    // Impacts already stored are skipped.
    s.complete(again.job_id, again.lease_id, imp(&records[300..]))
        .await
        .unwrap();
    let stored: Vec<(String, f64)> =
        sqlx::query_as("SELECT record, lost_kg_m FROM units WHERE job_id = ? ORDER BY unit")
            .bind(j.job_id)
            .fetch_all(&s.read)
            .await
            .unwrap();
    assert_eq!(stored.len(), 400);
    let mut lost = 0.0;
    for (rec, (json, lost_after)) in records.iter().zip(&stored) {
        assert_eq!(
            serde_json::from_str::<grit_erosion::ImpactRecord>(json).unwrap(),
            *rec
        );
        lost += rec.mass_loss_kg;
        assert_eq!(
            lost_after.to_bits(),
            f64::to_bits(lost),
            "the job's loss after each"
        );
    }
    let kept: i64 = sqlx::query_scalar("SELECT COUNT(*) FROM checkpoints")
        .fetch_one(&s.read)
        .await
        .unwrap();
    assert_eq!(kept, 0, "a done job of a fixed plan keeps no checkpoint");
}

#[tokio::test]
async fn impacts_must_carry_the_cells_grain_and_lose_less_than_the_surface() {
    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 60_000).await;
    let spec = CampaignSpec::from_json(TINY).unwrap();
    s.create_campaign(&spec, None).await.unwrap();
    let j = s.claim("w").await.unwrap().unwrap();
    let grain = impact_params(&j).grain_mass_kg_m();
    let refused = |rec| {
        let s = &s;
        let j = &j;
        async move {
            match s.heartbeat(j.job_id, j.lease_id, imp(&[rec])).await {
                Err(Error::Invalid { field, .. }) => field,
                other => panic!("expected a 422, got {other:?}"),
            }
        }
    };
    // A grain other than the cell's would put the sample's points at the wrong abscissa.
    assert_eq!(
        refused(placeholder_record(1, 1.7e308, 0.0)).await,
        "units[0].grain_mass_kg"
    );
    assert_eq!(
        refused(placeholder_record(1, grain * (1.0 + 1e-15), 0.0)).await,
        "units[0].grain_mass_kg"
    );
    // Finite but more than the whole surface: its sums would overflow to infinity.
    let surface = impact_params(&j).surface_mass_kg_m();
    assert_eq!(
        refused(placeholder_record(1, grain, 1e307)).await,
        "units[0].mass_loss_kg"
    );
    assert_eq!(
        refused(placeholder_record(1, grain, surface * 1.001)).await,
        "units[0].mass_loss_kg"
    );
    let stored: i64 = sqlx::query_scalar("SELECT COUNT(*) FROM units")
        .fetch_one(&s.read)
        .await
        .unwrap();
    assert_eq!(stored, 0, "nothing of a refused report is stored");
    let beat = s
        .heartbeat(
            j.job_id,
            j.lease_id,
            imp(&[placeholder_record(1, grain, surface)]),
        )
        .await
        .unwrap();
    assert_eq!(
        beat.impacts_done, 1,
        "the whole surface is the bound, and allowed"
    );
    // The bound holds for the sample's loss in all, not per impact.
    assert_eq!(
        refused(placeholder_record(2, grain, surface * 1e-3)).await,
        "units[0].mass_loss_kg"
    );
    // The record's two copies of the loss must agree.
    let mut two = placeholder_record(2, grain, 0.0);
    two.outcome.mass_loss_kg = 1e-9;
    assert_eq!(refused(two).await, "units[0].mass_loss_kg");
}

/// A job claimed again behind its stored impacts (a checkpoint older than them, or none) shows
/// as replaying in the status until its worker has reported those impacts again, and no
/// longer once it adds new ones; a claim starts the count afresh.
#[tokio::test]
async fn a_job_behind_its_stored_impacts_shows_its_replay_until_it_catches_up() {
    use crate::api::Replaying;
    use crate::checkpoint::CheckpointBytes;

    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 60_000).await;
    let spec = one_sample(20);
    let id = s.create_campaign(&spec, None).await.unwrap().id;
    let records = records(&spec, 20);
    let replaying = |st: crate::api::CampaignStatus| st.replaying;

    let j = s.claim("w").await.unwrap().unwrap();
    assert_eq!(replaying(s.status(id).await.unwrap()), None, "a fresh job");
    let ckpt = CheckpointBytes::new(4, vec![1; 8]);
    s.heartbeat(
        j.job_id,
        j.lease_id,
        imp(&records[..4]).with_checkpoint(Some(ckpt)),
    )
    .await
    .unwrap();
    s.heartbeat(j.job_id, j.lease_id, imp(&records[4..10]))
        .await
        .unwrap();
    assert_eq!(
        replaying(s.status(id).await.unwrap()),
        None,
        "adding new ones"
    );
    s.release(j.job_id, j.lease_id, imp(&[])).await.unwrap();

    // Resumed from the checkpoint at 4: impacts 5–10 are stored and run again.
    let again = s.claim("w").await.unwrap().unwrap();
    assert_eq!(again.impacts_done, 10);
    let left = |n| {
        Some(Replaying {
            jobs: 1,
            units_left: n,
        })
    };
    assert_eq!(replaying(s.status(id).await.unwrap()), left(6));
    s.heartbeat(again.job_id, again.lease_id, imp(&records[4..7]))
        .await
        .unwrap();
    assert_eq!(replaying(s.status(id).await.unwrap()), left(3));
    let beat = s
        .heartbeat(again.job_id, again.lease_id, imp(&records[7..12]))
        .await
        .unwrap();
    assert_eq!(beat.impacts_done, 12);
    assert_eq!(replaying(s.status(id).await.unwrap()), None, "caught up");

    // The next lease is behind again: its own reports, not the last lease's, count.
    s.release(again.job_id, again.lease_id, imp(&[]))
        .await
        .unwrap();
    let third = s.claim("w").await.unwrap().unwrap();
    assert_eq!(replaying(s.status(id).await.unwrap()), left(8));
    s.complete(third.job_id, third.lease_id, imp(&records[4..]))
        .await
        .unwrap();
    assert_eq!(replaying(s.status(id).await.unwrap()), None, "done");
}

#[tokio::test]
async fn the_rate_counts_the_campaigns_own_impacts_through_their_index_back_to_the_last_20() {
    use super::campaigns::{LATEST_UNITS, RECENT_UNITS};
    use sqlx::Row;

    let dir = tempfile::tempdir().unwrap();
    let s = store(dir.path(), 60_000).await;
    let spec = one_sample(20);
    let first = s.create_campaign(&spec, None).await.unwrap().id;
    let other = s.create_campaign(&spec, None).await.unwrap().id;
    let records = records(&spec, 3);
    let j = s.claim("w").await.unwrap().unwrap();
    let (ran, idle) = (
        j.campaign_id,
        if j.campaign_id == first { other } else { first },
    );
    s.heartbeat(j.job_id, j.lease_id, imp(&records))
        .await
        .unwrap();
    let rate = s.status(ran).await.unwrap().rate_impacts_per_s;
    assert!(rate.is_some_and(|r| r > 0.0), "{rate:?}");
    assert_eq!(s.status(idle).await.unwrap().rate_impacts_per_s, None);
    for (sql, limit) in [(RECENT_UNITS, None), (LATEST_UNITS, Some(20_i64))] {
        let q = format!("EXPLAIN QUERY PLAN {sql}");
        let mut q = sqlx::query(&q).bind(ran.to_string()).bind(0_i64);
        if let Some(limit) = limit {
            q = q.bind(limit);
        }
        let plan: Vec<String> = q
            .fetch_all(&s.read)
            .await
            .unwrap()
            .iter()
            .map(|r| r.get::<String, _>("detail"))
            .collect();
        assert!(
            plan.first().is_some_and(|p| p.contains("units_recent")),
            "the window's units are found by created_ms first: {plan:?}"
        );
    }
    // A slow campaign: no impact in the last 2 minutes, three 5 minutes ago.
    sqlx::query("UPDATE units SET created_ms = created_ms - 300000")
        .execute(&s.write)
        .await
        .unwrap();
    let rate = s.status(ran).await.unwrap().rate_impacts_per_s;
    assert!(
        rate.is_some_and(|r| (0.008..0.012).contains(&r)),
        "3 impacts over 300 s: {rate:?}"
    );
}
