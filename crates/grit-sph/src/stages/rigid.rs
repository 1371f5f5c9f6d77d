//! Rigid-body motion: the bodies from total force and torque (eq. 17), then their particles.

use rayon::prelude::*;

use super::{ParTasks, StepCtx};
use crate::body::Motion;
use crate::math::{omega_cross, rotate};

/// Advances every rigid body over the step from its contact force and torque, external force
/// and gravity (eq. 17, semi-implicit Euler), or along its prescribed motion, and moves its
/// particles with it.
pub(crate) fn rigid(ctx: &mut StepCtx<'_>) {
    let (g, time, dt) = (ctx.settings.gravity_m_s2, ctx.time, ctx.dt);
    let bodies = &mut *ctx.bodies;
    let p = &mut *ctx.p;
    let t_next = time + dt;
    for b in bodies.iter_mut() {
        let Some(r) = b.rigid_mut() else { continue };
        match r.motion.velocity(t_next) {
            None => {
                let f = r.contact_force_n_m + r.external.at(time) + g * r.mass_kg_m;
                r.velocity_m_s += f * (dt / r.mass_kg_m);
                r.omega_rad_s += r.contact_torque_n * dt / r.inertia_kg_m;
            }
            Some(v) => {
                r.velocity_m_s = v;
                r.omega_rad_s = 0.0;
            }
        }
        r.com_m += r.velocity_m_s * dt;
        r.angle_rad += r.omega_rad_s * dt;
    }
    let bodies = &*bodies;
    // Fixed bodies never move: skip their particles.
    let moving: Vec<bool> = bodies
        .iter()
        .map(|b| b.rigid().is_some_and(|r| r.motion != Motion::Fixed))
        .collect();
    if !moving.iter().any(|&m| m) {
        return;
    }
    p.pos
        .par_iter_mut()
        .zip(p.vel.par_iter_mut())
        .zip(p.body.par_iter())
        .zip(p.local.par_iter())
        .par_tasks()
        .for_each(|(((x, v), &b), l)| {
            if !moving[b as usize] {
                return;
            }
            if let Some(r) = bodies[b as usize].rigid() {
                let rl = rotate(*l, r.angle_rad);
                *x = r.com_m + rl;
                *v = r.velocity_m_s + omega_cross(r.omega_rad_s, rl);
            }
        });
}
