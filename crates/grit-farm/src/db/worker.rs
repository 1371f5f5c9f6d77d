//! The store's side of the worker endpoints: leasing jobs, and the lease holder's writes
//! (heartbeat, complete, fail, release) with the impacts and checkpoints they carry; expired
//! leases go back to the queue. The writes go through the group writer (`group`), which
//! applies each with the `apply_*` function here inside a transaction shared with others.
//! That writer is the farm's bottleneck, so what needs no database is done by the caller
//! before or after it: impact records are serialised and checkpoints decoded and hashed
//! before a request is queued, and a lease's scene is parsed and its checkpoint encoded
//! after the claim has committed. Every scene's units (impacts, jet slices) go in one table,
//! checked by the scene's own rules (`grit_erosion::Scene::check_record`).

use std::time::Duration;

use base64::Engine;
use grit_erosion::Scene;
use sqlx::{Row, Sqlite, Transaction};
use uuid::Uuid;

use super::extend::stored_cell;
use super::group::{mismatch, Op, Reply};
use super::{now_ms, parse_uuid, Store};
use crate::api::{Checkpoint, ClaimedJob, HeartbeatResponse};
use crate::checkpoint::{sha256_hex, CheckpointBytes};
use crate::error::{Error, Result};
use crate::scenes::SceneRegistry;
use grit_erosion::campaign::{StoredCell, UnitMasses};

/// Longest failure message kept per job.
pub(super) const MAX_ERROR_CHARS: usize = 4000;
/// Workers silent for longer are forgotten, so the table of names cannot grow without end.
const WORKER_FORGET_MS: i64 = 7 * 24 * 3600 * 1000;

/// Unit rows inserted by one statement: 8 bound values each keeps it under SQLite's smallest
/// limit on bound variables (999).
const UNIT_ROWS_PER_INSERT: usize = 120;

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
    /// `campaigns.scene`: the scene's kind.
    scene: String,
    extendable: bool,
    checkpoint: Option<StoredCheckpoint>,
}

impl Leased {
    /// The claim's answer: the scene parsed and the checkpoint enveloped.
    fn claimed(self) -> Result<ClaimedJob> {
        let job_id = self.job_id;
        let params: serde_json::Value = stored_params(job_id, &self.params)?;
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
            scene: self.scene,
            params,
            extendable: self.extendable,
            checkpoint: self.checkpoint.map(|c| c.envelope(job_id)),
        })
    }
}

/// A lease holder's report ready to store: its records serialised before it is queued, so
/// the writer only checks and binds them, whatever the scene.
pub(super) struct NewUnits {
    /// The scene the records are of ([`Scene::KIND`]): a job of another scene refuses them.
    kind: &'static str,
    /// The unit in words ([`Scene::UNIT`]), also the name of a record's number field.
    unit: &'static str,
    /// Each record's unit number (1-based) and the record as JSON, with round-trip float
    /// formatting (every f64 comes back bit for bit).
    rows: Vec<(u32, String)>,
    /// What a cell's growth reads of each record ([`Scene::masses`]), stored beside it.
    masses: Vec<Option<UnitMasses>>,
    /// The scene's checks of the records.
    check: Box<dyn CheckUnits>,
}

/// What a lease holder reports with a write: the records of the units it finished, of its
/// job's scene, ready for the store, and the checkpoint after them when it sends one.
pub struct Reported {
    units: NewUnits,
    checkpoint: Option<CheckpointBytes>,
}

impl Reported {
    /// `records` of scene `S`, without a checkpoint.
    pub fn of<S: Scene>(records: &[S::Record]) -> Result<Reported> {
        let units = NewUnits::of::<S>(records)?;
        Ok(Reported {
            units,
            checkpoint: None,
        })
    }

    /// A report without units or checkpoint.
    pub fn none() -> Reported {
        let units = NewUnits {
            kind: "",
            unit: "unit",
            rows: Vec::new(),
            masses: Vec::new(),
            check: Box::new(NoUnits),
        };
        Reported {
            units,
            checkpoint: None,
        }
    }

    /// This report with `checkpoint` (checked by the caller:
    /// `crate::checkpoint::verify_upload`) as the state after its units.
    pub fn with_checkpoint(self, checkpoint: Option<CheckpointBytes>) -> Reported {
        Reported { checkpoint, ..self }
    }
}

/// The check of a report without units: there is nothing to check.
struct NoUnits;

impl CheckUnits for NoUnits {
    fn check(&self, _: i64, _: &str, _: &[usize], _: f64) -> Result<Vec<f64>> {
        Ok(Vec::new())
    }
}

impl NewUnits {
    /// `records` of scene `S`, serialised.
    fn of<S: Scene>(records: &[S::Record]) -> Result<NewUnits> {
        let rows = records
            .iter()
            .map(|rec| {
                let json =
                    serde_json::to_string(rec).map_err(|e| Error::Internal(e.to_string()))?;
                Ok((S::unit_of(rec), json))
            })
            .collect::<Result<_>>()?;
        Ok(NewUnits {
            kind: S::KIND,
            unit: S::UNIT,
            rows,
            masses: records.iter().map(S::masses).collect(),
            check: Box::new(Records::<S>(records.to_vec())),
        })
    }
}

/// A scene's checks of reported records, its type erased so one writer queue carries every
/// scene's reports.
trait CheckUnits: Send + Sync {
    /// Checks records `new` (indices into the report) against the job's parameters as stored
    /// (`params` JSON), the job having lost `lost` kg/m before the first; returns the loss after
    /// each. A refusal names the field as `units[i].…`.
    fn check(&self, job_id: i64, params: &str, new: &[usize], lost: f64) -> Result<Vec<f64>>;
}

/// The records of scene `S` in a report.
struct Records<S: Scene>(Vec<S::Record>);

impl<S: Scene> CheckUnits for Records<S> {
    fn check(&self, job_id: i64, params: &str, new: &[usize], mut lost: f64) -> Result<Vec<f64>> {
        let p: S::Params = stored_params(job_id, params)?;
        new.iter()
            .map(|&i| {
                lost = S::check_record(&p, &self.0[i], lost)
                    .map_err(|e| Error::invalid(format!("units[{i}].{}", e.field), e.rule))?;
                Ok(lost)
            })
            .collect()
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

    /// [`Store::claim_for`] a worker that runs this coordinator's own engine ([`Store::own`]),
    /// as the local workers of `grit run` do.
    pub async fn claim(&self, worker: &str) -> Result<Option<ClaimedJob>> {
        let own = serde_json::to_string(&self.own.engines).expect("a map of strings serialises");
        self.claim_for(worker, &own).await
    }

    /// Leases the next queued job of a campaign that is unpinned or pinned to the worker's
    /// fingerprint for its scene; `engines` is a JSON object from scene kind to fingerprint,
    /// `*` standing for every scene (`WorkerEngine::to_json`).
    pub async fn claim_for(&self, worker: &str, engines: &str) -> Result<Option<ClaimedJob>> {
        match self
            .group
            .apply(Op::Claim {
                worker: worker.to_owned(),
                engines: engines.to_owned(),
            })
            .await?
        {
            Reply::Claimed(job) => job.map(|j| j.claimed()).transpose(),
            _ => Err(mismatch()),
        }
    }

    /// Why a worker with fingerprints `engines` (as [`Store::claim`] takes them) got no job
    /// while jobs are queued: the first queued campaign pinned to another engine, named with
    /// its fingerprint; `None` when nothing is queued.
    pub async fn why_no_job(&self, engines: &str) -> Result<Option<String>> {
        let row = sqlx::query(
            "SELECT c.id, c.scene, c.engine FROM jobs j JOIN campaigns c ON c.id = j.campaign_id
             WHERE j.state = 'queued' ORDER BY j.campaign_seq LIMIT 1",
        )
        .fetch_optional(&self.read)
        .await?;
        Ok(row.map(|r| {
            let (id, scene, engine): (String, String, Option<String>) =
                (r.get(0), r.get(1), r.get(2));
            format!(
                "jobs are queued, but campaign {id} is pinned to {scene} engine {} and this \
                 worker runs {engines}: start a worker built from the campaign's commit, or \
                 resubmit the campaign for this engine",
                engine.as_deref().unwrap_or("(none)")
            )
        }))
    }

    /// Renews the lease, stores the finished units and the checkpoint if one is reported.
    pub async fn heartbeat(
        &self,
        job_id: i64,
        lease: Uuid,
        reported: Reported,
    ) -> Result<HeartbeatResponse> {
        let op = Op::Heartbeat {
            job_id,
            lease,
            units: reported.units,
            checkpoint: reported.checkpoint,
        };
        match self.group.apply(op).await? {
            Reply::Beat(r) => Ok(r),
            _ => Err(mismatch()),
        }
    }

    /// Stores the last units and marks the job done; it must then have every planned unit.
    /// The checkpoint after the last unit is kept when the job's cell may still grow, and a
    /// cell whose last job this was is assessed and grown in the same transaction.
    pub async fn complete(&self, job_id: i64, lease: Uuid, reported: Reported) -> Result<()> {
        let op = Op::Complete {
            job_id,
            lease,
            units: reported.units,
            checkpoint: reported.checkpoint,
            scenes: self.scenes.clone(),
        };
        self.group.apply(op).await.map(drop)
    }

    /// Records a failure: back to the queue, or `failed` once attempts reach the maximum. The
    /// report's units are stored; a failed run's checkpoint is not kept.
    pub async fn fail(
        &self,
        job_id: i64,
        lease: Uuid,
        error: &str,
        reported: Reported,
    ) -> Result<()> {
        let op = Op::Fail {
            job_id,
            lease,
            error: error.chars().take(MAX_ERROR_CHARS).collect(),
            units: reported.units,
        };
        self.group.apply(op).await.map(drop)
    }

    /// Gives a job back without counting an attempt, keeping its units and checkpoint.
    pub async fn release(&self, job_id: i64, lease: Uuid, reported: Reported) -> Result<()> {
        let op = Op::Release {
            job_id,
            lease,
            units: reported.units,
            checkpoint: reported.checkpoint,
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
    engines: &str,
    sweep: bool,
) -> Result<Option<Leased>> {
    let now = now_ms();
    if sweep {
        reap(tx, now).await?;
    }
    // Every claim counts as a sign of life, an empty queue's too: idle workers are listed,
    // with the engines they run, so a queue waiting for an engine nobody has shows.
    sqlx::query(
        "INSERT INTO workers (name, first_seen_ms, last_seen_ms, engines) VALUES (?1, ?2, ?2, ?3)
         ON CONFLICT (name) DO UPDATE SET last_seen_ms = excluded.last_seen_ms,
                                          engines = excluded.engines",
    )
    .bind(worker)
    .bind(now)
    .bind(engines)
    .execute(&mut **tx)
    .await?;
    let lease = Uuid::new_v4();
    let expires = now + lease_ttl.as_millis() as i64;
    // The first queued job of a campaign that is unpinned or pinned to the worker's
    // fingerprint for its scene; the lease records that fingerprint for the units. Within a
    // campaign, a cell-by-cell campaign's lowest cell first, then fewest units planned first:
    // a grown cell's samples wait for the other cells' first round
    // (migrations/0011_queue_by_round.sql, 0012_queue_by_cell.sql).
    let Some(r) = sqlx::query(
        "UPDATE jobs SET state = 'leased', lease_id = ?1, worker = ?2, lease_expires_ms = ?3,
                         updated_ms = ?4, units_reported = 0,
                         engine = (SELECT coalesce(json_extract(?5, '$.\"' || c.scene || '\"'),
                                                   json_extract(?5, '$.\"*\"'))
                                   FROM campaigns c WHERE c.id = jobs.campaign_id)
         WHERE id = (SELECT j.id FROM jobs j JOIN campaigns c ON c.id = j.campaign_id
                     WHERE j.state = 'queued'
                       AND (c.engine IS NULL
                            OR c.engine = coalesce(json_extract(?5, '$.\"' || c.scene || '\"'),
                                                   json_extract(?5, '$.\"*\"')))
                     ORDER BY j.campaign_seq, j.queue_rank, j.units_planned, j.sample_index,
                              j.cell_index LIMIT 1)
         RETURNING id, campaign_id, cell_index, sample_index, seed, units_planned, units_done",
    )
    .bind(lease.to_string())
    .bind(worker)
    .bind(expires)
    .bind(now)
    .bind(engines)
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
        "SELECT c.params, c.units, c.units_max, k.units_done, k.data, k.sha256,
                (SELECT scene FROM campaigns WHERE id = ?2)
         FROM cells c LEFT JOIN checkpoints k ON k.job_id = ?1
         WHERE c.campaign_id = ?2 AND c.cell_index = ?3",
    )
    .bind(job_id)
    .bind(&campaign)
    .bind(cell)
    .fetch_one(&mut **tx)
    .await?;
    // At its cap too: a cell stopped there unsteady runs on from these states once a later
    // spec raises the cap (`Store::raise_caps`).
    let extendable = c.get::<Option<i64>, _>(2).is_some();
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
        planned: r.get("units_planned"),
        done: r.get("units_done"),
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
    // Stored or new, the highest unit this lease has reported: below `units_done`, the worker
    // is still computing stored units again (the status's `replaying`).
    let reported = units.rows.iter().map(|(n, _)| *n).max().unwrap_or(0);
    sqlx::query(
        "UPDATE jobs SET lease_expires_ms = ?, units_done = ?, updated_ms = ?,
                         units_reported = max(units_reported, ?)
         WHERE id = ?",
    )
    .bind(expires)
    .bind(done as i64)
    .bind(now)
    .bind(reported as i64)
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
    scenes: &SceneRegistry,
) -> Result<()> {
    let Report { now, held, done } = report(tx, job_id, lease, units, checkpoint).await?;
    if done < held.planned {
        return Err(Error::invalid(
            "units",
            format!(
                "the job has {done} of its {} planned units; send the rest before completing",
                held.planned
            ),
        ));
    }
    end_lease(tx, job_id, "done", done, now).await?;
    // A job that never stored a checkpoint has none to drop; a growing cell's are dropped
    // once it is assessed final.
    if held.cell.until_steady.is_none() && (held.has_checkpoint || checkpoint.is_some()) {
        sqlx::query("DELETE FROM checkpoints WHERE job_id = ?")
            .bind(job_id)
            .execute(&mut **tx)
            .await?;
    }
    if held.cell.until_steady.is_none() && held.cell.target_sem.is_none() {
        return Ok(());
    }
    let scene = scenes.get(&held.scene)?;
    super::extend::settle_cell(tx, &*scene, &held.campaign, &held.cell, now).await?;
    Ok(())
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
        "UPDATE jobs SET attempts = attempts + 1, units_done = ?, last_error = ?,
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
/// stores the units and then the checkpoint, if any.
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
    let done = store_units(tx, job_id, &held, units, now).await?;
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
    /// The job's cell as it stands now; its `params`, the scene as JSON, bound the records a
    /// worker may send.
    cell: StoredCell,
    /// Whether a checkpoint of the job is stored.
    has_checkpoint: bool,
    /// The job's scene (`campaigns.scene`).
    scene: String,
    /// The lease holder's engine fingerprint for that scene, stamped on its units.
    engine: Option<String>,
}

async fn check_lease(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    lease: Uuid,
    now: i64,
) -> Result<Held> {
    let r = sqlx::query(
        "SELECT j.state AS state, j.lease_id AS lease_id, j.lease_expires_ms AS lease_expires_ms,
                j.units_planned AS units_planned, j.units_done AS units_done,
                j.worker AS worker, j.campaign_id AS campaign_id, j.cell_index AS cell_index,
                k.angle_deg AS angle_deg, k.shape AS shape, k.swept AS swept,
                k.units AS units, k.samples AS samples, k.units_max AS units_max,
                k.units_step AS units_step, k.units_balanced AS units_balanced,
                k.samples_max AS samples_max,
                k.target_sem_rel AS target_sem_rel,
                EXISTS (SELECT 1 FROM checkpoints c WHERE c.job_id = j.id) AS has_checkpoint,
                (SELECT p.scene FROM campaigns p WHERE p.id = j.campaign_id) AS scene,
                j.engine AS engine, k.params AS params
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
        planned: r.get::<i64, _>("units_planned") as u32,
        done: r.get::<i64, _>("units_done") as u32,
        worker: r.get("worker"),
        campaign: r.get("campaign_id"),
        cell: stored_cell(&r)?,
        has_checkpoint: r.get("has_checkpoint"),
        scene: r.get("scene"),
        engine: r.get("engine"),
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
        "UPDATE jobs SET state = ?1, units_done = ?2, lease_id = NULL, lease_expires_ms = NULL,
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

/// The order appended units keep (`store_units`): `unit` `n` of a job with `done` stored and
/// `planned` in all is skipped (false) when already stored, taken (true) when it is the next,
/// and refused, naming `field`, when it leaves a gap or passes the plan.
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

/// The mass job `job_id` lost by its last stored unit (kg/m), 0 before the first.
async fn stored_loss(tx: &mut Transaction<'static, Sqlite>, job_id: i64) -> Result<f64> {
    let lost: Option<f64> = sqlx::query_scalar(
        "SELECT lost_kg_m FROM units WHERE job_id = ? ORDER BY unit DESC LIMIT 1",
    )
    .bind(job_id)
    .fetch_optional(&mut **tx)
    .await?;
    Ok(lost.unwrap_or(0.0))
}

/// The scene a job's cell stored at submission (`cells.params`).
fn stored_params<T: serde::de::DeserializeOwned>(job_id: i64, params: &str) -> Result<T> {
    serde_json::from_str(params)
        .map_err(|e| Error::Internal(format!("stored params of job {job_id}: {e}")))
}

/// Appends units after those stored; ones already stored are skipped (a resumed job re-runs
/// units past its checkpoint, and a retried heartbeat resends). Every new record is checked
/// by its scene before any is written, and they go in with one statement. Returns the count
/// stored afterwards.
async fn store_units(
    tx: &mut Transaction<'static, Sqlite>,
    job_id: i64,
    held: &Held,
    units: &NewUnits,
    now: i64,
) -> Result<u32> {
    if units.rows.is_empty() {
        return Ok(held.done);
    }
    if units.kind != held.scene {
        return Err(Error::invalid(
            "units",
            format!(
                "job {job_id} runs the {} scene: report its units, not {} units",
                held.scene, units.kind
            ),
        ));
    }
    let mut done = held.done;
    let mut new = Vec::with_capacity(units.rows.len());
    for (i, (n, _)) in units.rows.iter().enumerate() {
        if is_next(
            units.unit,
            *n,
            done,
            held.planned,
            format!("units[{i}].{}", units.unit),
        )? {
            new.push(i);
            done = *n;
        }
    }
    if new.is_empty() {
        return Ok(done);
    }
    let lost = units.check.check(
        job_id,
        &held.cell.params,
        &new,
        stored_loss(tx, job_id).await?,
    )?;
    for chunk in new
        .iter()
        .zip(&lost)
        .collect::<Vec<_>>()
        .chunks(UNIT_ROWS_PER_INSERT)
    {
        let mut qb = sqlx::QueryBuilder::<Sqlite>::new(
            "INSERT INTO units (job_id, unit, lost_kg_m, record, created_ms, grain_kg_m, loss_kg_m,
                                damage_kg_m, engine) ",
        );
        qb.push_values(chunk, |mut b, (&i, &lost)| {
            let (n, json) = &units.rows[i];
            let masses = units.masses[i];
            b.push_bind(job_id)
                .push_bind(*n as i64)
                .push_bind(lost)
                .push_bind(json.as_str())
                .push_bind(now)
                .push_bind(masses.map(|m| m.grain_kg_m))
                .push_bind(masses.map(|m| m.loss_kg_m))
                .push_bind(masses.and_then(|m| m.damage_kg_m))
                .push_bind(held.engine.as_deref());
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
                "checkpoint after unit {} but only {stored} units are stored; send them first",
                c.impacts_done
            ),
        ));
    }
    sqlx::query(
        "INSERT INTO checkpoints (job_id, units_done, data, sha256, updated_ms)
         VALUES (?, ?, ?, ?, ?)
         ON CONFLICT (job_id) DO UPDATE SET units_done = excluded.units_done,
             data = excluded.data, sha256 = excluded.sha256, updated_ms = excluded.updated_ms
         WHERE excluded.units_done >= checkpoints.units_done",
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
    fn appended_units_are_skipped_taken_or_refused_by_their_number() {
        let f = || "units[0].slice".to_string();
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
