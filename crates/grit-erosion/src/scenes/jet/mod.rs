//! The abrasive water-jet scene (docs/jet.md; the AWJ paper, Sci. Rep. 14, 26115, 2024): a
//! plane jet of water carrying DEM grains hits a metal target straight on, and the crater's
//! depth Cd, width Cw, the mass loss and the largest plastic strain are sampled against time.
//!
//! A run advances in slices of simulated time (`slice_ms`), the farm's unit of progress: after
//! each slice the crater is measured and the whole state can be checkpointed, so a killed run
//! loses at most one slice.

pub mod aggregate;
mod feed;
mod params;
mod rock;
mod run;
pub mod runs;
mod scene;
pub mod spec;
mod stored;

pub use feed::{grain_spacing_m, Feed};
pub use params::*;
pub use run::*;
pub use scene::{Layout, FIXED_SIDE_LAYERS, WATER_DENSITY_DIFFUSION, WATER_DENSITY_RANGE};

/// Slice `k` (from 1) of a made-up sample at `t_s` with mass loss `loss` and crater `cd`, for
/// the tests of what reads slices.
#[cfg(test)]
pub(crate) fn test_slice(k: u32, t_s: f64, loss: f64, cd: f64) -> JetSlice {
    JetSlice {
        slice: k,
        sample: grit_sph::crater::CraterSample {
            t_s,
            mass_loss_kg_m: loss,
            crater_depth_m: cd,
            crater_width_m: 2.0 * cd,
            max_plastic_strain: 0.1,
        },
        half_depth_width_m: cd,
        profile: vec![[-1e-3, -cd], [0.0, -2.0 * cd], [1e-3, -cd]],
        steps: 10,
        particles: 100,
        grains: 1,
        grains_fed: k as u64,
        water_deleted_kg_m: 0.0,
        water_fed_kg_m: 0.0,
        wall_s: 0.5,
        grain_hits: None,
        rock: None,
    }
}
