//! The store's side of the worker endpoints: leasing jobs, and the lease holder's writes
//! (heartbeat, complete, fail, release) with the impacts and checkpoints they carry; expired
//! leases go back to the queue. The writes go through the group writer (`group`), which
//! applies each with the `apply_*` function here inside a transaction shared with others.

use std::time::Duration;

use base64::Engine;
use grit_erosion::{ImpactParams, ImpactRecord};
use sqlx::{Row, Sqlite, Transaction};
use uuid::Uuid;

use super::group::{mismatch, Op, Reply};
use super::{now_ms, parse_uuid, Store};
use crate::api::{Checkpoint, ClaimedJob, HeartbeatResponse};
use crate::error::{Error, Result};

/// Longest failure message kept per job.
pub(super) const MAX_ERROR_CHARS: usize = 4000;
/// Workers silent for longer are forgotten, so the table of names cannot grow without end.
const WORKER_FORGET_MS: i64 = 7 * 24 * 3600 * 1000;

/// A checkpoint as stored.
struct StoredCheckpoint {
    impacts_done: u32,
    data: Vec<u8>,
    /// `None` for a checkpoint stored before checksums were.
    sha256: Option<String>,
}

/// A lease holder's write so far.
struct Report {
    now: i64,
    held: Held,
    /// Impacts stored for the job, this write's included.
    done: u32,
}

impl Store {
    /// Returns jobs whose lease expired to the queue with their attempt count raised, or
    /// marks them failed when they reach the maximum. Returns how many.
    pub async fn reap_expired(&self) -> Result<u64> {
        let mut tx = self.begin().await?;
        let now = now_ms();
        let n = reap(&mut tx, now).await?;
        sqlx::query("DELETE FROM workers WHERE last_seen_ms < ?")
            .bind(now - WORKER_FORGET_MS)
            .execute(&mut *tx)
            .await?;
        tx.commit().await?;
        Ok(n)
    }

    /// Returns every leased job to the queue without counting an attempt: used by the
    /// embedded mode at start, when no worker of an earlier run can still be alive.
    pub async fn requeue_all_leases(&self) -> Result<u64> {
        let mut tx = self.begin().await?;
        let n = sqlx::query(
            "UPDATE jobs SET state = 'queued', lease_id = NULL, worker = NULL,
                             lease_expires_ms = NULL, updated_ms = ?
             WHERE state = 'leased'",
        )
        .bind(now_ms())
        .execute(&mut *tx)
        .await?
        .rows_affected();
        tx.commit().await?;
        Ok(n)
    }

    /// Leases the next queued job to `worker`, or `None` when the queue is empty.
    pub async fn claim(&self, worker: &str) -> Result<Option<ClaimedJob>> {
        match self
            .group
            .apply(Op::Claim {
                worker: worker.to_owned(),
            })
            .await?
        {
            Reply::Claimed(job) => Ok(job.map(|j| *j)),
            _ => Err(mismatch()),
        }
    }

    /// Renews the lease, stores finished impacts and an optional checkpoint.
    pub async fn heartbeat(
        &self,
        job_id: i64,
        lease: Uuid,
        impacts: &[ImpactRecord],
        checkpoint: Option<&Checkpoint>,
    ) -> Result<HeartbeatResponse> {
        let op = Op::Heartbeat {
            job_id,
            lease,
            impacts: impacts.to_vec(),
            checkpoint: checkpoint.cloned(),
        };
        match self.group.apply(op).await? {
            Reply::Beat(r) => Ok(r),
            _ => Err(mismatch()),
        }
    }

    /// Stores the last impacts and marks the job done; it must then have every planned impact.
    /// The checkpoint after the last impact is kept when the job's cell may still grow, and
    /// a cell whose last job this was is assessed and grown in the same transaction.
    pub async fn complete(
        &self,
        job_id: i64,
        lease: Uuid,
        impacts: &[ImpactRecord],
        checkpoint: Option<&Checkpoint>,
    ) -> Result<()> {
        let op = Op::Complete {
            job_id,
            lease,
            impacts: impacts.to_vec(),
            checkpoint: checkpoint.cloned(),
        };
        self.group.apply(op).await.map(drop)
    }

    /// Records a failure: back to the queue, or `failed` once attempts reach the maximum.
    pub async fn fail(
        &self,
        job_id: i64,
        lease: Uuid,
        error: &str,
        impacts: &[ImpactRecord],
    ) -> Result<()> {
        let op = Op::Fail {
            job_id,
            lease,
            error: error.to_owned(),
            impacts: impacts.to_vec(),
        };
        self.group.apply(op).await.map(drop)
    }

    /// Gives a job back without counting an attempt, keeping its impacts and checkpoint.
    pub async fn release(
        &self,
        job_id: i64,
        lease: Uuid,
        impacts: &[ImpactRecord],
        checkpoint: Option<&Checkpoint>,
    ) -> Result<()> {
        let op = Op::Release {
            job_id,
            lease,
            impacts: impacts.to_vec(),
            checkpoint: checkpoint.cloned(),
        };
        self.group.apply(op).await.map(drop)
    }
}

/// Leases the next queued job to `worker` in `tx`, sweeping expired leases first when `sweep`
/// is set (a group sweeps once for all its claims).
pub(super) async fn apply_claim(
    tx: &mut Transaction<'static, Sqlite>,
    lease_ttl: Duration,
    worker: &str,
    sweep: bool,
) -> Result<Option<ClaimedJob>> {
    let now = now_ms();
    if sweep {
        reap(tx, now).await?;
    }
    // Every claim counts as a sign of life, an empty queue's too: idle workers are listed.
    sqlx::query(
        "INSERT INTO workers (name, first_seen_ms, last_seen_ms) VALUES (?1, ?2, ?2)
         ON CONFLICT (name) DO UPDATE SET last_seen_ms = excluded.last_seen_ms",
    )
    .bind(worker)
    .bind(now)
    .execute(&mut **tx)
    .await?;
    let lease = Uuid::new_v4();
    let expires = now + lease_ttl.as_millis() as i64;
    let Some(r) = sqlx::query(
        "UPDATE jobs SET state = 'leased', lease_id = ?, worker = ?, lease_expires_ms = ?,
                         updated_ms = ?
         WHERE id = (SELECT id FROM jobs WHERE state = 'queued'
                     ORDER BY campaign_seq, sample_index, cell_index LIMIT 1)
         RETURNING id, campaign_id, cell_index, sample_index, seed, impacts_planned,
                   impacts_done",
    )
    .bind(lease.to_string())
    .bind(worker)
    .bind(expires)
    .bind(now)
    .fetch_optional(&mut **tx)
    .await?
    else {
        return Ok(None);
    };
    let job_id: i64 = r.get("id");
    let campaign: String = r.get("campaign_id");
    let cell: i64 = r.get("cell_index");
    let cell_row = sqlx::query(
        "SELECT params, impacts, impacts_max FROM cells WHERE campaign_id = ? AND cell_index = ?",
    )
    .bind(&campaign)
    .bind(cell)
    .fetch_one(&mut **tx)
    .await?;
    let params: String = cell_row.get(0);
    let extendable = cell_row
        .get::<Option<i64>, _>(2)
        .is_some_and(|max| cell_row.get::<i64, _>(1) < max);
    let params: ImpactParams = serde_json::from_str(&params)
        .map_err(|e| Error::Internal(format!("stored params of job {job_id}: {e}")))?;
    let ckpt = load_checkpoint(tx, job_id).await?;
    Ok(Some(ClaimedJob {
        job_id,
        lease_id: lease,
        lease_ttl_s: lease_ttl.as_secs_f64(),
        campaign_id: parse_uuid(&campaign)?,
        cell: cell as u32,
        sample: r.get::<i64, _>("sample_index") as u32,
        seed: r.get::<i64, _>("seed") as u64,
        impacts_planned: r.get::<i64, _>("impacts_planned") as u32,
        impacts_done: r.get::<i64, _>("impacts_done") as u32,
        params,
        extendable,
        checkpoint: ckpt.map(|c| {
            let mut out = Checkpoint::from_bytes(job_id, c.impacts_done, &c.data);
            // The stored checksum, not one of the bytes as read now, so the worker
            // notices bytes damaged at rest.
            if let Some(sha) = c.sha256 {
                out.sha256 = sha;
            }
            out
        }),
    }))
}

/// A heartbeat in `tx`: renews the lease, stores finished impacts and an optional checkpoint.
pub(super) async fn apply_heartbeat(
    tx: &mut Transaction<'static, Sqlite>,
    lease_ttl: Duration,
    job_id: i64,
    lease: Uuid,
    impacts: &[ImpactRecord],
    checkpoint: Option<&Checkpoint>,
) -> Result<HeartbeatResponse> {
    let Report { now, done, .. } = report(tx, job_id, lease, impacts, checkpoint).await?;
    let expires = now + lease_ttl.as_millis() as i64;
    sqlx::query(
        "UPDATE jobs SET lease_expires_ms = ?, impacts_done = ?, updated_ms = ? WHERE id = ?",
    )
    .bind(expires)
    .bind(done as i64)
    .bind(now)
    .bind(job_id)
    .execute(&mut **tx)
    .await?;
    Ok(HeartbeatResponse {
        impacts_done: done,
        lease_expires_ms: expires,
    })
}

/// A completion in `tx`, by the rules of [`Store::complete`].
pub(super) async fn apply_complete(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    lease: Uuid,
    impacts: &[ImpactRecord],
    checkpoint: Option<&Checkpoint>,
) -> Result<()> {
    let Report { now, held, done } = report(tx, job_id, lease, impacts, checkpoint).await?;
    if done < held.planned {
        return Err(Error::invalid(
            "impacts",
            format!(
                "the job has {done} of its {} planned impacts; send the rest before completing",
                held.planned
            ),
        ));
    }
    end_lease(tx, job_id, "done", done, now).await?;
    let (campaign, cell, plan) = super::extend::plan_of_job(tx, job_id).await?;
    if !plan.impacts_may_grow() {
        sqlx::query("DELETE FROM checkpoints WHERE job_id = ?")
            .bind(job_id)
            .execute(&mut **tx)
            .await?;
    }
    super::extend::settle_cell(tx, &campaign, cell, plan, now).await
}

/// A failure in `tx`, by the rules of [`Store::fail`].
pub(super) async fn apply_fail(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    lease: Uuid,
    error: &str,
    impacts: &[ImpactRecord],
) -> Result<()> {
    let Report { now, done, .. } = report(tx, job_id, lease, impacts, None).await?;
    let error: String = error.chars().take(MAX_ERROR_CHARS).collect();
    sqlx::query(
        "UPDATE jobs SET attempts = attempts + 1, impacts_done = ?, last_error = ?,
             state = CASE WHEN attempts + 1 >=
                 (SELECT max_attempts FROM campaigns WHERE id = jobs.campaign_id)
                 THEN 'failed' ELSE 'queued' END,
             lease_id = NULL, worker = NULL, lease_expires_ms = NULL, updated_ms = ?
         WHERE id = ?",
    )
    .bind(done as i64)
    .bind(&error)
    .bind(now)
    .bind(job_id)
    .execute(&mut **tx)
    .await?;
    Ok(())
}

/// A release in `tx`, by the rules of [`Store::release`]; returns the impacts the job keeps.
pub(super) async fn apply_release(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    lease: Uuid,
    impacts: &[ImpactRecord],
    checkpoint: Option<&Checkpoint>,
) -> Result<u32> {
    let Report { now, done, .. } = report(tx, job_id, lease, impacts, checkpoint).await?;
    end_lease(tx, job_id, "queued", done, now).await?;
    Ok(done)
}

/// The start of a lease holder's write in `tx`: checks the lease, marks the worker seen, and
/// stores `impacts` and then the checkpoint, if any.
async fn report(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    lease: Uuid,
    impacts: &[ImpactRecord],
    checkpoint: Option<&Checkpoint>,
) -> Result<Report> {
    let now = now_ms();
    let held = check_lease(tx, job_id, lease, now).await?;
    touch_worker(tx, job_id, now).await?;
    let done = store_impacts(tx, job_id, &held, impacts, now).await?;
    if let Some(c) = checkpoint {
        store_checkpoint(tx, job_id, done, c, now).await?;
    }
    Ok(Report { now, held, done })
}

/// What the lease check learns about the job.
struct Held {
    planned: u32,
    done: u32,
}

async fn check_lease(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    lease: Uuid,
    now: i64,
) -> Result<Held> {
    let r = sqlx::query(
        "SELECT state, lease_id, lease_expires_ms, impacts_planned, impacts_done
         FROM jobs WHERE id = ?",
    )
    .bind(job_id)
    .fetch_optional(&mut **tx)
    .await?
    .ok_or_else(|| Error::NotFound(format!("job {job_id}")))?;
    let state: String = r.get("state");
    let holder: Option<String> = r.get("lease_id");
    let mine = holder.as_deref() == Some(lease.to_string().as_str());
    if mine && state == "cancelled" {
        return Err(Error::Gone(format!(
            "job {job_id} was cancelled with its campaign; drop it"
        )));
    }
    let live = r
        .get::<Option<i64>, _>("lease_expires_ms")
        .is_some_and(|e| e >= now);
    if !(mine && state == "leased" && live) {
        return Err(Error::Conflict(format!(
            "lease {lease} does not hold job {job_id} (expired or taken over); nothing was stored"
        )));
    }
    Ok(Held {
        planned: r.get::<i64, _>("impacts_planned") as u32,
        done: r.get::<i64, _>("impacts_done") as u32,
    })
}

/// Ends the lease on `job_id`: its state becomes `state` with `done` impacts stored at `now`.
/// A done job keeps its worker, as the one that finished it; a requeued one holds none.
async fn end_lease(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    state: &str,
    done: u32,
    now: i64,
) -> Result<()> {
    sqlx::query(
        "UPDATE jobs SET state = ?1, impacts_done = ?2, lease_id = NULL, lease_expires_ms = NULL,
                         worker = CASE WHEN ?1 = 'done' THEN worker END, updated_ms = ?3
         WHERE id = ?4",
    )
    .bind(state)
    .bind(done as i64)
    .bind(now)
    .bind(job_id)
    .execute(&mut **tx)
    .await?;
    Ok(())
}

/// Marks the worker holding `job_id` as seen at `now`; called by every write of a lease
/// holder before anything clears `jobs.worker`.
async fn touch_worker(tx: &mut Transaction<'static, Sqlite>, job_id: i64, now: i64) -> Result<()> {
    sqlx::query(
        "UPDATE workers SET last_seen_ms = ?
         WHERE name = (SELECT worker FROM jobs WHERE id = ?)",
    )
    .bind(now)
    .bind(job_id)
    .execute(&mut **tx)
    .await?;
    Ok(())
}

/// Appends impacts after those stored; ones already stored are skipped (a resumed job
/// re-runs impacts past its checkpoint, and a retried heartbeat resends). Returns the count
/// stored afterwards.
async fn store_impacts(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    held: &Held,
    impacts: &[ImpactRecord],
    now: i64,
) -> Result<u32> {
    let mut done = held.done;
    for (i, rec) in impacts.iter().enumerate() {
        let field = format!("impacts[{i}]");
        if rec.impact <= done {
            continue;
        }
        if rec.impact != done + 1 {
            return Err(Error::invalid(
                format!("{field}.impact"),
                format!("expected impact {} next, got {}", done + 1, rec.impact),
            ));
        }
        if rec.impact > held.planned {
            return Err(Error::invalid(
                format!("{field}.impact"),
                format!("the job plans only {} impacts", held.planned),
            ));
        }
        if !(rec.grain_mass_kg.is_finite() && rec.grain_mass_kg > 0.0) {
            return Err(Error::invalid(
                format!("{field}.grain_mass_kg"),
                "must be finite and > 0",
            ));
        }
        if !(rec.mass_loss_kg.is_finite() && rec.mass_loss_kg >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.mass_loss_kg"),
                "must be finite and ≥ 0",
            ));
        }
        let json = serde_json::to_string(rec).map_err(|e| Error::Internal(e.to_string()))?;
        sqlx::query(
            "INSERT INTO impacts (job_id, impact, grain_mass_kg, mass_loss_kg, record, created_ms)
             VALUES (?, ?, ?, ?, ?, ?)",
        )
        .bind(job_id)
        .bind(rec.impact as i64)
        .bind(rec.grain_mass_kg)
        .bind(rec.mass_loss_kg)
        .bind(json)
        .bind(now)
        .execute(&mut **tx)
        .await?;
        done = rec.impact;
    }
    Ok(done)
}

async fn store_checkpoint(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    stored: u32,
    c: &Checkpoint,
    now: i64,
) -> Result<()> {
    if c.impacts_done > stored {
        return Err(Error::invalid(
            "checkpoint.impacts_done",
            format!(
                "checkpoint after impact {} but only {stored} impacts are stored; send them first",
                c.impacts_done
            ),
        ));
    }
    let data = base64::engine::general_purpose::STANDARD
        .decode(&c.data_b64)
        .map_err(|e| Error::invalid("checkpoint.data_b64", format!("not base64: {e}")))?;
    let sha256 = crate::checkpoint::sha256_hex(&data);
    sqlx::query(
        "INSERT INTO checkpoints (job_id, impacts_done, data, sha256, updated_ms)
         VALUES (?, ?, ?, ?, ?)
         ON CONFLICT (job_id) DO UPDATE SET impacts_done = excluded.impacts_done,
             data = excluded.data, sha256 = excluded.sha256, updated_ms = excluded.updated_ms
         WHERE excluded.impacts_done >= checkpoints.impacts_done",
    )
    .bind(job_id)
    .bind(c.impacts_done as i64)
    .bind(data)
    .bind(sha256)
    .bind(now)
    .execute(&mut **tx)
    .await?;
    Ok(())
}

async fn load_checkpoint(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
) -> Result<Option<StoredCheckpoint>> {
    Ok(
        sqlx::query("SELECT impacts_done, data, sha256 FROM checkpoints WHERE job_id = ?")
            .bind(job_id)
            .fetch_optional(&mut **tx)
            .await?
            .map(|r| StoredCheckpoint {
                impacts_done: r.get::<i64, _>(0) as u32,
                data: r.get(1),
                sha256: r.get(2),
            }),
    )
}

pub(super) async fn reap(tx: &mut Transaction<'static, Sqlite>, now: i64) -> Result<u64> {
    let n = sqlx::query(
        "UPDATE jobs SET attempts = attempts + 1,
             last_error = 'lease expired (worker ' || COALESCE(worker, '?') || ' stopped reporting)',
             state = CASE WHEN attempts + 1 >=
                 (SELECT max_attempts FROM campaigns WHERE id = jobs.campaign_id)
                 THEN 'failed' ELSE 'queued' END,
             lease_id = NULL, worker = NULL, lease_expires_ms = NULL, updated_ms = ?
         WHERE state = 'leased' AND lease_expires_ms < ?",
    )
    .bind(now)
    .bind(now)
    .execute(&mut **tx)
    .await?
    .rows_affected();
    if n > 0 {
        tracing::info!(jobs = n, "expired leases returned to the queue");
    }
    Ok(n)
}
