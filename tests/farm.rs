//! End-to-end tests of the job farm: the real `grit` binary as coordinator and
//! workers over loopback, a fresh SQLite file per test, and real (coarse) SPH impacts.
//! Set TEST_LOG=1 to see the processes' logs on failure paths.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use grit_farm::api::CampaignState;
use grit_farm::{Client, ClientError, Secret};
use serde_json::Value;
use uuid::Uuid;

mod common;
use common::results::{assert_bitwise_equal, grit_run, raw_series};
use common::{
    grit_cli, start_coordinator, start_worker, submitter, wait_done, wait_for, Api, Coordinator,
    GRIT, SERIAL, SUBMIT, WORKER,
};

/// The coarsest real scene at 60°.
fn campaign(samples: u32, impacts: u32) -> String {
    common::campaign("e2e", "[60]", samples, impacts)
}

/// `grit serve` with a lease of `lease_ttl_s` and a 64 KiB limit on specs.
fn coordinator(dir: &Path, listen: &str, lease_ttl_s: f64, tag: &str) -> Coordinator {
    start_coordinator(
        dir,
        tag,
        listen,
        lease_ttl_s,
        &["--max-spec-bytes", "65536"],
        None,
    )
}

/// A worker that checkpoints after every impact, so a kill loses at most one.
fn worker(dir: &Path, url: &str, tag: &str) -> common::Proc {
    start_worker(dir, url, tag, &["--checkpoint-every", "1"])
}

fn worker_client(url: &str) -> Client {
    Client::new(url, Secret::new(Some(WORKER.into()))).unwrap()
}

#[tokio::test(flavor = "multi_thread")]
async fn two_workers_complete_a_campaign_and_match_grit_run() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    // Twenty impacts a sample (about a second a job) and both workers polling before the
    // campaign exists: each claims within one 0.2 s poll, long before the other could finish
    // its job and take the second one too.
    let spec = campaign(2, 20);
    let coord = coordinator(dir.path(), "127.0.0.1:0", 30.0, "a");
    let _w1 = worker(dir.path(), &coord.url, "w1");
    let _w2 = worker(dir.path(), &coord.url, "w2");
    for w in [&_w1, &_w2] {
        wait_for(
            Duration::from_secs(30),
            "the worker to start polling",
            || async { Ok::<_, ()>(w.log_text()) },
            |log| log.contains("engine fingerprints"),
        )
        .await;
    }
    let file = dir.path().join("spec.json");
    std::fs::write(&file, &spec).unwrap();
    let out = grit_cli(&coord.url, &["submit", file.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let id: Uuid = stdout.lines().last().unwrap().trim().parse().unwrap();
    let c = submitter(&coord.url);
    let s = wait_done(&c, id, Duration::from_secs(120)).await;
    assert_eq!(s.impacts_done, s.impacts_total);
    assert_eq!(s.impacts_total, 40);
    let farm = c.results_value(id, false).await.unwrap();
    assert_eq!(farm["partial"], Value::Bool(false));
    let local = grit_run(dir.path(), &spec, "local", false);
    assert_eq!(farm, local, "farm results equal grit run results");
    // Without --raw, results.json leaves the series out, but the charts are drawn from them:
    // the per-sample damage balance needs every impact.
    assert!(local.get("raw").is_none(), "{local}");
    let charts: Vec<String> = std::fs::read_dir(dir.path().join("local"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    assert!(
        charts
            .iter()
            .any(|n| n.starts_with("damage_balance_c00_") && n.ends_with(".png")),
        "{charts:?}"
    );
    // The same spec again resumes (here: finds it done); another spec in the same folder is
    // refused before it could overwrite the first one's results and charts.
    assert_eq!(grit_run(dir.path(), &spec, "local", false), local);
    let other = dir.path().join("other.json");
    std::fs::write(&other, campaign(1, 2)).unwrap();
    let out = Command::new(GRIT)
        .args([
            "run",
            other.to_str().unwrap(),
            "--workers",
            "1",
            "--quiet",
            "--out",
        ])
        .arg(dir.path().join("local"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("holds the results of another campaign"),
        "{stderr}"
    );
    // The results say how they were made and whether they are steady-state rates: twenty
    // impacts per sample are far too few for three last-20 windows.
    assert_eq!(farm["spec"]["samples"], 2, "{farm}");
    assert!(
        farm["spec"]["friction"].is_number(),
        "defaults filled in: {farm}"
    );
    assert_eq!(farm["grit_version"], env!("CARGO_PKG_VERSION"));
    // The numerics the cells ran with, which the spec does not carry.
    assert_eq!(
        farm["numerics"]["cfl"],
        grit_erosion::Numerics::default().engine.cfl,
        "{farm}"
    );
    assert_eq!(farm["steady"], Value::Bool(false));
    assert_eq!(
        farm["cells"][0]["steady_state"]["steady"],
        Value::Bool(false)
    );
    let id_text = id.to_string();
    let out = grit_cli(&coord.url, &["results", &id_text]);
    assert!(out.status.success());
    let stdout: Value = serde_json::from_slice(&out.stdout).expect("stdout stays JSON");
    assert_eq!(stdout, farm);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("warning: cell 60° hexagon is not at steady state: only 20 impacts"),
        "{stderr}"
    );
    let out = grit_cli(&coord.url, &["status", &id_text]);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("is not at steady state"), "{stderr}");
    // One line per cell under the campaign's line.
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("\n  60.0° hexagon  2/2 samples  40/40 impacts\n"),
        "{stdout}"
    );
    // Both workers took part (one job each, claimed in parallel).
    assert!(_w1.log_text().contains("job complete") && _w2.log_text().contains("job complete"));
}

#[tokio::test(flavor = "multi_thread")]
async fn one_worker_process_holds_two_jobs_at_once() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    // Ten impacts a sample: both loops claim within milliseconds of starting, long before
    // either could finish its first job and take the other's.
    let spec = campaign(2, 10);
    let coord = coordinator(dir.path(), "127.0.0.1:0", 30.0, "a");
    let c = submitter(&coord.url);
    let id = c.submit(&spec, None).await.unwrap().id;
    let w = start_worker(dir.path(), &coord.url, "w", &["--jobs", "2"]);
    let s = wait_done(&c, id, Duration::from_secs(120)).await;
    assert_eq!(s.impacts_done, 20);
    // Each job was run by its own loop of the one process, on its own lease.
    let jobs = Api::new(&coord.url)
        .ok(&format!("/campaigns/{id}/jobs"))
        .await;
    let mut names: Vec<&str> = jobs
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j["worker"].as_str().unwrap_or(""))
        .collect();
    names.sort();
    assert_eq!(names, ["w/1", "w/2"], "{jobs}");
    assert!(w.log_text().contains("jobs=2"), "{}", w.log_text());
    let farm = c.results_value(id, false).await.unwrap();
    assert_eq!(farm, grit_run(dir.path(), &spec, "local", false));
}

#[tokio::test(flavor = "multi_thread")]
async fn killed_worker_is_resumed_from_checkpoint_bit_for_bit() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let spec = campaign(1, 6);
    let coord = coordinator(dir.path(), "127.0.0.1:0", 2.0, "a");
    let c = submitter(&coord.url);
    let id = c.submit(&spec, None).await.unwrap().id;
    let mut w1 = worker(dir.path(), &coord.url, "w1");
    wait_for(
        Duration::from_secs(120),
        "2 impacts",
        || c.status(id),
        |s| s.impacts_done >= 2,
    )
    .await;
    w1.kill9();
    let before = c.status(id).await.unwrap();
    assert!(
        before.impacts_done < 6,
        "the job must still be running when killed"
    );
    let w2 = worker(dir.path(), &coord.url, "w2");
    wait_done(&c, id, Duration::from_secs(120)).await;
    assert!(
        w2.log_text().contains("resumed from checkpoint"),
        "the second worker resumes from the checkpoint:\n{}",
        w2.log_text()
    );
    let farm = raw_series(&c.results_value(id, true).await.unwrap());
    let local = raw_series(&grit_run(dir.path(), &spec, "local", true));
    assert_bitwise_equal(&farm, &local);
}

#[tokio::test(flavor = "multi_thread")]
async fn coordinator_restart_loses_nothing() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let spec = campaign(2, 4);
    let mut coord = coordinator(dir.path(), "127.0.0.1:0", 30.0, "a");
    let url = coord.url.clone();
    let c = submitter(&url);
    let id = c.submit(&spec, None).await.unwrap().id;
    let w1 = worker(dir.path(), &url, "w1");
    let w2 = worker(dir.path(), &url, "w2");
    let mid = wait_for(
        Duration::from_secs(120),
        "some impacts",
        || c.status(id),
        |s| s.impacts_done >= 2,
    )
    .await;
    coord.proc.kill9();
    tokio::time::sleep(Duration::from_secs(2)).await;
    let listen = url.trim_start_matches("http://").to_string();
    let _coord2 = coordinator(dir.path(), &listen, 30.0, "b");
    let after = c.status(id).await.unwrap();
    assert!(
        after.impacts_done >= mid.impacts_done,
        "nothing stored was lost"
    );
    let s = wait_done(&c, id, Duration::from_secs(180)).await;
    assert_eq!(s.impacts_done, 8);
    let farm = raw_series(&c.results_value(id, true).await.unwrap());
    for (_, _, records) in &farm {
        let numbers: Vec<u32> = records.iter().map(|r| r.impact).collect();
        assert_eq!(numbers, vec![1, 2, 3, 4]);
    }
    let local = raw_series(&grit_run(dir.path(), &spec, "local", true));
    assert_bitwise_equal(&farm, &local);
    assert!(w1.log_text().contains("unreachable") || w2.log_text().contains("unreachable"));
}

#[tokio::test(flavor = "multi_thread")]
async fn stale_worker_gets_409_and_changes_nothing() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let coord = coordinator(dir.path(), "127.0.0.1:0", 1.0, "a");
    let c = submitter(&coord.url);
    let id = c.submit(&campaign(1, 2), None).await.unwrap().id;
    let stale = worker_client(&coord.url);
    let job = stale.claim("stale").await.unwrap().expect("a job");
    // A real impact, slower than the 1 s lease.
    let params: grit_erosion::ImpactParams = serde_json::from_value(job.params.clone()).unwrap();
    let seed = job.seed;
    let record = tokio::task::spawn_blocking(move || {
        let mut s = grit_erosion::Sample::new(params, seed).unwrap();
        s.run_next().unwrap().clone()
    })
    .await
    .unwrap();
    tokio::time::sleep(Duration::from_millis(1500)).await;
    let fresh = worker_client(&coord.url)
        .claim("fresh")
        .await
        .unwrap()
        .expect("requeued job");
    assert_eq!(fresh.job_id, job.job_id);
    let hb = grit_farm::api::HeartbeatRequest {
        lease_id: job.lease_id,
        units: grit_farm::api::units(std::slice::from_ref(&record)),
        checkpoint: None,
    };
    let e = stale.heartbeat(job.job_id, &hb).await.unwrap_err();
    assert_eq!(e.status().map(|s| s.as_u16()), Some(409), "{e}");
    let done = grit_farm::api::CompleteRequest {
        lease_id: job.lease_id,
        units: grit_farm::api::units(&[record]),
        checkpoint: None,
    };
    let e = stale.complete(job.job_id, &done).await.unwrap_err();
    assert_eq!(e.status().map(|s| s.as_u16()), Some(409), "{e}");
    let raw = raw_series(&c.results_value(id, true).await.unwrap());
    assert!(
        raw[0].2.is_empty(),
        "nothing from the stale worker was stored"
    );
    assert_eq!(c.status(id).await.unwrap().impacts_done, 0);
}

#[tokio::test(flavor = "multi_thread")]
async fn auth_validation_size_and_unknown_ids() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let coord = coordinator(dir.path(), "127.0.0.1:0", 30.0, "a");
    let http = reqwest::Client::new();
    let api = format!("{}/api/v1", coord.url);
    let status = |r: reqwest::Response| r.status().as_u16();
    let status_of = |r: &reqwest::Response| r.status().as_u16();

    // 401: no token, a wrong token, or the other role's token.
    let r = http.get(format!("{api}/campaigns")).send().await.unwrap();
    assert_eq!(status(r), 401);
    let r = http
        .get(format!("{api}/campaigns"))
        .bearer_auth("nope")
        .send()
        .await
        .unwrap();
    assert_eq!(status(r), 401);
    let r = http
        .get(format!("{api}/campaigns"))
        .bearer_auth(WORKER)
        .send()
        .await
        .unwrap();
    assert_eq!(status(r), 401);
    let r = http
        .post(format!("{api}/worker/claim"))
        .bearer_auth(SUBMIT)
        .json(&serde_json::json!({"worker": "x"}))
        .send()
        .await
        .unwrap();
    assert_eq!(status(r), 401);
    // Open endpoints.
    let r = http.get(format!("{api}/healthz")).send().await.unwrap();
    assert_eq!(status(r), 200);
    let doc: Value = http
        .get(format!("{api}/openapi.json"))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert!(doc["paths"]["/api/v1/campaigns"].is_object());

    // 422 naming the field; 400 for malformed JSON.
    let post = |body: String| {
        http.post(format!("{api}/campaigns"))
            .bearer_auth(SUBMIT)
            .header("content-type", "application/json")
            .body(body)
            .send()
    };
    let r = post(r#"{"angles_deg": [45, 100]}"#.into()).await.unwrap();
    assert_eq!(r.status().as_u16(), 422);
    let body: Value = r.json().await.unwrap();
    assert_eq!(body["field"], "angles_deg[1]", "{body}");
    let r = post(r#"{"samples": 3, "colour": "red"}"#.into())
        .await
        .unwrap();
    assert_eq!(r.status().as_u16(), 422);
    let body: Value = r.json().await.unwrap();
    assert_eq!(body["field"], "colour", "{body}");
    let r = post(r#"{"impacts": 5}"#.into()).await.unwrap();
    assert_eq!(r.status().as_u16(), 422);
    assert_eq!(r.json::<Value>().await.unwrap()["field"], "impacts");
    let r = post(r#"{"samples": "#.into()).await.unwrap();
    assert_eq!(status(r), 400);
    // The CLI prints the field too and exits non-zero.
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, r#"{"shapes": ["pentagon"]}"#).unwrap();
    let out = grit_cli(&coord.url, &["submit", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("shapes[0]"));

    // 413 above the body limit (64 KiB in these tests), in the API's error body.
    let big = format!(r#"{{"name": "{}"}}"#, "x".repeat(100_000));
    let r = post(big).await.unwrap();
    assert_eq!(status_of(&r), 413);
    assert!(r.json::<Value>().await.unwrap()["error"].is_string());
    // The framework's own refusals come as JSON too: a method the path does not take (405,
    // naming those it does), a query the endpoint does not take (422 naming it).
    let r = http
        .put(format!("{api}/campaigns"))
        .bearer_auth(SUBMIT)
        .send()
        .await
        .unwrap();
    assert_eq!(status_of(&r), 405);
    let allow = r.headers()["allow"].to_str().unwrap().to_string();
    assert!(allow.contains("GET") && allow.contains("POST"), "{allow}");
    let body: Value = r.json().await.unwrap();
    assert!(body["error"].as_str().unwrap().contains("Allow"), "{body}");
    for (query, field) in [("raw=maybe", "raw"), ("rwa=true", "rwa")] {
        let r = http
            .get(format!(
                "{api}/campaigns/{}/results?{query}",
                Uuid::new_v4()
            ))
            .bearer_auth(SUBMIT)
            .send()
            .await
            .unwrap();
        assert_eq!(status_of(&r), 422, "{query}");
        assert_eq!(r.json::<Value>().await.unwrap()["field"], field);
    }
    // Worker bodies: the field named; an empty worker name refused; JSON types only.
    let claim = |body: Value| {
        http.post(format!("{api}/worker/claim"))
            .bearer_auth(WORKER)
            .json(&body)
            .send()
    };
    let any = "0000000000000000";
    for body in [
        serde_json::json!({"worker": 5, "engine": any}),
        serde_json::json!({"worker": "", "engine": any}),
        serde_json::json!({"worker": "   ", "engine": any}),
    ] {
        let r = claim(body.clone()).await.unwrap();
        assert_eq!(status_of(&r), 422, "{body}");
        assert_eq!(
            r.json::<Value>().await.unwrap()["field"],
            "worker",
            "{body}"
        );
    }
    // The engine is required and must be fingerprints, each named where it fails.
    for (body, field) in [
        (serde_json::json!({"worker": "w"}), "engine"),
        (
            serde_json::json!({"worker": "w", "engine": "0a40"}),
            "engine",
        ),
        (
            serde_json::json!({"worker": "w", "engine": {"impact": "0A408D93D042D5E9"}}),
            "engine.impact",
        ),
        (serde_json::json!({"worker": "w", "engine": {}}), "engine"),
    ] {
        let r = claim(body.clone()).await.unwrap();
        assert_eq!(status_of(&r), 422, "{body}");
        assert_eq!(r.json::<Value>().await.unwrap()["field"], field, "{body}");
    }
    let r = http
        .post(format!("{api}/worker/claim"))
        .bearer_auth(WORKER)
        .header("content-type", "text/plain")
        .body(r#"{"worker": "w"}"#)
        .send()
        .await
        .unwrap();
    assert_eq!(status_of(&r), 415);
    assert!(r.json::<Value>().await.unwrap()["error"].is_string());
    let r = http
        .post(format!("{api}/worker/claim"))
        .bearer_auth(WORKER)
        .header("content-type", "application/json; charset=utf-8")
        .body(r#"{"worker": "w", "engine": "0000000000000000"} trailing"#)
        .send()
        .await
        .unwrap();
    assert_eq!(status_of(&r), 400, "trailing characters after the JSON");
    let r = http
        .post(format!("{api}/worker/jobs/abc/heartbeat"))
        .bearer_auth(WORKER)
        .json(&serde_json::json!({"lease_id": Uuid::new_v4()}))
        .send()
        .await
        .unwrap();
    assert_eq!(status_of(&r), 404);
    assert!(r.json::<Value>().await.unwrap()["error"].is_string());

    // 404 for unknown ids and jobs.
    let c = submitter(&coord.url);
    let e = c.status(Uuid::new_v4()).await.unwrap_err();
    assert_eq!(e.status().map(|s| s.as_u16()), Some(404));
    let e = c.results_value(Uuid::new_v4(), false).await.unwrap_err();
    assert_eq!(e.status().map(|s| s.as_u16()), Some(404));
    let r = http
        .post(format!("{api}/worker/jobs/999/heartbeat"))
        .bearer_auth(WORKER)
        .json(&serde_json::json!({"lease_id": Uuid::new_v4()}))
        .send()
        .await
        .unwrap();
    assert_eq!(status(r), 404);
    // The token never reaches the log.
    let log = coord.proc.log_text();
    assert!(!log.contains(SUBMIT) && !log.contains(WORKER));
}

#[tokio::test(flavor = "multi_thread")]
async fn a_campaign_is_leased_only_to_workers_of_its_pinned_engine() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let coord = coordinator(dir.path(), "127.0.0.1:0", 30.0, "a");
    let c = submitter(&coord.url);
    let id = c.submit(&campaign(1, 2), None).await.unwrap().id;
    let own = grit_erosion::scene::engines::<grit_erosion::Scenes>().unwrap();
    // Pinned to the coordinator's own engine, and no worker of it seen yet.
    let s = c.status(id).await.unwrap();
    assert_eq!(s.engine.as_deref(), Some(own["impact"].as_str()));
    assert_eq!(s.engine_seen, Some(false));
    let out = grit_cli(&coord.url, &["status", &id.to_string()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!("warning: no worker with engine {}", own["impact"])),
        "{stderr}"
    );
    // Another engine gets 204 while the job is queued, and is told why.
    let http = reqwest::Client::new();
    let r = http
        .post(format!("{}/api/v1/worker/claim", coord.url))
        .bearer_auth(WORKER)
        .json(&serde_json::json!({"worker": "x", "engine": "0000000000000000"}))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status().as_u16(), 204);
    let why = r.headers()["grit-no-job"].to_str().unwrap().to_string();
    assert!(
        why.contains(&format!("pinned to impact engine {}", own["impact"])),
        "{why}"
    );
    assert_eq!(c.status(id).await.unwrap().jobs.queued, 1);
    // This binary's engine gets it; its units carry that fingerprint, and so do the results.
    let w = worker_client(&coord.url);
    let job = w.claim("real").await.unwrap().expect("the pinned job");
    assert_eq!(c.status(id).await.unwrap().engine_seen, Some(true));
    let params: grit_erosion::ImpactParams = serde_json::from_value(job.params.clone()).unwrap();
    let seed = job.seed;
    let records = tokio::task::spawn_blocking(move || {
        let mut s = grit_erosion::Sample::new(params, seed).unwrap();
        (0..2)
            .map(|_| s.run_next().unwrap().clone())
            .collect::<Vec<_>>()
    })
    .await
    .unwrap();
    w.complete(
        job.job_id,
        &grit_farm::api::CompleteRequest {
            lease_id: job.lease_id,
            units: grit_farm::api::units(&records),
            checkpoint: None,
        },
    )
    .await
    .unwrap();
    let results = c.results_value(id, false).await.unwrap();
    assert_eq!(results["engine"], own["impact"].as_str(), "{results}");
    assert!(results["commit"].is_string(), "{results}");
    assert_eq!(
        unit_engines(&dir.path().join("farm.db")).await,
        vec![own["impact"].clone()]
    );
    // A spec may name the engine; one that is no fingerprint is refused by field.
    let named = c
        .submit(
            &campaign(1, 2).replacen('{', r#"{"engine": "0123456789abcdef", "#, 1),
            None,
        )
        .await
        .unwrap()
        .id;
    assert_eq!(
        c.status(named).await.unwrap().engine.as_deref(),
        Some("0123456789abcdef")
    );
    let e = c
        .submit(
            &campaign(1, 2).replacen('{', r#"{"engine": "latest", "#, 1),
            None,
        )
        .await
        .unwrap_err();
    assert!(
        matches!(&e, ClientError::Status { field: Some(f), .. } if f == "engine"),
        "{e}"
    );
}

/// The distinct engine fingerprints stamped on the stored units of the database at `path`,
/// read beside the running coordinator.
async fn unit_engines(path: &Path) -> Vec<String> {
    let opts = sqlx::sqlite::SqliteConnectOptions::new()
        .filename(path)
        .read_only(true);
    let pool = sqlx::SqlitePool::connect_with(opts).await.unwrap();
    sqlx::query_scalar("SELECT DISTINCT engine FROM units ORDER BY 1")
        .fetch_all(&pool)
        .await
        .unwrap()
}

#[tokio::test(flavor = "multi_thread")]
async fn repeated_submit_with_idempotency_key_creates_one_campaign() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let coord = coordinator(dir.path(), "127.0.0.1:0", 30.0, "a");
    let c = submitter(&coord.url);
    let spec = campaign(1, 2);
    let first = c.submit(&spec, Some("key-1")).await.unwrap();
    assert!(first.created);
    let second = c.submit(&spec, Some("key-1")).await.unwrap();
    assert!(!second.created);
    assert_eq!(first.id, second.id);
    let file = dir.path().join("spec.json");
    std::fs::write(&file, &spec).unwrap();
    let out = grit_cli(
        &coord.url,
        &[
            "submit",
            file.to_str().unwrap(),
            "--idempotency-key",
            "key-1",
        ],
    );
    assert!(out.status.success());
    let last = String::from_utf8(out.stdout).unwrap();
    assert_eq!(last.lines().last().unwrap().trim(), first.id.to_string());
    assert_eq!(c.list().await.unwrap().len(), 1);
    // The same key with a different campaign is refused.
    let e = c.submit(&campaign(2, 2), Some("key-1")).await.unwrap_err();
    assert_eq!(e.status().map(|s| s.as_u16()), Some(409));
}

#[tokio::test(flavor = "multi_thread")]
async fn cancel_stops_handout_and_tells_running_workers() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let coord = coordinator(dir.path(), "127.0.0.1:0", 3.0, "a");
    let c = submitter(&coord.url);
    let id = c.submit(&campaign(3, 20), None).await.unwrap().id;
    let mut w = worker(dir.path(), &coord.url, "w1");
    wait_for(
        Duration::from_secs(60),
        "a leased job",
        || c.status(id),
        |s| s.jobs.leased >= 1,
    )
    .await;
    let out = grit_cli(&coord.url, &["cancel", &id.to_string()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = c.status(id).await.unwrap();
    assert_eq!(s.state, CampaignState::Cancelled);
    assert_eq!((s.jobs.queued, s.jobs.leased), (0, 0));
    assert_eq!(s.jobs.cancelled, 3);
    assert!(worker_client(&coord.url)
        .claim("probe")
        .await
        .unwrap()
        .is_none());
    // The worker hears it at its next heartbeat (every lease/3 = 1 s) and drops the job.
    let start = Instant::now();
    while !w.log_text().contains("cancelled") {
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "worker never told:\n{}",
            w.log_text()
        );
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    assert!(
        w.child.try_wait().unwrap().is_none(),
        "the worker keeps running"
    );
    w.kill9();
}

#[tokio::test(flavor = "multi_thread")]
async fn sigterm_releases_the_job_with_a_checkpoint_and_exits_0() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let coord = coordinator(dir.path(), "127.0.0.1:0", 30.0, "a");
    let c = submitter(&coord.url);
    let id = c.submit(&campaign(1, 20), None).await.unwrap().id;
    let mut w = worker(dir.path(), &coord.url, "w1");
    wait_for(
        Duration::from_secs(60),
        "an impact",
        || c.status(id),
        |s| s.impacts_done >= 1,
    )
    .await;
    // Twice, as under Slurm, which signals every process of a job while the job's batch shell
    // passes its own SIGTERM on: the second must not cut the checkpoint short.
    for _ in 0..2 {
        w.signal("TERM");
        std::thread::sleep(Duration::from_millis(20));
    }
    let code = w.wait_exit();
    assert!(code.success(), "exit status {code:?}");
    assert!(
        w.log_text().contains("released with a checkpoint"),
        "{}",
        w.log_text()
    );
    let s = c.status(id).await.unwrap();
    assert_eq!(
        (s.jobs.queued, s.jobs.leased),
        (1, 0),
        "the job is back in the queue at once"
    );
    let job = worker_client(&coord.url)
        .claim("next")
        .await
        .unwrap()
        .unwrap();
    assert!(job.checkpoint.is_some());
    assert_eq!(job.impacts_done, s.impacts_done as u32);
}

/// An until-steady campaign: the coarse scene erodes nothing in 25 impacts, so every sample
/// grows 21 → 23 → 25 and the cell ends at `max`, flagged unsteady.
fn until_steady_campaign() -> String {
    common::campaign("grow", "[60]", 2, 21).replace(
        r#""impacts": 21"#,
        r#""impacts": {"until_steady": {"min": 21, "max": 25, "step": 2}}"#,
    )
}

#[tokio::test(flavor = "multi_thread")]
async fn until_steady_extends_samples_bit_for_bit() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let spec = until_steady_campaign();
    assert!(spec.contains("until_steady"));
    let local_results = grit_run(dir.path(), &spec, "local", true);
    let cell = &local_results["cells"][0];
    assert_eq!(cell["impacts_planned"], 25, "grown to max");
    let reason = cell["steady_state"]["reason"].as_str().unwrap();
    assert!(
        cell["steady_state"]["steady"] == true || reason.starts_with("reached max 25 impacts"),
        "{reason}"
    );
    let local = raw_series(&local_results);
    assert!(local.iter().all(|(_, _, r)| r.len() == 25));

    // The first 21 impacts equal those of samples planned with 21 from the start.
    let fixed = raw_series(&grit_run(dir.path(), &campaign(2, 21), "fixed", true));
    let head: Vec<_> = local
        .iter()
        .map(|(c, s, r)| (*c, *s, r[..21].to_vec()))
        .collect();
    assert_bitwise_equal(&head, &fixed);

    // Capped at 23, then run again with the cap raised to 25: the cell runs on from its
    // samples' states at 23 to the bits of the cap of 25 from the start. The old spec is then
    // another campaign.
    let capped = spec.replace(r#""max": 25"#, r#""max": 23"#);
    let at_23 = grit_run(dir.path(), &capped, "raised", true);
    assert_eq!(at_23["cells"][0]["impacts_planned"], 23);
    let raised = grit_run(dir.path(), &spec, "raised", true);
    assert_eq!(raised["cells"][0]["steady_state"], cell["steady_state"]);
    assert_bitwise_equal(&raw_series(&raised), &local);
    std::fs::write(dir.path().join("capped.json"), &capped).unwrap();
    let out = Command::new(GRIT)
        .args(["run", "--quiet", "--out"])
        .arg(dir.path().join("raised"))
        .arg(dir.path().join("capped.json"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("until_steady.max may only be raised, from 25 (got 23)"),
        "{stderr}"
    );

    // Served, two workers, one killed with -9 while the cell grows: the same records.
    let coord = coordinator(dir.path(), "127.0.0.1:0", 2.0, "a");
    let c = submitter(&coord.url);
    let id = c.submit(&spec, None).await.unwrap().id;
    let mut w1 = worker(dir.path(), &coord.url, "w1");
    let _w2 = worker(dir.path(), &coord.url, "w2");
    let grown = wait_for(
        Duration::from_secs(120),
        "the first extension",
        || c.status(id),
        |s| s.impacts_total > 42 && s.impacts_done >= 43,
    )
    .await;
    assert!(grown.impacts_done < 50, "killed while the cell grows");
    w1.kill9();
    let s = wait_done(&c, id, Duration::from_secs(120)).await;
    assert_eq!((s.impacts_done, s.impacts_total), (50, 50));
    let farm_results = c.results_value(id, true).await.unwrap();
    assert_eq!(
        farm_results["cells"][0]["steady_state"],
        cell["steady_state"]
    );
    assert_bitwise_equal(&raw_series(&farm_results), &local);

    // Served too, `grit raise-caps` runs the cell on from its samples' states at 25; a lower
    // cap is refused (409) naming the rule.
    let file = dir.path().join("raised-27.json");
    std::fs::write(&file, spec.replace(r#""max": 25"#, r#""max": 27"#)).unwrap();
    let out = grit_cli(
        &coord.url,
        &["raise-caps", &id.to_string(), file.to_str().unwrap()],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains("cell 0: until_steady.max raised from 25 to 27; reopened for 27 impacts per sample, 2 of 2 samples from their state at 25"),
        "{said}"
    );
    let s = wait_done(&c, id, Duration::from_secs(120)).await;
    assert_eq!((s.impacts_done, s.impacts_total), (54, 54));
    let on = raw_series(&c.results_value(id, true).await.unwrap());
    let head: Vec<_> = on
        .iter()
        .map(|(c, s, r)| (*c, *s, r[..25].to_vec()))
        .collect();
    assert_bitwise_equal(&head, &local);
    let e = c.raise_caps(id, &spec).await.unwrap_err().to_string();
    assert!(e.contains("may only be raised, from 27 (got 25)"), "{e}");
}

/// `grit run` on a folder whose campaign is pinned to another engine: resuming it, or raising
/// its caps, is refused (exit 2, both fingerprints named) and changes nothing there;
/// `--engine-upgrade NEW` runs the spec afresh in NEW on this engine.
#[tokio::test(flavor = "multi_thread")]
async fn a_folder_pinned_to_another_engine_is_refused_or_upgraded() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let capped = common::campaign("pin", "[60]", 1, 21).replace(
        r#""impacts": 21"#,
        r#""impacts": {"until_steady": {"min": 21, "max": 23, "step": 2}}"#,
    );
    let first = grit_run(dir.path(), &capped, "old", true);
    let db = dir.path().join("old").join("grit.db");
    let other = "0000000000000000";
    let pool =
        sqlx::SqlitePool::connect_with(sqlx::sqlite::SqliteConnectOptions::new().filename(&db))
            .await
            .unwrap();
    sqlx::query("UPDATE campaigns SET engine = ?")
        .bind(other)
        .execute(&pool)
        .await
        .unwrap();
    let stored = |pool: sqlx::SqlitePool| async move {
        sqlx::query_scalar::<_, i64>("SELECT count(*) FROM units")
            .fetch_one(&pool)
            .await
            .unwrap()
    };
    let units = stored(pool.clone()).await;
    let own = grit_erosion::scene::engines::<grit_erosion::Scenes>().unwrap()["impact"].clone();

    let raised = dir.path().join("raised.json");
    std::fs::write(&raised, capped.replace(r#""max": 23"#, r#""max": 25"#)).unwrap();
    let run = |spec: &Path, extra: &[&str]| {
        Command::new(GRIT)
            .args(["run", "--quiet", "--out"])
            .arg(dir.path().join("old"))
            .args(extra)
            .arg(spec)
            .output()
            .unwrap()
    };
    for (spec, says) in [
        (
            dir.path().join("old.json"),
            format!("pinned to engine {other}, and this grit computes {own}"),
        ),
        (
            raised.clone(),
            format!("it is pinned to engine {other} and this grit computes {own}"),
        ),
    ] {
        let out = run(&spec, &[]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(&says), "{stderr}");
    }
    assert_eq!(
        stored(pool.clone()).await,
        units,
        "nothing run in the old folder"
    );
    let caps: String = sqlx::query_scalar("SELECT spec FROM campaigns")
        .fetch_one(&pool)
        .await
        .unwrap();
    assert!(
        caps.contains(r#""max":23"#) || caps.contains(r#""max": 23"#),
        "{caps}"
    );

    let fresh = dir.path().join("new");
    let out = run(
        &dir.path().join("old.json"),
        &["--raw", "--engine-upgrade", fresh.to_str().unwrap()],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "running it afresh in {} on engine {own}",
            fresh.display()
        )),
        "{stderr}"
    );
    let upgraded: Value =
        serde_json::from_str(&std::fs::read_to_string(fresh.join("results.json")).unwrap())
            .unwrap();
    assert_eq!(upgraded["engine"], own.as_str());
    // Only the pin was another engine's, so the fresh run repeats the first one's bits.
    assert_bitwise_equal(&raw_series(&upgraded), &raw_series(&first));
    assert_eq!(
        stored(pool).await,
        units,
        "the old folder is left as it was"
    );
}

/// `grit run --interim-every` writes the results so far to results.json while the campaign
/// runs (unfinished cells partial), and the final results over them at the end.
#[tokio::test(flavor = "multi_thread")]
async fn grit_run_writes_interim_results_while_it_runs() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("interim.json");
    std::fs::write(&spec, common::campaign("interim", "[45, 90]", 2, 6)).unwrap();
    let out_dir = dir.path().join("out");
    let results = out_dir.join("results.json");
    let mut child = Command::new(GRIT)
        .args(["run", "--quiet", "--workers", "1", "--threads", "1"])
        .args(["--interim-every", "0.2", "--out"])
        .arg(&out_dir)
        .arg(&spec)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut interim: Option<Value> = None;
    while child.try_wait().unwrap().is_none() {
        if let Ok(text) = std::fs::read_to_string(&results) {
            let v: Value = serde_json::from_str(&text).expect("written whole, never torn");
            if v["partial"] == true && interim.is_none() {
                interim = Some(v);
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    let interim = interim.expect("interim results while it ran");
    let cells = interim["cells"].as_array().unwrap();
    assert!(
        cells
            .iter()
            .any(|c| c["samples_reported"].as_u64() > Some(0)),
        "finished samples in the interim results: {interim}"
    );
    assert!(cells.iter().any(|c| c["partial"] == true), "{interim}");
    assert!(stderr.contains("interim results ("), "{stderr}");
    // `grit compare` reads them, saying which cells still ran.
    let file = dir.path().join("interim-results.json");
    std::fs::write(&file, interim.to_string()).unwrap();
    let out = Command::new(GRIT)
        .arg("compare")
        .arg(&file)
        .output()
        .unwrap();
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(table.contains("note: interim results: "), "{table}");
    let last: Value = serde_json::from_str(&std::fs::read_to_string(&results).unwrap()).unwrap();
    assert_eq!(last["partial"], false);
    // A cell complete in the interim results is the final one's.
    for (a, b) in cells.iter().zip(last["cells"].as_array().unwrap()) {
        if a["partial"] == false {
            assert_eq!(a["erosion_mean"], b["erosion_mean"]);
        }
    }
}
