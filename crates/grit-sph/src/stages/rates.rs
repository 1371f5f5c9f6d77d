//! The rates: the velocity gradient with the corrected kernel gradient (eqs. 15 and 7).

use rayon::prelude::*;

use super::{KernelSums, ParTasks, SphView, MIN_SUPPORT_NEIGHBOURS};
use crate::math::{outer, Matrix};
use crate::neighbours::{Pair, PairCache};

/// Velocity gradient ∇v_i of every particle (eq. 15, corrected by L_i of eq. 7); zero for rigid
/// particles and fragments.
pub(crate) fn velocity_gradients(
    s: SphView<'_>,
    cache: &PairCache,
    sums: &KernelSums,
) -> Vec<Matrix> {
    let SphView { p, nl, bc, .. } = s;
    let lc = &sums.lcorr;
    (0..p.len())
        .into_par_iter()
        .par_tasks()
        .map(|i| {
            let bi = p.body[i];
            if !bc[bi as usize].deformable || cache.count[i] < MIN_SUPPORT_NEIGHBOURS {
                return Matrix::zeros();
            }
            let vi = p.vel[i];
            let mut gv = Matrix::zeros();
            for &Pair { j, xij, r, dw, .. } in cache.of(nl, i) {
                if r == 0.0 {
                    continue;
                }
                gv += outer(p.vel[j] - vi, xij * (dw / r)) * sums.vol[j];
            }
            gv * lc[i].transpose()
        })
        .collect()
}
