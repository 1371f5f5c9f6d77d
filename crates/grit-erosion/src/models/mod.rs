//! Erosion models fitted to simulated erosion and compared with published ones: Oka's model
//! and the seed's shape-modified form ([`oka`]), the grain shapes and their shape factors
//! ([`shapes`]), and the comparison tables ([`compare`]).

pub mod compare;
pub mod oka;
pub mod shapes;
