//! Integration of the deformable and fluid particles (semi-implicit Euler) and the checks that
//! end a step which has blown up.

use rayon::prelude::*;

use super::{ParTasks, StepCtx};
use crate::body::BodyKind;
use crate::math::Vector;
use crate::particles::KINEMATIC;

/// What went wrong in a step that has blown up.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Blowup {
    /// The first particle, in particle order, that failed a check, and which check.
    Particle { index: usize, what: String },
    /// A rigid body whose position or velocity is not finite.
    Rigid { body: usize },
}

/// Integrates deformable and fluid particles over the step (semi-implicit Euler) with the SPH
/// accelerations `acc` and the contact forces `contact_force`. Then the failure checks: finite
/// state, positive density, no particle moved more than h, finite rigid bodies.
pub(crate) fn integrate(
    ctx: &mut StepCtx<'_>,
    acc: &[Vector],
    contact_force: &[Vector],
) -> Option<Blowup> {
    let (bc, h, time, dt) = (ctx.bc, ctx.kernel.h, ctx.time, ctx.dt);
    let bodies = &*ctx.bodies;
    let p = &mut *ctx.p;
    let t_next = time + dt;
    let motions: Vec<Option<Vector>> = bodies
        .iter()
        .map(|b| match &b.kind {
            BodyKind::Deformable {
                boundary_motion, ..
            }
            | BodyKind::Fluid {
                boundary_motion, ..
            } => boundary_motion.velocity(t_next),
            _ => None,
        })
        .collect();
    let cf = contact_force;
    let out: Vec<Option<String>> = p
        .pos
        .par_iter_mut()
        .zip(p.vel.par_iter_mut())
        .par_tasks()
        .enumerate()
        .map(|(i, (x, v))| {
            let b = p.body[i] as usize;
            if !bc[b].integrated() {
                return None;
            }
            if p.flags[i] & KINEMATIC != 0 {
                *v = motions[b].unwrap_or_else(Vector::zeros);
            } else {
                *v += (acc[i] + cf[i] / p.mass[i]) * dt;
            }
            let dxs = *v * dt;
            *x += dxs;
            if !(x.x.is_finite() && x.y.is_finite() && v.x.is_finite() && v.y.is_finite()) {
                return Some("position or velocity is not finite".to_string());
            }
            if !(p.sdev[i].iter().all(|s| s.is_finite()) && p.rho[i].is_finite()) {
                return Some("stress or density is not finite".to_string());
            }
            if p.rho[i] <= 0.0 {
                return Some(format!("density {:.4e} kg/m³ is not positive", p.rho[i]));
            }
            let step = dxs.norm();
            if step > h {
                return Some(format!(
                    "moved {step:.3e} m in one step, more than h = {h:.3e} m"
                ));
            }
            None
        })
        .collect();
    // The first failure in particle order, whatever the thread count.
    if let Some((index, what)) = out
        .into_iter()
        .enumerate()
        .find_map(|(i, f)| f.map(|what| (i, what)))
    {
        return Some(Blowup::Particle { index, what });
    }
    bodies
        .iter()
        .position(|b| {
            b.rigid().is_some_and(|r| {
                let ok = r
                    .com_m
                    .iter()
                    .chain(r.velocity_m_s.iter())
                    .all(|x| x.is_finite())
                    && r.omega_rad_s.is_finite();
                !ok
            })
        })
        .map(|body| Blowup::Rigid { body })
}
