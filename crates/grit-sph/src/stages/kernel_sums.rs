//! The kernel sums: Shepard sums Γ_i = Σ V_j W_ij (eq. 9 denominator), Bonet–Lok correction
//! matrices L_i (eq. 8) and the rates, the velocity gradients with the corrected kernel gradient
//! (eqs. 15 and 7), in one pass over the pairs; and the same-body pair cache the forces read.
//! Each pair's kernel is evaluated once (`pairs::fill_half_pairs`); each particle then sums its
//! pairs in its own row's order.

use rayon::prelude::*;

use super::pairs::{
    fill_half_pairs, row_blocks, scatter, PairCache, Side, APART, ROWS_PER_BLOCK, USED,
};
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
    /// Scratch of the one-thread scatter.
    pub acc: Vec<Acc>,
}

/// One particle's running kernel sums in the one-thread scatter (`scatter_sums`), together so
/// that a pair's partner is one cache line away.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Acc {
    g: f64,
    m: Matrix,
    gv: Matrix,
    count: u32,
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
    let n = p.len();
    if scatter() {
        scatter_sums(ctx, cache, sums);
        return;
    }
    // Each particle's results go straight to their places, block by block.
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

/// The kernel sums of `kernel_sums` on one thread: each pair is read once, in id order, and its
/// terms go to both particles. The moment and velocity-gradient products are the same at both
/// ends (x_ji = −x_ij and v_i − v_j = −(v_j − v_i) exactly, so the signs cancel bit for bit),
/// so they are formed once and scaled by each end's partner volume. Particle i receives its
/// terms from the rows of its lower partners, in increasing index, before those of its own row:
/// its row's order, so every sum is bitwise the gather's and the bits are the same on any
/// number of threads. The rows of used pairs (`PairCache::sides`) are not written: the forces
/// scatter on one thread too and do not read them.
fn scatter_sums(ctx: &StepCtx<'_>, cache: &mut PairCache, sums: &mut KernelSums) {
    let SphView { p, nl, k, bc } = ctx.sph();
    let hi = ctx.half;
    let w0 = k.w(0.0);
    let n = p.len();
    let vol = &sums.vol;
    let deformable = |i: usize| bc[p.body[i] as usize].deformable;
    let acc = &mut sums.acc;
    acc.clear();
    acc.extend((0..n).map(|i| Acc {
        g: vol[i] * w0,
        m: Matrix::zeros(),
        gv: Matrix::zeros(),
        count: 0,
    }));
    let (half, flags) = (&cache.half, &cache.flags);
    sums.shepard.resize(n, 0.0);
    sums.lcorr.resize(n, Matrix::zeros());
    sums.gradv.resize(n, Matrix::zeros());
    cache.count.resize(n, 0);
    for i in 0..n {
        if !deformable(i) {
            (
                sums.shepard[i],
                sums.lcorr[i],
                sums.gradv[i],
                cache.count[i],
            ) = (1.0, Matrix::identity(), Matrix::zeros(), 0);
            continue;
        }
        let (vi, voli) = (p.vel[i], vol[i]);
        let mut own = acc[i];
        let at = hi.start[i] as usize;
        let pairs = half[at..].iter().zip(&flags[at..]);
        for (&j, (pair, &bits)) in hi.upper_of(nl, i).iter().zip(pairs) {
            if bits & USED == 0 {
                continue;
            }
            let j = j as usize;
            let vj = vol[j];
            let other = &mut acc[j];
            own.g += vj * pair.w;
            other.g += voli * pair.w;
            if bits & APART != 0 {
                let grad = pair.xij * pair.dw_r;
                let moment = outer(-pair.xij, grad);
                own.m += moment * vj;
                other.m += moment * voli;
                let rate = outer(p.vel[j] - vi, grad);
                own.gv += rate * vj;
                other.gv += rate * voli;
            }
            own.count += 1;
            other.count += 1;
        }
        // Row i is done: its lower partners came before it, its upper ones now.
        let lcorr = correction(own.m);
        sums.shepard[i] = own.g;
        sums.lcorr[i] = lcorr;
        cache.count[i] = own.count;
        sums.gradv[i] = if own.count < MIN_SUPPORT_NEIGHBOURS {
            Matrix::zeros()
        } else {
            own.gv * lcorr.transpose()
        };
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
