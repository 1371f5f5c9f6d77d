//! The coordinator's dashboard: `GET /` is a self-contained page served without a
//! token and holding no data; `GET /api/v1/workers` and `GET /api/v1/campaigns/{id}/jobs`
//! show the workers seen recently and the failed jobs with their errors; headless Chromium,
//! given the submit token in the URL fragment, renders a campaign a real worker finished, its
//! progress and its erosion chart from the live API, with unsteady cells hollow and the
//! reasons noted. The real `grit` binary over loopback, a fresh SQLite file per test, real
//! (coarse) SPH impacts. TEST_LOG=1 prints the processes' logs.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use serde_json::json;

mod common;
use common::{campaign, start_worker, wait_for, Api, Coordinator, SERIAL, SUBMIT, WORKER};

const CHROMIUM: &str = "/usr/bin/chromium";

/// `grit serve` on a free loopback port, failing a job for good after `max_attempts`.
fn start_coordinator(dir: &Path, max_attempts: u32) -> Coordinator {
    let attempts = max_attempts.to_string();
    common::start_coordinator(
        dir,
        "a",
        "127.0.0.1:0",
        30.0,
        &["--max-attempts", &attempts],
        None,
    )
}

/// This binary's engine fingerprints, as a worker claims with them: the coordinator pins its
/// campaigns to them.
fn engine() -> serde_json::Value {
    json!(grit_erosion::scene::engines::<grit_erosion::Scenes>().unwrap())
}

/// Claims the queued job as `worker` and reports a failure, as a worker whose engine stopped
/// with an error does.
async fn claim_and_fail(api: &Api, worker: &str, error: &str) -> i64 {
    let (status, job) = api
        .post(
            "/worker/claim",
            WORKER,
            &json!({ "worker": worker, "engine": engine() }),
        )
        .await;
    assert_eq!(status, 200, "{job}");
    let job_id = job["job_id"].as_i64().unwrap();
    let (status, body) = api
        .post(
            &format!("/worker/jobs/{job_id}/fail"),
            WORKER,
            &json!({ "lease_id": job["lease_id"], "error": error }),
        )
        .await;
    assert_eq!(status, 204, "{body}");
    job_id
}

/// Fails the test unless Chromium is installed: a dashboard test that skips itself would let a
/// broken page pass CI.
fn chromium() -> &'static str {
    assert!(
        Path::new(CHROMIUM).exists(),
        "{CHROMIUM} is missing: the dashboard test drives headless Chromium. Install it with \
         `apt-get install -y chromium` (scripts/test does this)."
    );
    CHROMIUM
}

/// Headless Chromium on `url` with `extra` flags and a fresh profile; returns stdout. Killed
/// after two minutes so a hung browser fails the test instead of stalling it.
fn run_chromium(dir: &Path, url: &str, extra: &[&str]) -> String {
    let profile = tempfile::tempdir_in(dir).unwrap();
    let out = dir.join("chromium.out");
    let err = dir.join("chromium.err");
    let mut child = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(extra)
        .arg(url)
        .stdout(std::fs::File::create(&out).unwrap())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .expect("chromium starts");
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "chromium did not finish in 120 s:\n{}",
                std::fs::read_to_string(&err).unwrap_or_default()
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(
        status.success(),
        "chromium failed ({status}):\n{}",
        std::fs::read_to_string(&err).unwrap_or_default()
    );
    std::fs::read_to_string(&out).unwrap()
}

#[tokio::test(flavor = "multi_thread")]
async fn page_is_open_and_the_new_endpoints_list_workers_and_failed_jobs() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let coord = start_coordinator(dir.path(), 1);
    let url = coord.url.clone();
    let api = Api::new(&url);
    let http = reqwest::Client::new();

    // The page needs no token and carries no data, only the code that fetches it.
    let id = api.submit(&campaign("endpoints", "[60]", 2, 2)).await;
    let r = http.get(format!("{url}/")).send().await.unwrap();
    assert_eq!(r.status().as_u16(), 200);
    let h = r.headers();
    assert!(h["content-type"].to_str().unwrap().starts_with("text/html"));
    let csp = h["content-security-policy"].to_str().unwrap();
    assert!(csp.contains("connect-src 'self'"), "{csp}");
    let page = r.text().await.unwrap();
    assert!(page.contains("<svg") || page.contains("createElementNS"));
    assert!(!page.contains(&id) && !page.contains("endpoints"));

    // Both endpoints take the submit token, not the worker's.
    for path in ["/workers", &format!("/campaigns/{id}/jobs")] {
        assert_eq!(api.get(path, None).await.0, 401, "{path}");
        assert_eq!(api.get(path, Some(WORKER)).await.0, 401, "{path}");
    }
    let w = api.ok("/workers").await;
    assert_eq!(w["workers"], json!([]), "nobody has claimed yet");
    assert_eq!(w["lease_ttl_s"], json!(30.0));

    // A worker holding a job is listed with it and its heartbeat.
    let (status, job) = api
        .post(
            "/worker/claim",
            WORKER,
            &json!({ "worker": "probe-a", "engine": engine() }),
        )
        .await;
    assert_eq!(status, 200);
    let w = api.ok("/workers").await;
    let listed = &w["workers"][0];
    assert_eq!(listed["name"], "probe-a", "{w}");
    assert_eq!(listed["jobs"][0]["job_id"], job["job_id"]);
    assert_eq!(listed["jobs"][0]["campaign_id"], json!(id));
    assert_eq!(listed["jobs"][0]["campaign_name"], "endpoints");
    assert_eq!(listed["jobs"][0]["angle_deg"], json!(60.0));
    assert_eq!(listed["jobs"][0]["impacts_planned"], 2);
    assert!(listed["jobs"][0]["last_heartbeat_ms"].as_i64().unwrap() > 0);
    // With one attempt allowed, a reported failure fails the job for good.
    let (status, _) = api
        .post(
            &format!("/worker/jobs/{}/fail", job["job_id"]),
            WORKER,
            &json!({ "lease_id": job["lease_id"], "error": "impact 1: negative density at particle 7" }),
        )
        .await;
    assert_eq!(status, 204);
    // An idle worker polling an empty queue is listed too, holding nothing.
    let failed_id = job["job_id"].as_i64().unwrap();
    let other = claim_and_fail(
        &api,
        "probe-b",
        "impact 1: grain passed through the surface",
    )
    .await;
    // Distinct milliseconds, so the order by last sight is certain.
    tokio::time::sleep(Duration::from_millis(20)).await;
    let (status, _) = api
        .post(
            "/worker/claim",
            WORKER,
            &json!({ "worker": "probe-idle", "engine": engine() }),
        )
        .await;
    assert_eq!(status, 204);
    let w = api.ok("/workers").await;
    let names: Vec<&str> = w["workers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["name"].as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 3, "{w}");
    assert_eq!(names[0], "probe-idle", "most recently seen first: {w}");
    assert!(w["workers"]
        .as_array()
        .unwrap()
        .iter()
        .all(|x| x["jobs"] == json!([])));
    tokio::time::sleep(Duration::from_millis(20)).await;
    assert_eq!(
        api.ok("/workers?seen_within_s=0.01").await["workers"]
            .as_array()
            .map(Vec::len),
        Some(0)
    );

    let failed = api.ok(&format!("/campaigns/{id}/jobs?state=failed")).await;
    let failed = failed.as_array().unwrap();
    assert_eq!(failed.len(), 2);
    assert_eq!(failed[0]["job_id"], json!(failed_id));
    assert_eq!(failed[0]["state"], "failed");
    assert_eq!(failed[0]["attempts"], 1);
    assert_eq!(
        failed[0]["last_error"],
        "impact 1: negative density at particle 7"
    );
    assert_eq!(failed[1]["job_id"], json!(other));
    let all = api.ok(&format!("/campaigns/{id}/jobs?limit=1")).await;
    assert_eq!(all.as_array().map(Vec::len), Some(1));
    assert_eq!(
        api.ok(&format!("/campaigns/{id}/jobs?state=done")).await,
        json!([])
    );

    // Bad input: 422 naming the field; unknown campaign: 404.
    for (path, field) in [
        (format!("/campaigns/{id}/jobs?state=broken"), "state"),
        (format!("/campaigns/{id}/jobs?limit=0"), "limit"),
        (format!("/campaigns/{id}/jobs?limit=x"), "limit"),
        (format!("/campaigns/{id}/jobs?colour=red"), "colour"),
        ("/workers?seen_within_s=-1".to_string(), "seen_within_s"),
        ("/workers?seen_within_s=NaN".to_string(), "seen_within_s"),
        ("/workers?since=5".to_string(), "since"),
    ] {
        let (status, body) = api.get(&path, Some(SUBMIT)).await;
        assert_eq!(status, 422, "{path}: {body}");
        assert_eq!(body["field"], field, "{path}: {body}");
    }
    let unknown = uuid::Uuid::new_v4();
    assert_eq!(
        api.get(&format!("/campaigns/{unknown}/jobs"), Some(SUBMIT))
            .await
            .0,
        404
    );

    // Documented in the OpenAPI document.
    let (_, doc) = api.get("/openapi.json", None).await;
    assert!(doc["paths"]["/api/v1/workers"]["get"].is_object());
    assert!(doc["paths"]["/api/v1/campaigns/{id}/jobs"]["get"].is_object());
    assert!(doc["components"]["schemas"]["WorkersResponse"].is_object());
    let log = coord.proc.log_text();
    assert!(!log.contains(SUBMIT) && !log.contains(WORKER));
}

#[tokio::test(flavor = "multi_thread")]
async fn chromium_shows_a_finished_campaign_its_chart_workers_and_failed_jobs() {
    let chromium_path = chromium();
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let coord = start_coordinator(dir.path(), 1);
    let url = coord.url.clone();
    let api = Api::new(&url);

    // Two angles × two samples × 20 impacts: enough for each sample's last-20 slope, so the
    // erosion chart has a point with an error bar at each angle. Until steady with its cap at
    // its start, so each cell stops at the cap and the note says how to raise it.
    let id = api
        .submit(&campaign("dashboard-e2e", "[45, 90]", 2, 20).replace(
            r#""impacts": 20"#,
            r#""impacts": {"until_steady": {"min": 20, "max": 20, "step": 10}}"#,
        ))
        .await;
    let worker = start_worker(dir.path(), &url, "dash-worker", &[]);
    // While it runs, the worker is listed with the job it holds.
    let start = Instant::now();
    loop {
        let w = api.ok("/workers").await;
        if w["workers"][0]["jobs"][0]["campaign_id"] == json!(id) {
            assert_eq!(w["workers"][0]["name"], "dash-worker");
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "{w}");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    wait_for(
        Duration::from_secs(900),
        "the campaign done",
        || api.campaign(&id),
        |s| s["state"] == "done",
    )
    .await;
    assert!(worker.log_text().contains("job complete"));
    drop(worker);
    // A second campaign whose only job fails, so the page has an error to show.
    let failing = api
        .submit(&campaign("dashboard-failing", "[30]", 1, 2))
        .await;
    claim_and_fail(
        &api,
        "dash-probe",
        "impact 1: particle 42 moved more than h in one step",
    )
    .await;
    wait_for(
        Duration::from_secs(10),
        "failed",
        || api.campaign(&failing),
        |s| s["state"] == "failed",
    )
    .await;
    let results = api.ok(&format!("/campaigns/{id}/results")).await;
    let with_erosion = results["cells"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["erosion_mean"].is_number())
        .count();
    assert_eq!(with_erosion, 2, "both cells have an erosion: {results}");
    assert!(
        results["cells"]
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c["erosion_std"].is_number()),
        "both cells have a spread over their 2 samples: {results}"
    );

    let page = format!("{url}/#token={SUBMIT}");
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().unwrap();
    let full = run_chromium(dir.path(), &page, &["--dump-dom"]);
    std::fs::write(target.join("dashboard-dom.html"), &full).unwrap();
    // What the scripts rendered, without the script's own text.
    let dom = full.split("<script>").next().unwrap().to_string();
    let fail = |what: &str| -> ! {
        panic!("the rendered page lacks {what}; DOM:\n{dom}");
    };
    if !dom.contains(&id) || !dom.contains("dashboard-e2e") {
        fail("the campaign's id and name");
    }
    if !dom.contains(">done<") || !dom.contains("80 / 80 impacts") {
        fail("the campaign's state and progress");
    }
    if dom.contains("class=\"banner error\"") {
        fail("a page without an error banner (token refused, or API unreachable)");
    }
    let chart = dom
        .split("id=\"erosion-chart\"")
        .nth(1)
        .and_then(|rest| rest.split("</svg>").next())
        .unwrap_or_else(|| fail("the erosion chart"));
    if chart.matches("class=\"point\"").count() != 2 || !chart.contains("class=\"errbar\"") {
        fail("two erosion points with error bars");
    }
    // Twenty impacts leave the last-20 window starting at the first impact, before any
    // sample's incubation ends: such a cell is hollow, and the note under the chart says why.
    let unsteady: Vec<&serde_json::Value> = results["cells"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["steady_state"]["steady"] == json!(false))
        .collect();
    assert!(!unsteady.is_empty(), "20 impacts are not steady: {results}");
    if chart.matches("data-steady=\"false\"").count() != unsteady.len() {
        fail("one hollow point per unsteady cell");
    }
    let note = dom
        .split("id=\"steady-note\"")
        .nth(1)
        .and_then(|rest| rest.split("</div>").next())
        .unwrap_or_else(|| fail("the steady-state note"));
    for c in &unsteady {
        let reason = c["steady_state"]["reason"].as_str().unwrap();
        let shown = reason
            .replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;");
        if !note.contains("Hollow points: not at steady state or not balanced")
            || !note.contains(&shown)
        {
            fail(&format!("the note with the reason `{reason}`"));
        }
        assert!(reason.starts_with("reached max 20 impacts"), "{reason}");
    }
    if !note.contains(&format!("grit raise-caps {id} SPEC.json")) {
        fail("the hint that raising the cap runs the capped cells on");
    }
    if !dom.contains("dash-worker") {
        fail("the worker");
    }
    if !dom.contains("particle 42 moved more than h") || !dom.contains("dashboard-failing") {
        fail("the failed job and its error");
    }
    assert!(
        !full.contains(SUBMIT),
        "the token must not be written into the page"
    );

    let png = target.join("dashboard.png");
    let _ = std::fs::remove_file(&png);
    run_chromium(
        dir.path(),
        &page,
        &[
            &format!("--screenshot={}", png.display()),
            "--window-size=1280,1000",
        ],
    );
    let img = image::open(&png)
        .unwrap_or_else(|e| panic!("{}: not a PNG: {e}", png.display()))
        .to_rgb8();
    assert_eq!(img.dimensions(), (1280, 1000));
    let mut colours: Vec<[u8; 3]> = img.pixels().step_by(7).map(|p| p.0).collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(
        colours.len() > 50,
        "{} looks blank: {} colours",
        png.display(),
        colours.len()
    );
    eprintln!(
        "dashboard screenshot (via {chromium_path}): {}",
        png.display()
    );
}

#[tokio::test(flavor = "multi_thread")]
async fn chromium_shows_a_jet_campaign_with_its_charts() {
    chromium();
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let coord = start_coordinator(dir.path(), 3);
    let api = Api::new(&coord.url);
    // Two jet speeds, one sample of four 1 µs slices each, on the tiny jet scene.
    let id = api
        .submit(
            r#"{"scene": "jet", "name": "dashboard-jet", "samples": 1, "velocity_m_s": [400, 500],
                "spacing_m": 1e-4, "jet_width_m": 6e-4, "target_width_m": 3e-3,
                "target_depth_m": 8e-4, "standoff_m": 6e-4, "grain_diameter_m": 2e-4,
                "mass_flow_kg_s": 0.01, "time_ms": 0.004, "slice_ms": 0.001}"#,
        )
        .await;
    let worker = start_worker(dir.path(), &coord.url, "jet-worker", &[]);
    wait_for(
        Duration::from_secs(120),
        "the jet campaign done",
        || api.campaign(&id),
        |s| s["state"] == "done",
    )
    .await;
    drop(worker);
    let page = format!("{}/#token={SUBMIT}", coord.url);
    let full = run_chromium(dir.path(), &page, &["--dump-dom"]);
    let dom = full.split("<script>").next().unwrap().to_string();
    let fail = |what: &str| -> ! {
        panic!("the rendered page lacks {what}; DOM:\n{dom}");
    };
    if !dom.contains("dashboard-jet") || !dom.contains("8 / 8 slices") {
        fail("the jet campaign and its progress in slices");
    }
    if dom.contains("class=\"banner error\"") {
        fail("a page without an error banner");
    }
    if !dom.contains("id=\"impact-charts\" hidden") {
        fail("the impact charts hidden");
    }
    let chart = |id: &str| -> String {
        dom.split(&format!("id=\"{id}\""))
            .nth(1)
            .and_then(|rest| rest.split("</svg>").next())
            .unwrap_or_else(|| fail(id))
            .to_string()
    };
    if chart("jet-speed-chart").matches("class=\"point\"").count() != 2 {
        fail("Cd against jet speed with a point per cell");
    }
    for id in ["jet-depth-chart", "jet-width-chart", "jet-mass-chart"] {
        if !chart(id).contains("<polyline") {
            fail(&format!("a line in {id}"));
        }
    }
    for cell in 0..2 {
        if chart(&format!("jet-profile-chart-{cell}"))
            .matches("<polyline")
            .count()
            < 2
        {
            fail(&format!("profiles at several times for cell {cell}"));
        }
    }
    // Four slices are too few for the stage-3 window: the note says so for each cell.
    let note = dom
        .split("id=\"jet-note\"")
        .nth(1)
        .and_then(|rest| rest.split("</div>").next())
        .unwrap_or_else(|| fail("the stage-3 note"));
    if note.matches("only 4 slices").count() != 2 {
        fail("the stage-3 reason of both cells");
    }
}
