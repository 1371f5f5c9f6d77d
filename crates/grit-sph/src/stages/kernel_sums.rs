//! The kernel sums: Shepard sums Γ_i = Σ V_j W_ij (eq. 9 denominator), Bonet–Lok correction
//! matrices L_i (eq. 8) and the rates, the velocity gradients with the corrected kernel gradient
//! (eqs. 15 and 7), in one pass over the pairs; and the same-body pair cache the forces read.

use rayon::prelude::*;

use super::{ParTasks, SphView, MIN_SUPPORT_NEIGHBOURS};
use crate::math::{outer, Matrix, Vector};
use crate::neighbours::{body_pairs, CachedPair, PairCache};

/// Per-particle results of the kernel sums, read by the later stages of the same step.
#[derive(Debug, Clone, Default)]
pub(crate) struct KernelSums {
    /// Particle volumes m/ρ at the kernel sums, computed once instead of once per pair; valid
    /// until the stress stage updates ρ.
    pub vol: Vec<f64>,
    /// Shepard sums Γ_i (eq. 9 denominator).
    pub shepard: Vec<f64>,
    /// Bonet–Lok correction matrices L_i (eq. 8).
    pub lcorr: Vec<Matrix>,
    /// Velocity gradients ∇v_i (eq. 15, corrected by L_i of eq. 7); zero for rigid particles and
    /// fragments.
    pub gradv: Vec<Matrix>,
}

/// One particle's kernel sums, before they are stored.
struct ParticleSums {
    shepard: f64,
    lcorr: Matrix,
    gradv: Matrix,
    pairs: u32,
}

/// Shepard sums Γ_i = Σ V_j W_ij (eq. 9 denominator), Bonet–Lok matrices L_i (eq. 8) and
/// velocity gradients (eqs. 15 and 7) into `sums`; every same-body pair inside the support into
/// `cache`. The velocity gradient of particle i needs only its own L_i, so it is summed in the
/// same pass, term by term in the same order as a separate pass would.
pub(crate) fn kernel_sums(s: SphView<'_>, cache: &mut PairCache, sums: &mut KernelSums) {
    let SphView { p, nl, k, bc } = s;
    let w0 = k.w(0.0);
    let n = p.len();
    super::volumes(p, &mut sums.vol);
    let vol = &sums.vol;
    let buf = &mut cache.pairs;
    // Rows are overwritten before they are read: grow, never clear (a memset per step).
    if buf.len() < nl.list.len() {
        buf.resize(nl.list.len(), CachedPair::default());
    }
    // One mutable slice per particle, so the rows fill in parallel, each by its own owner.
    let mut rows: Vec<&mut [CachedPair]> = Vec::with_capacity(n);
    let mut rest = buf.as_mut_slice();
    for i in 0..n {
        let (row, tail) = rest.split_at_mut(nl.of(i).len());
        rows.push(row);
        rest = tail;
    }
    let out: Vec<ParticleSums> = rows
        .into_par_iter()
        .par_tasks()
        .enumerate()
        .map(|(i, row)| {
            let bi = p.body[i];
            if !bc[bi as usize].deformable {
                return ParticleSums {
                    shepard: 1.0,
                    lcorr: Matrix::identity(),
                    gradv: Matrix::zeros(),
                    pairs: 0,
                };
            }
            let mut g = vol[i] * w0;
            let mut m = Matrix::zeros();
            let vi = p.vel[i];
            let mut gv = Matrix::zeros();
            let mut cnt = 0;
            for pair in body_pairs(p, nl, k, i) {
                // Listed within the skin but outside the support: contributes nothing.
                if pair.w == 0.0 && pair.dw == 0.0 {
                    continue;
                }
                let j = pair.j as usize;
                let vj = vol[j];
                g += vj * pair.w;
                let (mut dw_r, mut e) = (0.0, Vector::zeros());
                if pair.r > 0.0 {
                    dw_r = pair.dw / pair.r;
                    e = pair.xij / pair.r;
                    let grad = pair.xij * dw_r;
                    m += outer(-pair.xij, grad) * vj;
                    gv += outer(p.vel[j] - vi, grad) * vj;
                }
                row[cnt] = CachedPair {
                    j: pair.j,
                    xij: pair.xij,
                    e,
                    r: pair.r,
                    w: pair.w,
                    dw_r,
                    near_ref: pair.near_ref,
                };
                cnt += 1;
            }
            let lcorr = correction(m);
            // Fragments fly ballistically: no velocity gradient.
            let gradv = if cnt < MIN_SUPPORT_NEIGHBOURS as usize {
                Matrix::zeros()
            } else {
                gv * lcorr.transpose()
            };
            ParticleSums {
                shepard: g,
                lcorr,
                gradv,
                pairs: cnt as u32,
            }
        })
        .collect();
    sums.shepard.clear();
    sums.lcorr.clear();
    sums.gradv.clear();
    cache.count.clear();
    for o in out {
        sums.shepard.push(o.shepard);
        sums.lcorr.push(o.lcorr);
        sums.gradv.push(o.gradv);
        cache.count.push(o.pairs);
    }
}

/// Inverts the Bonet–Lok moment matrix (eq. 8); where a particle has too few neighbours for a
/// well-conditioned inverse (an isolated fragment), the uncorrected gradient is used instead.
fn correction(m: Matrix) -> Matrix {
    let tr = m.trace();
    let det = m.determinant();
    // Smallest eigenvalue of the symmetric part relative to the mean: a conditioning measure.
    let disc = ((tr * 0.5).powi(2) - det).max(0.0).sqrt();
    let lmin = tr * 0.5 - disc;
    if tr > 0.0 && lmin > 0.05 * tr * 0.5 {
        m.try_inverse().unwrap_or_else(Matrix::identity)
    } else {
        Matrix::identity()
    }
}
