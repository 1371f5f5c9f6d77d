//! The coordinator's SQLite store. Every state change is made in a `BEGIN IMMEDIATE`
//! transaction on the single writer connection; the workers' frequent writes (claims,
//! heartbeats, completions) are grouped several to a transaction by one writer task (`group`),
//! the rare ones (campaigns, the lease sweep) take a transaction each. Reads go through a
//! separate read-only pool so status polling never queues behind writes (WAL lets readers run
//! beside the writer). `Store` is the one handle; its queries sit by resource beside the HTTP
//! routes: `campaigns`, `worker` (leases and what lease holders report) and `workers`.

use std::path::Path;
use std::str::FromStr;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use grit_erosion::campaign::{CellRecords, QueueOrder, StoredCell};
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteJournalMode, SqlitePool, SqlitePoolOptions, SqliteSynchronous,
};
use sqlx::{Row, Sqlite, Transaction};
use uuid::Uuid;

use crate::error::{Error, Result};

mod campaigns;
mod checkpoints;
mod extend;
mod group;
mod worker;
mod workers;

pub use checkpoints::StoredJob;
pub use worker::Reported;

/// A report of impact records, for the tests.
#[cfg(test)]
fn imp(records: &[grit_erosion::ImpactRecord]) -> Reported {
    Reported::of::<grit_erosion::Sample>(records).expect("records serialise")
}

/// The impact scene of a claim, for the tests.
#[cfg(test)]
fn impact_params(job: &crate::api::ClaimedJob) -> grit_erosion::ImpactParams {
    assert_eq!(job.scene, "impact");
    serde_json::from_value(job.params.clone()).expect("an impact claim's params")
}

/// The results of impact campaign `id`, for the tests.
#[cfg(test)]
async fn impact_results(s: &Store, id: Uuid) -> grit_erosion::CampaignResults {
    let r = s.results_any(id, false).await.expect("results");
    r.impact()
        .expect("an impact campaign's results")
        .results
        .clone()
}

/// A report of jet slices, for the tests.
#[cfg(test)]
fn jet(records: &[grit_erosion::jet::JetSlice]) -> Reported {
    Reported::of::<grit_erosion::jet::JetRun>(records).expect("records serialise")
}

#[cfg(test)]
mod extend_tests;
#[cfg(test)]
mod group_tests;
#[cfg(test)]
mod jet_tests;
#[cfg(test)]
mod results_tests;
#[cfg(test)]
mod tests;

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
    group: group::GroupWriter,
    /// Lease length.
    pub lease_ttl: Duration,
    /// Attempts (lost or failed leases) after which a job stays `failed`.
    pub max_attempts: u32,
    /// The scenes whose jobs this store's coordinator runs.
    pub scenes: crate::scenes::SceneRegistry,
    /// This coordinator's engine: new campaigns are pinned to it unless their spec names one.
    pub own: OwnEngine,
}

/// A coordinator's own engine (`grit version --json`): the fingerprint of each scene it runs,
/// by kind, and the commit it was built from. Empty, new campaigns are left unpinned, as
/// campaigns before pins were.
#[derive(Debug, Clone, Default)]
pub struct OwnEngine {
    /// Fingerprint of each scene, by kind.
    pub engines: std::collections::BTreeMap<String, String>,
    /// The commit of the build, `unknown` without git at build time.
    pub commit: Option<String>,
}

/// When a commit counts as done, and so when a write is answered: SQLite's `synchronous`
/// setting under WAL (`docs/operations.md`, "Durability of what was answered").
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Synchronous {
    /// Every commit is flushed to the disk before it is answered: nothing answered is lost
    /// to a killed process, an operating-system crash or a power loss.
    #[default]
    Full,
    /// A commit is answered once handed to the operating system, and flushed at WAL
    /// checkpoints: nothing answered is lost to a killed process, but an operating-system
    /// crash or a power loss may undo the last commits.
    Normal,
}

impl std::str::FromStr for Synchronous {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "full" => Ok(Synchronous::Full),
            "normal" => Ok(Synchronous::Normal),
            _ => Err(format!("expected full or normal, got {s:?}")),
        }
    }
}

impl Store {
    /// Opens (creating if missing) the database at `path` and applies the migrations, with
    /// every commit flushed to the disk. Starts the group writer on the current runtime.
    pub async fn open(path: &Path, lease_ttl: Duration, max_attempts: u32) -> Result<Store> {
        Store::open_with(path, lease_ttl, max_attempts, Synchronous::Full).await
    }

    /// [`Store::open`] with commits made durable as `synchronous` says.
    pub async fn open_with(
        path: &Path,
        lease_ttl: Duration,
        max_attempts: u32,
        synchronous: Synchronous,
    ) -> Result<Store> {
        let opts = SqliteConnectOptions::new()
            .filename(path)
            .create_if_missing(true)
            .journal_mode(SqliteJournalMode::Wal)
            .synchronous(match synchronous {
                Synchronous::Full => SqliteSynchronous::Full,
                Synchronous::Normal => SqliteSynchronous::Normal,
            })
            .busy_timeout(Duration::from_secs(30))
            .foreign_keys(true);
        let write = SqlitePoolOptions::new()
            .max_connections(1)
            .after_release(|conn, _| Box::pin(release_writer(conn)))
            .connect_with(opts.clone())
            .await?;
        sqlx::migrate!("../../migrations").run(&write).await?;
        let read = SqlitePoolOptions::new()
            .max_connections(4)
            .connect_with(opts.read_only(true))
            .await?;
        Ok(Store {
            group: group::GroupWriter::start(write.clone(), lease_ttl),
            write,
            read,
            lease_ttl,
            max_attempts: max_attempts.max(1),
            scenes: Default::default(),
            own: OwnEngine::default(),
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
}

/// Whether the writer connection may go back to the pool. Some errors, `SQLITE_FULL` among
/// them, make SQLite roll the transaction back by itself; the `ROLLBACK` sqlx then sends for
/// the dropped transaction fails, and sqlx keeps counting the connection as inside a
/// transaction, so every later `BEGIN` on it would be refused. Such a connection is closed and
/// the pool opens a fresh one, so the store works again as soon as the disk has space.
async fn release_writer(conn: &mut sqlx::SqliteConnection) -> sqlx::Result<bool> {
    use sqlx::Connection;
    if !conn.is_in_transaction() {
        return Ok(true);
    }
    // A dropped transaction's rollback is queued on the connection, not yet run: a ping
    // waits for it.
    conn.ping().await?;
    let clean = !conn.is_in_transaction();
    if !clean {
        tracing::warn!(
            "the database rolled back a failed transaction itself; reopening the writer connection"
        );
    }
    Ok(clean)
}

impl Store {
    /// `cells` of campaign `id` with the records (JSON) their samples stored, in unit order.
    async fn cell_records(
        &self,
        id: Uuid,
        cells: Vec<StoredCell>,
    ) -> Result<Vec<CellRecords<String>>> {
        let rows = sqlx::query(
            "SELECT j.cell_index, j.sample_index, u.record
             FROM units u JOIN jobs j ON j.id = u.job_id
             WHERE j.campaign_id = ?
             ORDER BY j.cell_index, j.sample_index, u.unit",
        )
        .bind(id.to_string())
        .fetch_all(&self.read)
        .await?;
        let mut per_cell: Vec<CellRecords<String>> = cells
            .into_iter()
            .map(|cell| CellRecords {
                cell,
                samples: Default::default(),
            })
            .collect();
        for r in rows {
            let cell = r.get::<i64, _>(0) as usize;
            if let Some(c) = per_cell.get_mut(cell) {
                let sample = r.get::<i64, _>(1) as u32;
                c.samples.entry(sample).or_default().push(r.get(2));
            }
        }
        Ok(per_cell)
    }
}

/// Parses a uuid the store wrote.
fn parse_uuid(s: &str) -> Result<Uuid> {
    Uuid::from_str(s).map_err(|e| Error::Internal(format!("stored id {s}: {e}")))
}

/// The campaign stored under `key`, if any: its id when its spec is `spec_json`, a 409 when
/// the key was used for another spec.
pub(crate) async fn by_idempotency_key(
    tx: &mut Transaction<'static, Sqlite>,
    key: Option<&str>,
    spec_json: &str,
) -> Result<Option<Uuid>> {
    let Some(key) = key else {
        return Ok(None);
    };
    let row = sqlx::query("SELECT id, spec FROM campaigns WHERE idempotency_key = ?")
        .bind(key)
        .fetch_optional(&mut **tx)
        .await?;
    let Some(row) = row else {
        return Ok(None);
    };
    let old: String = row.get("spec");
    if old != spec_json {
        return Err(Error::Conflict(
            "Idempotency-Key already used for a different campaign".into(),
        ));
    }
    Ok(Some(parse_uuid(&row.get::<String, _>("id"))?))
}

/// A campaign row to insert: everything but its cells and jobs.
pub(crate) struct NewCampaign<'a> {
    pub id: Uuid,
    /// The scene's kind (`grit_erosion::Scene::KIND`).
    pub scene: &'static str,
    pub name: Option<&'a str>,
    pub spec_json: &'a str,
    pub samples: u32,
    /// Impacts, or slices for a jet campaign, over all jobs.
    pub units_total: u64,
    pub max_attempts: u32,
    pub idempotency_key: Option<&'a str>,
    pub now: i64,
    /// The engine fingerprint the campaign is pinned to, if any.
    pub engine: Option<&'a str>,
    /// The commit of the grit that created it.
    pub commit: Option<&'a str>,
}

/// Inserts the campaign row `c`; returns its rowid, the `seq` its jobs carry.
pub(crate) async fn insert_campaign(
    tx: &mut Transaction<'static, Sqlite>,
    c: NewCampaign<'_>,
) -> Result<i64> {
    Ok(sqlx::query(
        "INSERT INTO campaigns (id, name, spec, samples, units_total, max_attempts,
                                idempotency_key, created_ms, scene, engine, commit_id)
         VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?) RETURNING rowid",
    )
    .bind(c.id.to_string())
    .bind(c.name)
    .bind(c.spec_json)
    .bind(c.samples as i64)
    .bind(c.units_total as i64)
    .bind(c.max_attempts as i64)
    .bind(c.idempotency_key)
    .bind(c.now)
    .bind(c.scene)
    .bind(c.engine)
    .bind(c.commit)
    .fetch_one(&mut **tx)
    .await?
    .get(0))
}

/// A job row to insert as queued: (cell, sample, impacts planned, seed).
pub(crate) type NewJob = (u32, u32, u32, u64);

/// Inserts `jobs` of `campaign` (rowid `seq`) as queued, ranked in the claim order `queue`
/// asks for (migrations/0012_queue_by_cell.sql). Multi-row inserts keep a campaign of many
/// thousand jobs to a few statements; 400 rows × 9 values stays under SQLite's limit on bound
/// variables.
pub(crate) async fn insert_queued_jobs(
    tx: &mut Transaction<'static, Sqlite>,
    campaign: &str,
    seq: i64,
    jobs: &[NewJob],
    queue: QueueOrder,
    now: i64,
) -> Result<()> {
    for chunk in jobs.chunks(400) {
        let mut qb = sqlx::QueryBuilder::<Sqlite>::new(
            "INSERT INTO jobs (campaign_id, campaign_seq, queue_rank, cell_index, sample_index,
                               seed, units_planned, state, updated_ms) ",
        );
        qb.push_values(chunk, |mut b, (cell, sample, impacts, seed)| {
            let rank = match queue {
                QueueOrder::Rounds => 0,
                QueueOrder::Cells => *cell as i64,
            };
            b.push_bind(campaign)
                .push_bind(seq)
                .push_bind(rank)
                .push_bind(*cell as i64)
                .push_bind(*sample as i64)
                .push_bind(*seed as i64)
                .push_bind(*impacts as i64)
                .push_bind("queued")
                .push_bind(now);
        });
        qb.build().execute(&mut **tx).await?;
    }
    Ok(())
}
