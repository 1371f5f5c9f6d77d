//! When an impact may end, a choice Mohseni-Mofidi et al. 2022 (section 4) leaves open: each
//! impact of a sample run again with a stricter end criterion shows with numbers that the mass
//! loss does not depend on it.

use serde::{Deserialize, Serialize};

use crate::impact::sample::{Sample, SampleError};
use crate::impact::{run_impact, ImpactParams};

/// One impact run twice from the same surface and grain: with the scene's end criterion and
/// with a stricter one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SettleRow {
    /// 1-based impact number in the reference sample.
    pub impact: u32,
    /// Mass loss with the scene's criterion (kg/m).
    pub mass_loss_kg: f64,
    /// Mass loss with the stricter criterion (kg/m).
    pub mass_loss_strict_kg: f64,
    /// Damage added over the surface, ΣΔD, with the scene's criterion: a continuous measure of
    /// what the impact did, where removed mass moves in whole particles.
    pub damage_added: f64,
    /// The same with the stricter criterion.
    pub damage_added_strict: f64,
    /// Simulated time of the impact with each criterion (s).
    pub sim_time_s: f64,
    /// Simulated time with the stricter criterion (s).
    pub sim_time_strict_s: f64,
}

/// Runs a sample of `impacts` with `params` and, before each impact, the same impact from the
/// same surface with `strict_fraction` in place of `params.settle_fraction`; the sample goes
/// on with the scene's criterion, so both runs of an impact always start from one state.
pub fn settle_study(
    params: &ImpactParams,
    seed: u64,
    impacts: u32,
    strict_fraction: f64,
    mut progress: impl FnMut(&SettleRow),
) -> Result<Vec<SettleRow>, SampleError> {
    let strict = ImpactParams {
        settle_fraction: strict_fraction,
        ..params.clone()
    };
    strict.validate()?;
    let mut s = Sample::new(params.clone(), seed)?;
    let mut rows = Vec::new();
    for k in 0..impacts {
        let grain = s.next_grain()?;
        let before: f64 = s.surface().damage.iter().sum();
        let alt = run_impact(&strict, s.surface(), &grain, &|| false).map_err(|error| {
            SampleError::Impact {
                impact: k + 1,
                error,
            }
        })?;
        let alt_damage = damage_added(before, &alt.surface.damage, alt.outcome.mass_loss_kg, &s);
        let r = s.run_next()?.clone();
        let damage = damage_added(before, &s.surface().damage, r.mass_loss_kg, &s);
        let row = SettleRow {
            impact: r.impact,
            mass_loss_kg: r.mass_loss_kg,
            mass_loss_strict_kg: alt.outcome.mass_loss_kg,
            damage_added: damage,
            damage_added_strict: alt_damage,
            sim_time_s: r.outcome.sim_time_s,
            sim_time_strict_s: alt.outcome.sim_time_s,
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
