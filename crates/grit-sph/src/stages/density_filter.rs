//! The periodic density filter: the seed's Shepard average (eq. 12) or its first-order
//! moving-least-squares form (Colagrossi & Landrini 2003).

use rayon::prelude::*;

use super::{ParTasks, SphView};
use crate::kernel::Kernel;
use crate::neighbours::{body_pairs, NeighbourLists, Pair};
use crate::particles::Particles;
use crate::world::DensityFilter;

/// The filtered density of every particle: ρ_i = Σ m_j W_ij / Σ V_j W_ij over the body, self
/// included (eq. 12), or its MLS form, with the particle volumes `vol`; rigid particles keep
/// theirs.
pub(crate) fn filter_density(s: SphView<'_>, vol: &[f64], filter: DensityFilter) -> Vec<f64> {
    let SphView { p, nl, k, bc } = s;
    let w0 = k.w(0.0);
    let mls = filter == DensityFilter::Mls;
    (0..p.len())
        .into_par_iter()
        .par_tasks()
        .map(|i| {
            let bi = p.body[i];
            if !bc[bi as usize].deformable {
                return p.rho[i];
            }
            if mls {
                if let Some(r) = mls_density(p, nl, k, vol, i) {
                    return r;
                }
            }
            let (mut num, mut den) = (p.mass[i] * w0, vol[i] * w0);
            for Pair { j, w, .. } in body_pairs(p, nl, k, i) {
                let j = j as usize;
                num += p.mass[j] * w;
                den += vol[j] * w;
            }
            num / den
        })
        .collect()
}

/// First-order MLS density at particle `i` (Colagrossi & Landrini 2003): ρ_i = Σ_j m_j W_ij
/// (β0 + β·x_ji), with β solving the moment system Σ_j V_j W_ij [1 x_ji]ᵀ[1 x_ji] β = e1, so a
/// linear density field comes back exactly. None where the system is near-singular (a particle
/// with neighbours on a line), which then falls back to eq. 12.
fn mls_density(
    p: &Particles,
    nl: &NeighbourLists,
    k: &Kernel,
    vol: &[f64],
    i: usize,
) -> Option<f64> {
    use nalgebra::{Matrix3, Vector3};
    // Offsets in units of h keep the moment matrix well scaled.
    let inv_h = 1.0 / k.h;
    let w0 = k.w(0.0);
    // ρ_i is linear in β, so one pass gathers both the moments A and b = Σ_j m_j W_ij q_j,
    // and ρ_i = β·b.
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    a[(0, 0)] = vol[i] * w0;
    b[0] = p.mass[i] * w0;
    for Pair { j, xij, w, .. } in body_pairs(p, nl, k, i) {
        let j = j as usize;
        let q = Vector3::new(1.0, -xij.x * inv_h, -xij.y * inv_h);
        a += q * q.transpose() * (vol[j] * w);
        b += q * (p.mass[j] * w);
    }
    // Relative to the zeroth moment: below this the linear terms are not determined.
    if a.determinant() <= 1e-6 * a[(0, 0)].powi(3) {
        return None;
    }
    let beta = a.try_inverse()?.column(0).into_owned();
    let rho = beta.dot(&b);
    (rho.is_finite() && rho > 0.0).then_some(rho)
}
