//! Studies of the simulation's own choices, each run locally on the current rayon pool: when an
//! impact may end (`settle`), where the numerics go unstable (`stability`), speed against
//! accuracy over resolutions and numerical variants (`sweep`), and the timing of one impact
//! (`bench`). They report progress through callbacks and return rows; writing files and
//! drawing charts is the caller's.

pub mod bench;
pub mod budget;
pub mod settle;
pub mod stability;
pub mod sweep;

pub use grit_sph::InputError;

use crate::impact::sample::SampleError;
use crate::impact::ImpactParams;
use crate::models::shapes::Shape;

/// Why a study could not run or stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StudyError {
    /// An option or the scene breaks a rule; names the option (e.g. `--cfl`) or scene field.
    #[error(transparent)]
    Invalid(#[from] InputError),
    /// A sample of the study failed.
    #[error(transparent)]
    Sample(#[from] SampleError),
    /// One point of the speed–accuracy sweep failed.
    // The cause follows through `source()`: error chains print it once.
    #[error("{variant} at {ppd} per Dg")]
    Point {
        /// Name of the variant.
        variant: String,
        /// Particles per grain diameter.
        ppd: f64,
        /// What failed.
        source: SampleError,
    },
}

/// The reference scene of the studies (hexagon, 100 m/s, AISI 304; Mohseni-Mofidi et al. 2022,
/// section 4) at another angle and particle spacing.
pub fn scene(angle_deg: f64, spacing_m: f64) -> ImpactParams {
    ImpactParams {
        spacing_m,
        ..ImpactParams::paper(angle_deg, Shape::Hexagon)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error;

    #[test]
    fn a_failed_point_names_itself_and_leaves_its_cause_to_the_chain() {
        let cause = SampleError::Checkpoint("torn".into());
        let e = StudyError::Point {
            variant: "default".into(),
            ppd: 8.0,
            source: cause,
        };
        assert_eq!(e.to_string(), "default at 8 per Dg");
        assert_eq!(e.source().unwrap().to_string(), "checkpoint: torn");
    }
}
