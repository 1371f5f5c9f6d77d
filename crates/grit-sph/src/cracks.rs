//! A rock target's damage as an output of the jet (AWJ paper Figs. 22–28; issue 37): which
//! target particles still hold to the rock, and the cracks in it (docs/jet.md#rock-targets).
//!
//! - **Held** ([`held`]): a particle joined to the target's fixed particles through a chain of
//!   particles each closer than the link to the next, where a fractured particle (D = 1) may
//!   pass the chain on only to fractured ones. Fractured rock carries no tension (eq. 40's cut
//!   at −T (1 − D)), so rubble can rest on the rock and stay in place but cannot hold an intact
//!   piece to it: the rest of the target is detached, the rock's mass loss.
//! - **Crack** ([`cracks`]): a connected set (links closer than the link) of held particles at
//!   D ≥ [`CRACK_DAMAGE`], at least [`MIN_CRACK_PARTICLES`] of them; its length is its extent
//!   along its principal axis plus one spacing (n Δx for a straight line of n particles).

use serde::{Deserialize, Serialize};

use crate::error::InputError;
use crate::math::Vector;

/// Damage from which a particle belongs to a crack: it has lost 90 % of its tensile strength
/// (eq. 40's cut at −T (1 − D)); JH-2 fractures in tension in one step, so cracks are mostly
/// at D = 1 and this threshold adds the nearly fractured particles around them.
pub const CRACK_DAMAGE: f64 = 0.9;

/// Fewest particles in a crack: a lone damaged particle is a damaged point, not a line.
pub const MIN_CRACK_PARTICLES: usize = 2;

/// A uniform grid of cells `link_m` wide over `positions`, for neighbour look-ups within
/// `link_m`; each cell lists its particles in index order, so every walk is deterministic.
struct Grid<'a> {
    positions: &'a [Vector],
    link_m: f64,
    cells: std::collections::HashMap<(i64, i64), Vec<usize>>,
}

impl<'a> Grid<'a> {
    fn new(positions: &'a [Vector], link_m: f64) -> Self {
        let mut cells: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
        for (i, p) in positions.iter().enumerate() {
            cells.entry(Self::cell(link_m, p)).or_default().push(i);
        }
        Grid {
            positions,
            link_m,
            cells,
        }
    }

    fn cell(link_m: f64, p: &Vector) -> (i64, i64) {
        ((p.x / link_m).floor() as i64, (p.y / link_m).floor() as i64)
    }

    /// Calls `f` with every particle closer than the link to particle `i` (itself included).
    fn near(&self, i: usize, mut f: impl FnMut(usize)) {
        let x = self.positions[i];
        let (cx, cy) = Self::cell(self.link_m, &x);
        let link2 = self.link_m * self.link_m;
        for dy in -1..=1 {
            for dx in -1..=1 {
                for &j in self.cells.get(&(cx + dx, cy + dy)).into_iter().flatten() {
                    if (self.positions[j] - x).norm_squared() < link2 {
                        f(j);
                    }
                }
            }
        }
    }
}

fn check(field: &str, n: usize, len: usize, link_m: f64) -> Result<(), InputError> {
    InputError::require_positive("cracks.link_m", link_m)?;
    if n != len {
        return Err(InputError::new(
            format!("cracks.{field}"),
            format!("has {n} entries for {len} positions"),
        ));
    }
    Ok(())
}

/// Which target particles still hold to the rock: reached from an `anchored` (fixed) particle
/// through links closer than `link_m`, where a particle that is not `intact` passes the chain
/// on only to particles that are not intact either (module doc). Anchors pass it on to all.
pub fn held(
    positions: &[Vector],
    anchored: &[bool],
    intact: &[bool],
    link_m: f64,
) -> Result<Vec<bool>, InputError> {
    check("anchored", anchored.len(), positions.len(), link_m)?;
    check("intact", intact.len(), positions.len(), link_m)?;
    let grid = Grid::new(positions, link_m);
    let mut joined = anchored.to_vec();
    let mut queue: std::collections::VecDeque<usize> =
        (0..positions.len()).filter(|&i| anchored[i]).collect();
    while let Some(i) = queue.pop_front() {
        let holds_all = intact[i] || anchored[i];
        grid.near(i, |j| {
            if !joined[j] && (holds_all || !intact[j]) {
                joined[j] = true;
                queue.push_back(j);
            }
        });
    }
    Ok(joined)
}

/// One crack: a connected set of damaged particles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crack {
    /// Its particles.
    pub particles: usize,
    /// Its extent along its principal axis plus one spacing (m).
    pub length_m: f64,
    /// The lowest y of its particles (m): its deepest tip under a jet coming down along −y.
    pub lowest_y_m: f64,
}

/// The cracks among `positions` (module doc): connected sets, through links closer than
/// `link_m`, of the particles marked `damaged`, at least [`MIN_CRACK_PARTICLES`] each, in the
/// order of their first particle. `spacing_m` is the particle spacing, a lone particle's length.
pub fn cracks(
    positions: &[Vector],
    damaged: &[bool],
    link_m: f64,
    spacing_m: f64,
) -> Result<Vec<Crack>, InputError> {
    check("damaged", damaged.len(), positions.len(), link_m)?;
    InputError::require_positive("cracks.spacing_m", spacing_m)?;
    let idx: Vec<usize> = (0..positions.len()).filter(|&i| damaged[i]).collect();
    let pts: Vec<Vector> = idx.iter().map(|&i| positions[i]).collect();
    let grid = Grid::new(&pts, link_m);
    let mut seen = vec![false; pts.len()];
    let mut out = Vec::new();
    for start in 0..pts.len() {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        let mut members = vec![start];
        let mut k = 0;
        while k < members.len() {
            grid.near(members[k], |j| {
                if !seen[j] {
                    seen[j] = true;
                    members.push(j);
                }
            });
            k += 1;
        }
        if members.len() >= MIN_CRACK_PARTICLES {
            let set: Vec<Vector> = members.iter().map(|&j| pts[j]).collect();
            out.push(Crack {
                particles: set.len(),
                length_m: principal_extent(&set) + spacing_m,
                lowest_y_m: set.iter().map(|p| p.y).fold(f64::INFINITY, f64::min),
            });
        }
    }
    Ok(out)
}

/// The extent of `points` along their principal axis (the covariance's major eigenvector):
/// max − min of the points' projections on it.
pub fn principal_extent(points: &[Vector]) -> f64 {
    let n = points.len() as f64;
    let mean = points.iter().fold(Vector::zeros(), |s, p| s + p) / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in points {
        let d = p - mean;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let axis = Vector::new(theta.cos(), theta.sin());
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let s = axis.dot(p);
            (lo.min(s), hi.max(s))
        });
    hi - lo
}

/// A rock target's damage at the end of a jet slice (docs/jet.md#rock-targets), beside its
/// crater sample: the AWJ paper's cracks and damage area (Figs. 22, 25, 28), measured.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RockDamage {
    /// Mass of the target's particles that no longer hold to the rock ([`held`]) but are still
    /// in the scene (kg/m); part of the slice's mass loss.
    pub detached_kg_m: f64,
    /// Particles of the target at D = 1, held or not.
    pub fractured_particles: usize,
    /// Cracks in the held target ([`cracks`]).
    pub crack_count: usize,
    /// Their lengths summed (m).
    pub crack_length_m: f64,
    /// How far the deepest crack tip lies below the crater's bottom (m), 0 when none does.
    pub crack_depth_below_crater_m: f64,
    /// Area of the held particles at D ≥ [`CRACK_DAMAGE`] in the 2D section, particles × Δx²
    /// (m²).
    pub damaged_area_m2: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: f64 = 1e-4;

    #[test]
    fn two_separate_lines_are_two_cracks_of_their_lengths() {
        // A 10 × 10 block; a vertical line of 6 damaged particles and a diagonal of 4, apart.
        let mut pos = Vec::new();
        let mut dmg = Vec::new();
        for j in 0..10 {
            for i in 0..10 {
                pos.push(Vector::new(i as f64 * S, -(j as f64) * S));
                let vertical = i == 2 && j < 6;
                let diagonal = (5..9).contains(&i) && j == i - 3;
                dmg.push(vertical || diagonal);
            }
        }
        let c = cracks(&pos, &dmg, 1.5 * S, S).unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].particles, 6);
        assert!((c[0].length_m - 6.0 * S).abs() < 1e-12);
        assert!((c[0].lowest_y_m + 5.0 * S).abs() < 1e-12);
        assert_eq!(c[1].particles, 4);
        assert!((c[1].length_m - (3.0 * 2f64.sqrt() * S + S)).abs() < 1e-12);
    }

    #[test]
    fn rubble_holds_rubble_but_not_an_intact_piece() {
        // anchor – intact – fractured – fractured – intact, one spacing apart; a far fractured.
        let pos: Vec<Vector> = [0.0, 1.0, 2.0, 3.0, 4.0, 9.0]
            .iter()
            .map(|&x| Vector::new(x * S, 0.0))
            .collect();
        let anchored = [true, false, false, false, false, false];
        let intact = [true, true, false, false, true, false];
        let h = held(&pos, &anchored, &intact, 1.5 * S).unwrap();
        assert_eq!(h, vec![true, true, true, true, false, false]);
        assert_eq!(
            held(&pos, &anchored[..2], &intact, S).unwrap_err().field,
            "cracks.anchored"
        );
    }
}
