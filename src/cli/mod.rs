//! The commands of `grit`, one module per group, and what they share: the thread pool of
//! `--threads`, the async runtime and logging of the farm commands, tokens, file output and
//! progress bars. Every command returns `anyhow::Result`; `main` prints the error.

pub mod bench;
pub mod campaign;
pub mod fit;
pub mod jet;
pub mod output;
pub mod plot;
pub mod progress;
pub mod sample;
pub mod serve;
pub mod study;
pub mod version;

use std::path::PathBuf;

use anyhow::{bail, Context};
use grit_farm::worker::Stop;
use grit_farm::Secret;

/// Most threads or local workers a command starts: more than any worker machine's cores,
/// well below the system's limit on threads.
pub const MAX_THREADS: usize = 1024;
/// Longest time a seconds flag takes (about 116 days): any more is a typo in the units.
pub const MAX_SECONDS: f64 = 1e7;

/// A whole number in [`lo`, `hi`], or the rule in words: the integer flags' parsers.
fn whole_in<T>(s: &str, lo: T, hi: T) -> Result<T, String>
where
    T: std::str::FromStr + PartialOrd + std::fmt::Display,
{
    match s.parse::<T>() {
        Ok(n) if lo <= n && n <= hi => Ok(n),
        _ => Err(format!("must be a whole number from {lo} to {hi}")),
    }
}

/// Parser of `--threads`, `--workers` and `--clients`: 1 to [`MAX_THREADS`].
pub fn thread_count(s: &str) -> Result<usize, String> {
    whole_in(s, 1, MAX_THREADS)
}

/// Parser of a duration flag: a finite number of seconds, > 0 and at most [`MAX_SECONDS`].
pub fn seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= MAX_SECONDS => Ok(v),
        _ => Err(format!(
            "must be a number of seconds > 0 and at most {MAX_SECONDS:e}"
        )),
    }
}

/// Parser of a count that must be at least 1 (`--checkpoint-every`, `--max-attempts`).
pub fn at_least_one(s: &str) -> Result<u32, String> {
    whole_in(s, 1, u32::MAX)
}

/// Parser of an impact count: 1 to the most a sample may be planned with.
pub fn impact_count(s: &str) -> Result<u32, String> {
    whole_in(s, 1, grit_erosion::campaign::MAX_IMPACTS)
}

/// Parser of impacts taken before a measured one: 0 to the most a sample may be planned with.
pub fn impacts_before(s: &str) -> Result<u32, String> {
    whole_in(s, 0, grit_erosion::campaign::MAX_IMPACTS)
}

/// Parser of a benchmark's repeats: 1 to 1000.
pub fn repeat_count(s: &str) -> Result<usize, String> {
    whole_in(s, 1, 1000)
}

/// Parser of a request-size limit in bytes: 1 KiB (the smallest request) to 4 GiB.
pub fn body_bytes(s: &str) -> Result<usize, String> {
    whole_in(s, 1024, 4 << 30)
}

/// The rayon pool of `--threads` (1 or more, by its parser): that many threads, all cores
/// when `None`.
pub fn pool(threads: Option<usize>) -> anyhow::Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .context("thread pool")
}

/// The async runtime of the farm commands.
pub fn runtime() -> anyhow::Result<tokio::runtime::Runtime> {
    tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .context("cannot start the async runtime")
}

/// Logs to standard error at `default` level, or as `RUST_LOG` says.
pub fn init_tracing(default: &str) {
    let filter = tracing_subscriber::EnvFilter::try_from_env("RUST_LOG")
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .try_init();
}

/// SIGTERM or SIGINT triggers `stop`; a second SIGINT exits at once. Further SIGTERMs are the
/// same request again: a scheduler may send it twice (Slurm signals every process of a job,
/// and the job's shell passes its own on), and one arriving after the first was handled would
/// otherwise cut the checkpoint short. Schedulers that lose patience send SIGKILL.
pub fn on_signals(stop: Stop) {
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
            tracing::info!("stop requested; finishing up (SIGINT again to exit at once)");
            stop.trigger();
            loop {
                tokio::select! {
                    _ = term.recv() => tracing::info!("SIGTERM again; still finishing up"),
                    _ = int.recv() => std::process::exit(130),
                }
            }
        }
        #[cfg(not(unix))]
        {
            let _ = tokio::signal::ctrl_c().await;
            stop.trigger();
        }
    });
}

/// A token given as `--{flag}` or `--{flag}-file`, not both; none when neither.
pub fn read_token(
    value: Option<String>,
    file: Option<PathBuf>,
    flag: &str,
) -> anyhow::Result<Secret> {
    // A token given but blank would silently mean "no token": refused instead.
    let given = |t: String, what: String| {
        if t.trim().is_empty() {
            bail!("{what}: the token is empty");
        }
        Ok(Secret::new(Some(t)))
    };
    match (value, file) {
        (Some(_), Some(_)) => bail!("give --{flag} or --{flag}-file, not both"),
        (Some(v), None) => given(v, format!("--{flag}")),
        (None, Some(p)) => {
            let what = format!("--{flag}-file {}", p.display());
            let t = std::fs::read_to_string(&p).with_context(|| what.clone())?;
            given(t, what)
        }
        (None, None) => Ok(Secret::default()),
    }
}
