//! Group commit of the lease holders' writes. Claims, heartbeats, completions, failures and
//! releases are queued to one writer task, which applies every request waiting at that moment
//! inside one `BEGIN IMMEDIATE` transaction and commits once: with many workers, one commit
//! (and one flush to the disk) then carries many requests instead of one.
//!
//! Each request is decided inside the shared transaction by the same rules as alone (lease
//! checks, 409s, impacts skipped when already stored), after the requests queued before it.
//! A refused request must leave nothing behind while the others go on: a group is applied
//! first without savepoints, and at the first refusal it is rolled back and applied again
//! with each request inside its own `SAVEPOINT`, so the refused one alone is undone. No
//! request is answered before the transaction holding it has committed. When the
//! transaction itself fails (a commit refused for a full disk, a savepoint SQLite already
//! unwound), nothing of it is stored and each of its requests is applied again alone, in a
//! transaction of its own, so each gets its own answer.

use std::time::Duration;

use sqlx::{Sqlite, SqlitePool, Transaction};
use tokio::sync::{mpsc, oneshot};
use uuid::Uuid;

use super::now_ms;
use super::worker::{
    apply_claim, apply_complete, apply_fail, apply_heartbeat, apply_release, reap, Leased, NewUnits,
};
use crate::api::HeartbeatResponse;
use crate::checkpoint::CheckpointBytes;
use crate::error::{Error, Result};
use crate::scenes::SceneRegistry;

/// Most requests applied in one transaction; more wait for the next one. Bounds how long
/// the writer holds the database between commits (and so the latency of other writes).
const MAX_GROUP: usize = 512;
/// Requests that may wait for the writer before senders wait for room.
const QUEUE: usize = 4096;

/// A lease holder's write, owned so it can wait in the queue and be applied again alone. It
/// comes ready to store (impact or slice records serialised, checkpoint decoded and hashed, error message
/// cut to length), so the writer spends its time on the database alone.
pub(super) enum Op {
    Claim {
        worker: String,
    },
    Heartbeat {
        job_id: i64,
        lease: Uuid,
        units: NewUnits,
        checkpoint: Option<CheckpointBytes>,
    },
    Complete {
        job_id: i64,
        lease: Uuid,
        units: NewUnits,
        checkpoint: Option<CheckpointBytes>,
        /// The scenes that judge the job's cell once it is done.
        scenes: SceneRegistry,
    },
    Fail {
        job_id: i64,
        lease: Uuid,
        error: String,
        units: NewUnits,
    },
    Release {
        job_id: i64,
        lease: Uuid,
        units: NewUnits,
        checkpoint: Option<CheckpointBytes>,
    },
}

/// What an applied request answers.
pub(super) enum Reply {
    Claimed(Option<Box<Leased>>),
    Beat(HeartbeatResponse),
    /// A release, with the impacts the job keeps.
    Released(u32),
    Done,
}

/// A queued request and where its answer goes.
pub(super) struct Pending {
    op: Op,
    reply: oneshot::Sender<Result<Reply>>,
}

/// The handle requests are queued through; the writer task ends when every handle is gone.
#[derive(Clone)]
pub(super) struct GroupWriter {
    queue: mpsc::Sender<Pending>,
}

impl GroupWriter {
    /// Starts the writer task on the current runtime, writing through `pool`.
    pub fn start(pool: SqlitePool, lease_ttl: Duration) -> GroupWriter {
        let (queue, rx) = mpsc::channel(QUEUE);
        tokio::spawn(run(pool, lease_ttl, rx));
        GroupWriter { queue }
    }

    /// Applies `op` in the next group and returns its answer once that group has committed.
    pub async fn apply(&self, op: Op) -> Result<Reply> {
        let (reply, answer) = oneshot::channel();
        let stopped = || Error::Internal("the database writer task has stopped".into());
        self.queue
            .send(Pending { op, reply })
            .await
            .map_err(|_| stopped())?;
        answer.await.map_err(|_| stopped())?
    }
}

async fn run(pool: SqlitePool, lease_ttl: Duration, mut rx: mpsc::Receiver<Pending>) {
    let mut batch = Vec::with_capacity(MAX_GROUP);
    while rx.recv_many(&mut batch, MAX_GROUP).await > 0 {
        // A request whose caller has gone (its connection closed) is not applied, as a
        // handler dropped before its commit stored nothing either.
        batch.retain(|p| !p.reply.is_closed());
        let answers = match batch.len() {
            0 => continue,
            1 => vec![alone(&pool, lease_ttl, &batch[0].op).await],
            n => match applied_together(&pool, lease_ttl, &batch).await {
                Ok(answers) => answers,
                Err(e) => {
                    tracing::warn!(error = %e, requests = n,
                        "a group of writes could not commit; applying each alone");
                    let mut answers = Vec::with_capacity(n);
                    for p in &batch {
                        answers.push(alone(&pool, lease_ttl, &p.op).await);
                    }
                    answers
                }
            },
        };
        for (p, answer) in batch.drain(..).zip(answers) {
            if let Ok(reply) = &answer {
                log_applied(&p.op, reply);
            }
            // The caller may have gone meanwhile; what committed stays committed.
            let _ = p.reply.send(answer);
        }
    }
}

/// Applies `op` in a transaction of its own.
async fn alone(pool: &SqlitePool, lease_ttl: Duration, op: &Op) -> Result<Reply> {
    let mut tx = pool.begin_with("BEGIN IMMEDIATE").await?;
    let reply = apply(&mut tx, lease_ttl, op, true).await?;
    tx.commit().await?;
    Ok(reply)
}

/// Applies the requests of `batch` together. Most groups hold no refused request, so they
/// are first applied without savepoints (half the statements); at the first refusal that
/// transaction is dropped and the group applied again with a savepoint around each request.
async fn applied_together(
    pool: &SqlitePool,
    lease_ttl: Duration,
    batch: &[Pending],
) -> Result<Vec<Result<Reply>>> {
    match group(pool, lease_ttl, batch, false).await? {
        Some(answers) => Ok(answers),
        None => Ok(group(pool, lease_ttl, batch, true)
            .await?
            .ok_or_else(|| Error::Internal("a savepoint did not hold a refusal".into()))?),
    }
}

/// Applies every request of `batch` in one transaction and commits. With `savepoints`, each
/// request runs within its own, and a refused one is rolled back alone; without, the first
/// refusal rolls the whole transaction back and gives `None`. `Err` when the transaction as
/// a whole failed: then nothing of it is stored.
async fn group(
    pool: &SqlitePool,
    lease_ttl: Duration,
    batch: &[Pending],
    savepoints: bool,
) -> Result<Option<Vec<Result<Reply>>>> {
    let mut tx = pool.begin_with("BEGIN IMMEDIATE").await?;
    // One sweep of expired leases serves every claim of the group.
    if batch.iter().any(|p| matches!(p.op, Op::Claim { .. })) {
        reap(&mut tx, now_ms()).await?;
    }
    let mut answers = Vec::with_capacity(batch.len());
    for p in batch {
        if savepoints {
            sql(&mut tx, "SAVEPOINT request").await?;
        }
        let answer = apply(&mut tx, lease_ttl, &p.op, false).await;
        match (&answer, savepoints) {
            (Ok(_), false) => {}
            (Err(_), false) => return Ok(None),
            (Ok(_), true) => sql(&mut tx, "RELEASE request").await?,
            (Err(_), true) => {
                // Fails when SQLite has already rolled the whole transaction back (some I/O
                // errors do): the group is then lost and replayed request by request.
                sql(&mut tx, "ROLLBACK TO request").await?;
                sql(&mut tx, "RELEASE request").await?;
            }
        }
        answers.push(answer);
    }
    tx.commit().await?;
    Ok(Some(answers))
}

async fn sql(tx: &mut Transaction<'static, Sqlite>, statement: &str) -> Result<()> {
    sqlx::query(statement).execute(&mut **tx).await?;
    Ok(())
}

/// Applies one request in `tx`; a claim sweeps expired leases first when `reap` is set.
async fn apply(
    tx: &mut Transaction<'static, Sqlite>,
    lease_ttl: Duration,
    op: &Op,
    reap: bool,
) -> Result<Reply> {
    Ok(match op {
        Op::Claim { worker } => Reply::Claimed(
            apply_claim(tx, lease_ttl, worker, reap)
                .await?
                .map(Box::new),
        ),
        Op::Heartbeat {
            job_id,
            lease,
            units,
            checkpoint,
        } => Reply::Beat(
            apply_heartbeat(tx, lease_ttl, *job_id, *lease, units, checkpoint.as_ref()).await?,
        ),
        Op::Complete {
            job_id,
            lease,
            units,
            checkpoint,
            scenes,
        } => {
            apply_complete(tx, *job_id, *lease, units, checkpoint.as_ref(), scenes).await?;
            Reply::Done
        }
        Op::Fail {
            job_id,
            lease,
            error,
            units,
        } => {
            apply_fail(tx, *job_id, *lease, error, units).await?;
            Reply::Done
        }
        Op::Release {
            job_id,
            lease,
            units,
            checkpoint,
        } => Reply::Released(apply_release(tx, *job_id, *lease, units, checkpoint.as_ref()).await?),
    })
}

/// Logs a request once it is committed.
fn log_applied(op: &Op, reply: &Reply) {
    match (op, reply) {
        (Op::Claim { worker }, Reply::Claimed(Some(job))) => {
            tracing::debug!(job = job.job_id, worker, "job leased");
        }
        (Op::Complete { job_id, .. }, _) => tracing::debug!(job = job_id, "job done"),
        (Op::Fail { job_id, error, .. }, _) => {
            tracing::warn!(job = job_id, error = %error, "job attempt failed");
        }
        (Op::Release { job_id, .. }, Reply::Released(done)) => {
            tracing::info!(job = job_id, impacts = done, "job released");
        }
        _ => {}
    }
}

/// The answer to a request of another kind than expected: a bug, answered 500.
pub(super) fn mismatch() -> Error {
    Error::Internal("the database writer answered another kind of request".into())
}
