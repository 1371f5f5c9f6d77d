//! The worker's loop for a jet job: run its slices in order (each in a blocking thread, rayon
//! inside the engine), report every finished slice by heartbeat with a checkpoint of the state
//! after it, so a killed worker loses at most the slice it was running; complete. A stop or a
//! lost lease abandons the running slice through `run_next_slice_observed`'s cancel callback;
//! on stop the job is released with the checkpoint after the last finished slice.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use grit_erosion::jet::{JetParams, JetRun, JetSlice};

use super::{JobEnd, Runner};
use crate::api::{
    Checkpoint, ClaimedJob, JetCompleteRequest, JetFailRequest, JetHeartbeatRequest,
    JetReleaseRequest,
};
use crate::checkpoint::verify_jet;

impl Runner {
    /// The run to continue: from the checkpoint when it passes `checkpoint::verify_jet`, else
    /// from the start (slices the coordinator already has come out the same and are skipped).
    fn open_jet(job: &ClaimedJob, params: &JetParams) -> Result<JetRun, String> {
        if let Some(c) = &job.checkpoint {
            match verify_jet(c, job.job_id, params, job.seed) {
                Ok(run) => {
                    tracing::info!(
                        job = job.job_id,
                        slices = run.slices_done(),
                        "resumed from checkpoint"
                    );
                    return Ok(run);
                }
                Err(e) => {
                    tracing::warn!(job = job.job_id, error = %e, "checkpoint unusable; starting the run again")
                }
            }
        }
        JetRun::new(params.clone(), job.seed).map_err(|e| e.to_string())
    }

    pub(super) async fn run_jet_job(&mut self, job: ClaimedJob, params: JetParams) -> JobEnd {
        let mut run = match Self::open_jet(&job, &params) {
            Ok(r) => r,
            Err(e) => {
                return self
                    .fail_jet(&job, format!("cannot set up the jet run: {e}"), vec![])
                    .await
            }
        };
        let mut pending: Vec<JetSlice> = run
            .slices()
            .iter()
            .filter(|s| s.slice > job.impacts_done)
            .cloned()
            .collect();
        // The state after the last finished slice, handed back on stop; until a slice is done
        // here, the coordinator's stored checkpoint (if any) is the newest.
        let mut last: Option<Checkpoint> = None;
        let tick = Duration::from_secs_f64((job.lease_ttl_s / 3.0).max(0.2));
        let lost = Arc::new(AtomicBool::new(false));
        while run.slices_done() < job.impacts_planned {
            if self.stop.is_set() {
                return self.release_jet(&job, pending, last).await;
            }
            let stop = self.stop.clone();
            let lost_flag = lost.clone();
            let pool = self.pool.clone();
            let job_id = job.job_id;
            let mut handle = tokio::task::spawn_blocking(move || {
                let cancel = || stop.is_set() || lost_flag.load(Ordering::SeqCst);
                let mut step = || {
                    run.run_next_slice_observed(&cancel, None)
                        .map(|s| s.cloned())
                };
                let result = match &pool {
                    // The pool is this worker's own: one world steps on it at a time.
                    Some(p) => grit_sph::polling::install_polling(p, step),
                    None => step(),
                };
                // Serialising the world takes milliseconds: here, not on the async threads.
                let checkpoint =
                    matches!(result, Ok(Some(_))).then(|| Checkpoint::of_jet(job_id, &run));
                (run, result, checkpoint)
            });
            // Keep the lease alive while the slice runs.
            let (r, result, checkpoint) = loop {
                tokio::select! {
                    joined = &mut handle => match joined {
                        Ok(v) => break v,
                        Err(e) => return self.fail_jet(&job, format!("slice thread panicked: {e}"), pending).await,
                    },
                    _ = tokio::time::sleep(tick) => {
                        match self.heartbeat_jet(&job, &mut pending, None).await {
                            Ok(()) => {}
                            Err(Some(why)) => { lost.store(true, Ordering::SeqCst); tracing::warn!(%why, "lease lost; abandoning the slice"); }
                            Err(None) => {}
                        }
                    }
                }
            };
            run = r;
            match result {
                Ok(Some(slice)) => {
                    self.summary.slices += 1;
                    tracing::info!(
                        job = job.job_id,
                        slice = slice.slice,
                        t_s = slice.sample.t_s,
                        mass_loss_kg_m = slice.sample.mass_loss_kg_m,
                        crater_depth_m = slice.sample.crater_depth_m,
                        "slice done"
                    );
                    pending.push(slice);
                    last = checkpoint;
                }
                _ if lost.load(Ordering::SeqCst) => {
                    return JobEnd::Lost("lease lost while the slice ran".into())
                }
                // Cancelled mid-slice: the run's state is not a slice's end; hand back the last.
                Ok(None) => return self.release_jet(&job, pending, last).await,
                Err(_) if self.stop.is_set() => return self.release_jet(&job, pending, last).await,
                Err(e) => return self.fail_jet(&job, e.to_string(), pending).await,
            }
            // Every slice goes with the state after it, so a kill loses at most one slice.
            match self.heartbeat_jet(&job, &mut pending, last.clone()).await {
                Ok(()) | Err(None) => {}
                Err(Some(why)) => return JobEnd::Lost(why),
            }
        }
        self.complete_jet(&job, pending).await
    }

    /// Sends the pending slices; clears them once acknowledged. `Err(Some)` means the lease is
    /// gone (409/410/404); `Err(None)` a transient failure (slices kept for the next try).
    async fn heartbeat_jet(
        &self,
        job: &ClaimedJob,
        pending: &mut Vec<JetSlice>,
        checkpoint: Option<Checkpoint>,
    ) -> Result<(), Option<String>> {
        let req = JetHeartbeatRequest {
            lease_id: job.lease_id,
            slices: pending.clone(),
            checkpoint,
        };
        match self.client.heartbeat_jet(job.job_id, &req).await {
            Ok(_) => {
                pending.clear();
                Ok(())
            }
            Err(e) if e.is_transient() => {
                tracing::warn!(error = %e, pending = pending.len(), "heartbeat failed; slices kept for the next one");
                Err(None)
            }
            Err(e) => Err(Some(e.to_string())),
        }
    }

    async fn complete_jet(&self, job: &ClaimedJob, pending: Vec<JetSlice>) -> JobEnd {
        let req = JetCompleteRequest {
            lease_id: job.lease_id,
            slices: pending,
        };
        match self
            .deliver("complete", || self.client.complete_jet(job.job_id, &req))
            .await
        {
            Ok(()) => {
                tracing::info!(job = job.job_id, "job complete");
                JobEnd::Done
            }
            Err(e) => JobEnd::Lost(format!("complete refused: {e}")),
        }
    }

    async fn fail_jet(&self, job: &ClaimedJob, error: String, pending: Vec<JetSlice>) -> JobEnd {
        tracing::error!(job = job.job_id, %error, "job failed");
        let req = JetFailRequest {
            lease_id: job.lease_id,
            error,
            slices: pending,
        };
        if let Err(e) = self
            .deliver("fail", || self.client.fail_jet(job.job_id, &req))
            .await
        {
            tracing::warn!(error = %e, "reporting the failure failed");
        }
        JobEnd::Failed
    }

    async fn release_jet(
        &self,
        job: &ClaimedJob,
        pending: Vec<JetSlice>,
        checkpoint: Option<Checkpoint>,
    ) -> JobEnd {
        let slices = checkpoint.as_ref().map(|c| c.impacts_done);
        let req = JetReleaseRequest {
            lease_id: job.lease_id,
            slices: pending,
            checkpoint,
        };
        match self
            .deliver("release", || self.client.release_jet(job.job_id, &req))
            .await
        {
            Ok(()) => tracing::info!(job = job.job_id, ?slices, "job released"),
            Err(e) => {
                tracing::warn!(job = job.job_id, error = %e, "release failed; the lease will expire")
            }
        }
        JobEnd::Stopped
    }
}
