//! The commands of `grit`, one module per group, and what they share: the thread pool of
//! `--threads`, the async runtime and logging of the farm commands, tokens, file output and
//! progress bars. Every command returns `anyhow::Result`; `main` prints the error.

pub mod bench;
pub mod campaign;
pub mod jet;
pub mod output;
pub mod plot;
pub mod progress;
pub mod sample;
pub mod serve;
pub mod study;

use std::path::PathBuf;

use anyhow::{bail, Context};
use grit_farm::worker::Stop;
use grit_farm::Secret;

/// The rayon pool of `--threads`: that many threads, all cores when `None`.
pub fn pool(threads: Option<usize>) -> anyhow::Result<rayon::ThreadPool> {
    if threads == Some(0) {
        bail!("--threads: must be at least 1");
    }
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

/// SIGTERM or SIGINT triggers `stop`; a second signal exits at once.
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

/// A token given as `--{flag}` or `--{flag}-file`, not both; none when neither.
pub fn read_token(
    value: Option<String>,
    file: Option<PathBuf>,
    flag: &str,
) -> anyhow::Result<Secret> {
    match (value, file) {
        (Some(_), Some(_)) => bail!("give --{flag} or --{flag}-file, not both"),
        (Some(v), None) => Ok(Secret::new(Some(v))),
        (None, Some(p)) => std::fs::read_to_string(&p)
            .map(|t| Secret::new(Some(t)))
            .with_context(|| format!("--{flag}-file {}", p.display())),
        (None, None) => Ok(Secret::default()),
    }
}
