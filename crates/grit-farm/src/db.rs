//! The coordinator's SQLite store. Every state change is one `BEGIN IMMEDIATE` transaction
//! on the single writer connection; reads go through a separate read-only pool so status
//! polling never queues behind writes (WAL lets readers run beside the writer).

use std::collections::BTreeMap;
use std::path::Path;
use std::str::FromStr;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use base64::Engine;
use grit_erosion::campaign::CampaignSpec;
use grit_erosion::{aggregate_campaign, Impact, ImpactParams, ImpactRecord, SampleInput};
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteJournalMode, SqlitePool, SqlitePoolOptions, SqliteSynchronous,
};
use sqlx::{QueryBuilder, Row, Sqlite, Transaction};
use uuid::Uuid;

use crate::api::{
    CampaignCreated, CampaignState, CampaignStatus, CampaignSummary, CellProgress, Checkpoint,
    ClaimedJob, HeartbeatResponse, HeldJob, JobCounts, JobError, JobInfo, JobState, RawSample,
    ResultsResponse, WorkerInfo, WorkersResponse,
};
use crate::error::{Error, Result};

/// Longest failure message kept per job.
const MAX_ERROR_CHARS: usize = 4000;
/// Window over which the impact rate (and so the ETA) is measured.
const RATE_WINDOW_MS: i64 = 120_000;
/// Workers silent for longer are forgotten, so the table of names cannot grow without end.
const WORKER_FORGET_MS: i64 = 7 * 24 * 3600 * 1000;

/// Current time in Unix milliseconds.
pub fn now_ms() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_millis() as i64)
        .unwrap_or(0)
}

/// The coordinator database.
#[derive(Clone)]
pub struct Store {
    write: SqlitePool,
    read: SqlitePool,
    /// Lease length.
    pub lease_ttl: Duration,
    /// Attempts (lost or failed leases) after which a job stays `failed`.
    pub max_attempts: u32,
}

/// A checkpoint as stored.
struct StoredCheckpoint {
    impacts_done: u32,
    data: Vec<u8>,
}

impl Store {
    /// Opens (creating if missing) the database at `path` and applies the migrations.
    pub async fn open(path: &Path, lease_ttl: Duration, max_attempts: u32) -> Result<Store> {
        let opts = SqliteConnectOptions::new()
            .filename(path)
            .create_if_missing(true)
            .journal_mode(SqliteJournalMode::Wal)
            // NORMAL in WAL mode survives a crashed process (the tests kill the coordinator);
            // only an OS crash can lose the last transactions.
            .synchronous(SqliteSynchronous::Normal)
            .busy_timeout(Duration::from_secs(30))
            .foreign_keys(true);
        let write = SqlitePoolOptions::new()
            .max_connections(1)
            .connect_with(opts.clone())
            .await?;
        sqlx::migrate!("../../migrations").run(&write).await?;
        let read = SqlitePoolOptions::new()
            .max_connections(4)
            .connect_with(opts.read_only(true))
            .await?;
        Ok(Store {
            write,
            read,
            lease_ttl,
            max_attempts: max_attempts.max(1),
        })
    }

    async fn begin(&self) -> Result<Transaction<'static, Sqlite>> {
        Ok(self.write.begin_with("BEGIN IMMEDIATE").await?)
    }

    /// Liveness check: the database answers a query.
    pub async fn ping(&self) -> Result<()> {
        sqlx::query("SELECT 1").execute(&self.read).await?;
        Ok(())
    }

    /// Validates, expands and stores a campaign with all its jobs in one transaction. With an
    /// idempotency key already used, returns the earlier campaign instead.
    pub async fn create_campaign(
        &self,
        spec: &CampaignSpec,
        idempotency_key: Option<&str>,
    ) -> Result<CampaignCreated> {
        let cells = spec.cells()?;
        let impacts_total = spec.impacts_total()?;
        let jobs_total = cells.len() as u64 * spec.samples as u64;
        let spec_json = serde_json::to_string(spec).map_err(|e| Error::Internal(e.to_string()))?;
        let mut tx = self.begin().await?;
        if let Some(key) = idempotency_key {
            let row = sqlx::query("SELECT id, spec FROM campaigns WHERE idempotency_key = ?")
                .bind(key)
                .fetch_optional(&mut *tx)
                .await?;
            if let Some(row) = row {
                let id: String = row.get("id");
                let old: String = row.get("spec");
                if old != spec_json {
                    return Err(Error::Conflict(
                        "Idempotency-Key already used for a different campaign".into(),
                    ));
                }
                return Ok(CampaignCreated {
                    id: parse_uuid(&id)?,
                    jobs: jobs_total,
                    impacts_total,
                    created: false,
                });
            }
        }
        let id = Uuid::new_v4();
        let now = now_ms();
        let seq: i64 = sqlx::query(
            "INSERT INTO campaigns (id, name, spec, samples, impacts_total, max_attempts,
                                    idempotency_key, created_ms)
             VALUES (?, ?, ?, ?, ?, ?, ?, ?) RETURNING rowid",
        )
        .bind(id.to_string())
        .bind(&spec.name)
        .bind(&spec_json)
        .bind(spec.samples as i64)
        .bind(impacts_total as i64)
        .bind(self.max_attempts as i64)
        .bind(idempotency_key)
        .bind(now)
        .fetch_one(&mut *tx)
        .await?
        .get(0);
        for cell in &cells {
            sqlx::query(
                "INSERT INTO cells (campaign_id, cell_index, angle_deg, shape, swept, impacts, params)
                 VALUES (?, ?, ?, ?, ?, ?, ?)",
            )
            .bind(id.to_string())
            .bind(cell.index as i64)
            .bind(cell.params.angle_deg)
            .bind(cell.params.shape.name())
            .bind(serde_json::to_string(&cell.swept).map_err(|e| Error::Internal(e.to_string()))?)
            .bind(cell.impacts as i64)
            .bind(
                serde_json::to_string(&cell.params)
                    .map_err(|e| Error::Internal(e.to_string()))?,
            )
            .execute(&mut *tx)
            .await?;
        }
        // Multi-row inserts keep a campaign of many thousand jobs to a few statements; 400
        // rows × 8 values stays under SQLite's limit on bound variables.
        let jobs: Vec<(u32, u32, u32, u64)> = cells
            .iter()
            .flat_map(|c| {
                (0..spec.samples).map(move |s| {
                    (
                        c.index,
                        s,
                        c.impacts,
                        grit_erosion::campaign::job_seed(spec.seed, c.index, s),
                    )
                })
            })
            .collect();
        for chunk in jobs.chunks(400) {
            let mut qb = QueryBuilder::<Sqlite>::new(
                "INSERT INTO jobs (campaign_id, campaign_seq, cell_index, sample_index, seed,
                                   impacts_planned, state, updated_ms) ",
            );
            qb.push_values(chunk, |mut b, (cell, sample, impacts, seed)| {
                b.push_bind(id.to_string())
                    .push_bind(seq)
                    .push_bind(*cell as i64)
                    .push_bind(*sample as i64)
                    .push_bind(*seed as i64)
                    .push_bind(*impacts as i64)
                    .push_bind("queued")
                    .push_bind(now);
            });
            qb.build().execute(&mut *tx).await?;
        }
        tx.commit().await?;
        tracing::info!(campaign = %id, jobs = jobs_total, impacts_total, "campaign created");
        Ok(CampaignCreated {
            id,
            jobs: jobs_total,
            impacts_total,
            created: true,
        })
    }

    /// Every campaign, newest first, with state and progress.
    pub async fn list_campaigns(&self) -> Result<Vec<CampaignSummary>> {
        let rows = sqlx::query(
            "SELECT c.id, c.name, c.impacts_total, c.created_ms, c.cancelled_ms,
                    COALESCE(SUM(j.impacts_done), 0) AS done,
                    COALESCE(SUM(j.state = 'queued'), 0) AS queued,
                    COALESCE(SUM(j.state = 'leased'), 0) AS leased,
                    COALESCE(SUM(j.state = 'done'), 0) AS jobs_done,
                    COALESCE(SUM(j.state = 'failed'), 0) AS failed,
                    COUNT(j.id) AS jobs
             FROM campaigns c LEFT JOIN jobs j ON j.campaign_id = c.id
             GROUP BY c.id ORDER BY c.created_ms DESC, c.rowid DESC",
        )
        .fetch_all(&self.read)
        .await?;
        rows.iter()
            .map(|r| {
                let counts = JobCounts {
                    queued: r.get::<i64, _>("queued") as u64,
                    leased: r.get::<i64, _>("leased") as u64,
                    done: r.get::<i64, _>("jobs_done") as u64,
                    failed: r.get::<i64, _>("failed") as u64,
                    cancelled: 0,
                };
                let impacts_done = r.get::<i64, _>("done") as u64;
                Ok(CampaignSummary {
                    id: parse_uuid(&r.get::<String, _>("id"))?,
                    name: r.get("name"),
                    state: derive_state(
                        r.get::<Option<i64>, _>("cancelled_ms").is_some(),
                        &counts,
                        r.get::<i64, _>("jobs") as u64,
                        impacts_done,
                    ),
                    impacts_done,
                    impacts_total: r.get::<i64, _>("impacts_total") as u64,
                    created_ms: r.get("created_ms"),
                })
            })
            .collect()
    }

    async fn campaign_row(&self, id: Uuid) -> Result<sqlx::sqlite::SqliteRow> {
        sqlx::query("SELECT * FROM campaigns WHERE id = ?")
            .bind(id.to_string())
            .fetch_optional(&self.read)
            .await?
            .ok_or_else(|| Error::NotFound(format!("campaign {id}")))
    }

    /// Progress of one campaign: jobs per state, impacts, per-cell progress, rate, ETA.
    pub async fn status(&self, id: Uuid) -> Result<CampaignStatus> {
        let c = self.campaign_row(id).await?;
        let ids = id.to_string();
        let mut counts = JobCounts::default();
        for r in sqlx::query(
            "SELECT state, COUNT(*) AS n FROM jobs WHERE campaign_id = ? GROUP BY state",
        )
        .bind(&ids)
        .fetch_all(&self.read)
        .await?
        {
            let n = r.get::<i64, _>("n") as u64;
            match r.get::<String, _>("state").as_str() {
                "queued" => counts.queued = n,
                "leased" => counts.leased = n,
                "done" => counts.done = n,
                "failed" => counts.failed = n,
                _ => counts.cancelled += n,
            }
        }
        let samples = c.get::<i64, _>("samples") as u64;
        let mut cells = Vec::new();
        for r in sqlx::query(
            "SELECT k.cell_index, k.angle_deg, k.shape, k.swept, k.impacts,
                    COALESCE(SUM(j.impacts_done), 0) AS done,
                    COALESCE(SUM(j.state = 'done'), 0) AS samples_done
             FROM cells k LEFT JOIN jobs j
               ON j.campaign_id = k.campaign_id AND j.cell_index = k.cell_index
             WHERE k.campaign_id = ? GROUP BY k.cell_index ORDER BY k.cell_index",
        )
        .bind(&ids)
        .fetch_all(&self.read)
        .await?
        {
            cells.push(CellProgress {
                cell: r.get::<i64, _>("cell_index") as u32,
                angle_deg: r.get("angle_deg"),
                shape: r.get("shape"),
                swept: serde_json::from_str(&r.get::<String, _>("swept")).unwrap_or_default(),
                samples_done: r.get::<i64, _>("samples_done") as u64,
                samples_total: samples,
                impacts_done: r.get::<i64, _>("done") as u64,
                impacts_total: r.get::<i64, _>("impacts") as u64 * samples,
            });
        }
        let impacts_done: u64 = cells.iter().map(|c| c.impacts_done).sum();
        let impacts_total = c.get::<i64, _>("impacts_total") as u64;
        let now = now_ms();
        let recent = sqlx::query(
            "SELECT COUNT(*) AS n, MIN(i.created_ms) AS first FROM impacts i
             JOIN jobs j ON j.id = i.job_id
             WHERE j.campaign_id = ? AND i.created_ms > ?",
        )
        .bind(&ids)
        .bind(now - RATE_WINDOW_MS)
        .fetch_one(&self.read)
        .await?;
        let n: i64 = recent.get("n");
        // Over a window that starts at the first recent impact, so a fresh campaign's rate is
        // not diluted by the minutes before it started.
        let rate = recent
            .get::<Option<i64>, _>("first")
            .filter(|_| n > 1)
            .map(|first| n as f64 / ((now - first).max(1000) as f64 / 1000.0));
        let cancelled = c.get::<Option<i64>, _>("cancelled_ms").is_some();
        let total_jobs =
            counts.queued + counts.leased + counts.done + counts.failed + counts.cancelled;
        let state = derive_state(cancelled, &counts, total_jobs, impacts_done);
        let eta = match state {
            CampaignState::Done => Some(0.0),
            CampaignState::Queued | CampaignState::Running => rate
                .filter(|r| *r > 0.0)
                .map(|r| impacts_total.saturating_sub(impacts_done) as f64 / r),
            _ => None,
        };
        let last_error = sqlx::query(
            "SELECT id, cell_index, sample_index, attempts, last_error FROM jobs
             WHERE campaign_id = ? AND state = 'failed' ORDER BY updated_ms DESC LIMIT 1",
        )
        .bind(&ids)
        .fetch_optional(&self.read)
        .await?
        .map(|r| JobError {
            job_id: r.get("id"),
            cell: r.get::<i64, _>("cell_index") as u32,
            sample: r.get::<i64, _>("sample_index") as u32,
            attempts: r.get::<i64, _>("attempts") as u32,
            error: r.get::<Option<String>, _>("last_error").unwrap_or_default(),
        });
        Ok(CampaignStatus {
            id,
            name: c.get("name"),
            state,
            impacts_done,
            impacts_total,
            jobs: counts,
            rate_impacts_per_s: rate,
            eta_s: eta,
            cells,
            last_error,
            created_ms: c.get("created_ms"),
        })
    }

    /// Aggregated results (partial while jobs remain); with `raw`, every sample's series.
    pub async fn results(&self, id: Uuid, raw: bool) -> Result<ResultsResponse> {
        let c = self.campaign_row(id).await?;
        let spec = CampaignSpec::from_json(&c.get::<String, _>("spec"))?;
        let cells = spec.cells()?;
        let rows = sqlx::query(
            "SELECT j.cell_index, j.sample_index, i.grain_mass_kg, i.mass_loss_kg
             FROM impacts i JOIN jobs j ON j.id = i.job_id
             WHERE j.campaign_id = ?
             ORDER BY j.cell_index, j.sample_index, i.impact",
        )
        .bind(id.to_string())
        .fetch_all(&self.read)
        .await?;
        let mut per_cell: Vec<BTreeMap<u32, Vec<Impact>>> = vec![BTreeMap::new(); cells.len()];
        for r in &rows {
            let cell = r.get::<i64, _>(0) as usize;
            let sample = r.get::<i64, _>(1) as u32;
            if let Some(m) = per_cell.get_mut(cell) {
                m.entry(sample).or_default().push(Impact {
                    grain_mass_kg: r.get(2),
                    mass_loss_kg: r.get(3),
                });
            }
        }
        let inputs: Vec<_> = cells
            .iter()
            .zip(per_cell)
            .map(|(cell, samples)| {
                cell.input(
                    spec.samples,
                    samples
                        .into_iter()
                        .map(|(sample, impacts)| SampleInput { sample, impacts })
                        .collect(),
                )
            })
            .collect();
        let results = aggregate_campaign(&inputs, grit_erosion::SLOPE_WINDOW)
            .map_err(|e| Error::Internal(format!("aggregation: {e}")))?;
        let raw = if raw {
            Some(self.raw_series(id).await?)
        } else {
            None
        };
        Ok(ResultsResponse { results, raw })
    }

    async fn raw_series(&self, id: Uuid) -> Result<Vec<RawSample>> {
        let jobs = sqlx::query(
            "SELECT id, cell_index, sample_index, seed, state FROM jobs
             WHERE campaign_id = ? ORDER BY cell_index, sample_index",
        )
        .bind(id.to_string())
        .fetch_all(&self.read)
        .await?;
        let rows = sqlx::query(
            "SELECT i.job_id, i.record FROM impacts i JOIN jobs j ON j.id = i.job_id
             WHERE j.campaign_id = ? ORDER BY i.job_id, i.impact",
        )
        .bind(id.to_string())
        .fetch_all(&self.read)
        .await?;
        let mut records: BTreeMap<i64, Vec<ImpactRecord>> = BTreeMap::new();
        for r in rows {
            let rec: ImpactRecord = serde_json::from_str(&r.get::<String, _>(1))
                .map_err(|e| Error::Internal(format!("stored impact record: {e}")))?;
            records.entry(r.get(0)).or_default().push(rec);
        }
        Ok(jobs
            .iter()
            .map(|j| RawSample {
                cell: j.get::<i64, _>("cell_index") as u32,
                sample: j.get::<i64, _>("sample_index") as u32,
                seed: j.get::<i64, _>("seed") as u64,
                state: j.get("state"),
                impacts: records.remove(&j.get::<i64, _>("id")).unwrap_or_default(),
            })
            .collect())
    }

    /// A campaign's jobs in cell and sample order, only those in `state` if given, at most
    /// `limit` of them.
    pub async fn jobs(
        &self,
        id: Uuid,
        state: Option<JobState>,
        limit: u32,
    ) -> Result<Vec<JobInfo>> {
        self.campaign_row(id).await?;
        let rows = sqlx::query(
            "SELECT id, cell_index, sample_index, state, attempts, impacts_done, impacts_planned,
                    worker, lease_expires_ms, updated_ms, last_error
             FROM jobs WHERE campaign_id = ?1 AND (?2 IS NULL OR state = ?2)
             ORDER BY cell_index, sample_index LIMIT ?3",
        )
        .bind(id.to_string())
        .bind(state.map(JobState::as_str))
        .bind(limit as i64)
        .fetch_all(&self.read)
        .await?;
        rows.iter()
            .map(|r| {
                Ok(JobInfo {
                    job_id: r.get("id"),
                    cell: r.get::<i64, _>("cell_index") as u32,
                    sample: r.get::<i64, _>("sample_index") as u32,
                    state: job_state(&r.get::<String, _>("state"))?,
                    attempts: r.get::<i64, _>("attempts") as u32,
                    impacts_done: r.get::<i64, _>("impacts_done") as u32,
                    impacts_planned: r.get::<i64, _>("impacts_planned") as u32,
                    worker: r.get("worker"),
                    lease_expires_ms: r.get("lease_expires_ms"),
                    updated_ms: r.get("updated_ms"),
                    last_error: r.get("last_error"),
                })
            })
            .collect()
    }

    /// Workers heard from within `within`, most recently seen first, with the jobs they hold.
    pub async fn workers(&self, within: Duration) -> Result<WorkersResponse> {
        let since = now_ms() - within.as_millis().min(i64::MAX as u128) as i64;
        let rows = sqlx::query(
            "SELECT name, first_seen_ms, last_seen_ms FROM workers WHERE last_seen_ms >= ?
             ORDER BY last_seen_ms DESC, name",
        )
        .bind(since)
        .fetch_all(&self.read)
        .await?;
        let mut held: BTreeMap<String, Vec<HeldJob>> = BTreeMap::new();
        for r in sqlx::query(
            "SELECT j.id, j.campaign_id, c.name AS campaign_name, j.cell_index, k.angle_deg,
                    k.shape, j.sample_index, j.impacts_done, j.impacts_planned, j.updated_ms,
                    j.lease_expires_ms, j.worker
             FROM jobs j
             JOIN campaigns c ON c.id = j.campaign_id
             JOIN cells k ON k.campaign_id = j.campaign_id AND k.cell_index = j.cell_index
             WHERE j.state = 'leased' AND j.worker IS NOT NULL ORDER BY j.id",
        )
        .fetch_all(&self.read)
        .await?
        {
            held.entry(r.get("worker")).or_default().push(HeldJob {
                job_id: r.get("id"),
                campaign_id: parse_uuid(&r.get::<String, _>("campaign_id"))?,
                campaign_name: r.get("campaign_name"),
                cell: r.get::<i64, _>("cell_index") as u32,
                angle_deg: r.get("angle_deg"),
                shape: r.get("shape"),
                sample: r.get::<i64, _>("sample_index") as u32,
                impacts_done: r.get::<i64, _>("impacts_done") as u32,
                impacts_planned: r.get::<i64, _>("impacts_planned") as u32,
                // Claims and heartbeats are the only writes to a leased job's updated_ms.
                last_heartbeat_ms: r.get("updated_ms"),
                lease_expires_ms: r.get::<Option<i64>, _>("lease_expires_ms").unwrap_or(0),
            });
        }
        Ok(WorkersResponse {
            lease_ttl_s: self.lease_ttl.as_secs_f64(),
            seen_within_s: within.as_secs_f64(),
            workers: rows
                .iter()
                .map(|r| {
                    let name: String = r.get("name");
                    WorkerInfo {
                        jobs: held.remove(&name).unwrap_or_default(),
                        name,
                        first_seen_ms: r.get("first_seen_ms"),
                        last_seen_ms: r.get("last_seen_ms"),
                    }
                })
                .collect(),
        })
    }

    /// Cancels a campaign: unfinished jobs become `cancelled` (their holders learn it at the
    /// next heartbeat). Returns how many jobs changed.
    pub async fn cancel(&self, id: Uuid) -> Result<u64> {
        let mut tx = self.begin().await?;
        let now = now_ms();
        let found = sqlx::query(
            "UPDATE campaigns SET cancelled_ms = COALESCE(cancelled_ms, ?) WHERE id = ?",
        )
        .bind(now)
        .bind(id.to_string())
        .execute(&mut *tx)
        .await?
        .rows_affected();
        if found == 0 {
            return Err(Error::NotFound(format!("campaign {id}")));
        }
        // lease_id stays, so the holder's next heartbeat is told "cancelled" (410), not 409.
        let n = sqlx::query(
            "UPDATE jobs SET state = 'cancelled', lease_expires_ms = NULL, updated_ms = ?
             WHERE campaign_id = ? AND state IN ('queued', 'leased', 'failed')",
        )
        .bind(now)
        .bind(id.to_string())
        .execute(&mut *tx)
        .await?
        .rows_affected();
        sqlx::query(
            "DELETE FROM checkpoints WHERE job_id IN
               (SELECT id FROM jobs WHERE campaign_id = ? AND state = 'cancelled')",
        )
        .bind(id.to_string())
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        tracing::info!(campaign = %id, jobs = n, "campaign cancelled");
        Ok(n)
    }

    /// Puts a campaign's failed jobs back in the queue with their attempts reset.
    pub async fn retry_failed(&self, id: Uuid) -> Result<u64> {
        let mut tx = self.begin().await?;
        let row = sqlx::query("SELECT cancelled_ms FROM campaigns WHERE id = ?")
            .bind(id.to_string())
            .fetch_optional(&mut *tx)
            .await?
            .ok_or_else(|| Error::NotFound(format!("campaign {id}")))?;
        if row.get::<Option<i64>, _>(0).is_some() {
            return Err(Error::Conflict("campaign is cancelled".into()));
        }
        let n = sqlx::query(
            "UPDATE jobs SET state = 'queued', attempts = 0, lease_id = NULL, worker = NULL,
                             lease_expires_ms = NULL, updated_ms = ?
             WHERE campaign_id = ? AND state = 'failed'",
        )
        .bind(now_ms())
        .bind(id.to_string())
        .execute(&mut *tx)
        .await?
        .rows_affected();
        tx.commit().await?;
        Ok(n)
    }

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
        let mut tx = self.begin().await?;
        let now = now_ms();
        reap(&mut tx, now).await?;
        // Every claim counts as a sign of life, an empty queue's too: idle workers are listed.
        sqlx::query(
            "INSERT INTO workers (name, first_seen_ms, last_seen_ms) VALUES (?1, ?2, ?2)
             ON CONFLICT (name) DO UPDATE SET last_seen_ms = excluded.last_seen_ms",
        )
        .bind(worker)
        .bind(now)
        .execute(&mut *tx)
        .await?;
        let lease = Uuid::new_v4();
        let expires = now + self.lease_ttl.as_millis() as i64;
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
        .fetch_optional(&mut *tx)
        .await?
        else {
            tx.commit().await?;
            return Ok(None);
        };
        let job_id: i64 = r.get("id");
        let campaign: String = r.get("campaign_id");
        let cell: i64 = r.get("cell_index");
        let params: String =
            sqlx::query("SELECT params FROM cells WHERE campaign_id = ? AND cell_index = ?")
                .bind(&campaign)
                .bind(cell)
                .fetch_one(&mut *tx)
                .await?
                .get(0);
        let params: ImpactParams = serde_json::from_str(&params)
            .map_err(|e| Error::Internal(format!("stored params of job {job_id}: {e}")))?;
        let ckpt = load_checkpoint(&mut tx, job_id).await?;
        tx.commit().await?;
        tracing::debug!(job = job_id, worker, "job leased");
        Ok(Some(ClaimedJob {
            job_id,
            lease_id: lease,
            lease_ttl_s: self.lease_ttl.as_secs_f64(),
            campaign_id: parse_uuid(&campaign)?,
            cell: cell as u32,
            sample: r.get::<i64, _>("sample_index") as u32,
            seed: r.get::<i64, _>("seed") as u64,
            impacts_planned: r.get::<i64, _>("impacts_planned") as u32,
            impacts_done: r.get::<i64, _>("impacts_done") as u32,
            params,
            checkpoint: ckpt.map(|c| Checkpoint {
                impacts_done: c.impacts_done,
                data_b64: base64::engine::general_purpose::STANDARD.encode(c.data),
            }),
        }))
    }

    /// Renews the lease, stores finished impacts and an optional checkpoint.
    pub async fn heartbeat(
        &self,
        job_id: i64,
        lease: Uuid,
        impacts: &[ImpactRecord],
        checkpoint: Option<&Checkpoint>,
    ) -> Result<HeartbeatResponse> {
        let mut tx = self.begin().await?;
        let now = now_ms();
        let held = check_lease(&mut tx, job_id, lease, now).await?;
        touch_worker(&mut tx, job_id, now).await?;
        let done = store_impacts(&mut tx, job_id, &held, impacts, now).await?;
        if let Some(c) = checkpoint {
            store_checkpoint(&mut tx, job_id, done, c, now).await?;
        }
        let expires = now + self.lease_ttl.as_millis() as i64;
        sqlx::query(
            "UPDATE jobs SET lease_expires_ms = ?, impacts_done = ?, updated_ms = ? WHERE id = ?",
        )
        .bind(expires)
        .bind(done as i64)
        .bind(now)
        .bind(job_id)
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(HeartbeatResponse {
            impacts_done: done,
            lease_expires_ms: expires,
        })
    }

    /// Stores the last impacts and marks the job done; it must then have every planned impact.
    pub async fn complete(&self, job_id: i64, lease: Uuid, impacts: &[ImpactRecord]) -> Result<()> {
        let mut tx = self.begin().await?;
        let now = now_ms();
        let held = check_lease(&mut tx, job_id, lease, now).await?;
        touch_worker(&mut tx, job_id, now).await?;
        let done = store_impacts(&mut tx, job_id, &held, impacts, now).await?;
        if done < held.planned {
            return Err(Error::invalid(
                "impacts",
                format!(
                    "the job has {done} of its {} planned impacts; send the rest before completing",
                    held.planned
                ),
            ));
        }
        sqlx::query(
            "UPDATE jobs SET state = 'done', impacts_done = ?, lease_id = NULL,
                             lease_expires_ms = NULL, updated_ms = ?
             WHERE id = ?",
        )
        .bind(done as i64)
        .bind(now)
        .bind(job_id)
        .execute(&mut *tx)
        .await?;
        sqlx::query("DELETE FROM checkpoints WHERE job_id = ?")
            .bind(job_id)
            .execute(&mut *tx)
            .await?;
        tx.commit().await?;
        tracing::debug!(job = job_id, "job done");
        Ok(())
    }

    /// Records a failure: back to the queue, or `failed` once attempts reach the maximum.
    pub async fn fail(
        &self,
        job_id: i64,
        lease: Uuid,
        error: &str,
        impacts: &[ImpactRecord],
    ) -> Result<()> {
        let mut tx = self.begin().await?;
        let now = now_ms();
        let held = check_lease(&mut tx, job_id, lease, now).await?;
        touch_worker(&mut tx, job_id, now).await?;
        let done = store_impacts(&mut tx, job_id, &held, impacts, now).await?;
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
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        tracing::warn!(job = job_id, error = %error, "job attempt failed");
        Ok(())
    }

    /// Gives a job back without counting an attempt, keeping its impacts and checkpoint.
    pub async fn release(
        &self,
        job_id: i64,
        lease: Uuid,
        impacts: &[ImpactRecord],
        checkpoint: Option<&Checkpoint>,
    ) -> Result<()> {
        let mut tx = self.begin().await?;
        let now = now_ms();
        let held = check_lease(&mut tx, job_id, lease, now).await?;
        touch_worker(&mut tx, job_id, now).await?;
        let done = store_impacts(&mut tx, job_id, &held, impacts, now).await?;
        if let Some(c) = checkpoint {
            store_checkpoint(&mut tx, job_id, done, c, now).await?;
        }
        sqlx::query(
            "UPDATE jobs SET state = 'queued', impacts_done = ?, lease_id = NULL, worker = NULL,
                             lease_expires_ms = NULL, updated_ms = ?
             WHERE id = ?",
        )
        .bind(done as i64)
        .bind(now)
        .bind(job_id)
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        tracing::info!(job = job_id, impacts = done, "job released");
        Ok(())
    }
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

fn job_state(s: &str) -> Result<JobState> {
    JobState::parse(s).ok_or_else(|| Error::Internal(format!("stored job state {s:?}")))
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
    sqlx::query(
        "INSERT INTO checkpoints (job_id, impacts_done, data, updated_ms) VALUES (?, ?, ?, ?)
         ON CONFLICT (job_id) DO UPDATE SET impacts_done = excluded.impacts_done,
             data = excluded.data, updated_ms = excluded.updated_ms
         WHERE excluded.impacts_done >= checkpoints.impacts_done",
    )
    .bind(job_id)
    .bind(c.impacts_done as i64)
    .bind(data)
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
        sqlx::query("SELECT impacts_done, data FROM checkpoints WHERE job_id = ?")
            .bind(job_id)
            .fetch_optional(&mut **tx)
            .await?
            .map(|r| StoredCheckpoint {
                impacts_done: r.get::<i64, _>(0) as u32,
                data: r.get(1),
            }),
    )
}

async fn reap(tx: &mut Transaction<'static, Sqlite>, now: i64) -> Result<u64> {
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

fn derive_state(cancelled: bool, c: &JobCounts, total: u64, impacts_done: u64) -> CampaignState {
    if cancelled {
        CampaignState::Cancelled
    } else if c.done == total {
        CampaignState::Done
    } else if c.queued == 0 && c.leased == 0 {
        CampaignState::Failed
    } else if c.leased == 0 && c.done == 0 && impacts_done == 0 {
        CampaignState::Queued
    } else {
        CampaignState::Running
    }
}

/// Parses a uuid stored by this module.
fn parse_uuid(s: &str) -> Result<Uuid> {
    Uuid::from_str(s).map_err(|e| Error::Internal(format!("stored id {s}: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TINY: &str = r#"{"angles_deg": [90], "shapes": ["hexagon"], "samples": 2, "impacts": 2,
        "allow_short_samples": true, "spacing_m": 25e-6}"#;

    async fn store(dir: &Path, ttl_ms: u64) -> Store {
        Store::open(&dir.join("t.db"), Duration::from_millis(ttl_ms), 2)
            .await
            .unwrap()
    }

    #[tokio::test]
    async fn expired_leases_count_attempts_until_the_job_fails() {
        let dir = tempfile::tempdir().unwrap();
        let s = store(dir.path(), 1).await;
        let spec = CampaignSpec::from_json(TINY).unwrap();
        let id = s.create_campaign(&spec, None).await.unwrap().id;
        // Sample 0 first (claim order), then the other.
        let a = s.claim("w").await.unwrap().unwrap();
        assert_eq!(a.sample, 0);
        tokio::time::sleep(Duration::from_millis(5)).await;
        let b = s.claim("w").await.unwrap().unwrap();
        assert_eq!(
            b.job_id, a.job_id,
            "the expired job is first in the queue again"
        );
        tokio::time::sleep(Duration::from_millis(5)).await;
        s.reap_expired().await.unwrap();
        let st = s.status(id).await.unwrap();
        assert_eq!(st.jobs.failed, 1);
        assert_eq!(st.jobs.queued, 1);
        let e = st.last_error.unwrap();
        assert_eq!(e.attempts, 2);
        assert!(e.error.contains("lease expired"), "{}", e.error);
        assert_eq!(s.retry_failed(id).await.unwrap(), 1);
        assert_eq!(s.status(id).await.unwrap().jobs.queued, 2);
    }

    #[tokio::test]
    async fn workers_are_listed_idle_or_with_the_job_they_hold() {
        let dir = tempfile::tempdir().unwrap();
        let s = store(dir.path(), 60_000).await;
        assert!(s.claim("idle").await.unwrap().is_none());
        let spec = CampaignSpec::from_json(TINY).unwrap();
        let id = s.create_campaign(&spec, None).await.unwrap().id;
        let j = s.claim("busy").await.unwrap().unwrap();
        tokio::time::sleep(Duration::from_millis(5)).await;
        s.heartbeat(j.job_id, j.lease_id, &[], None).await.unwrap();
        let w = s.workers(Duration::from_secs(60)).await.unwrap();
        let names: Vec<&str> = w.workers.iter().map(|w| w.name.as_str()).collect();
        assert_eq!(names, ["busy", "idle"], "most recently seen first");
        let held = &w.workers[0].jobs;
        assert_eq!(held.len(), 1);
        assert_eq!((held[0].job_id, held[0].campaign_id), (j.job_id, id));
        assert_eq!(held[0].last_heartbeat_ms, w.workers[0].last_seen_ms);
        assert!(w.workers[1].jobs.is_empty());
        // A failed attempt clears the job's worker, but the worker stays listed.
        s.fail(j.job_id, j.lease_id, "boom", &[]).await.unwrap();
        let w = s.workers(Duration::from_secs(60)).await.unwrap();
        assert!(w.workers.iter().all(|w| w.jobs.is_empty()));
        let queued = s.jobs(id, Some(JobState::Queued), 10).await.unwrap();
        assert_eq!(queued.len(), 2);
        assert_eq!(queued[0].last_error.as_deref(), Some("boom"));
        assert_eq!(s.jobs(id, None, 1).await.unwrap().len(), 1);
        let e = s.jobs(Uuid::new_v4(), None, 10).await.unwrap_err();
        assert_eq!(e.status(), axum::http::StatusCode::NOT_FOUND);
    }

    #[tokio::test]
    async fn failure_reports_keep_the_error_and_stale_leases_get_409() {
        let dir = tempfile::tempdir().unwrap();
        let s = store(dir.path(), 60_000).await;
        let spec = CampaignSpec::from_json(TINY).unwrap();
        let id = s.create_campaign(&spec, None).await.unwrap().id;
        let j = s.claim("w").await.unwrap().unwrap();
        let e = s
            .heartbeat(j.job_id, Uuid::new_v4(), &[], None)
            .await
            .unwrap_err();
        assert_eq!(e.status(), axum::http::StatusCode::CONFLICT);
        s.fail(j.job_id, j.lease_id, "impact 1: unstable", &[])
            .await
            .unwrap();
        let e = s
            .fail(j.job_id, j.lease_id, "again", &[])
            .await
            .unwrap_err();
        assert_eq!(
            e.status(),
            axum::http::StatusCode::CONFLICT,
            "the lease ended"
        );
        let j2 = s.claim("w").await.unwrap().unwrap();
        s.fail(j2.job_id, j2.lease_id, "impact 1: unstable", &[])
            .await
            .unwrap();
        let st = s.status(id).await.unwrap();
        assert_eq!(st.jobs.failed + st.jobs.queued, 2);
        assert_eq!(
            st.last_error.map(|e| e.error).as_deref(),
            Some("impact 1: unstable")
        );
        assert_eq!(s.cancel(id).await.unwrap(), 2);
        assert!(s.claim("w").await.unwrap().is_none());
        assert_eq!(s.status(id).await.unwrap().state, CampaignState::Cancelled);
    }
}
