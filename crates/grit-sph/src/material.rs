//! Elastic–plastic material data: linear elasticity, Johnson–Cook strength (eq. 18) and
//! Johnson–Cook fracture (eqs. 19–20) of the seed paper; AISI 304 of its Table 1 is the default.
//! The water-jet scene's metals (OFHC copper, Al 6061-T6) add a Mie–Grüneisen EOS
//! (docs/jet.md#metal-targets); its rocks (red sandstone, granite, `rock.rs`) are JH-2 solids
//! (AWJ paper eqs. 38–41, docs/jet.md#rock-targets).

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::eos::{EquationOfState, MieGruneisen};
use crate::error::InputError;
use crate::jh2::{Jh2Damage, Jh2Laws, Jh2Strength};

/// Names [`Material::by_name`] knows, in the order error messages list them.
pub const MATERIAL_NAMES: [&str; 5] = ["aisi304", "copper", "al6061", "sandstone", "granite"];

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
    /// Strength law (Johnson–Cook, eq. 18); `None` keeps the material elastic.
    pub plasticity: Option<Strength>,
    /// Fracture law (Johnson–Cook, eqs. 19–20); `None` disables damage.
    pub damage: Option<Fracture>,
    /// Pressure law; `None` is the linear `p = K (ρ/ρ0 − 1)` of seed eq. 11 (and is left out of
    /// the JSON, so materials stored before this field existed keep their bytes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eos: Option<EquationOfState>,
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

/// A strength law: how the deviatoric stress yields: Johnson–Cook (seed eq. 18) or JH-2 (AWJ
/// paper eq. 38). In JSON it is the law's parameters alone, as before there was a choice; a
/// reader tells them apart by JH-2's `hel_pa`.
#[derive(Debug, Clone, PartialEq)]
pub enum Strength {
    /// Johnson–Cook (seed eq. 18).
    JohnsonCook(JohnsonCook),
    /// Johnson–Holmquist JH-2 (AWJ paper eq. 38).
    JohnsonHolmquist2(Jh2Strength),
}

impl Strength {
    /// The Johnson–Cook parameters, when this is Johnson–Cook.
    pub fn johnson_cook(&self) -> Option<&JohnsonCook> {
        match self {
            Strength::JohnsonCook(jc) => Some(jc),
            Strength::JohnsonHolmquist2(_) => None,
        }
    }
}

impl Serialize for Strength {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Strength::JohnsonCook(jc) => jc.serialize(s),
            Strength::JohnsonHolmquist2(j) => j.serialize(s),
        }
    }
}

/// Reads one of two laws written as their parameters alone: `B` where the JSON object has the
/// key `marker`, else `A`. Materials are only ever stored as JSON (a sample checkpoint keeps its
/// scene as JSON text), so a format that cannot be looked into reads `A`, the law it always read.
fn either<'de, D, A, B, T>(
    d: D,
    marker: &str,
    a: impl FnOnce(A) -> T,
    b: impl FnOnce(B) -> T,
) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    A: serde::de::DeserializeOwned,
    B: serde::de::DeserializeOwned,
{
    use serde::de::Error;
    if !d.is_human_readable() {
        return A::deserialize(d).map(a);
    }
    let v = serde_json::Value::deserialize(d)?;
    if v.get(marker).is_some() {
        serde_json::from_value(v).map(b).map_err(D::Error::custom)
    } else {
        serde_json::from_value(v).map(a).map_err(D::Error::custom)
    }
}

impl<'de> Deserialize<'de> for Strength {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        either(
            d,
            "hel_pa",
            Strength::JohnsonCook,
            Strength::JohnsonHolmquist2,
        )
    }
}

/// A fracture law: the strain at which damage reaches 1: Johnson–Cook (seed eqs. 19–20) or JH-2
/// (AWJ paper eq. 39); written in JSON as the law's parameters alone, JH-2 told by `ef_min`.
#[derive(Debug, Clone, PartialEq)]
pub enum Fracture {
    /// Johnson–Cook (seed eqs. 19–20).
    JohnsonCook(JohnsonCookDamage),
    /// Johnson–Holmquist JH-2 (AWJ paper eq. 39).
    JohnsonHolmquist2(Jh2Damage),
}

impl Fracture {
    /// The Johnson–Cook parameters, when this is Johnson–Cook.
    pub fn johnson_cook(&self) -> Option<&JohnsonCookDamage> {
        match self {
            Fracture::JohnsonCook(d) => Some(d),
            Fracture::JohnsonHolmquist2(_) => None,
        }
    }
}

impl Serialize for Fracture {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Fracture::JohnsonCook(d) => d.serialize(s),
            Fracture::JohnsonHolmquist2(d) => d.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Fracture {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        either(
            d,
            "ef_min",
            Fracture::JohnsonCook,
            Fracture::JohnsonHolmquist2,
        )
    }
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
            plasticity: Some(Strength::JohnsonCook(JohnsonCook {
                a_pa: 555.5e6,
                b_pa: 1379e6,
                n: 0.9497,
                c: 0.01503,
                ref_strain_rate_s: 1e-4,
                m: 1.3263,
                t_ref_k: 293.0,
                t_melt_k: 1673.0,
            })),
            damage: Some(Fracture::JohnsonCook(JohnsonCookDamage {
                d1: -0.7786,
                d2: 2.5588,
                d3: -0.3607,
                d4: -0.0191,
                d5: 0.0,
                ref_strain_rate_s: 1e-3,
            })),
            eos: None,
        }
    }

    /// OFHC copper: Johnson–Cook strength and fracture, shock Mie–Grüneisen EOS
    /// (constants and sources: docs/jet.md#metal-targets, docs/references.md).
    pub fn copper() -> Self {
        Material {
            name: "copper".into(),
            density_kg_m3: 8960.0,
            youngs_modulus_pa: 124e9,
            poisson_ratio: 0.34,
            heat_capacity_j_kgk: 383.0,
            plasticity: Some(Strength::JohnsonCook(JohnsonCook {
                a_pa: 90e6,
                b_pa: 292e6,
                n: 0.31,
                c: 0.025,
                ref_strain_rate_s: 1.0,
                m: 1.09,
                t_ref_k: 293.0,
                t_melt_k: 1356.0,
            })),
            damage: Some(Fracture::JohnsonCook(JohnsonCookDamage {
                d1: 0.54,
                d2: 4.89,
                d3: -3.03,
                d4: 0.014,
                d5: 1.12,
                ref_strain_rate_s: 1.0,
            })),
            eos: Some(EquationOfState::MieGruneisen(MieGruneisen {
                rho0_kg_m3: 8960.0,
                c0_m_s: 3940.0,
                s1: 1.49,
                s2: 0.0,
                s3: 0.0,
                gamma0: 2.02,
                a: 0.0,
            })),
        }
    }

    /// Aluminium alloy 6061-T6: Johnson–Cook strength and fracture, shock Mie–Grüneisen EOS
    /// (constants and sources: docs/jet.md#metal-targets, docs/references.md).
    pub fn al6061() -> Self {
        Material {
            name: "al6061".into(),
            density_kg_m3: 2703.0,
            youngs_modulus_pa: 68.9e9,
            poisson_ratio: 0.33,
            heat_capacity_j_kgk: 896.0,
            plasticity: Some(Strength::JohnsonCook(JohnsonCook {
                a_pa: 324e6,
                b_pa: 114e6,
                n: 0.42,
                c: 0.002,
                ref_strain_rate_s: 1.0,
                m: 1.34,
                t_ref_k: 293.0,
                t_melt_k: 933.0,
            })),
            damage: Some(Fracture::JohnsonCook(JohnsonCookDamage {
                d1: -0.77,
                d2: 1.45,
                d3: -0.47,
                d4: 0.0,
                d5: 1.6,
                ref_strain_rate_s: 1.0,
            })),
            eos: Some(EquationOfState::MieGruneisen(MieGruneisen {
                rho0_kg_m3: 2703.0,
                c0_m_s: 5350.0,
                s1: 1.34,
                s2: 0.0,
                s3: 0.0,
                gamma0: 2.0,
                a: 0.0,
            })),
        }
    }

    /// The preset called `name` (one of [`MATERIAL_NAMES`]); an unknown name is an error that
    /// names it and lists the known ones.
    pub fn by_name(name: &str) -> Result<Self, InputError> {
        match name {
            "aisi304" => Ok(Self::aisi304()),
            "copper" => Ok(Self::copper()),
            "al6061" => Ok(Self::al6061()),
            "sandstone" => Ok(Self::sandstone()),
            "granite" => Ok(Self::granite()),
            _ => Err(InputError::new(
                "material",
                format!(
                    "unknown material `{name}`; known names: {}, or a full material object",
                    MATERIAL_NAMES.join(", ")
                ),
            )),
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
            eos: None,
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

    /// Small-strain bulk modulus of the pressure law: K of eq. 11, or ρ0 c0² of the EOS where
    /// the material has one (docs/jet.md#equations-of-state).
    pub fn pressure_bulk_modulus(&self) -> f64 {
        self.eos
            .map_or_else(|| self.bulk_modulus(), |e| e.bulk_modulus())
    }

    /// Longitudinal (P-wave) sound speed sqrt((K + 4G/3)/ρ0) with the pressure law's K, the CFL
    /// signal speed.
    pub fn sound_speed(&self) -> f64 {
        ((self.pressure_bulk_modulus() + 4.0 / 3.0 * self.shear_modulus()) / self.density_kg_m3)
            .sqrt()
    }

    /// The material's three JH-2 laws, when it is a JH-2 solid (strength, damage and a
    /// polynomial EOS together; `validate` refuses a partial set).
    pub fn jh2(&self) -> Option<Jh2Laws> {
        match (&self.plasticity, &self.damage, &self.eos) {
            (
                Some(Strength::JohnsonHolmquist2(strength)),
                Some(Fracture::JohnsonHolmquist2(damage)),
                Some(EquationOfState::Polynomial(eos)),
            ) => Some(Jh2Laws {
                strength: *strength,
                damage: *damage,
                eos: *eos,
            }),
            _ => None,
        }
    }

    /// Whether any of the material's laws is a JH-2 one.
    pub fn is_jh2(&self) -> bool {
        matches!(self.plasticity, Some(Strength::JohnsonHolmquist2(_)))
            || matches!(self.damage, Some(Fracture::JohnsonHolmquist2(_)))
            || matches!(self.eos, Some(EquationOfState::Polynomial(_)))
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
        if let Some(Strength::JohnsonCook(jc)) = &self.plasticity {
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
        if self.is_jh2() {
            if self.jh2().is_none() {
                return Err(InputError::new(
                    "material.plasticity",
                    "a JH-2 solid needs all three of its laws: JH-2 plasticity (hel_pa...), JH-2 \
                     damage (ef_min...) and the polynomial eos (kind \"polynomial\")",
                ));
            }
            if let Some(Strength::JohnsonHolmquist2(s)) = &self.plasticity {
                s.validate("material.plasticity")?;
            }
            if let Some(Fracture::JohnsonHolmquist2(d)) = &self.damage {
                d.validate("material.damage")?;
            }
        }
        if let Some(Fracture::JohnsonCook(d)) = &self.damage {
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
        if let Some(eos) = &self.eos {
            eos.validate("material.eos")?;
            let rho0 = eos.reference_density();
            if (rho0 / self.density_kg_m3 - 1.0).abs() > 1e-9 {
                return Err(InputError::new(
                    "material.eos.rho0_kg_m3",
                    format!(
                        "must equal material.density_kg_m3 ({}), got {rho0}",
                        self.density_kg_m3
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl Default for Material {
    fn default() -> Self {
        Self::aisi304()
    }
}

#[cfg(test)]
impl Material {
    /// The Johnson–Cook strength and fracture laws of a preset that has both.
    pub(crate) fn johnson_cook_laws(&self) -> (&JohnsonCook, &JohnsonCookDamage) {
        let jc = self.plasticity.as_ref().and_then(Strength::johnson_cook);
        let d = self.damage.as_ref().and_then(Fracture::johnson_cook);
        (
            jc.expect("Johnson–Cook strength"),
            d.expect("Johnson–Cook fracture"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_by_name_and_their_constants() {
        for name in MATERIAL_NAMES {
            let m = Material::by_name(name).unwrap();
            assert_eq!(m.name, name);
            m.validate().unwrap();
        }
        let cu = Material::copper();
        let (jc, d) = cu.johnson_cook_laws();
        assert_eq!(
            (jc.a_pa, jc.b_pa, jc.n, jc.c, jc.m),
            (90e6, 292e6, 0.31, 0.025, 1.09)
        );
        assert_eq!((jc.ref_strain_rate_s, jc.t_melt_k), (1.0, 1356.0));
        assert_eq!(
            (d.d1, d.d2, d.d3, d.d4, d.d5),
            (0.54, 4.89, -3.03, 0.014, 1.12)
        );
        let Some(EquationOfState::MieGruneisen(g)) = &cu.eos else {
            panic!("copper has a Grüneisen EOS")
        };
        assert_eq!(
            (g.rho0_kg_m3, g.c0_m_s, g.s1, g.gamma0),
            (8960.0, 3940.0, 1.49, 2.02)
        );

        let al = Material::al6061();
        let (jc, d) = al.johnson_cook_laws();
        assert_eq!(
            (jc.a_pa, jc.b_pa, jc.n, jc.c, jc.m),
            (324e6, 114e6, 0.42, 0.002, 1.34)
        );
        assert_eq!(jc.t_melt_k, 933.0);
        assert_eq!(
            (d.d1, d.d2, d.d3, d.d4, d.d5),
            (-0.77, 1.45, -0.47, 0.0, 1.6)
        );
        let Some(EquationOfState::MieGruneisen(g)) = &al.eos else {
            panic!("al6061 has a Grüneisen EOS")
        };
        assert_eq!(
            (g.rho0_kg_m3, g.c0_m_s, g.s1, g.gamma0),
            (2703.0, 5350.0, 1.34, 2.0)
        );
    }

    #[test]
    fn linear_bulk_modulus_of_the_presets_is_near_the_shock_one() {
        // The engine's linear law uses K from E and ν; the Grüneisen slope at rest is ρ0 c0².
        // They are different measurements of one modulus, so they agree to ~15 %.
        for m in [Material::copper(), Material::al6061()] {
            let Some(EquationOfState::MieGruneisen(g)) = &m.eos else {
                unreachable!()
            };
            let r = m.bulk_modulus() / g.bulk_modulus();
            assert!((0.85..1.0).contains(&r), "{}: {r}", m.name);
        }
    }

    #[test]
    fn unknown_name_is_a_clear_error() {
        let err = Material::by_name("brass").unwrap_err();
        assert_eq!(err.field, "material");
        assert!(err.rule.contains("`brass`"), "{}", err.rule);
        for name in MATERIAL_NAMES {
            assert!(err.rule.contains(name), "{}", err.rule);
        }
    }

    #[test]
    fn aisi304_json_has_no_eos_key_and_old_json_still_reads() {
        let json = serde_json::to_string(&Material::aisi304()).unwrap();
        assert_eq!(json, AISI304_JSON);
        let back: Material = serde_json::from_str(AISI304_JSON).unwrap();
        assert_eq!(back, Material::aisi304());
        let cu = serde_json::to_string(&Material::copper()).unwrap();
        assert!(cu.contains(r#""eos":{"kind":"mie_gruneisen""#), "{cu}");
        assert_eq!(
            serde_json::from_str::<Material>(&cu).unwrap(),
            Material::copper()
        );
    }

    /// AISI 304 as stored scenes held it before the EOS field existed.
    const AISI304_JSON: &str = concat!(
        r#"{"name":"aisi304","density_kg_m3":7890.0,"youngs_modulus_pa":200000000000.0,"#,
        r#""poisson_ratio":0.3,"heat_capacity_j_kgk":510.0,"plasticity":{"a_pa":555500000.0,"#,
        r#""b_pa":1379000000.0,"n":0.9497,"c":0.01503,"ref_strain_rate_s":0.0001,"m":1.3263,"#,
        r#""t_ref_k":293.0,"t_melt_k":1673.0},"damage":{"d1":-0.7786,"d2":2.5588,"d3":-0.3607,"#,
        r#""d4":-0.0191,"d5":0.0,"ref_strain_rate_s":0.001}}"#
    );

    #[test]
    fn eos_density_must_match_the_material() {
        let mut m = Material::copper();
        m.density_kg_m3 = 8900.0;
        assert_eq!(m.validate().unwrap_err().field, "material.eos.rho0_kg_m3");
        let mut m = Material::al6061();
        if let Some(EquationOfState::MieGruneisen(g)) = &mut m.eos {
            g.s1 = f64::NAN;
        }
        assert_eq!(m.validate().unwrap_err().field, "material.eos.s1");
    }
}
