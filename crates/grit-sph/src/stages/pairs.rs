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
    let wide = lanes_pay();
    row_blocks(half, &hi.start)
        .into_par_iter()
        .zip(row_blocks(flags, &hi.start))
        .flat_map_iter(|(rows, bits)| rows.rows().zip(bits.rows()))
        .for_each(|((i, row_out), (_, bits))| {
            let xi = p.pos[i];
            let u = hi.upper[i] as usize;
            let js = hi.upper_of(nl, i);
            let refs = &nl.near_ref[u..u + js.len()];
            let row = Row {
                xi,
                pos: &p.pos,
                js,
                refs,
                k,
                r2max,
            };
            if wide {
                row.fill_wide(row_out, bits);
            } else {
                row.fill(row_out, bits);
            }
        });
}

/// Whether this CPU has 256-bit vectors (AVX2), on which a row's pairs evaluated four at a time
/// pay (0.957x the reference impact's one-thread wall); on SSE2 alone they cost more than the
/// branch on the support they save (1.025x), so such a CPU keeps the pair-by-pair loop.
pub(crate) fn lanes_pay() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The upper half of particle i's neighbour row: its partners j > i and their reference flags.
#[derive(Clone, Copy)]
struct Row<'a> {
    xi: Vector,
    pos: &'a [Vector],
    js: &'a [u32],
    refs: &'a [bool],
    k: &'a Kernel,
    r2max: f64,
}

impl Row<'_> {
    /// Pair by pair, skipping the skin's pairs beyond the support.
    #[inline(always)]
    fn fill(self, out: &mut [HalfPair], bits: &mut [u8]) {
        self.fill_from(0, out, bits);
    }

    /// Pairs `from..` one by one (`one_pair`).
    #[inline(always)]
    fn fill_from(self, from: usize, out: &mut [HalfPair], bits: &mut [u8]) {
        let Row {
            xi,
            pos,
            js,
            refs,
            k,
            r2max,
        } = self;
        for (((out, bit), &j), &near_ref) in out[from..]
            .iter_mut()
            .zip(bits[from..].iter_mut())
            .zip(&js[from..])
            .zip(&refs[from..])
        {
            let (pair, b) = one_pair(xi, pos[j as usize], near_ref, k, r2max);
            if let Some(pair) = pair {
                *out = pair;
            }
            *bit = b;
        }
    }

    /// Four pairs at a time with no branch, then the last one to three pair by pair: the
    /// kernel's powers and the four square roots pack into vector instructions, and the skin's
    /// pairs cost no misprediction. Each lane's arithmetic is the single pair's, so the bits
    /// are `fill`'s.
    #[inline(always)]
    fn fill_lanes(self, out: &mut [HalfPair], bits: &mut [u8]) {
        let mut at = 0;
        while at + LANES <= self.js.len() {
            let lanes = PairLanes::new(
                self.xi,
                self.pos,
                &self.js[at..at + LANES],
                self.k,
                self.r2max,
            );
            lanes.store(&self.refs[at..at + LANES], &mut out[at..], &mut bits[at..]);
            at += LANES;
        }
        self.fill_from(at, out, bits);
    }

    /// `fill_lanes` compiled for AVX2 (and no FMA, so every operation rounds as in `fill`),
    /// where `lanes_pay` found it.
    #[inline(always)]
    fn fill_wide(self, out: &mut [HalfPair], bits: &mut [u8]) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `fill_half_pairs` takes this path only where `lanes_pay` detected AVX2.
        unsafe {
            fill_lanes_avx2(self, out, bits)
        }
        #[cfg(not(target_arch = "x86_64"))]
        self.fill_lanes(out, bits)
    }
}

/// `Row::fill_lanes` with AVX2's 256-bit registers, whatever the build's target CPU.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn fill_lanes_avx2(row: Row<'_>, out: &mut [HalfPair], bits: &mut [u8]) {
    row.fill_lanes(out, bits)
}

/// Pair (i, j) and its flags; out of the support, no pair and flags 0.
#[inline(always)]
fn one_pair(
    xi: Vector,
    xj: Vector,
    near_ref: bool,
    k: &Kernel,
    r2max: f64,
) -> (Option<HalfPair>, u8) {
    let xij = xi - xj;
    let r2 = xij.norm_squared();
    if r2 >= r2max {
        return (None, 0);
    }
    let r = r2.sqrt();
    let (w, dw) = k.w_dw(r);
    let dw_r = if r > 0.0 { dw / r } else { 0.0 };
    (
        Some(HalfPair { xij, w, dw_r }),
        pair_flags(w, dw, r, near_ref),
    )
}

/// The flags of a pair inside the support: used unless its kernel and gradient both vanish,
/// near its reference partner, apart (r > 0).
#[inline(always)]
fn pair_flags(w: f64, dw: f64, r: f64, near_ref: bool) -> u8 {
    let used = if w == 0.0 && dw == 0.0 { 0 } else { USED };
    used | if near_ref { NEAR_REF } else { 0 } | if r > 0.0 { APART } else { 0 }
}

/// Pairs `fill_half_pairs` evaluates together.
const LANES: usize = 4;

/// `LANES` pairs of one row, each evaluated by the single pair's operations.
struct PairLanes {
    xij: [Vector; LANES],
    r2: [f64; LANES],
    r: [f64; LANES],
    w: [f64; LANES],
    dw: [f64; LANES],
    dw_r: [f64; LANES],
    inside: [bool; LANES],
}

impl PairLanes {
    #[inline(always)]
    fn new(xi: Vector, pos: &[Vector], js: &[u32], k: &Kernel, r2max: f64) -> Self {
        let mut l = PairLanes {
            xij: [Vector::zeros(); LANES],
            r2: [0.0; LANES],
            r: [0.0; LANES],
            w: [0.0; LANES],
            dw: [0.0; LANES],
            dw_r: [0.0; LANES],
            inside: [false; LANES],
        };
        for (x, &j) in l.xij.iter_mut().zip(js) {
            *x = xi - pos[j as usize];
        }
        for n in 0..LANES {
            l.r2[n] = l.xij[n].norm_squared();
            l.inside[n] = l.r2[n] < r2max;
        }
        for n in 0..LANES {
            l.r[n] = l.r2[n].sqrt();
        }
        (l.w, l.dw) = k.w_dw_lanes(l.r);
        for n in 0..LANES {
            // A pair out of the support gets W = dW/dr = 0 and, like a coincident one, no
            // quotient; its flags say it is unused.
            let q = l.dw[n] / if l.r[n] > 0.0 { l.r[n] } else { 1.0 };
            l.dw_r[n] = if l.r[n] > 0.0 { q } else { 0.0 };
        }
        l
    }

    /// Writes the pairs and their flags; a pair out of the support is written too (with
    /// W = dW/dr = 0) and flagged 0, so no reader looks at it.
    #[inline(always)]
    fn store(&self, near_ref: &[bool], out: &mut [HalfPair], bits: &mut [u8]) {
        for n in 0..LANES {
            out[n] = HalfPair {
                xij: self.xij[n],
                w: self.w[n],
                dw_r: self.dw_r[n],
            };
            bits[n] = if self.inside[n] {
                pair_flags(self.w[n], self.dw[n], self.r[n], near_ref[n])
            } else {
                0
            };
        }
    }
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

    /// Uniform numbers in [0, 1) from a xorshift generator: the same rows on every machine.
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The lanes must give each pair the single pair's bits: in the support, on its edge,
    /// beyond it and coincident, for every kernel.
    #[test]
    fn pairs_evaluated_four_at_a_time_have_the_single_pairs_bits() {
        use crate::kernel::KernelKind;
        let mut next = uniform(0x9e3779b97f4a7c15);
        let mut checked = [0usize; 3];
        for kind in [
            KernelKind::Quintic,
            KernelKind::WendlandC2,
            KernelKind::CubicSpline,
        ] {
            let k = Kernel::new(kind, 1.3e-5);
            let r2max = k.radius() * k.radius();
            for _ in 0..20_000 {
                let xi = Vector::new(next() * 1e-3, next() * 1e-3);
                let pos: Vec<Vector> = (0..LANES)
                    .map(|_| match (next() * 8.0) as u32 {
                        0 => xi,
                        1 => xi + Vector::new(k.radius(), 0.0),
                        _ => {
                            let (r, t) = (next() * 1.3 * k.radius(), next() * 6.3);
                            xi + Vector::new(r * t.cos(), r * t.sin())
                        }
                    })
                    .collect();
                let js: Vec<u32> = (0..LANES as u32).collect();
                let refs: Vec<bool> = (0..LANES).map(|_| next() < 0.5).collect();
                let mut out = vec![HalfPair::default(); LANES];
                let mut bits = vec![0xffu8; LANES];
                PairLanes::new(xi, &pos, &js, &k, r2max).store(&refs, &mut out, &mut bits);
                for n in 0..LANES {
                    let (pair, b) = one_pair(xi, pos[n], refs[n], &k, r2max);
                    assert_eq!(bits[n], b, "{kind:?} lane {n}");
                    let Some(pair) = pair else {
                        checked[0] += 1;
                        continue;
                    };
                    let of = |p: &HalfPair| [p.xij.x, p.xij.y, p.w, p.dw_r].map(f64::to_bits);
                    assert_eq!(of(&out[n]), of(&pair), "{kind:?} lane {n}");
                    checked[if b & APART == 0 { 1 } else { 2 }] += 1;
                }
            }
        }
        // Pairs beyond the support, coincident ones and the rest were all compared.
        assert!(checked.iter().all(|&c| c > 100), "{checked:?}");
    }

    /// A row filled four pairs at a time, portably and with AVX2 where this CPU has it, must
    /// have the pair-by-pair loop's bits: whichever path a worker's CPU takes, the same pairs.
    #[test]
    fn every_row_fill_has_the_pair_by_pair_bits() {
        let mut next = uniform(0x2545f4914f6cdd1d);
        let k = Kernel::new(crate::kernel::KernelKind::Quintic, 9.4e-6);
        let r2max = k.radius() * k.radius();
        let mut compared = 0;
        for len in 0..40usize {
            for _ in 0..50 {
                let xi = Vector::new(next() * 1e-3, next() * 1e-3);
                let pos: Vec<Vector> = std::iter::once(xi)
                    .chain((0..len).map(|_| {
                        let (r, t) = (next() * 1.2 * k.radius(), next() * 6.3);
                        xi + Vector::new(r * t.cos(), r * t.sin())
                    }))
                    .collect();
                let js: Vec<u32> = (0..len as u32).map(|j| j + 1).collect();
                let refs: Vec<bool> = (0..len).map(|_| next() < 0.5).collect();
                let row = Row {
                    xi,
                    pos: &pos,
                    js: &js,
                    refs: &refs,
                    k: &k,
                    r2max,
                };
                let fill = |f: &dyn Fn(&mut [HalfPair], &mut [u8])| {
                    let (mut out, mut bits) = (vec![HalfPair::default(); len], vec![0xffu8; len]);
                    f(&mut out, &mut bits);
                    let used = |n: usize| bits[n] != 0;
                    let pairs: Vec<[u64; 4]> = (0..len)
                        .filter(|&n| used(n))
                        .map(|n| {
                            [out[n].xij.x, out[n].xij.y, out[n].w, out[n].dw_r].map(f64::to_bits)
                        })
                        .collect();
                    (bits, pairs)
                };
                let want = fill(&|o, b| row.fill(o, b));
                assert_eq!(fill(&|o, b| row.fill_lanes(o, b)), want, "row of {len}");
                if lanes_pay() {
                    assert_eq!(
                        fill(&|o, b| row.fill_wide(o, b)),
                        want,
                        "row of {len}, AVX2"
                    );
                }
                compared += want.1.len();
            }
        }
        assert!(compared > 10_000, "{compared} pairs");
    }

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
