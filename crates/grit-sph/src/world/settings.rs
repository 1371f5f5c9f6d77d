//! Numerical settings of a world and their validation; the defaults are the seed's choices
//! (Mohseni-Mofidi et al., Materials 2022, 15, 286, section 2).

use serde::{Deserialize, Serialize};

use crate::error::InputError;
use crate::fluid::ArtificialViscosity;
use crate::kernel::KernelKind;
use crate::math::Vector;

/// Numerical settings of a world; defaults are the seed's choices.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Settings {
    /// Initial particle spacing Δx (m); also the contact equilibrium distance (section 3.1).
    pub spacing_m: f64,
    /// Smoothing length over spacing, h/Δx (seed: 1.3).
    pub h_over_dx: f64,
    /// Kernel function (seed: quintic spline, eq. 4).
    pub kernel: KernelKind,
    /// Courant number of the time step dt = CFL · h / max(c + |v|).
    pub cfl: f64,
    /// Gravity (m/s²).
    pub gravity_m_s2: Vector,
    /// Hourglass coefficient α of eq. 16 (0 switches hourglass control off).
    pub hourglass: f64,
    /// Steps between Shepard density filters (eq. 12; seed: 40; 0 switches it off).
    pub shepard_interval: u32,
    /// Which density filter runs every `shepard_interval` steps (seed: Shepard, eq. 12).
    pub density_filter: DensityFilter,
    /// Verlet skin over Δx: lists are rebuilt once a particle has moved half of it.
    pub skin_over_dx: f64,
    /// Upper bound of the time step (s).
    pub dt_max_s: f64,
    /// Fraction of plastic work turned into heat (Taylor–Quinney coefficient).
    pub taylor_quinney: f64,
    /// Initial temperature of deformable bodies (K).
    pub temperature_k: f64,
    /// Whether the contact springs may shorten the time step below the material's CFL step.
    /// Off, a stiff spring is integrated with too long a step: the stability map needs that.
    pub contact_limits_dt: bool,
    /// Rigid bodies keep only their outline layer of particles: interior particles of a rigid body are never searched, touched or summed, and its mass
    /// and inertia come from the polygon, so dropping them changes no result.
    pub rigid_shell: bool,
    /// Monaghan artificial viscosity of the deformable bodies' pairs (the AWJ paper eq. 26,
    /// α = β = 1.0 in its solid phase); `None`, the impact scene's choice, adds none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solid_viscosity: Option<ArtificialViscosity>,
}

/// The largest Courant number `Settings` accepts.
pub const MAX_CFL: f64 = 2.0;
/// Smallest Courant number a scene may ask for: a hundred times more steps than the seed's
/// 0.3 is a typo, not a setting.
pub const MIN_CFL: f64 = 1e-3;
/// Largest hourglass coefficient (eq. 16): 100 times the seed's 0.1.
pub const MAX_HOURGLASS: f64 = 10.0;

impl Default for Settings {
    fn default() -> Self {
        Settings {
            spacing_m: 8e-6,
            h_over_dx: 1.3,
            kernel: KernelKind::Quintic,
            cfl: 0.3,
            gravity_m_s2: Vector::zeros(),
            hourglass: 0.1,
            shepard_interval: 40,
            density_filter: DensityFilter::Shepard,
            skin_over_dx: 0.5,
            dt_max_s: 1e-3,
            taylor_quinney: 0.9,
            temperature_k: 293.0,
            contact_limits_dt: true,
            rigid_shell: false,
            solid_viscosity: None,
        }
    }
}

impl Settings {
    /// The water-jet paper's Courant number C_F (its eq. 51).
    pub const WATER_JET_CFL: f64 = 0.2;

    /// The water-jet paper's numerics (seed 002, docs/jet.md): cubic spline at h = 1.25 Δx,
    /// Courant number C_F = 0.2, no density filter, the solid phase's artificial viscosity
    /// α = β = 1.0, at spacing `spacing_m` under `gravity_m_s2`.
    pub fn water_jet(spacing_m: f64, gravity_m_s2: Vector) -> Settings {
        Settings {
            spacing_m,
            h_over_dx: 1.25,
            kernel: KernelKind::CubicSpline,
            cfl: Self::WATER_JET_CFL,
            gravity_m_s2,
            shepard_interval: 0,
            solid_viscosity: Some(ArtificialViscosity::SOLID),
            ..Settings::default()
        }
    }

    /// Checks that every setting is usable; the error names the field.
    pub fn validate(&self) -> Result<(), InputError> {
        let pos = |f: &str, v: f64| InputError::require_positive(f, v);
        pos("spacing_m", self.spacing_m)?;
        pos("h_over_dx", self.h_over_dx)?;
        pos("cfl", self.cfl)?;
        // Above 1 the step is unstable in every case `grit bench stability` maps; up to 2 is
        // allowed so that the map can show where.
        if !(MIN_CFL..=MAX_CFL).contains(&self.cfl) {
            return Err(InputError::new(
                "cfl",
                format!(
                    "must lie in [{MIN_CFL}, {MAX_CFL}] for an explicit step, got {}",
                    self.cfl
                ),
            ));
        }
        pos("skin_over_dx", self.skin_over_dx)?;
        pos("dt_max_s", self.dt_max_s)?;
        pos("temperature_k", self.temperature_k)?;
        if !(self.hourglass.is_finite() && (0.0..=MAX_HOURGLASS).contains(&self.hourglass)) {
            return Err(InputError::new(
                "hourglass",
                format!(
                    "must lie in [0, {MAX_HOURGLASS}] (the seed's is 0.1), got {}",
                    InputError::shown(self.hourglass)
                ),
            ));
        }
        if !(self.taylor_quinney.is_finite() && (0.0..=1.0).contains(&self.taylor_quinney)) {
            return Err(InputError::new(
                "taylor_quinney",
                format!("must lie in [0, 1], got {}", self.taylor_quinney),
            ));
        }
        if !(self.gravity_m_s2.x.is_finite() && self.gravity_m_s2.y.is_finite()) {
            return Err(InputError::new("gravity_m_s2", "must be finite"));
        }
        if let Some(av) = &self.solid_viscosity {
            av.validate("solid_viscosity")?;
        }
        Ok(())
    }
}

/// The periodic density re-initialisation: the seed's zeroth-order Shepard average (eq. 12), or
/// its first-order moving-least-squares form (Colagrossi & Landrini 2003, Dilts 1999).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum DensityFilter {
    /// Eq. 12: a kernel-weighted average. It flattens any density gradient over a kernel
    /// width, so it also damps resolved elastic waves, and most at a free surface.
    #[default]
    Shepard,
    /// Eq. 12 with the kernel corrected to reproduce linear fields, at free surfaces too: it
    /// removes particle-scale noise and leaves resolved strain gradients almost untouched.
    Mls,
}
