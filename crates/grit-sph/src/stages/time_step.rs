//! The stable time step of an explicit step.

use rayon::prelude::*;

use super::{BodyConst, ParTasks};
use crate::contact::ContactPair;
use crate::particles::Particles;
use crate::world::Settings;

/// Stable time step: CFL on the material signal speed plus particle speed over the smoothing
/// length `h`, the fluid's limits (`fluid_dt`), and the contact springs' period where
/// `Settings::contact_limits_dt` asks for it.
pub(crate) fn stable_dt(
    p: &Particles,
    bc: &[BodyConst],
    h: f64,
    settings: &Settings,
    contacts: &[ContactPair],
) -> f64 {
    let smax = (0..p.len())
        .into_par_iter()
        .par_tasks()
        .filter(|&i| bc[p.body[i] as usize].deformable)
        .map(|i| bc[p.body[i] as usize].sound + p.vel[i].norm())
        .reduce(|| 0.0, f64::max);
    let mut dt = settings.dt_max_s;
    if smax > 0.0 {
        dt = dt.min(settings.cfl * h / smax);
    }
    if super::any_fluid(bc) {
        dt = dt.min(super::fluid_dt(p, bc, h, settings.cfl));
    }
    for c in contacts.iter().filter(|_| settings.contact_limits_dt) {
        if c.min_mass.is_finite() {
            dt = dt.min(settings.cfl * (c.min_mass / (c.k_r + c.k_f)).sqrt() * 2.0);
        }
    }
    dt
}
