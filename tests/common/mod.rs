//! Helpers the process-level tests share: the `grit` binary as coordinator and workers, each a
//! child process killed on drop with its log in a file; the coarsest real campaign; a JSON
//! client of the API; the CLI as a submitter; and polling until a campaign gets somewhere.
#![allow(dead_code)] // each test file uses its own subset

use std::future::Future;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

use grit_farm::api::{CampaignState, CampaignStatus};
use grit_farm::{Client, Secret};
use serde_json::Value;
use uuid::Uuid;

pub mod results;

pub const GRIT: &str = env!("CARGO_BIN_EXE_grit");
pub const SUBMIT: &str = "submit-token-for-tests";
pub const WORKER: &str = "worker-token-for-tests";

/// Asserts that the PNG at `path` decodes and is not blank (more than three colours).
pub fn png_ok(path: &Path) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    let colours: std::collections::BTreeSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(colours.len() > 3, "{} is blank", path.display());
}

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

    /// Sends `signal` (a `kill` name such as `TERM` or `STOP`). The child is not reaped before
    /// `wait_exit`, so its pid is still its own even if it has exited.
    pub fn signal(&self, signal: &str) {
        let pid = self.child.id().to_string();
        let ok = Command::new("kill")
            .args([&format!("-{signal}"), &pid])
            .status()
            .unwrap()
            .success();
        assert!(ok, "kill -{signal} {pid}");
    }

    /// Waits up to 30 s for the process to exit; how it exited.
    pub fn wait_exit(&mut self) -> ExitStatus {
        let start = Instant::now();
        loop {
            if let Some(code) = self.child.try_wait().unwrap() {
                return code;
            }
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "{} did not exit",
                self.log.display()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
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

/// A coordinator process and the base URL it printed.
pub struct Coordinator {
    pub proc: Proc,
    pub url: String,
}

/// `grit serve` at `listen` with the test tokens, a lease of `lease_ttl_s` and `extra` flags,
/// logging to `dir/coordinator-{tag}.log`; its database is `db`, which may lie on another
/// filesystem than the log, or else `dir/farm.db`.
pub fn start_coordinator(
    dir: &Path,
    tag: &str,
    listen: &str,
    lease_ttl_s: f64,
    extra: &[&str],
    db: Option<&Path>,
) -> Coordinator {
    let mut cmd = coordinator_command(dir, listen, lease_ttl_s, extra, db);
    let log = dir.join(format!("coordinator-{tag}.log"));
    cmd.stderr(std::fs::File::create(&log).unwrap());
    spawn_coordinator(cmd, log)
}

/// `cmd` (from `coordinator_command`) started as `start_coordinator` does, with standard error sent through a pipe that the test copies into
/// the log: a limit later set on the process's file writes (`RLIMIT_FSIZE`) then spares its
/// log, where the test reads what it said about the refused writes.
pub fn start_coordinator_piped_log(dir: &Path, tag: &str, mut cmd: Command) -> Coordinator {
    let log = dir.join(format!("coordinator-{tag}.log"));
    cmd.stderr(Stdio::piped());
    let mut c = spawn_coordinator(cmd, log.clone());
    let mut from = c.proc.child.stderr.take().unwrap();
    let mut to = std::fs::File::create(&log).unwrap();
    // Ends when the process does (its end of the pipe closes).
    std::thread::spawn(move || {
        use std::io::{Read, Write};
        let mut buf = [0u8; 8192];
        while let Ok(n @ 1..) = from.read(&mut buf) {
            if to.write_all(&buf[..n]).is_err() {
                break;
            }
        }
    });
    c.proc.log = log;
    c
}

/// The `grit serve` command `start_coordinator` runs, before its standard error is set.
pub fn coordinator_command(
    dir: &Path,
    listen: &str,
    lease_ttl_s: f64,
    extra: &[&str],
    db: Option<&Path>,
) -> Command {
    let db = db.map_or_else(|| dir.join("farm.db"), Path::to_path_buf);
    let mut cmd = Command::new(GRIT);
    cmd.args(["serve", "--db"])
        .arg(&db)
        .args([
            "--listen",
            listen,
            "--lease-ttl-s",
            &lease_ttl_s.to_string(),
        ])
        .args(extra)
        .env("GRIT_SUBMIT_TOKEN", SUBMIT)
        .env("GRIT_WORKER_TOKEN", WORKER)
        .env("RUST_LOG", "info");
    cmd
}

/// Starts `cmd` (a `grit serve`) and reads the address it printed on its first line.
fn spawn_coordinator(mut cmd: Command, log: PathBuf) -> Coordinator {
    let mut child = cmd
        .stdout(Stdio::piped())
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
    Coordinator {
        proc: Proc { child, log },
        url,
    }
}

/// `grit work` against `url` on one thread, named `name`, with `args` added, logging to
/// `dir/worker-{name}.log`.
pub fn start_worker(dir: &Path, url: &str, name: &str, args: &[&str]) -> Proc {
    let log = dir.join(format!("worker-{name}.log"));
    let child = Command::new(GRIT)
        .args(["work", "--coordinator", url, "--token", WORKER])
        .args(["--threads", "1", "--poll-s", "0.2", "--name", name])
        // One job per process unless the test asks for more, whatever the machine's cores.
        .args(if args.contains(&"--jobs") {
            &[][..]
        } else {
            &["--jobs", "1"][..]
        })
        .args(args)
        .env("RUST_LOG", "info")
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .expect("grit work starts");
    Proc { child, log }
}

/// Runs `cmd` to its end, which must succeed (its standard error is the failure's message).
pub fn succeeds(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("the command starts");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `grit` with `args` as a submitter of the coordinator at `url` (its address and token from
/// the environment, as a user's shell gives them).
pub fn grit_cli(url: &str, args: &[&str]) -> Output {
    Command::new(GRIT)
        .args(args)
        .env("GRIT_COORDINATOR", url)
        .env("GRIT_TOKEN", SUBMIT)
        .output()
        .expect("grit runs")
}

/// A client of the coordinator at `url` with the submit token.
pub fn submitter(url: &str) -> Client {
    Client::new(url, Secret::new(Some(SUBMIT.into()))).unwrap()
}

/// Waits up to `limit` for campaign `id` to finish, which it must do as `done`.
pub async fn wait_done(c: &Client, id: Uuid, limit: Duration) -> CampaignStatus {
    let s = wait_for(limit, "done", || c.status(id), |s| s.state.is_final()).await;
    assert_eq!(s.state, CampaignState::Done, "{s:?}");
    s
}

/// Polls `status` every 100 ms until `done` accepts its answer, which it returns; fails after
/// `limit`. A failed poll is retried, so a coordinator may restart meanwhile.
pub async fn wait_for<T: std::fmt::Debug, E, F: Future<Output = Result<T, E>>>(
    limit: Duration,
    what: &str,
    mut status: impl FnMut() -> F,
    done: impl Fn(&T) -> bool,
) -> T {
    let start = Instant::now();
    loop {
        if let Ok(s) = status().await {
            if done(&s) {
                return s;
            }
            assert!(
                start.elapsed() < limit,
                "timed out waiting for {what}; last status {s:?}"
            );
        } else {
            assert!(start.elapsed() < limit, "timed out waiting for {what}");
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

/// A small HTTP client of the API: JSON calls with a bearer token, answering (status, body).
pub struct Api {
    http: reqwest::Client,
    base: String,
}

impl Api {
    /// A client of the coordinator at base URL `url`.
    pub fn new(url: &str) -> Api {
        Api {
            http: reqwest::Client::new(),
            base: format!("{url}/api/v1"),
        }
    }

    /// `GET path` under `/api/v1`, with `token` if given.
    pub async fn get(&self, path: &str, token: Option<&str>) -> (u16, Value) {
        let mut rb = self.http.get(format!("{}{path}", self.base));
        if let Some(t) = token {
            rb = rb.bearer_auth(t);
        }
        let r = rb.send().await.unwrap();
        let status = r.status().as_u16();
        (status, r.json().await.unwrap_or(Value::Null))
    }

    /// `POST path` under `/api/v1` with a JSON `body` and `token`.
    pub async fn post(&self, path: &str, token: &str, body: &Value) -> (u16, Value) {
        let r = self
            .http
            .post(format!("{}{path}", self.base))
            .bearer_auth(token)
            .json(body)
            .send()
            .await
            .unwrap();
        let status = r.status().as_u16();
        (status, r.json().await.unwrap_or(Value::Null))
    }

    /// Submits `spec` with the submit token; returns the new campaign's id.
    pub async fn submit(&self, spec: &str) -> String {
        let r = self
            .http
            .post(format!("{}/campaigns", self.base))
            .bearer_auth(SUBMIT)
            .header("content-type", "application/json")
            .body(spec.to_string())
            .send()
            .await
            .unwrap();
        assert_eq!(r.status().as_u16(), 201);
        let body: Value = r.json().await.unwrap();
        body["id"].as_str().unwrap().to_string()
    }

    /// A campaign's status with the submit token, or the HTTP status it was refused with.
    pub async fn campaign(&self, id: &str) -> Result<Value, u16> {
        match self.get(&format!("/campaigns/{id}"), Some(SUBMIT)).await {
            (200, body) => Ok(body),
            (status, _) => Err(status),
        }
    }

    /// `GET path` with the submit token, which must answer 200.
    pub async fn ok(&self, path: &str) -> Value {
        let (status, body) = self.get(path, Some(SUBMIT)).await;
        assert_eq!(status, 200, "GET {path}: {body}");
        body
    }
}
