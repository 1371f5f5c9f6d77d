//! The store's side of `GET /workers`: the workers seen recently and the jobs they hold.

use std::collections::BTreeMap;
use std::time::Duration;

use sqlx::Row;

use super::{now_ms, parse_uuid, Store};
use crate::api::{HeldJob, WorkerInfo, WorkersResponse};
use crate::error::Result;

impl Store {
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
                    k.shape, j.sample_index, j.units_done, j.units_planned, j.updated_ms,
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
                impacts_done: r.get::<i64, _>("units_done") as u32,
                impacts_planned: r.get::<i64, _>("units_planned") as u32,
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
}
