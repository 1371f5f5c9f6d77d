//! Constitutive pieces, per particle: Johnson–Cook yield (eq. 18), the radial return of J2
//! plasticity, adiabatic heating, and Johnson–Cook fracture strain (eqs. 19–20).

use crate::material::{JohnsonCook, JohnsonCookDamage};
use crate::math::{exp, ln, pow, Matrix};
use crate::particles::von_mises;

/// Homologous temperature T* = (T − Tref)/(Tmelt − Tref), clamped to [0, 1].
#[inline]
pub fn homologous_temperature(jc: &JohnsonCook, t: f64) -> f64 {
    ((t - jc.t_ref_k) / (jc.t_melt_k - jc.t_ref_k)).clamp(0.0, 1.0)
}

/// Johnson–Cook yield stress (eq. 18) and its derivatives with respect to plastic strain and
/// plastic strain rate. The rate term is (1 + C ln(ε̇/ε̇0)), held at 1 below ε̇0 so the
/// logarithm never softens the material (docs/references.md#constitutive-forms).
#[inline]
pub fn jc_yield(jc: &JohnsonCook, eps_p: f64, rate: f64, t: f64) -> (f64, f64, f64) {
    let th = thermal_softening(jc, t);
    let hard = hardening(jc, eps_p);
    let (rate_term, drate) = rate_factor(jc, rate);
    (
        hard * rate_term * th,
        hardening_slope(jc, eps_p) * rate_term * th,
        hard * drate * th,
    )
}

/// The thermal factor 1 − T*^m of Johnson–Cook yield (eq. 18).
#[inline]
pub fn thermal_softening(jc: &JohnsonCook, t: f64) -> f64 {
    let ts = homologous_temperature(jc, t);
    // 0^m is exactly 0 for m > 0: at room temperature the power is skipped, to the same bits.
    if ts == 0.0 && jc.m > 0.0 {
        1.0
    } else {
        1.0 - pow(ts, jc.m)
    }
}

/// Johnson–Cook strain hardening A + B ε_p^n (eq. 18); the power is skipped, to the same bits,
/// where ε_p = 0.
#[inline]
fn hardening(jc: &JohnsonCook, eps_p: f64) -> f64 {
    let e = eps_p.max(0.0);
    if e == 0.0 && jc.n > 0.0 {
        jc.a_pa
    } else {
        jc.a_pa + jc.b_pa * pow(e, jc.n)
    }
}

/// d(A + B ε_p^n)/dε_p = n B ε_p^(n−1) of eq. 18, 0 at ε_p = 0.
#[inline]
fn hardening_slope(jc: &JohnsonCook, eps_p: f64) -> f64 {
    if eps_p > 0.0 {
        jc.b_pa * jc.n * pow(eps_p, jc.n - 1.0)
    } else {
        0.0
    }
}

/// The rate factor 1 + C ln(ε̇/ε̇0) of eq. 18 and its derivative in ε̇, held at (1, 0) below ε̇0.
#[inline]
fn rate_factor(jc: &JohnsonCook, rate: f64) -> (f64, f64) {
    if rate > jc.ref_strain_rate_s {
        (1.0 + jc.c * ln(rate / jc.ref_strain_rate_s), jc.c / rate)
    } else {
        (1.0, 0.0)
    }
}

/// The zero-rate Johnson–Cook yield stress (eq. 18) at one plastic strain and temperature, with
/// its thermal factor: what the radial return's elastic check needs, and all that depends on the
/// particle's state alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YieldAt {
    /// (A + B ε_p^n)(1 − T*^m) (Pa).
    pub sy0: f64,
    /// 1 − T*^m.
    pub th: f64,
}

/// `YieldAt` for plastic strain `eps_p` and temperature `t`.
#[inline]
pub fn yield_at(jc: &JohnsonCook, eps_p: f64, t: f64) -> YieldAt {
    // The elastic check needs the yield stress alone: no derivative, so no second power.
    yield_hardened(jc, hardening(jc, eps_p), t)
}

/// `YieldAt` at temperature `t` for a plastic strain whose hardening A + B ε_p^n (eq. 18) is
/// `hard` (`Plastic::hardening`), to the bits of `yield_at`.
#[inline]
pub fn yield_hardened(jc: &JohnsonCook, hard: f64, t: f64) -> YieldAt {
    let th = thermal_softening(jc, t);
    YieldAt { sy0: hard * th, th }
}

/// Result of the return mapping for one particle and one step.
#[derive(Debug, Clone, Copy)]
pub struct Plastic {
    /// Corrected in-plane deviatoric stress.
    pub sdev: Matrix,
    /// Plastic strain increment Δε_p.
    pub d_eps: f64,
    /// Yield stress at the end of the step (Pa).
    pub sigma_y: f64,
    /// A + B (ε_p + Δε)^n where the iteration ended on the returned Δε: the next step's
    /// `YieldAt` at the new ε_p needs no power of its own (`yield_hardened`).
    pub hardening: Option<f64>,
}

/// J2 radial return (Wilkins; Simo & Hughes 1998, box 3.1): the trial deviator is scaled back to
/// the Johnson–Cook yield surface, solving σ_eq* − 3GΔε = σ_y(ε_p + Δε, Δε/Δt, T) for Δε by
/// safeguarded Newton iteration in ln Δε.
///
/// For J2 with isotropic hardening the closest-point projection is radial, so this is the
/// converged limit of the seed's cutting-plane iterations, reached with one scalar solve.
pub fn radial_return(
    s_trial: Matrix,
    shear: f64,
    jc: &JohnsonCook,
    eps_p: f64,
    dt: f64,
    t: f64,
) -> Plastic {
    radial_return_at(s_trial, shear, jc, eps_p, dt, yield_at(jc, eps_p, t))
}

/// `radial_return` with the particle's `YieldAt` given (the stress stage keeps it between steps
/// while ε_p and T do not change).
pub fn radial_return_at(
    s_trial: Matrix,
    shear: f64,
    jc: &JohnsonCook,
    eps_p: f64,
    dt: f64,
    at: YieldAt,
) -> Plastic {
    let seq = von_mises(&s_trial);
    let YieldAt { sy0, th } = at;
    if seq <= sy0 {
        return Plastic {
            sdev: s_trial,
            d_eps: 0.0,
            sigma_y: sy0,
            hardening: None,
        };
    }
    // f(Δε) = seq − 3GΔε − σy(Δε) is decreasing, and concave in ln Δε. Holding either growing
    // term of σy at its value at Δε = 0 (the hardening at ε_p, or the rate factor at 1) leaves
    // a larger f, whose root bounds the root from above: Δε ≤ (seq − σy0)/3G, and, where the
    // rate term acts, Δε ≤ Δt ε̇0 exp((seq/σy0 − 1)/C). Newton in ln Δε from the smaller bound
    // descends to the root without passing it, in about two iterations; Newton in Δε bisects
    // down to roots of 1e-13–1e-10 (docs/performance.md, "The radial return in ln Δε"). The
    // bracket is [0, seq/3G], not the bounds, because they are rounded.
    let g3 = 3.0 * shear;
    let linear = (seq - sy0) / g3;
    let viscous = if jc.c > 0.0 && sy0 > 0.0 {
        dt * jc.ref_strain_rate_s * exp((seq / sy0 - 1.0) / jc.c)
    } else {
        f64::INFINITY
    };
    let (mut lo, mut hi) = (0.0, seq / g3);
    let mut de = linear.min(viscous);
    let mut sy = sy0;
    let mut ended = None;
    for _ in 0..60 {
        let e = eps_p + de;
        let hard = hardening(jc, e);
        let rate = de / dt;
        let (rate_term, drate) = rate_factor(jc, rate);
        sy = hard * rate_term * th;
        let fv = seq - g3 * de - sy;
        if fv > 0.0 {
            lo = de;
        } else {
            hi = de;
        }
        if fv.abs() <= 1e-12 * seq || hi - lo <= 1e-15 * hi {
            ended = Some(hard);
            break;
        }
        // df/d(ln Δε) = Δε f′(Δε); the derivative's power only once the step goes on.
        let dfu = -de * (g3 + hardening_slope(jc, e) * rate_term * th) - hard * drate * rate * th;
        let next = de * exp(-fv / dfu);
        // A step below the last bit of Δε: converged as far as f can be evaluated.
        if next == de {
            ended = Some(hard);
            break;
        }
        de = if next > lo && next < hi && dfu < 0.0 {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    let scale = ((seq - 3.0 * shear * de) / seq).max(0.0);
    Plastic {
        sdev: s_trial * scale,
        d_eps: de,
        sigma_y: sy,
        hardening: ended,
    }
}

/// Smallest fracture strain used where eq. 20 goes to zero or below at high triaxiality: such a
/// particle fails within a few steps of plastic flow instead of at once.
pub const MIN_FRACTURE_STRAIN: f64 = 1e-3;

/// Stress triaxiality σ* = −p/σ_eq of eq. 20 from the pressure `pressure` and the von Mises
/// stress `seq` (0 where σ_eq is 0); positive in tension.
#[inline]
pub fn triaxiality(pressure: f64, seq: f64) -> f64 {
    if seq > 0.0 {
        -pressure / seq
    } else {
        0.0
    }
}

/// Johnson–Cook fracture strain (eq. 20) for triaxiality σ* = −p/σ_eq, plastic strain rate and
/// temperature; the rate logarithm is held at 0 below ε̇0f as in eq. 18.
pub fn fracture_strain(
    d: &JohnsonCookDamage,
    jc: &JohnsonCook,
    triax: f64,
    rate: f64,
    t: f64,
) -> f64 {
    let rate_term = if rate > d.ref_strain_rate_s {
        1.0 + d.d4 * ln(rate / d.ref_strain_rate_s)
    } else {
        1.0
    };
    let ef = (d.d1 + d.d2 * exp(d.d3 * triax))
        * rate_term
        * (1.0 + d.d5 * homologous_temperature(jc, t));
    ef.max(MIN_FRACTURE_STRAIN)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;

    #[test]
    fn radial_return_lands_on_the_yield_surface() {
        let m = Material::aisi304();
        let (jc, _) = m.johnson_cook_laws();
        let g = m.shear_modulus();
        let s = Matrix::new(3e9, 1e9, 1e9, -1e9);
        let dt = 1e-9;
        let r = radial_return(s, g, jc, 0.1, dt, 400.0);
        assert!(r.d_eps > 0.0);
        let (sy, _, _) = jc_yield(jc, 0.1 + r.d_eps, r.d_eps / dt, 400.0);
        assert!(
            (von_mises(&r.sdev) - sy).abs() < 1e-6 * sy,
            "{} vs {sy}",
            von_mises(&r.sdev)
        );
        // Consistency: the stress drop is 3GΔε.
        assert!((von_mises(&s) - von_mises(&r.sdev) - 3.0 * g * r.d_eps).abs() < 1e-6 * sy);
    }

    /// f(Δε) of the return, as the solver states it.
    fn residual(s: Matrix, g: f64, jc: &JohnsonCook, eps_p: f64, dt: f64, t: f64, de: f64) -> f64 {
        von_mises(&s) - 3.0 * g * de - jc_yield(jc, eps_p + de, de / dt, t).0
    }

    proptest::proptest! {
        /// Over the states an impact produces (overstress from a hair to 3x, plastic strain
        /// 0-2, steps 0.1-10 ns, room temperature to near melt), the return lands on the
        /// yield surface to the solver's tolerance (|f| <= 1e-12 seq, or the last bit of Δε)
        /// and agrees with a 200-step bisection of f to 1e-9 of Δε.
        #[test]
        fn radial_return_solves_f_to_its_tolerance(
            over in 1e-6f64..2.0,
            eps_p in 0.0f64..2.0,
            dt in 1e-10f64..1e-8,
            t in 293.0f64..1500.0,
            shear_part in -1.0f64..1.0,
        ) {
            let m = Material::aisi304();
            let (jc, _) = m.johnson_cook_laws();
            let g = m.shear_modulus();
            let sy0 = yield_at(jc, eps_p, t).sy0;
            let dir = Matrix::new(1.0, shear_part, shear_part, -1.0);
            let s = dir * ((1.0 + over) * sy0 / von_mises(&dir));
            let r = radial_return(s, g, jc, eps_p, dt, t);
            let seq = von_mises(&s);
            let f = residual(s, g, jc, eps_p, dt, t, r.d_eps);
            let step = residual(s, g, jc, eps_p, dt, t, r.d_eps * (1.0 + 4.0 * f64::EPSILON));
            proptest::prop_assert!(r.d_eps > 0.0 && r.d_eps <= seq / (3.0 * g));
            proptest::prop_assert!(
                f.abs() <= 1e-12 * seq || f.abs() <= (f - step).abs(),
                "f = {f} at seq {seq}"
            );
            let (mut lo, mut hi) = (0.0, seq / (3.0 * g));
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if residual(s, g, jc, eps_p, dt, t, mid) > 0.0 { lo = mid } else { hi = mid }
            }
            proptest::prop_assert!(
                (r.d_eps - lo).abs() <= 1e-9 * lo,
                "{} against bisection {lo}", r.d_eps
            );
            proptest::prop_assert_eq!(r.hardening, Some(hardening(jc, eps_p + r.d_eps)));
        }
    }

    #[test]
    fn elastic_state_is_untouched() {
        let m = Material::aisi304();
        let (jc, _) = m.johnson_cook_laws();
        let s = Matrix::new(1e8, 0.0, 0.0, -1e8);
        let r = radial_return(s, m.shear_modulus(), jc, 0.0, 1e-9, 293.0);
        assert_eq!(r.d_eps, 0.0);
        assert_eq!(r.sdev, s);
    }

    #[test]
    fn yield_is_zero_at_melt_and_rate_term_never_softens() {
        let m = Material::aisi304();
        let (jc, _) = m.johnson_cook_laws();
        assert_eq!(jc_yield(jc, 0.2, 1e3, jc.t_melt_k + 10.0).0, 0.0);
        let slow = jc_yield(jc, 0.0, 1e-8, 293.0).0;
        assert_eq!(slow, jc.a_pa);
    }

    #[test]
    fn fracture_strain_follows_triaxiality() {
        let m = Material::aisi304();
        let (jc, d) = m.johnson_cook_laws();
        let comp = fracture_strain(d, jc, -1.0, 1.0, 293.0);
        let tens = fracture_strain(d, jc, 1.0, 1.0, 293.0);
        assert!(
            comp > tens,
            "compression must be more ductile: {comp} vs {tens}"
        );
        assert!(
            (tens - (-0.7786 + 2.5588 * (-0.3607f64).exp()) * (1.0 - 0.0191 * (1000.0f64).ln()))
                .abs()
                < 1e-12
        );
    }
}
