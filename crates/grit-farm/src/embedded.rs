//! The embedded mode behind `grit run`: a coordinator on a SQLite file in the output folder and
//! N local workers in one process, run until the campaign ends; progress is reported through a
//! callback and the results are returned. Running it again on the same folder with the same
//! campaign resumes where it stopped (the submit is idempotent on the spec). Campaigns of
//! either scene run so.

use std::path::PathBuf;
use std::time::Duration;

use grit_erosion::campaign::{AnySpec, CampaignSpec};

use crate::api::{AnyResults, CampaignState, CampaignStatus};
use crate::client::{Client, ClientError};
use crate::db::{OwnEngine, Store};
use crate::server::{self, Config, Secret};
use crate::worker::{self, Stop, WorkerOptions};

/// Options of `grit run`.
#[derive(Debug, Clone)]
pub struct EmbeddedOptions {
    /// Output folder: the coordinator's `grit.db` goes there.
    pub out: PathBuf,
    /// Local workers; `None`: [`split_cores`]'s choice for the campaign's jobs.
    pub workers: Option<usize>,
    /// Engine threads per worker; `None` splits the machine's cores among the workers.
    pub threads_per_worker: Option<usize>,
    /// Checkpoint every this many impacts (a jet job checkpoints after every slice).
    pub checkpoint_every: u32,
    /// Include every sample's per-impact series in the results (as `?raw=true`).
    pub raw: bool,
    /// The commit this grit was built from, recorded with a new campaign.
    pub commit: Option<String>,
    /// Results of the finished samples so far ([`RunEvent::Interim`]) at most this often,
    /// whenever jobs finished since the last; `None`: only at the end.
    pub interim_every: Option<Duration>,
}

/// Local workers and engine threads per worker for a campaign of `jobs` jobs on `cores`
/// cores, where not given: one single-thread worker per core while the jobs fill the cores,
/// since samples side by side scale better than the threads inside one impact
/// (docs/performance.md, *The farm past two cores*); with fewer jobs than cores, one worker
/// per job and the cores shared among them, so none sits idle.
pub fn split_cores(
    cores: usize,
    jobs: usize,
    workers: Option<usize>,
    threads: Option<usize>,
) -> (usize, usize) {
    let cores = cores.max(1);
    let workers = workers.unwrap_or(cores.min(jobs)).max(1);
    let threads = threads.unwrap_or(cores / workers).max(1);
    (workers, threads)
}

/// What the embedded run reports while it runs.
#[derive(Debug)]
pub enum RunEvent<'a> {
    /// The campaign is in the database with this many impacts in all (an earlier, interrupted
    /// run of the same campaign may have done some).
    Started {
        /// Impacts of the whole campaign.
        impacts_total: u64,
    },
    /// The campaign's status, polled twice a second.
    Status(&'a CampaignStatus),
    /// A line worth showing: a failed job, a worker that stopped with an error.
    Note(String),
    /// The results so far (cells still running marked `partial`), while the campaign runs:
    /// a campaign of days can be looked at without stopping it.
    Interim(&'a AnyResults),
}

/// What `grit run` produced.
#[derive(Debug)]
pub struct EmbeddedOutcome {
    /// Final state of the campaign (not final when stopped from outside).
    pub state: CampaignState,
    /// The results, as the results endpoint serves them with `?raw=true` whatever
    /// [`EmbeddedOptions::raw`] says: the charts need every sample's series, and the caller
    /// drops them before writing where they were not asked for ([`AnyResults::strip_raw`]).
    pub results: AnyResults,
}

/// Why the embedded run could not go on.
#[derive(Debug, thiserror::Error)]
pub enum EmbeddedError {
    /// The output folder could not be created.
    #[error("--out {path}: {source}")]
    OutDir {
        /// The folder.
        path: PathBuf,
        /// What failed.
        source: std::io::Error,
    },
    /// The database in the output folder could not be opened.
    #[error("database {path}: {source}")]
    Database {
        /// The database file.
        path: PathBuf,
        /// What failed.
        source: crate::Error,
    },
    /// The output folder holds another spec's campaign.
    #[error("--out {out} holds the results of another campaign ({id}; {why}); give a fresh --out for this spec, or run that campaign's own spec there to resume it (a spec differing only in higher until_steady.max values raises its caps)")]
    OtherCampaign {
        /// The folder.
        out: PathBuf,
        /// The campaign already in its database.
        id: uuid::Uuid,
        /// What makes this spec another campaign.
        why: String,
    },
    /// The output folder's campaign is pinned to another engine than this grit's.
    #[error("--out {out} holds this campaign pinned to engine {pinned}, and this grit computes {own}: its samples would mix two engines' bits. Resume it with a grit of engine {pinned}, or pass --engine-upgrade NEW_DIR to run the spec afresh there with this engine")]
    OtherEngine {
        /// The folder.
        out: PathBuf,
        /// The fingerprint the campaign is pinned to.
        pinned: String,
        /// This grit's fingerprint for the campaign's scene.
        own: String,
    },
    /// This grit's engine fingerprint could not be computed.
    #[error("engine fingerprint: {0}")]
    Fingerprint(String),
    /// A database operation failed.
    #[error(transparent)]
    Store(#[from] crate::Error),
    /// The spec could not be written as JSON for its idempotency key.
    #[error("campaign spec: {0}")]
    Spec(#[from] serde_json::Error),
    /// The local coordinator could not start.
    #[error("cannot start the local coordinator: {0}")]
    Start(std::io::Error),
    /// A worker's client could not be built.
    #[error(transparent)]
    Client(#[from] ClientError),
}

/// FNV-1a, 64 bit: a stable digest of the spec, used as its idempotency key.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ *b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The idempotency key under which `grit run` stores `spec` in its database, so running the
/// same spec again continues the same campaign.
pub fn campaign_key(spec: &CampaignSpec) -> Result<String, serde_json::Error> {
    any_campaign_key(&AnySpec::Impact(spec.clone()))
}

/// [`campaign_key`] for a spec of either scene; an impact spec's key is the same.
pub fn any_campaign_key(spec: &AnySpec) -> Result<String, serde_json::Error> {
    let spec_json = serde_json::to_string(spec)?;
    Ok(format!("grit-run:{:016x}", fnv1a(spec_json.as_bytes())))
}

/// This grit's engine, as a coordinator records it with the campaigns it creates.
fn own_engine(commit: Option<String>) -> Result<OwnEngine, EmbeddedError> {
    Ok(OwnEngine {
        engines: grit_erosion::scene::engines::<grit_erosion::Scenes>()
            .map_err(|e| EmbeddedError::Fingerprint(e.to_string()))?,
        commit,
    })
}

/// The database of folder `out`, as this grit's coordinator (built from `commit`) opens it.
async fn open_store(out: &std::path::Path, commit: Option<String>) -> Result<Store, EmbeddedError> {
    let path = out.join("grit.db");
    let mut store = Store::open(&path, Duration::from_secs(120), 3)
        .await
        .map_err(|source| EmbeddedError::Database { path, source })?;
    store.own = own_engine(commit)?;
    Ok(store)
}

/// Campaign `id` (of `spec`) pinned to another engine than `store`'s own: (pinned, own).
async fn mismatch(
    store: &Store,
    id: uuid::Uuid,
    spec: &AnySpec,
) -> Result<Option<(String, String)>, EmbeddedError> {
    let pinned = store.status(id).await?.engine;
    let own = store.own.engines.get(spec.scene().as_str()).cloned();
    Ok(match (pinned, own) {
        (Some(pinned), Some(own)) if pinned != own => Some((pinned, own)),
        _ => None,
    })
}

/// Whether `out` holds `spec`'s campaign pinned to another engine than this grit's, which
/// [`run`] refuses to resume there: (pinned, own). `None` for a folder without it.
pub async fn engine_mismatch(
    spec: &AnySpec,
    out: &std::path::Path,
) -> Result<Option<(String, String)>, EmbeddedError> {
    if !out.join("grit.db").exists() {
        return Ok(None);
    }
    let store = open_store(out, None).await?;
    let Some(c) = store.list_campaigns().await?.into_iter().next() else {
        return Ok(None);
    };
    if !store.has_key(&any_campaign_key(spec)?).await? {
        return Ok(None);
    }
    mismatch(&store, c.id, spec).await
}

/// Runs `spec` to the end (or until `stop`) and returns its results; `on_event` hears of the
/// start, every status poll and anything worth a line.
pub async fn run(
    spec: &AnySpec,
    opts: &EmbeddedOptions,
    stop: Stop,
    mut on_event: impl FnMut(RunEvent<'_>),
) -> Result<EmbeddedOutcome, EmbeddedError> {
    std::fs::create_dir_all(&opts.out).map_err(|source| EmbeddedError::OutDir {
        path: opts.out.clone(),
        source,
    })?;
    let store = open_store(&opts.out, opts.commit.clone()).await?;
    // Nothing else uses this file, so leases left by an interrupted run are dead.
    store.requeue_all_leases().await?;
    let key = any_campaign_key(spec)?;
    // One campaign per folder: another spec's results.json and charts would overwrite this
    // one's, and its charts would mix with them. The same campaign with higher caps runs on.
    if !store.has_key(&key).await? {
        if let Some(other) = store.list_campaigns().await?.first() {
            let other_campaign = |why: String| EmbeddedError::OtherCampaign {
                out: opts.out.clone(),
                id: other.id,
                why,
            };
            // Its samples must not mix engines, whatever this spec is to it.
            if let Some((pinned, own)) = mismatch(&store, other.id, spec).await? {
                return Err(other_campaign(format!(
                    "it is pinned to engine {pinned} and this grit computes {own}"
                )));
            }
            match store.raise_caps(other.id, spec, Some(&key)).await {
                Ok(raised) => {
                    for r in raised {
                        on_event(RunEvent::Note(r.describe()));
                    }
                }
                Err(crate::Error::Conflict(why)) => return Err(other_campaign(why)),
                Err(e) => return Err(e.into()),
            }
        }
    }
    let created = store.create(spec, Some(&key)).await?;
    if let Some((pinned, own)) = mismatch(&store, created.id, spec).await? {
        return Err(EmbeddedError::OtherEngine {
            out: opts.out.clone(),
            pinned,
            own,
        });
    }
    if !created.created {
        // Running again continues the campaign. Jobs that failed here mostly lost their lease
        // while the whole process was stopped or the machine slept (its own workers could not
        // report), so each gets a fresh round of attempts, as `grit retry-failed` gives a farm.
        let n = store.retry_failed(created.id).await?;
        if n > 0 {
            tracing::warn!("{n} failed jobs queued again");
        }
    }
    // Loopback only, with throwaway tokens: other local users cannot feed it results.
    let worker_token = uuid::Uuid::new_v4().to_string();
    let config = Config {
        submit_token: Secret::new(Some(uuid::Uuid::new_v4().to_string())),
        worker_token: Secret::new(Some(worker_token.clone())),
        ..Config::default()
    };
    let running = server::start("127.0.0.1:0", store.clone(), config)
        .await
        .map_err(EmbeddedError::Start)?;
    let base = format!("http://{}", running.addr);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    // All the campaign's jobs, done ones included: a cell that grows queues them again.
    let j = store.status(created.id).await?.jobs;
    let jobs = (j.queued + j.leased + j.done + j.failed) as usize;
    let (workers, threads) = split_cores(cores, jobs, opts.workers, opts.threads_per_worker);
    tracing::info!(workers, threads, jobs, "local workers");
    let worker_stop = Stop::default();
    let mut handles = Vec::new();
    for i in 0..workers {
        let client = Client::new(&base, Secret::new(Some(worker_token.clone())))?;
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

    on_event(RunEvent::Started {
        impacts_total: created.impacts_total,
    });
    let mut interim = Interim::new(opts.interim_every, j.done);
    let state = loop {
        let status = store.status(created.id).await?;
        on_event(RunEvent::Status(&status));
        if !status.state.is_final() && interim.due(&status) {
            let results = store.results_any(created.id, opts.raw).await?;
            on_event(RunEvent::Interim(&results));
        }
        if status.state.is_final() {
            if let Some(e) = &status.last_error {
                on_event(RunEvent::Note(format!(
                    "job of cell {} sample {} failed: {}",
                    e.cell, e.sample, e.error
                )));
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
            Ok(Err(e)) => on_event(RunEvent::Note(format!("worker stopped: {e}"))),
            Err(e) => on_event(RunEvent::Note(format!("worker panicked: {e}"))),
        }
    }
    let results = store.results_any(created.id, true).await?;
    running.stop().await;
    Ok(EmbeddedOutcome { state, results })
}

/// When [`run`] next reports interim results: once `every` has passed since the last report
/// (or the start) and jobs finished since, so a campaign between jobs costs no aggregation.
struct Interim {
    every: Option<Duration>,
    last: std::time::Instant,
    done: u64,
}

impl Interim {
    /// Counting from now, with `done` jobs finished.
    fn new(every: Option<Duration>, done: u64) -> Interim {
        Interim {
            every,
            last: std::time::Instant::now(),
            done,
        }
    }

    fn due(&mut self, status: &CampaignStatus) -> bool {
        let Some(every) = self.every else {
            return false;
        };
        if status.jobs.done == self.done || self.last.elapsed() < every {
            return false;
        }
        self.last = std::time::Instant::now();
        self.done = status.jobs.done;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::split_cores;

    #[test]
    fn jobs_fill_the_cores_one_thread_each_and_fewer_jobs_share_them() {
        assert_eq!(split_cores(2, 150, None, None), (2, 1));
        assert_eq!(split_cores(16, 3, None, None), (3, 5));
        assert_eq!(split_cores(2, 1, None, None), (1, 2));
        assert_eq!(split_cores(16, 0, None, None), (1, 16), "no jobs");
        assert_eq!(
            split_cores(16, 3, Some(8), None),
            (8, 2),
            "--workers is kept"
        );
        assert_eq!(
            split_cores(16, 3, None, Some(1)),
            (3, 1),
            "--threads is kept"
        );
        assert_eq!(split_cores(2, 150, Some(1), Some(1)), (1, 1));
    }
}
