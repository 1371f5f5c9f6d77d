//! The store's side of the campaign endpoints: submitting (expanding a spec into cells and
//! jobs), progress, results, the jobs list, cancel and retry.

use std::collections::BTreeMap;

use grit_erosion::campaign::{AnySpec, CampaignPlan, CampaignSpec, Scene, StoredJob};
use sqlx::Row;
use uuid::Uuid;

use super::{
    by_idempotency_key, insert_campaign, insert_queued_jobs, now_ms, parse_uuid, NewCampaign, Store,
};
use crate::api::{
    AnyResults, CampaignCreated, CampaignState, CampaignStatus, CampaignSummary, CellProgress,
    JobCounts, JobError, JobInfo, JobState, Replaying,
};
use crate::error::{Error, Result};

/// Window over which the impact rate (and so the ETA) is measured while it holds at least
/// `RATE_MIN_UNITS` units.
const RATE_WINDOW_MS: i64 = 120_000;
/// A slower campaign's rate is taken over its last `RATE_MIN_UNITS` units instead, no further
/// back than `RATE_LONGEST_MS`: at one impact per 30 s two minutes hold four, and the ETA of a
/// long campaign jumped by half from one progress line to the next.
const RATE_MIN_UNITS: i64 = 20;
const RATE_LONGEST_MS: i64 = 1_800_000;

/// The units one campaign stored since a time, and the first of them: the rate's window.
/// CROSS JOIN keeps units the outer loop, so the count walks `units_recent` over the window's
/// few rows; left to itself SQLite walked every unit of the campaign's jobs (1.7 s at 29 000
/// units, on a machine loaded by the campaign's own workers).
pub(super) const RECENT_UNITS: &str = "SELECT COUNT(*) AS n, MIN(u.created_ms) AS first
     FROM units u CROSS JOIN jobs j ON j.id = u.job_id
     WHERE j.campaign_id = ? AND u.created_ms > ?";

/// The times of one campaign's latest units since a time, newest first, at most a number of
/// them; through `units_recent` as `RECENT_UNITS`.
pub(super) const LATEST_UNITS: &str = "SELECT u.created_ms AS t
     FROM units u CROSS JOIN jobs j ON j.id = u.job_id
     WHERE j.campaign_id = ? AND u.created_ms > ?
     ORDER BY u.created_ms DESC LIMIT ?";

/// A scene's results JSON object with the campaign's pinned `engine` and its creator's
/// `commit` in front. The keys are spliced in rather than the body parsed and written again,
/// which would cost a pass over a raw listing of every record and could reorder its keys. An
/// unpinned campaign's results are left as they were.
fn with_engine(body: String, engine: Option<String>, commit: Option<String>) -> String {
    let (Some(engine), Some(rest)) = (engine, body.strip_prefix('{')) else {
        return body;
    };
    let head = serde_json::json!({ "engine": engine, "commit": commit.unwrap_or_else(|| "unknown".into()) })
        .to_string();
    let sep = if rest.trim_start().starts_with('}') {
        ""
    } else {
        ","
    };
    format!("{}{sep}{rest}", &head[..head.len() - 1])
}

/// The scene stored in a campaign row's `scene` column.
fn scene_of(r: &sqlx::sqlite::SqliteRow) -> Scene {
    Scene::parse(&r.get::<String, _>("scene")).unwrap_or_default()
}

impl Store {
    /// Validates, expands and stores a campaign of any scene with all its jobs in one
    /// transaction. With an idempotency key already used, returns the earlier campaign
    /// instead.
    pub async fn create(
        &self,
        spec: &AnySpec,
        idempotency_key: Option<&str>,
    ) -> Result<CampaignCreated> {
        let plan = spec.plan()?;
        let spec_json = serde_json::to_string(spec).map_err(|e| Error::Internal(e.to_string()))?;
        self.create_planned(
            &plan,
            &spec_json,
            spec.name(),
            idempotency_key,
            spec.engine(),
        )
        .await
    }

    /// Stores campaign `plan` (its spec as `spec_json`, its name `name`) with all its jobs in
    /// one transaction: [`Store::create`] once the spec is planned, and the way in for a scene
    /// whose spec grit does not parse. It is pinned to `engine`, or else to this coordinator's
    /// own fingerprint for its scene ([`Store::own`]; unpinned when that is unknown).
    pub async fn create_planned(
        &self,
        plan: &CampaignPlan,
        spec_json: &str,
        name: Option<&str>,
        idempotency_key: Option<&str>,
        engine: Option<&str>,
    ) -> Result<CampaignCreated> {
        let engine = engine.or_else(|| self.own.engines.get(plan.kind).map(String::as_str));
        let jobs_total = plan.jobs.len() as u64;
        let internal = |e: serde_json::Error| Error::Internal(e.to_string());
        let mut tx = self.begin().await?;
        if let Some(id) = by_idempotency_key(&mut tx, idempotency_key, spec_json).await? {
            return Ok(CampaignCreated {
                id,
                jobs: jobs_total,
                impacts_total: plan.units_total,
                created: false,
            });
        }
        let id = Uuid::new_v4();
        let now = now_ms();
        let seq = insert_campaign(
            &mut tx,
            NewCampaign {
                id,
                scene: plan.kind,
                name,
                spec_json,
                samples: plan.samples,
                units_total: plan.units_total,
                max_attempts: self.max_attempts,
                idempotency_key,
                now,
                engine,
                commit: self.own.commit.as_deref(),
            },
        )
        .await?;
        let target = plan.target_sem;
        for cell in &plan.cells {
            sqlx::query(
                "INSERT INTO cells (campaign_id, cell_index, angle_deg, shape, swept, units, params,
                                    samples, units_max, units_step, units_balanced, samples_max,
                                    target_sem_rel)
                 VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            )
            .bind(id.to_string())
            .bind(cell.index as i64)
            .bind(cell.angle_deg)
            .bind(cell.shape.as_deref())
            .bind(serde_json::to_string(&cell.swept).map_err(internal)?)
            .bind(cell.units as i64)
            .bind(cell.params.as_str())
            .bind(plan.samples as i64)
            .bind(cell.until_steady.map(|u| u.max as i64))
            .bind(cell.until_steady.map(|u| u.step as i64))
            .bind(cell.until_steady.map(|u| u.balanced))
            .bind(target.map(|t| t.max as i64))
            .bind(target.map(|t| t.target_sem_rel))
            .execute(&mut *tx)
            .await?;
        }
        insert_queued_jobs(&mut tx, &id.to_string(), seq, &plan.jobs, plan.queue, now).await?;
        tx.commit().await?;
        tracing::info!(campaign = %id, scene = plan.kind, jobs = jobs_total,
            units_total = plan.units_total, engine, "campaign created");
        Ok(CampaignCreated {
            id,
            jobs: jobs_total,
            impacts_total: plan.units_total,
            created: true,
        })
    }

    /// [`Store::create`] of an impact campaign.
    pub async fn create_campaign(
        &self,
        spec: &CampaignSpec,
        idempotency_key: Option<&str>,
    ) -> Result<CampaignCreated> {
        self.create(&AnySpec::Impact(spec.clone()), idempotency_key)
            .await
    }

    /// Whether a campaign was submitted under `key` (`Idempotency-Key`).
    pub async fn has_key(&self, key: &str) -> Result<bool> {
        let row = sqlx::query("SELECT 1 FROM campaigns WHERE idempotency_key = ?")
            .bind(key)
            .fetch_optional(&self.read)
            .await?;
        Ok(row.is_some())
    }

    /// Every campaign, newest first, with state and progress.
    pub async fn list_campaigns(&self) -> Result<Vec<CampaignSummary>> {
        let rows = sqlx::query(
            "SELECT c.id, c.name, c.units_total, c.created_ms, c.cancelled_ms, c.scene,
                    COALESCE(SUM(j.units_done), 0) AS done,
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
                    impacts_total: r.get::<i64, _>("units_total") as u64,
                    created_ms: r.get("created_ms"),
                    scene: scene_of(r),
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
        let mut cells = Vec::new();
        for r in sqlx::query(
            "SELECT k.cell_index, k.angle_deg, k.shape, k.swept, k.units, k.samples,
                    COALESCE(SUM(j.units_done), 0) AS done,
                    COALESCE(SUM(j.state = 'done'), 0) AS samples_done
             FROM cells k LEFT JOIN jobs j
               ON j.campaign_id = k.campaign_id AND j.cell_index = k.cell_index
             WHERE k.campaign_id = ? GROUP BY k.cell_index ORDER BY k.cell_index",
        )
        .bind(&ids)
        .fetch_all(&self.read)
        .await?
        {
            let samples = r.get::<i64, _>("samples") as u64;
            cells.push(CellProgress {
                cell: r.get::<i64, _>("cell_index") as u32,
                angle_deg: r.get("angle_deg"),
                shape: r.get("shape"),
                swept: serde_json::from_str(&r.get::<String, _>("swept")).unwrap_or_default(),
                samples_done: r.get::<i64, _>("samples_done") as u64,
                samples_total: samples,
                impacts_done: r.get::<i64, _>("done") as u64,
                impacts_total: r.get::<i64, _>("units") as u64 * samples,
            });
        }
        let impacts_done: u64 = cells.iter().map(|c| c.impacts_done).sum();
        let impacts_total = c.get::<i64, _>("units_total") as u64;
        let now = now_ms();
        let scene = scene_of(&c);
        let recent = sqlx::query(RECENT_UNITS)
            .bind(&ids)
            .bind(now - RATE_WINDOW_MS)
            .fetch_one(&self.read)
            .await?;
        let (mut n, mut first): (i64, Option<i64>) = (recent.get("n"), recent.get("first"));
        if n < RATE_MIN_UNITS {
            let latest = sqlx::query(LATEST_UNITS)
                .bind(&ids)
                .bind(now - RATE_LONGEST_MS)
                .bind(RATE_MIN_UNITS)
                .fetch_all(&self.read)
                .await?;
            n = latest.len() as i64;
            first = latest.last().map(|r| r.get("t"));
        }
        // Over a window that starts at the first of the units counted, so a fresh campaign's
        // rate is not diluted by the minutes before it started.
        let rate = first
            .filter(|_| n > 1)
            .map(|first| n as f64 / ((now - first).max(1000) as f64 / 1000.0));
        // A running job is behind until its worker has reported its stored units again from
        // where it resumed: its checkpoint, or the start without one (units_reported: the
        // highest unit the lease has reported, stored or new).
        let behind = sqlx::query(
            "SELECT COUNT(*) AS jobs, COALESCE(SUM(behind), 0) AS units FROM (
                 SELECT j.units_done - max(j.units_reported, COALESCE(k.units_done, 0)) AS behind
                 FROM jobs j LEFT JOIN checkpoints k ON k.job_id = j.id
                 WHERE j.campaign_id = ? AND j.state = 'leased') WHERE behind > 0",
        )
        .bind(&ids)
        .fetch_one(&self.read)
        .await?;
        let replaying = match behind.get::<i64, _>("jobs") {
            0 => None,
            jobs => Some(Replaying {
                jobs: jobs as u64,
                units_left: behind.get::<i64, _>("units") as u64,
            }),
        };
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
        let engine: Option<String> = c.get("engine");
        let engine_seen = match &engine {
            Some(fp) => Some(
                self.engine_seen(&c.get::<String, _>("scene"), fp, now)
                    .await?,
            ),
            None => None,
        };
        Ok(CampaignStatus {
            id,
            name: c.get("name"),
            state,
            impacts_done,
            impacts_total,
            jobs: counts,
            rate_impacts_per_s: rate,
            eta_s: eta,
            replaying,
            cells,
            last_error,
            created_ms: c.get("created_ms"),
            scene,
            engine,
            engine_seen,
        })
    }

    /// The results JSON the results endpoint serves (partial while jobs remain; with `raw`,
    /// every job's records), written by the campaign's scene from its stored spec, its cells
    /// as they stand now and their records.
    pub async fn results_json(&self, id: Uuid, raw: bool) -> Result<String> {
        let c = self.campaign_row(id).await?;
        let scene = self.scenes.get(&c.get::<String, _>("scene"))?;
        let cells = self.cell_records(id, self.stored_cells(id).await?).await?;
        let raw = if raw {
            Some(self.job_records(id).await?)
        } else {
            None
        };
        let body = scene.results(&c.get::<String, _>("spec"), cells, raw)?;
        Ok(with_engine(
            body,
            c.get("engine"),
            c.get::<Option<String>, _>("commit_id"),
        ))
    }

    /// Whether a worker whose fingerprint for `scene` is `engine` claimed or reported since
    /// one lease period before `now`.
    async fn engine_seen(&self, scene: &str, engine: &str, now: i64) -> Result<bool> {
        let path = format!("$.\"{scene}\"");
        Ok(sqlx::query(
            "SELECT 1 FROM workers WHERE last_seen_ms >= ?1
               AND (json_extract(engines, ?2) = ?3 OR json_extract(engines, '$.\"*\"') = ?3)
             LIMIT 1",
        )
        .bind(now - self.lease_ttl.as_millis() as i64)
        .bind(path)
        .bind(engine)
        .fetch_optional(&self.read)
        .await?
        .is_some())
    }

    /// [`Store::results_json`] read as grit's own scenes' results.
    pub async fn results_any(&self, id: Uuid, raw: bool) -> Result<AnyResults> {
        serde_json::from_str(&self.results_json(id, raw).await?)
            .map_err(|e| Error::Internal(format!("results of campaign {id}: {e}")))
    }

    /// Every job of campaign `id` in cell and sample order, with the records (JSON) of the
    /// units it stored, in order.
    async fn job_records(&self, id: Uuid) -> Result<Vec<StoredJob<String>>> {
        let jobs = sqlx::query(
            "SELECT id, cell_index, sample_index, seed, state FROM jobs
             WHERE campaign_id = ? ORDER BY cell_index, sample_index",
        )
        .bind(id.to_string())
        .fetch_all(&self.read)
        .await?;
        let rows = sqlx::query(
            "SELECT u.job_id, u.record FROM units u JOIN jobs j ON j.id = u.job_id
             WHERE j.campaign_id = ? ORDER BY u.job_id, u.unit",
        )
        .bind(id.to_string())
        .fetch_all(&self.read)
        .await?;
        let mut records: BTreeMap<i64, Vec<String>> = BTreeMap::new();
        for r in rows {
            records.entry(r.get(0)).or_default().push(r.get(1));
        }
        Ok(jobs
            .iter()
            .map(|j| StoredJob {
                cell: j.get::<i64, _>("cell_index") as u32,
                sample: j.get::<i64, _>("sample_index") as u32,
                seed: j.get::<i64, _>("seed") as u64,
                state: j.get("state"),
                records: records.remove(&j.get::<i64, _>("id")).unwrap_or_default(),
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
            "SELECT id, cell_index, sample_index, state, attempts, units_done, units_planned,
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
                    impacts_done: r.get::<i64, _>("units_done") as u32,
                    impacts_planned: r.get::<i64, _>("units_planned") as u32,
                    worker: r.get("worker"),
                    lease_expires_ms: r.get("lease_expires_ms"),
                    updated_ms: r.get("updated_ms"),
                    last_error: r.get("last_error"),
                })
            })
            .collect()
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
}

fn job_state(s: &str) -> Result<JobState> {
    JobState::parse(s).ok_or_else(|| Error::Internal(format!("stored job state {s:?}")))
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
