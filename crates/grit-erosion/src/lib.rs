//! grit-erosion: the science around the SPH engine (Mohseni-Mofidi et al. 2022, section 4):
//! grain shapes and their shape factors, aggregation of per-impact mass losses into erosion,
//! the Oka and shape-modified Oka erosion models fitted to simulated erosion, and the studies
//! of the simulation's own choices (`studies`).
#![warn(missing_docs)]

pub mod aggregate;
pub mod campaign;
pub mod compare;
pub mod fits;
pub mod impact;
pub mod jet;
pub mod sample;
pub mod shapes;
pub mod steady;
pub mod studies;

pub use aggregate::{
    aggregate_campaign, aggregate_cell, AggregateError, CampaignResults, CellInput, CellResult,
    Impact, SampleInput, SLOPE_WINDOW,
};
pub use fits::{
    fit_modified_oka, fit_oka, FitError, ModifiedOkaModel, OkaModel, ShapeExponents,
    ShapeReference, AISI304_HV_GPA,
};
pub use impact::{
    filter_interval_in_time, ImpactError, ImpactOutcome, ImpactParams, Numerics, DEFAULT_CFL,
};
pub use sample::{ImpactRecord, Sample, SampleError};
pub use shapes::{Shape, ShapeError, ShapeInfo};
pub use steady::{SlopeFit, SteadyState};
