//! The stress update: continuity (eq. 5), the Jaumann stress rate (eq. 13), radial return with
//! Johnson–Cook yield (eq. 18), adiabatic heating and damage (eqs. 19–20).

use rayon::prelude::*;

use super::{BodyConst, ParTasks};
use crate::body::Body;
use crate::material::{Fracture, Strength};
use crate::math::Matrix;
use crate::particles::{von_mises, Particles};
use crate::physics;

/// Continuity (eq. 5 as ρ̇ = −ρ tr ∇v), Jaumann rate (eq. 13), radial return with Johnson–Cook
/// yield (eq. 18), adiabatic heating with Taylor–Quinney coefficient `beta`, damage
/// (eqs. 19–20), and the deformation gradient the hourglass stiffness compares against, from the
/// velocity gradients `gv`; returns the plastic work of the step (J/m).
pub(crate) fn stress(
    p: &mut Particles,
    bodies: &[Body],
    bc: &[BodyConst],
    gv: &[Matrix],
    beta: f64,
    dt: f64,
) -> f64 {
    let plastic_work: f64 = p
        .rho
        .par_iter_mut()
        .zip(p.sdev.par_iter_mut())
        .zip(p.eps_p.par_iter_mut())
        .zip(p.eps_p_rate.par_iter_mut())
        .zip(p.temp.par_iter_mut())
        .zip(p.damage.par_iter_mut())
        .zip(p.def_grad.par_iter_mut())
        .zip(p.body.par_iter())
        .zip(p.mass.par_iter())
        .zip(p.rho0.par_iter())
        .par_tasks()
        .enumerate()
        .map(
            |(i, (((((((((rho, s), ep), epr), temp), dmg), fdef), &b), &m), &rho0))| {
                let c = bc[b as usize];
                if !c.deformable {
                    return 0.0;
                }
                let l = gv[i];
                let d = (l + l.transpose()) * 0.5;
                let w = (l - l.transpose()) * 0.5;
                let trd = d.trace();
                *rho *= 1.0 - dt * trd;
                *fdef += l * *fdef * dt;
                let dev = d - Matrix::identity() * (trd / 3.0);
                let s_trial = *s + (dev * (2.0 * c.shear) + w * *s - *s * w) * dt;
                let mat = bodies[b as usize]
                    .material()
                    .expect("deformable body has a material");
                match &mat.plasticity {
                    None => {
                        *s = s_trial;
                        0.0
                    }
                    Some(Strength::JohnsonCook(jc)) => {
                        let r = physics::radial_return(s_trial, c.shear, jc, *ep, dt, *temp);
                        *s = r.sdev;
                        *epr = r.d_eps / dt;
                        if r.d_eps > 0.0 {
                            let wp = r.sigma_y * r.d_eps; // plastic work per volume
                            if let Some(Fracture::JohnsonCook(dm)) = &mat.damage {
                                let seq = von_mises(&r.sdev);
                                let pr = c.pressure(*rho, rho0);
                                let triax = if seq > 0.0 { -pr / seq } else { 0.0 };
                                let ef = physics::fracture_strain(dm, jc, triax, *epr, *temp);
                                *dmg += r.d_eps / ef;
                            }
                            *ep += r.d_eps;
                            *temp += beta * wp / (*rho * mat.heat_capacity_j_kgk);
                            wp * m / *rho
                        } else {
                            0.0
                        }
                    }
                }
            },
        )
        .collect::<Vec<f64>>()
        .iter()
        .sum();
    plastic_work
}
