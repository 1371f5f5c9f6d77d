//! The store's side of jet campaigns (docs/jet-campaigns.md): submitting one (cells and jobs
//! whose unit is a slice), and its results from the stored slices.

use grit_erosion::campaign::{job_seed, JetCampaignSpec, Scene};
use grit_erosion::jet::aggregate::{aggregate_jet_campaign, JetCellInput, JetSampleInput};
use grit_erosion::jet::JetSlice;
use sqlx::Row;
use uuid::Uuid;

use super::{
    by_idempotency_key, insert_campaign, insert_queued_jobs, now_ms, per_cell_and_sample,
    NewCampaign, NewJob, Store,
};
use crate::api::{CampaignCreated, JetResultsResponse, RawJetSample};
use crate::error::{Error, Result};

/// The jet hits the target straight on: the angle stored with a jet cell.
const JET_ANGLE_DEG: f64 = 90.0;
/// What a jet cell stores as its shape: the scene's name.
const JET_SHAPE: &str = "jet";

fn internal(e: impl std::fmt::Display) -> Error {
    Error::Internal(e.to_string())
}

impl Store {
    /// Validates, expands and stores a jet campaign with all its jobs in one transaction;
    /// its `impacts_total` counts slices. With an idempotency key already used, returns the
    /// earlier campaign instead.
    pub async fn create_jet_campaign(
        &self,
        spec: &JetCampaignSpec,
        idempotency_key: Option<&str>,
    ) -> Result<CampaignCreated> {
        let cells = spec.cells()?;
        let slices_total = spec.slices_total()?;
        let samples = spec.samples;
        let jobs_total = cells.len() as u64 * samples as u64;
        let spec_json = serde_json::to_string(spec).map_err(internal)?;
        let mut tx = self.begin().await?;
        if let Some(id) = by_idempotency_key(&mut tx, idempotency_key, &spec_json).await? {
            return Ok(CampaignCreated {
                id,
                jobs: jobs_total,
                impacts_total: slices_total,
                created: false,
            });
        }
        let id = Uuid::new_v4();
        let now = now_ms();
        let seq = insert_campaign(
            &mut tx,
            NewCampaign {
                id,
                scene: Scene::Jet,
                name: spec.name.as_deref(),
                spec_json: &spec_json,
                samples,
                units_total: slices_total,
                max_attempts: self.max_attempts,
                idempotency_key,
                now,
            },
        )
        .await?;
        for cell in &cells {
            sqlx::query(
                "INSERT INTO cells (campaign_id, cell_index, angle_deg, shape, swept, impacts,
                                    params, samples)
                 VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
            )
            .bind(id.to_string())
            .bind(cell.index as i64)
            .bind(JET_ANGLE_DEG)
            .bind(JET_SHAPE)
            .bind(serde_json::to_string(&cell.swept).map_err(internal)?)
            .bind(cell.slices as i64)
            .bind(serde_json::to_string(&cell.params).map_err(internal)?)
            .bind(samples as i64)
            .execute(&mut *tx)
            .await?;
        }
        let jobs: Vec<NewJob> = cells
            .iter()
            .flat_map(|c| {
                (0..samples).map(move |s| (c.index, s, c.slices, job_seed(spec.seed, c.index, s)))
            })
            .collect();
        insert_queued_jobs(&mut tx, &id.to_string(), seq, &jobs, now).await?;
        tx.commit().await?;
        tracing::info!(campaign = %id, jobs = jobs_total, slices_total, "jet campaign created");
        Ok(CampaignCreated {
            id,
            jobs: jobs_total,
            impacts_total: slices_total,
            created: true,
        })
    }

    /// A jet campaign's results (partial while jobs remain) from its stored spec and slices;
    /// with `raw`, every sample's slices.
    pub(super) async fn jet_results(
        &self,
        id: Uuid,
        spec_text: &str,
        raw: bool,
    ) -> Result<JetResultsResponse> {
        let spec = JetCampaignSpec::from_json(spec_text)?;
        let cells = spec.cells()?;
        let rows = sqlx::query(
            "SELECT j.cell_index, j.sample_index, s.record
             FROM slices s JOIN jobs j ON j.id = s.job_id
             WHERE j.campaign_id = ?
             ORDER BY j.cell_index, j.sample_index, s.slice",
        )
        .bind(id.to_string())
        .fetch_all(&self.read)
        .await?;
        let per_cell = per_cell_and_sample(&rows, cells.len(), |r| {
            serde_json::from_str::<JetSlice>(&r.get::<String, _>(2))
                .map_err(|e| Error::Internal(format!("stored slice record: {e}")))
        })?;
        let inputs: Vec<JetCellInput> = cells
            .iter()
            .zip(per_cell)
            .map(|(cell, samples)| JetCellInput {
                cell: cell.index,
                params: cell.params.clone(),
                pump_pressure_mpa: cell.pump_pressure_mpa,
                swept: cell.swept.clone(),
                planned_samples: spec.samples as usize,
                planned_slices: cell.slices as usize,
                samples: samples
                    .into_iter()
                    .map(|(sample, slices)| JetSampleInput { sample, slices })
                    .collect(),
            })
            .collect();
        let spec_value: serde_json::Value = serde_json::from_str(spec_text)
            .map_err(|e| Error::Internal(format!("stored spec: {e}")))?;
        let results = aggregate_jet_campaign(&inputs)
            .map_err(|e| Error::Internal(format!("aggregation: {e}")))?
            .with_spec(spec_value);
        let raw = if raw {
            Some(self.raw_slices(id).await?)
        } else {
            None
        };
        Ok(JetResultsResponse { results, raw })
    }

    async fn raw_slices(&self, id: Uuid) -> Result<Vec<RawJetSample>> {
        let jobs = self.job_records::<JetSlice>(id, "slices", "slice").await?;
        Ok(jobs
            .into_iter()
            .map(|(j, slices)| RawJetSample {
                cell: j.cell,
                sample: j.sample,
                seed: j.seed,
                state: j.state,
                slices,
            })
            .collect())
    }
}
