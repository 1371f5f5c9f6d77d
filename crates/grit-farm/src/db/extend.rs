//! Cells that grow with their results (`docs/erosion.md`, "Extending a cell"): when the last
//! job of such a cell completes, the same transaction assesses the cell from its stored
//! impacts and either plans every sample for more impacts (they resume from the checkpoint
//! kept after their last impact), adds samples, or finishes the cell and drops its kept
//! checkpoints. The rule itself is grit-erosion's [`next_step`].

use std::collections::BTreeMap;

use grit_erosion::campaign::{job_seed, next_step, CampaignSpec, NextStep, TargetSem, UntilSteady};
use grit_erosion::{aggregate_cell, CellInput, Impact, SampleInput, SLOPE_WINDOW};
use sqlx::{Row, Sqlite, Transaction};
use uuid::Uuid;

use super::{insert_queued_jobs, NewJob, Store};
use crate::error::{Error, Result};

/// A cell's current plan and the rules that may grow it.
#[derive(Debug, Clone, Copy)]
pub(super) struct CellPlan {
    /// Impacts every sample is planned for now.
    pub impacts: u32,
    /// Samples the cell has now.
    pub samples: u32,
    /// Impacts grow until steady, if set.
    pub until: Option<UntilSteady>,
    /// Samples grow until the error bar is small, if set.
    pub target: Option<TargetSem>,
}

impl CellPlan {
    /// The plan in row `r`, whose columns carry the names of [`PLAN_COLUMNS`].
    pub fn from_row(r: &sqlx::sqlite::SqliteRow) -> CellPlan {
        let impacts = r.get::<i64, _>("units") as u32;
        let samples = r.get::<i64, _>("samples") as u32;
        let until = match (
            r.get::<Option<i64>, _>("units_max"),
            r.get::<Option<i64>, _>("units_step"),
        ) {
            (Some(max), Some(step)) => Some(UntilSteady {
                min: impacts.min(max as u32),
                max: max as u32,
                step: step as u32,
            }),
            _ => None,
        };
        let target = match (
            r.get::<Option<f64>, _>("target_sem_rel"),
            r.get::<Option<i64>, _>("samples_max"),
        ) {
            (Some(t), Some(max)) => Some(TargetSem {
                target_sem_rel: t,
                min: samples.min(max as u32),
                max: max as u32,
            }),
            _ => None,
        };
        CellPlan {
            impacts,
            samples,
            until,
            target,
        }
    }

    /// Whether the samples of this cell may still be asked for more impacts, so the state
    /// after their last impact must be kept.
    pub fn impacts_may_grow(&self) -> bool {
        self.until.is_some_and(|u| self.impacts < u.max)
    }
}

const PLAN_COLUMNS: &str = "units, samples, units_max, units_step, samples_max, target_sem_rel";

impl Store {
    /// Every cell's current plan, in cell order.
    pub(super) async fn cell_plans(&self, id: Uuid) -> Result<Vec<CellPlan>> {
        Ok(sqlx::query(&format!(
            "SELECT {PLAN_COLUMNS} FROM cells WHERE campaign_id = ? ORDER BY cell_index"
        ))
        .bind(id.to_string())
        .fetch_all(&self.read)
        .await?
        .iter()
        .map(CellPlan::from_row)
        .collect())
    }
}

/// After a job of `cell` completed: once every job of the cell is done, grows the cell by
/// its rules or finishes it. Runs inside the completing transaction, so a crash anywhere
/// leaves either the job still leased or the cell fully grown.
pub(super) async fn settle_cell(
    tx: &mut Transaction<'static, Sqlite>,
    campaign: &str,
    cell: i64,
    plan: CellPlan,
    now: i64,
) -> Result<()> {
    if plan.until.is_none() && plan.target.is_none() {
        return Ok(());
    }
    let open: i64 = sqlx::query(
        "SELECT COUNT(*) FROM jobs WHERE campaign_id = ? AND cell_index = ? AND state != 'done'",
    )
    .bind(campaign)
    .bind(cell)
    .fetch_one(&mut **tx)
    .await?
    .get(0);
    if open > 0 {
        return Ok(());
    }
    let rows = sqlx::query(
        "SELECT j.sample_index, u.record
         FROM units u JOIN jobs j ON j.id = u.job_id
         WHERE j.campaign_id = ? AND j.cell_index = ? ORDER BY j.sample_index, u.unit",
    )
    .bind(campaign)
    .bind(cell)
    .fetch_all(&mut **tx)
    .await?;
    let mut samples: BTreeMap<u32, Vec<Impact>> = BTreeMap::new();
    for r in &rows {
        // An impact record's grain mass and loss are all the assessment reads of it.
        let impact = serde_json::from_str(r.get::<&str, _>(1))
            .map_err(|e| Error::Internal(format!("stored unit record: {e}")))?;
        samples
            .entry(r.get::<i64, _>(0) as u32)
            .or_default()
            .push(impact);
    }
    let input = CellInput {
        angle_deg: 0.0,
        shape: String::new(),
        swept: BTreeMap::new(),
        planned_samples: plan.samples as usize,
        planned_impacts: plan.impacts as usize,
        samples: samples
            .into_iter()
            .map(|(sample, impacts)| SampleInput { sample, impacts })
            .collect(),
    };
    let result = aggregate_cell(&input, SLOPE_WINDOW)
        .map_err(|e| Error::Internal(format!("assessing cell {cell}: {e}")))?;
    let step = next_step(&result, plan.until, plan.target);
    match step {
        NextStep::ExtendImpacts(to) => {
            sqlx::query(
                "UPDATE jobs SET units_planned = ?, state = 'queued', lease_id = NULL,
                                 worker = NULL, lease_expires_ms = NULL, updated_ms = ?
                 WHERE campaign_id = ? AND cell_index = ?",
            )
            .bind(to as i64)
            .bind(now)
            .bind(campaign)
            .bind(cell)
            .execute(&mut **tx)
            .await?;
            grow_cell(
                tx,
                campaign,
                cell,
                PlanColumn::Impacts(to),
                (to - plan.impacts) as i64 * plan.samples as i64,
            )
            .await?;
        }
        NextStep::AddSamples(to) => {
            let r = sqlx::query("SELECT rowid, spec FROM campaigns WHERE id = ?")
                .bind(campaign)
                .fetch_one(&mut **tx)
                .await?;
            let seq: i64 = r.get(0);
            let seed = CampaignSpec::from_json(&r.get::<String, _>(1))?.seed;
            let jobs: Vec<NewJob> = (plan.samples..to)
                .map(|s| (cell as u32, s, plan.impacts, job_seed(seed, cell as u32, s)))
                .collect();
            insert_queued_jobs(tx, campaign, seq, &jobs, now).await?;
            grow_cell(
                tx,
                campaign,
                cell,
                PlanColumn::Samples(to),
                (to - plan.samples) as i64 * plan.impacts as i64,
            )
            .await?;
        }
        NextStep::Final => {}
    }
    let drop_checkpoints = match step {
        NextStep::ExtendImpacts(_) => false,
        // Added samples may leave the cell unsteady again, and then every sample grows.
        NextStep::AddSamples(_) => !plan.impacts_may_grow(),
        NextStep::Final => true,
    };
    if drop_checkpoints {
        sqlx::query(
            "DELETE FROM checkpoints WHERE job_id IN
               (SELECT id FROM jobs WHERE campaign_id = ? AND cell_index = ?)",
        )
        .bind(campaign)
        .bind(cell)
        .execute(&mut **tx)
        .await?;
    }
    tracing::info!(campaign, cell, ?step, "cell assessed");
    Ok(())
}

/// The cell's new plan: impacts per sample, or samples.
enum PlanColumn {
    Impacts(u32),
    Samples(u32),
}

/// Records a cell's new plan and adds `added_impacts` to its campaign's total.
async fn grow_cell(
    tx: &mut Transaction<'static, Sqlite>,
    campaign: &str,
    cell: i64,
    plan: PlanColumn,
    added_impacts: i64,
) -> Result<()> {
    let (sql, value) = match plan {
        PlanColumn::Impacts(n) => (
            "UPDATE cells SET units = ? WHERE campaign_id = ? AND cell_index = ?",
            n,
        ),
        PlanColumn::Samples(n) => (
            "UPDATE cells SET samples = ? WHERE campaign_id = ? AND cell_index = ?",
            n,
        ),
    };
    sqlx::query(sql)
        .bind(value as i64)
        .bind(campaign)
        .bind(cell)
        .execute(&mut **tx)
        .await?;
    sqlx::query("UPDATE campaigns SET units_total = units_total + ? WHERE id = ?")
        .bind(added_impacts)
        .bind(campaign)
        .execute(&mut **tx)
        .await?;
    Ok(())
}
