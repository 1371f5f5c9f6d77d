//! `grit run`: a coordinator on a SQLite file in the output folder, N local workers, a
//! progress bar, and the results JSON at the end. Running it again on the same folder with
//! the same campaign resumes where it stopped (the submit is idempotent on the spec).

use std::path::{Path, PathBuf};
use std::time::Duration;

use grit_erosion::campaign::CampaignSpec;
use indicatif::{ProgressBar, ProgressStyle};

use crate::api::{CampaignState, ResultsResponse};
use crate::client::Client;
use crate::db::Store;
use crate::server::{self, Config, Secret};
use crate::worker::{self, Stop, WorkerOptions};

/// Options of `grit run`.
#[derive(Debug, Clone)]
pub struct EmbeddedOptions {
    /// Output folder: `grit.db` and `results.json` go there.
    pub out: PathBuf,
    /// Local workers.
    pub workers: usize,
    /// Engine threads per worker; `None` splits the machine's cores among the workers.
    pub threads_per_worker: Option<usize>,
    /// Checkpoint every this many impacts.
    pub checkpoint_every: u32,
    /// Show the progress bar.
    pub progress: bool,
    /// Include every sample's per-impact series in results.json (as `?raw=true`).
    pub raw: bool,
}

/// What `grit run` produced.
#[derive(Debug)]
pub struct EmbeddedOutcome {
    /// Final state of the campaign.
    pub state: CampaignState,
    /// The results, as the results endpoint serves them.
    pub results: ResultsResponse,
    /// Where they were written.
    pub results_path: PathBuf,
}

/// FNV-1a, 64 bit: a stable digest of the spec, used as its idempotency key.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ *b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Writes `value` as pretty JSON to `path` through a temporary file, so a reader never sees
/// half a file.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> std::io::Result<()> {
    let tmp = path.with_extension("json.tmp");
    let mut text = serde_json::to_string_pretty(value).map_err(std::io::Error::other)?;
    text.push('\n');
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
}

/// Runs `spec` to the end (or until `stop`), writing `results.json` into `opts.out`.
pub async fn run(
    spec: &CampaignSpec,
    opts: &EmbeddedOptions,
    stop: Stop,
) -> Result<EmbeddedOutcome, String> {
    std::fs::create_dir_all(&opts.out).map_err(|e| format!("--out {}: {e}", opts.out.display()))?;
    let db_path = opts.out.join("grit.db");
    let store = Store::open(&db_path, Duration::from_secs(120), 3)
        .await
        .map_err(|e| format!("database {}: {e}", db_path.display()))?;
    // Nothing else uses this file, so leases left by an interrupted run are dead.
    store
        .requeue_all_leases()
        .await
        .map_err(|e| e.to_string())?;
    let spec_json = serde_json::to_string(spec).map_err(|e| e.to_string())?;
    let key = format!("grit-run:{:016x}", fnv1a(spec_json.as_bytes()));
    let created = store
        .create_campaign(spec, Some(&key))
        .await
        .map_err(|e| e.to_string())?;
    // Loopback only, with throwaway tokens: other local users cannot feed it results.
    let worker_token = uuid::Uuid::new_v4().to_string();
    let config = Config {
        submit_token: Secret::new(Some(uuid::Uuid::new_v4().to_string())),
        worker_token: Secret::new(Some(worker_token.clone())),
        ..Config::default()
    };
    let running = server::start("127.0.0.1:0", store.clone(), config)
        .await
        .map_err(|e| format!("cannot start the local coordinator: {e}"))?;
    let base = format!("http://{}", running.addr);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let workers = opts.workers.max(1);
    let threads = opts
        .threads_per_worker
        .unwrap_or_else(|| (cores / workers).max(1));
    let worker_stop = Stop::default();
    let mut handles = Vec::new();
    for i in 0..workers {
        let client = Client::new(&base, Secret::new(Some(worker_token.clone())))
            .map_err(|e| e.to_string())?;
        let wopts = WorkerOptions {
            name: format!("local-{i}"),
            threads: Some(threads),
            checkpoint_every: opts.checkpoint_every,
            idle_poll: Duration::from_millis(500),
            ..WorkerOptions::default()
        };
        handles.push(tokio::spawn(worker::run(
            client,
            wopts,
            worker_stop.clone(),
        )));
    }

    let bar = if opts.progress {
        ProgressBar::new(created.impacts_total)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} impacts  {msg}",
        )
        .expect("valid template"),
    );
    // Without a terminal (a log file, a batch job) the bar draws nothing: say the same in a
    // plain line now and then, so long campaigns still show progress.
    let plain = opts.progress && !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let started = std::time::Instant::now();
    let mut last_line: Option<std::time::Instant> = None;
    let state = loop {
        let status = store.status(created.id).await.map_err(|e| e.to_string())?;
        bar.set_position(status.impacts_done);
        let rate = status
            .rate_impacts_per_s
            .map_or("rate –".to_string(), |r| format!("{:.3} impacts/s", r));
        let eta = status.eta_s.map_or("ETA –".to_string(), |s| {
            format!(
                "ETA {}",
                indicatif::HumanDuration(Duration::from_secs_f64(s))
            )
        });
        bar.set_message(format!(
            "{rate}  {eta}  jobs {}/{} done{}",
            status.jobs.done,
            status.jobs.done
                + status.jobs.queued
                + status.jobs.leased
                + status.jobs.failed
                + status.jobs.cancelled,
            if status.jobs.failed > 0 {
                format!(", {} failed", status.jobs.failed)
            } else {
                String::new()
            }
        ));
        if plain && last_line.is_none_or(|t| t.elapsed() >= Duration::from_secs(30)) {
            last_line = Some(std::time::Instant::now());
            eprintln!(
                "[{:>6.0} s] {}/{} impacts  {}",
                started.elapsed().as_secs_f64(),
                status.impacts_done,
                status.impacts_total,
                bar.message()
            );
        }
        if status.state.is_final() {
            if let Some(e) = &status.last_error {
                bar.println(format!(
                    "job of cell {} sample {} failed: {}",
                    e.cell, e.sample, e.error
                ));
            }
            break status.state;
        }
        if stop.sleep(Duration::from_millis(500)).await {
            break status.state;
        }
    };
    worker_stop.trigger();
    for h in handles {
        match h.await {
            Ok(Ok(_)) => {}
            Ok(Err(e)) => bar.println(format!("worker stopped: {e}")),
            Err(e) => bar.println(format!("worker panicked: {e}")),
        }
    }
    bar.finish();
    let results = store
        .results(created.id, opts.raw)
        .await
        .map_err(|e| e.to_string())?;
    let results_path = opts.out.join("results.json");
    write_json(&results_path, &results).map_err(|e| format!("{}: {e}", results_path.display()))?;
    running.stop().await;
    Ok(EmbeddedOutcome {
        state,
        results,
        results_path,
    })
}
