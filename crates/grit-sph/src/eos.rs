//! Equations of state for the solid pressure: the linear form of the impact scene (seed eq. 11)
//! and the Mie–Grüneisen form of the water-jet scene (docs/jet.md#equations-of-state).
//!
//! The Mie–Grüneisen fraction is the usual shock (Us–up) form with optional quadratic and cubic
//! slope terms; with S2 = S3 = a = 0 it is the metal form. Its reference curve is the Hugoniot, so
//! a state on the Hugoniot with the Rankine–Hugoniot energy returns the Hugoniot pressure exactly.

use serde::{Deserialize, Serialize};

use crate::error::InputError;
use crate::jh2::PolynomialEos;

/// Which pressure law a material follows; the default linear law is `p = K (ρ/ρ0 − 1)` (seed eq. 11).
///
/// The brittle model's polynomial EOS (JH-2, AWJ paper eqs. 40–41) is the second variant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum EquationOfState {
    /// Shock Mie–Grüneisen EOS (docs/jet.md#equations-of-state).
    MieGruneisen(MieGruneisen),
    /// JH-2 polynomial EOS, K1 μ + K2 μ² + K3 μ³ (AWJ paper eq. 40; docs/jet.md#rock-targets).
    Polynomial(PolynomialEos),
}

impl EquationOfState {
    /// Pressure (Pa) at density `rho` (kg/m³) and specific internal energy `e` (J/kg).
    #[inline]
    pub fn pressure(&self, rho: f64, e: f64) -> f64 {
        match self {
            EquationOfState::MieGruneisen(g) => g.pressure(rho, e),
            // The polynomial reads no energy; its bulking pressure is the particle's, added by
            // the engine (`jh2::pressure_of`).
            EquationOfState::Polynomial(q) => q.pressure(rho, 0.0),
        }
    }

    /// Small-strain bulk modulus ρ0 c0² (Pa): the slope of p(ρ) at ρ0 and the CFL signal.
    pub fn bulk_modulus(&self) -> f64 {
        match self {
            EquationOfState::MieGruneisen(g) => g.bulk_modulus(),
            EquationOfState::Polynomial(q) => q.bulk_modulus(),
        }
    }

    /// Smallest compression η > 0 where the law is singular (∞ where it never is).
    pub fn singular_compression(&self) -> f64 {
        match self {
            EquationOfState::MieGruneisen(g) => g.singular_compression(),
            EquationOfState::Polynomial(_) => f64::INFINITY,
        }
    }

    /// Reference density ρ0 (kg/m³) of the law; a material's must equal it.
    pub fn reference_density(&self) -> f64 {
        match self {
            EquationOfState::MieGruneisen(g) => g.rho0_kg_m3,
            EquationOfState::Polynomial(q) => q.rho0_kg_m3,
        }
    }

    /// Checks the constants; errors name `field` extended by the constant.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        match self {
            EquationOfState::MieGruneisen(g) => g.validate(field),
            EquationOfState::Polynomial(q) => q.validate(field),
        }
    }

    /// Whether the law reads the specific internal energy e (Mie–Grüneisen's Γ ρ0 e), so the
    /// solid integrates one (docs/jet.md#energy); the polynomial EOS does not.
    pub fn reads_energy(&self) -> bool {
        matches!(self, EquationOfState::MieGruneisen(_))
    }
}

/// Mie–Grüneisen EOS with a Us = c0 + S1 up (+ S2, S3 terms) Hugoniot as reference curve.
///
/// With η = ρ/ρ0 − 1, in compression (η ≥ 0)
/// `p = ρ0 c0² η [1 + (1 − Γ0/2) η − (a/2) η²] / [1 − (S1 − 1) η − S2 η²/(η + 1) − S3 η³/(η + 1)²]²
///      + (Γ0 + a η) ρ0 e`,
/// and in tension (η < 0) `p = ρ0 c0² η + (Γ0 + a η) ρ0 e` (docs/jet.md#equations-of-state).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MieGruneisen {
    /// Reference density ρ0 (kg/m³).
    pub rho0_kg_m3: f64,
    /// Bulk sound speed c0, the Us–up intercept (m/s).
    pub c0_m_s: f64,
    /// Linear Us–up slope S1 (–).
    pub s1: f64,
    /// Quadratic slope coefficient S2 (–); 0 for the metals.
    #[serde(default)]
    pub s2: f64,
    /// Cubic slope coefficient S3 (–); 0 for the metals.
    #[serde(default)]
    pub s3: f64,
    /// Grüneisen coefficient Γ0 (–).
    pub gamma0: f64,
    /// First-order volume correction a of Γ (–); 0 for the metals.
    #[serde(default)]
    pub a: f64,
}

impl MieGruneisen {
    /// Water's hydrocode set: ρ0 1000 kg/m³, c0 1480 m/s, S1 2.56, S2 −1.986, S3 0.2268,
    /// Γ0 0.4934, a 1.3937 (docs/references.md#water; the AWJ paper's water EOS, eq. 24).
    pub const fn water() -> MieGruneisen {
        MieGruneisen {
            rho0_kg_m3: 1000.0,
            c0_m_s: 1480.0,
            s1: 2.56,
            s2: -1.986,
            s3: 0.2268,
            gamma0: 0.4934,
            a: 1.3937,
        }
    }

    /// Pressure (Pa) at density `rho` (kg/m³) and specific internal energy `e` (J/kg, 0 = reference).
    ///
    /// Beyond the compression where the denominator vanishes ([`Self::singular_compression`]) the
    /// value is meaningless; the caller's state check must reject such densities.
    #[inline]
    pub fn pressure(&self, rho: f64, e: f64) -> f64 {
        let eta = rho / self.rho0_kg_m3 - 1.0;
        let k0 = self.rho0_kg_m3 * self.c0_m_s * self.c0_m_s;
        let thermal = (self.gamma0 + self.a * eta) * self.rho0_kg_m3 * e;
        if eta < 0.0 {
            return k0 * eta + thermal;
        }
        let num = 1.0 + (1.0 - 0.5 * self.gamma0) * eta - 0.5 * self.a * eta * eta;
        let den = self.denominator(eta);
        k0 * eta * num / (den * den) + thermal
    }

    fn denominator(&self, eta: f64) -> f64 {
        let e1 = eta + 1.0;
        1.0 - (self.s1 - 1.0) * eta
            - self.s2 * eta * eta / e1
            - self.s3 * eta * eta * eta / (e1 * e1)
    }

    /// ρ0 c0², the slope dp/dη at the reference state: the bulk modulus the CFL and the linear
    /// limit use.
    pub fn bulk_modulus(&self) -> f64 {
        self.rho0_kg_m3 * self.c0_m_s * self.c0_m_s
    }

    /// Cold-curve sound speed √(dp/dρ) at e = 0 (m/s) of the shock form above: c0 at ρ0, rising
    /// with compression; 0 beyond [`Self::singular_compression`] where the slope has no meaning.
    pub fn sound_speed(&self, rho: f64) -> f64 {
        let eta = rho / self.rho0_kg_m3 - 1.0;
        if eta < 0.0 {
            return self.c0_m_s;
        }
        // d/dη of k0 η N/D², N and D the numerator and denominator of the compression fraction.
        let num = 1.0 + (1.0 - 0.5 * self.gamma0) * eta - 0.5 * self.a * eta * eta;
        let dnum = 1.0 - 0.5 * self.gamma0 - self.a * eta;
        let e1 = eta + 1.0;
        let den = self.denominator(eta);
        let dden = -(self.s1 - 1.0)
            - self.s2 * eta * (eta + 2.0) / (e1 * e1)
            - self.s3 * eta * eta * (eta + 3.0) / (e1 * e1 * e1);
        if den <= 0.0 {
            return 0.0;
        }
        let dp_deta = self.bulk_modulus()
            * ((num + eta * dnum) / (den * den) - 2.0 * eta * num * dden / (den * den * den));
        (dp_deta.max(0.0) / self.rho0_kg_m3).sqrt()
    }

    /// Smallest η > 0 where the compression denominator vanishes (∞ when it never does below η = 10).
    pub fn singular_compression(&self) -> f64 {
        // The metal form's denominator is linear in η: its root is exact and costs nothing,
        // which matters because the engine asks for it at every step.
        if self.s2 == 0.0 && self.s3 == 0.0 {
            return if self.s1 > 1.0 && 1.0 / (self.s1 - 1.0) <= 10.0 {
                1.0 / (self.s1 - 1.0)
            } else {
                f64::INFINITY
            };
        }
        // The denominator starts at 1; bisect on a fine scan so S2/S3 turning points are not missed.
        let steps = 10_000;
        let mut prev = 0.0;
        for k in 1..=steps {
            let eta = 10.0 * k as f64 / steps as f64;
            if self.denominator(eta) <= 0.0 {
                let (mut lo, mut hi) = (prev, eta);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if self.denominator(mid) > 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                return 0.5 * (lo + hi);
            }
            prev = eta;
        }
        f64::INFINITY
    }

    /// The Hugoniot state for particle speed `up` (m/s) of the linear Us = c0 + S1 up law:
    /// (shock speed Us, density, pressure ρ0 Us up, specific energy up²/2), the
    /// Rankine–Hugoniot jump conditions from rest.
    pub fn hugoniot(&self, up: f64) -> HugoniotState {
        let us = self.c0_m_s + self.s1 * up;
        HugoniotState {
            shock_speed_m_s: us,
            rho_kg_m3: self.rho0_kg_m3 * us / (us - up),
            pressure_pa: self.rho0_kg_m3 * us * up,
            energy_j_kg: 0.5 * up * up,
        }
    }

    /// Checks every constant; errors name `field.<constant>` and the rule.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        InputError::require_positive(format!("{field}.rho0_kg_m3"), self.rho0_kg_m3)?;
        InputError::require_positive(format!("{field}.c0_m_s"), self.c0_m_s)?;
        for (name, v) in [
            ("s1", self.s1),
            ("s2", self.s2),
            ("s3", self.s3),
            ("gamma0", self.gamma0),
            ("a", self.a),
        ] {
            if !v.is_finite() {
                return Err(InputError::new(
                    format!("{field}.{name}"),
                    format!("must be finite, got {v}"),
                ));
            }
        }
        if self.s1 < 1.0 {
            return Err(InputError::new(
                format!("{field}.s1"),
                format!(
                    "must be >= 1 (a shock must outrun the material behind it), got {}",
                    self.s1
                ),
            ));
        }
        Ok(())
    }
}

/// A state behind a steady shock running into material at rest (Rankine–Hugoniot).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HugoniotState {
    /// Shock speed Us (m/s).
    pub shock_speed_m_s: f64,
    /// Density behind the shock (kg/m³).
    pub rho_kg_m3: f64,
    /// Pressure behind the shock (Pa).
    pub pressure_pa: f64,
    /// Specific internal energy gained, up²/2 (J/kg).
    pub energy_j_kg: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn copper() -> MieGruneisen {
        match crate::material::Material::copper().eos {
            Some(EquationOfState::MieGruneisen(m)) => m,
            other => panic!("copper's preset has no Mie–Grüneisen EOS: {other:?}"),
        }
    }

    #[test]
    fn copper_hugoniot_at_200_m_s() {
        let g = copper();
        let h = g.hugoniot(200.0);
        assert!((h.shock_speed_m_s - 4238.0).abs() < 1e-9);
        // The published reference: 7.59 GPa, within 2 %.
        assert!(
            (h.pressure_pa / 7.59e9 - 1.0).abs() < 0.02,
            "{}",
            h.pressure_pa
        );
        // On the Hugoniot with the jump's energy the EOS returns the jump's pressure to round-off.
        let p = g.pressure(h.rho_kg_m3, h.energy_j_kg);
        assert!(
            (p / h.pressure_pa - 1.0).abs() < 1e-12,
            "{p} vs {}",
            h.pressure_pa
        );
        assert!((p / 7.59e9 - 1.0).abs() < 0.02);
        // Without the energy term the cold pressure lies below by about Γ0 χ / 2 (χ = up/Us).
        let cold = g.pressure(h.rho_kg_m3, 0.0);
        let chi = 200.0 / h.shock_speed_m_s;
        assert!((1.0 - cold / p - 0.5 * g.gamma0 * chi).abs() < 1e-9);
    }

    #[test]
    fn hugoniot_consistency_over_a_range_of_particle_speeds() {
        let g = copper();
        for up in [10.0, 100.0, 500.0, 1000.0, 2000.0] {
            let h = g.hugoniot(up);
            let p = g.pressure(h.rho_kg_m3, h.energy_j_kg);
            assert!((p / h.pressure_pa - 1.0).abs() < 1e-10, "up {up}");
        }
    }

    #[test]
    fn small_strain_limit_is_the_linear_law_and_continuous_at_zero() {
        let g = copper();
        let k = g.bulk_modulus();
        for eta in [1e-7, -1e-7] {
            let p = g.pressure(g.rho0_kg_m3 * (1.0 + eta), 0.0);
            assert!((p / (k * eta) - 1.0).abs() < 1e-5, "eta {eta}");
        }
        assert_eq!(g.pressure(g.rho0_kg_m3, 0.0), 0.0);
        // Tension is linear in η.
        let p = g.pressure(0.9 * g.rho0_kg_m3, 0.0);
        assert!((p / (-0.1 * k) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn water_form_with_quadratic_and_cubic_terms() {
        // Water constants of docs/jet.md; at η = 0.1 evaluate the formula term by term.
        let w = MieGruneisen::water();
        let eta: f64 = 0.1;
        let num = 1.0 + (1.0 - 0.4934 / 2.0) * eta - 1.3937 / 2.0 * eta * eta;
        let den = 1.0 - 1.56 * eta + 1.986 * eta * eta / 1.1 - 0.2268 * eta.powi(3) / 1.21;
        let e = 1e4;
        let expect = 1000.0 * 1480.0f64.powi(2) * eta * num / (den * den)
            + (0.4934 + 1.3937 * eta) * 1000.0 * e;
        let p = w.pressure(1100.0, e);
        assert!((p / expect - 1.0).abs() < 1e-12, "{p} vs {expect}");
        assert!(w.validate("water").is_ok());
    }

    #[test]
    fn sound_speed_is_c0_at_rest_and_the_slope_of_the_pressure() {
        let water = MieGruneisen::water();
        for g in [copper(), water] {
            assert!((g.sound_speed(g.rho0_kg_m3) - g.c0_m_s).abs() < 1e-9);
            assert_eq!(g.sound_speed(0.9 * g.rho0_kg_m3), g.c0_m_s);
            for eta in [0.01, 0.1, 0.3] {
                let rho = g.rho0_kg_m3 * (1.0 + eta);
                let d = 1e-6 * rho;
                let fd = (g.pressure(rho + d, 0.0) - g.pressure(rho - d, 0.0)) / (2.0 * d);
                let c = g.sound_speed(rho);
                assert!((c * c / fd - 1.0).abs() < 1e-7, "eta {eta}: {c}² vs {fd}");
                assert!(c > g.c0_m_s);
            }
        }
    }

    #[test]
    fn singular_compression_of_the_linear_slope() {
        let g = copper();
        let eta = g.singular_compression();
        assert!((eta - 1.0 / 0.49).abs() < 1e-9, "{eta}");
        // The scan of the general form finds the same root when S2 is all but zero.
        let nearly = MieGruneisen { s2: 1e-300, ..g };
        assert!((nearly.singular_compression() - eta).abs() < 1e-9);
        // A quadratic term moves the root, which the scan finds: the denominator vanishes there.
        let steep = MieGruneisen { s2: 0.5, ..g };
        let eta2 = steep.singular_compression();
        assert!(
            eta2 < eta && steep.denominator(eta2).abs() < 1e-12,
            "{eta2}"
        );
        assert!(steep.denominator(0.999 * eta2) > 0.0);
        // Water's denominator never vanishes below η = 10, nor does a slope S1 ≤ 1.
        assert_eq!(MieGruneisen::water().singular_compression(), f64::INFINITY);
        assert_eq!(
            MieGruneisen { s1: 1.0, ..g }.singular_compression(),
            f64::INFINITY
        );
    }

    #[test]
    fn validation_names_the_field() {
        let mut g = copper();
        g.s1 = 0.5;
        let err = g.validate("material.eos").unwrap_err();
        assert_eq!(err.field, "material.eos.s1");
        let mut g = copper();
        g.c0_m_s = -1.0;
        assert_eq!(
            g.validate("material.eos").unwrap_err().field,
            "material.eos.c0_m_s"
        );
    }

    #[test]
    fn json_is_tagged_and_defaults_the_water_terms() {
        let eos: EquationOfState = serde_json::from_str(
            r#"{"kind":"mie_gruneisen","rho0_kg_m3":8960,"c0_m_s":3940,"s1":1.49,"gamma0":2.02}"#,
        )
        .unwrap();
        assert_eq!(eos, EquationOfState::MieGruneisen(copper()));
    }
}
