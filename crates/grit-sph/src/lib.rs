//! grit-sph: a 2D SPH engine for solid particle erosion, after the seed paper
//! (Mohseni-Mofidi et al., Materials 2022, 15, 286, sections 2 and 3).
//!
//! No I/O, no async: a `World` holds particles and bodies and advances them by `step()`.
#![warn(missing_docs)]

pub mod eos;
pub mod error;
pub mod fluid;
pub mod jh2;
pub mod material;
pub mod rock;

pub use eos::{EquationOfState, MieGruneisen};
pub use error::{InputError, SimError};
pub use fluid::{Fluid, FLUID_NAMES};
pub use jh2::{Jh2Damage, Jh2Laws, Jh2Strength, PolynomialEos};
pub use material::{Fracture, JohnsonCook, JohnsonCookDamage, Material, Strength, MATERIAL_NAMES};
pub mod body;
pub mod contact;
pub mod coupling;
pub mod cracks;
pub mod crater;
pub mod dem;
pub mod geometry;
pub mod kernel;
pub mod lcg;
pub mod math;
pub mod neighbours;
pub mod particles;
pub mod physics;
pub mod polling;
mod stages;
pub mod timers;
pub mod vtk;
pub mod world;

pub use body::{Body, BodyKind, ExternalForce, Motion, Rigid};
pub use contact::{cfl_matched_stiffness, ContactModel, ContactParams};
pub use geometry::Polygon;
pub use kernel::{Kernel, KernelKind};
pub use math::{Matrix, Vector};
pub use particles::{Particles, ParticlesState};
pub use timers::{Stage, Timers};
pub use world::{
    Abrasives, CeilingPass, DensityFilter, Energy, GrainOutflow, Inflow, Nozzle, NumericalWork,
    Outflow, PenaltyParams, Settings, WallLoad, World, WorldState,
};
pub mod verification;

/// Which path the pair pass (seed eqs. 4, 8–9: the kernel of each same-body pair) takes on
/// this CPU: "four at a time (AVX2)" or "pair by pair"; both give the same bits.
pub fn pair_pass() -> &'static str {
    if stages::pairs::lanes_pay() {
        "four at a time (AVX2)"
    } else {
        "pair by pair"
    }
}
