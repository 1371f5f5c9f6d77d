//! Abrasive grains in the world (docs/jet.md#grains-in-the-world): the DEM discs of the AWJ
//! paper, coupled to a fluid body through porosity and drag (eqs. 20, 42–50) and to the
//! deformable bodies through the penalty contact (eqs. 12–14), advanced inside each SPH step.

use serde::{Deserialize, Serialize};

use super::World;
use crate::coupling::{disc_area, CouplingParams};
use crate::dem::{Dem, Grain};
use crate::error::InputError;
use crate::math::Vector;
use crate::stages;

/// The abrasive–target penalty contact's constants (the AWJ paper eq. 13); its range d_ini is
/// the world's particle spacing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PenaltyParams {
    /// Overlap coefficient χ in [0, 1) of F^n = (1 − χ)(2 m_a/Δt²)(d_ini − d_p). The paper gives
    /// no value. With the engine's kick–drift step a force F moves a particle by F Δt²/m in one
    /// step, twice what the paper's leap-frog half kick does, so χ = 0.5 removes an overlap in
    /// one step, as χ = 0 ("no overlap allowed") does in the paper's scheme.
    pub chi: f64,
    /// Coulomb friction μ between a grain and the target's particles (the paper gives none).
    pub friction: f64,
}

impl Default for PenaltyParams {
    fn default() -> Self {
        PenaltyParams {
            chi: 0.5,
            friction: 0.3,
        }
    }
}

impl PenaltyParams {
    /// Checks χ in [0, 1) and μ ≥ 0; errors name `field.<parameter>`.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        if !(self.chi.is_finite() && (0.0..1.0).contains(&self.chi)) {
            return Err(InputError::new(
                format!("{field}.chi"),
                format!("must lie in [0, 1), got {}", self.chi),
            ));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(InputError::new(
                format!("{field}.friction"),
                format!("must be a finite number >= 0, got {}", self.friction),
            ));
        }
        Ok(())
    }
}

/// A box outside which grains are deleted (the scene's outlets), and what it has deleted.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GrainOutflow {
    /// Lower-left corner (m).
    pub min_m: Vector,
    /// Upper-right corner (m).
    pub max_m: Vector,
    /// Grains deleted so far.
    pub grains: u64,
}

/// The grains of a world and how they meet the fluid and the target.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Abrasives {
    /// The grains, their walls, contact constants and gravity.
    pub dem: Dem,
    /// The unresolved coupling's constants (R_c and the drag switch).
    pub coupling: CouplingParams,
    /// The penalty contact with deformable particles.
    pub penalty: PenaltyParams,
    /// The fluid body the grains couple to; `None` for grains in vacuum.
    pub fluid_body: Option<usize>,
    /// Where grains leave the scene, if anywhere.
    pub outflow: Option<GrainOutflow>,
    /// Grains added since the set was given to the world (`World::add_grain`).
    pub added: u64,
    /// DEM sub-steps taken in the last SPH step.
    #[serde(skip)]
    pub substeps: u32,
    /// Contact starts with the target since the log was last taken
    /// (`World::take_grain_contacts`).
    #[serde(skip)]
    pub hits: Vec<GrainHit>,
    /// Grain-steps in contact with the target since the log was last taken.
    #[serde(skip)]
    pub steps_in_contact: u64,
}

/// What [`World::take_grain_contacts`] hands over: the grains' contact starts with the target
/// and how long they stayed, since it was last called.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GrainContacts {
    /// Every contact start, first touches and returns, in the order they happened (grain
    /// order within a step).
    pub starts: Vec<GrainHit>,
    /// Grain-steps in contact: over the steps, the number of grains touching in each.
    pub steps_in_contact: u64,
}

/// The start of a grain's contact with a deformable particle (the penalty contact of the AWJ
/// paper eqs. 12–14): how fast the jet delivered it, to set beside the paper's single grain in
/// a jet (166 m/s at R_c = 2 d; docs/jet.md#how-fast-the-grains-arrive).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GrainHit {
    /// Time of the step in which the contact began (s).
    pub t_s: f64,
    /// The grain's speed |v| at the start of that step (m/s).
    pub speed_m_s: f64,
    /// Its approach speed along the contact normal, (v_grain − v_particle)·n with n from the
    /// grain's centre to the particle (m/s).
    pub normal_speed_m_s: f64,
    /// Whether it is the grain's first touch of the target (else a return after leaving it).
    pub first: bool,
}

impl Abrasives {
    /// Grains `dem` coupled to fluid body `fluid_body` with `coupling`, touching the deformable
    /// bodies through `penalty`.
    pub fn new(
        dem: Dem,
        coupling: CouplingParams,
        penalty: PenaltyParams,
        fluid_body: Option<usize>,
    ) -> Self {
        Abrasives {
            dem,
            coupling,
            penalty,
            fluid_body,
            outflow: None,
            added: 0,
            substeps: 0,
            hits: Vec::new(),
            steps_in_contact: 0,
        }
    }

    /// A grain's momentum per metre of depth, the plane model's: its disc of the grain's density
    /// (kg/m · m/s). The grain carries a sphere's mass; the disc's is m · 3/(4R).
    pub fn plane_momentum(g: &Grain) -> Vector {
        g.vel * plane_mass(g)
    }
}

/// A grain's mass per metre of depth in the plane model: its disc's, ρ π R² = m · 3/(4R).
pub fn plane_mass(g: &Grain) -> f64 {
    let rho = g.mass_kg / (4.0 / 3.0 * std::f64::consts::PI * g.radius_m.powi(3));
    rho * disc_area(g.radius_m)
}

impl World {
    /// Gives the world abrasive grains (replacing any it had); the fluid body must be a fluid.
    pub fn set_abrasives(&mut self, abrasives: Abrasives) -> Result<(), InputError> {
        abrasives.coupling.validate("abrasives.coupling")?;
        abrasives.penalty.validate("abrasives.penalty")?;
        abrasives.dem.params.validate()?;
        if let Some(b) = abrasives.fluid_body {
            if self.bodies.get(b).and_then(|x| x.fluid()).is_none() {
                return Err(InputError::new(
                    "abrasives.fluid_body",
                    format!("body {b} is not a fluid body"),
                ));
            }
        }
        if let Some(o) = &abrasives.outflow {
            check_box("abrasives.outflow", o.min_m, o.max_m)?;
        }
        self.abrasives = Some(abrasives);
        Ok(())
    }

    /// Deletes grains outside the box `min_m`–`max_m` at the end of every step.
    pub fn set_grain_outflow(&mut self, min_m: Vector, max_m: Vector) -> Result<(), InputError> {
        check_box("grain_outflow", min_m, max_m)?;
        let ab = self.abrasives_mut("grain_outflow")?;
        ab.outflow = Some(GrainOutflow {
            min_m,
            max_m,
            grains: 0,
        });
        Ok(())
    }

    /// Adds a grain (a nozzle's feed); checked like the grains of [`Dem::new`].
    pub fn add_grain(&mut self, g: Grain) -> Result<(), InputError> {
        let ab = self.abrasives_mut("grain")?;
        ab.dem.add(g)?;
        ab.added += 1;
        Ok(())
    }

    /// The grains and their coupling, if the world has any.
    pub fn abrasives(&self) -> Option<&Abrasives> {
        self.abrasives.as_ref()
    }

    /// The fluid as each grain sees it now (ε_i, v̄_f and S_i of the AWJ paper eqs. 45, 46,
    /// 50), from the porosity and pairs the step's coupling stage would find at these positions;
    /// empty without abrasives or a coupled fluid, S_i = 0 for a grain with no fluid within R_c.
    pub fn grain_fluid(&self) -> Result<Vec<crate::coupling::GrainFluid>, InputError> {
        let Some(ab) = &self.abrasives else {
            return Ok(Vec::new());
        };
        let Some(fb) = ab.fluid_body else {
            return Ok(Vec::new());
        };
        let fluid = self.bodies[fb].fluid().expect("checked by set_abrasives");
        let p = &self.particles;
        let mut porosity = Vec::new();
        let frame = stages::grain_porosity(p, ab, &mut porosity)?;
        // ε_i and v̄_f do not depend on θ; the forces computed beside them are not used.
        let theta = vec![Vector::zeros(); p.len()];
        let f = stages::evaluate_coupling(p, ab, fluid, &frame, &porosity, &theta)?;
        let none = crate::coupling::GrainFluid {
            shepard: 0.0,
            porosity: 1.0,
            velocity: Vector::zeros(),
        };
        Ok(f.map_or_else(|| vec![none; ab.dem.grains.len()], |f| f.grain_fluid))
    }

    /// The grains' contact starts with the target and their grain-steps in contact since the
    /// last call; empty without abrasives.
    pub fn take_grain_contacts(&mut self) -> GrainContacts {
        self.abrasives
            .as_mut()
            .map(|ab| GrainContacts {
                starts: std::mem::take(&mut ab.hits),
                steps_in_contact: std::mem::take(&mut ab.steps_in_contact),
            })
            .unwrap_or_default()
    }

    fn abrasives_mut(&mut self, field: &str) -> Result<&mut Abrasives, InputError> {
        self.abrasives
            .as_mut()
            .ok_or_else(|| InputError::new(field, "the world has no abrasives (set_abrasives)"))
    }

    /// Deletes the grains outside the outflow box, booking them.
    pub(super) fn grain_outflow_step(&mut self) {
        let Some(ab) = self.abrasives.as_mut() else {
            return;
        };
        let Some(o) = ab.outflow.as_mut() else {
            return;
        };
        let inside = |x: Vector| {
            x.x >= o.min_m.x && x.x <= o.max_m.x && x.y >= o.min_m.y && x.y <= o.max_m.y
        };
        let before = ab.dem.grains.len();
        if ab.dem.grains.iter().all(|g| inside(g.pos)) {
            return;
        }
        ab.dem.retain(|g| inside(g.pos));
        o.grains += (before - ab.dem.grains.len()) as u64;
    }
}

fn check_box(field: &str, min_m: Vector, max_m: Vector) -> Result<(), InputError> {
    let finite = min_m.iter().chain(max_m.iter()).all(|v| v.is_finite());
    if !finite || min_m.x >= max_m.x || min_m.y >= max_m.y {
        return Err(InputError::new(
            field,
            format!("needs finite corners with min < max, got {min_m:?} to {max_m:?}"),
        ));
    }
    Ok(())
}
