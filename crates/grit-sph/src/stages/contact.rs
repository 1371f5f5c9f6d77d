//! The contact stage: detection and forces for every contact pair (seed section 3,
//! eqs. 21–29), with the reactions on the rigid bodies gathered in particle order.

use rayon::prelude::*;

use super::{ParTasks, StepCtx};
use crate::body::Motion;
use crate::contact::{self, ContactPair};
use crate::math::{cross, Vector};
use crate::neighbours::ContactLists;

/// One secondary particle's contact in this step.
struct Hit {
    /// Force on the secondary particle (N/m); its nearest primary particle takes the opposite.
    force: Vector,
    /// Nearest primary boundary particle.
    nearest: usize,
    /// Distance from the primary surface (eq. 21) (m).
    distance: f64,
    /// Work of the contact dashpot over the step (J/m).
    damping_work: f64,
}

/// A secondary particle's contact state after this step, and its hit if it is in contact.
#[derive(Default)]
struct Outcome {
    /// Friction spring Δl (eq. 25); zero out of contact.
    spring: Vector,
    /// Penetration P (eq. 23); zero out of contact.
    penetration: f64,
    hit: Option<Hit>,
}

/// A secondary particle found on the far side of a primary surface: the step has failed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PassedThrough {
    /// Index of the contact pair.
    pub pair: usize,
    /// Index of the secondary particle.
    pub particle: usize,
    /// Its distance from the primary surface (m), negative.
    pub distance: f64,
}

/// Contact detection and forces for every pair (eqs. 21–29), with the particle spacing as the
/// equilibrium distance: the force on each particle into `force`, the reactions into the rigid
/// bodies' contact force and torque, the dashpot work added to `damping_work`. Reactions are
/// collected per rigid body in particle order, so the sums do not depend on the thread count.
/// Stops at the first pair in which a particle has passed through the primary surface, and
/// returns it. `vol` holds the particle volumes, `lists[c]` pair c's candidate primary particles
/// of the secondary particles near the primary. A secondary particle without candidates is out of contact: its spring and
/// penetration are zero (they are cleared once after each build, `ContactLists::sweep`).
pub(crate) fn contact(
    ctx: &mut StepCtx<'_>,
    lists: &mut [ContactLists],
    vol: &[f64],
    contacts: &mut [ContactPair],
    force: &mut Vec<Vector>,
    damping_work: &mut f64,
) -> Option<PassedThrough> {
    let (p, k, dx, dt) = (&*ctx.p, ctx.kernel, ctx.settings.spacing_m, ctx.dt);
    let bodies = &mut *ctx.bodies;
    let n = p.len();
    force.clear();
    force.resize(n, Vector::zeros());
    for b in bodies.iter_mut() {
        if let Some(r) = b.rigid_mut() {
            r.contact_force_n_m = Vector::zeros();
            r.contact_torque_n = 0.0;
        }
    }
    for (ci, c) in contacts.iter_mut().enumerate() {
        let cl = &mut lists[ci];
        let sec = c.secondary as u32;
        if cl.sweep {
            let mut listed = cl.particles.iter().peekable();
            for i in 0..n {
                if listed.next_if_eq(&&(i as u32)).is_none() && p.body[i] == sec {
                    c.spring[i] = Vector::zeros();
                    c.penetration[i] = 0.0;
                }
            }
            cl.sweep = false;
        }
        let nl = &cl.rows;
        let (k_r, k_f, mu, zeta, model) = (
            c.k_r,
            c.k_f,
            c.params.friction,
            c.params.damping_ratio,
            c.params.model,
        );
        let probe = contact::Detector {
            model,
            kernel: k,
            dx,
            k_r,
        };
        let prim_fixed = matches!(
            bodies[c.primary].rigid().map(|r| r.motion),
            Some(Motion::Fixed)
        );
        let sec_fixed = matches!(
            bodies[c.secondary].rigid().map(|r| r.motion),
            Some(Motion::Fixed)
        );
        let (spring, penetration) = (&c.spring, &c.penetration);
        let outcomes: Vec<Outcome> = cl
            .particles
            .par_iter()
            .par_tasks()
            .enumerate()
            .map(|(row, &i)| {
                let i = i as usize;
                let js = nl.of(row).iter().map(|&j| j as usize);
                let det = probe.detect(p.pos[i], js, &p.pos, |j| vol[j]);
                let det = match det {
                    Some(d) if d.penetration > 0.0 => d,
                    _ => return Outcome::default(),
                };
                let mut dl = spring[i];
                let pen_rate = (det.penetration - penetration[i]) / dt;
                let j = det.nearest;
                let vrel = p.vel[i] - p.vel[j];
                let fr = det.repulsion;
                let m_eff = match (sec_fixed, prim_fixed) {
                    (true, _) => p.mass[j],
                    (_, true) => p.mass[i],
                    _ => p.mass[i] * p.mass[j] / (p.mass[i] + p.mass[j]),
                };
                let c_t = 2.0 * zeta * (k_f * m_eff).sqrt();
                let ff = contact::Friction { k_f, c_t, mu }.force(
                    &mut dl,
                    vrel,
                    det.normal,
                    dt,
                    fr.norm(),
                );
                let cdamp = 2.0 * zeta * (k_r * m_eff).sqrt();
                let fd = det.normal * (cdamp * pen_rate);
                let work = -fd.norm() * pen_rate.abs() * dt;
                Outcome {
                    spring: dl,
                    penetration: det.penetration,
                    hit: Some(Hit {
                        force: fr + ff + fd,
                        nearest: j,
                        distance: det.distance,
                        damping_work: work,
                    }),
                }
            })
            .collect();
        // Sequential gather: eq. 29 reactions and eq. 17 sums in particle order.
        let mut damp = 0.0;
        let mut through = None;
        for (&i, o) in cl.particles.iter().zip(outcomes) {
            let i = i as usize;
            c.spring[i] = o.spring;
            c.penetration[i] = o.penetration;
            let Some(Hit {
                force: f,
                nearest: j,
                distance: dist,
                damping_work: work,
            }) = o.hit
            else {
                continue;
            };
            force[i] += f;
            force[j] -= f;
            damp += work;
            if dist < 0.0 && through.is_none() {
                through = Some((i, dist));
            }
            let bj = &mut bodies[c.primary];
            if let Some(r) = bj.rigid_mut() {
                r.contact_force_n_m -= f;
                r.contact_torque_n += cross(p.pos[j] - r.com_m, -f);
            }
            if let Some(r) = bodies[c.secondary].rigid_mut() {
                r.contact_force_n_m += f;
                r.contact_torque_n += cross(p.pos[i] - r.com_m, f);
            }
        }
        *damping_work += damp;
        if let Some((i, dist)) = through {
            return Some(PassedThrough {
                pair: ci,
                particle: i,
                distance: dist,
            });
        }
    }
    None
}
