//! The stress update: continuity (eq. 5), the Jaumann stress rate (eq. 13), radial return with
//! Johnson–Cook yield (eq. 18), adiabatic heating and damage (eqs. 19–20); or, for rock, the
//! JH-2 update (AWJ paper eqs. 38–41, `jh2::jh2_update`).

use rayon::prelude::*;

use super::{ParTasks, StepCtx};
use crate::jh2::{self, Jh2State};
use crate::material::{Fracture, JohnsonCook, Strength};
use crate::math::Matrix;
use crate::particles::von_mises;
use crate::physics::{self, YieldAt};

/// A particle's zero-rate yield stress (`physics::YieldAt`) as last computed, with the particle
/// and the state it was computed for: a particle that stays elastic keeps ε_p and T, so its
/// elastic check takes no power (on a surface after 30 impacts most particles have ε_p > 0 and
/// T above room temperature, two powers each per step otherwise).
#[derive(Debug, Clone, Copy)]
pub(crate) struct YieldMemo {
    id: u32,
    eps_p: u64,
    temp: u64,
    at: YieldAt,
}

impl Default for YieldMemo {
    fn default() -> Self {
        YieldMemo {
            id: u32::MAX,
            eps_p: 0,
            temp: 0,
            at: YieldAt { sy0: 0.0, th: 0.0 },
        }
    }
}

impl YieldMemo {
    /// The particle's `YieldAt`, from the memo where it was computed for this particle (by id)
    /// at these bits of ε_p and T, else computed now and kept. Keyed on the state itself, the
    /// memo needs no invalidation: a deletion, reordering or restored checkpoint only misses.
    #[inline]
    fn get(&mut self, id: u32, jc: &JohnsonCook, eps_p: f64, temp: f64) -> YieldAt {
        if self.id != id || self.eps_p != eps_p.to_bits() || self.temp != temp.to_bits() {
            self.keep(id, eps_p, temp, physics::yield_at(jc, eps_p, temp));
        }
        self.at
    }

    /// Keeps the particle's `YieldAt` at its new ε_p and T from the hardening the radial return
    /// ended on, so the next step's `get` finds it and takes one power, not two.
    #[inline]
    fn set_hardened(&mut self, id: u32, jc: &JohnsonCook, eps_p: f64, temp: f64, hard: f64) {
        self.keep(id, eps_p, temp, physics::yield_hardened(jc, hard, temp));
    }

    /// The memo of `at`, computed for particle `id` at these ε_p and T.
    #[inline]
    fn keep(&mut self, id: u32, eps_p: f64, temp: f64, at: YieldAt) {
        *self = YieldMemo {
            id,
            eps_p: eps_p.to_bits(),
            temp: temp.to_bits(),
            at,
        };
    }
}

/// Continuity (eq. 5 as ρ̇ = −ρ tr ∇v), Jaumann rate (eq. 13), radial return with Johnson–Cook
/// yield (eq. 18), adiabatic heating with the Taylor–Quinney coefficient of the settings, damage
/// (eqs. 19–20), and the deformation gradient the hourglass stiffness compares against, from the
/// velocity gradients `gv`; returns the plastic work of the step (J/m). `memo` keeps each
/// particle's zero-rate yield stress between steps.
pub(crate) fn stress(ctx: &mut StepCtx<'_>, gv: &[Matrix], memo: &mut Vec<YieldMemo>) -> f64 {
    let (bc, beta, dt) = (ctx.bc, ctx.settings.taylor_quinney, ctx.dt);
    let bodies = &*ctx.bodies;
    let p = &mut *ctx.p;
    memo.resize(p.len(), YieldMemo::default());
    let plastic_work: f64 = p
        .rho
        .par_iter_mut()
        .zip(p.sdev.par_iter_mut())
        .zip(p.eps_p.par_iter_mut())
        .zip(p.eps_p_rate.par_iter_mut())
        .zip(p.temp.par_iter_mut())
        .zip(p.energy.par_iter())
        .zip(p.damage.par_iter_mut().zip(p.bulking.par_iter_mut()))
        .zip(p.def_grad.par_iter_mut())
        .zip(p.body.par_iter())
        .zip(p.mass.par_iter())
        .zip(p.rho0.par_iter())
        .zip(memo.par_iter_mut())
        .par_tasks()
        .enumerate()
        .map(
            |(
                i,
                (
                    (
                        (((((((((rho, s), ep), epr), temp), &en), (dmg, bulk)), fdef), &b), &m),
                        &rho0,
                    ),
                    memo,
                ),
            )| {
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
                    Some(Strength::JohnsonHolmquist2(_)) => {
                        let laws = c.jh2.as_ref().expect("a JH-2 strength has all three laws");
                        *rho = rho.max(jh2::least_density(laws, *bulk, *dmg));
                        let st = Jh2State {
                            sdev: s_trial,
                            eps_p: *ep,
                            damage: *dmg,
                            bulking: *bulk,
                        };
                        let rate = jh2::equivalent_rate(&d);
                        let r = jh2::jh2_update(s_trial, st, *rho, rate, c.shear, laws);
                        *s = r.state.sdev;
                        *ep = r.state.eps_p;
                        *dmg = r.state.damage;
                        *bulk = r.state.bulking;
                        *epr = r.d_eps / dt;
                        let wp = r.sigma_y * r.d_eps;
                        if wp > 0.0 {
                            *temp += beta * wp / (*rho * mat.heat_capacity_j_kgk);
                        }
                        wp * m / *rho
                    }
                    Some(Strength::JohnsonCook(jc)) => {
                        let at = memo.get(p.id[i], jc, *ep, *temp);
                        let r = physics::radial_return_at(s_trial, c.shear, jc, *ep, dt, at);
                        *s = r.sdev;
                        *epr = r.d_eps / dt;
                        if r.d_eps > 0.0 {
                            let wp = r.sigma_y * r.d_eps; // plastic work per volume
                            if let Some(Fracture::JohnsonCook(dm)) = &mat.damage {
                                let seq = von_mises(&r.sdev);
                                let pr = c.pressure(*rho, rho0, en);
                                let triax = physics::triaxiality(pr, seq);
                                let ef = physics::fracture_strain(dm, jc, triax, *epr, *temp);
                                *dmg += r.d_eps / ef;
                            }
                            *ep += r.d_eps;
                            *temp += beta * wp / (*rho * mat.heat_capacity_j_kgk);
                            if let Some(hard) = r.hardening {
                                memo.set_hardened(p.id[i], jc, *ep, *temp, hard);
                            }
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
