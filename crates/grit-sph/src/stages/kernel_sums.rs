//! The kernel sums: Shepard sums Γ_i = Σ V_j W_ij (eq. 9 denominator), Bonet–Lok correction
//! matrices L_i (eq. 8) and the rates, the velocity gradients with the corrected kernel gradient
//! (eqs. 15 and 7), in one pass over the pairs; and the same-body pair cache the forces read.
//! Each pair's kernel is evaluated once (`pairs::fill_half_pairs`); each particle then sums its
//! pairs in its own row's order.

use rayon::prelude::*;

use super::pairs::{fill_half_pairs, row_blocks, PairCache, Side, APART, ROWS_PER_BLOCK, USED};
use super::{SphView, StepCtx, MIN_SUPPORT_NEIGHBOURS};
use crate::math::{outer, Matrix};

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
/// `cache`, evaluated once per pair (`StepCtx::half`). The velocity gradient of particle i needs
/// only its own L_i, so it is summed in the same pass, term by term in the same order as a
/// separate pass would.
pub(crate) fn kernel_sums(ctx: &StepCtx<'_>, cache: &mut PairCache, sums: &mut KernelSums) {
    let SphView { p, nl, k, bc } = ctx.sph();
    let hi = ctx.half;
    let w0 = k.w(0.0);
    super::volumes(p, &mut sums.vol);
    let vol = &sums.vol;
    fill_half_pairs(p, nl, hi, k, &mut cache.half, &mut cache.flags);
    let (half, flags) = (&cache.half, &cache.flags);
    let particle_sums = |i: usize, row: &mut [Side]| {
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
        let ids = &hi.id[nl.start[i] as usize..];
        for (&j, &id) in nl.of(i).iter().zip(ids) {
            let bits = flags[id as usize];
            if bits & USED == 0 {
                continue;
            }
            let pair = half[id as usize].seen((j as usize) < i);
            let j = j as usize;
            let vj = vol[j];
            g += vj * pair.w;
            if bits & APART != 0 {
                let grad = pair.xij * pair.dw_r;
                m += outer(-pair.xij, grad) * vj;
                gv += outer(p.vel[j] - vi, grad) * vj;
            }
            row[cnt] = Side { j: j as u32, id };
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
    };
    // Each particle's results go straight to their places, block by block.
    let n = p.len();
    sums.shepard.resize(n, 0.0);
    sums.lcorr.resize(n, Matrix::zeros());
    sums.gradv.resize(n, Matrix::zeros());
    cache.count.resize(n, 0);
    let outs = sums
        .shepard
        .par_chunks_mut(ROWS_PER_BLOCK)
        .zip(sums.lcorr.par_chunks_mut(ROWS_PER_BLOCK))
        .zip(sums.gradv.par_chunks_mut(ROWS_PER_BLOCK))
        .zip(cache.count.par_chunks_mut(ROWS_PER_BLOCK));
    row_blocks(&mut cache.sides, &nl.start)
        .into_par_iter()
        .zip(outs)
        .for_each(|(rows, (((shepard, lcorr), gradv), count))| {
            for (k, (i, row)) in rows.rows().enumerate() {
                let o = particle_sums(i, row);
                (shepard[k], lcorr[k], gradv[k], count[k]) = (o.shepard, o.lcorr, o.gradv, o.pairs);
            }
        });
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
