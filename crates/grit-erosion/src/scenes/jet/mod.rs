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
