//! The same-body pairs of a step, each evaluated once (`neighbours::HalfIndex`): the separation,
//! the kernel W and dW/dr (seed eq. 4) of pair (i, j), i < j, seen from i. Particle j reads the
//! same values turned round: x_ji = −x_ij and e_ji = −e_ij exactly, and W, dW/dr and r do not
//! depend on the side, so each particle's sums get bitwise the terms they would from its own
//! evaluation of the pair.

use rayon::prelude::*;

use super::ParTasks;
use crate::kernel::Kernel;
use crate::math::Vector;
use crate::neighbours::{HalfIndex, NeighbourLists};
use crate::particles::Particles;

/// One same-body pair (i, j), i < j, as the kernel sums leave it for the forces: the quotients
/// dW/dr / r and x_ij / r are taken once here, so no later stage divides by r again (both are 0
/// for coincident particles, which every sum skips).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct HalfPair {
    /// x_ij = x_i − x_j.
    pub xij: Vector,
    /// Unit vector x_ij / r.
    pub e: Vector,
    pub r: f64,
    pub w: f64,
    /// dW/dr / r: the kernel gradient is x_ij times this.
    pub dw_r: f64,
    /// Reference positions within the kernel support (`NeighbourLists::near_ref`).
    pub near_ref: bool,
    /// Inside the kernel support with W or dW/dr non-zero: the lists reach a skin beyond the
    /// support, and the pairs out there would add exact zeros.
    pub used: bool,
}

impl HalfPair {
    /// The pair seen from its higher-index particle when `flip`: x_ij and e_ij change sign.
    #[inline]
    pub fn seen(mut self, flip: bool) -> HalfPair {
        if flip {
            self.xij = -self.xij;
            self.e = -self.e;
        }
        self
    }
}

/// A used pair in one particle's row: its partner and the pair's id; the pair is seen turned
/// round when the partner's index is the lower.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Side {
    /// Index of the neighbour, 32 bits like the lists.
    pub j: u32,
    /// Id of the pair (`HalfIndex`).
    pub id: u32,
}

/// The same-body pairs of this step: each pair's values once, by id, and each particle's used
/// pairs in its row's order (first `count[i]` entries of its slice of the neighbour rows).
/// Filled by the kernel sums, read by the forces.
#[derive(Debug, Clone, Default)]
pub(crate) struct PairCache {
    /// Pairs by id.
    pub half: Vec<HalfPair>,
    /// Used pairs, laid out like the neighbour rows.
    pub sides: Vec<Side>,
    /// Pairs used in each particle's row.
    pub count: Vec<u32>,
}

impl PairCache {
    /// The used same-body pairs of particle `i` (filled by the kernel sums this step).
    #[inline]
    pub fn of<'a>(&'a self, nl: &NeighbourLists, i: usize) -> &'a [Side] {
        let s = nl.start[i] as usize;
        &self.sides[s..s + self.count[i] as usize]
    }
}

/// `buf` cut into one mutable slice per row, row i of length `start[i + 1] − start[i]`, so the
/// rows fill in parallel, each by its own owner. `buf` grows to fit and is never cleared: every
/// row is written before it is read (a memset per step otherwise).
pub(crate) fn rows_mut<'a, T: Default + Clone>(
    buf: &'a mut Vec<T>,
    start: &[u32],
) -> Vec<&'a mut [T]> {
    let total = start.last().map_or(0, |&s| s as usize);
    if buf.len() < total {
        buf.resize(total, T::default());
    }
    let mut rows = Vec::with_capacity(start.len().saturating_sub(1));
    let mut rest = buf.as_mut_slice();
    for w in start.windows(2) {
        let (row, tail) = rest.split_at_mut((w[1] - w[0]) as usize);
        rows.push(row);
        rest = tail;
    }
    rows
}

/// Evaluates every same-body pair once into `half`, by id.
pub(crate) fn fill_half_pairs(
    p: &Particles,
    nl: &NeighbourLists,
    hi: &HalfIndex,
    k: &Kernel,
    half: &mut Vec<HalfPair>,
) {
    if hi.start.last().is_none_or(|&s| s == 0) {
        return;
    }
    let r2max = k.radius() * k.radius();
    rows_mut(half, &hi.start)
        .into_par_iter()
        .par_tasks()
        .enumerate()
        .for_each(|(i, row)| {
            let xi = p.pos[i];
            let u = hi.upper[i] as usize;
            let js = hi.upper_of(nl, i);
            for ((out, &j), &near_ref) in row.iter_mut().zip(js).zip(&nl.near_ref[u..]) {
                let xij = xi - p.pos[j as usize];
                let r2 = xij.norm_squared();
                if r2 >= r2max {
                    out.used = false;
                    continue;
                }
                let r = r2.sqrt();
                let (w, dw) = k.w_dw(r);
                let (mut dw_r, mut e) = (0.0, Vector::zeros());
                if r > 0.0 {
                    dw_r = dw / r;
                    e = xij / r;
                }
                *out = HalfPair {
                    xij,
                    e,
                    r,
                    w,
                    dw_r,
                    near_ref,
                    used: !(w == 0.0 && dw == 0.0),
                };
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_pair_fills_one_cache_line() {
        assert_eq!(std::mem::size_of::<HalfPair>(), 64);
    }

    #[test]
    fn a_pair_turned_round_is_the_pair_evaluated_from_the_other_end() {
        let k = Kernel::new(crate::kernel::KernelKind::Quintic, 1.3);
        let (a, b) = (
            Vector::new(0.1, -2.7),
            Vector::new(1.23456789, -1.987654321),
        );
        let eval = |xi: Vector, xj: Vector| {
            let xij = xi - xj;
            let r = xij.norm_squared().sqrt();
            let (w, dw) = k.w_dw(r);
            (xij, xij / r, r, w, dw / r)
        };
        let (xij, e, r, w, dw_r) = eval(a, b);
        let turned = HalfPair {
            xij,
            e,
            r,
            w,
            dw_r,
            near_ref: true,
            used: true,
        }
        .seen(true);
        let (xji, eji, rji, wji, dw_rji) = eval(b, a);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&[turned.xij.x, turned.xij.y, turned.e.x, turned.e.y]),
            bits(&[xji.x, xji.y, eji.x, eji.y])
        );
        assert_eq!(
            bits(&[turned.r, turned.w, turned.dw_r]),
            bits(&[rji, wji, dw_rji])
        );
    }
}
