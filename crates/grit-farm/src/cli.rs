//! The farm's subcommands of `grit`: serve, work, run, submit, status, results, cancel,
//! retry-failed, bench farm. `main.rs` flattens `FarmCommand` into its own command list.

use std::io::Write;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use clap::{Args, Subcommand};
use grit_erosion::campaign::CampaignSpec;
use grit_erosion::stability::StabilityGrid;
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use uuid::Uuid;

use crate::api::CampaignState;
use crate::client::{Client, ClientError};
use crate::db::Store;
use crate::server::{self, Config, Secret};
use crate::worker::{self, Stop, WorkerOptions};

/// A failed command: the message is printed, the process exits non-zero.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct CliError(pub String);

impl From<ClientError> for CliError {
    fn from(e: ClientError) -> Self {
        CliError(e.to_string())
    }
}

type CliResult = Result<ExitCode, CliError>;

/// `println!` that ignores a closed stdout (`grit status --json | head`) instead of panicking.
macro_rules! say {
    ($($t:tt)*) => {{
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

/// Subcommands of the job farm.
#[derive(Subcommand, Debug)]
pub enum FarmCommand {
    /// Run the coordinator: REST API under /api/v1 on a SQLite database.
    Serve(ServeArgs),
    /// Run a worker: lease jobs from a coordinator and simulate their impacts.
    Work(WorkArgs),
    /// Run a whole campaign on this machine (coordinator + local workers) and write results.
    Run(RunArgs),
    /// Submit a campaign spec; prints the campaign id alone on the last line.
    Submit(SubmitArgs),
    /// Show a campaign's progress (or every campaign without an id).
    Status(StatusArgs),
    /// Fetch a campaign's aggregated results (partial while it runs).
    Results(ResultsArgs),
    /// Cancel a campaign: no more jobs are handed out; running workers drop theirs.
    Cancel(IdArgs),
    /// Put a campaign's failed jobs back in the queue.
    RetryFailed(IdArgs),
    /// Benchmarks of the farm.
    Bench(BenchArgs),
}

fn read_token(
    value: Option<String>,
    file: Option<PathBuf>,
    flag: &str,
) -> Result<Secret, CliError> {
    match (value, file) {
        (Some(_), Some(_)) => Err(CliError(format!(
            "give --{flag} or --{flag}-file, not both"
        ))),
        (Some(v), None) => Ok(Secret::new(Some(v))),
        (None, Some(p)) => std::fs::read_to_string(&p)
            .map(|t| Secret::new(Some(t)))
            .map_err(|e| CliError(format!("--{flag}-file {}: {e}", p.display()))),
        (None, None) => Ok(Secret::default()),
    }
}

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
    #[arg(long, env = "GRIT_LEASE_TTL_S", default_value_t = 120.0)]
    pub lease_ttl_s: f64,
    /// Lost or failed leases after which a job stays failed.
    #[arg(long, env = "GRIT_MAX_ATTEMPTS", default_value_t = 3)]
    pub max_attempts: u32,
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
    #[arg(long, default_value_t = server::DEFAULT_SUBMIT_LIMIT)]
    pub max_spec_bytes: usize,
    /// Largest worker request, bytes (heartbeats carry checkpoints).
    #[arg(long, default_value_t = server::DEFAULT_WORKER_LIMIT)]
    pub max_worker_bytes: usize,
    /// Serve without tokens on a non-loopback address (anyone who can connect may submit
    /// and report results).
    #[arg(long)]
    pub insecure_no_auth: bool,
}

/// `grit work`.
#[derive(Args, Debug)]
pub struct WorkArgs {
    /// Coordinator base URL.
    #[arg(
        long,
        env = "GRIT_COORDINATOR",
        default_value = "http://127.0.0.1:8080"
    )]
    pub coordinator: String,
    /// Worker token.
    #[arg(long, env = "GRIT_TOKEN", hide_env_values = true)]
    pub token: Option<String>,
    /// File holding the worker token.
    #[arg(long, env = "GRIT_TOKEN_FILE")]
    pub token_file: Option<PathBuf>,
    /// Engine threads (rayon pool size); default all cores.
    #[arg(long, env = "GRIT_THREADS")]
    pub threads: Option<usize>,
    /// Upload a checkpoint every this many impacts.
    #[arg(long, default_value_t = 5)]
    pub checkpoint_every: u32,
    /// Name reported to the coordinator (default host:pid).
    #[arg(long)]
    pub name: Option<String>,
    /// Exit when the queue is empty instead of waiting for more jobs.
    #[arg(long)]
    pub exit_when_idle: bool,
    /// Seconds between claims while the queue is empty.
    #[arg(long, default_value_t = 5.0)]
    pub poll_s: f64,
}

/// `grit run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Campaign spec JSON (issue 3); `-` reads standard input.
    pub campaign: PathBuf,
    /// Local workers (default: one per core, each with one engine thread, since samples
    /// are independent and parallelise better than the threads inside one impact).
    #[arg(long)]
    pub workers: Option<usize>,
    /// Engine threads per worker (default: cores / workers).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Output folder: grit.db (resumable) and results.json.
    #[arg(long, default_value = "out/run")]
    pub out: PathBuf,
    /// Checkpoint every this many impacts.
    #[arg(long, default_value_t = 5)]
    pub checkpoint_every: u32,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Include every sample's per-impact series in results.json (as `results --raw`).
    #[arg(long)]
    pub raw: bool,
}

/// Where the coordinator is and how to authenticate, for client commands.
#[derive(Args, Debug)]
pub struct Remote {
    /// Coordinator base URL.
    #[arg(
        long,
        env = "GRIT_COORDINATOR",
        default_value = "http://127.0.0.1:8080"
    )]
    pub coordinator: String,
    /// Submit token.
    #[arg(long, env = "GRIT_TOKEN", hide_env_values = true)]
    pub token: Option<String>,
    /// File holding the token.
    #[arg(long, env = "GRIT_TOKEN_FILE")]
    pub token_file: Option<PathBuf>,
}

impl Remote {
    fn client(self) -> Result<Client, CliError> {
        let token = read_token(self.token, self.token_file, "token")?;
        Ok(Client::new(&self.coordinator, token)?)
    }
}

/// `grit submit`.
#[derive(Args, Debug)]
pub struct SubmitArgs {
    /// Campaign spec JSON; `-` reads standard input.
    pub file: PathBuf,
    /// Idempotency key: submitting again with the same key returns the same campaign.
    #[arg(long)]
    pub idempotency_key: Option<String>,
    #[command(flatten)]
    remote: Remote,
}

/// `grit status`.
#[derive(Args, Debug)]
pub struct StatusArgs {
    /// Campaign id; without it, every campaign is listed.
    pub id: Option<String>,
    /// Refresh with progress bars until the campaign ends.
    #[arg(long)]
    pub watch: bool,
    /// Print the status JSON of the API.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    remote: Remote,
}

/// `grit results`.
#[derive(Args, Debug)]
pub struct ResultsArgs {
    /// Campaign id.
    pub id: String,
    /// Write to this file instead of standard output.
    #[arg(short = 'o', long)]
    pub output: Option<PathBuf>,
    /// Include every sample's per-impact series.
    #[arg(long)]
    pub raw: bool,
    #[command(flatten)]
    remote: Remote,
}

/// A campaign id and the coordinator.
#[derive(Args, Debug)]
pub struct IdArgs {
    /// Campaign id.
    pub id: String,
    #[command(flatten)]
    remote: Remote,
}

/// `grit bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(subcommand)]
    what: BenchWhat,
}

#[derive(Subcommand, Debug)]
enum BenchWhat {
    /// The coordinator alone: claims+completions/s at several client counts and heartbeat
    /// latency, with jobs that do no simulation.
    Farm {
        /// Concurrent clients, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = vec![1, 8, 64])]
        clients: Vec<usize>,
        /// Seconds per client count.
        #[arg(long, default_value_t = 5.0)]
        seconds: f64,
        /// Folder for the scratch database.
        #[arg(long, default_value = "target/bench-farm")]
        dir: PathBuf,
        /// Print JSON rows instead of a Markdown table.
        #[arg(long)]
        json: bool,
    },
    /// One impact of the reference scene (hexagon, 45°, 100 m/s, AISI 304, 8 µm) timed on 1
    /// thread and on N threads from the same surface: particle-steps per second and stages.
    Impact {
        #[command(flatten)]
        scene: ImpactScene,
        /// Threads of the timed run (1 is always timed too).
        #[arg(long, default_value_t = 2)]
        threads: usize,
        /// Alternate the 1-thread and the N-thread run this many times and report medians.
        #[arg(long, default_value_t = 1)]
        repeat: usize,
        /// Print the figures as JSON.
        #[arg(long)]
        json: bool,
    },
    /// The speed–accuracy sweep: erosion of the hexagon (samples × impacts) and the Hertz p0
    /// error at several resolutions and numerical variants, against wall time per impact.
    /// Writes OUT/sweep.{csv,json} and the chart OUT/speed-accuracy.{png,svg}, and names the
    /// cheapest setting within the finest's error bars.
    Sweep {
        /// Impact angle (degrees).
        #[arg(long, default_value_t = 45.0)]
        angle: f64,
        /// Resolutions, particles per grain diameter, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = vec![8.0, 12.0, 16.0, 24.0, 32.0])]
        ppd: Vec<f64>,
        /// Numerical variants (seed, wendland_c2, full_flight, cfl=X, absorbing=N), comma-separated; the
        /// first is the reference.
        #[arg(long, value_delimiter = ',', default_values_t = vec!["seed".to_string(), "wendland_c2".to_string()])]
        variants: Vec<String>,
        /// Resolutions of the variants after the first (default: all of --ppd).
        #[arg(long, value_delimiter = ',')]
        variant_ppd: Vec<f64>,
        /// Samples per point.
        #[arg(long, default_value_t = 5)]
        samples: u32,
        /// Impacts per sample.
        #[arg(long, default_value_t = 30)]
        impacts: u32,
        /// Seed of sample 0; sample k uses seed + k.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Width of the band of aim points (Dg); the reduced campaign's 0.5 by default.
        #[arg(long, default_value_t = 0.5)]
        range_dg: f64,
        /// Surface width (Dg); the reduced campaign's 2.5 (checked by its domain study).
        #[arg(long, default_value_t = 2.5)]
        width_dg: f64,
        /// Surface depth (Dg); the reduced campaign's 1.25.
        #[arg(long, default_value_t = 1.25)]
        depth_dg: f64,
        /// Output folder.
        #[arg(long, default_value = "out/sweep")]
        out: PathBuf,
        /// Keep the points already in OUT/sweep.json and run only the missing ones.
        #[arg(long)]
        resume: bool,
        /// Threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// The stability map: one impact with the Courant number swept against the hourglass
    /// coefficient, and the contact stiffness against the time step for both contact models;
    /// each point stable or with the engine's diagnostic. Writes OUT/stability.{csv,json,png,svg}.
    Stability {
        /// Impact angle (degrees).
        #[arg(long, default_value_t = 45.0)]
        angle: f64,
        /// Particle spacing Δx (m): 1.5625e-5 is 16 particles per Dg.
        #[arg(long, default_value_t = 1.5625e-5)]
        spacing_m: f64,
        /// Impacts the surface takes (with the default numerics) before the mapped one.
        #[arg(long, default_value_t = 0)]
        after: u32,
        /// Seed of the sample the grain comes from.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Courant numbers, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = StabilityGrid::default().cfl)]
        cfl: Vec<f64>,
        /// Hourglass coefficients α, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = StabilityGrid::default().hourglass)]
        hourglass: Vec<f64>,
        /// Contact stiffness over the default k, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = StabilityGrid::default().stiffness_scale)]
        stiffness: Vec<f64>,
        /// A point is stopped as collapsed after this many times the steps the longest impact
        /// takes at its first step's dt.
        #[arg(long, default_value_t = 3.0)]
        budget: f64,
        /// Output folder.
        #[arg(long, default_value = "out/stability")]
        out: PathBuf,
        /// Threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
    },
}

fn init_tracing(default: &str) {
    let filter = tracing_subscriber::EnvFilter::try_from_env("RUST_LOG")
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .try_init();
}

fn runtime() -> Result<tokio::runtime::Runtime, CliError> {
    tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|e| CliError(format!("cannot start the async runtime: {e}")))
}

/// SIGTERM or SIGINT triggers `stop`; a second signal exits at once.
fn on_signals(stop: Stop) {
    tokio::spawn(async move {
        #[cfg(unix)]
        {
            use tokio::signal::unix::{signal, SignalKind};
            let (Ok(mut term), Ok(mut int)) = (
                signal(SignalKind::terminate()),
                signal(SignalKind::interrupt()),
            ) else {
                return;
            };
            tokio::select! { _ = term.recv() => {}, _ = int.recv() => {} }
            tracing::info!("stop requested; finishing up (signal again to exit at once)");
            stop.trigger();
            tokio::select! { _ = term.recv() => {}, _ = int.recv() => {} }
            std::process::exit(130);
        }
        #[cfg(not(unix))]
        {
            let _ = tokio::signal::ctrl_c().await;
            stop.trigger();
        }
    });
}

fn read_spec_text(path: &Path) -> Result<String, CliError> {
    if path == Path::new("-") {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut std::io::stdin(), &mut s)
            .map_err(|e| CliError(format!("stdin: {e}")))?;
        return Ok(s);
    }
    std::fs::read_to_string(path).map_err(|e| CliError(format!("{}: {e}", path.display())))
}

fn parse_id(s: &str) -> Result<Uuid, CliError> {
    s.parse()
        .map_err(|_| CliError(format!("campaign id `{s}` is not a uuid")))
}

/// Runs one farm subcommand.
pub fn dispatch(cmd: FarmCommand) -> CliResult {
    let rt = runtime()?;
    match cmd {
        FarmCommand::Serve(a) => {
            init_tracing("info");
            rt.block_on(serve(a))
        }
        FarmCommand::Work(a) => {
            init_tracing("info");
            rt.block_on(work(a))
        }
        FarmCommand::Run(a) => {
            init_tracing("warn");
            rt.block_on(run(a))
        }
        FarmCommand::Submit(a) => {
            init_tracing("warn");
            rt.block_on(submit(a))
        }
        FarmCommand::Status(a) => {
            init_tracing("warn");
            rt.block_on(status(a))
        }
        FarmCommand::Results(a) => {
            init_tracing("warn");
            rt.block_on(results(a))
        }
        FarmCommand::Cancel(a) => {
            init_tracing("warn");
            rt.block_on(async {
                let id = parse_id(&a.id)?;
                let r = a.remote.client()?.cancel(id).await?;
                say!("cancelled {id}: {} jobs stopped", r.jobs);
                Ok(ExitCode::SUCCESS)
            })
        }
        FarmCommand::RetryFailed(a) => {
            init_tracing("warn");
            rt.block_on(async {
                let id = parse_id(&a.id)?;
                let r = a.remote.client()?.retry_failed(id).await?;
                say!("{id}: {} failed jobs queued again", r.jobs);
                Ok(ExitCode::SUCCESS)
            })
        }
        FarmCommand::Bench(a) => {
            init_tracing("warn");
            rt.block_on(bench(a))
        }
    }
}

async fn serve(a: ServeArgs) -> CliResult {
    if !(a.lease_ttl_s.is_finite() && a.lease_ttl_s >= 0.5) {
        return Err(CliError(format!(
            "--lease-ttl-s must be at least 0.5, got {}",
            a.lease_ttl_s
        )));
    }
    let submit_token = read_token(a.submit_token, a.submit_token_file, "submit-token")?;
    let worker_token = read_token(a.worker_token, a.worker_token_file, "worker-token")?;
    let loopback = a
        .listen
        .parse::<SocketAddr>()
        .is_ok_and(|s| s.ip().is_loopback())
        || a.listen.starts_with("localhost:");
    let missing = submit_token.expose().is_none() || worker_token.expose().is_none();
    if missing && !loopback && !a.insecure_no_auth {
        return Err(CliError(
            "set GRIT_SUBMIT_TOKEN and GRIT_WORKER_TOKEN (or --*-token-file) before listening on a non-loopback address, or pass --insecure-no-auth".into(),
        ));
    }
    if missing {
        tracing::warn!("a token is not set: its endpoints accept anyone who can connect");
    }
    let store = Store::open(
        &a.db,
        Duration::from_secs_f64(a.lease_ttl_s),
        a.max_attempts,
    )
    .await
    .map_err(|e| CliError(format!("--db {}: {e}", a.db.display())))?;
    let config = Config {
        submit_token,
        worker_token,
        submit_limit: a.max_spec_bytes,
        worker_limit: a.max_worker_bytes,
    };
    let running = server::start(&a.listen, store, config)
        .await
        .map_err(|e| CliError(format!("--listen {}: {e}", a.listen)))?;
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

async fn work(a: WorkArgs) -> CliResult {
    let token = read_token(a.token, a.token_file, "token")?;
    let client = Client::new(&a.coordinator, token)?;
    if a.checkpoint_every == 0 {
        return Err(CliError("--checkpoint-every must be at least 1".into()));
    }
    if !(a.poll_s.is_finite() && a.poll_s > 0.0) {
        return Err(CliError("--poll-s must be > 0".into()));
    }
    let opts = WorkerOptions {
        name: a.name.unwrap_or_else(worker::default_name),
        threads: a.threads,
        checkpoint_every: a.checkpoint_every,
        exit_when_idle: a.exit_when_idle,
        idle_poll: Duration::from_secs_f64(a.poll_s),
        ..WorkerOptions::default()
    };
    let stop = Stop::default();
    on_signals(stop.clone());
    tracing::info!(coordinator = %client.base(), name = %opts.name, "worker started");
    let summary = worker::run(client, opts, stop)
        .await
        .map_err(|e| CliError(e.to_string()))?;
    tracing::info!(
        jobs = summary.jobs_done,
        impacts = summary.impacts,
        "worker stopped"
    );
    Ok(ExitCode::SUCCESS)
}

async fn run(a: RunArgs) -> CliResult {
    let text = read_spec_text(&a.campaign)?;
    let spec = CampaignSpec::from_json(&text)
        .and_then(|s| s.validate().map(|_| s))
        .map_err(|e| CliError(format!("{}: {e}", a.campaign.display())))?;
    let opts = crate::embedded::EmbeddedOptions {
        out: a.out.clone(),
        workers: a
            .workers
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        threads_per_worker: a.threads,
        checkpoint_every: a.checkpoint_every.max(1),
        progress: !a.quiet,
        raw: a.raw,
    };
    let stop = Stop::default();
    on_signals(stop.clone());
    let outcome = crate::embedded::run(&spec, &opts, stop)
        .await
        .map_err(CliError)?;
    eprintln!(
        "campaign {:?}; results in {}",
        outcome.state,
        outcome.results_path.display()
    );
    for c in &outcome.results.results.cells {
        let fmt = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{x:.4e}"));
        say!(
            "{:>6.1}°  {:<10} samples {:>3}  erosion {} ± {}",
            c.angle_deg,
            c.shape,
            c.samples,
            fmt(c.erosion_mean),
            fmt(c.erosion_std)
        );
    }
    // Charts beside results.json (`grit plot` draws the same); a chart that fails leaves
    // the results, already written, standing.
    match grit_plot::plot_file(&outcome.results_path, &a.out) {
        Ok(r) => eprintln!(
            "{} chart files (PNG, SVG) in {}",
            r.files.len(),
            a.out.display()
        ),
        Err(e) => eprintln!("charts not written: {e}"),
    }
    Ok(match outcome.state {
        CampaignState::Done => ExitCode::SUCCESS,
        _ => ExitCode::from(1),
    })
}

async fn submit(a: SubmitArgs) -> CliResult {
    let text = read_spec_text(&a.file)?;
    let client = a.remote.client()?;
    let created = client
        .submit(&text, a.idempotency_key.as_deref())
        .await
        .map_err(|e| match e {
            ClientError::Status { message, .. } => {
                CliError(format!("{}: {message}", a.file.display()))
            }
            other => other.into(),
        })?;
    eprintln!(
        "{} campaign: {} jobs, {} impacts",
        if created.created {
            "submitted"
        } else {
            "already submitted"
        },
        created.jobs,
        created.impacts_total
    );
    say!("{}", created.id);
    Ok(ExitCode::SUCCESS)
}

fn fmt_eta(s: Option<f64>) -> String {
    s.map_or("–".into(), |s| {
        indicatif::HumanDuration(Duration::from_secs_f64(s.max(0.0))).to_string()
    })
}

async fn status(a: StatusArgs) -> CliResult {
    let json = a.json;
    let client = a.remote.client()?;
    let Some(id) = a.id.as_deref() else {
        let list = client.list().await?;
        if json {
            say!(
                "{}",
                serde_json::to_string_pretty(&list).expect("serialises")
            );
        } else {
            for c in list {
                say!(
                    "{}  {:<9}  {}/{} impacts  {}",
                    c.id,
                    format!("{:?}", c.state).to_lowercase(),
                    c.impacts_done,
                    c.impacts_total,
                    c.name.unwrap_or_default()
                );
            }
        }
        return Ok(ExitCode::SUCCESS);
    };
    let id = parse_id(id)?;
    if !a.watch {
        let s = client.status(id).await?;
        if json {
            say!("{}", serde_json::to_string_pretty(&s).expect("serialises"));
        } else {
            say!(
                "{}  {}  {}/{} impacts  jobs: {} queued, {} leased, {} done, {} failed, {} cancelled  rate {}  ETA {}",
                s.id,
                format!("{:?}", s.state).to_lowercase(),
                s.impacts_done,
                s.impacts_total,
                s.jobs.queued,
                s.jobs.leased,
                s.jobs.done,
                s.jobs.failed,
                s.jobs.cancelled,
                s.rate_impacts_per_s.map_or("–".into(), |r| format!("{r:.3}/s")),
                fmt_eta(s.eta_s)
            );
            if let Some(e) = s.last_error {
                say!(
                    "last error (cell {}, sample {}): {}",
                    e.cell,
                    e.sample,
                    e.error
                );
            }
        }
        return Ok(ExitCode::SUCCESS);
    }
    let multi = MultiProgress::new();
    let style = ProgressStyle::with_template("{prefix:>22} {wide_bar} {pos}/{len} {msg}")
        .expect("valid template");
    let total = multi.add(ProgressBar::new(0).with_style(style.clone()));
    total.set_prefix("all cells");
    let mut cells: Vec<ProgressBar> = Vec::new();
    loop {
        let s = match client.status(id).await {
            Ok(s) => s,
            Err(e) if e.is_transient() => {
                total.set_message(format!("(coordinator unreachable: {e})"));
                tokio::time::sleep(Duration::from_secs(2)).await;
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        total.set_length(s.impacts_total);
        total.set_position(s.impacts_done);
        total.set_message(format!(
            "{}  rate {}  ETA {}",
            format!("{:?}", s.state).to_lowercase(),
            s.rate_impacts_per_s
                .map_or("–".into(), |r| format!("{r:.3}/s")),
            fmt_eta(s.eta_s)
        ));
        while cells.len() < s.cells.len() {
            let c = &s.cells[cells.len()];
            let bar = multi.add(ProgressBar::new(c.impacts_total).with_style(style.clone()));
            bar.set_prefix(format!("{:.1}° {}", c.angle_deg, c.shape));
            cells.push(bar);
        }
        for (bar, c) in cells.iter().zip(&s.cells) {
            bar.set_position(c.impacts_done);
            bar.set_message(format!("{}/{} samples", c.samples_done, c.samples_total));
        }
        if s.state.is_final() {
            total.finish();
            for b in &cells {
                b.finish();
            }
            if let Some(e) = s.last_error {
                say!(
                    "last error (cell {}, sample {}): {}",
                    e.cell,
                    e.sample,
                    e.error
                );
            }
            return Ok(ExitCode::SUCCESS);
        }
        tokio::time::sleep(Duration::from_secs(2)).await;
    }
}

async fn results(a: ResultsArgs) -> CliResult {
    let id = parse_id(&a.id)?;
    let v = a.remote.client()?.results_value(id, a.raw).await?;
    match &a.output {
        Some(p) => {
            crate::embedded::write_json(p, &v)
                .map_err(|e| CliError(format!("{}: {e}", p.display())))?;
            eprintln!("results written to {}", p.display());
        }
        None => say!("{}", serde_json::to_string_pretty(&v).expect("serialises")),
    }
    Ok(ExitCode::SUCCESS)
}

/// The scene `grit bench impact` times: issue 5's reference scene, or a variant of it.
#[derive(Debug, Clone, clap::Args)]
pub struct ImpactScene {
    /// Impact angle (degrees).
    #[arg(long, default_value_t = 45.0)]
    angle: f64,
    /// Particle spacing Δx (m); 8e-6 is the reference, coarser ones are quicker.
    #[arg(long, default_value_t = 8e-6)]
    spacing_m: f64,
    /// Impacts the surface takes before the timed one (the second scene: 30).
    #[arg(long, default_value_t = 0)]
    after: u32,
    /// Seed of the sample.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Simulate every particle of the grain, not only its outline (the model before the
    /// grain-shell saving; the results are bitwise the same, the cost is not).
    #[arg(long)]
    full_grain: bool,
    /// Simulate the grain's approach step by step instead of skipping to just before its
    /// first contact (the model before the flight skip).
    #[arg(long)]
    full_flight: bool,
    /// Keep the surface's particles in Z-order of neighbour cells, re-sorted at every
    /// neighbour rebuild (an option under test; results differ by rounding only).
    #[arg(long)]
    cell_order: bool,
}

/// Runs a benchmark on tokio's blocking pool: it holds its thread for minutes.
async fn blocking(f: impl FnOnce() -> CliResult + Send + 'static) -> CliResult {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| CliError(format!("benchmark thread: {e}")))?
}

/// `grit bench impact`: synchronous, the engine runs on rayon pools of its own.
fn bench_impact(scene: ImpactScene, threads: usize, repeat: usize, json: bool) -> CliResult {
    use grit_erosion::{ImpactParams, Sample, Shape};
    let ImpactScene {
        angle,
        spacing_m,
        after,
        seed,
        full_grain,
        full_flight,
        cell_order,
    } = scene;
    if threads == 0 {
        return Err(CliError("--threads: must be at least 1".into()));
    }
    if repeat == 0 {
        return Err(CliError("--repeat: must be at least 1".into()));
    }
    let mut params = ImpactParams {
        spacing_m,
        ..ImpactParams::paper(angle, Shape::Hexagon)
    };
    params.numerics.engine.rigid_shell &= !full_grain;
    params.numerics.skip_flight &= !full_flight;
    params.numerics.engine.cell_order |= cell_order;
    params
        .validate()
        .map_err(|e| CliError(format!("{}: {}", e.field, e.rule)))?;
    let mut s = Sample::new(params, seed).map_err(|e| CliError(e.to_string()))?;
    for k in 0..after {
        eprintln!("preparing the surface: impact {} of {after}", k + 1);
        s.run_next().map_err(|e| CliError(e.to_string()))?;
    }
    let b =
        grit_erosion::bench::impact(&s, threads, repeat).map_err(|e| CliError(e.to_string()))?;
    if json {
        say!("{}", serde_json::to_string_pretty(&b).expect("serialises"));
        return Ok(ExitCode::SUCCESS);
    }
    say!(
        "scene: hexagon {angle} deg, 100 m/s, AISI 304, spacing {spacing_m:e} m, surface after {after} impacts, grain {}, flight {}, particles in {} order",
        if full_grain { "filled" } else { "outline only" },
        if full_flight { "simulated" } else { "skipped" },
        if cell_order { "cell" } else { "creation" }
    );
    say!("particles                 {}", b.particles);
    say!("steps                     {}", b.steps);
    let runs = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.2}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if b.repeats > 1 {
        say!("repeats                   {} (medians below)", b.repeats);
        say!(
            "wall runs ({} threads)     {} s",
            b.threads,
            runs(&b.wall_s_runs)
        );
        say!(
            "wall runs (1 thread)      {} s",
            runs(&b.wall_1_thread_s_runs)
        );
    }
    say!("wall ({} threads)          {:.2} s", b.threads, b.wall_s);
    say!("wall (1 thread)           {:.2} s", b.wall_1_thread_s);
    say!("particle-steps/s          {:.3e}", b.particle_steps_per_s);
    say!(
        "particle-steps/s/thread   {:.3e}",
        b.particle_steps_per_s_per_thread
    );
    if let Some(x) = b.speedup_1_to_2 {
        say!("speed-up 1 -> 2 threads   {x:.2}");
    }
    let total: f64 = b.stages.values().sum();
    for (k, v) in &b.stages {
        say!(
            "  {k:<14} {v:>8.3} s  {:>5.1}%",
            100.0 * v / total.max(1e-12)
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// A rayon pool of `threads` threads (all cores when `None`).
fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool, CliError> {
    if threads == Some(0) {
        return Err(CliError("--threads: must be at least 1".into()));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| CliError(format!("thread pool: {e}")))
}

fn bench_stability(args: crate::studies::StabilityArgs, threads: Option<usize>) -> CliResult {
    let points = pool(threads)?
        .install(|| crate::studies::stability(&args))
        .map_err(CliError)?;
    print!("{}", crate::studies::stability_table(&points));
    say!(
        "wrote {0}/stability.csv, .json, .png and .svg",
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

fn bench_sweep(args: crate::studies::SweepArgs, threads: Option<usize>) -> CliResult {
    let rows = pool(threads)?
        .install(|| crate::studies::sweep(&args))
        .map_err(CliError)?;
    say!("summary of {}:", args.out.join("sweep.json").display());
    for r in &rows {
        say!("{}", crate::studies::sweep_line(r));
    }
    match grit_erosion::sweep::cheapest_within(&rows) {
        Some(b) => {
            let cost = grit_erosion::sweep::Cost::of(&rows);
            say!(
                "cheapest within the finest's ±1 std: {} at {} per Dg, {:.3} s per impact ({})",
                b.variant,
                b.particles_per_dg,
                cost.get(b),
                cost.label()
            )
        }
        None => say!("no erosion at the finest resolution: no setting can be judged against it"),
    }
    say!(
        "wrote {0}/sweep.csv, {0}/sweep.json and {0}/speed-accuracy.png, .svg",
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

async fn bench(a: BenchArgs) -> CliResult {
    let (clients, seconds, dir, json) = match a.what {
        BenchWhat::Farm {
            clients,
            seconds,
            dir,
            json,
        } => (clients, seconds, dir, json),
        BenchWhat::Sweep {
            angle,
            ppd,
            variants,
            variant_ppd,
            samples,
            impacts,
            seed,
            range_dg,
            width_dg,
            depth_dg,
            out,
            resume,
            threads,
        } => {
            let variants = variants
                .iter()
                .map(|v| grit_erosion::sweep::Variant::parse(v))
                .collect::<Result<Vec<_>, _>>()
                .map_err(CliError)?;
            let args = crate::studies::SweepArgs {
                params: grit_erosion::ImpactParams {
                    distribution_range_dg: range_dg,
                    surface_width_dg: width_dg,
                    surface_depth_dg: depth_dg,
                    ..crate::studies::scene(angle, 8e-6)
                },
                ppd,
                variants,
                variant_ppd,
                samples,
                impacts,
                seed,
                out,
                resume,
            };
            return blocking(move || bench_sweep(args, threads)).await;
        }
        BenchWhat::Stability {
            angle,
            spacing_m,
            after,
            seed,
            cfl,
            hourglass,
            stiffness,
            budget,
            out,
            threads,
        } => {
            let args = crate::studies::StabilityArgs {
                params: crate::studies::scene(angle, spacing_m),
                seed,
                after,
                grid: StabilityGrid {
                    cfl,
                    hourglass,
                    stiffness_scale: stiffness,
                },
                budget_factor: budget,
                out,
            };
            return blocking(move || bench_stability(args, threads)).await;
        }
        BenchWhat::Impact {
            scene,
            threads,
            repeat,
            json,
        } => {
            return blocking(move || bench_impact(scene, threads, repeat, json)).await;
        }
    };
    if clients.is_empty() || clients.contains(&0) {
        return Err(CliError("--clients: every count must be at least 1".into()));
    }
    let rows = crate::bench::run(&dir, &clients, seconds)
        .await
        .map_err(CliError)?;
    if json {
        say!(
            "{}",
            serde_json::to_string_pretty(&rows).expect("serialises")
        );
    } else {
        print!("{}", crate::bench::table(&rows));
    }
    Ok(ExitCode::SUCCESS)
}
