//! Helpers the process-level tests share: the `grit` binary as coordinator and workers, each a
//! child process killed on drop with its log in a file, and the coarsest real campaign.
#![allow(dead_code)] // each test file uses its own subset

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

pub const GRIT: &str = env!("CARGO_BIN_EXE_grit");
pub const SUBMIT: &str = "submit-token-for-tests";
pub const WORKER: &str = "worker-token-for-tests";

/// The tests share two cores and time leases, so they run one at a time (a tokio mutex: the
/// guard is held across awaits, and a failed test must not poison it for the others).
pub static SERIAL: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());

/// The coarsest real scene: 10 particles per grain diameter on a small surface, hexagons at
/// `angles` (a JSON array), with `impacts` per sample.
pub fn campaign(name: &str, angles: &str, samples: u32, impacts: u32) -> String {
    format!(
        r#"{{"name": "{name}", "seed": 11, "angles_deg": {angles}, "shapes": ["hexagon"],
            "samples": {samples}, "impacts": {impacts}, "allow_short_samples": true,
            "spacing_m": 25e-6, "surface_width_dg": 3.0, "surface_depth_dg": 1.3}}"#
    )
}

/// A child process killed on drop, with its log in a file (printed on drop when `TEST_LOG`
/// is set).
pub struct Proc {
    pub child: Child,
    pub log: PathBuf,
}

impl Proc {
    pub fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    pub fn kill9(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        self.kill9();
        if std::env::var_os("TEST_LOG").is_some() {
            eprintln!("--- {} ---\n{}", self.log.display(), self.log_text());
        }
    }
}

/// `grit serve` on `dir/farm.db` with the test tokens and `args` (listen address, lease TTL,
/// …), logging to `dir/coordinator-{tag}.log`; returns the process and the base URL it
/// printed.
pub fn start_coordinator(dir: &Path, tag: &str, args: &[&str]) -> (Proc, String) {
    let log = dir.join(format!("coordinator-{tag}.log"));
    let mut child = Command::new(GRIT)
        .args(["serve", "--db"])
        .arg(dir.join("farm.db"))
        .args(args)
        .env("GRIT_SUBMIT_TOKEN", SUBMIT)
        .env("GRIT_WORKER_TOKEN", WORKER)
        .env("RUST_LOG", "info")
        .stdout(Stdio::piped())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .expect("grit serve starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line
        .trim()
        .rsplit(' ')
        .next()
        .filter(|u| u.starts_with("http://"))
        .unwrap_or_else(|| panic!("no address line from grit serve: {line:?}"))
        .to_string();
    (Proc { child, log }, url)
}

/// `grit work` against `url` on one thread, named `name`, with `args` added, logging to
/// `dir/worker-{name}.log`.
pub fn start_worker(dir: &Path, url: &str, name: &str, args: &[&str]) -> Proc {
    let log = dir.join(format!("worker-{name}.log"));
    let child = Command::new(GRIT)
        .args(["work", "--coordinator", url, "--token", WORKER])
        .args(["--threads", "1", "--poll-s", "0.2", "--name", name])
        .args(args)
        .env("RUST_LOG", "info")
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .expect("grit work starts");
    Proc { child, log }
}
