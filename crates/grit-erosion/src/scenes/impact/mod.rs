//! The impact scene (seed paper section 4): one angular grain after another on a fresh
//! AISI 304 surface; its parameters, one impact, a sample of impacts, the campaign spec, and
//! the aggregation of mass-loss curves into steady-state erosion.

pub mod aggregate;
pub mod balance;
mod params;
mod run;
pub mod sample;
pub mod spec;
pub mod steady;
mod stored;

pub use params::*;
pub use run::*;
