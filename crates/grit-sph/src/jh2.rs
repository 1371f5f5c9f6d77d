//! The Johnson–Holmquist (JH-2) model of a brittle solid, as the AWJ paper writes it for rock
//! (its eqs. 38–41; Johnson & Holmquist 1994): strength normalised at the Hugoniot elastic limit,
//! damage from plastic strain, and the polynomial EOS with bulking (docs/jet.md#rock-targets).
//!
//! The constants live in three structs, one per law of a [`Material`](crate::Material):
//! [`Jh2Strength`] (its `plasticity`), [`Jh2Damage`] (its `damage`) and [`PolynomialEos`] (its
//! `eos`). The functions here are pure, so the verification rows can check them against the
//! formulas and the stress stage can call them per particle.

use serde::{Deserialize, Serialize};

use crate::error::InputError;
use crate::math::{ln, pow, Matrix};
use crate::particles::{dev_contract, von_mises};

/// JH-2 strength constants (AWJ paper eq. 38), SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Jh2Strength {
    /// Intact strength coefficient A (–).
    pub a: f64,
    /// Intact strength pressure exponent N (–).
    pub n: f64,
    /// Fractured strength coefficient B (–).
    pub b: f64,
    /// Fractured strength pressure exponent M (–).
    pub m: f64,
    /// Strain-rate coefficient C (–).
    pub c: f64,
    /// Reference strain rate ε̇0 (1/s); the AWJ paper's 1 s⁻¹.
    pub ref_strain_rate_s: f64,
    /// Largest normalised fractured strength σ*_fmax (–).
    pub sfmax: f64,
    /// Hugoniot elastic limit HEL (Pa): the longitudinal stress of a uniaxial-strain wave at yield.
    pub hel_pa: f64,
    /// Pressure at the HEL, P_HEL (Pa).
    pub p_hel_pa: f64,
    /// Largest hydrostatic tension T (Pa) of the intact material.
    pub t_pa: f64,
}

/// JH-2 damage constants (AWJ paper eq. 39).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Jh2Damage {
    /// D1 of ε_f = D1 (P* + T*)^D2 (–).
    pub d1: f64,
    /// D2 (–).
    pub d2: f64,
    /// Smallest fracture strain ε_f,min (–): LS-DYNA's EFMIN; 0 lets a particle in tension
    /// (P* → −T*) fracture at its first plastic strain, as the bare law does.
    pub ef_min: f64,
}

/// Polynomial EOS of JH-2 (AWJ paper eqs. 40–41): P = K1 μ + K2 μ² + K3 μ³ + ΔP for μ ≥ 0 and
/// K1 μ + ΔP for μ < 0 (μ = ρ/ρ0 − 1), ΔP the bulking pressure.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolynomialEos {
    /// Reference density ρ0 (kg/m³).
    pub rho0_kg_m3: f64,
    /// Bulk modulus K1 (Pa).
    pub k1_pa: f64,
    /// Quadratic coefficient K2 (Pa).
    pub k2_pa: f64,
    /// Cubic coefficient K3 (Pa).
    pub k3_pa: f64,
    /// Bulking fraction β of eq. 41 (0 ≤ β ≤ 1): the share of the lost elastic shear energy
    /// that becomes hydrostatic potential energy.
    pub beta: f64,
}

impl PolynomialEos {
    /// The polynomial of eq. 40 at compression μ, without bulking: K1 μ + K2 μ² + K3 μ³ in
    /// compression, K1 μ in tension.
    #[inline]
    pub fn cold(&self, mu: f64) -> f64 {
        if mu < 0.0 {
            self.k1_pa * mu
        } else {
            mu * (self.k1_pa + mu * (self.k2_pa + mu * self.k3_pa))
        }
    }

    /// Pressure (Pa) at density `rho` with bulking pressure `bulking` (Pa): eq. 40 with ΔP on both
    /// branches (docs/jet.md#rock-targets says why the tension branch keeps it).
    #[inline]
    pub fn pressure(&self, rho: f64, bulking: f64) -> f64 {
        self.cold(rho / self.rho0_kg_m3 - 1.0) + bulking
    }

    /// Slope dP/dρ at ρ0 times ρ0: K1, the small-strain bulk modulus and the CFL signal.
    pub fn bulk_modulus(&self) -> f64 {
        self.k1_pa
    }

    /// The bulking pressure after a step that released `du` (J/m³, ≥ 0) of elastic shear energy
    /// at compression `mu`, from `bulking` before it (AWJ paper eq. 41):
    /// ΔP' = −K1 μ + √((K1 μ + ΔP)² + 2 β K1 ΔU).
    #[inline]
    pub fn bulked(&self, bulking: f64, mu: f64, du: f64) -> f64 {
        if du <= 0.0 || self.beta == 0.0 {
            return bulking;
        }
        let k1mu = self.k1_pa * mu;
        let s = k1mu + bulking;
        -k1mu + (s * s + 2.0 * self.beta * self.k1_pa * du).sqrt()
    }

    /// Checks the constants; errors name `field.<constant>`.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        InputError::require_positive(format!("{field}.rho0_kg_m3"), self.rho0_kg_m3)?;
        InputError::require_positive(format!("{field}.k1_pa"), self.k1_pa)?;
        for (name, v) in [("k2_pa", self.k2_pa), ("k3_pa", self.k3_pa)] {
            if !v.is_finite() {
                return Err(InputError::new(
                    format!("{field}.{name}"),
                    format!("must be finite, got {v}"),
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.beta) {
            return Err(InputError::new(
                format!("{field}.beta"),
                format!("must lie in [0, 1], got {}", self.beta),
            ));
        }
        Ok(())
    }
}

impl Jh2Strength {
    /// σ_HEL = 3/2 (HEL − P_HEL) (Pa): the von Mises stress at the HEL, the strengths' unit.
    #[inline]
    pub fn sigma_hel(&self) -> f64 {
        1.5 * (self.hel_pa - self.p_hel_pa)
    }

    /// The rate factor 1 + C ln ε̇*, held at 1 below ε̇0 so the logarithm never softens.
    #[inline]
    pub fn rate_factor(&self, rate: f64) -> f64 {
        if rate > self.ref_strain_rate_s {
            1.0 + self.c * ln(rate / self.ref_strain_rate_s)
        } else {
            1.0
        }
    }

    /// Normalised intact strength σ*_i = A (P* + T*)^N (1 + C ln ε̇*) (eq. 38), 0 at or below
    /// P* = −T*.
    #[inline]
    pub fn intact(&self, pressure: f64, rate: f64) -> f64 {
        let x = (pressure + self.t_pa) / self.p_hel_pa;
        if x <= 0.0 {
            0.0
        } else {
            self.a * pow(x, self.n) * self.rate_factor(rate)
        }
    }

    /// Normalised fractured strength σ*_f = B (P*)^M (1 + C ln ε̇*) ≤ σ*_fmax (eq. 38), 0 in
    /// tension.
    #[inline]
    pub fn fractured(&self, pressure: f64, rate: f64) -> f64 {
        let x = pressure / self.p_hel_pa;
        if x <= 0.0 {
            0.0
        } else {
            (self.b * pow(x, self.m) * self.rate_factor(rate)).min(self.sfmax)
        }
    }

    /// Yield stress σ_y = σ_HEL [σ*_i − D (σ*_i − σ*_f)] (Pa) at pressure `pressure`, strain rate
    /// `rate` and damage `damage` (eq. 38).
    #[inline]
    pub fn yield_stress(&self, pressure: f64, rate: f64, damage: f64) -> f64 {
        let si = self.intact(pressure, rate);
        let sf = self.fractured(pressure, rate);
        self.sigma_hel() * (si - damage * (si - sf))
    }

    /// Checks the constants; errors name `field.<constant>`.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        for (name, v) in [
            ("a", self.a),
            ("n", self.n),
            ("m", self.m),
            ("ref_strain_rate_s", self.ref_strain_rate_s),
            ("hel_pa", self.hel_pa),
            ("p_hel_pa", self.p_hel_pa),
        ] {
            InputError::require_positive(format!("{field}.{name}"), v)?;
        }
        for (name, v) in [
            ("b", self.b),
            ("c", self.c),
            ("sfmax", self.sfmax),
            ("t_pa", self.t_pa),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(InputError::new(
                    format!("{field}.{name}"),
                    format!("must be >= 0, got {v}"),
                ));
            }
        }
        if self.p_hel_pa >= self.hel_pa {
            return Err(InputError::new(
                format!("{field}.p_hel_pa"),
                format!(
                    "must be below hel_pa ({}), got {}: σ_HEL = 1.5 (HEL − P_HEL) must be > 0",
                    self.hel_pa, self.p_hel_pa
                ),
            ));
        }
        Ok(())
    }
}

impl Jh2Damage {
    /// Fracture strain ε_f = D1 (P* + T*)^D2 (eq. 39), at least `ef_min`; 0 at or below P* = −T*.
    #[inline]
    pub fn fracture_strain(&self, s: &Jh2Strength, pressure: f64) -> f64 {
        let x = (pressure + s.t_pa) / s.p_hel_pa;
        let ef = if x <= 0.0 {
            0.0
        } else {
            self.d1 * pow(x, self.d2)
        };
        ef.max(self.ef_min)
    }

    /// Checks the constants; errors name `field.<constant>`.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        InputError::require_positive(format!("{field}.d1"), self.d1)?;
        if !self.d2.is_finite() {
            return Err(InputError::new(
                format!("{field}.d2"),
                format!("must be finite, got {}", self.d2),
            ));
        }
        if !(self.ef_min.is_finite() && self.ef_min >= 0.0) {
            return Err(InputError::new(
                format!("{field}.ef_min"),
                format!("must be >= 0, got {}", self.ef_min),
            ));
        }
        Ok(())
    }
}

/// The three JH-2 laws of one material together: the stress update and the pressure read all
/// three (the tensile cut of the pressure is the strength's T, the bulking needs the strength).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jh2Laws {
    /// Strength (eq. 38).
    pub strength: Jh2Strength,
    /// Damage (eq. 39).
    pub damage: Jh2Damage,
    /// Polynomial EOS with bulking (eqs. 40–41).
    pub eos: PolynomialEos,
}

/// A particle's JH-2 state that one step changes: deviatoric stress, plastic strain, damage and
/// bulking pressure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jh2State {
    /// In-plane deviatoric stress (Pa).
    pub sdev: Matrix,
    /// Equivalent plastic strain (–).
    pub eps_p: f64,
    /// Damage D (–), 0 intact, 1 fractured.
    pub damage: f64,
    /// Bulking pressure ΔP (Pa).
    pub bulking: f64,
}

/// What one JH-2 step did besides the new state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jh2Step {
    /// The state after the step.
    pub state: Jh2State,
    /// Plastic strain increment Δε_p (–).
    pub d_eps: f64,
    /// Yield stress the deviator was returned to (Pa), or the trial's von Mises stress when
    /// elastic.
    pub sigma_y: f64,
    /// Elastic shear energy released by the damage of the step, ΔU of eq. 41 (J/m³).
    pub released: f64,
}

/// Equivalent strain rate √(2/3 ė:ė) of the in-plane rate of deformation `d` (1/s), with the
/// plane-strain out-of-plane deviator: the ε̇ of JH-2's rate term.
#[inline]
pub fn equivalent_rate(d: &Matrix) -> f64 {
    let dev = d - Matrix::identity() * (d.trace() / 3.0);
    (2.0 / 3.0 * dev_contract(&dev)).sqrt()
}

/// One JH-2 stress update (AWJ paper eqs. 38–41) from the trial deviator `s_trial` (after the
/// Jaumann rate), the particle's state `st` at density `rho`, its total equivalent strain rate
/// `rate` and shear modulus `shear`:
///
/// 1. the pressure from the polynomial EOS with the state's bulking, never below −T (1 − D);
/// 2. the yield stress of eq. 38 at the state's damage; a trial above it is returned radially,
///    Δε_p = (σ_eq − σ_y)/(3G);
/// 3. D += Δε_p / ε_f (eq. 39), at most 1; a fractured particle (D = 1) no longer gains plastic
///    strain (the AWJ paper, after eq. 39) and keeps a deviator up to the fractured strength
///    σ_HEL σ*_f (eq. 38 at D = 1), none at P ≤ 0 (docs/jet.md#rock-targets: the paper's text
///    zeroes it, its eq. 38 does not);
/// 4. the elastic shear energy released as D grows, ΔU = (σ_y(D)² − σ_y(D')²)/(6G) at the step's
///    pressure, feeds the bulking pressure of eq. 41.
///
/// The pressure is held through the step, as hydrocodes do, so the update is explicit.
pub fn jh2_update(
    s_trial: Matrix,
    st: Jh2State,
    rho: f64,
    rate: f64,
    shear: f64,
    laws: &Jh2Laws,
) -> Jh2Step {
    let Jh2Laws {
        strength,
        damage: damage_law,
        eos,
    } = laws;
    let pressure = pressure_of(laws, rho, st.bulking, st.damage);
    if st.damage >= 1.0 {
        // Comminuted rock: frictional strength under compression, none in tension.
        let sf = strength.sigma_hel() * strength.fractured(pressure, rate);
        let seq = von_mises(&s_trial);
        let sdev = if seq <= sf {
            s_trial
        } else if sf > 0.0 {
            s_trial * (sf / seq)
        } else {
            Matrix::zeros()
        };
        return Jh2Step {
            state: Jh2State { sdev, ..st },
            d_eps: 0.0,
            sigma_y: seq.min(sf),
            released: 0.0,
        };
    }
    let sy = strength.yield_stress(pressure, rate, st.damage);
    let seq = von_mises(&s_trial);
    if seq <= sy {
        return Jh2Step {
            state: Jh2State {
                sdev: s_trial,
                ..st
            },
            d_eps: 0.0,
            sigma_y: seq,
            released: 0.0,
        };
    }
    let d_eps = (seq - sy) / (3.0 * shear);
    let ef = damage_law.fracture_strain(strength, pressure);
    let damage = if ef > 0.0 {
        (st.damage + d_eps / ef).min(1.0)
    } else {
        1.0
    };
    let sy_new = strength.yield_stress(pressure, rate, damage);
    let released = ((sy * sy - sy_new * sy_new) / (6.0 * shear)).max(0.0);
    let mu = rho / eos.rho0_kg_m3 - 1.0;
    let bulking = eos.bulked(st.bulking, mu, released);
    // A particle fractured in this step drops at once to the fractured strength.
    let sdev = if damage >= 1.0 {
        s_trial * (strength.sigma_hel() * strength.fractured(pressure, rate) / seq)
    } else {
        s_trial * (sy / seq)
    };
    Jh2Step {
        state: Jh2State {
            sdev,
            eps_p: st.eps_p + d_eps,
            damage,
            bulking,
        },
        d_eps,
        sigma_y: sy,
        released,
    }
}

/// The pressure of a JH-2 particle (Pa): the polynomial EOS at `rho` with bulking `bulking`,
/// never below −T (1 − D) (Johnson & Holmquist 1994), so a fractured particle carries no tension.
#[inline]
pub fn pressure_of(laws: &Jh2Laws, rho: f64, bulking: f64, damage: f64) -> f64 {
    laws.eos
        .pressure(rho, bulking)
        .max(-laws.strength.t_pa * (1.0 - damage.min(1.0)))
}

/// The least density of a JH-2 particle (kg/m³): where the tension branch of eq. 40 meets the
/// cut −T (1 − D), ρ0 (1 + μ_cut) with K1 μ_cut + ΔP = −T (1 − D), never above ρ0. Stretched
/// past it, rock opens voids between its fragments instead of thinning its solid
/// (docs/jet.md#rock-targets): the pressure there is the cut's either way, and the particle's
/// volume m/ρ stays that of its solid in every pair sum.
#[inline]
pub fn least_density(laws: &Jh2Laws, bulking: f64, damage: f64) -> f64 {
    let cut = -laws.strength.t_pa * (1.0 - damage.min(1.0));
    let mu = ((cut - bulking) / laws.eos.k1_pa).min(0.0);
    laws.eos.rho0_kg_m3 * (1.0 + mu)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;

    #[test]
    fn the_least_density_is_where_the_tension_is_cut() {
        let l = Material::sandstone().jh2().expect("sandstone is JH-2");
        for (bulking, damage) in [(0.0, 0.0), (0.0, 0.5), (3e7, 1.0), (0.0, 1.0)] {
            let rho = least_density(&l, bulking, damage);
            assert!(rho <= l.eos.rho0_kg_m3);
            let cut = -l.strength.t_pa * (1.0 - damage);
            // At the least density the EOS gives the cut, to rounding (1 mPa).
            let p = l.eos.pressure(rho, bulking);
            assert!(
                (p - cut).abs() < 1e-3,
                "{bulking} {damage}: {p} against {cut}"
            );
        }
        // A fractured, unbulked particle keeps its solid's density.
        assert_eq!(least_density(&l, 0.0, 1.0), l.eos.rho0_kg_m3);
    }

    fn granite() -> (Jh2Strength, Jh2Damage, PolynomialEos) {
        let l = Material::granite().jh2().expect("granite is JH-2");
        (l.strength, l.damage, l.eos)
    }

    #[test]
    fn strength_surface_is_the_formula() {
        let (s, _, _) = granite();
        let phel = s.p_hel_pa;
        for pstar in [-0.5 * s.t_pa / phel, 0.0, 0.1, 0.5, 1.0, 2.0] {
            let p = pstar * phel;
            let ts = s.t_pa / phel;
            let intact = 1.01 * (pstar + ts).powf(0.76);
            assert!((s.intact(p, 1.0) - intact).abs() < 1e-12 * intact.max(1.0));
            let fr = if pstar > 0.0 {
                (0.68 * pstar.powf(0.83)).min(s.sfmax)
            } else {
                0.0
            };
            assert!((s.fractured(p, 1.0) - fr).abs() < 1e-12);
            let half = s.yield_stress(p, 1.0, 0.5);
            assert!((half - s.sigma_hel() * 0.5 * (intact + fr)).abs() < 1e-9 * s.sigma_hel());
        }
        // No strength at or below P* = −T*; the rate term only strengthens.
        assert_eq!(s.intact(-s.t_pa, 10.0), 0.0);
        assert_eq!(s.rate_factor(0.1), 1.0);
        assert!((s.rate_factor(100.0) - (1.0 + s.c * 100f64.ln())).abs() < 1e-12);
    }

    #[test]
    fn bulking_at_zero_compression_is_the_square_root() {
        let (_, _, e) = granite();
        let du = 1e4;
        let dp = e.bulked(0.0, 0.0, du);
        assert!((dp - (2.0 * e.beta * e.k1_pa * du).sqrt()).abs() < 1e-6);
        assert_eq!(e.bulked(3.0, 0.01, 0.0), 3.0);
    }

    #[test]
    fn tension_is_capped_at_t_times_one_minus_d() {
        let l = Material::granite().jh2().unwrap();
        let (s, e) = (l.strength, l.eos);
        let rho = 0.9 * e.rho0_kg_m3;
        assert_eq!(pressure_of(&l, rho, 0.0, 0.0), -s.t_pa);
        assert_eq!(pressure_of(&l, rho, 0.0, 0.5), -0.5 * s.t_pa);
        assert_eq!(pressure_of(&l, rho, 0.0, 1.0), 0.0);
        let mu = 0.01;
        let p = pressure_of(&l, e.rho0_kg_m3 * (1.0 + mu), 5e6, 0.0);
        let expect = e.k1_pa * mu + e.k2_pa * mu * mu + e.k3_pa * mu * mu * mu + 5e6;
        assert!((p - expect).abs() < 1e-6 * expect);
    }

    #[test]
    fn a_fractured_particle_keeps_no_deviator() {
        let l = Material::granite().jh2().unwrap();
        let st = Jh2State {
            sdev: Matrix::zeros(),
            eps_p: 0.0,
            damage: 1.0,
            bulking: 0.0,
        };
        let r = jh2_update(
            Matrix::new(1e8, 0.0, 0.0, -1e8),
            st,
            l.eos.rho0_kg_m3,
            1.0,
            2e10,
            &l,
        );
        assert_eq!(r.state.sdev, Matrix::zeros());
        assert_eq!(r.d_eps, 0.0);
    }

    #[test]
    fn a_fractured_particle_under_compression_keeps_the_fractured_strength() {
        let l = Material::granite().jh2().unwrap();
        let st = Jh2State {
            sdev: Matrix::zeros(),
            eps_p: 0.3,
            damage: 1.0,
            bulking: 0.0,
        };
        let rho = l.eos.rho0_kg_m3 * 1.02;
        let p = pressure_of(&l, rho, 0.0, 1.0);
        let sf = l.strength.sigma_hel() * l.strength.fractured(p, 1.0);
        assert!(sf > 0.0);
        let big = Matrix::new(2.0 * sf, 0.0, 0.0, -2.0 * sf);
        let r = jh2_update(big, st, rho, 1.0, 2e10, &l);
        assert!((von_mises(&r.state.sdev) / sf - 1.0).abs() < 1e-12);
        assert_eq!((r.state.eps_p, r.state.damage, r.d_eps), (0.3, 1.0, 0.0));
        let small = big * (0.1 * sf / von_mises(&big));
        let r = jh2_update(small, st, rho, 1.0, 2e10, &l);
        assert_eq!(r.state.sdev, small);
    }
}
