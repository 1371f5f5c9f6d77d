//! The coordinator's load test (`grit bench farm`): the coordinator alone under load. Clients
//! claim a job, send one heartbeat and complete it with a placeholder impact; nothing is
//! simulated (the only place in grit where a job does no simulation), so the figures are the
//! coordinator's own cost.

use std::time::{Duration, Instant};

use grit_erosion::campaign::{CampaignSpec, MAX_JOBS};
use grit_erosion::{ImpactOutcome, ImpactRecord};
use serde::Serialize;

use crate::api::{units, CompleteRequest, HeartbeatRequest};
use crate::client::{Client, ClientError};
use crate::db::{Store, Synchronous};
use crate::server::{self, Config, Secret};

/// Why the load test could not run.
#[derive(Debug, thiserror::Error)]
pub enum LoadTestError {
    /// A client count of zero, or none.
    #[error("--clients: every count must be at least 1")]
    Clients,
    /// The scratch folder could not be created.
    #[error("{path}: {source}")]
    Dir {
        /// The folder.
        path: std::path::PathBuf,
        /// What failed.
        source: std::io::Error,
    },
    /// The coordinator could not start.
    #[error("cannot start the coordinator: {0}")]
    Start(std::io::Error),
    /// The database failed.
    #[error(transparent)]
    Store(#[from] crate::Error),
    /// A client request failed.
    #[error(transparent)]
    Client(#[from] ClientError),
    /// A client task panicked or was cancelled.
    #[error("load-test client: {0}")]
    Task(#[from] tokio::task::JoinError),
}

/// Figures of one concurrency level.
#[derive(Debug, Clone, Serialize)]
pub struct LoadTestRow {
    /// Concurrent clients.
    pub clients: usize,
    /// Jobs claimed and completed.
    pub jobs: u64,
    /// Seconds measured.
    pub seconds: f64,
    /// Claims plus completions per second.
    pub claims_completions_per_s: f64,
    /// Median heartbeat latency, ms.
    pub heartbeat_p50_ms: f64,
    /// 99th-percentile heartbeat latency, ms.
    pub heartbeat_p99_ms: f64,
    /// Requests that failed (no answer, or an error status); a sound run has none.
    pub errors: u64,
}

/// Jobs queued per second measured: above any rate the coordinator reaches.
const JOBS_PER_S: f64 = 20_000.0;

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

/// Runs the load test for each client count, `seconds` each, on a fresh database in `dir`
/// whose commits are made durable as `synchronous` says.
pub async fn run(
    dir: &std::path::Path,
    clients: &[usize],
    seconds: f64,
    synchronous: Synchronous,
) -> Result<Vec<LoadTestRow>, LoadTestError> {
    if clients.is_empty() || clients.contains(&0) {
        return Err(LoadTestError::Clients);
    }
    std::fs::create_dir_all(dir).map_err(|source| LoadTestError::Dir {
        path: dir.to_path_buf(),
        source,
    })?;
    let db = dir.join(format!("bench-{}.db", uuid::Uuid::new_v4()));
    let store = Store::open_with(&db, Duration::from_secs(60), 3, synchronous).await?;
    let token = uuid::Uuid::new_v4().to_string();
    let config = Config {
        submit_token: Secret::new(Some(token.clone())),
        worker_token: Secret::new(Some(token.clone())),
        ..Config::default()
    };
    let running = server::start("127.0.0.1:0", store.clone(), config)
        .await
        .map_err(LoadTestError::Start)?;
    let base = format!("http://{}", running.addr);
    let mut rows = Vec::new();
    for &n in clients {
        // Enough jobs that the queue never runs dry during the measurement: a client that
        // finds it empty stops, and the level would under-report.
        let samples = ((seconds * JOBS_PER_S).ceil() as usize).clamp(20_000, MAX_JOBS);
        let spec = CampaignSpec::from_json(&format!(
            r#"{{"angles_deg": [90], "shapes": ["hexagon"], "impacts": 1, "samples": {samples},
                "allow_short_samples": true, "spacing_m": 25e-6}}"#
        ))
        .map_err(crate::Error::from)?;
        store.create_campaign(&spec, None).await?;
        let deadline = Instant::now() + Duration::from_secs_f64(seconds);
        let start = Instant::now();
        let mut tasks = Vec::new();
        for i in 0..n {
            let client = Client::new(&base, Secret::new(Some(token.clone())))?;
            tasks.push(tokio::spawn(client_loop(
                client,
                format!("bench-{i}"),
                deadline,
            )));
        }
        let mut jobs = 0;
        let mut errors = 0;
        let mut lat = Vec::new();
        let mut ran_dry = false;
        for t in tasks {
            let tally = t.await?;
            ran_dry |= tally.ran_dry;
            jobs += tally.jobs;
            errors += tally.errors;
            lat.extend(tally.heartbeat_ms);
        }
        let secs = start.elapsed().as_secs_f64();
        if ran_dry {
            tracing::warn!(
                clients = n,
                "the queue ran dry before the time was up: this level's rate is a lower bound"
            );
        }
        lat.sort_by(f64::total_cmp);
        let row = LoadTestRow {
            clients: n,
            jobs,
            seconds: secs,
            claims_completions_per_s: 2.0 * jobs as f64 / secs,
            heartbeat_p50_ms: percentile(&lat, 0.50),
            heartbeat_p99_ms: percentile(&lat, 0.99),
            errors,
        };
        tracing::info!(?row, "load-test level done");
        rows.push(row);
        // Drop the rest of the queue so the next level starts from the same state.
        for c in store.list_campaigns().await? {
            store.cancel(c.id).await?;
        }
    }
    running.stop().await;
    let _ = std::fs::remove_file(&db);
    let _ = std::fs::remove_file(db.with_extension("db-wal"));
    let _ = std::fs::remove_file(db.with_extension("db-shm"));
    Ok(rows)
}

/// What one simulated worker got done.
#[derive(Default)]
struct Tally {
    jobs: u64,
    errors: u64,
    heartbeat_ms: Vec<f64>,
    /// Found the queue empty and stopped early.
    ran_dry: bool,
}

/// Claims, heartbeats and completes jobs until `deadline`. A failed request is counted and
/// the worker moves on to its next claim (a job it dropped comes back when its lease
/// expires), so one error does not end the measurement.
async fn client_loop(client: Client, name: String, deadline: Instant) -> Tally {
    let mut t = Tally::default();
    let any_engine = crate::api::WorkerEngine::One("0".repeat(16));
    while Instant::now() < deadline {
        // The bench's campaigns are unpinned: any fingerprint claims them, and none is
        // computed inside the measured seconds.
        let job = match client.claim_with(&name, &any_engine).await {
            Ok(Some(job)) => job,
            Ok(None) => {
                t.ran_dry = true;
                break;
            }
            Err(e) => {
                t.errors += 1;
                tracing::debug!(error = %e, "load-test claim failed");
                // A pause, so a coordinator that refuses everything is not flooded.
                tokio::time::sleep(Duration::from_millis(10)).await;
                continue;
            }
        };
        let start = Instant::now();
        let beat = client
            .heartbeat(
                job.job_id,
                &HeartbeatRequest {
                    lease_id: job.lease_id,
                    units: vec![],
                    checkpoint: None,
                },
            )
            .await;
        if let Err(e) = beat {
            t.errors += 1;
            tracing::debug!(error = %e, "load-test heartbeat failed");
            continue;
        }
        t.heartbeat_ms.push(start.elapsed().as_secs_f64() * 1e3);
        // The load test submits impact campaigns only.
        let grain = serde_json::from_value::<grit_erosion::ImpactParams>(job.params.clone())
            .map_or(0.0, |p| p.grain_mass_kg_m());
        let record = placeholder_record(1, grain, 0.0);
        let done = client
            .complete(
                job.job_id,
                &CompleteRequest {
                    lease_id: job.lease_id,
                    units: units(&[record]),
                    checkpoint: None,
                },
            )
            .await;
        match done {
            Ok(()) => t.jobs += 1,
            Err(e) => {
                t.errors += 1;
                tracing::debug!(error = %e, "load-test completion failed");
            }
        }
    }
    t
}

/// The rows as a Markdown table.
pub fn table(rows: &[LoadTestRow]) -> String {
    let mut s = String::from(
        "| clients | jobs | claims+completions/s | heartbeat p50 (ms) | heartbeat p99 (ms) | errors |\n|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {:.0} | {:.2} | {:.2} | {} |\n",
            r.clients,
            r.jobs,
            r.claims_completions_per_s,
            r.heartbeat_p50_ms,
            r.heartbeat_p99_ms,
            r.errors
        ));
    }
    s
}

/// Impact `impact` as a worker would report it, with no simulation behind it: a grain of
/// `grain_mass_kg` removing `mass_loss_kg`, settled at once. The load test's jobs and the
/// store's tests report these.
pub(crate) fn placeholder_record(
    impact: u32,
    grain_mass_kg: f64,
    mass_loss_kg: f64,
) -> ImpactRecord {
    ImpactRecord {
        impact,
        grain_mass_kg,
        mass_loss_kg,
        orientation_rad: 0.0,
        aim_x_m: 0.0,
        outcome: ImpactOutcome {
            mass_loss_kg,
            removed_particles: 0,
            detached_kg: 0.0,
            detached_particles: 0,
            sim_time_s: 0.0,
            steps: 0,
            rebound_ratio: 0.0,
            settled: true,
            damage_added_kg: None,
        },
    }
}
