//! The abrasive feed (the AWJ paper eqs. 54–55, docs/jet.md#the-scene): the jet is cut into
//! columns of length y_dis = ρ_p v_jet V_a / M, V_a = π d³/6, and each column carries one grain
//! at a random place in it, so the mass flow is M.

use grit_sph::dem::Grain;
use grit_sph::{InputError, Vector, World};
use serde::{Deserialize, Serialize};

use super::{JetParams, Layout};
use crate::scene::stream_units;

/// Length y_dis of the jet that carries one grain (m), eq. 55 solved for it: ρ_p v_jet V_a / M
/// with V_a = π d³/6; infinite for M = 0.
pub fn grain_spacing_m(params: &JetParams) -> f64 {
    let d = params.grain_diameter_m;
    let v_a = std::f64::consts::PI * d * d * d / 6.0;
    params.grain_density_kg_m3 * params.velocity_m_s * v_a / params.mass_flow_kg_s
}

/// Draws of grain k's place across the jet before the feed gives up (`release`'s error): at the
/// paper's highest mass flow (0.07 kg/s at 500 m/s, a grain every 0.12 mm of a 1 mm jet) the
/// grains cover a quarter of the jet, and a free place is found in a few draws.
const PLACE_TRIES: usize = 256;

/// Which grain comes next. Grain k sits at distance s_k = (k + u_k) y_dis along the jet from its
/// head and at x = (2 w − 1)(d_jet/2 − R) across it, u_k and w the draws of ChaCha stream k of
/// the run's seed: u_k the first, w the first of the following draws that puts the grain at
/// least a diameter from every grain placed before it. Placed anywhere, two grains within a
/// diameter of each other start overlapping, and their contact throws them apart at up to four
/// times the jet's speed (docs/jet.md#how-fast-the-grains-arrive). The places depend only on
/// the seed, so a resumed run feeds what an unbroken one would.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Feed {
    next: u64,
    /// Places (x, s) of the grains fed last that are within a diameter of the jet's length of
    /// the next place; the next grain is kept clear of them.
    recent: Vec<[f64; 2]>,
}

impl Feed {
    /// A feed that has released nothing.
    pub fn new(_params: &JetParams) -> Feed {
        Feed {
            next: 0,
            recent: Vec::new(),
        }
    }

    /// Grains released so far.
    pub fn fed(&self) -> u64 {
        self.next
    }

    /// Grain k's place (x, s): s from the stream's first draw, x from the first of the
    /// following draws that keeps it a diameter from the recent grains; errors when none of
    /// `PLACE_TRIES` does (a mass flow the jet's width cannot carry).
    fn place(&self, params: &JetParams, seed: u64, y_dis: f64) -> Result<[f64; 2], InputError> {
        let d = params.grain_diameter_m;
        let half = 0.5 * params.jet_width_m - 0.5 * d;
        let mut units = stream_units(seed, self.next);
        let s = (self.next as f64 + units.next().expect("endless")) * y_dis;
        for w in units.take(PLACE_TRIES) {
            let x = (2.0 * w - 1.0) * half;
            let clear = self
                .recent
                .iter()
                .all(|&[xj, sj]| (x - xj).hypot(s - sj) >= d);
            if clear {
                return Ok([x, s]);
            }
        }
        Err(InputError::new(
            "mass_flow_kg_s",
            format!(
                "{} kg/s puts a grain every {:.3e} m of a {:.3e} m jet: grain {} found no place \
                 a diameter clear of the others in {PLACE_TRIES} draws",
                params.mass_flow_kg_s, y_dis, params.jet_width_m, self.next
            ),
        ))
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
        loop {
            let [x, s] = self.place(params, seed, y_dis)?;
            if s > travelled {
                return Ok(());
            }
            // Released when the jet had run s, the grain has since moved at its own speed.
            let ratio = params.grain_speed_ratio;
            let below = (travelled - s) * ratio;
            let mut g = Grain::sphere(
                Vector::new(x, layout.nozzle_y_m - below),
                r,
                params.grain_density_kg_m3,
            );
            g.vel = Vector::new(0.0, -params.velocity_m_s * ratio);
            world.add_grain(g)?;
            self.commit([x, s], 2.0 * r);
        }
    }

    /// Takes `place` (x, s) as the next grain's, keeping the places within `d` of the jet's
    /// length behind it for the grains to come (s grows with k, by 0 to 2 y_dis).
    fn commit(&mut self, place: [f64; 2], d: f64) {
        self.recent.retain(|&[_, sj]| sj > place[1] - d);
        self.recent.push(place);
        self.next += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::stream_draws;

    /// The first `n` places of `params`' feed, each committed as `release` does.
    fn places(params: &JetParams, seed: u64, n: usize) -> Result<Vec<[f64; 2]>, InputError> {
        let (mut feed, y_dis, d) = (
            Feed::new(params),
            grain_spacing_m(params),
            params.grain_diameter_m,
        );
        let mut out = Vec::new();
        for _ in 0..n {
            let place = feed.place(params, seed, y_dis)?;
            feed.commit(place, d);
            out.push(place);
        }
        Ok(out)
    }

    #[test]
    fn grains_are_placed_a_diameter_apart_inside_the_jet_at_the_paper_s_highest_flow() {
        for m in [0.02, 0.07] {
            let params = JetParams {
                mass_flow_kg_s: m,
                ..JetParams::default()
            };
            let (d, half) = (
                params.grain_diameter_m,
                0.5 * (params.jet_width_m - params.grain_diameter_m),
            );
            let p = places(&params, 7, 2000).unwrap();
            for (k, a) in p.iter().enumerate() {
                assert!(a[0].abs() <= half, "grain {k} outside the jet: {a:?}");
                for b in &p[k + 1..] {
                    assert!(
                        (a[0] - b[0]).hypot(a[1] - b[1]) >= d,
                        "{m} kg/s: {a:?} and {b:?} overlap"
                    );
                }
            }
            // Each column keeps its grain, so the mass flow is the one asked for.
            let y_dis = grain_spacing_m(&params);
            for (k, a) in p.iter().enumerate() {
                assert!(
                    a[1] >= k as f64 * y_dis && a[1] < (k + 1) as f64 * y_dis,
                    "grain {k}"
                );
            }
            // A grain with nothing near keeps the place of its stream's first two draws.
            let (u, w) = stream_draws(7, 0);
            assert_eq!(p[0], [(2.0 * w - 1.0) * half, u * y_dis]);
        }
    }

    #[test]
    fn a_mass_flow_the_jet_cannot_carry_apart_is_refused_with_the_field_named() {
        let params = JetParams {
            mass_flow_kg_s: 2.0,
            ..JetParams::default()
        };
        let e = places(&params, 1, 1000).unwrap_err();
        assert_eq!(e.field, "mass_flow_kg_s", "{e}");
        assert!(e.to_string().contains("no place"), "{e}");
    }
}
