//! A rock target's slice measures (docs/jet.md#rock-targets): fractured rock stays in the
//! world, so the mass loss is what no longer holds to the rock (`cracks::held`), and the cracks
//! of the held rock are counted (`cracks::cracks`).

use grit_sph::cracks::{self, RockDamage, CRACK_DAMAGE};
use grit_sph::crater::{self, Crater, CraterOptions, CraterSample};
use grit_sph::{InputError, World};

/// The crater sample, crater and damage of rock body `target` at the world's time: Cd and Cw
/// of the held particles, the mass loss `gone_kg_m` (deleted and left through the outflow)
/// plus the detached particles still in the scene, and the cracks of the held particles.
/// `detached` (particle ids, sorted) gains the particles found detached now and keeps the
/// earlier ones: a piece once cut loose is lost even if the flow lays it back on the rock, so
/// the loss never falls (a particle that then leaves the scene moves to `gone_kg_m`).
pub(super) fn measure(
    w: &World,
    target: usize,
    surface_y_m: f64,
    spacing_m: f64,
    gone_kg_m: f64,
    detached: &mut Vec<u32>,
) -> Result<(CraterSample, Crater, RockDamage), InputError> {
    let opts = CraterOptions::for_spacing(spacing_m);
    let p = w.particles();
    let of_body = crater::body_particles(p, target as u32);
    let pos: Vec<_> = of_body.iter().map(|&i| p.pos[i]).collect();
    let fixed = crater::fixed_of(p, &of_body);
    let intact: Vec<bool> = of_body.iter().map(|&i| p.damage[i] < 1.0).collect();
    let mut held = cracks::held(&pos, &fixed, &intact, opts.link_m)?;
    detached.extend(
        of_body
            .iter()
            .zip(&held)
            .filter(|(_, &h)| !h)
            .map(|(&i, _)| p.id[i]),
    );
    detached.sort_unstable();
    detached.dedup();
    let mut detached_kg_m = 0.0;
    for (h, &i) in held.iter_mut().zip(&of_body) {
        if detached.binary_search(&p.id[i]).is_ok() {
            *h = false;
            detached_kg_m += p.mass[i];
        }
    }
    let (sample, c) = crater::sample_kept(
        w.time(),
        p,
        target as u32,
        gone_kg_m + detached_kg_m,
        surface_y_m,
        opts,
        &held,
    )?;
    let damaged: Vec<bool> = of_body
        .iter()
        .zip(&held)
        .map(|(&i, &h)| h && p.damage[i] >= CRACK_DAMAGE)
        .collect();
    let found = cracks::cracks(&pos, &damaged, opts.link_m, spacing_m)?;
    let bottom_y = surface_y_m - c.depth_m;
    let lowest = found
        .iter()
        .map(|k| k.lowest_y_m)
        .fold(f64::INFINITY, f64::min);
    let damage = RockDamage {
        detached_kg_m,
        fractured_particles: intact.iter().filter(|&&i| !i).count(),
        crack_count: found.len(),
        crack_length_m: found.iter().fold(0.0, |sum, k| sum + k.length_m),
        crack_depth_below_crater_m: if lowest.is_finite() {
            (bottom_y - lowest).max(0.0)
        } else {
            0.0
        },
        damaged_area_m2: damaged.iter().filter(|&&d| d).count() as f64 * spacing_m * spacing_m,
    };
    Ok((sample, c, damage))
}
