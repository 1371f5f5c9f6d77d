//! A rock target's measures (docs/jet.md#rock-targets): fractured rock stays in the world, so
//! the mass loss is what no longer holds to the rock (`cracks::held`), found on a clock of its
//! own ([`detach_every_s`]), and the cracks of the held rock are counted (`cracks::cracks`) at
//! each slice's end.

use grit_sph::cracks::{self, RockDamage, CRACK_DAMAGE};
use grit_sph::crater::{self, Crater, CraterOptions, CraterSample};
use grit_sph::{InputError, Vector, World};

/// Speed (m/s) at which a piece would cross one spacing between two detachment checks: above
/// the fastest jet the presets are run at (400 m/s), so a piece thrown off at the jet's speed
/// is seen at least once on its way out.
const DETACH_CHECK_SPEED_M_S: f64 = 1000.0;

/// Simulated time (s) between two detachment checks at spacing `spacing_m`: Δx over
/// [`DETACH_CHECK_SPEED_M_S`], 0.1 µs at Δx = 100 µm. A fixed clock, so how a run is cut into
/// slices does not change which passing separations are caught.
pub(super) fn detach_every_s(spacing_m: f64) -> f64 {
    spacing_m / DETACH_CHECK_SPEED_M_S
}

/// Rock body `target`'s particles now: their indices, positions, and which of them hold to the
/// rock (`cracks::held`).
struct Held {
    of_body: Vec<usize>,
    pos: Vec<Vector>,
    held: Vec<bool>,
}

fn held_now(w: &World, target: usize, link_m: f64) -> Result<Held, InputError> {
    let p = w.particles();
    let of_body = crater::body_particles(p, target as u32);
    let pos: Vec<_> = of_body.iter().map(|&i| p.pos[i]).collect();
    let fixed = crater::fixed_of(p, &of_body);
    let intact: Vec<bool> = of_body.iter().map(|&i| p.damage[i] < 1.0).collect();
    let held = cracks::held(&pos, &fixed, &intact, link_m)?;
    Ok(Held { of_body, pos, held })
}

/// Adds to `detached` (particle ids, sorted) the particles of rock body `target` that no
/// longer hold to the rock now. A piece once cut loose stays lost even if the flow lays it back
/// on the rock, so the loss never falls (a particle that then leaves the scene moves to the
/// outflow's mass).
pub(super) fn detach(
    w: &World,
    target: usize,
    spacing_m: f64,
    detached: &mut Vec<u32>,
) -> Result<(), InputError> {
    let Held { of_body, held, .. } =
        held_now(w, target, CraterOptions::for_spacing(spacing_m).link_m)?;
    let p = w.particles();
    detached.extend(
        of_body
            .iter()
            .zip(&held)
            .filter(|(_, &h)| !h)
            .map(|(&i, _)| p.id[i]),
    );
    detached.sort_unstable();
    detached.dedup();
    Ok(())
}

/// The crater sample, crater and damage of rock body `target` at the world's time: Cd and Cw
/// of the particles held now and not `detached`, the mass loss `gone_kg_m` (deleted and left
/// through the outflow) plus the `detached` particles still in the scene, and the cracks of the
/// held particles.
pub(super) fn measure(
    w: &World,
    target: usize,
    surface_y_m: f64,
    spacing_m: f64,
    gone_kg_m: f64,
    detached: &[u32],
) -> Result<(CraterSample, Crater, RockDamage), InputError> {
    let opts = CraterOptions::for_spacing(spacing_m);
    let p = w.particles();
    let Held {
        of_body,
        pos,
        mut held,
    } = held_now(w, target, opts.link_m)?;
    let mut detached_kg_m = 0.0;
    for (h, &i) in held.iter_mut().zip(&of_body) {
        if detached.binary_search(&p.id[i]).is_ok() {
            *h = false;
            detached_kg_m += p.mass[i];
        }
    }
    let (sample, c) = crater::sample(
        w.time(),
        p,
        target as u32,
        gone_kg_m + detached_kg_m,
        surface_y_m,
        opts,
        Some(&held),
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
        fractured_particles: of_body.iter().filter(|&&i| p.damage[i] >= 1.0).count(),
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
