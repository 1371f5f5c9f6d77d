//! The store's side of the worker endpoints: leasing jobs, and the lease holder's writes
//! (heartbeat, complete, fail, release) with the impacts and checkpoints they carry; expired
//! leases go back to the queue. The writes go through the group writer (`group`), which
//! applies each with the `apply_*` function here inside a transaction shared with others.
//! That writer is the farm's bottleneck, so what needs no database is done by the caller
//! before or after it: impact records are serialised and checkpoints decoded and hashed
//! before a request is queued, and a lease's scene is parsed and its checkpoint encoded
//! after the claim has committed. A jet job's lease holder reports slices, stored in their own
//! table, where an impact job's reports impacts; the rules are the same.

use std::time::Duration;

use base64::Engine;
use grit_erosion::jet::{JetParams, JetRun, JetSlice};
use grit_erosion::{ImpactParams, ImpactRecord, Sample, Scene};
use sqlx::{Row, Sqlite, Transaction};
use uuid::Uuid;

use super::extend::CellPlan;
use super::group::{mismatch, Op, Reply};
use super::{now_ms, parse_uuid, Store};
use crate::api::{Checkpoint, ClaimedJob, HeartbeatResponse};
use crate::checkpoint::{sha256_hex, CheckpointBytes};
use crate::error::{Error, Result};

/// Longest failure message kept per job.
pub(super) const MAX_ERROR_CHARS: usize = 4000;
/// Workers silent for longer are forgotten, so the table of names cannot grow without end.
const WORKER_FORGET_MS: i64 = 7 * 24 * 3600 * 1000;

/// Impact rows inserted by one statement: 6 bound values each keeps it under SQLite's
/// smallest limit on bound variables (999).
const IMPACT_ROWS_PER_INSERT: usize = 150;

/// A checkpoint as stored.
struct StoredCheckpoint {
    impacts_done: u32,
    data: Vec<u8>,
    /// `None` for a checkpoint stored before checksums were.
    sha256: Option<String>,
}

impl StoredCheckpoint {
    /// The envelope handed to the worker resuming job `job_id`. It carries the stored
    /// checksum, not one of the bytes as read now, so the worker notices bytes damaged at
    /// rest; a checkpoint stored before checksums were is hashed here.
    fn envelope(self, job_id: i64) -> Checkpoint {
        Checkpoint {
            job_id,
            impacts_done: self.impacts_done,
            size_bytes: self.data.len() as u64,
            sha256: self.sha256.unwrap_or_else(|| sha256_hex(&self.data)),
            data_b64: base64::engine::general_purpose::STANDARD.encode(&self.data),
        }
    }
}

/// A lease as the writer granted it, with the scene still as stored; [`Leased::claimed`]
/// makes it the claim's answer once the writer has moved on.
pub(super) struct Leased {
    pub job_id: i64,
    lease: Uuid,
    lease_ttl_s: f64,
    campaign: String,
    cell: i64,
    sample: i64,
    seed: i64,
    planned: i64,
    done: i64,
    /// `cells.params`: the scene as JSON.
    params: String,
    /// `campaigns.scene`: `impact` or `jet`.
    scene: String,
    extendable: bool,
    checkpoint: Option<StoredCheckpoint>,
}

impl Leased {
    /// The claim's answer: the scene parsed and the checkpoint enveloped.
    fn claimed(self) -> Result<ClaimedJob> {
        let job_id = self.job_id;
        let (params, jet) = if self.scene == "jet" {
            let jet: JetParams = stored_params(job_id, &self.params)?;
            (ImpactParams::default(), Some(jet))
        } else {
            (stored_params(job_id, &self.params)?, None)
        };
        Ok(ClaimedJob {
            job_id,
            lease_id: self.lease,
            lease_ttl_s: self.lease_ttl_s,
            campaign_id: parse_uuid(&self.campaign)?,
            cell: self.cell as u32,
            sample: self.sample as u32,
            seed: self.seed as u64,
            impacts_planned: self.planned as u32,
            impacts_done: self.done as u32,
            params,
            jet,
            extendable: self.extendable,
            checkpoint: self.checkpoint.map(|c| c.envelope(job_id)),
        })
    }
}

/// A record to store (an impact, a jet slice), serialised before it is queued so the writer
/// only binds it.
pub(super) struct NewRecord<R> {
    /// The record, for its scene's checks and its columns.
    record: R,
    /// The whole record as JSON, with round-trip float formatting (every f64 comes back
    /// bit for bit; a slice's profile included).
    json: String,
}

/// `records` ready to store.
fn serialised<R: serde::Serialize + Clone>(records: &[R]) -> Result<Vec<NewRecord<R>>> {
    records
        .iter()
        .map(|rec| {
            Ok(NewRecord {
                record: rec.clone(),
                json: serde_json::to_string(rec).map_err(|e| Error::Internal(e.to_string()))?,
            })
        })
        .collect()
}

/// What a lease holder reports with a write: the finished impacts of an impact job, or the
/// finished slices of a jet job (the other one empty).
#[derive(Debug, Clone, Copy, Default)]
pub struct Reported<'a> {
    /// Impacts, for an impact job.
    pub impacts: &'a [ImpactRecord],
    /// Slices, for a jet job.
    pub slices: &'a [JetSlice],
}

impl<'a> Reported<'a> {
    /// Impacts of an impact job.
    pub fn impacts(impacts: &'a [ImpactRecord]) -> Self {
        Reported {
            impacts,
            slices: &[],
        }
    }

    /// Slices of a jet job.
    pub fn slices(slices: &'a [JetSlice]) -> Self {
        Reported {
            impacts: &[],
            slices,
        }
    }
}

/// A report ready to store: records serialised before the writer sees them.
pub(super) struct NewUnits {
    pub impacts: Vec<NewRecord<ImpactRecord>>,
    pub slices: Vec<NewRecord<JetSlice>>,
}

impl NewUnits {
    fn of(r: Reported<'_>) -> Result<NewUnits> {
        Ok(NewUnits {
            impacts: serialised(r.impacts)?,
            slices: serialised(r.slices)?,
        })
    }
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
            Reply::Claimed(job) => job.map(|j| j.claimed()).transpose(),
            _ => Err(mismatch()),
        }
    }

    /// Renews the lease, stores finished impacts and an optional checkpoint (checked by the
    /// caller: `crate::checkpoint::verify_upload`).
    pub async fn heartbeat(
        &self,
        job_id: i64,
        lease: Uuid,
        impacts: &[ImpactRecord],
        checkpoint: Option<CheckpointBytes>,
    ) -> Result<HeartbeatResponse> {
        self.heartbeat_with(job_id, lease, Reported::impacts(impacts), checkpoint)
            .await
    }

    /// [`Store::heartbeat`] for either scene: impacts of an impact job, slices of a jet job.
    pub async fn heartbeat_with(
        &self,
        job_id: i64,
        lease: Uuid,
        reported: Reported<'_>,
        checkpoint: Option<CheckpointBytes>,
    ) -> Result<HeartbeatResponse> {
        let op = Op::Heartbeat {
            job_id,
            lease,
            units: NewUnits::of(reported)?,
            checkpoint,
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
        checkpoint: Option<CheckpointBytes>,
    ) -> Result<()> {
        self.complete_with(job_id, lease, Reported::impacts(impacts), checkpoint)
            .await
    }

    /// [`Store::complete`] for either scene; a jet job must then have every planned slice.
    pub async fn complete_with(
        &self,
        job_id: i64,
        lease: Uuid,
        reported: Reported<'_>,
        checkpoint: Option<CheckpointBytes>,
    ) -> Result<()> {
        let op = Op::Complete {
            job_id,
            lease,
            units: NewUnits::of(reported)?,
            checkpoint,
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
        self.fail_with(job_id, lease, error, Reported::impacts(impacts))
            .await
    }

    /// [`Store::fail`] for either scene.
    pub async fn fail_with(
        &self,
        job_id: i64,
        lease: Uuid,
        error: &str,
        reported: Reported<'_>,
    ) -> Result<()> {
        let op = Op::Fail {
            job_id,
            lease,
            error: error.chars().take(MAX_ERROR_CHARS).collect(),
            units: NewUnits::of(reported)?,
        };
        self.group.apply(op).await.map(drop)
    }

    /// Gives a job back without counting an attempt, keeping its impacts and checkpoint.
    pub async fn release(
        &self,
        job_id: i64,
        lease: Uuid,
        impacts: &[ImpactRecord],
        checkpoint: Option<CheckpointBytes>,
    ) -> Result<()> {
        self.release_with(job_id, lease, Reported::impacts(impacts), checkpoint)
            .await
    }

    /// [`Store::release`] for either scene.
    pub async fn release_with(
        &self,
        job_id: i64,
        lease: Uuid,
        reported: Reported<'_>,
        checkpoint: Option<CheckpointBytes>,
    ) -> Result<()> {
        let op = Op::Release {
            job_id,
            lease,
            units: NewUnits::of(reported)?,
            checkpoint,
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
) -> Result<Option<Leased>> {
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
    // The job's cell and its checkpoint, if any, in one statement.
    let c = sqlx::query(
        "SELECT c.params, c.impacts, c.impacts_max, k.impacts_done, k.data, k.sha256,
                (SELECT scene FROM campaigns WHERE id = ?2)
         FROM cells c LEFT JOIN checkpoints k ON k.job_id = ?1
         WHERE c.campaign_id = ?2 AND c.cell_index = ?3",
    )
    .bind(job_id)
    .bind(&campaign)
    .bind(cell)
    .fetch_one(&mut **tx)
    .await?;
    let extendable = c
        .get::<Option<i64>, _>(2)
        .is_some_and(|max| c.get::<i64, _>(1) < max);
    let checkpoint = c
        .get::<Option<i64>, _>(3)
        .map(|impacts_done| StoredCheckpoint {
            impacts_done: impacts_done as u32,
            data: c.get(4),
            sha256: c.get(5),
        });
    Ok(Some(Leased {
        job_id,
        lease,
        lease_ttl_s: lease_ttl.as_secs_f64(),
        campaign,
        cell,
        sample: r.get("sample_index"),
        seed: r.get("seed"),
        planned: r.get("impacts_planned"),
        done: r.get("impacts_done"),
        params: c.get(0),
        scene: c.get(6),
        extendable,
        checkpoint,
    }))
}

/// A heartbeat in `tx`: renews the lease, stores finished impacts and an optional checkpoint.
pub(super) async fn apply_heartbeat(
    tx: &mut Transaction<'static, Sqlite>,
    lease_ttl: Duration,
    job_id: i64,
    lease: Uuid,
    units: &NewUnits,
    checkpoint: Option<&CheckpointBytes>,
) -> Result<HeartbeatResponse> {
    let Report { now, done, .. } = report(tx, job_id, lease, units, checkpoint).await?;
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
    units: &NewUnits,
    checkpoint: Option<&CheckpointBytes>,
) -> Result<()> {
    let Report { now, held, done } = report(tx, job_id, lease, units, checkpoint).await?;
    if done < held.planned {
        let unit = held.unit();
        return Err(Error::invalid(
            unit,
            format!(
                "the job has {done} of its {} planned {unit}; send the rest before completing",
                held.planned
            ),
        ));
    }
    end_lease(tx, job_id, "done", done, now).await?;
    // A job that never stored a checkpoint has none to drop.
    if !held.plan.impacts_may_grow() && (held.has_checkpoint || checkpoint.is_some()) {
        sqlx::query("DELETE FROM checkpoints WHERE job_id = ?")
            .bind(job_id)
            .execute(&mut **tx)
            .await?;
    }
    super::extend::settle_cell(tx, &held.campaign, held.cell, held.plan, now).await
}

/// A failure in `tx`, by the rules of [`Store::fail`]; `error` comes cut to
/// [`MAX_ERROR_CHARS`].
pub(super) async fn apply_fail(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    lease: Uuid,
    error: &str,
    units: &NewUnits,
) -> Result<()> {
    let Report { now, done, .. } = report(tx, job_id, lease, units, None).await?;
    sqlx::query(
        "UPDATE jobs SET attempts = attempts + 1, impacts_done = ?, last_error = ?,
             state = CASE WHEN attempts + 1 >=
                 (SELECT max_attempts FROM campaigns WHERE id = jobs.campaign_id)
                 THEN 'failed' ELSE 'queued' END,
             lease_id = NULL, worker = NULL, lease_expires_ms = NULL, updated_ms = ?
         WHERE id = ?",
    )
    .bind(done as i64)
    .bind(error)
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
    units: &NewUnits,
    checkpoint: Option<&CheckpointBytes>,
) -> Result<u32> {
    let Report { now, done, .. } = report(tx, job_id, lease, units, checkpoint).await?;
    end_lease(tx, job_id, "queued", done, now).await?;
    Ok(done)
}

/// The start of a lease holder's write in `tx`: checks the lease, marks the worker seen, and
/// stores the impacts (or a jet job's slices) and then the checkpoint, if any.
async fn report(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    lease: Uuid,
    units: &NewUnits,
    checkpoint: Option<&CheckpointBytes>,
) -> Result<Report> {
    let now = now_ms();
    let held = check_lease(tx, job_id, lease, now).await?;
    touch_worker(tx, held.worker.as_deref(), now).await?;
    let done = if held.jet {
        if !units.impacts.is_empty() {
            return Err(Error::invalid(
                "impacts",
                format!("job {job_id} runs the jet scene: report slices, not impacts"),
            ));
        }
        store_slices(tx, job_id, &held, &units.slices, now).await?
    } else {
        if !units.slices.is_empty() {
            return Err(Error::invalid(
                "slices",
                format!("job {job_id} runs the impact scene: report impacts, not slices"),
            ));
        }
        store_impacts(tx, job_id, &held, &units.impacts, now).await?
    };
    if let Some(c) = checkpoint {
        store_checkpoint(tx, job_id, done, c, now).await?;
    }
    Ok(Report { now, held, done })
}

/// What the lease check learns about the job, its cell's plan included (which a completion
/// needs), so no write of a lease holder reads the job twice.
struct Held {
    planned: u32,
    done: u32,
    /// The lease holder's name.
    worker: Option<String>,
    campaign: String,
    cell: i64,
    plan: CellPlan,
    /// Whether a checkpoint of the job is stored.
    has_checkpoint: bool,
    /// Whether the job runs the jet scene (its units are slices).
    jet: bool,
    /// `cells.params`: the scene as JSON, which bounds the records a worker may send.
    params: String,
}

impl Held {
    /// The job's unit of progress, as its field is named.
    fn unit(&self) -> &'static str {
        if self.jet {
            "slices"
        } else {
            "impacts"
        }
    }
}

async fn check_lease(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    lease: Uuid,
    now: i64,
) -> Result<Held> {
    let r = sqlx::query(
        "SELECT j.state AS state, j.lease_id AS lease_id, j.lease_expires_ms AS lease_expires_ms,
                j.impacts_planned AS impacts_planned, j.impacts_done AS impacts_done,
                j.worker AS worker, j.campaign_id AS campaign_id, j.cell_index AS cell_index,
                k.impacts AS impacts, k.samples AS samples, k.impacts_max AS impacts_max,
                k.impacts_step AS impacts_step, k.samples_max AS samples_max,
                k.target_sem_rel AS target_sem_rel,
                EXISTS (SELECT 1 FROM checkpoints c WHERE c.job_id = j.id) AS has_checkpoint,
                (SELECT p.scene FROM campaigns p WHERE p.id = j.campaign_id) AS scene,
                k.params AS params
         FROM jobs j JOIN cells k ON k.campaign_id = j.campaign_id AND k.cell_index = j.cell_index
         WHERE j.id = ?",
    )
    .bind(job_id)
    .fetch_optional(&mut **tx)
    .await?
    .ok_or_else(|| Error::NotFound(format!("job {job_id}")))?;
    let state: &str = r.get("state");
    let holder: Option<&str> = r.get("lease_id");
    let mut text = Uuid::encode_buffer();
    let mine = holder == Some(&*lease.hyphenated().encode_lower(&mut text));
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
        worker: r.get("worker"),
        campaign: r.get("campaign_id"),
        cell: r.get("cell_index"),
        plan: CellPlan::from_row(&r),
        has_checkpoint: r.get("has_checkpoint"),
        jet: r.get::<&str, _>("scene") == "jet",
        params: r.get("params"),
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

/// Marks the lease holder `worker` as seen at `now`; called by every write of a lease holder
/// before anything clears `jobs.worker`.
async fn touch_worker(
    tx: &mut Transaction<'static, Sqlite>,
    worker: Option<&str>,
    now: i64,
) -> Result<()> {
    let Some(worker) = worker else {
        return Ok(());
    };
    sqlx::query("UPDATE workers SET last_seen_ms = ? WHERE name = ?")
        .bind(now)
        .bind(worker)
        .execute(&mut **tx)
        .await?;
    Ok(())
}

/// The order appended records keep (`store_impacts`, `store_slices`): record `n` of a job with
/// `done` stored and `planned` in all is skipped (false) when already stored, taken (true) when
/// it is the next, and refused, naming `field`, when it leaves a gap or passes the plan.
fn is_next(unit: &str, n: u32, done: u32, planned: u32, field: String) -> Result<bool> {
    if n <= done {
        return Ok(false);
    }
    if n != done + 1 {
        return Err(Error::invalid(
            field,
            format!("expected {unit} {} next, got {n}", done + 1),
        ));
    }
    if n > planned {
        return Err(Error::invalid(
            field,
            format!("the job plans only {planned} {unit}s"),
        ));
    }
    Ok(true)
}

/// The mass job `job_id`'s stored impacts lost, in all (kg/m).
async fn stored_loss(tx: &mut Transaction<'static, Sqlite>, job_id: i64) -> Result<f64> {
    let sum: Option<f64> =
        sqlx::query_scalar("SELECT SUM(mass_loss_kg) FROM impacts WHERE job_id = ?")
            .bind(job_id)
            .fetch_one(&mut **tx)
            .await?;
    Ok(sum.unwrap_or(0.0))
}

/// The scene a job's cell stored at submission (`cells.params`).
fn stored_params<T: serde::de::DeserializeOwned>(job_id: i64, params: &str) -> Result<T> {
    serde_json::from_str(params)
        .map_err(|e| Error::Internal(format!("stored params of job {job_id}: {e}")))
}

/// Appends impacts after those stored; ones already stored are skipped (a resumed job
/// re-runs impacts past its checkpoint, and a retried heartbeat resends). Every record is
/// checked before any is written, and the new ones go in with one statement. Returns the
/// count stored afterwards.
async fn store_impacts(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    held: &Held,
    impacts: &[NewRecord<ImpactRecord>],
    now: i64,
) -> Result<u32> {
    let mut done = held.done;
    let mut new = Vec::with_capacity(impacts.len());
    let mut scene = None;
    // The sample's loss so far, read once the first new record needs it.
    let mut lost: Option<f64> = None;
    for (i, rec) in impacts.iter().enumerate() {
        let field = |name: &str| format!("impacts[{i}].{name}");
        if !is_next(
            "impact",
            rec.record.impact,
            done,
            held.planned,
            field("impact"),
        )? {
            continue;
        }
        let p = match &scene {
            Some(p) => p,
            None => scene.insert(stored_params::<ImpactParams>(job_id, &held.params)?),
        };
        let before = match lost {
            Some(l) => l,
            None => stored_loss(tx, job_id).await?,
        };
        lost = Some(
            Sample::check_record(p, &rec.record, before)
                .map_err(|e| Error::invalid(field(&e.field), e.rule))?,
        );
        new.push(rec);
        done = rec.record.impact;
    }
    for chunk in new.chunks(IMPACT_ROWS_PER_INSERT) {
        let mut qb = sqlx::QueryBuilder::<Sqlite>::new(
            "INSERT INTO impacts (job_id, impact, grain_mass_kg, mass_loss_kg, record, created_ms) ",
        );
        qb.push_values(chunk, |mut b, rec| {
            b.push_bind(job_id)
                .push_bind(rec.record.impact as i64)
                .push_bind(rec.record.grain_mass_kg)
                .push_bind(rec.record.mass_loss_kg)
                .push_bind(rec.json.as_str())
                .push_bind(now);
        });
        qb.build().execute(&mut **tx).await?;
    }
    Ok(done)
}

/// Appends a jet job's slices after those stored, by the rules of [`store_impacts`]: slices
/// already stored are skipped, the next must be stored + 1, every record is checked before
/// any is written. Returns the count stored afterwards.
async fn store_slices(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    held: &Held,
    slices: &[NewRecord<JetSlice>],
    now: i64,
) -> Result<u32> {
    let mut done = held.done;
    let mut new = Vec::with_capacity(slices.len());
    let mut scene = None;
    for (i, rec) in slices.iter().enumerate() {
        let field = |name: &str| format!("slices[{i}].{name}");
        if !is_next(
            "slice",
            rec.record.slice,
            done,
            held.planned,
            field("slice"),
        )? {
            continue;
        }
        let p = match &scene {
            Some(p) => p,
            None => scene.insert(stored_params::<JetParams>(job_id, &held.params)?),
        };
        JetRun::check_record(p, &rec.record, 0.0)
            .map_err(|e| Error::invalid(field(&e.field), e.rule))?;
        new.push(rec);
        done = rec.record.slice;
    }
    for chunk in new.chunks(IMPACT_ROWS_PER_INSERT) {
        let mut qb = sqlx::QueryBuilder::<Sqlite>::new(
            "INSERT INTO slices (job_id, slice, t_s, mass_loss_kg_m, record, created_ms) ",
        );
        qb.push_values(chunk, |mut b, rec| {
            b.push_bind(job_id)
                .push_bind(rec.record.slice as i64)
                .push_bind(rec.record.sample.t_s)
                .push_bind(rec.record.sample.mass_loss_kg_m)
                .push_bind(rec.json.as_str())
                .push_bind(now);
        });
        qb.build().execute(&mut **tx).await?;
    }
    Ok(done)
}

async fn store_checkpoint(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    stored: u32,
    c: &CheckpointBytes,
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
    sqlx::query(
        "INSERT INTO checkpoints (job_id, impacts_done, data, sha256, updated_ms)
         VALUES (?, ?, ?, ?, ?)
         ON CONFLICT (job_id) DO UPDATE SET impacts_done = excluded.impacts_done,
             data = excluded.data, sha256 = excluded.sha256, updated_ms = excluded.updated_ms
         WHERE excluded.impacts_done >= checkpoints.impacts_done",
    )
    .bind(job_id)
    .bind(c.impacts_done as i64)
    .bind(c.bytes.as_slice())
    .bind(c.sha256.as_str())
    .bind(now)
    .execute(&mut **tx)
    .await?;
    Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;

    fn refusal(r: Result<bool>) -> (String, String) {
        match r {
            Err(Error::Invalid { field, rule }) => (field, rule),
            other => panic!("expected a refusal, got {other:?}"),
        }
    }

    #[test]
    fn appended_records_are_skipped_taken_or_refused_by_their_number() {
        let f = || "slices[0].slice".to_string();
        assert!(!is_next("slice", 2, 2, 5, f()).unwrap());
        assert!(is_next("slice", 3, 2, 5, f()).unwrap());
        assert_eq!(
            refusal(is_next("slice", 4, 2, 5, f())),
            (f(), "expected slice 3 next, got 4".to_string())
        );
        assert_eq!(
            refusal(is_next("impact", 6, 5, 5, f())),
            (f(), "the job plans only 5 impacts".to_string())
        );
    }
}
