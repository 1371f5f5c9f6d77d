//! Faults a shared cluster throws at the farm, end to end with the real `grit` binary over
//! loopback and a fresh database per test: the coordinator killed with `kill -9` and
//! restarted on its database, the coordinator frozen (`SIGSTOP`) past a worker's request
//! timeout and past the lease, the coordinator's disk filling up, and checkpoint uploads cut
//! short, damaged or sent for the wrong job. Each campaign must still complete with impact
//! records bit-equal to `grit run`'s, each impact stored once.
//! docs/operations.md describes what an operator sees and does in each case.
//! Set TEST_LOG=1 to see the processes' logs.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use grit_erosion::{ImpactRecord, Sample};
use grit_farm::api::{CampaignStatus, Checkpoint, HeartbeatRequest, ReleaseRequest};
use grit_farm::{Client, Secret};
use serde_json::json;
use uuid::Uuid;

mod common;
use common::results::{assert_bitwise_equal, grit_run, raw_series};
use common::{
    start_coordinator, start_worker, submitter, wait_done, wait_for, Api, Proc, SERIAL, WORKER,
};

type Series = Vec<(u64, u64, Vec<ImpactRecord>)>;

/// The coarsest real scene at 60°.
fn campaign(samples: u32, impacts: u32) -> String {
    common::campaign("faults", "[60]", samples, impacts)
}

/// A worker that uploads a checkpoint with every impact, with `extra` flags.
fn worker(dir: &Path, url: &str, name: &str, extra: &[&str]) -> Proc {
    let mut args = vec!["--checkpoint-every", "1"];
    args.extend_from_slice(extra);
    start_worker(dir, url, name, &args)
}

/// Waits up to `limit` until at least `n` impacts are stored.
async fn wait_impacts(c: &Client, id: Uuid, n: u64, limit: Duration) -> CampaignStatus {
    let what = format!("{n} impacts");
    wait_for(limit, &what, || c.status(id), |s| s.impacts_done >= n).await
}

/// Fails unless every worker process is still running.
fn assert_alive(workers: &mut [&mut Proc]) {
    for w in workers.iter_mut() {
        assert!(
            w.child.try_wait().unwrap().is_none(),
            "a worker exited:\n{}",
            w.log_text()
        );
    }
}

/// Each job's stored impacts are exactly 1..=`planned`, in order: none lost, none twice.
fn assert_each_impact_once(farm: &Series, planned: u32) {
    for (cell, sample, records) in farm {
        let numbers: Vec<u32> = records.iter().map(|r| r.impact).collect();
        let expected: Vec<u32> = (1..=planned).collect();
        assert_eq!(numbers, expected, "cell {cell} sample {sample}");
    }
}

/// The stored series, their count per job, and their bits against `grit run` of `spec`.
async fn assert_matches_grit_run(c: &Client, id: Uuid, dir: &Path, spec: &str, planned: u32) {
    let farm = raw_series(&c.results_value(id, true).await.unwrap());
    assert_each_impact_once(&farm, planned);
    let local = raw_series(&grit_run(dir, spec, "local", true));
    assert_bitwise_equal(&farm, &local);
}

/// `kill -9` of the coordinator twice while two workers heartbeat and upload checkpoints;
/// each time it comes back on the same database and address and the workers carry on.
#[tokio::test(flavor = "multi_thread")]
async fn coordinator_killed_twice_mid_campaign_loses_and_repeats_nothing() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    // Workers finish the job they hold while the coordinator is down and deliver it on its
    // return, but claim no other: with more jobs than workers an outage moves the count by at
    // most two jobs (8 impacts), so the campaign is still running at the second kill.
    let spec = campaign(6, 4);
    let mut coord = start_coordinator(dir.path(), "a", "127.0.0.1:0", 30.0, &[], None);
    let url = coord.url.clone();
    // Workers know the coordinator by URL only, so it comes back on the same address.
    let listen = url.trim_start_matches("http://").to_string();
    let c = submitter(&url);
    let id = c.submit(&spec, None).await.unwrap().id;
    let mut w1 = worker(dir.path(), &url, "w1", &[]);
    let mut w2 = worker(dir.path(), &url, "w2", &[]);
    let limit = Duration::from_secs(120);
    for (round, (after, tag)) in [(2, "b"), (12, "c")].into_iter().enumerate() {
        let mid = wait_impacts(&c, id, after, limit).await;
        assert!(
            mid.impacts_done < mid.impacts_total,
            "round {round}: the campaign must still be running when the coordinator dies"
        );
        coord.proc.kill9();
        // Long enough for the workers to find it gone and start backing off.
        tokio::time::sleep(Duration::from_secs(2)).await;
        assert_alive(&mut [&mut w1, &mut w2]);
        coord = start_coordinator(dir.path(), tag, &listen, 30.0, &[], None);
        let now = c.status(id).await.unwrap();
        assert!(
            now.impacts_done >= mid.impacts_done,
            "round {round}: stored impacts survive the crash ({} then {})",
            mid.impacts_done,
            now.impacts_done
        );
    }
    let s = wait_done(&c, id, Duration::from_secs(180)).await;
    assert_eq!(s.impacts_done, s.impacts_total);
    assert_eq!(s.impacts_total, 24);
    assert_matches_grit_run(&c, id, dir.path(), &spec, 4).await;
    let logs = w1.log_text() + &w2.log_text();
    assert!(
        logs.contains("unreachable"),
        "the workers saw the coordinator gone:\n{logs}"
    );
    assert_alive(&mut [&mut w1, &mut w2]);
}

/// `SIGSTOP` of the coordinator, first past the worker's request timeout but within the
/// lease (the worker retries and keeps its job), then past the lease (the worker's next
/// report is refused with 409, it drops the job, claims it again and resumes from the
/// checkpoint); the records still equal `grit run`'s.
#[tokio::test(flavor = "multi_thread")]
async fn frozen_coordinator_keeps_workers_and_expired_leases_rerun_bit_for_bit() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    // Enough impacts that the job outlives the first freeze and the poll after it: during a
    // freeze each impact waits out a 1 s heartbeat timeout, after it the impacts run at full
    // speed (tens of milliseconds each at this spacing).
    let impacts = 40;
    let spec = campaign(1, impacts);
    // A 12 s lease is renewed every 4 s; a 5 s freeze spans at least one heartbeat (which
    // times out after 1 s) yet leaves the lease alive: the last renewal is at most 4 s
    // before the freeze and the next at most 4 s after it.
    let lease_s = 12.0;
    let coord = start_coordinator(dir.path(), "a", "127.0.0.1:0", lease_s, &[], None);
    let c = submitter(&coord.url);
    let id = c.submit(&spec, None).await.unwrap().id;
    let mut w = worker(dir.path(), &coord.url, "w1", &["--request-timeout-s", "1"]);
    let limit = Duration::from_secs(120);
    wait_impacts(&c, id, 1, limit).await;

    coord.proc.signal("STOP");
    tokio::time::sleep(Duration::from_secs(5)).await;
    coord.proc.signal("CONT");
    let s = c.status(id).await.unwrap();
    assert_eq!(s.jobs.leased, 1, "the job keeps its lease: {s:?}");
    let log = w.log_text();
    assert!(
        log.contains("unreachable"),
        "a request timed out during the freeze:\n{log}"
    );
    assert!(
        !log.contains("job dropped") && log.matches("job leased").count() == 1,
        "the worker kept its job:\n{log}"
    );
    assert_alive(&mut [&mut w]);

    let before = wait_impacts(&c, id, s.impacts_done + 1, limit).await;
    assert!(
        before.impacts_done < before.impacts_total,
        "the job must still be running when frozen again"
    );
    coord.proc.signal("STOP");
    tokio::time::sleep(Duration::from_secs_f64(lease_s + 2.0)).await;
    coord.proc.signal("CONT");
    let s = wait_done(&c, id, Duration::from_secs(180)).await;
    assert_eq!(s.impacts_done, impacts as u64);
    let log = w.log_text();
    assert!(
        log.contains("job dropped") && log.contains("409"),
        "the expired lease was refused with 409:\n{log}"
    );
    assert!(
        log.contains("resumed from checkpoint"),
        "the job was resumed from its checkpoint:\n{log}"
    );
    assert_alive(&mut [&mut w]);
    assert_matches_grit_run(&c, id, dir.path(), &spec, impacts).await;
}

/// The soft limit on the size of the files process `pid` writes (`RLIMIT_FSIZE`), set from
/// outside while it runs; `None` restores `was`. Returns the limit it had. No privilege is
/// needed to lower the soft limit of one's own process or to raise it back up to the hard one.
fn set_file_size_limit(
    pid: u32,
    bytes: Option<libc::rlim_t>,
    was: Option<libc::rlimit>,
) -> libc::rlimit {
    let pid = libc::pid_t::try_from(pid).unwrap();
    let mut old = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: both pointers are to live rlimit values for the duration of the call.
    let rc = unsafe { libc::prlimit(pid, libc::RLIMIT_FSIZE, std::ptr::null(), &mut old) };
    assert_eq!(
        rc,
        0,
        "prlimit reading RLIMIT_FSIZE of {pid}: {}",
        std::io::Error::last_os_error()
    );
    let new = libc::rlimit {
        rlim_cur: bytes.unwrap_or_else(|| was.expect("the limit to restore").rlim_cur),
        rlim_max: old.rlim_max,
    };
    // SAFETY: as above.
    let rc = unsafe { libc::prlimit(pid, libc::RLIMIT_FSIZE, &new, std::ptr::null_mut()) };
    assert_eq!(
        rc,
        0,
        "prlimit setting RLIMIT_FSIZE of {pid} to {bytes:?}: {}",
        std::io::Error::last_os_error()
    );
    old
}

/// The coordinator's disk refusing every write (its file-size limit lowered to 0 while it
/// runs, so each write fails with `EFBIG`, as a write over a disk quota fails with `EDQUOT`;
/// SQLite reports both as `SQLITE_IOERR_WRITE`): writes are refused with 503 naming the
/// cause, the workers retry, what was stored stays, and once writes succeed again the campaign
/// completes bit for bit. `SQLITE_FULL` itself (no space left) is the unit test
/// `a_full_database_is_503_and_recovers`. Needs no privilege, so it runs everywhere.
#[tokio::test(flavor = "multi_thread")]
async fn full_disk_refuses_writes_with_503_and_recovers_when_freed() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let spec = campaign(1, 6);
    let mut cmd = common::coordinator_command(dir.path(), "127.0.0.1:0", 30.0, &[], None);
    // The process must see EFBIG rather than die of the SIGXFSZ that comes with it.
    // SAFETY: only signal(2), async-signal-safe, runs between fork and exec.
    unsafe {
        use std::os::unix::process::CommandExt;
        cmd.pre_exec(|| {
            if libc::signal(libc::SIGXFSZ, libc::SIG_IGN) == libc::SIG_ERR {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let mut coord = common::start_coordinator_piped_log(dir.path(), "a", cmd);
    let c = submitter(&coord.url);
    let id = c.submit(&spec, None).await.unwrap().id;
    let mut w = worker(dir.path(), &coord.url, "w1", &[]);
    let limit = Duration::from_secs(120);
    wait_impacts(&c, id, 2, limit).await;
    let before = raw_series(&c.results_value(id, true).await.unwrap());

    let pid = coord.proc.child.id();
    let was = set_file_size_limit(pid, Some(0), None);
    // The worker's next report (an impact and its checkpoint) must be written.
    let start = Instant::now();
    while !(coord.proc.log_text().contains("refused the write") && w.log_text().contains("503")) {
        assert!(
            coord.proc.child.try_wait().unwrap().is_none(),
            "the coordinator died:\n{}",
            coord.proc.log_text()
        );
        assert!(
            start.elapsed() < Duration::from_secs(90),
            "no refused write seen.\ncoordinator:\n{}\nworker:\n{}",
            coord.proc.log_text(),
            w.log_text()
        );
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    let log = w.log_text();
    assert!(
        log.contains("SQLITE_IOERR_WRITE") && log.contains("nothing was stored"),
        "the 503 names the cause:\n{log}"
    );
    assert_alive(&mut [&mut w]);
    // Reads still work, and what was stored before is unchanged.
    let during = raw_series(&c.results_value(id, true).await.unwrap());
    assert_eq!(during.len(), before.len());
    for ((_, _, a), (_, _, b)) in before.iter().zip(&during) {
        assert!(
            b.len() >= a.len() && b[..a.len()] == a[..],
            "stored impacts changed"
        );
    }
    let stuck = c.status(id).await.unwrap();
    assert!(stuck.impacts_done < 6, "writes went on: {stuck:?}");

    set_file_size_limit(pid, None, Some(was));
    let s = wait_done(&c, id, Duration::from_secs(180)).await;
    assert_eq!(s.impacts_done, 6);
    assert_matches_grit_run(&c, id, dir.path(), &spec, 6).await;
    let out = Command::new("sqlite3")
        .arg(dir.path().join("farm.db"))
        .arg("PRAGMA integrity_check;")
        .output();
    // sqlite3 is not needed for the rest of the suite; where it is installed it must agree.
    if let Ok(out) = out {
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            !out.status.success() || text.trim() == "ok",
            "integrity_check: {text}"
        );
    }
    assert_alive(&mut [&mut w]);
}

/// An envelope of `bytes` for job `job` that keeps `meant`'s length and checksum, as when
/// the bytes were damaged on the way.
fn damaged(job: i64, meant: &Checkpoint, bytes: &[u8]) -> Checkpoint {
    Checkpoint {
        size_bytes: meant.size_bytes,
        sha256: meant.sha256.clone(),
        ..Checkpoint::from_bytes(job, meant.impacts_done, bytes)
    }
}

/// Checkpoint uploads cut short, with a flipped byte, or meant for another job, each sent by
/// the lease holder with the next impact: each is refused with a 422 naming the problem and
/// nothing of its request is stored. The next claim of the job hands out its last good
/// checkpoint, a worker resumes from it, and the records equal `grit run`'s.
#[tokio::test(flavor = "multi_thread")]
async fn corrupt_checkpoint_uploads_are_refused_and_the_last_good_one_is_resumed() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let spec = campaign(2, 3);
    let coord = start_coordinator(dir.path(), "a", "127.0.0.1:0", 60.0, &[], None);
    let c = submitter(&coord.url);
    let id = c.submit(&spec, None).await.unwrap().id;
    let wc = Client::new(&coord.url, Secret::new(Some(WORKER.into()))).unwrap();
    let a = wc.claim("tester").await.unwrap().expect("job a");
    let b = wc.claim("tester").await.unwrap().expect("job b");
    assert_ne!(a.job_id, b.job_id);

    // Job a's first two impacts, run here; the first is reported with its checkpoint.
    let params: grit_erosion::ImpactParams = serde_json::from_value(a.params.clone()).unwrap();
    let seed = a.seed;
    let (one, two) = tokio::task::spawn_blocking(move || {
        let mut s = Sample::new(params, seed).unwrap();
        s.run_next().unwrap();
        let one = s.clone();
        s.run_next().unwrap();
        (one, s)
    })
    .await
    .unwrap();
    let good = Checkpoint::of(a.job_id, &one);
    let hb = HeartbeatRequest {
        lease_id: a.lease_id,
        units: grit_farm::api::units(one.records()),
        checkpoint: Some(good.clone()),
    };
    assert_eq!(wc.heartbeat(a.job_id, &hb).await.unwrap().impacts_done, 1);

    let bytes = two.checkpoint();
    let next = Checkpoint::of(a.job_id, &two);
    let half = &bytes[..bytes.len() / 2];
    let mut flipped = bytes.clone();
    flipped[bytes.len() / 2] ^= 0x10;
    let b_params = serde_json::from_value(b.params.clone()).unwrap();
    let b_bytes = Sample::new(b_params, b.seed).unwrap().checkpoint();
    let uploads = [
        (
            "cut short in transit",
            damaged(a.job_id, &next, half),
            "checkpoint.data_b64",
            format!(
                "checkpoint truncated: {} of its {} bytes arrived",
                half.len(),
                bytes.len()
            ),
        ),
        (
            "cut short before its checksum was taken",
            Checkpoint::from_bytes(a.job_id, 2, half),
            "checkpoint.data_b64",
            "checkpoint: truncated".into(),
        ),
        (
            "a flipped byte",
            damaged(a.job_id, &next, &flipped),
            "checkpoint.sha256",
            "checkpoint checksum mismatch".into(),
        ),
        (
            "job b's checkpoint",
            Checkpoint::from_bytes(b.job_id, 0, &b_bytes),
            "checkpoint.job_id",
            format!(
                "the checkpoint belongs to job {}, not job {}",
                b.job_id, a.job_id
            ),
        ),
        (
            "job b's bytes labelled as job a's",
            Checkpoint::from_bytes(a.job_id, 0, &b_bytes),
            "checkpoint.data_b64",
            "belongs to another job".into(),
        ),
    ];
    let api = Api::new(&coord.url);
    for (what, ckpt, field, says) in &uploads {
        let body = json!({
            "lease_id": a.lease_id,
            "impacts": [two.records()[1]],
            "checkpoint": ckpt,
        });
        let path = format!("/worker/jobs/{}/heartbeat", a.job_id);
        let (status, answer) = api.post(&path, WORKER, &body).await;
        assert_eq!(status, 422, "{what}: {answer}");
        assert_eq!(answer["field"], *field, "{what}: {answer}");
        let error = answer["error"].as_str().unwrap();
        assert!(error.contains(says.as_str()), "{what}: {error}");
        // Nothing of the request was stored: not its impact either.
        let s = c.status(id).await.unwrap();
        assert_eq!(s.impacts_done, 1, "{what}: {s:?}");
    }
    // A release with a bad checkpoint is refused too, and the job stays leased.
    let (status, answer) = api
        .post(
            &format!("/worker/jobs/{}/release", a.job_id),
            WORKER,
            &json!({"lease_id": a.lease_id, "checkpoint": uploads[2].1}),
        )
        .await;
    assert_eq!(
        (status, answer["field"].as_str()),
        (422, Some("checkpoint.sha256"))
    );
    assert_eq!(c.status(id).await.unwrap().jobs.leased, 2);
    assert!(
        coord.proc.log_text().contains("checkpoint refused"),
        "{}",
        coord.proc.log_text()
    );

    // Both jobs back to the queue; the next claim of job a hands out its last good checkpoint.
    for (job, lease) in [(a.job_id, a.lease_id), (b.job_id, b.lease_id)] {
        let back = ReleaseRequest {
            lease_id: lease,
            units: vec![],
            checkpoint: None,
        };
        wc.release(job, &back).await.unwrap();
    }
    let again = wc.claim("tester").await.unwrap().expect("job a again");
    assert_eq!(again.job_id, a.job_id);
    assert_eq!(again.impacts_done, 1);
    let handed = again.checkpoint.clone().expect("a checkpoint");
    assert_eq!(
        serde_json::to_value(&handed).unwrap(),
        serde_json::to_value(&good).unwrap(),
        "the last good checkpoint is handed out"
    );
    let back = ReleaseRequest {
        lease_id: again.lease_id,
        units: vec![],
        checkpoint: None,
    };
    wc.release(a.job_id, &back).await.unwrap();

    let w = worker(dir.path(), &coord.url, "w1", &[]);
    let s = wait_done(&c, id, Duration::from_secs(180)).await;
    assert_eq!(s.impacts_done, 6);
    let log = w.log_text();
    assert!(
        log.contains("resumed from checkpoint"),
        "job a resumed from its checkpoint:\n{log}"
    );
    assert!(!log.contains("checkpoint unusable"), "{log}");
    assert_matches_grit_run(&c, id, dir.path(), &spec, 3).await;
}

/// A thousand simulated workers at once (`grit bench farm`): every request answered, none an
/// error, and the figures the operator reads are all there.
#[test]
fn a_thousand_workers_at_once_get_no_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_grit"))
        .args([
            "bench",
            "farm",
            "--clients",
            "1000",
            "--seconds",
            "3",
            "--json",
            "--dir",
        ])
        .arg(dir.path())
        .output()
        .expect("run grit bench farm");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let row = &rows[0];
    assert_eq!(row["clients"], 1000, "{rows}");
    assert_eq!(row["errors"], 0, "{rows}");
    assert!(
        row["claims_completions_per_s"].as_f64().unwrap() > 0.0,
        "{rows}"
    );
    assert!(row["heartbeat_p99_ms"].as_f64().unwrap() > 0.0, "{rows}");
}

/// `grit run` asleep: a process stopped (or a machine suspended) past the lease fails its own
/// jobs, since its workers cannot heartbeat. Running `grit run` again gives the failed jobs a
/// fresh round of attempts and ends with the same bits as a run that never failed.
#[tokio::test(flavor = "multi_thread")]
async fn grit_run_again_retries_jobs_failed_by_expired_leases() {
    let dir = tempfile::tempdir().unwrap();
    let spec_text = campaign(2, 2);
    let spec = grit_erosion::campaign::CampaignSpec::from_json(&spec_text).unwrap();
    let out = dir.path().join("asleep");
    std::fs::create_dir_all(&out).unwrap();
    {
        // The campaign as `grit run` stores it, with every lease expiring at once and three
        // attempts, like the embedded coordinator's.
        let store = grit_farm::Store::open(&out.join("grit.db"), Duration::from_millis(1), 3)
            .await
            .unwrap();
        let key = grit_farm::embedded::campaign_key(&spec).unwrap();
        let id = store.create_campaign(&spec, Some(&key)).await.unwrap().id;
        let mut failed = 0;
        for _ in 0..100 {
            store.claim("asleep").await.unwrap().expect("a queued job");
            tokio::time::sleep(Duration::from_millis(5)).await;
            store.reap_expired().await.unwrap();
            failed = store.status(id).await.unwrap().jobs.failed;
            if failed > 0 {
                break;
            }
        }
        assert_eq!(failed, 1, "one job failed by three expired leases");
    }
    let again = grit_run(dir.path(), &spec_text, "asleep", true);
    let clean = grit_run(dir.path(), &spec_text, "clean", true);
    assert_bitwise_equal(&raw_series(&again), &raw_series(&clean));
    assert_eq!(raw_series(&again).len(), 2, "both jobs ran");
}
