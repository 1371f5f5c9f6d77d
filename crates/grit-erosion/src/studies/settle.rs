//! When an impact may end, a choice Mohseni-Mofidi et al. 2022 (section 4) leaves open: each
//! impact of a sample run again with another end criterion shows with numbers whether the mass
//! loss depends on it (a stricter one), or what a looser one would save and change.

use serde::{Deserialize, Serialize};

use crate::impact::sample::{Sample, SampleError};
use crate::impact::{run_impact, ImpactParams};

/// One impact run twice from the same surface and grain: with the scene's end criterion and
/// with another one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SettleRow {
    /// 1-based impact number in the reference sample.
    pub impact: u32,
    /// Mass loss with the scene's criterion (kg/m).
    pub mass_loss_kg: f64,
    /// Mass loss with the other criterion (kg/m).
    pub mass_loss_other_kg: f64,
    /// Damage added over the surface, ΣΔD, with the scene's criterion: a continuous measure of
    /// what the impact did, where removed mass moves in whole particles.
    pub damage_added: f64,
    /// The same with the other criterion.
    pub damage_added_other: f64,
    /// Simulated time of the impact with the scene's criterion (s).
    pub sim_time_s: f64,
    /// Simulated time with the other criterion (s).
    pub sim_time_other_s: f64,
    /// Steps of the impact with the scene's criterion: its cost.
    pub steps: u64,
    /// Steps with the other criterion.
    pub steps_other: u64,
}

/// Runs `impacts` more impacts of `sample` with its scene and, before each, the same impact
/// from the same surface with `other_fraction` in place of the scene's `settle_fraction`; the
/// sample goes on with the scene's criterion, so both runs of an impact always start from one
/// state. `sample` is fresh or a worn surface from a checkpoint.
pub fn settle_study(
    mut s: Sample,
    impacts: u32,
    other_fraction: f64,
    mut progress: impl FnMut(&SettleRow),
) -> Result<Vec<SettleRow>, SampleError> {
    let other = ImpactParams {
        settle_fraction: other_fraction,
        ..s.params().clone()
    };
    other.validate()?;
    let mut rows = Vec::new();
    for _ in 0..impacts {
        let grain = s.next_grain()?;
        let before: f64 = s.surface().damage.iter().sum();
        let impact = s.impacts_done() + 1;
        let alt = run_impact(&other, s.surface(), &grain, &|| false)
            .map_err(|error| SampleError::Impact { impact, error })?;
        let alt_damage = damage_added(before, &alt.surface.damage, alt.outcome.mass_loss_kg, &s);
        let r = s.run_next()?.clone();
        let damage = damage_added(before, &s.surface().damage, r.mass_loss_kg, &s);
        let row = SettleRow {
            impact: r.impact,
            mass_loss_kg: r.mass_loss_kg,
            mass_loss_other_kg: alt.outcome.mass_loss_kg,
            damage_added: damage,
            damage_added_other: alt_damage,
            sim_time_s: r.outcome.sim_time_s,
            sim_time_other_s: alt.outcome.sim_time_s,
            steps: r.outcome.steps,
            steps_other: alt.outcome.steps,
        };
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// ΣD after minus ΣD before, counting each removed particle as D = 1 (the surface lattice
/// has one particle mass, so the removed count is mass / particle mass).
fn damage_added(before: f64, after: &[f64], removed_kg: f64, s: &Sample) -> f64 {
    let p = s.params();
    let particle_kg = p.material.density_kg_m3 * p.spacing_m * p.spacing_m;
    after.iter().sum::<f64>() + removed_kg / particle_kg - before
}
