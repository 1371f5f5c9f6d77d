//! Cells as stored, and cells that grow with their results (`docs/erosion.md`, "Extending a
//! cell"): when the last job of such a cell completes, the same transaction hands the cell
//! and its units' stored masses to its scene ([`FarmScene::next_step`]), and either plans every
//! sample for more units (they resume from the checkpoint kept after their last unit), adds
//! samples, or finishes the cell and drops its kept checkpoints.

use std::collections::BTreeMap;

use grit_erosion::campaign::{
    job_seed, AnySpec, NextStep, QueueOrder, StoredCell, TargetSem, UnitMasses, UntilSteady,
};
use serde::Deserialize;
use sqlx::{Row, Sqlite, Transaction};
use uuid::Uuid;

use super::{insert_queued_jobs, now_ms, NewJob, Store};
use crate::api::RaisedCell;
use crate::error::{Error, Result};
use crate::scenes::FarmScene;

/// The cell in row `r`, whose columns carry the names of [`CELL_COLUMNS`]: the one source of
/// a cell as it stands now, grown or not.
pub(super) fn stored_cell(r: &sqlx::sqlite::SqliteRow) -> Result<StoredCell> {
    let units = r.get::<i64, _>("units") as u32;
    let samples = r.get::<i64, _>("samples") as u32;
    let until_steady = match (
        r.get::<Option<i64>, _>("units_max"),
        r.get::<Option<i64>, _>("units_step"),
    ) {
        (Some(max), Some(step)) => Some(UntilSteady {
            min: units.min(max as u32),
            max: max as u32,
            step: step as u32,
            balanced: r.get::<Option<bool>, _>("units_balanced").unwrap_or(false),
        }),
        _ => None,
    };
    let target_sem = match (
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
    let swept = serde_json::from_str(r.get::<&str, _>("swept"))
        .map_err(|e| Error::Internal(format!("stored swept values: {e}")))?;
    Ok(StoredCell {
        index: r.get::<i64, _>("cell_index") as u32,
        angle_deg: r.get("angle_deg"),
        shape: r.get("shape"),
        swept,
        params: r.get("params"),
        units,
        samples,
        until_steady,
        target_sem,
    })
}

/// The columns of `cells` that [`stored_cell`] reads.
pub(super) const CELL_COLUMNS: &str = "cell_index, angle_deg, shape, swept, params, units, samples,
     units_max, units_step, units_balanced, samples_max, target_sem_rel";

impl Store {
    /// Every cell of campaign `id` as it stands now, in cell order.
    pub(super) async fn stored_cells(&self, id: Uuid) -> Result<Vec<StoredCell>> {
        sqlx::query(&format!(
            "SELECT {CELL_COLUMNS} FROM cells WHERE campaign_id = ? ORDER BY cell_index"
        ))
        .bind(id.to_string())
        .fetch_all(&self.read)
        .await?
        .iter()
        .map(stored_cell)
        .collect()
    }
}

impl Store {
    /// Raises the caps (`until_steady.max`) of campaign `id` to those of `spec`, a spec of the
    /// same campaign but for its caps ([`grit_erosion::campaign::CampaignPlan::raised_caps`]),
    /// stores `spec` in place of the old one (under `key` when given), and plans anew every
    /// cell that had stopped at its old cap short of its rule, in one transaction. A
    /// `Conflict` names what makes `spec` another campaign.
    pub async fn raise_caps(
        &self,
        id: Uuid,
        spec: &AnySpec,
        key: Option<&str>,
    ) -> Result<Vec<RaisedCell>> {
        let campaign = id.to_string();
        let mut tx = self.begin().await?;
        let row = sqlx::query("SELECT spec, cancelled_ms, scene FROM campaigns WHERE id = ?")
            .bind(&campaign)
            .fetch_optional(&mut *tx)
            .await?
            .ok_or_else(|| Error::NotFound(format!("campaign {id}")))?;
        if row.get::<Option<i64>, _>(1).is_some() {
            return Err(Error::Conflict("campaign is cancelled".into()));
        }
        let other = |why: String| Error::Conflict(format!("not the stored campaign: {why}"));
        let stored = AnySpec::from_json(row.get::<&str, _>(0))
            .map_err(|e| other(format!("its stored spec no longer reads ({e})")))?;
        if stored.name() != spec.name() || stored.engine() != spec.engine() {
            return Err(other("its names or pinned engines differ".into()));
        }
        let raised = stored.plan()?.raised_caps(&spec.plan()?).map_err(other)?;
        let scene = self.scenes.get(row.get::<&str, _>(2))?;
        let now = now_ms();
        let mut report = Vec::new();
        for cap in raised {
            let cell = cap.cell as i64;
            let r = sqlx::query(&format!(
                "UPDATE cells SET units_max = ? WHERE campaign_id = ? AND cell_index = ?
                 RETURNING {CELL_COLUMNS}"
            ))
            .bind(cap.to as i64)
            .bind(&campaign)
            .bind(cell)
            .fetch_one(&mut *tx)
            .await?;
            let plan = stored_cell(&r)?;
            let resumed: i64 = sqlx::query(
                "SELECT COUNT(*) FROM jobs j JOIN checkpoints k ON k.job_id = j.id
                 WHERE j.campaign_id = ? AND j.cell_index = ? AND k.units_done = ?",
            )
            .bind(&campaign)
            .bind(cell)
            .bind(plan.units as i64)
            .fetch_one(&mut *tx)
            .await?
            .get(0);
            // A cell whose last round still runs is judged under the new cap when it ends;
            // one that met its rule below the old cap stays as it is.
            let step = if plan.units >= cap.from {
                settle_cell(&mut tx, &*scene, &campaign, &plan, now).await?
            } else {
                None
            };
            report.push(RaisedCell {
                cell: cap.cell,
                from: cap.from,
                to: cap.to,
                reopened_to: match step {
                    Some(NextStep::ExtendImpacts(to)) => Some(to),
                    _ => None,
                },
                resumed: resumed as u32,
                samples: plan.samples,
            });
        }
        let spec_json = serde_json::to_string(spec).map_err(|e| Error::Internal(e.to_string()))?;
        sqlx::query(
            "UPDATE campaigns SET spec = ?, idempotency_key = coalesce(?, idempotency_key)
             WHERE id = ?",
        )
        .bind(spec_json)
        .bind(key)
        .bind(&campaign)
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        tracing::info!(campaign = %id, ?report, "caps raised");
        Ok(report)
    }
}

/// What a farm reads of any stored spec: the campaign's seed, which every job's derives from,
/// and the order its jobs are handed out in.
#[derive(Deserialize)]
struct Seeded {
    seed: u64,
    #[serde(default)]
    queue: QueueOrder,
}

/// After a job of cell `plan`, one with growth rules, completed: once every job of the cell
/// is done, grows the cell as its scene decides or finishes it, and returns that step (`None`:
/// jobs of the cell are still open). Runs inside the completing transaction, so a crash anywhere
/// leaves either the job still leased or the cell fully grown.
pub(super) async fn settle_cell(
    tx: &mut Transaction<'static, Sqlite>,
    scene: &dyn FarmScene,
    campaign: &str,
    plan: &StoredCell,
    now: i64,
) -> Result<Option<NextStep>> {
    let cell = plan.index as i64;
    let open: i64 = sqlx::query(
        "SELECT COUNT(*) FROM jobs WHERE campaign_id = ? AND cell_index = ? AND state != 'done'",
    )
    .bind(campaign)
    .bind(cell)
    .fetch_one(&mut **tx)
    .await?
    .get(0);
    if open > 0 {
        return Ok(None);
    }
    // A unit stored before its masses had columns is read from its record.
    let rows = sqlx::query(
        "SELECT j.sample_index, u.grain_kg_m, u.loss_kg_m,
                CASE WHEN u.grain_kg_m IS NULL OR u.loss_kg_m IS NULL THEN u.record END,
                u.damage_kg_m
         FROM units u JOIN jobs j ON j.id = u.job_id
         WHERE j.campaign_id = ? AND j.cell_index = ? ORDER BY j.sample_index, u.unit",
    )
    .bind(campaign)
    .bind(cell)
    .fetch_all(&mut **tx)
    .await?;
    let mut samples: BTreeMap<u32, Vec<UnitMasses>> = BTreeMap::new();
    for r in &rows {
        let masses = match (r.get::<Option<f64>, _>(1), r.get::<Option<f64>, _>(2)) {
            (Some(grain_kg_m), Some(loss_kg_m)) => UnitMasses {
                grain_kg_m,
                loss_kg_m,
                damage_kg_m: r.get::<Option<f64>, _>(4),
            },
            _ => scene.masses(r.get::<&str, _>(3))?.ok_or_else(|| {
                Error::Internal(format!("cell {cell} grows, but its scene reads no masses"))
            })?,
        };
        samples
            .entry(r.get::<i64, _>(0) as u32)
            .or_default()
            .push(masses);
    }
    let step = scene.next_step(plan, &samples)?;
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
                (to - plan.units) as i64 * plan.samples as i64,
            )
            .await?;
        }
        NextStep::AddSamples(to) => {
            let r = sqlx::query("SELECT rowid, spec FROM campaigns WHERE id = ?")
                .bind(campaign)
                .fetch_one(&mut **tx)
                .await?;
            let seq: i64 = r.get(0);
            let Seeded { seed, queue } = serde_json::from_str(r.get::<&str, _>(1))
                .map_err(|e| Error::Internal(format!("stored spec's seed or queue: {e}")))?;
            let jobs: Vec<NewJob> = (plan.samples..to)
                .map(|s| (plan.index, s, plan.units, job_seed(seed, plan.index, s)))
                .collect();
            insert_queued_jobs(tx, campaign, seq, &jobs, queue, now).await?;
            grow_cell(
                tx,
                campaign,
                cell,
                PlanColumn::Samples(to),
                (to - plan.samples) as i64 * plan.units as i64,
            )
            .await?;
        }
        NextStep::Final => {}
    }
    let drop_checkpoints = match step {
        NextStep::ExtendImpacts(_) => false,
        // Added samples may leave the cell unsteady again, and then every sample grows.
        NextStep::AddSamples(_) => plan.until_steady.is_none(),
        // A cell stopped at its cap unsteady keeps its samples' last states, so that a later
        // spec raising the cap runs them on (`Store::raise_caps`).
        NextStep::Final => !stopped_at_cap(scene, plan, &samples)?,
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
    Ok(Some(step))
}

/// Whether cell `plan`, assessed final, stopped at its cap short of its rule: under a higher
/// cap its scene would grow it.
fn stopped_at_cap(
    scene: &dyn FarmScene,
    plan: &StoredCell,
    samples: &BTreeMap<u32, Vec<UnitMasses>>,
) -> Result<bool> {
    let Some(u) = plan.until_steady.filter(|u| plan.units >= u.max) else {
        return Ok(false);
    };
    let uncapped = StoredCell {
        until_steady: Some(UntilSteady {
            max: plan.units.saturating_add(u.step),
            ..u
        }),
        ..plan.clone()
    };
    Ok(matches!(
        scene.next_step(&uncapped, samples)?,
        NextStep::ExtendImpacts(_)
    ))
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
