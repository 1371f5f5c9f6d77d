//! The water of the abrasive water-jet scene: its preset and the per-pair terms of the fluid's
//! SPH equations with porosity-weighted density ρ̄ = ε ρ (the AWJ paper, Sci. Rep. 14, 26115,
//! 2024, eqs. 21–27; docs/jet.md#water).
//!
//! Every pair function takes ∇W = ∇_a W_ab (from [`grad_w`]), x_ab = x_a − x_b and
//! v_ab = v_a − v_b, and returns particle a's share; particle b's is the same call with the
//! roles swapped.

use serde::{Deserialize, Serialize};

use crate::eos::MieGruneisen;
use crate::error::InputError;
use crate::kernel::Kernel;
use crate::math::Vector;

/// Names [`Fluid::by_name`] knows, in the order error messages list them.
pub const FLUID_NAMES: [&str; 1] = ["water"];

/// Monaghan's artificial viscosity coefficients α_π, β_π (the AWJ paper eqs. 26–27).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArtificialViscosity {
    /// Linear (bulk-viscosity) coefficient α_π (–).
    pub alpha: f64,
    /// Quadratic (anti-penetration) coefficient β_π (–).
    pub beta: f64,
}

impl ArtificialViscosity {
    /// α_π = β_π = 0.1, the AWJ paper's choice for the fluid phase (text after eq. 27).
    pub const WATER: ArtificialViscosity = ArtificialViscosity {
        alpha: 0.1,
        beta: 0.1,
    };

    /// α_π = β_π = 1.0, the AWJ paper's choice for the solid phase (text after eq. 27).
    pub const SOLID: ArtificialViscosity = ArtificialViscosity {
        alpha: 1.0,
        beta: 1.0,
    };

    /// Π_ab of the AWJ paper eqs. 26–27 (m⁵/(kg·s²), i.e. a pressure over a squared density):
    /// (−α c̄ φ + β φ²)/ρ̄_ab for approaching pairs (v_ab·x_ab < 0), 0 otherwise, with
    /// φ = h̄ v_ab·x_ab/(|x_ab|² + (0.1 h̄)²). Symmetric in a and b.
    #[inline]
    pub fn pi_ab(
        &self,
        x_ab: Vector,
        v_ab: Vector,
        c_mean: f64,
        rho_mean: f64,
        h_mean: f64,
    ) -> f64 {
        let vx = v_ab.dot(&x_ab);
        if vx >= 0.0 {
            return 0.0;
        }
        let phi = h_mean * vx / (x_ab.norm_squared() + 0.01 * h_mean * h_mean);
        (-self.alpha * c_mean * phi + self.beta * phi * phi) / rho_mean
    }

    /// Checks α, β finite and ≥ 0; errors name `field.alpha` or `field.beta`.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        for (name, v) in [("alpha", self.alpha), ("beta", self.beta)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(InputError::new(
                    format!("{field}.{name}"),
                    format!("must be a finite number >= 0, got {v}"),
                ));
            }
        }
        Ok(())
    }
}

/// A weakly compressible fluid: Mie–Grüneisen EOS (the AWJ paper eq. 24), dynamic viscosity for
/// the Shao–Lo term (eq. 25) and the drag laws (eqs. 47–49), artificial viscosity (eq. 26) and the
/// lowest pressure it sustains.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fluid {
    /// Name used in reports.
    pub name: String,
    /// Pressure law; its ρ0 is the fluid's reference density.
    pub eos: MieGruneisen,
    /// Dynamic viscosity μ (Pa·s).
    pub dynamic_viscosity_pa_s: f64,
    /// Artificial viscosity coefficients of the fluid phase.
    pub artificial_viscosity: ArtificialViscosity,
    /// Lowest (gauge) pressure the fluid sustains (Pa, ≤ 0): the EOS's tension branch is cut here,
    /// where the liquid would cavitate (docs/jet.md#water).
    pub min_pressure_pa: f64,
    /// Coefficient δ of the density diffusion of Molteni & Colagrossi (2009) in the continuity
    /// equation, δ h c0 Σ_b 2 (ρ̄_b − ρ̄_a) (−dW/dr / r) V_b; 0 (the AWJ paper's equations, and
    /// the default) adds none. DualSPHysics's usual value is 0.1 (docs/jet.md#the-scene).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub density_diffusion: f64,
    /// Free particles whose density leaves [lo ρ0, hi ρ0] are deleted at the end of the step
    /// and booked as the body's removed mass (DualSPHysics's `RhopOut`): spray that has thinned
    /// to a fraction of water's density no longer stands for liquid, and its volume m/ρ̄ would
    /// swamp its neighbours' sums. `None` (the default) keeps every particle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_range: Option<[f64; 2]>,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// Gauge pressure at which water at 20 °C boils under 1 atm: vapour pressure 2.34 kPa minus
/// 101.325 kPa (docs/references.md#water).
pub const WATER_CAVITATION_GAUGE_PA: f64 = 2.34e3 - 101.325e3;

impl Fluid {
    /// Water: the hydrocode Mie–Grüneisen set (`MieGruneisen::water`), μ = 1e-3 Pa·s (ν = 1e-6 m²/s as in the AWJ paper),
    /// α_π = β_π = 0.1, cut at the cavitation pressure (docs/references.md#water).
    pub fn water() -> Self {
        Fluid {
            name: "water".into(),
            eos: MieGruneisen::water(),
            dynamic_viscosity_pa_s: 1.0e-3,
            artificial_viscosity: ArtificialViscosity::WATER,
            min_pressure_pa: WATER_CAVITATION_GAUGE_PA,
            density_diffusion: 0.0,
            density_range: None,
        }
    }

    /// The preset called `name` (one of [`FLUID_NAMES`]); an unknown name is an error on field
    /// `fluid` that names it and lists the known ones.
    pub fn by_name(name: &str) -> Result<Self, InputError> {
        match name {
            "water" => Ok(Self::water()),
            _ => Err(InputError::new(
                "fluid",
                format!(
                    "unknown fluid `{name}`; known names: {}, or a full fluid object",
                    FLUID_NAMES.join(", ")
                ),
            )),
        }
    }

    /// Checks every constant; errors name `field.<constant>` and the rule.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        self.eos.validate(&format!("{field}.eos"))?;
        InputError::require_positive(
            format!("{field}.dynamic_viscosity_pa_s"),
            self.dynamic_viscosity_pa_s,
        )?;
        self.artificial_viscosity
            .validate(&format!("{field}.artificial_viscosity"))?;
        if !(self.density_diffusion.is_finite() && (0.0..=1.0).contains(&self.density_diffusion)) {
            return Err(InputError::new(
                format!("{field}.density_diffusion"),
                format!("must lie in [0, 1], got {}", self.density_diffusion),
            ));
        }
        if let Some([lo, hi]) = self.density_range {
            if !(lo.is_finite() && hi.is_finite() && 0.0 < lo && lo < 1.0 && hi > 1.0) {
                return Err(InputError::new(
                    format!("{field}.density_range"),
                    format!("must be [lo, hi] with 0 < lo < 1 < hi, got [{lo}, {hi}]"),
                ));
            }
        }
        if !(self.min_pressure_pa.is_finite() && self.min_pressure_pa <= 0.0) {
            return Err(InputError::new(
                format!("{field}.min_pressure_pa"),
                format!(
                    "must be a finite number <= 0 (a gauge pressure), got {}",
                    self.min_pressure_pa
                ),
            ));
        }
        Ok(())
    }

    /// Reference density ρ0 (kg/m³), the EOS's.
    pub fn density(&self) -> f64 {
        self.eos.rho0_kg_m3
    }

    /// Kinematic viscosity ν = μ/ρ0 (m²/s), the ν of the Shao–Lo term (the AWJ paper eq. 25).
    pub fn kinematic_viscosity(&self) -> f64 {
        self.dynamic_viscosity_pa_s / self.eos.rho0_kg_m3
    }

    /// Pressure (Pa) of a fluid particle from its porosity-weighted density ρ̄ (the AWJ paper eq.
    /// 21), porosity ε ∈ (0, 1] and specific internal energy e (J/kg; 0 without an energy
    /// equation): the EOS (eq. 24) at the fluid's own density ρ = ρ̄/ε, floored at
    /// `min_pressure_pa` (docs/jet.md#water, the choices).
    #[inline]
    pub fn pressure(&self, rho_bar: f64, porosity: f64, e: f64) -> f64 {
        self.eos
            .pressure(rho_bar / porosity, e)
            .max(self.min_pressure_pa)
    }

    /// The density ρ (kg/m³) at which the EOS's cold curve (eq. 24, e = 0) gives the gauge
    /// pressure `pressure_pa`: the inverse of [`Self::pressure`] at ε = 1, for setting up a
    /// fluid at rest under a known pressure (a hydrostatic column). An error on `field` for a
    /// pressure that is not finite, below `min_pressure_pa`, or beyond what the law reaches short
    /// of its singular compression.
    pub fn density_at(&self, pressure_pa: f64, field: &str) -> Result<f64, InputError> {
        if !(pressure_pa.is_finite() && pressure_pa >= self.min_pressure_pa) {
            return Err(InputError::new(
                field,
                format!(
                    "must be a finite pressure >= min_pressure_pa ({} Pa), got {pressure_pa}",
                    self.min_pressure_pa
                ),
            ));
        }
        let g = &self.eos;
        let rho0 = g.rho0_kg_m3;
        if pressure_pa <= 0.0 {
            // The tension branch is linear.
            return Ok(rho0 * (1.0 + pressure_pa / g.bulk_modulus()));
        }
        // The compression branch rises from 0 until its numerator's η² term or the singular
        // compression turns it over: the bracket doubles while the pressure still rises, within
        // the 0.9 of the singular compression the engine evaluates.
        let p_at = |eta: f64| g.pressure(rho0 * (1.0 + eta), 0.0);
        let cap = 0.9 * g.singular_compression().min(10.0);
        let mut eta_max = 1e-3_f64.min(cap);
        while 2.0 * eta_max <= cap && p_at(2.0 * eta_max) > p_at(eta_max) {
            eta_max *= 2.0;
        }
        let hi_p = p_at(eta_max);
        if pressure_pa > hi_p {
            return Err(InputError::new(
                field,
                format!("{pressure_pa} Pa is beyond the EOS's range (at most {hi_p:.4e} Pa)"),
            ));
        }
        let (mut lo, mut hi) = (0.0, eta_max);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if p_at(mid) < pressure_pa {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(rho0 * (1.0 + 0.5 * (lo + hi)))
    }

    /// Sound speed (m/s) at the fluid's own density ρ = ρ̄/ε: √(dp/dρ) of the EOS's cold curve,
    /// c0 at rest and in tension (for the CFL limit and c̄ of eq. 26).
    #[inline]
    pub fn sound_speed(&self, rho_bar: f64, porosity: f64) -> f64 {
        self.eos.sound_speed(rho_bar / porosity)
    }
}

/// ∇_a W_ab = (x_ab/r) dW/dr (1/m³) for x_ab = x_a − x_b; zero at r = 0 and beyond the support.
#[inline]
pub fn grad_w(kernel: &Kernel, x_ab: Vector) -> Vector {
    let r = x_ab.norm();
    if r <= 0.0 {
        return Vector::zeros();
    }
    let (_, dw) = kernel.w_dw(r);
    x_ab * (dw / r)
}

/// Particle a's continuity rate term ρ̄_a (m_b/ρ̄_b) v_ab·∇_a W_ab (kg/(m³·s) in 2D per metre of
/// depth), the AWJ paper eq. 22 with porosity-weighted densities ρ̄ = ε ρ.
#[inline]
pub fn continuity_rate(
    rho_bar_a: f64,
    m_b: f64,
    rho_bar_b: f64,
    v_ab: Vector,
    grad: Vector,
) -> f64 {
    rho_bar_a * (m_b / rho_bar_b) * v_ab.dot(&grad)
}

/// Particle a's pressure acceleration −m_b (P_a/ρ̄_a² + P_b/ρ̄_b²) ∇_a W_ab (m/s²), the first
/// term of the AWJ paper eq. 23.
#[inline]
pub fn pressure_acceleration(
    m_b: f64,
    p_a: f64,
    rho_bar_a: f64,
    p_b: f64,
    rho_bar_b: f64,
    grad: Vector,
) -> Vector {
    -grad * (m_b * (p_a / (rho_bar_a * rho_bar_a) + p_b / (rho_bar_b * rho_bar_b)))
}

/// The laminar viscosity of Shao & Lo (2003), the AWJ paper eq. 25, for a fluid of kinematic
/// viscosity ν with smoothing length h.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaoLo {
    /// Kinematic viscosity ν (m²/s).
    pub nu: f64,
    /// Smoothing length h (m): 0.01 h² keeps the pair term finite as |x_ab| → 0.
    pub h: f64,
}

impl ShaoLo {
    /// Particle a's laminar viscous acceleration (m/s²) from its pair with b:
    /// 4 ν m_b (x_ab·∇_a W_ab) / [(ρ̄_a + ρ̄_b)(|x_ab|² + 0.01 h²)] v_ab; summed over the
    /// neighbours it approximates ν ∇²v.
    #[inline]
    pub fn acceleration(
        &self,
        m_b: f64,
        rho_bar_a: f64,
        rho_bar_b: f64,
        x_ab: Vector,
        v_ab: Vector,
        grad: Vector,
    ) -> Vector {
        let (nu, h) = (self.nu, self.h);
        let r2 = x_ab.norm_squared();
        v_ab * (4.0 * nu * m_b * x_ab.dot(&grad) / ((rho_bar_a + rho_bar_b) * (r2 + 0.01 * h * h)))
    }
}

/// Particle a's artificial viscous acceleration −m_b Π_ab ∇_a W_ab (m/s²), the π^art term of the
/// AWJ paper eq. 23 with Π_ab from [`ArtificialViscosity::pi_ab`].
#[inline]
pub fn artificial_viscosity_acceleration(m_b: f64, pi_ab: f64, grad: Vector) -> Vector {
    -grad * (m_b * pi_ab)
}

/// Particle a's share of the heat its artificial viscosity dissipates with b (J/kg/s),
/// ½ m_b Π_ab v_ab·∇_a W_ab (Monaghan 1992, eq. 2.27): each end takes half of the work the
/// pair's viscous forces take from the motion.
#[inline]
pub fn viscous_heating(m_b: f64, pi_ab: f64, v_ab: Vector, grad: Vector) -> f64 {
    0.5 * m_b * pi_ab * v_ab.dot(&grad)
}

#[cfg(test)]
mod tests;
