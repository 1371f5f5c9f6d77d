//! The abrasive feed (the AWJ paper eqs. 54–55, docs/jet.md#the-scene): the jet is cut into
//! columns of length y_dis = ρ_p v_jet V_a / M, V_a = π d³/6, and each column carries one grain
//! at a random place in it, so the mass flow is M.

use grit_sph::dem::Grain;
use grit_sph::{InputError, Vector, World};
use serde::{Deserialize, Serialize};

use super::{JetParams, Layout};
use crate::sample::stream_draws;

/// Length y_dis of the jet that carries one grain (m), eq. 55 solved for it: ρ_p v_jet V_a / M
/// with V_a = π d³/6; infinite for M = 0.
pub fn grain_spacing_m(params: &JetParams) -> f64 {
    let d = params.grain_diameter_m;
    let v_a = std::f64::consts::PI * d * d * d / 6.0;
    params.grain_density_kg_m3 * params.velocity_m_s * v_a / params.mass_flow_kg_s
}

/// Which grain comes next. Grain k sits at distance (k + u_k) y_dis along the jet from its
/// head and at x = (2 w_k − 1)(d_jet/2 − R) across it, u_k and w_k the draws of ChaCha stream
/// k of the run's seed: grain k does not depend on how the run got there or where it resumed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Feed {
    next: u64,
}

impl Feed {
    /// A feed that has released nothing.
    pub fn new(_params: &JetParams) -> Feed {
        Feed { next: 0 }
    }

    /// Grains released so far.
    pub fn fed(&self) -> u64 {
        self.next
    }

    /// Adds to `world` every grain whose place along the jet has left the nozzle by now
    /// (the jet has run v_jet · t), moving at `grain_speed_ratio` × v_jet.
    pub fn release(
        &mut self,
        world: &mut World,
        params: &JetParams,
        layout: &Layout,
        seed: u64,
    ) -> Result<(), InputError> {
        if params.mass_flow_kg_s <= 0.0 {
            return Ok(());
        }
        let y_dis = grain_spacing_m(params);
        let travelled = params.velocity_m_s * world.time();
        let r = 0.5 * params.grain_diameter_m;
        let half = 0.5 * params.jet_width_m - r;
        loop {
            let (u, w) = stream_draws(seed, self.next);
            let s = (self.next as f64 + u) * y_dis;
            if s > travelled {
                return Ok(());
            }
            // Released when the jet had run s, the grain has since moved at its own speed.
            let ratio = params.grain_speed_ratio;
            let below = (travelled - s) * ratio;
            let pos = Vector::new((2.0 * w - 1.0) * half, layout.nozzle_y_m - below);
            let mut g = Grain::sphere(pos, r, params.grain_density_kg_m3);
            g.vel = Vector::new(0.0, -params.velocity_m_s * ratio);
            world.add_grain(g)?;
            self.next += 1;
        }
    }
}
