//! Erosion models fitted to simulated erosion and compared with published ones: Oka's model
//! and the seed's shape-modified form ([`oka`]), the grain shapes and their shape factors
//! ([`shapes`]), the comparison tables ([`compare`]), and the full Oka model E(α, v, d) fitted
//! jointly to steady cells ([`fit`]) and written for CFD and DEM codes ([`export`]).

pub mod compare;
pub mod export;
pub mod fit;
pub mod oka;
pub mod shapes;
