//! The same-body pairs of a step, each evaluated once (`neighbours::HalfIndex`): the separation,
//! the kernel W and dW/dr (seed eq. 4) of pair (i, j), i < j, seen from i. Particle j reads the
//! same values turned round: x_ji = −x_ij exactly (and so e_ji = −e_ij where the forces take
//! it again), and W, dW/dr and r do not depend on the side, so each particle's sums get bitwise
//! the terms they would from its own evaluation of the pair.

use rayon::prelude::*;

use crate::kernel::Kernel;
use crate::math::Vector;
use crate::neighbours::{HalfIndex, NeighbourLists};
use crate::particles::Particles;

/// One same-body pair (i, j), i < j, as the kernel sums leave it for the forces, in 32 bytes
/// (two to a cache line; its flags are apart, in `PairCache::flags`): the quotient dW/dr / r is
/// taken once here (0 for coincident particles, which every sum skips); r and x_ij / r are
/// taken again where the hourglass force needs them, by the same operations, so to the same
/// bits.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct HalfPair {
    /// x_ij = x_i − x_j.
    pub xij: Vector,
    pub w: f64,
    /// dW/dr / r: the kernel gradient is x_ij times this.
    pub dw_r: f64,
}

/// Inside the kernel support with W or dW/dr non-zero: the lists reach a skin beyond the
/// support, and the pairs out there would add exact zeros.
pub(crate) const USED: u8 = 1;
/// Reference positions within the kernel support (`NeighbourLists::near_ref`).
pub(crate) const NEAR_REF: u8 = 2;
/// r > 0: the particles are not coincident.
pub(crate) const APART: u8 = 4;

impl HalfPair {
    /// The pair seen from its higher-index particle when `flip`: x_ij changes sign.
    #[inline]
    pub fn seen(mut self, flip: bool) -> HalfPair {
        if flip {
            self.xij = -self.xij;
        }
        self
    }

    /// The distance r, as `fill_half_pairs` took it.
    #[inline]
    pub fn r(&self) -> f64 {
        self.xij.norm_squared().sqrt()
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
    /// Each pair's `USED`, `NEAR_REF` and `APART` bits, by id: a gather reads one byte to skip
    /// a pair out of the support instead of its record.
    pub flags: Vec<u8>,
    /// Used pairs, laid out like the neighbour rows; written by the kernel sums' gather (two or
    /// more threads) for the forces' gather, left as they are on one thread, where both scatter.
    pub sides: Vec<Side>,
    /// Pairs used in each particle's row.
    pub count: Vec<u32>,
}

impl PairCache {
    /// The used same-body pairs of particle `i` (filled by the kernel sums this step on two or
    /// more threads).
    #[inline]
    pub fn of<'a>(&'a self, nl: &NeighbourLists, i: usize) -> &'a [Side] {
        let s = nl.start[i] as usize;
        &self.sides[s..s + self.count[i] as usize]
    }
}

/// Whether this step's pair loops scatter each half pair to both particles (one thread) rather
/// than gather each particle's row (two or more). The kernel sums and the forces must agree:
/// the kernel sums' scatter leaves `PairCache::sides` unwritten, and only the forces' gather
/// reads them.
pub(crate) fn scatter() -> bool {
    rayon::current_num_threads() == 1
}

/// `buf` cut into one mutable slice per row, row i of length `start[i + 1] − start[i]`, so the
/// rows fill in parallel, each by its own owner; `buf` grows as for `row_blocks`, whose blocks
/// it cuts on the calling thread (for the neighbour rebuild, where one serial pass per rebuild
/// costs nothing against the search).
pub(crate) fn rows_mut<'a, T: Default + Clone>(
    buf: &'a mut Vec<T>,
    start: &'a [u32],
) -> Vec<&'a mut [T]> {
    row_blocks(buf, start)
        .into_iter()
        .flat_map(|block| block.rows().map(|(_, row)| row))
        .collect()
}

/// Rows of the pair cache one task takes in the loops over its rows.
pub(crate) const ROWS_PER_BLOCK: usize = 64;

/// A block of `ROWS_PER_BLOCK` consecutive rows of a buffer laid out by `start` (row i is
/// `start[i]..start[i + 1]`): its first row and its entries. The task that takes it cuts the
/// rows itself (`rows`), so no serial pass over every row runs before the parallel loop (on a
/// virtual machine such a pass lets the idle worker fall asleep: docs/performance.md, "Why two
/// threads give 1.6").
pub(crate) struct RowBlock<'a, T> {
    first: usize,
    entries: &'a mut [T],
    start: &'a [u32],
}

impl<'a, T> RowBlock<'a, T> {
    /// The block's rows in order, with their indices.
    pub fn rows(self) -> impl Iterator<Item = (usize, &'a mut [T])> {
        let RowBlock {
            first,
            mut entries,
            start,
        } = self;
        let last = (first + ROWS_PER_BLOCK).min(start.len() - 1);
        (first..last).map(move |i| {
            let (row, rest) =
                std::mem::take(&mut entries).split_at_mut((start[i + 1] - start[i]) as usize);
            entries = rest;
            (i, row)
        })
    }
}

/// `buf` cut into blocks of `ROWS_PER_BLOCK` rows of `start`'s layout, as many as
/// `par_chunks_mut(ROWS_PER_BLOCK)` cuts a per-row array into. `buf` grows to fit and is never
/// cleared: every row is written before it is read.
pub(crate) fn row_blocks<'a, T: Default + Clone>(
    buf: &'a mut Vec<T>,
    start: &'a [u32],
) -> Vec<RowBlock<'a, T>> {
    let total = start.last().map_or(0, |&s| s as usize);
    if buf.len() < total {
        buf.resize(total, T::default());
    }
    let n = start.len().saturating_sub(1);
    let mut blocks = Vec::with_capacity(n.div_ceil(ROWS_PER_BLOCK));
    let mut rest = buf.as_mut_slice();
    for first in (0..n).step_by(ROWS_PER_BLOCK) {
        let last = (first + ROWS_PER_BLOCK).min(n);
        let (entries, tail) =
            std::mem::take(&mut rest).split_at_mut((start[last] - start[first]) as usize);
        rest = tail;
        blocks.push(RowBlock {
            first,
            entries,
            start,
        });
    }
    blocks
}

/// Evaluates every same-body pair once into `half`, and its bits into `flags`, by id.
pub(crate) fn fill_half_pairs(
    p: &Particles,
    nl: &NeighbourLists,
    hi: &HalfIndex,
    k: &Kernel,
    half: &mut Vec<HalfPair>,
    flags: &mut Vec<u8>,
) {
    if hi.start.last().is_none_or(|&s| s == 0) {
        return;
    }
    let r2max = k.radius() * k.radius();
    row_blocks(half, &hi.start)
        .into_par_iter()
        .zip(row_blocks(flags, &hi.start))
        .flat_map_iter(|(rows, bits)| rows.rows().zip(bits.rows()))
        .for_each(|((i, row), (_, bits))| {
            let xi = p.pos[i];
            let u = hi.upper[i] as usize;
            let js = hi.upper_of(nl, i);
            let each = row.iter_mut().zip(bits.iter_mut()).zip(js);
            for (((out, bit), &j), &near_ref) in each.zip(&nl.near_ref[u..]) {
                let xij = xi - p.pos[j as usize];
                let r2 = xij.norm_squared();
                if r2 >= r2max {
                    *bit = 0;
                    continue;
                }
                let r = r2.sqrt();
                let (w, dw) = k.w_dw(r);
                let dw_r = if r > 0.0 { dw / r } else { 0.0 };
                *out = HalfPair { xij, w, dw_r };
                *bit = if w == 0.0 && dw == 0.0 { 0 } else { USED }
                    | if near_ref { NEAR_REF } else { 0 }
                    | if r > 0.0 { APART } else { 0 };
            }
        });
}

/// The used same-body pairs of particle `i` this step, seen from `i`: (j, pair).
pub(crate) fn pairs_of<'a>(
    s: super::SphView<'a>,
    hi: &'a HalfIndex,
    cache: &'a PairCache,
    i: usize,
) -> impl Iterator<Item = (usize, HalfPair)> + 'a {
    let nl = s.nl;
    let ids = &hi.id[nl.start[i] as usize..];
    nl.of(i).iter().zip(ids).filter_map(move |(&j, &id)| {
        let bits = cache.flags[id as usize];
        (bits & (USED | APART) == USED | APART)
            .then(|| (j as usize, cache.half[id as usize].seen((j as usize) < i)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_half_pairs_fill_one_cache_line() {
        assert_eq!(std::mem::size_of::<HalfPair>(), 32);
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
        let (xij, _, r, w, dw_r) = eval(a, b);
        let pair = HalfPair { xij, w, dw_r };
        assert_eq!(pair.r().to_bits(), r.to_bits());
        let turned = pair.seen(true);
        let (xji, eji, rji, wji, dw_rji) = eval(b, a);
        let e = turned.xij / turned.r();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&[turned.xij.x, turned.xij.y, e.x, e.y]),
            bits(&[xji.x, xji.y, eji.x, eji.y])
        );
        assert_eq!(
            bits(&[turned.r(), turned.w, turned.dw_r]),
            bits(&[rji, wji, dw_rji])
        );
    }
}
