//! Bodies: deformable Johnson–Cook solids, rigid bodies (grains, walls, sliders) whose
//! motion follows total force and torque (seed eq. 17), and weakly compressible fluids (the AWJ
//! paper's water, docs/jet.md#water-in-the-engine).

use serde::{Deserialize, Serialize};

use crate::fluid::Fluid;
use crate::material::Material;
use crate::math::Vector;

/// How a rigid body, or the kinematic particles of a deformable one, move.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Motion {
    /// Integrated from forces.
    Free,
    /// Never moves.
    Fixed,
    /// Prescribed velocity, ramped linearly from zero over `ramp_s` to avoid a shock.
    Velocity {
        /// Target velocity (m/s).
        velocity_m_s: Vector,
        /// Ramp time (s); 0 applies the velocity at once.
        ramp_s: f64,
    },
}

impl Motion {
    /// The prescribed velocity at time `t`, or `None` for free motion.
    pub fn velocity(&self, t: f64) -> Option<Vector> {
        match *self {
            Motion::Free => None,
            Motion::Fixed => Some(Vector::zeros()),
            Motion::Velocity {
                velocity_m_s,
                ramp_s,
            } => {
                let f = if ramp_s > 0.0 {
                    (t / ramp_s).min(1.0)
                } else {
                    1.0
                };
                Some(velocity_m_s * f)
            }
        }
    }
}

/// An external force on a rigid body per unit depth:
/// `constant + ramp · clamp((t − ramp_start_s) / ramp_s, 0, 1)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct ExternalForce {
    /// Constant part (N/m).
    pub constant_n_m: Vector,
    /// Part that grows linearly to its full value at `ramp_s` (N/m).
    pub ramp_n_m: Vector,
    /// Ramp time (s).
    pub ramp_s: f64,
    /// Time the ramp starts (s).
    pub ramp_start_s: f64,
}

impl ExternalForce {
    /// The force at time `t` (N/m).
    pub fn at(&self, t: f64) -> Vector {
        let t = t - self.ramp_start_s;
        let f = if t < 0.0 {
            0.0
        } else if self.ramp_s > 0.0 {
            (t / self.ramp_s).min(1.0)
        } else {
            1.0
        };
        self.constant_n_m + self.ramp_n_m * f
    }
}

/// State of a rigid body: mass and inertia from its polygon, integrated from eq. 17.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Rigid {
    /// Mass per unit depth (kg/m).
    pub mass_kg_m: f64,
    /// Moment of inertia about the centre of mass per unit depth (kg·m).
    pub inertia_kg_m: f64,
    /// Centre of mass (m).
    pub com_m: Vector,
    /// Rotation angle from the initial orientation (rad).
    pub angle_rad: f64,
    /// Velocity of the centre of mass (m/s).
    pub velocity_m_s: Vector,
    /// Angular velocity (rad/s).
    pub omega_rad_s: f64,
    /// How the body moves.
    pub motion: Motion,
    /// External force (N/m), besides gravity.
    pub external: ExternalForce,
    /// Total contact force of the last step (N/m), eq. 17.
    pub contact_force_n_m: Vector,
    /// Total contact torque of the last step (N), eq. 17.
    pub contact_torque_n: f64,
}

/// What a body is made of.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum BodyKind {
    /// An SPH elastic–plastic solid.
    Deformable {
        /// Its material.
        material: Material,
        /// Motion of its kinematic particles (a prescribed-motion boundary), if any.
        boundary_motion: Motion,
    },
    /// A rigid body.
    Rigid(Rigid),
    /// A weakly compressible fluid (the AWJ paper eqs. 21–27): its particles carry the
    /// porosity-weighted density ρ̄; its kinematic particles are the walls that hold it.
    Fluid {
        /// Its EOS, viscosity and artificial viscosity.
        fluid: Fluid,
        /// Motion of its kinematic (wall) particles.
        boundary_motion: Motion,
    },
}

/// A body of the scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Body {
    /// Name for reports and diagnostics.
    pub name: String,
    /// Deformable or rigid.
    pub kind: BodyKind,
    /// Mass of particles deleted for damage D ≥ 1 (kg/m), the erosion measure; for a fluid, of
    /// particles deleted out of its density range (`Fluid::density_range`).
    pub removed_mass_kg_m: f64,
    /// Number of particles deleted for damage (a fluid: out of its density range).
    pub removed_particles: u64,
}

impl Body {
    /// The rigid state, if rigid.
    pub fn rigid(&self) -> Option<&Rigid> {
        match &self.kind {
            BodyKind::Rigid(r) => Some(r),
            _ => None,
        }
    }

    /// The rigid state, mutable, if rigid.
    pub fn rigid_mut(&mut self) -> Option<&mut Rigid> {
        match &mut self.kind {
            BodyKind::Rigid(r) => Some(r),
            _ => None,
        }
    }

    /// The material, if deformable.
    pub fn material(&self) -> Option<&Material> {
        match &self.kind {
            BodyKind::Deformable { material, .. } => Some(material),
            _ => None,
        }
    }

    /// The fluid, if a fluid body.
    pub fn fluid(&self) -> Option<&Fluid> {
        match &self.kind {
            BodyKind::Fluid { fluid, .. } => Some(fluid),
            _ => None,
        }
    }

    /// True for rigid bodies.
    pub fn is_rigid(&self) -> bool {
        matches!(self.kind, BodyKind::Rigid(_))
    }
}
