//! The water-jet scene's rock presets, red sandstone and granite, as JH-2 solids (AWJ paper
//! eqs. 38–41). The paper's Table 3 did not survive in its text; the constants, their sources and
//! which of them are uncertain are in docs/references.md#rock-presets and docs/jet.md#rock-targets.

use crate::eos::EquationOfState;
use crate::jh2::{Jh2Damage, Jh2Strength, PolynomialEos};
use crate::material::{Fracture, Material, Strength};

/// Young's modulus and Poisson's ratio of an isotropic solid with bulk modulus `k` and shear
/// modulus `g`: E = 9KG/(3K + G), ν = (3K − 2G)/(2(3K + G)). The presets give K1 and G, as
/// JH-2 sets do; the engine's `Material` keeps E and ν.
pub fn elastic_from_bulk_shear(k: f64, g: f64) -> (f64, f64) {
    (
        9.0 * k * g / (3.0 * k + g),
        (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)),
    )
}

/// A JH-2 material from its density, shear modulus, heat capacity and three laws.
fn jh2_material(
    name: &str,
    shear_pa: f64,
    heat_capacity_j_kgk: f64,
    strength: Jh2Strength,
    damage: Jh2Damage,
    eos: PolynomialEos,
) -> Material {
    let (e, nu) = elastic_from_bulk_shear(eos.k1_pa, shear_pa);
    Material {
        name: name.into(),
        density_kg_m3: eos.rho0_kg_m3,
        youngs_modulus_pa: e,
        poisson_ratio: nu,
        heat_capacity_j_kgk,
        plasticity: Some(Strength::JohnsonHolmquist2(strength)),
        damage: Some(Fracture::JohnsonHolmquist2(damage)),
        eos: Some(EquationOfState::Polynomial(eos)),
    }
}

/// The Barre-granite JH-2 strength (Wang, Yin & Luo 2018, eq. 38's A, N, B, M, C) with the
/// HEL, P_HEL and T given (Pa); both presets share its dimensionless shape.
fn barre_shape(hel_pa: f64, p_hel_pa: f64, t_pa: f64) -> Jh2Strength {
    Jh2Strength {
        a: 1.01,
        n: 0.76,
        b: 0.68,
        m: 0.83,
        c: 0.005,
        ref_strain_rate_s: 1.0,
        sfmax: 1.0,
        hel_pa,
        p_hel_pa,
        t_pa,
    }
}

/// The Barre-granite JH-2 damage constants (Wang, Yin & Luo 2018, eq. 39's D1, D2), no ε_f,min
/// (docs/references.md#rock-presets).
const BARRE_DAMAGE: Jh2Damage = Jh2Damage {
    d1: 0.005,
    d2: 0.7,
    ef_min: 0.0,
};

impl Material {
    /// Granite: the JH-2 set of Barre granite (Wang, Yin & Luo, Appl. Sci. 8:1675, 2018), the
    /// AWJ paper's granite source; σ*_fmax and ε_f,min are grit's (docs/references.md#rock-presets).
    pub fn granite() -> Self {
        jh2_material(
            "granite",
            21.9e9,
            790.0,
            barre_shape(4.5e9, 2.93e9, 12e6),
            BARRE_DAMAGE,
            PolynomialEos {
                rho0_kg_m3: 2660.0,
                k1_pa: 25.7e9,
                k2_pa: -4.5e9,
                k3_pa: 3.0e9,
                beta: 1.0,
            },
        )
    }

    /// Red sandstone: no published JH-2 set was found, so this one is derived: handbook elastic
    /// constants and strengths of a red sandstone (E 16 GPa, ν 0.25, UCS 70 MPa, T 4 MPa), the
    /// granite's dimensionless shape constants, and the HEL of an elastic uniaxial-strain wave
    /// at the pressure that gives that UCS (docs/references.md#rock-presets).
    pub fn sandstone() -> Self {
        // K = E/(3(1 − 2ν)) = 10.67 GPa, G = E/(2(1 + ν)) = 6.4 GPa; K2 and K3 keep the
        // granite's ratios to K1.
        let k1 = 16e9 / 1.5;
        jh2_material(
            "sandstone",
            6.4e9,
            920.0,
            barre_shape(1.11e9, 0.617e9, 4e6),
            BARRE_DAMAGE,
            PolynomialEos {
                rho0_kg_m3: 2400.0,
                k1_pa: k1,
                k2_pa: k1 * (-4.5 / 25.7),
                k3_pa: k1 * (3.0 / 25.7),
                beta: 1.0,
            },
        )
    }
}

/// The uniaxial compressive strength (Pa) of intact JH-2 material at the reference rate: the
/// stress σ with σ = σ_HEL A (σ/(3 P_HEL) + T*)^N, where a uniaxial stress state has P = σ/3
/// and von Mises stress σ (eq. 38 at D = 0), solved by bisection.
pub fn uniaxial_compressive_strength(s: &Jh2Strength) -> f64 {
    bisect(
        |sig| sig - s.sigma_hel() * s.intact(sig / 3.0, 0.0),
        0.0,
        s.sigma_hel() * s.a * 10.0,
    )
}

/// The root in [lo, hi] of `f`, negative below it and positive above, by 200 bisections: the
/// uniaxial strengths of eq. 38 (this module and the rock verification rows).
pub fn bisect(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_jh2_solids_with_their_moduli() {
        for m in [Material::sandstone(), Material::granite()] {
            m.validate().unwrap();
            let l = m.jh2().expect("a full JH-2 set");
            // The engine's moduli from E and ν are the set's K1 and G.
            assert!(
                (m.bulk_modulus() / l.eos.k1_pa - 1.0).abs() < 1e-12,
                "{}",
                m.name
            );
            assert_eq!(m.pressure_bulk_modulus(), l.eos.k1_pa);
            assert!(m.poisson_ratio > 0.0 && m.poisson_ratio < 0.5);
        }
        let g = Material::granite();
        assert!((g.shear_modulus() / 21.9e9 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn uniaxial_strengths_of_the_presets() {
        // The sandstone's HEL was chosen for a 70 MPa UCS; the granite set gives about 100 MPa.
        let ss = Material::sandstone().jh2().unwrap().strength;
        let ucs = uniaxial_compressive_strength(&ss);
        assert!((ucs / 70e6 - 1.0).abs() < 0.01, "{ucs}");
        let gr = Material::granite().jh2().unwrap().strength;
        let ucs = uniaxial_compressive_strength(&gr);
        assert!((ucs / 100e6 - 1.0).abs() < 0.02, "{ucs}");
        // The sandstone's HEL is the elastic uniaxial-strain wave's at P_HEL:
        // HEL = P_HEL (1 + 4G/(3K)).
        let m = Material::sandstone();
        let ratio = 1.0 + 4.0 * m.shear_modulus() / (3.0 * m.bulk_modulus());
        assert!((ss.hel_pa / (ss.p_hel_pa * ratio) - 1.0).abs() < 0.01);
    }

    #[test]
    fn json_round_trip_and_laws_told_apart() {
        for m in [Material::sandstone(), Material::granite()] {
            let json = serde_json::to_string(&m).unwrap();
            assert!(json.contains(r#""kind":"polynomial""#), "{json}");
            assert_eq!(serde_json::from_str::<Material>(&json).unwrap(), m);
        }
        // A JH-2 strength with a missing constant names it.
        let mut v = serde_json::to_value(Material::granite()).unwrap();
        v["plasticity"].as_object_mut().unwrap().remove("t_pa");
        let err = serde_json::from_value::<Material>(v)
            .unwrap_err()
            .to_string();
        assert!(err.contains("t_pa"), "{err}");
    }

    #[test]
    fn a_partial_jh2_set_is_refused() {
        let mut m = Material::granite();
        m.eos = None;
        assert_eq!(m.validate().unwrap_err().field, "material.plasticity");
        let mut m = Material::granite();
        if let Some(Strength::JohnsonHolmquist2(s)) = &mut m.plasticity {
            s.p_hel_pa = 5e9;
        }
        assert_eq!(
            m.validate().unwrap_err().field,
            "material.plasticity.p_hel_pa"
        );
        let mut m = Material::sandstone();
        if let Some(EquationOfState::Polynomial(e)) = &mut m.eos {
            e.beta = 1.5;
        }
        assert_eq!(m.validate().unwrap_err().field, "material.eos.beta");
    }
}
