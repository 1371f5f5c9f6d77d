//! The farm's long-running processes: `grit serve` (the coordinator) and `grit work` (a worker).

use std::io::Write;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{bail, Context};
use clap::Args;
use grit_farm::server::{self, Config};
use grit_farm::worker::{self, Stop, WorkerOptions};
use grit_farm::{Client, Store};

use super::campaign::Remote;
use super::output::say;
use super::{on_signals, read_token};

/// `grit serve`.
#[derive(Args, Debug)]
pub struct ServeArgs {
    /// SQLite database file (created if missing). Keep it on a local disk, not a network
    /// filesystem: SQLite's locking needs one.
    #[arg(long, env = "GRIT_DB", default_value = "grit.db")]
    pub db: PathBuf,
    /// Address to listen on; port 0 picks a free port (the bound address is printed).
    #[arg(long, env = "GRIT_LISTEN", default_value = "127.0.0.1:8080")]
    pub listen: String,
    /// Lease length in seconds; a worker that misses heartbeats this long loses its job.
    #[arg(long, env = "GRIT_LEASE_TTL_S", default_value_t = 120.0, value_parser = crate::cli::seconds)]
    pub lease_ttl_s: f64,
    /// Lost or failed leases after which a job stays failed.
    #[arg(long, env = "GRIT_MAX_ATTEMPTS", default_value_t = 3, value_parser = crate::cli::at_least_one)]
    pub max_attempts: u32,
    /// When a write is answered: `full` once flushed to the disk (survives a power loss), or
    /// `normal` once handed to the operating system (survives a killed coordinator, but an OS
    /// crash or power loss may undo the last answered writes; faster on a slow disk).
    #[arg(long, env = "GRIT_SYNCHRONOUS", default_value = "full")]
    pub synchronous: grit_farm::Synchronous,
    /// Token for submitting and reading campaigns.
    #[arg(long, env = "GRIT_SUBMIT_TOKEN", hide_env_values = true)]
    pub submit_token: Option<String>,
    /// File holding the submit token.
    #[arg(long, env = "GRIT_SUBMIT_TOKEN_FILE")]
    pub submit_token_file: Option<PathBuf>,
    /// Token for workers.
    #[arg(long, env = "GRIT_WORKER_TOKEN", hide_env_values = true)]
    pub worker_token: Option<String>,
    /// File holding the worker token.
    #[arg(long, env = "GRIT_WORKER_TOKEN_FILE")]
    pub worker_token_file: Option<PathBuf>,
    /// Largest campaign spec accepted, bytes (larger gets 413).
    #[arg(long, default_value_t = server::DEFAULT_SUBMIT_LIMIT, value_parser = crate::cli::body_bytes)]
    pub max_spec_bytes: usize,
    /// Largest worker request, bytes (heartbeats carry checkpoints).
    #[arg(long, default_value_t = server::DEFAULT_WORKER_LIMIT, value_parser = crate::cli::body_bytes)]
    pub max_worker_bytes: usize,
    /// Serve without tokens on a non-loopback address (anyone who can connect may submit
    /// and report results).
    #[arg(long)]
    pub insecure_no_auth: bool,
}

/// `grit work`.
#[derive(Args, Debug)]
pub struct WorkArgs {
    #[command(flatten)]
    pub remote: Remote,
    /// Engine threads (rayon pool size) of each job; default one (all cores with `--jobs 1`).
    #[arg(long, env = "GRIT_THREADS", value_parser = crate::cli::thread_count)]
    pub threads: Option<usize>,
    /// Jobs this process holds at once, each on its own lease and engine pool, reported to the
    /// coordinator as NAME/1 … NAME/N. Default: the machine's cores divided by `--threads`, so
    /// one process serves all of a machine's cores with one job per core (a farm's throughput
    /// is one job per core: docs/performance.md).
    #[arg(long, env = "GRIT_JOBS", value_parser = crate::cli::thread_count)]
    pub jobs: Option<usize>,
    /// Upload a checkpoint every this many impacts.
    #[arg(long, default_value_t = 5, value_parser = crate::cli::at_least_one)]
    pub checkpoint_every: u32,
    /// Name reported to the coordinator (default host:pid).
    #[arg(long)]
    pub name: Option<String>,
    /// Exit when the queue is empty instead of waiting for more jobs.
    #[arg(long)]
    pub exit_when_idle: bool,
    /// Seconds between claims while the queue is empty.
    #[arg(long, default_value_t = 5.0, value_parser = crate::cli::seconds)]
    pub poll_s: f64,
    /// Seconds a request to the coordinator may take before the worker gives up on it and
    /// retries (a stalled coordinator holds requests open); must cover a checkpoint upload.
    #[arg(long, env = "GRIT_REQUEST_TIMEOUT_S", default_value_t = grit_farm::client::DEFAULT_REQUEST_TIMEOUT.as_secs_f64(), value_parser = crate::cli::seconds)]
    pub request_timeout_s: f64,
}

/// `grit serve`: the coordinator until SIGTERM or SIGINT.
pub async fn serve(a: ServeArgs) -> anyhow::Result<ExitCode> {
    if !(a.lease_ttl_s.is_finite() && a.lease_ttl_s >= 0.5) {
        bail!("--lease-ttl-s must be at least 0.5, got {}", a.lease_ttl_s);
    }
    let submit_token = read_token(a.submit_token, a.submit_token_file, "submit-token")?;
    let worker_token = read_token(a.worker_token, a.worker_token_file, "worker-token")?;
    let loopback = a
        .listen
        .parse::<SocketAddr>()
        .is_ok_and(|s| s.ip().is_loopback())
        || a.listen.starts_with("localhost:");
    if submit_token.expose().is_some() && submit_token.expose() == worker_token.expose() {
        bail!("the submit and worker tokens are the same: a worker could then submit and cancel campaigns; give each role its own");
    }
    let missing = submit_token.expose().is_none() || worker_token.expose().is_none();
    if missing && !loopback && !a.insecure_no_auth {
        bail!("set GRIT_SUBMIT_TOKEN and GRIT_WORKER_TOKEN (or --*-token-file) before listening on a non-loopback address, or pass --insecure-no-auth");
    }
    if missing {
        tracing::warn!("a token is not set: its endpoints accept anyone who can connect");
    }
    let mut store = Store::open_with(
        &a.db,
        Duration::from_secs_f64(a.lease_ttl_s),
        a.max_attempts,
        a.synchronous,
    )
    .await
    .with_context(|| format!("--db {}", a.db.display()))?;
    // New campaigns are pinned to the engine this coordinator computes, unless their spec
    // names one.
    store.own = grit_farm::OwnEngine {
        engines: grit_erosion::scene::engines::<grit_erosion::Scenes>()
            .context("engine fingerprint")?,
        commit: Some(env!("GRIT_COMMIT").to_string()),
    };
    tracing::info!(engines = ?store.own.engines, "new campaigns are pinned to these engines");
    let config = Config {
        submit_token,
        worker_token,
        submit_limit: a.max_spec_bytes,
        worker_limit: a.max_worker_bytes,
    };
    let running = server::start(&a.listen, store, config)
        .await
        .with_context(|| format!("--listen {}", a.listen))?;
    // Tests and scripts read the bound address (port 0 resolved) from this line.
    say!("grit coordinator listening on http://{}", running.addr);
    let _ = std::io::stdout().flush();
    tracing::info!(addr = %running.addr, db = %a.db.display(), "coordinator started");
    let stop = Stop::default();
    on_signals(stop.clone());
    while !stop.sleep(Duration::from_secs(3600)).await {}
    running.stop().await;
    Ok(ExitCode::SUCCESS)
}

/// `grit work`: leases and runs jobs until stopped (or idle with `--exit-when-idle`).
pub async fn work(a: WorkArgs) -> anyhow::Result<ExitCode> {
    let token = read_token(a.remote.token, a.remote.token_file, "token")?;
    let client = Client::with_timeout(
        &a.remote.coordinator,
        token,
        Duration::from_secs_f64(a.request_timeout_s),
    )?;
    let name = a.name.unwrap_or_else(worker::default_name);
    // Samples are independent and parallelise better than the threads inside one impact, so
    // by default every core runs a job of its own on one engine thread.
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let jobs = a
        .jobs
        .unwrap_or_else(|| (cores / a.threads.unwrap_or(1)).max(1));
    let threads = a.threads.or((jobs > 1).then_some(1));
    let stop = Stop::default();
    on_signals(stop.clone());
    tracing::info!(coordinator = %client.base(), %name, jobs = jobs, "worker started");
    let loops: Vec<_> = (1..=jobs)
        .map(|k| {
            let opts = WorkerOptions {
                name: if jobs > 1 {
                    format!("{name}/{k}")
                } else {
                    name.clone()
                },
                threads,
                checkpoint_every: a.checkpoint_every,
                exit_when_idle: a.exit_when_idle,
                idle_poll: Duration::from_secs_f64(a.poll_s),
                ..WorkerOptions::default()
            };
            tokio::spawn(worker::run(client.clone(), opts, stop.clone()))
        })
        .collect();
    let (mut jobs, mut units) = (0, 0);
    let mut failed = None;
    for l in loops {
        match l.await.context("worker loop panicked")? {
            Ok(s) => {
                jobs += s.jobs_done;
                units += s.units;
            }
            Err(e) => {
                // One loop refused (a bad token): stop the others too.
                stop.trigger();
                failed.get_or_insert(e);
            }
        }
    }
    tracing::info!(jobs, units, "worker stopped");
    if let Some(e) = failed {
        return Err(e.into());
    }
    Ok(ExitCode::SUCCESS)
}
