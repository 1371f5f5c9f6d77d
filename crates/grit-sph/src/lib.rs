//! grit-sph: a 2D SPH engine for solid particle erosion, after the seed paper
//! (Mohseni-Mofidi et al., Materials 2022, 15, 286, sections 2 and 3).
//!
//! No I/O, no async: a `World` holds particles and bodies and advances them by `step()`.
#![warn(missing_docs)]

pub mod error;
pub mod material;

pub use error::{InputError, SimError};
pub use material::{JohnsonCook, JohnsonCookDamage, Material};
