//! grit-erosion: the science around the SPH engine (Mohseni-Mofidi et al. 2022, section 4):
//! grain shapes and their shape factors, aggregation of per-impact mass losses into erosion,
//! the Oka and shape-modified Oka erosion models fitted to simulated erosion, and the studies
//! of the simulation's own choices (`studies`).
#![warn(missing_docs)]

pub mod campaign;
pub mod fingerprint;
pub mod models;
pub mod scene;
pub mod scenes;
pub mod stats;
pub mod studies;

pub use scenes::{impact, jet};

pub use impact::aggregate::{
    aggregate_campaign, aggregate_cell, CampaignResults, CellInput, CellResult, Impact,
    SampleInput, Stationarity, SLOPE_WINDOW,
};
pub use impact::sample::{ImpactRecord, Sample, SampleError};
pub use impact::steady::SteadyState;
pub use impact::{
    filter_interval_in_time, ImpactError, ImpactOutcome, ImpactParams, Numerics, DEFAULT_CFL,
};
pub use models::oka::{
    fit_modified_oka, fit_oka, FitError, ModifiedOkaModel, OkaModel, ShapeExponents,
    ShapeReference, AISI304_HV_GPA,
};
pub use models::shapes::{Shape, ShapeError, ShapeInfo};
pub use scene::{Scene, SceneError, SceneSet, SceneVisitor, Scenes};
pub use stats::{AggregateError, SlopeFit};
