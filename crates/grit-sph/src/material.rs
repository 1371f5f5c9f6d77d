//! Elastic–plastic material data: linear elasticity, Johnson–Cook strength (eq. 18) and
//! Johnson–Cook fracture (eqs. 19–20) of the seed paper; AISI 304 of its Table 1 is the default.

use serde::{Deserialize, Serialize};

use crate::error::InputError;

/// Johnson–Cook metal with linear elasticity (seed Table 1 field meanings), SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Name used in reports.
    #[serde(default = "default_name")]
    pub name: String,
    /// Reference density ρ0 (kg/m³).
    pub density_kg_m3: f64,
    /// Young's modulus E (Pa).
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio ν (–).
    pub poisson_ratio: f64,
    /// Specific heat capacity Cp (J/(kg·K)), for adiabatic heating from plastic work.
    pub heat_capacity_j_kgk: f64,
    /// Johnson–Cook strength parameters (eq. 18); `None` keeps the material elastic.
    pub plasticity: Option<JohnsonCook>,
    /// Johnson–Cook fracture parameters (eqs. 19–20); `None` disables damage.
    pub damage: Option<JohnsonCookDamage>,
}

fn default_name() -> String {
    "custom".to_string()
}

/// Johnson–Cook yield stress parameters (seed eq. 18).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JohnsonCook {
    /// Initial yield stress A (Pa).
    pub a_pa: f64,
    /// Hardening coefficient B (Pa).
    pub b_pa: f64,
    /// Strain hardening exponent n (–).
    pub n: f64,
    /// Strain-rate coefficient C (–).
    pub c: f64,
    /// Reference plastic strain rate ε̇0 (1/s).
    pub ref_strain_rate_s: f64,
    /// Thermal softening exponent m (–).
    pub m: f64,
    /// Reference (room) temperature Tref (K).
    pub t_ref_k: f64,
    /// Melting temperature Tmelt (K).
    pub t_melt_k: f64,
}

/// Johnson–Cook fracture strain parameters (seed eq. 20).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JohnsonCookDamage {
    /// D1 (–).
    pub d1: f64,
    /// D2 (–).
    pub d2: f64,
    /// D3 (–).
    pub d3: f64,
    /// D4 (–).
    pub d4: f64,
    /// D5 (–).
    pub d5: f64,
    /// Reference fracture strain rate ε̇0f (1/s).
    pub ref_strain_rate_s: f64,
}

impl Material {
    /// AISI 304 stainless steel, seed Table 1.
    pub fn aisi304() -> Self {
        Material {
            name: "aisi304".into(),
            density_kg_m3: 7890.0,
            youngs_modulus_pa: 200e9,
            poisson_ratio: 0.3,
            heat_capacity_j_kgk: 510.0,
            plasticity: Some(JohnsonCook {
                a_pa: 555.5e6,
                b_pa: 1379e6,
                n: 0.9497,
                c: 0.01503,
                ref_strain_rate_s: 1e-4,
                m: 1.3263,
                t_ref_k: 293.0,
                t_melt_k: 1673.0,
            }),
            damage: Some(JohnsonCookDamage {
                d1: -0.7786,
                d2: 2.5588,
                d3: -0.3607,
                d4: -0.0191,
                d5: 0.0,
                ref_strain_rate_s: 1e-3,
            }),
        }
    }

    /// Purely elastic aluminium of the seed's Hertz case (section 3.3.3): E 70 GPa, ν 0.3.
    pub fn elastic_aluminium() -> Self {
        Material {
            name: "aluminium-elastic".into(),
            density_kg_m3: 2700.0,
            youngs_modulus_pa: 70e9,
            poisson_ratio: 0.3,
            heat_capacity_j_kgk: 900.0,
            plasticity: None,
            damage: None,
        }
    }

    /// Bulk modulus K = E / (3 (1 − 2ν)), used by the EOS (eq. 11).
    pub fn bulk_modulus(&self) -> f64 {
        self.youngs_modulus_pa / (3.0 * (1.0 - 2.0 * self.poisson_ratio))
    }

    /// Shear modulus G = E / (2 (1 + ν)), used by the Jaumann rate (eq. 13).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus_pa / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// Longitudinal (P-wave) sound speed sqrt((K + 4G/3)/ρ0), the CFL signal speed.
    pub fn sound_speed(&self) -> f64 {
        ((self.bulk_modulus() + 4.0 / 3.0 * self.shear_modulus()) / self.density_kg_m3).sqrt()
    }

    /// Checks every field is physical; the error names the field and the rule.
    pub fn validate(&self) -> Result<(), InputError> {
        let pos =
            |field: &str, v: f64| InputError::require_positive(format!("material.{field}"), v);
        let fin = |field: &str, v: f64| -> Result<(), InputError> {
            if v.is_finite() {
                Ok(())
            } else {
                Err(InputError::new(
                    format!("material.{field}"),
                    format!("must be finite, got {v}"),
                ))
            }
        };
        pos("density_kg_m3", self.density_kg_m3)?;
        pos("youngs_modulus_pa", self.youngs_modulus_pa)?;
        pos("heat_capacity_j_kgk", self.heat_capacity_j_kgk)?;
        if !(self.poisson_ratio.is_finite()
            && self.poisson_ratio > -1.0
            && self.poisson_ratio < 0.5)
        {
            return Err(InputError::new(
                "material.poisson_ratio",
                format!("must lie in (-1, 0.5), got {}", self.poisson_ratio),
            ));
        }
        if let Some(jc) = &self.plasticity {
            pos("plasticity.a_pa", jc.a_pa)?;
            if !(jc.b_pa.is_finite() && jc.b_pa >= 0.0) {
                return Err(InputError::new(
                    "material.plasticity.b_pa",
                    format!("must be >= 0, got {}", jc.b_pa),
                ));
            }
            pos("plasticity.n", jc.n)?;
            if !(jc.c.is_finite() && jc.c >= 0.0) {
                return Err(InputError::new(
                    "material.plasticity.c",
                    format!("must be >= 0, got {}", jc.c),
                ));
            }
            pos("plasticity.ref_strain_rate_s", jc.ref_strain_rate_s)?;
            pos("plasticity.m", jc.m)?;
            pos("plasticity.t_ref_k", jc.t_ref_k)?;
            pos("plasticity.t_melt_k", jc.t_melt_k)?;
            if jc.t_melt_k <= jc.t_ref_k {
                return Err(InputError::new(
                    "material.plasticity.t_melt_k",
                    format!("must exceed t_ref_k ({}), got {}", jc.t_ref_k, jc.t_melt_k),
                ));
            }
        }
        if let Some(d) = &self.damage {
            if self.plasticity.is_none() {
                return Err(InputError::new(
                    "material.damage",
                    "needs material.plasticity: Johnson-Cook damage grows only with plastic strain",
                ));
            }
            fin("damage.d1", d.d1)?;
            fin("damage.d2", d.d2)?;
            fin("damage.d3", d.d3)?;
            fin("damage.d4", d.d4)?;
            fin("damage.d5", d.d5)?;
            pos("damage.ref_strain_rate_s", d.ref_strain_rate_s)?;
        }
        Ok(())
    }
}

impl Default for Material {
    fn default() -> Self {
        Self::aisi304()
    }
}
