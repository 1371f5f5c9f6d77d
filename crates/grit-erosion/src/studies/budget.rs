//! Where an impact's erosion comes from, in the terms of the seed's failure law (Mohseni-Mofidi
//! et al. 2022, eqs. 19–20): D grows by Δε_p/ε_f(σ*), so the damage an impact adds to the
//! surface is its plastic straining times the mean inverse fracture strain under which it
//! strained. At steady state the surface's damage stock is stationary and the removed mass
//! equals the damage added, so E(α) splits into how much the grain deforms the surface and how
//! damaging the stress state of that deformation is; each part is measured per impact here.

use serde::{Deserialize, Serialize};

use crate::impact::sample::{Sample, SampleError};
use crate::impact::SURFACE_BODY;
use crate::stats::{stats, Stats};
use grit_sph::particles::{von_mises, KINEMATIC};
use grit_sph::physics::triaxiality;
use grit_sph::World;

/// Upper edges of the triaxiality bins σ* = −p/σ_eq the budget is split into: strong
/// compression, mild compression, mild tension, strong tension (uniaxial tension is 1/3).
pub const TRIAXIALITY_EDGES: [f64; 3] = [-1.0 / 3.0, 0.0, 1.0 / 3.0];

/// Bins of `TRIAXIALITY_EDGES`.
pub const BINS: usize = TRIAXIALITY_EDGES.len() + 1;

/// The budget of one impact, mass-weighted over the surface (kg/m of prism length).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BudgetRow {
    /// Impact angle of the sample's scene (degrees).
    pub angle_deg: f64,
    /// The sample's seed.
    pub seed: u64,
    /// 1-based impact number in the sample.
    pub impact: u32,
    /// Grain mass (kg/m).
    pub grain_mass_kg: f64,
    /// Σ m D over the free surface particles when the impact began (kg/m): the damage stock
    /// earlier impacts left. It stops growing only once removal pays for what impacts add.
    pub damage_stock_kg: f64,
    /// Mass removed by the impact (kg/m).
    pub mass_loss_kg: f64,
    /// Σ m Δε_p over the surface (kg/m): how much the impact deformed it.
    pub plastic_kg: f64,
    /// Σ m ΔD (kg/m), a removed particle counted to D = 1: what the impact spent of the
    /// surface's failure strain.
    pub damage_kg: f64,
    /// Σ m Δε_p σ* / Σ m Δε_p: the mean triaxiality under which the surface strained.
    pub mean_triaxiality: f64,
    /// The largest Δε_p one particle took in this impact: a chip cut in one pass needs it to
    /// reach the fracture strain.
    pub max_plastic_increment: f64,
    /// The largest ΔD one particle took in this impact (to 1 for one that failed).
    pub max_damage_increment: f64,
    /// Σ m Δε_p per triaxiality bin (`TRIAXIALITY_EDGES`).
    pub plastic_by_triaxiality_kg: [f64; BINS],
    /// Σ m ΔD per triaxiality bin.
    pub damage_by_triaxiality_kg: [f64; BINS],
    /// Mass removed (failed or torn off) by the damage it had when the impact began, in
    /// quarters [0, 1/4), … [3/4, 1]: the first bin is cut out by this impact alone, the last
    /// was worn through by earlier ones.
    pub removed_by_start_damage_kg: [f64; 4],
}

impl BudgetRow {
    /// Damage added per plastic strain: the mass-weighted mean of 1/ε_f over the straining.
    pub fn damage_per_strain(&self) -> f64 {
        if self.plastic_kg > 0.0 {
            self.damage_kg / self.plastic_kg
        } else {
            0.0
        }
    }
}

/// Last seen state of one surface particle, by its id.
#[derive(Clone, Copy, Default)]
struct Seen {
    start_damage: f64,
    start_eps_p: f64,
    eps_p: f64,
    damage: f64,
    mass: f64,
    bin: usize,
    present: bool,
    failed: bool,
    /// The observed step that last found this particle in the world.
    stamp: u64,
}

/// Sums of one impact, filled step by step.
#[derive(Default)]
struct Tally {
    plastic: [f64; BINS],
    damage: [f64; BINS],
    plastic_triax: f64,
}

/// Quarter of D in [0, 1] a removed particle's damage before the impact falls in.
fn quarter(damage: f64) -> usize {
    ((4.0 * damage) as usize).min(3)
}

fn bin_of(triax: f64) -> usize {
    TRIAXIALITY_EDGES
        .iter()
        .position(|&e| triax < e)
        .unwrap_or(TRIAXIALITY_EDGES.len())
}

/// Runs `impacts` more impacts of `sample` and returns each impact's budget. The observer reads
/// the world after every step and charges each particle's growth of ε_p and D since the last
/// step to the triaxiality it has now; the sample goes on bit for bit as without it.
pub fn budget(
    sample: &mut Sample,
    impacts: u32,
    mut progress: impl FnMut(&BudgetRow),
) -> Result<Vec<BudgetRow>, SampleError> {
    let mut rows = Vec::new();
    for _ in 0..impacts {
        let surface = sample.surface();
        let size = surface.id.iter().max().map_or(0, |&m| m as usize + 1);
        let mut seen = vec![Seen::default(); size];
        // The fixed boundary layers neither strain nor leave.
        for i in (0..surface.len()).filter(|&i| surface.flags[i] & KINEMATIC == 0) {
            seen[surface.id[i] as usize] = Seen {
                start_damage: surface.damage[i],
                start_eps_p: surface.eps_p[i],
                eps_p: surface.eps_p[i],
                damage: surface.damage[i],
                mass: surface.mass[i],
                bin: bin_of(0.0),
                failed: false,
                present: true,
                stamp: 0,
            };
        }
        let mut present = seen.iter().filter(|s| s.present).count();
        let mut step = 0u64;
        let stock: f64 = seen.iter().map(|s| s.mass * s.damage).sum();
        let mut tally = Tally::default();
        let mut removed = [0.0; 4];
        let mut failed = 0u64;
        let mut observe = |w: &World| {
            let p = w.particles();
            let pressure = w.pressures();
            step += 1;
            let mut found = 0;
            for (i, &pr) in pressure.iter().enumerate() {
                if p.body[i] as usize != SURFACE_BODY || p.flags[i] & KINEMATIC != 0 {
                    continue;
                }
                let id = p.id[i] as usize;
                let Some(s) = seen.get_mut(id) else { continue };
                s.stamp = step;
                found += 1;
                let triax = triaxiality(pr, von_mises(&p.sdev[i]));
                let bin = bin_of(triax);
                let (de, dd) = (p.eps_p[i] - s.eps_p, p.damage[i] - s.damage);
                tally.plastic[bin] += s.mass * de;
                tally.damage[bin] += s.mass * dd;
                tally.plastic_triax += s.mass * de * triax;
                s.eps_p = p.eps_p[i];
                s.damage = p.damage[i];
                s.bin = bin;
            }
            // A particle that failed inside this step left the world at D = 1: its last step's
            // growth to 1 is charged to the state it was last seen in. Fragments detached after
            // the grain has left (no failure counted) keep the damage they had.
            let now = w.bodies()[SURFACE_BODY].removed_particles;
            let to_one = now > failed;
            failed = now;
            if found == present {
                return; // nobody left in this step
            }
            present = found;
            for s in seen.iter_mut() {
                if s.present && s.stamp != step {
                    removed[quarter(s.start_damage)] += s.mass;
                    if to_one {
                        tally.damage[s.bin] += s.mass * (1.0 - s.damage).max(0.0);
                        s.failed = true;
                    }
                    s.present = false;
                }
            }
        };
        let r = sample
            .run_next_observed(&|| false, Some(&mut observe))?
            .clone();
        // Fragments torn off at the impact's last check leave after the last step is observed.
        let mut kept = vec![false; size];
        for &id in &sample.surface().id {
            if let Some(k) = kept.get_mut(id as usize) {
                *k = true;
            }
        }
        for (s, _) in seen.iter().zip(&kept).filter(|(s, k)| s.present && !**k) {
            removed[quarter(s.start_damage)] += s.mass;
        }
        let plastic: f64 = tally.plastic.iter().sum();
        // A particle's last seen state, or D = 1 for one that failed.
        let max_of = |f: &dyn Fn(&Seen) -> f64| seen.iter().map(f).fold(0.0, f64::max);
        let max_plastic_increment = max_of(&|s| s.eps_p - s.start_eps_p);
        let max_damage_increment = max_of(&|s| {
            if s.failed {
                1.0 - s.start_damage
            } else {
                s.damage - s.start_damage
            }
        });
        let row = BudgetRow {
            angle_deg: sample.params().angle_deg,
            seed: sample.seed(),
            impact: r.impact,
            grain_mass_kg: r.grain_mass_kg,
            damage_stock_kg: stock,
            mass_loss_kg: r.mass_loss_kg,
            plastic_kg: plastic,
            damage_kg: tally.damage.iter().sum(),
            mean_triaxiality: if plastic > 0.0 {
                tally.plastic_triax / plastic
            } else {
                0.0
            },
            max_plastic_increment,
            max_damage_increment,
            plastic_by_triaxiality_kg: tally.plastic,
            damage_by_triaxiality_kg: tally.damage,
            removed_by_start_damage_kg: removed,
        };
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// One angle's budget over its rows, each per unit grain mass (mg/g for the masses).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleBudget {
    /// Impact angle (degrees).
    pub angle_deg: f64,
    /// Impacts summed.
    pub impacts: usize,
    /// Removed mass per grain mass (mg/g).
    pub mass_loss: Stats,
    /// Σ m Δε_p per grain mass (mg/g): deformation.
    pub plastic: Stats,
    /// Σ m ΔD per grain mass (mg/g): the steady-state erosion the impacts pay for.
    pub damage: Stats,
    /// Σ m ΔD / Σ m Δε_p over the angle's impacts (the mean 1/ε_f of the straining).
    pub damage_per_strain: f64,
    /// Mean triaxiality of the straining.
    pub mean_triaxiality: f64,
    /// Share of Σ m ΔD in each triaxiality bin.
    pub damage_share_by_triaxiality: [f64; BINS],
    /// Share of the removed mass in each quarter of its damage at the impact's start.
    pub removed_share_by_start_damage: [f64; 4],
}

/// Groups `rows` by angle (ascending) into per-impact means with standard errors.
pub fn by_angle(rows: &[BudgetRow]) -> Vec<AngleBudget> {
    let mut angles: Vec<f64> = rows.iter().map(|r| r.angle_deg).collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    angles
        .into_iter()
        .filter_map(|a| {
            let rs: Vec<&BudgetRow> = rows.iter().filter(|r| r.angle_deg == a).collect();
            let per = |f: &dyn Fn(&BudgetRow) -> f64| -> Option<Stats> {
                stats(
                    &rs.iter()
                        .map(|r| 1e3 * f(r) / r.grain_mass_kg)
                        .collect::<Vec<_>>(),
                )
            };
            let plastic: f64 = rs.iter().map(|r| r.plastic_kg).sum();
            let damage: f64 = rs.iter().map(|r| r.damage_kg).sum();
            let mut share = [0.0; BINS];
            for r in &rs {
                for (s, d) in share.iter_mut().zip(r.damage_by_triaxiality_kg) {
                    *s += d;
                }
            }
            if damage > 0.0 {
                share.iter_mut().for_each(|s| *s /= damage);
            }
            let triax: f64 = rs.iter().map(|r| r.mean_triaxiality * r.plastic_kg).sum();
            let mut cut = [0.0; 4];
            for r in &rs {
                for (c, m) in cut.iter_mut().zip(r.removed_by_start_damage_kg) {
                    *c += m;
                }
            }
            let removed: f64 = cut.iter().sum();
            if removed > 0.0 {
                cut.iter_mut().for_each(|c| *c /= removed);
            }
            Some(AngleBudget {
                angle_deg: a,
                impacts: rs.len(),
                mass_loss: per(&|r| r.mass_loss_kg)?,
                plastic: per(&|r| r.plastic_kg)?,
                damage: per(&|r| r.damage_kg)?,
                damage_per_strain: if plastic > 0.0 { damage / plastic } else { 0.0 },
                mean_triaxiality: if plastic > 0.0 { triax / plastic } else { 0.0 },
                damage_share_by_triaxiality: share,
                removed_share_by_start_damage: cut,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::scene;

    #[test]
    fn triaxiality_bins_split_at_their_edges() {
        assert_eq!(bin_of(-1.0), 0);
        assert_eq!(bin_of(-0.2), 1);
        assert_eq!(bin_of(0.0), 2);
        assert_eq!(bin_of(0.5), 3);
    }

    #[test]
    fn the_budget_adds_up_and_leaves_the_sample_as_it_was() {
        let params = scene(45.0, 25e-6);
        let mut plain = Sample::new(params.clone(), 4).unwrap();
        let mut watched = Sample::new(params, 4).unwrap();
        for _ in 0..2 {
            plain.run_next().unwrap();
        }
        let rows = budget(&mut watched, 2, |_| {}).unwrap();
        // The observer reads only: the same records and the same surface, bit for bit.
        assert_eq!(plain.records(), watched.records());
        assert_eq!(plain.surface().eps_p, watched.surface().eps_p);
        let surface = watched.surface();
        let total_eps: f64 = surface
            .mass
            .iter()
            .zip(&surface.eps_p)
            .map(|(m, e)| m * e)
            .sum();
        let first: f64 = rows.iter().map(|r| r.plastic_kg).sum();
        // A fresh surface starts at zero strain, so the survivors hold what was charged step by
        // step (to rounding over the steps), less what leaving particles took with them.
        assert!(first > 0.0, "a 45° impact deforms the surface");
        if rows.iter().all(|r| r.mass_loss_kg == 0.0) {
            assert!(
                (total_eps - first).abs() <= 1e-9 * first,
                "{total_eps} vs {first}"
            );
        } else {
            assert!(total_eps <= first * (1.0 + 1e-9), "{total_eps} > {first}");
        }
        for (r, rec) in rows.iter().zip(watched.records()) {
            // The record's damage added, from the stocks before and after, is what the observer
            // charged step by step.
            let added = rec.outcome.damage_added_kg.expect("new records carry it");
            assert!(
                (added - r.damage_kg).abs() <= 1e-9 * r.damage_kg.abs().max(1e-12),
                "{added} vs {}",
                r.damage_kg
            );
            let bins: f64 = r.plastic_by_triaxiality_kg.iter().sum();
            assert!((bins - r.plastic_kg).abs() <= 1e-12 * r.plastic_kg.abs());
            assert!(r.damage_kg >= 0.0 && r.plastic_kg >= 0.0);
            assert!((-3.0..3.0).contains(&r.mean_triaxiality));
        }
        let a = by_angle(&rows);
        assert_eq!(a.len(), 1);
        assert_eq!(a[0].impacts, 2);
        let shares: f64 = a[0].damage_share_by_triaxiality.iter().sum();
        assert!(a[0].damage.mean == 0.0 || (shares - 1.0).abs() < 1e-9);
        for r in &rows {
            // Everything removed was seen leaving: the removed bins hold the impact's loss.
            let gone: f64 = r.removed_by_start_damage_kg.iter().sum();
            assert!((gone - r.mass_loss_kg).abs() <= 1e-9 * r.mass_loss_kg.max(1e-30));
        }
    }
}
