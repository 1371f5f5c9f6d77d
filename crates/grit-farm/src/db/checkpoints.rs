//! What the coordinator checks an uploaded checkpoint against before any write: the scene
//! and seed of the job it is sent for (read-only, beside the writer).

use sqlx::Row;

use super::Store;
use crate::checkpoint::JobParams;
use crate::error::{Error, Result};

impl Store {
    /// The scene (impact or jet) and seed of job `job_id`, which its checkpoints must hold;
    /// 404 when there is no such job.
    pub async fn job_params(&self, job_id: i64) -> Result<(JobParams, u64)> {
        let r = sqlx::query(
            "SELECT c.params, j.seed, k.scene FROM jobs j
             JOIN cells c ON c.campaign_id = j.campaign_id AND c.cell_index = j.cell_index
             JOIN campaigns k ON k.id = j.campaign_id
             WHERE j.id = ?",
        )
        .bind(job_id)
        .fetch_optional(&self.read)
        .await?
        .ok_or_else(|| Error::NotFound(format!("job {job_id}")))?;
        let params: String = r.get(0);
        let scene: String = r.get(2);
        let bad =
            |e: serde_json::Error| Error::Internal(format!("stored params of job {job_id}: {e}"));
        let params = if scene == "jet" {
            JobParams::Jet(serde_json::from_str(&params).map_err(bad)?)
        } else {
            JobParams::Impact(serde_json::from_str(&params).map_err(bad)?)
        };
        Ok((params, r.get::<i64, _>(1) as u64))
    }

    /// The scene of job `job_id`'s campaign (`campaigns.scene`: `impact` or `jet`).
    pub async fn job_scene(&self, job_id: i64) -> Result<String> {
        sqlx::query_scalar(
            "SELECT k.scene FROM jobs j JOIN campaigns k ON k.id = j.campaign_id WHERE j.id = ?",
        )
        .bind(job_id)
        .fetch_optional(&self.read)
        .await?
        .ok_or_else(|| Error::NotFound(format!("job {job_id}")))
    }
}
