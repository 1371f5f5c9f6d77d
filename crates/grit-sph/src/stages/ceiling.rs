//! The ceiling of a step's pair loops: the bare Shepard sum Γ_i = Σ_j V_j W_ij (eq. 9
//! denominator) over the pairs the step used, and nothing else. A benchmark times it beside the
//! full step to say how far the step is from the least any pair loop over the same list costs
//! (docs/performance.md, "The ceiling").

use super::pairs::{PairCache, USED};
use crate::kernel::Kernel;
use crate::neighbours::{HalfIndex, NeighbourLists};
use crate::particles::Particles;

/// What one bare kernel-sum pass did, so that a caller can keep it observable.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CeilingPass {
    /// Pair terms summed: every used same-body pair, seen from each of its two particles.
    pub pair_terms: u64,
    /// Σ_i Γ_i over the particles, the pass's result.
    pub sum: f64,
}

/// Σ_j V_j W(|x_i − x_j|) for every particle i over its used same-body pairs of the last step
/// (`cache`'s flags, in rows the kernel sums counted: a rigid body's are not), the kernel
/// evaluated per pair from the current positions, on the calling thread.
pub(crate) fn ceiling(
    p: &Particles,
    nl: &NeighbourLists,
    hi: &HalfIndex,
    cache: &PairCache,
    vol: &[f64],
    k: &Kernel,
) -> CeilingPass {
    let mut out = CeilingPass::default();
    for (i, &xi) in p.pos.iter().enumerate() {
        if cache.count[i] == 0 {
            continue;
        }
        let mut g = 0.0;
        let ids = &hi.id[nl.start[i] as usize..];
        for (&j, &id) in nl.of(i).iter().zip(ids) {
            if cache.flags[id as usize] & USED == 0 {
                continue;
            }
            let r = (xi - p.pos[j as usize]).norm();
            g += vol[j as usize] * k.w(r);
            out.pair_terms += 1;
        }
        out.sum += g;
    }
    out
}
