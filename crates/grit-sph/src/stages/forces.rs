//! The forces: the stress divergence with the normalised kernel gradient (eqs. 6 and 9), the
//! hourglass force (eq. 16) and gravity.

use rayon::prelude::*;

use super::{ParTasks, SphView, HG_MIN_SEPARATION_H, MIN_SUPPORT_NEIGHBOURS};
use crate::math::{Matrix, Vector};
use crate::neighbours::{CachedPair, PairCache};
use crate::particles::KINEMATIC;
use crate::world::Settings;

/// One particle's acceleration and the work of its hourglass force over the step.
struct ParticleForce {
    acc: Vector,
    hourglass_work: f64,
}

/// Accelerations from the stress divergence with the normalised gradient (eq. 6, 9, with the
/// Shepard sums `sh`), the hourglass force (eq. 16, against the velocity gradients `gv`) and
/// gravity, into `accel`; returns the hourglass work of the step (J/m). `vol` holds the volumes
/// after the stress stage.
#[allow(clippy::too_many_arguments)]
pub(crate) fn forces(
    s: SphView<'_>,
    cache: &PairCache,
    vol: &[f64],
    sh: &[f64],
    gv: &[Matrix],
    settings: &Settings,
    dt: f64,
    accel: &mut Vec<Vector>,
) -> f64 {
    let SphView { p, nl, k, bc } = s;
    let alpha = settings.hourglass;
    let g = settings.gravity_m_s2;
    let h = k.h;
    // σ_i / (ρ_i² Γ_i): the factor of eq. 6 with eq. 9's normalisation.
    let sig: Vec<Matrix> = (0..p.len())
        .into_par_iter()
        .par_tasks()
        .map(|i| {
            let c = bc[p.body[i] as usize];
            if !c.deformable {
                return Matrix::zeros();
            }
            let pr = p.pressure(i, c.bulk);
            (p.sdev[i] - Matrix::identity() * pr) / (p.rho[i] * p.rho[i] * sh[i])
        })
        .collect();
    let out: Vec<ParticleForce> = (0..p.len())
        .into_par_iter()
        .par_tasks()
        .map(|i| {
            let bi = p.body[i];
            let c = bc[bi as usize];
            // Kinematic particles follow their prescribed motion: their force is never used.
            if !c.deformable || p.flags[i] & KINEMATIC != 0 {
                return ParticleForce {
                    acc: Vector::zeros(),
                    hourglass_work: 0.0,
                };
            }
            if cache.count[i] < MIN_SUPPORT_NEIGHBOURS {
                return ParticleForce {
                    acc: g,
                    hourglass_work: 0.0,
                };
            }
            let vi = p.vel[i];
            let voli = vol[i];
            let mut a = Vector::zeros();
            let mut fhg = Vector::zeros();
            for &CachedPair {
                j,
                xij,
                e,
                r,
                w,
                dw_r,
                near_ref,
            } in cache.of(nl, i)
            {
                if r == 0.0 {
                    continue;
                }
                let j = j as usize;
                let grad = xij * dw_r;
                a += (sig[i] + sig[j]) * grad * p.mass[j];
                if alpha > 0.0 && w > 0.0 {
                    // Not the kernel sums' volume: the stress stage has moved ρ since (continuity), and
                    // both volumes must be the same step's for a symmetric pair force.
                    let volj = vol[j];
                    // Heavily sheared material can bring two particles almost on top of
                    // each other; 1/r² then makes the pair force stiff enough to blow the
                    // explicit step up (seen at 75°, impact 70). Below 0.4 h the weight stops
                    // growing; lattice neighbours (r ≈ 0.77 h) are untouched.
                    let rr = r.max(HG_MIN_SEPARATION_H * h);
                    let cij = alpha * voli * volj * w / (rr * rr);
                    // Viscous part: velocity error against the mean velocity gradient.
                    let vij = vi - p.vel[j];
                    let dv = (vij - (gv[i] + gv[j]) * xij * 0.5).dot(&e);
                    let visc = 0.5 * (p.rho[i] + p.rho[j]) * c.sound * h * dv;
                    // Stiffness part: separation error against the mean deformation gradient.
                    let stiff = if near_ref {
                        let xr = p.x_ref[i] - p.x_ref[j];
                        let ds = (xij - (p.def_grad[i] + p.def_grad[j]) * xr * 0.5).dot(&e);
                        c.youngs * ds.clamp(-0.5 * r, 0.5 * r)
                    } else {
                        0.0
                    };
                    fhg -= e * (cij * 0.5 * (stiff + visc));
                }
            }
            let acc = a + fhg / p.mass[i] + g;
            ParticleForce {
                acc,
                hourglass_work: fhg.dot(&vi) * dt,
            }
        })
        .collect();
    accel.clear();
    let mut hg = 0.0;
    for f in out {
        accel.push(f.acc);
        hg += f.hourglass_work;
    }
    hg
}
