//! The worker loop, one for every scene (`grit_erosion::Scene`): claim a job, run its units
//! (impacts, jet slices) in order, each in a blocking thread with rayon inside the engine,
//! report every finished unit by heartbeat, upload a checkpoint every K units, complete. On
//! stop it abandons the running unit through the engine's cancel callback, hands back the
//! state after the last finished unit and releases the lease.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use std::future::Future;
use std::pin::Pin;

use grit_erosion::{Scene, SceneSet, SceneVisitor, Scenes};
use serde::Serialize;
use serde_json::Value;

use crate::api::{
    units, Checkpoint, ClaimedJob, CompleteRequest, FailRequest, HeartbeatRequest, ReleaseRequest,
    WorkerEngine,
};
use crate::checkpoint::verify;
use crate::client::{Client, ClientError};

/// Runs a claimed job as scene `S`, its parameters read from the claim.
struct RunJob<'a> {
    runner: &'a mut Runner,
    job: ClaimedJob,
}

impl<'a> SceneVisitor for RunJob<'a> {
    type Output = Pin<Box<dyn Future<Output = JobEnd> + Send + 'a>>;

    fn visit<S: Scene>(self) -> Self::Output {
        Box::pin(async move {
            match serde_json::from_value::<S::Params>(self.job.params.clone()) {
                Ok(params) => self.runner.run::<S>(self.job, params).await,
                Err(e) => {
                    let why = format!("the job's {} parameters do not read: {e}", S::KIND);
                    self.runner.fail(&self.job, why, vec![]).await
                }
            }
        })
    }
}

/// A stop request shared by a signal handler, the async loop and the engine's cancel callback.
#[derive(Clone)]
pub struct Stop {
    flag: Arc<AtomicBool>,
    tx: Arc<tokio::sync::watch::Sender<bool>>,
}

impl Default for Stop {
    fn default() -> Self {
        Stop {
            flag: Arc::new(AtomicBool::new(false)),
            tx: Arc::new(tokio::sync::watch::channel(false).0),
        }
    }
}

impl Stop {
    /// Requests the stop.
    pub fn trigger(&self) {
        self.flag.store(true, Ordering::SeqCst);
        self.tx.send_replace(true);
    }

    /// Whether a stop was requested.
    pub fn is_set(&self) -> bool {
        self.flag.load(Ordering::SeqCst)
    }

    /// Sleeps for `d`, returning early (true) if a stop is requested.
    pub async fn sleep(&self, d: Duration) -> bool {
        let mut rx = self.tx.subscribe();
        if *rx.borrow() {
            return true;
        }
        tokio::select! {
            _ = tokio::time::sleep(d) => self.is_set(),
            _ = rx.wait_for(|v| *v) => true,
        }
    }
}

/// How a worker behaves.
#[derive(Debug, Clone)]
pub struct WorkerOptions {
    /// Name reported to the coordinator.
    pub name: String,
    /// Threads of the engine's rayon pool; `None` uses rayon's global pool.
    pub threads: Option<usize>,
    /// Upload a checkpoint every this many impacts.
    pub checkpoint_every: u32,
    /// Exit once the queue is empty instead of polling.
    pub exit_when_idle: bool,
    /// Wait between claims when the queue is empty.
    pub idle_poll: Duration,
    /// Longest wait between retries while the coordinator is unreachable.
    pub max_backoff: Duration,
}

impl Default for WorkerOptions {
    fn default() -> Self {
        WorkerOptions {
            name: default_name(),
            threads: None,
            checkpoint_every: 5,
            exit_when_idle: false,
            idle_poll: Duration::from_secs(2),
            max_backoff: Duration::from_secs(60),
        }
    }
}

/// `host:pid`, so a job in the coordinator log names the process that held it.
pub fn default_name() -> String {
    let host = std::env::var("HOSTNAME")
        .ok()
        .or_else(|| std::fs::read_to_string("/etc/hostname").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "worker".into());
    format!("{host}:{}", std::process::id())
}

/// What a worker did before it stopped.
#[derive(Debug, Clone, Default)]
pub struct WorkerSummary {
    /// Jobs completed.
    pub jobs_done: u64,
    /// Units simulated: impacts, jet slices.
    pub units: u64,
}

/// A failure that stops the worker (bad token, an answer it cannot understand).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct WorkerError(pub String);

enum JobEnd {
    Done,
    Lost(String),
    Failed,
    Stopped,
}

struct Runner {
    client: Client,
    /// The fingerprints of the scenes this worker runs, sent with every claim.
    engine: WorkerEngine,
    opts: WorkerOptions,
    stop: Stop,
    pool: Option<Arc<rayon::ThreadPool>>,
    summary: WorkerSummary,
}

/// Runs the worker loop for grit's scenes until `stop` is triggered (or the queue is empty
/// with `exit_when_idle`).
pub async fn run(
    client: Client,
    opts: WorkerOptions,
    stop: Stop,
) -> Result<WorkerSummary, WorkerError> {
    run_scenes::<Scenes>(client, opts, stop).await
}

/// [`run`] for the scenes of set `Z`: a job of a scene outside it fails, naming the scene.
pub async fn run_scenes<Z: SceneSet>(
    client: Client,
    opts: WorkerOptions,
    stop: Stop,
) -> Result<WorkerSummary, WorkerError> {
    let pool = match opts.threads {
        Some(n) => Some(Arc::new(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n.max(1))
                .thread_name(|i| format!("grit-engine-{i}"))
                .build()
                .map_err(|e| WorkerError(format!("--threads: {e}")))?,
        )),
        None => None,
    };
    let engines = grit_erosion::scene::engines::<Z>()
        .map_err(|e| WorkerError(format!("engine fingerprint: {e}")))?;
    tracing::info!(?engines, "engine fingerprints");
    let mut r = Runner {
        client,
        engine: WorkerEngine::PerScene(engines),
        opts,
        stop,
        pool,
        summary: WorkerSummary::default(),
    };
    let mut backoff = Duration::from_millis(500);
    loop {
        if r.stop.is_set() {
            break;
        }
        match r.client.claim_with(&r.opts.name, &r.engine).await {
            Ok(Some(job)) => {
                backoff = Duration::from_millis(500);
                tracing::info!(
                    job = job.job_id,
                    cell = job.cell,
                    sample = job.sample,
                    done = job.impacts_done,
                    planned = job.impacts_planned,
                    "job leased"
                );
                match r.run_job::<Z>(job).await {
                    JobEnd::Done => r.summary.jobs_done += 1,
                    JobEnd::Lost(why) => tracing::warn!(%why, "job dropped"),
                    JobEnd::Failed => {}
                    JobEnd::Stopped => break,
                }
            }
            Ok(None) => {
                if r.opts.exit_when_idle {
                    break;
                }
                if r.stop.sleep(r.opts.idle_poll).await {
                    break;
                }
            }
            Err(e) if e.is_transient() => {
                tracing::warn!(error = %e, retry_in_s = backoff.as_secs_f64(), "claim failed");
                if r.stop.sleep(backoff).await {
                    break;
                }
                backoff = (backoff * 2).min(r.opts.max_backoff);
            }
            Err(e) => return Err(WorkerError(format!("claim refused: {e}"))),
        }
    }
    Ok(r.summary)
}

impl Runner {
    /// The run to continue: from the checkpoint when it passes `checkpoint::verify` (its job,
    /// length, checksum and decoding), else from the start (units the coordinator already has
    /// are run again, bit-identical, and skipped by it).
    fn open<S: Scene>(job: &ClaimedJob, params: &S::Params) -> Result<S, String> {
        if let Some(c) = &job.checkpoint {
            match verify::<S>(c, job.job_id, params, job.seed) {
                Ok(run) => {
                    tracing::info!(
                        job = job.job_id,
                        units = run.units_done(),
                        "resumed from checkpoint"
                    );
                    return Ok(run);
                }
                Err(e) => {
                    tracing::warn!(job = job.job_id, error = %e, "checkpoint unusable; starting the job again")
                }
            }
        }
        S::start(params, job.seed).map_err(|e| e.to_string())
    }

    /// Runs `job` as the scene of `Z` its claim names.
    async fn run_job<Z: SceneSet>(&mut self, job: ClaimedJob) -> JobEnd {
        let kind = job.scene.clone();
        if !Z::kinds().contains(&kind.as_str()) {
            let known = Z::kinds().join(", ");
            let why = format!("this worker runs the scenes {known}, not {kind:?}");
            return self.fail(&job, why, vec![]).await;
        }
        let visit = RunJob { runner: self, job };
        Z::visit(&kind, visit).expect("the kind is the set's").await
    }

    /// Runs job `job` of scene `S` unit by unit (each in a blocking thread, rayon inside the
    /// engine), reporting every finished unit by heartbeat, with a checkpoint every
    /// `checkpoint_every` units (every unit where a cancelled unit leaves the state
    /// mid-unit, `Scene::CHECKPOINT_EACH_UNIT`), and completes it.
    async fn run<S: Scene>(&mut self, job: ClaimedJob, params: S::Params) -> JobEnd {
        let mut run = match Self::open::<S>(&job, &params) {
            Ok(r) => r,
            Err(e) => {
                return self
                    .fail(&job, format!("cannot set up the job: {e}"), vec![])
                    .await
            }
        };
        let mut pending: Vec<S::Record> = run
            .records()
            .into_iter()
            .filter(|r| S::unit_of(r) > job.impacts_done)
            .collect();
        // The state after the last finished unit, for a scene whose cancelled unit leaves it
        // mid-unit; until a unit is done here, the coordinator's stored checkpoint is newest.
        let mut last: Option<Checkpoint> = None;
        let tick = Duration::from_secs_f64((job.lease_ttl_s / 3.0).max(0.2));
        let lost = Arc::new(AtomicBool::new(false));
        let every = if S::CHECKPOINT_EACH_UNIT {
            1
        } else {
            self.opts.checkpoint_every.max(1)
        };
        let mut checkpoint_due = false;
        while run.units_done() < job.impacts_planned {
            if self.stop.is_set() {
                return self.release(&job, &run, pending, last).await;
            }
            let stop = self.stop.clone();
            let lost_flag = lost.clone();
            let pool = self.pool.clone();
            let (job_id, planned) = (job.job_id, job.impacts_planned);
            let mut handle = tokio::task::spawn_blocking(move || {
                let cancel = || stop.is_set() || lost_flag.load(Ordering::SeqCst);
                let result = match &pool {
                    // The pool is this worker's own: one world steps on it at a time.
                    Some(p) => grit_sph::polling::install_polling(p, || run.run_next(&cancel)),
                    None => run.run_next(&cancel),
                };
                // Serialising a large state takes milliseconds: here, not on the async threads.
                let checkpoint = (matches!(result, Ok(Some(_)))
                    && run.units_done() % every == 0
                    && run.units_done() < planned)
                    .then(|| Checkpoint::of(job_id, &run));
                (run, result, checkpoint)
            });
            // Keep the lease alive while the unit runs (an impact can take minutes).
            let (r, result, checkpoint) = loop {
                tokio::select! {
                    joined = &mut handle => match joined {
                        Ok(v) => break v,
                        Err(e) => return self.fail(&job, format!("{} thread panicked: {e}", S::UNIT), units(&pending)).await,
                    },
                    _ = tokio::time::sleep(tick) => {
                        match self.heartbeat(&job, &mut pending, None).await {
                            Ok(()) => {}
                            Err(Some(why)) => { lost.store(true, Ordering::SeqCst); tracing::warn!(%why, "lease lost; abandoning the {}", S::UNIT); }
                            Err(None) => {}
                        }
                    }
                }
            };
            run = r;
            match result {
                Ok(Some(rec)) => {
                    self.summary.units += 1;
                    tracing::info!(
                        job = job.job_id,
                        unit = S::unit_of(&rec),
                        "{} done",
                        S::UNIT
                    );
                    pending.push(rec);
                    if checkpoint.is_some() {
                        checkpoint_due = true;
                        last = checkpoint;
                    }
                }
                _ if lost.load(Ordering::SeqCst) => {
                    return JobEnd::Lost(format!("lease lost while the {} ran", S::UNIT))
                }
                // Cancelled: hand back the state after the last finished unit.
                Ok(None) => return self.release(&job, &run, pending, last).await,
                Err(_) if self.stop.is_set() => {
                    return self.release(&job, &run, pending, last).await
                }
                Err(e) => return self.fail(&job, e.to_string(), units(&pending)).await,
            }
            let ckpt = if checkpoint_due { last.clone() } else { None };
            match self.heartbeat(&job, &mut pending, ckpt).await {
                Ok(()) => checkpoint_due = false,
                Err(Some(why)) => return JobEnd::Lost(why),
                Err(None) => {}
            }
        }
        let end = job.extendable.then(|| Checkpoint::of(job.job_id, &run));
        self.complete(&job, units(&pending), end).await
    }

    /// Sends the pending units; clears them once acknowledged. `Err(Some)` means the lease is
    /// gone (409/410/404); `Err(None)` a transient failure (units kept for the next try).
    async fn heartbeat<R: Serialize>(
        &self,
        job: &ClaimedJob,
        pending: &mut Vec<R>,
        checkpoint: Option<Checkpoint>,
    ) -> Result<(), Option<String>> {
        let req = HeartbeatRequest {
            lease_id: job.lease_id,
            units: units(pending),
            checkpoint,
        };
        match self.client.heartbeat(job.job_id, &req).await {
            Ok(_) => {
                pending.clear();
                Ok(())
            }
            Err(e) if e.is_transient() => {
                tracing::warn!(error = %e, pending = pending.len(), "heartbeat failed; units kept for the next one");
                Err(None)
            }
            Err(e) => Err(Some(e.to_string())),
        }
    }

    /// Retries `call` with backoff while the coordinator is unreachable; gives up after
    /// `limit` when stopping (the lease then expires and the job is resumed elsewhere).
    async fn deliver<F, Fut>(&self, what: &str, mut call: F) -> Result<(), ClientError>
    where
        F: FnMut() -> Fut,
        Fut: std::future::Future<Output = Result<(), ClientError>>,
    {
        let mut backoff = Duration::from_millis(500);
        let mut waited = Duration::ZERO;
        loop {
            match call().await {
                Err(e) if e.is_transient() => {
                    if self.stop.is_set() && waited > Duration::from_secs(30) {
                        return Err(e);
                    }
                    tracing::warn!(error = %e, what, retry_in_s = backoff.as_secs_f64(), "coordinator unreachable");
                    tokio::time::sleep(backoff).await;
                    waited += backoff;
                    backoff = (backoff * 2).min(self.opts.max_backoff);
                }
                other => return other,
            }
        }
    }

    async fn complete(
        &self,
        job: &ClaimedJob,
        pending: Vec<Value>,
        checkpoint: Option<Checkpoint>,
    ) -> JobEnd {
        let req = CompleteRequest {
            lease_id: job.lease_id,
            units: pending,
            checkpoint,
        };
        match self
            .deliver("complete", || self.client.complete(job.job_id, &req))
            .await
        {
            Ok(()) => {
                tracing::info!(job = job.job_id, "job complete");
                JobEnd::Done
            }
            Err(e) => JobEnd::Lost(format!("complete refused: {e}")),
        }
    }

    async fn fail(&self, job: &ClaimedJob, error: String, pending: Vec<Value>) -> JobEnd {
        tracing::error!(job = job.job_id, %error, "job failed");
        let req = FailRequest {
            lease_id: job.lease_id,
            error,
            units: pending,
        };
        if let Err(e) = self
            .deliver("fail", || self.client.fail(job.job_id, &req))
            .await
        {
            tracing::warn!(error = %e, "reporting the failure failed");
        }
        JobEnd::Failed
    }

    /// Gives the job back with the state after its last finished unit: `run`'s own where a
    /// cancelled unit leaves it untouched, else `last`, the checkpoint taken after that unit.
    async fn release<S: Scene>(
        &self,
        job: &ClaimedJob,
        run: &S,
        pending: Vec<S::Record>,
        last: Option<Checkpoint>,
    ) -> JobEnd {
        let checkpoint = if S::CHECKPOINT_EACH_UNIT {
            last
        } else {
            Some(Checkpoint::of(job.job_id, run))
        };
        let done = checkpoint.as_ref().map(|c| c.impacts_done);
        let req = ReleaseRequest {
            lease_id: job.lease_id,
            units: units(&pending),
            checkpoint,
        };
        match self
            .deliver("release", || self.client.release(job.job_id, &req))
            .await
        {
            Ok(()) if done.is_some() => {
                tracing::info!(job = job.job_id, ?done, "job released with a checkpoint")
            }
            Ok(()) => tracing::info!(job = job.job_id, "job released; its last checkpoint stands"),
            Err(e) => {
                tracing::warn!(job = job.job_id, error = %e, "release failed; the lease will expire")
            }
        }
        JobEnd::Stopped
    }
}

#[cfg(test)]
mod tests {
    //! A worker resumes only from a checkpoint that passes the check; a damaged one (bytes
    //! changed at rest, so they no longer match the stored checksum) starts the sample again.

    use base64::Engine;
    use grit_erosion::{ImpactParams, Sample};
    use uuid::Uuid;

    use super::*;

    fn job(sample: &Sample, checkpoint: Option<Checkpoint>) -> ClaimedJob {
        ClaimedJob {
            job_id: 4,
            lease_id: Uuid::nil(),
            lease_ttl_s: 60.0,
            campaign_id: Uuid::nil(),
            cell: 0,
            sample: 0,
            seed: sample.seed(),
            impacts_planned: 3,
            impacts_done: sample.impacts_done(),
            scene: "impact".into(),
            params: serde_json::to_value(sample.params()).unwrap(),
            extendable: false,
            checkpoint,
        }
    }

    #[test]
    fn damaged_checkpoint_starts_the_sample_again() {
        let params = ImpactParams {
            spacing_m: 40e-6,
            surface_width_dg: 2.0,
            surface_depth_dg: 2.0,
            distribution_range_dg: 0.0,
            ..ImpactParams::default()
        };
        let mut sample = Sample::new(params, 9).unwrap();
        sample.run_next().unwrap();
        let good = Checkpoint::of(4, &sample);
        let open = |c| {
            let j = job(&sample, c);
            Runner::open::<Sample>(&j, sample.params())
        };
        let resumed = open(Some(good.clone())).unwrap();
        assert_eq!(resumed.impacts_done(), 1);
        assert_eq!(resumed.checkpoint(), sample.checkpoint());

        let mut bytes = sample.checkpoint();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        let damaged = Checkpoint {
            data_b64: base64::engine::general_purpose::STANDARD.encode(&bytes),
            ..good.clone()
        };
        let fresh = open(Some(damaged)).unwrap();
        assert_eq!(fresh.impacts_done(), 0);
        let other_job = Checkpoint { job_id: 5, ..good };
        let fresh = open(Some(other_job)).unwrap();
        assert_eq!(fresh.impacts_done(), 0);
    }
}
