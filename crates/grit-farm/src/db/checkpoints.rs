//! What the coordinator reads of a job before it hands a lease holder's write to the writer:
//! the scene, parameters and seed that its units and checkpoints are checked against
//! (read-only, beside the writer).

use sqlx::Row;

use super::Store;
use crate::error::{Error, Result};

/// A job's scene as stored.
pub struct StoredJob {
    /// The job's id.
    pub id: i64,
    /// `campaigns.scene`: the scene's kind.
    pub scene: String,
    /// `cells.params`: the scene's parameters as JSON.
    pub params: String,
    /// The job's seed.
    pub seed: u64,
}

impl Store {
    /// The scene, parameters and seed of job `job_id`; 404 when there is no such job.
    pub async fn stored_job(&self, job_id: i64) -> Result<StoredJob> {
        let r = sqlx::query(
            "SELECT k.scene, c.params, j.seed FROM jobs j
             JOIN cells c ON c.campaign_id = j.campaign_id AND c.cell_index = j.cell_index
             JOIN campaigns k ON k.id = j.campaign_id
             WHERE j.id = ?",
        )
        .bind(job_id)
        .fetch_optional(&self.read)
        .await?
        .ok_or_else(|| Error::NotFound(format!("job {job_id}")))?;
        Ok(StoredJob {
            id: job_id,
            scene: r.get(0),
            params: r.get(1),
            seed: r.get::<i64, _>(2) as u64,
        })
    }
}
