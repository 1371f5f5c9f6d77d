//! Drag of a grain in the fluid: Schiller–Naumann drag coefficient, Ergun / Wen–Yu momentum
//! exchange (the AWJ paper, Sci. Rep. 14, 26115, 2024, eqs. 44, 47–49) and the terminal settling
//! velocity they give (docs/jet.md#unresolved-coupling).

use crate::error::InputError;
use crate::fluid::Fluid;
use crate::math::pow;

/// Reynolds number at and above which the Schiller–Naumann C_d is the constant 0.44 (eq. 48).
pub const NEWTON_REYNOLDS: f64 = 1000.0;

/// Porosity at and below which the drag follows Ergun, above it Wen–Yu (the AWJ paper eq. 47).
pub const DEFAULT_SWITCH_POROSITY: f64 = 0.8;

/// Grain Reynolds number Re = |v_af| ε ρ_f d/μ (the AWJ paper eq. 49).
#[inline]
pub fn reynolds(speed: f64, porosity: f64, diameter: f64, rho_f: f64, mu: f64) -> f64 {
    speed * porosity * rho_f * diameter / mu
}

/// Schiller–Naumann drag coefficient (the AWJ paper eq. 48): 24/Re (1 + 0.15 Re^0.687) below
/// Re = 1000, 0.44 from there on; +∞ at Re = 0 ([`drag_coefficient_times_re`] stays finite).
#[inline]
pub fn drag_coefficient(re: f64) -> f64 {
    if re < NEWTON_REYNOLDS {
        24.0 / re * (1.0 + 0.15 * pow(re, 0.687))
    } else {
        0.44
    }
}

/// C_d·Re of the Schiller–Naumann law (eq. 48), finite at Re = 0 where it is 24 (Stokes).
#[inline]
pub fn drag_coefficient_times_re(re: f64) -> f64 {
    if re < NEWTON_REYNOLDS {
        24.0 * (1.0 + 0.15 * pow(re, 0.687))
    } else {
        0.44 * re
    }
}

/// The drag per unit grain volume and unit slip velocity, β/(1 − ε) (kg/(m³·s)), of the AWJ
/// paper eqs. 44 and 47, so that F_d = [β/(1 − ε)] V_i v_af:
///
/// - ε ≤ `switch` (Ergun): 150 (1 − ε) μ/(ε d²) + 1.75 ρ_f |v_af|/d;
/// - ε > `switch` (Wen–Yu): 0.75 C_d ρ_f |v_af| ε^−1.65/d, written with C_d·Re so that it is
///   finite at |v_af| = 0 and at ε = 1 (a lone grain), where eq. 44's β/(1 − ε) is 0/0.
#[inline]
pub fn drag_per_volume(
    porosity: f64,
    speed: f64,
    diameter: f64,
    rho_f: f64,
    mu: f64,
    switch: f64,
) -> f64 {
    let eps = porosity;
    if eps <= switch {
        150.0 * (1.0 - eps) * mu / (eps * diameter * diameter) + 1.75 * rho_f * speed / diameter
    } else {
        // 0.75 C_d ρ_f |v| ε^−1.65/d = 0.75 (C_d Re) μ ε^−2.65/d², Re = |v| ε ρ_f d/μ.
        let re = reynolds(speed, eps, diameter, rho_f, mu);
        0.75 * drag_coefficient_times_re(re) * mu * pow(eps, -2.65) / (diameter * diameter)
    }
}

/// Stokes' terminal velocity (ρ_p − ρ_f) g d²/(18 μ) (m/s) of a sphere, the small-Re limit of
/// [`terminal_velocity`] at ε = 1.
pub fn stokes_velocity(rho_p: f64, diameter: f64, fluid: &Fluid, g: f64) -> f64 {
    (rho_p - fluid.density()) * g * diameter * diameter / (18.0 * fluid.dynamic_viscosity_pa_s)
}

/// Stokes' relaxation time τ = ρ_p d²/(18 μ) (s): a grain released at rest reaches
/// v_t (1 − e^{−t/τ}) in the Stokes limit.
pub fn stokes_relaxation_time(rho_p: f64, diameter: f64, fluid: &Fluid) -> f64 {
    rho_p * diameter * diameter / (18.0 * fluid.dynamic_viscosity_pa_s)
}

/// Terminal settling state of one grain (docs/jet.md#unresolved-coupling).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settling {
    /// Terminal slip speed (m/s); positive downwards (along g) for a grain denser than the fluid.
    pub velocity_m_s: f64,
    /// Grain Reynolds number at that speed (eq. 49).
    pub reynolds: f64,
    /// Bisection steps taken.
    pub iterations: u32,
}

/// Terminal velocity of a grain of density `rho_p` and diameter `d` settling at porosity ε under
/// gravity `g`: the speed where the drag [β/(1 − ε)] V v of eqs. 44, 47 balances the weight less
/// the buoyancy (ρ_p − ρ_f) V g, solved by bisection (the drag is increasing in v). Errors name
/// the offending argument.
pub fn terminal_velocity(
    rho_p: f64,
    diameter: f64,
    porosity: f64,
    fluid: &Fluid,
    g: f64,
    switch: f64,
) -> Result<Settling, InputError> {
    InputError::require_positive("settling.rho_p", rho_p)?;
    InputError::require_positive("settling.diameter", diameter)?;
    InputError::require_positive("settling.g", g)?;
    if !(porosity.is_finite() && porosity > 0.0 && porosity <= 1.0) {
        return Err(InputError::new(
            "settling.porosity",
            format!("must lie in (0, 1], got {porosity}"),
        ));
    }
    if !(switch.is_finite() && switch > 0.0 && switch < 1.0) {
        return Err(InputError::new(
            "settling.switch",
            format!("must lie in (0, 1), got {switch}"),
        ));
    }
    fluid.validate("settling.fluid")?;
    let (rho_f, mu) = (fluid.density(), fluid.dynamic_viscosity_pa_s);
    let excess = (rho_p - rho_f) * g;
    let k = |v: f64| drag_per_volume(porosity, v, diameter, rho_f, mu, switch);
    // The drag per volume never falls with speed, so v ≤ |excess|/k(0) bounds the root.
    let mut hi = excess.abs() / k(0.0);
    let mut lo = 0.0;
    let mut iterations = 0;
    while hi - lo > 1e-15 * hi && iterations < 200 {
        let mid = 0.5 * (lo + hi);
        if k(mid) * mid < excess.abs() {
            lo = mid;
        } else {
            hi = mid;
        }
        iterations += 1;
    }
    let v = 0.5 * (lo + hi);
    Ok(Settling {
        velocity_m_s: v.copysign(excess),
        reynolds: reynolds(v, porosity, diameter, rho_f, mu),
        iterations,
    })
}
