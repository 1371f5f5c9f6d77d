//! Erosion models fitted to simulated erosion: Oka's model (seed paper eqs. 34–35; Oka,
//! Okamura & Yoshida 2005, Wear 259) and the seed paper's shape-modified Oka model
//! (eqs. 37–38).
//!
//! Angles are in degrees from the surface, as in the seed paper's figures. Hv is the Vickers
//! hardness in GPa taken as a number (the seed: "normalized by 1 GPa").

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Vickers hardness of AISI 304 in GPa, the seed paper's surface (docs/references.md#aisi-304:
/// 1.77–1.8 GPa, the value EDEM and ANSYS Fluent documentation use).
pub const AISI304_HV_GPA: f64 = 1.8;

/// A fit's input or parameters break a rule, or the fit cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// A field breaks a rule; names it, e.g. `points[3].erosion`.
    #[error("{field}: {rule}")]
    Invalid {
        /// Path of the offending field.
        field: String,
        /// The rule broken, in words.
        rule: String,
    },
    /// Fewer points (or distinct angles) than the fit has parameters.
    #[error("too few points: {needed} {what} needed, got {got}")]
    TooFewPoints {
        /// How many are needed.
        needed: usize,
        /// What is counted, e.g. "distinct angles".
        what: &'static str,
        /// How many there are.
        got: usize,
    },
    /// The data cannot determine every parameter.
    #[error("underdetermined: {0}")]
    Underdetermined(String),
    /// The iteration did not settle.
    #[error("no convergence after {iterations} iterations (weighted rss {rss:e})")]
    NotConverged {
        /// Iterations run.
        iterations: usize,
        /// Weighted residual sum of squares reached.
        rss: f64,
    },
}

fn invalid(field: String, rule: impl Into<String>) -> FitError {
    FitError::Invalid {
        field,
        rule: rule.into(),
    }
}

/// Oka's exponents for silica (SiO2) grains: n1 = 0.71 Hv^0.14, n2 = 2.4 Hv^−0.94
/// (Oka et al. 2005; docs/references.md#erosion-models). Hv = 1.8 gives n1 ≈ 0.771, n2 ≈ 1.381.
pub fn oka_silica_exponents(hv_gpa: f64) -> (f64, f64) {
    (0.71 * hv_gpa.powf(0.14), 2.4 * hv_gpa.powf(-0.94))
}

/// Oka's angle function g(α) = (sin α)^n1 (1 + Hv (1 − sin α))^n2, seed paper eq. 35.
pub fn oka_g(angle_deg: f64, n1: f64, n2: f64, hv_gpa: f64) -> f64 {
    let s = angle_deg.to_radians().sin();
    s.powf(n1) * (1.0 + hv_gpa * (1.0 - s)).powf(n2)
}

/// Oka's erosion model E(α) = g(α) E90, seed paper eqs. 34–35.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OkaModel {
    /// Exponent n1 of sin α (eq. 35).
    pub n1: f64,
    /// Exponent n2 of 1 + Hv (1 − sin α) (eq. 35).
    pub n2: f64,
    /// Erosion at 90°, dimensionless (mass lost / grain mass).
    pub e90: f64,
    /// Surface Vickers hardness, GPa.
    pub hv_gpa: f64,
}

impl OkaModel {
    /// Oka's published silica exponents for hardness Hv, with a given E90 (the seed paper
    /// multiplies Oka's g by the simulated E90 for Fig. 11a).
    pub fn silica(hv_gpa: f64, e90: f64) -> Self {
        let (n1, n2) = oka_silica_exponents(hv_gpa);
        OkaModel {
            n1,
            n2,
            e90,
            hv_gpa,
        }
    }

    /// g(α), seed paper eq. 35.
    pub fn g(&self, angle_deg: f64) -> f64 {
        oka_g(angle_deg, self.n1, self.n2, self.hv_gpa)
    }

    /// E(α) = g(α) E90, seed paper eq. 34.
    pub fn erosion(&self, angle_deg: f64) -> f64 {
        self.g(angle_deg) * self.e90
    }

    /// Angle in (0°, 90°] where g(α) is largest, found numerically (grid, then golden
    /// section). For n1, n2 > 0 it is arcsin(n1 (1 + Hv) / (Hv (n1 + n2))) when that is
    /// below 1, else 90°; the tests check the search against that closed form.
    pub fn max_angle_deg(&self) -> f64 {
        argmax_deg(|a| self.g(a))
    }
}

/// Maximiser over (0°, 90°] of a function that is unimodal near its grid maximum.
fn argmax_deg(f: impl Fn(f64) -> f64) -> f64 {
    const STEP: f64 = 0.01;
    let n = (90.0 / STEP).round() as usize;
    let mut best = (STEP, f64::NEG_INFINITY);
    for k in 1..=n {
        let a = k as f64 * STEP;
        let v = f(a);
        if v > best.1 {
            best = (a, v);
        }
    }
    let (mut lo, mut hi) = ((best.0 - STEP).max(STEP * 1e-3), (best.0 + STEP).min(90.0));
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut x1, mut x2) = (hi - r * (hi - lo), lo + r * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..60 {
        if f1 >= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - r * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + r * (hi - lo);
            f2 = f(x2);
        }
    }
    let mid = 0.5 * (lo + hi);
    // The golden search cannot land on the closed end 90°, where g often peaks.
    if f(90.0) >= f(mid) {
        90.0
    } else {
        mid
    }
}

fn one() -> f64 {
    1.0
}

/// A simulated erosion at one angle, for fitting Oka's model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErosionPoint {
    /// Impact angle, degrees from the surface, in (0, 90].
    pub angle_deg: f64,
    /// Erosion, dimensionless.
    pub erosion: f64,
    /// Weight of the squared residual, e.g. 1/sem²; 1 when absent.
    #[serde(default = "one")]
    pub weight: f64,
}

/// Standard errors of the fitted Oka parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OkaStdErrors {
    /// Standard error of n1.
    pub n1: f64,
    /// Standard error of n2.
    pub n2: f64,
    /// Standard error of E90.
    pub e90: f64,
}

/// Oka's model least-squares fitted to simulated erosion (seed paper Fig. 11a).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OkaFit {
    /// Fitted n1, n2 and E90 (Hv as given).
    pub model: OkaModel,
    /// Erosion minus model at each point, in input order.
    pub residuals: Vec<f64>,
    /// Weighted residual sum of squares, Σ w r².
    pub rss: f64,
    /// Standard errors from s² (JᵀWJ)⁻¹ with s² = rss/(m − 3); `null` unless m > 3.
    pub std_errors: Option<OkaStdErrors>,
    /// Angle of maximum erosion, degrees.
    pub angle_max_deg: f64,
    /// Levenberg–Marquardt iterations taken.
    pub iterations: usize,
}

fn check_hv(hv_gpa: f64) -> Result<(), FitError> {
    if hv_gpa.is_finite() && hv_gpa > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            "hv_gpa".into(),
            format!("must be finite and > 0, got {hv_gpa}"),
        ))
    }
}

fn check_point(i: usize, angle_deg: f64, erosion: f64, weight: f64) -> Result<(), FitError> {
    if !(angle_deg.is_finite() && angle_deg > 0.0 && angle_deg <= 90.0) {
        return Err(invalid(
            format!("points[{i}].angle_deg"),
            format!("must be in (0, 90], got {angle_deg}"),
        ));
    }
    if !erosion.is_finite() {
        return Err(invalid(
            format!("points[{i}].erosion"),
            format!("must be finite, got {erosion}"),
        ));
    }
    if !(weight.is_finite() && weight > 0.0) {
        return Err(invalid(
            format!("points[{i}].weight"),
            format!("must be finite and > 0, got {weight}"),
        ));
    }
    Ok(())
}

fn distinct_angles(angles: impl Iterator<Item = f64>) -> usize {
    let mut a: Vec<f64> = angles.collect();
    a.sort_by(f64::total_cmp);
    a.dedup();
    a.len()
}

/// Weighted residuals √w (model − y) and Jacobian rows ∂/∂(n1, n2, E90), eq. 34–35.
fn oka_residuals(points: &[ErosionPoint], hv: f64, p: &Vector3<f64>) -> (Vec<f64>, Vec<[f64; 3]>) {
    let mut r = Vec::with_capacity(points.len());
    let mut j = Vec::with_capacity(points.len());
    for pt in points {
        let s = pt.angle_deg.to_radians().sin();
        let (ls, lh) = (s.ln(), (1.0 + hv * (1.0 - s)).ln());
        let g = (p[0] * ls + p[1] * lh).exp();
        let model = g * p[2];
        let sw = pt.weight.sqrt();
        r.push(sw * (model - pt.erosion));
        j.push([sw * model * ls, sw * model * lh, sw * g]);
    }
    (r, j)
}

/// Start for the iteration: ln E = ln E90 + n1 ln sin α + n2 ln(1 + Hv(1 − sin α)) is linear,
/// so when every erosion is positive a log-space fit (delta-method weights w E²) lands
/// next to the answer; otherwise Oka's silica exponents with the best E90 for them.
fn oka_start(points: &[ErosionPoint], hv: f64) -> Vector3<f64> {
    if points.iter().all(|p| p.erosion > 0.0) {
        let m = points.len();
        let mut a = DMatrix::zeros(m, 3);
        let mut b = DVector::zeros(m);
        for (i, pt) in points.iter().enumerate() {
            let s = pt.angle_deg.to_radians().sin();
            let sw = pt.weight.sqrt() * pt.erosion;
            a[(i, 0)] = sw * s.ln();
            a[(i, 1)] = sw * (1.0 + hv * (1.0 - s)).ln();
            a[(i, 2)] = sw;
            b[i] = sw * pt.erosion.ln();
        }
        if let Ok(x) = a.svd(true, true).solve(&b, 1e-14) {
            if x.iter().all(|v| v.is_finite()) {
                return Vector3::new(x[0], x[1], x[2].exp());
            }
        }
    }
    let (n1, n2) = oka_silica_exponents(hv);
    let (mut num, mut den) = (0.0, 0.0);
    for pt in points {
        let g = oka_g(pt.angle_deg, n1, n2, hv);
        num += pt.weight * g * pt.erosion;
        den += pt.weight * g * g;
    }
    Vector3::new(n1, n2, num / den)
}

const LM_MAX_ITER: usize = 500;

/// Levenberg–Marquardt with Marquardt's diagonal scaling, so E90 (≈1e-3) and the
/// exponents (≈1) need no manual scaling.
fn levenberg_marquardt(
    points: &[ErosionPoint],
    hv: f64,
    start: Vector3<f64>,
) -> Result<(Vector3<f64>, usize), FitError> {
    let rss_of = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
    let mut p = start;
    let (mut r, mut j) = oka_residuals(points, hv, &p);
    let mut rss = rss_of(&r);
    let mut lambda = 1e-3;
    for iter in 1..=LM_MAX_ITER {
        let mut jtj = Matrix3::zeros();
        let mut jtr = Vector3::zeros();
        for (ri, ji) in r.iter().zip(&j) {
            let jv = Vector3::from(*ji);
            jtj += jv * jv.transpose();
            jtr += jv * *ri;
        }
        let dmax = jtj.diagonal().max();
        let accepted = loop {
            let mut a = jtj;
            for k in 0..3 {
                a[(k, k)] += lambda * jtj[(k, k)].max(1e-12 * dmax);
            }
            let step = a.cholesky().map(|c| c.solve(&(-jtr)));
            if let Some(step) = step.filter(|s| s.iter().all(|v| v.is_finite())) {
                let trial = p + step;
                let (tr, tj) = oka_residuals(points, hv, &trial);
                let trss = rss_of(&tr);
                if trss.is_finite() && trss < rss {
                    let small_step = (0..3).all(|k| step[k].abs() <= 1e-10 * (p[k].abs() + 1e-12));
                    let small_gain = rss - trss <= 1e-14 * rss;
                    (p, r, j, rss) = (trial, tr, tj, trss);
                    lambda = (lambda / 10.0).max(1e-15);
                    break Some(small_step || small_gain);
                }
            }
            lambda *= 10.0;
            if lambda > 1e16 {
                break None;
            }
        };
        match accepted {
            // No step lowers the rss even when damped to a tiny gradient step: a minimum
            // at working precision.
            None => return Ok((p, iter)),
            Some(true) => return Ok((p, iter)),
            Some(false) => {}
        }
        if rss == 0.0 {
            return Ok((p, iter));
        }
    }
    Err(FitError::NotConverged {
        iterations: LM_MAX_ITER,
        rss,
    })
}

/// Least-squares fit of n1, n2 and E90 of Oka's model (eqs. 34–35) to simulated erosion,
/// by Levenberg–Marquardt with the analytic Jacobian; Hv fixed.
pub fn fit_oka(points: &[ErosionPoint], hv_gpa: f64) -> Result<OkaFit, FitError> {
    check_hv(hv_gpa)?;
    for (i, p) in points.iter().enumerate() {
        check_point(i, p.angle_deg, p.erosion, p.weight)?;
    }
    let distinct = distinct_angles(points.iter().map(|p| p.angle_deg));
    if distinct < 3 {
        return Err(FitError::TooFewPoints {
            needed: 3,
            what: "distinct angles",
            got: distinct,
        });
    }
    if points
        .iter()
        .all(|p| p.angle_deg == 90.0 || p.erosion == 0.0)
    {
        return Err(FitError::Underdetermined(
            "every point off 90° has zero erosion; n1 and n2 are not determined".into(),
        ));
    }
    let (p, iterations) = levenberg_marquardt(points, hv_gpa, oka_start(points, hv_gpa))?;
    let model = OkaModel {
        n1: p[0],
        n2: p[1],
        e90: p[2],
        hv_gpa,
    };
    let (r, j) = oka_residuals(points, hv_gpa, &p);
    let rss: f64 = r.iter().map(|x| x * x).sum();
    let m = points.len();
    let std_errors = (m > 3)
        .then(|| {
            let mut jtj = Matrix3::zeros();
            for ji in &j {
                let jv = Vector3::from(*ji);
                jtj += jv * jv.transpose();
            }
            jtj.try_inverse()
        })
        .flatten()
        .map(|cov| {
            let s2 = rss / (m - 3) as f64;
            OkaStdErrors {
                n1: (s2 * cov[(0, 0)]).sqrt(),
                n2: (s2 * cov[(1, 1)]).sqrt(),
                e90: (s2 * cov[(2, 2)]).sqrt(),
            }
        });
    Ok(OkaFit {
        residuals: points
            .iter()
            .map(|pt| pt.erosion - model.erosion(pt.angle_deg))
            .collect(),
        rss,
        std_errors,
        angle_max_deg: model.max_angle_deg(),
        iterations,
        model,
    })
}

/// Exponents n3..n6 of the shape modification h (seed paper eq. 38).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ShapeExponents {
    /// Exponent of e/e_ref at every angle.
    pub n3: f64,
    /// Exponent of An/An_ref at every angle.
    pub n4: f64,
    /// Exponent of e/e_ref per degree above 45°.
    pub n5: f64,
    /// Exponent of An/An_ref per degree above 45°.
    pub n6: f64,
}

impl ShapeExponents {
    /// The seed paper's values, section 4 (Fig. 14): −0.5, 1.5, −0.003, 0.03.
    pub const SEED: ShapeExponents = ShapeExponents {
        n3: -0.5,
        n4: 1.5,
        n5: -0.003,
        n6: 0.03,
    };
}

/// Reference grain of the shape modification (seed paper eq. 38): its e and An.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ShapeReference {
    /// Reference aspect ratio e_ref.
    pub aspect_ratio: f64,
    /// Reference angularity An_ref.
    pub angularity: f64,
}

impl ShapeReference {
    /// The hexagon, the seed paper's reference: e = 2/√3 (Table 2: 1.155), An = 3.0 — the
    /// exact values `shapes` computes, so a hexagon gets h = 1 exactly.
    pub const HEXAGON: ShapeReference = ShapeReference {
        aspect_ratio: 1.154_700_538_379_251_5,
        angularity: 3.0,
    };
}

/// h(e, An, α) = (e/e_ref)^n3 (An/An_ref)^n4, times (e/e_ref)^(n5(α−45))
/// (An/An_ref)^(n6(α−45)) for α > 45°; seed paper eq. 38, α in degrees.
pub fn shape_modification(
    angle_deg: f64,
    aspect_ratio: f64,
    angularity: f64,
    reference: &ShapeReference,
    n: &ShapeExponents,
) -> f64 {
    let (le, la) = (
        (aspect_ratio / reference.aspect_ratio).ln(),
        (angularity / reference.angularity).ln(),
    );
    let above = (angle_deg - 45.0).max(0.0);
    (n.n3 * le + n.n4 * la + above * (n.n5 * le + n.n6 * la)).exp()
}

/// Shape-modified Oka model E = g(α) h(e, An, α) E90, seed paper eq. 37.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModifiedOkaModel {
    /// Oka's g and E90 fitted to the reference grain.
    pub oka: OkaModel,
    /// Reference grain.
    pub reference: ShapeReference,
    /// n3..n6.
    pub exponents: ShapeExponents,
}

impl ModifiedOkaModel {
    /// h(e, An, α), eq. 38.
    pub fn h(&self, angle_deg: f64, aspect_ratio: f64, angularity: f64) -> f64 {
        shape_modification(
            angle_deg,
            aspect_ratio,
            angularity,
            &self.reference,
            &self.exponents,
        )
    }

    /// E(α) = g(α) h(e, An, α) E90, eq. 37.
    pub fn erosion(&self, angle_deg: f64, aspect_ratio: f64, angularity: f64) -> f64 {
        self.oka.erosion(angle_deg) * self.h(angle_deg, aspect_ratio, angularity)
    }
}

/// A simulated erosion of one grain shape at one angle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ShapedPoint {
    /// Impact angle, degrees from the surface, in (0, 90].
    pub angle_deg: f64,
    /// Grain aspect ratio e.
    pub aspect_ratio: f64,
    /// Grain angularity An.
    pub angularity: f64,
    /// Erosion, dimensionless; must be > 0 for the log-space fit.
    pub erosion: f64,
    /// Weight of the squared residual, e.g. 1/sem²; 1 when absent.
    #[serde(default = "one")]
    pub weight: f64,
}

/// n3..n6 fitted to simulated erosion of several shapes (seed paper eq. 38, Fig. 14).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModifiedOkaFit {
    /// The model with fitted n3..n6.
    pub model: ModifiedOkaModel,
    /// The seed paper's n3..n6, for comparison.
    pub seed: ShapeExponents,
    /// Erosion minus model at each point, in input order.
    pub residuals: Vec<f64>,
    /// Weighted residual sum of squares in erosion, Σ w r².
    pub rss: f64,
}

/// Fits n3..n6 given the reference grain's Oka g and E90 (eq. 37–38). ln(E / (g E90)) is
/// linear in n3..n6, so this is weighted linear least squares in log space, with each
/// point's weight w turned into w E² (delta method: σ_lnE ≈ σ_E / E) so the fit
/// approximates least squares in erosion.
pub fn fit_modified_oka(
    points: &[ShapedPoint],
    oka: &OkaModel,
    reference: &ShapeReference,
) -> Result<ModifiedOkaFit, FitError> {
    check_hv(oka.hv_gpa)?;
    if !(oka.e90.is_finite() && oka.e90 > 0.0 && oka.n1.is_finite() && oka.n2.is_finite()) {
        return Err(invalid(
            "oka".into(),
            format!("needs finite n1, n2 and E90 > 0, got {oka:?}"),
        ));
    }
    for (name, v) in [
        ("reference.aspect_ratio", reference.aspect_ratio),
        ("reference.angularity", reference.angularity),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                name.into(),
                format!("must be finite and > 0, got {v}"),
            ));
        }
    }
    for (i, p) in points.iter().enumerate() {
        check_point(i, p.angle_deg, p.erosion, p.weight)?;
        if p.erosion <= 0.0 {
            return Err(invalid(
                format!("points[{i}].erosion"),
                format!(
                    "must be > 0 for the log-space fit, got {}; drop or re-run that cell",
                    p.erosion
                ),
            ));
        }
        for (name, v) in [
            ("aspect_ratio", p.aspect_ratio),
            ("angularity", p.angularity),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    format!("points[{i}].{name}"),
                    format!("must be finite and > 0, got {v}"),
                ));
            }
        }
    }
    if points.len() < 4 {
        return Err(FitError::TooFewPoints {
            needed: 4,
            what: "points",
            got: points.len(),
        });
    }
    let m = points.len();
    let mut a = DMatrix::zeros(m, 4);
    let mut b = DVector::zeros(m);
    for (i, p) in points.iter().enumerate() {
        let le = (p.aspect_ratio / reference.aspect_ratio).ln();
        let la = (p.angularity / reference.angularity).ln();
        let above = (p.angle_deg - 45.0).max(0.0);
        let sw = p.weight.sqrt() * p.erosion;
        let row = [le, la, above * le, above * la];
        for (k, v) in row.iter().enumerate() {
            a[(i, k)] = sw * v;
        }
        b[i] = sw * (p.erosion / oka.erosion(p.angle_deg)).ln();
    }
    let svd = a.svd(true, true);
    let smax = svd.singular_values.max();
    let tol = 1e-10 * smax;
    let rank = svd.rank(tol);
    if smax == 0.0 || rank < 4 {
        return Err(FitError::Underdetermined(format!(
            "the points determine {rank} of n3..n6; they need shapes whose (e, An) ratios to \
             the reference are not proportional, both at or below 45° and above 45°"
        )));
    }
    let x = svd
        .solve(&b, tol)
        .map_err(|e| FitError::Underdetermined(e.to_string()))?;
    let model = ModifiedOkaModel {
        oka: *oka,
        reference: *reference,
        exponents: ShapeExponents {
            n3: x[0],
            n4: x[1],
            n5: x[2],
            n6: x[3],
        },
    };
    let residuals: Vec<f64> = points
        .iter()
        .map(|p| p.erosion - model.erosion(p.angle_deg, p.aspect_ratio, p.angularity))
        .collect();
    let rss = residuals
        .iter()
        .zip(points)
        .map(|(r, p)| p.weight * r * r)
        .sum();
    Ok(ModifiedOkaFit {
        model,
        seed: ShapeExponents::SEED,
        residuals,
        rss,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::shapes::Shape;
    use proptest::prelude::*;

    const ANGLES: [f64; 6] = [15.0, 30.0, 45.0, 60.0, 75.0, 90.0];

    fn points(model: &OkaModel, angles: &[f64]) -> Vec<ErosionPoint> {
        angles
            .iter()
            .map(|&a| ErosionPoint {
                angle_deg: a,
                erosion: model.erosion(a),
                weight: 1.0,
            })
            .collect()
    }

    #[test]
    fn oka_silica_on_aisi_304_matches_notes() {
        let m = OkaModel::silica(AISI304_HV_GPA, 1.0);
        assert!(
            (m.n1 - 0.771).abs() < 5e-4 && (m.n2 - 1.381).abs() < 5e-4,
            "{m:?}"
        );
        assert!((m.g(90.0) - 1.0).abs() < 1e-15);
        assert!((m.g(45.0) - 1.37).abs() < 5e-3, "{}", m.g(45.0));
        let peak = m.max_angle_deg();
        assert!((peak - 34.0).abs() < 0.5, "{peak}");
    }

    #[test]
    fn max_angle_search_matches_closed_form() {
        for (n1, n2, hv) in [
            (0.771, 1.381, 1.8),
            (0.5, 2.0, 1.0),
            (1.2, 0.9, 2.5),
            (2.0, 0.1, 1.0),
        ] {
            let m = OkaModel {
                n1,
                n2,
                e90: 1.0,
                hv_gpa: hv,
            };
            let s = n1 * (1.0 + hv) / (hv * (n1 + n2));
            let expected = if s < 1.0 { s.asin().to_degrees() } else { 90.0 };
            assert!(
                (m.max_angle_deg() - expected).abs() < 1e-6,
                "{n1} {n2} {hv}"
            );
        }
    }

    #[test]
    fn oka_fit_recovers_exact_parameters() {
        let truth = OkaModel {
            n1: 0.771,
            n2: 1.381,
            e90: 2.3e-3,
            hv_gpa: AISI304_HV_GPA,
        };
        let fit = fit_oka(&points(&truth, &ANGLES), AISI304_HV_GPA).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-8 * b.abs();
        assert!(
            close(fit.model.n1, truth.n1) && close(fit.model.n2, truth.n2),
            "{fit:?}"
        );
        assert!(close(fit.model.e90, truth.e90));
        assert!(fit.residuals.iter().all(|r| r.abs() < 1e-12 * truth.e90));
        assert!((fit.angle_max_deg - truth.max_angle_deg()).abs() < 1e-6);
    }

    #[test]
    fn levenberg_marquardt_converges_from_a_poor_start() {
        let truth = OkaModel {
            n1: 1.1,
            n2: 0.6,
            e90: 4e-4,
            hv_gpa: 1.2,
        };
        let pts = points(&truth, &ANGLES);
        let (p, iterations) = levenberg_marquardt(&pts, 1.2, Vector3::new(0.2, 2.5, 4e-3)).unwrap();
        assert!(
            (p[0] - 1.1).abs() < 1e-7 && (p[1] - 0.6).abs() < 1e-7,
            "{p:?}"
        );
        assert!((p[2] - 4e-4).abs() < 1e-7 * 4e-4);
        assert!(iterations > 1);
    }

    #[test]
    fn oka_fit_with_noise_stays_near_truth() {
        let truth = OkaModel::silica(AISI304_HV_GPA, 1.5e-3);
        let angles: Vec<f64> = (1..=18).map(|k| 5.0 * k as f64).collect();
        let eps = crate::models::test_noise(angles.len(), 0);
        let pts: Vec<ErosionPoint> = angles
            .iter()
            .zip(&eps)
            .map(|(&a, e)| ErosionPoint {
                angle_deg: a,
                erosion: truth.erosion(a) * (1.0 + 0.01 * e),
                weight: 1.0,
            })
            .collect();
        let fit = fit_oka(&pts, AISI304_HV_GPA).unwrap();
        let se = fit.std_errors.unwrap();
        assert!((fit.model.n1 - truth.n1).abs() < 0.05, "{fit:?}");
        assert!((fit.model.n2 - truth.n2).abs() < 0.1, "{fit:?}");
        assert!(
            (fit.model.e90 - truth.e90).abs() < 0.02 * truth.e90,
            "{fit:?}"
        );
        assert!((fit.model.n1 - truth.n1).abs() < 4.0 * se.n1);
        assert!((fit.angle_max_deg - truth.max_angle_deg()).abs() < 2.0);
    }

    #[test]
    fn oka_fit_accepts_zero_erosion_and_weights() {
        let truth = OkaModel::silica(AISI304_HV_GPA, 1e-3);
        let mut pts = points(&truth, &ANGLES);
        pts.push(ErosionPoint {
            angle_deg: 2.0,
            erosion: 0.0,
            weight: 1e-6,
        });
        let fit = fit_oka(&pts, AISI304_HV_GPA).unwrap();
        assert!((fit.model.n1 - truth.n1).abs() < 0.05, "{fit:?}");
        let json: ErosionPoint =
            serde_json::from_str(r#"{"angle_deg": 30, "erosion": 1e-3}"#).unwrap();
        assert_eq!(json.weight, 1.0);
    }

    #[test]
    fn oka_fit_errors_are_clear() {
        let truth = OkaModel::silica(AISI304_HV_GPA, 1e-3);
        let two = points(&truth, &[30.0, 30.0, 90.0]);
        assert!(matches!(
            fit_oka(&two, 1.8),
            Err(FitError::TooFewPoints {
                needed: 3,
                got: 2,
                ..
            })
        ));
        let mut bad = points(&truth, &ANGLES);
        bad[2].erosion = f64::INFINITY;
        assert!(fit_oka(&bad, 1.8)
            .unwrap_err()
            .to_string()
            .starts_with("points[2].erosion"));
        let mut bad = points(&truth, &ANGLES);
        bad[0].angle_deg = 0.0;
        assert!(fit_oka(&bad, 1.8)
            .unwrap_err()
            .to_string()
            .starts_with("points[0].angle_deg"));
        let mut bad = points(&truth, &ANGLES);
        bad[1].weight = -1.0;
        assert!(fit_oka(&bad, 1.8).is_err());
        assert!(fit_oka(&points(&truth, &ANGLES), f64::NAN).is_err());
        let zeros: Vec<ErosionPoint> = ANGLES
            .iter()
            .map(|&a| ErosionPoint {
                angle_deg: a,
                erosion: if a == 90.0 { 1e-3 } else { 0.0 },
                weight: 1.0,
            })
            .collect();
        assert!(matches!(
            fit_oka(&zeros, 1.8),
            Err(FitError::Underdetermined(_))
        ));
    }

    fn shaped_points(
        model: &ModifiedOkaModel,
        shapes: &[Shape],
        angles: &[f64],
    ) -> Vec<ShapedPoint> {
        let mut out = Vec::new();
        for s in shapes {
            let (an, e) = s.factors().unwrap();
            for &a in angles {
                out.push(ShapedPoint {
                    angle_deg: a,
                    aspect_ratio: e,
                    angularity: an,
                    erosion: model.erosion(a, e, an),
                    weight: 1.0,
                });
            }
        }
        out
    }

    #[test]
    fn hexagon_reference_gives_h_of_one() {
        let (an, e) = Shape::Hexagon.factors().unwrap();
        for a in ANGLES {
            let h = shape_modification(a, e, an, &ShapeReference::HEXAGON, &ShapeExponents::SEED);
            assert!((h - 1.0).abs() < 1e-14, "{h}");
        }
        assert_eq!(
            format!("{:.3}", ShapeReference::HEXAGON.aspect_ratio),
            "1.155"
        );
    }

    #[test]
    fn seed_h_is_continuous_at_45_and_favours_angular_grains() {
        let r = ShapeReference::HEXAGON;
        let n = ShapeExponents::SEED;
        let (an, e) = Shape::Square.factors().unwrap();
        let below = shape_modification(45.0, e, an, &r, &n);
        let above = shape_modification(45.0 + 1e-9, e, an, &r, &n);
        assert!((below - above).abs() < 1e-9);
        assert!(shape_modification(90.0, e, an, &r, &n) > below);
        let (an_r, e_r) = Shape::Rectangle.factors().unwrap();
        assert!(
            shape_modification(90.0, e_r, an_r, &r, &n) < shape_modification(90.0, e, an, &r, &n)
        );
    }

    #[test]
    fn modified_oka_fit_recovers_seed_exponents() {
        let oka = OkaModel::silica(AISI304_HV_GPA, 1.2e-3);
        let truth = ModifiedOkaModel {
            oka,
            reference: ShapeReference::HEXAGON,
            exponents: ShapeExponents::SEED,
        };
        let pts = shaped_points(&truth, &Shape::paper(), &ANGLES);
        let fit = fit_modified_oka(&pts, &oka, &ShapeReference::HEXAGON).unwrap();
        let (f, t) = (fit.model.exponents, ShapeExponents::SEED);
        for (a, b) in [(f.n3, t.n3), (f.n4, t.n4), (f.n5, t.n5), (f.n6, t.n6)] {
            assert!((a - b).abs() < 1e-9 * b.abs(), "{f:?}");
        }
        assert_eq!(fit.seed, ShapeExponents::SEED);
        assert!(fit.rss < 1e-30);
    }

    #[test]
    fn modified_oka_fit_errors_are_clear() {
        let oka = OkaModel::silica(AISI304_HV_GPA, 1e-3);
        let truth = ModifiedOkaModel {
            oka,
            reference: ShapeReference::HEXAGON,
            exponents: ShapeExponents::SEED,
        };
        let hex_only = shaped_points(&truth, &[Shape::Hexagon], &ANGLES);
        assert!(matches!(
            fit_modified_oka(&hex_only, &oka, &ShapeReference::HEXAGON),
            Err(FitError::Underdetermined(_))
        ));
        let low_only = shaped_points(&truth, &Shape::paper(), &[15.0, 30.0, 45.0]);
        assert!(matches!(
            fit_modified_oka(&low_only, &oka, &ShapeReference::HEXAGON),
            Err(FitError::Underdetermined(_))
        ));
        let mut neg = shaped_points(&truth, &Shape::paper(), &ANGLES);
        neg[5].erosion = 0.0;
        let err = fit_modified_oka(&neg, &oka, &ShapeReference::HEXAGON)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("points[5].erosion: must be > 0"), "{err}");
        let few = &shaped_points(&truth, &Shape::paper(), &ANGLES)[..3];
        assert!(matches!(
            fit_modified_oka(few, &oka, &ShapeReference::HEXAGON),
            Err(FitError::TooFewPoints { needed: 4, .. })
        ));
    }

    proptest! {
        #[test]
        fn oka_fit_recovers_random_models(
            n1 in 0.2..1.6f64, n2 in 0.2..2.5f64, e90 in 1e-6..1e-1f64, hv in 0.5..3.0f64,
        ) {
            let truth = OkaModel { n1, n2, e90, hv_gpa: hv };
            let fit = fit_oka(&points(&truth, &ANGLES), hv).unwrap();
            prop_assert!((fit.model.n1 - n1).abs() < 1e-6, "{:?}", fit);
            prop_assert!((fit.model.n2 - n2).abs() < 1e-6, "{:?}", fit);
            prop_assert!((fit.model.e90 - e90).abs() < 1e-6 * e90, "{:?}", fit);
        }

        #[test]
        fn lm_recovers_random_models_from_silica_start(
            n1 in 0.3..1.3f64, n2 in 0.5..2.0f64, e90 in 1e-5..1e-2f64,
        ) {
            let truth = OkaModel { n1, n2, e90, hv_gpa: 1.8 };
            let pts = points(&truth, &ANGLES);
            let (s1, s2) = oka_silica_exponents(1.8);
            let (p, _) = levenberg_marquardt(&pts, 1.8, Vector3::new(s1, s2, 1e-3)).unwrap();
            prop_assert!((p[0] - n1).abs() < 1e-6 && (p[1] - n2).abs() < 1e-6, "{:?}", p);
        }

        #[test]
        fn modified_oka_fit_recovers_random_exponents(
            n3 in -2.0..2.0f64, n4 in -2.0..3.0f64, n5 in -0.02..0.02f64, n6 in -0.05..0.05f64,
        ) {
            let oka = OkaModel::silica(AISI304_HV_GPA, 1e-3);
            let exponents = ShapeExponents { n3, n4, n5, n6 };
            let truth = ModifiedOkaModel { oka, reference: ShapeReference::HEXAGON, exponents };
            let pts = shaped_points(&truth, &Shape::paper(), &ANGLES);
            let f = fit_modified_oka(&pts, &oka, &ShapeReference::HEXAGON).unwrap().model.exponents;
            prop_assert!((f.n3 - n3).abs() < 1e-8 && (f.n4 - n4).abs() < 1e-8);
            prop_assert!((f.n5 - n5).abs() < 1e-10 && (f.n6 - n6).abs() < 1e-10);
        }
    }
}
