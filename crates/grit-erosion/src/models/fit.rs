//! The full Oka model E(α, v, d) = E90,ref g(α) h(e, An, α) (v/v_ref)^k2 (d/d_ref)^k3 (Oka &
//! Yoshida 2005, *Wear* 259, 102–109, eq. 4 with g of seed eq. 35; h of seed eq. 38), fitted
//! jointly to the steady cells of one or more results files, weighted by their standard errors.
//!
//! ln E is linear in θ = (ln E90,ref, n1, n2, k2, k3, n3..n6), so the fit is a least-squares
//! problem in erosion (weights 1/s.e.²) whose start comes from the weighted linear fit in log
//! space; Levenberg–Marquardt then takes a few steps. Any parameter may be fixed at a value
//! instead of fitted, which the data demand when they cannot determine it (one speed, one size).

use std::collections::BTreeMap;

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::impact::aggregate::CampaignResults;
use crate::models::compare::spec_number;
use crate::models::oka::{
    oka_g, oka_silica_exponents, shape_modification, FitError, ShapeExponents, ShapeReference,
};
use crate::models::shapes::Shape;

/// Oka's reference speed for his silica correlation, m/s (Oka & Yoshida 2005, Table 2).
pub const OKA_V_REF_M_S: f64 = 104.0;
/// Oka's reference grain size for his silica correlation, m (326 µm; Oka & Yoshida 2005).
pub const OKA_D_REF_M: f64 = 326e-6;

/// Oka's speed exponent for silica grains, k2 = 2.3 Hv^0.038 (Oka & Yoshida 2005, Table 2).
pub fn oka_silica_k2(hv_gpa: f64) -> f64 {
    2.3 * hv_gpa.powf(0.038)
}

/// Oka's size exponent for silica grains, k3 = 0.19 (Oka & Yoshida 2005, Table 2).
pub const OKA_SILICA_K3: f64 = 0.19;

/// Oka's reference-erosion constant for silica grains, K = 65 mm³ of target per kg of grains
/// (Oka & Yoshida 2005, Table 2).
pub const OKA_SILICA_K_MM3_PER_KG: f64 = 65.0;

/// Oka's hardness exponent of E90 for silica grains, k1 = −0.12 (Oka & Yoshida 2005, Table 2).
pub const OKA_SILICA_K1: f64 = -0.12;

/// Oka's predicted normal-impact erosion of a target of hardness `hv_gpa` (GPa, taken as a
/// number) and density `density_kg_m3` by silica grains of diameter `d_m` at `v_m_s`, as mass
/// lost per mass of grains: E90 = K Hv^k1 (v/V′)^k2 (d/D′)^k3 (Oka & Yoshida 2005, eq. 4,
/// Table 2), the volume turned into mass with the target's density.
pub fn oka_silica_e90(hv_gpa: f64, density_kg_m3: f64, v_m_s: f64, d_m: f64) -> f64 {
    let mm3_per_kg = OKA_SILICA_K_MM3_PER_KG
        * hv_gpa.powf(OKA_SILICA_K1)
        * (v_m_s / OKA_V_REF_M_S).powf(oka_silica_k2(hv_gpa))
        * (d_m / OKA_D_REF_M).powf(OKA_SILICA_K3);
    mm3_per_kg * 1e-9 * density_kg_m3
}

/// A parameter of the full Oka model (Oka & Yoshida 2005 eq. 4; seed eqs. 35, 38).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Param {
    /// E90 at v_ref and d_ref for the reference grain (mass lost / grain mass).
    E90Ref,
    /// Exponent of sin α (seed eq. 35).
    N1,
    /// Exponent of 1 + Hv (1 − sin α) (seed eq. 35).
    N2,
    /// Speed exponent (Oka & Yoshida 2005 eq. 4).
    K2,
    /// Size exponent (Oka & Yoshida 2005 eq. 4).
    K3,
    /// Exponent of e/e_ref (seed eq. 38).
    N3,
    /// Exponent of An/An_ref (seed eq. 38).
    N4,
    /// Exponent of e/e_ref per degree above 45° (seed eq. 38).
    N5,
    /// Exponent of An/An_ref per degree above 45° (seed eq. 38).
    N6,
}

impl Param {
    /// Every parameter, in the order of θ.
    pub const ALL: [Param; 9] = [
        Param::E90Ref,
        Param::N1,
        Param::N2,
        Param::K2,
        Param::K3,
        Param::N3,
        Param::N4,
        Param::N5,
        Param::N6,
    ];

    /// The name in files and on the command line (`e90_ref`, `n1`, …).
    pub fn name(self) -> &'static str {
        match self {
            Param::E90Ref => "e90_ref",
            Param::N1 => "n1",
            Param::N2 => "n2",
            Param::K2 => "k2",
            Param::K3 => "k3",
            Param::N3 => "n3",
            Param::N4 => "n4",
            Param::N5 => "n5",
            Param::N6 => "n6",
        }
    }

    /// The parameter of that name, if any.
    pub fn from_name(name: &str) -> Option<Param> {
        Param::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The published value: Oka's for silica at hardness Hv (n1, n2, k2, k3; Oka & Yoshida
    /// 2005) or the seed's n3..n6 (Fig. 14); `None` for E90, which is the simulation's own.
    pub fn published(self, hv_gpa: f64) -> Option<f64> {
        let (n1, n2) = oka_silica_exponents(hv_gpa);
        let s = ShapeExponents::SEED;
        match self {
            Param::E90Ref => None,
            Param::N1 => Some(n1),
            Param::N2 => Some(n2),
            Param::K2 => Some(oka_silica_k2(hv_gpa)),
            Param::K3 => Some(OKA_SILICA_K3),
            Param::N3 => Some(s.n3),
            Param::N4 => Some(s.n4),
            Param::N5 => Some(s.n5),
            Param::N6 => Some(s.n6),
        }
    }

    fn is_shape(self) -> bool {
        matches!(self, Param::N3 | Param::N4 | Param::N5 | Param::N6)
    }
}

/// The full Oka model E = E90,ref g(α) h(e, An, α) (v/v_ref)^k2 (d/d_ref)^k3 (Oka & Yoshida
/// 2005 eq. 4; seed eqs. 35 and 38). Erosion is mass lost over grain mass; in grit's 2D plane
/// strain both are per unit depth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FullOkaModel {
    /// Erosion at 90°, v_ref and d_ref, reference grain (kg of target per kg of grains).
    pub e90_ref: f64,
    /// Exponent of sin α.
    pub n1: f64,
    /// Exponent of 1 + Hv (1 − sin α).
    pub n2: f64,
    /// Speed exponent.
    pub k2: f64,
    /// Size exponent.
    pub k3: f64,
    /// Target Vickers hardness, GPa taken as a number (seed eq. 35).
    pub hv_gpa: f64,
    /// Reference speed, m/s.
    pub v_ref_m_s: f64,
    /// Reference grain diameter (of the circle of equal area), m.
    pub d_ref_m: f64,
    /// Reference grain of the shape modification.
    pub reference: ShapeReference,
    /// n3..n6, when cells of other shapes entered the fit; `null`: the model holds for the
    /// reference grain only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_exponents: Option<ShapeExponents>,
}

impl FullOkaModel {
    /// g(α) = (sin α)^n1 (1 + Hv (1 − sin α))^n2, seed eq. 35, α in degrees.
    pub fn g(&self, angle_deg: f64) -> f64 {
        oka_g(angle_deg, self.n1, self.n2, self.hv_gpa)
    }

    /// E(α, v, d) for the reference grain, Oka & Yoshida 2005 eq. 4 with seed eq. 35.
    pub fn erosion(&self, angle_deg: f64, velocity_m_s: f64, diameter_m: f64) -> f64 {
        self.e90_ref
            * self.g(angle_deg)
            * (velocity_m_s / self.v_ref_m_s).powf(self.k2)
            * (diameter_m / self.d_ref_m).powf(self.k3)
    }

    /// E(α, v, d) for a grain of aspect ratio e and angularity An: the reference grain's times
    /// h(e, An, α) (seed eq. 38); h = 1 when the model has no shape exponents.
    pub fn erosion_shaped(
        &self,
        angle_deg: f64,
        velocity_m_s: f64,
        diameter_m: f64,
        aspect_ratio: f64,
        angularity: f64,
    ) -> f64 {
        let h = self.shape_exponents.map_or(1.0, |n| {
            shape_modification(angle_deg, aspect_ratio, angularity, &self.reference, &n)
        });
        self.erosion(angle_deg, velocity_m_s, diameter_m) * h
    }

    /// The value of one parameter (n3..n6 are 0 without shape exponents).
    pub fn value(&self, p: Param) -> f64 {
        let s = self.shape_exponents.unwrap_or(ShapeExponents {
            n3: 0.0,
            n4: 0.0,
            n5: 0.0,
            n6: 0.0,
        });
        match p {
            Param::E90Ref => self.e90_ref,
            Param::N1 => self.n1,
            Param::N2 => self.n2,
            Param::K2 => self.k2,
            Param::K3 => self.k3,
            Param::N3 => s.n3,
            Param::N4 => s.n4,
            Param::N5 => s.n5,
            Param::N6 => s.n6,
        }
    }
}

/// One steady cell as the fit sees it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitCell {
    /// The results file it came from.
    pub source: String,
    /// The cell's name (angle, shape, swept values).
    pub label: String,
    /// Impact angle, degrees from the surface.
    pub angle_deg: f64,
    /// Impact speed, m/s.
    pub velocity_m_s: f64,
    /// Grain diameter, m.
    pub diameter_m: f64,
    /// Grain shape name.
    pub shape: String,
    /// Grain aspect ratio e (seed Table 2).
    pub aspect_ratio: f64,
    /// Grain angularity An (seed Table 2).
    pub angularity: f64,
    /// Cell erosion (mass lost / grain mass).
    pub erosion: f64,
    /// Its standard error over samples.
    pub erosion_sem: f64,
}

/// What the fit holds fixed and the references it measures against.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// Target Vickers hardness, GPa.
    pub hv_gpa: f64,
    /// Reference speed, m/s.
    pub v_ref_m_s: f64,
    /// Reference grain diameter, m.
    pub d_ref_m: f64,
    /// Reference grain of the shape modification.
    pub reference: ShapeReference,
    /// Parameters held at a value instead of fitted.
    pub fixed: BTreeMap<Param, f64>,
}

/// A fitted or fixed parameter beside its published value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamEstimate {
    /// Which parameter.
    pub name: Param,
    /// Its value.
    pub value: f64,
    /// Standard error, from the covariance s² (JᵀWJ)⁻¹; `null` when fixed.
    pub std_error: Option<f64>,
    /// Whether it was held fixed rather than fitted.
    pub fixed: bool,
    /// Oka's silica value at the fit's Hv, or the seed's n3..n6; `null` for E90.
    pub published: Option<f64>,
}

/// One cell against the fitted model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CellResidual {
    /// The cell as fitted.
    #[serde(flatten)]
    pub cell: FitCell,
    /// The model's erosion there.
    pub model: f64,
    /// erosion − model.
    pub residual: f64,
    /// (erosion − model) / s.e.
    pub pull: f64,
}

/// Covariance of the fitted parameters, in their own units (E90 not its logarithm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Covariance {
    /// The fitted parameters, in the order of the matrix's rows.
    pub params: Vec<Param>,
    /// The matrix, scaled like the standard errors.
    pub matrix: Vec<Vec<f64>>,
}

/// The full Oka model fitted to cells, with its goodness of fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FullOkaFit {
    /// The model with the fitted (and fixed) parameters.
    pub model: FullOkaModel,
    /// Every parameter of the model with its standard error and published value.
    pub parameters: Vec<ParamEstimate>,
    /// Covariance of the fitted parameters.
    pub covariance: Covariance,
    /// χ² = Σ ((erosion − model)/s.e.)².
    pub chi2: f64,
    /// Degrees of freedom: cells − fitted parameters.
    pub dof: usize,
    /// χ²/dof; `null` when dof is 0.
    pub chi2_per_dof: Option<f64>,
    /// Factor the standard errors carry: √(χ²/dof) when above 1, else 1 (the Particle Data
    /// Group's scale factor: a fit worse than the error bars widens its errors, a better one
    /// does not narrow them).
    pub error_scale: f64,
    /// Every cell with its model value and residual, in input order.
    pub cells: Vec<CellResidual>,
    /// Levenberg–Marquardt iterations taken.
    pub iterations: usize,
}

impl FullOkaFit {
    /// The estimate of one parameter, if the model has it.
    pub fn parameter(&self, p: Param) -> Option<&ParamEstimate> {
        self.parameters.iter().find(|e| e.name == p)
    }
}

fn invalid(field: impl Into<String>, rule: impl Into<String>) -> FitError {
    FitError::Invalid {
        field: field.into(),
        rule: rule.into(),
    }
}

fn positive(field: &str, v: f64) -> Result<(), FitError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, format!("must be finite and > 0, got {v}")))
    }
}

/// Cells of a results file ready to fit: speed and size from the cell's swept values or the
/// spec, shape factors from the built-in shapes (seed Table 2). A cell not at steady state
/// (seed section 4) is an error, or with `drop_unsteady` left out with a note.
pub fn cells_from_results(
    source: &str,
    r: &CampaignResults,
    drop_unsteady: bool,
) -> Result<(Vec<FitCell>, Vec<String>), FitError> {
    let spec = r.spec.as_ref();
    let mut cells = Vec::new();
    let mut notes = Vec::new();
    for c in &r.cells {
        let field = format!("{source}: cell {}", c.label());
        let steady = c.steady_state.as_ref();
        if !steady.is_some_and(|s| s.steady) {
            let why = steady.map_or("it carries no steady-state check (an older file)", |s| {
                s.reason.as_str()
            });
            if drop_unsteady {
                notes.push(format!("{field} left out: not at steady state ({why})"));
                continue;
            }
            return Err(invalid(
                field,
                format!("is not at steady state ({why}); its slope is not an erosion rate"),
            ));
        }
        if let Some(other) = c
            .swept
            .keys()
            .find(|k| !matches!(k.as_str(), "velocity_m_s" | "grain_diameter_m"))
        {
            return Err(invalid(
                field,
                format!("sweeps {other}, which the Oka model has no term for"),
            ));
        }
        let velocity_m_s = c
            .swept
            .get("velocity_m_s")
            .copied()
            .or_else(|| spec_number(spec, &["velocity_m_s"]))
            .ok_or_else(|| invalid(&field, "has no speed: the file carries no spec"))?;
        let diameter_m = c
            .swept
            .get("grain_diameter_m")
            .copied()
            .or_else(|| spec_number(spec, &["grain", "diameter_m"]))
            .ok_or_else(|| invalid(&field, "has no grain size: the file carries no spec"))?;
        let shape = Shape::from_name(&c.shape).ok_or_else(|| {
            invalid(
                &field,
                format!(
                    "shape {:?} is not a built-in shape, so its e and An are unknown",
                    c.shape
                ),
            )
        })?;
        let (angularity, aspect_ratio) = shape
            .factors()
            .map_err(|e| invalid(&field, e.to_string()))?;
        let erosion = c
            .erosion_mean
            .ok_or_else(|| invalid(&field, "has no erosion (no sample has a slope)"))?;
        let erosion_sem = c.erosion_sem.ok_or_else(|| {
            invalid(
                &field,
                "has no standard error (fewer than 2 samples); the fit weights cells by it",
            )
        })?;
        cells.push(FitCell {
            source: source.to_string(),
            label: c.label(),
            angle_deg: c.angle_deg,
            velocity_m_s,
            diameter_m,
            shape: c.shape.clone(),
            aspect_ratio,
            angularity,
            erosion,
            erosion_sem,
        });
    }
    Ok((cells, notes))
}

fn distinct(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

fn is_reference(c: &FitCell, r: &ShapeReference) -> bool {
    (c.aspect_ratio / r.aspect_ratio - 1.0).abs() < 1e-9
        && (c.angularity / r.angularity - 1.0).abs() < 1e-9
}

/// Row of the log-linear design: ln E = Σ θ_k x_k with θ = (ln E90, n1, n2, k2, k3, n3..n6).
fn design_row(c: &FitCell, o: &FitOptions) -> [f64; 9] {
    let s = c.angle_deg.to_radians().sin();
    let le = (c.aspect_ratio / o.reference.aspect_ratio).ln();
    let la = (c.angularity / o.reference.angularity).ln();
    let above = (c.angle_deg - 45.0).max(0.0);
    [
        1.0,
        s.ln(),
        (1.0 + o.hv_gpa * (1.0 - s)).ln(),
        (c.velocity_m_s / o.v_ref_m_s).ln(),
        (c.diameter_m / o.d_ref_m).ln(),
        le,
        la,
        above * le,
        above * la,
    ]
}

fn check_inputs(cells: &[FitCell], o: &FitOptions) -> Result<(), FitError> {
    positive("hv_gpa", o.hv_gpa)?;
    positive("v_ref_m_s", o.v_ref_m_s)?;
    positive("d_ref_m", o.d_ref_m)?;
    positive("reference.aspect_ratio", o.reference.aspect_ratio)?;
    positive("reference.angularity", o.reference.angularity)?;
    for (p, v) in &o.fixed {
        if !v.is_finite() {
            return Err(invalid(format!("fixed.{}", p.name()), "must be finite"));
        }
        if *p == Param::E90Ref {
            positive("fixed.e90_ref", *v)?;
        }
    }
    for (i, c) in cells.iter().enumerate() {
        let f = |name: &str| format!("cells[{i}].{name} ({})", c.label);
        if !(c.angle_deg.is_finite() && c.angle_deg > 0.0 && c.angle_deg <= 90.0) {
            return Err(invalid(
                f("angle_deg"),
                format!("must be in (0, 90], got {}", c.angle_deg),
            ));
        }
        positive(&f("velocity_m_s"), c.velocity_m_s)?;
        positive(&f("diameter_m"), c.diameter_m)?;
        positive(&f("aspect_ratio"), c.aspect_ratio)?;
        positive(&f("angularity"), c.angularity)?;
        positive(&f("erosion_sem"), c.erosion_sem)?;
        if !c.erosion.is_finite() {
            return Err(invalid(
                f("erosion"),
                format!("must be finite, got {}", c.erosion),
            ));
        }
    }
    Ok(())
}

/// Which parameters enter the model and which of them are fitted; the data's limits as
/// errors that say what to fix.
fn free_params(cells: &[FitCell], o: &FitOptions) -> Result<(bool, Vec<Param>), FitError> {
    let shaped = cells.iter().any(|c| !is_reference(c, &o.reference));
    if !shaped {
        if let Some(p) = o.fixed.keys().find(|p| p.is_shape()) {
            return Err(invalid(
                format!("fixed.{}", p.name()),
                "every cell is the reference grain, so n3..n6 do not enter the model",
            ));
        }
    }
    let free: Vec<Param> = Param::ALL
        .into_iter()
        .filter(|p| (shaped || !p.is_shape()) && !o.fixed.contains_key(p))
        .collect();
    let hint = |p: Param| {
        format!(
            "fix it at a value (Oka's for silica at Hv {}: {:.4})",
            o.hv_gpa,
            p.published(o.hv_gpa).unwrap_or(f64::NAN)
        )
    };
    let speeds = distinct(cells.iter().map(|c| c.velocity_m_s));
    if free.contains(&Param::K2) && speeds.len() < 2 {
        return Err(FitError::Underdetermined(format!(
            "k2: every cell has the same speed ({} m/s), so the speed exponent cannot be fitted; {}",
            speeds.first().copied().unwrap_or(f64::NAN),
            hint(Param::K2)
        )));
    }
    let sizes = distinct(cells.iter().map(|c| c.diameter_m));
    if free.contains(&Param::K3) && sizes.len() < 2 {
        return Err(FitError::Underdetermined(format!(
            "k3: every cell has the same grain size ({} m), so the size exponent cannot be fitted; {}",
            sizes.first().copied().unwrap_or(f64::NAN),
            hint(Param::K3)
        )));
    }
    let angles = distinct(cells.iter().map(|c| c.angle_deg)).len();
    let n_free = [Param::N1, Param::N2]
        .iter()
        .filter(|p| free.contains(p))
        .count();
    if n_free > 0 && angles < n_free + 1 {
        return Err(FitError::Underdetermined(format!(
            "n1, n2: the cells have {angles} distinct angle(s); fitting {n_free} of n1 and n2 \
             beside E90 needs {}; fix n1 and n2 at values (Oka's for silica at Hv {}: {:.4}, {:.4})",
            n_free + 1,
            o.hv_gpa,
            Param::N1.published(o.hv_gpa).unwrap_or(f64::NAN),
            Param::N2.published(o.hv_gpa).unwrap_or(f64::NAN),
        )));
    }
    if cells.len() < free.len() {
        return Err(FitError::TooFewPoints {
            needed: free.len(),
            what: "steady cells (one per fitted parameter)",
            got: cells.len(),
        });
    }
    Ok((shaped, free))
}

/// θ in the order of [`Param::ALL`] with ln E90 first, from a model.
fn theta_of(m: &FullOkaModel) -> [f64; 9] {
    let mut t = [0.0; 9];
    for (k, p) in Param::ALL.into_iter().enumerate() {
        t[k] = m.value(p);
    }
    t[0] = m.e90_ref.ln();
    t
}

struct Problem<'a> {
    rows: Vec<[f64; 9]>,
    cells: &'a [FitCell],
    free: Vec<usize>,
}

impl Problem<'_> {
    /// Weighted residuals (model − erosion)/s.e. and their Jacobian in the free parameters.
    fn residuals(&self, theta: &[f64; 9]) -> (DVector<f64>, DMatrix<f64>) {
        let (m, p) = (self.cells.len(), self.free.len());
        let mut r = DVector::zeros(m);
        let mut j = DMatrix::zeros(m, p);
        for (i, (row, c)) in self.rows.iter().zip(self.cells).enumerate() {
            let e = row.iter().zip(theta).map(|(x, t)| x * t).sum::<f64>().exp();
            r[i] = (e - c.erosion) / c.erosion_sem;
            for (col, &k) in self.free.iter().enumerate() {
                j[(i, col)] = e * row[k] / c.erosion_sem;
            }
        }
        (r, j)
    }

    /// Start: weighted least squares of ln E (delta-method weights (E/s.e.)²) over the cells
    /// with E > 0, when they are enough; else the published values.
    fn start(&self, mut theta: [f64; 9]) -> [f64; 9] {
        let positive: Vec<usize> = (0..self.cells.len())
            .filter(|&i| self.cells[i].erosion > 0.0)
            .collect();
        let p = self.free.len();
        if positive.len() >= p {
            let mut a = DMatrix::zeros(positive.len(), p);
            let mut b = DVector::zeros(positive.len());
            for (r, &i) in positive.iter().enumerate() {
                let c = &self.cells[i];
                let w = c.erosion / c.erosion_sem;
                let fixed: f64 = (0..9)
                    .filter(|k| !self.free.contains(k))
                    .map(|k| self.rows[i][k] * theta[k])
                    .sum();
                for (col, &k) in self.free.iter().enumerate() {
                    a[(r, col)] = w * self.rows[i][k];
                }
                b[r] = w * (c.erosion.ln() - fixed);
            }
            if let Ok(x) = a.svd(true, true).solve(&b, 1e-12) {
                if x.iter().all(|v| v.is_finite()) {
                    for (col, &k) in self.free.iter().enumerate() {
                        theta[k] = x[col];
                    }
                    return theta;
                }
            }
        }
        let mean = self.cells.iter().map(|c| c.erosion.abs()).sum::<f64>() / p.max(1) as f64;
        if self.free.contains(&0) {
            theta[0] = mean.max(1e-12).ln();
        }
        theta
    }
}

const LM_MAX_ITER: usize = 500;

/// Levenberg–Marquardt with Marquardt's diagonal scaling over the free parameters; nalgebra
/// solves each damped normal system.
fn levenberg_marquardt(pb: &Problem, mut theta: [f64; 9]) -> Result<([f64; 9], usize), FitError> {
    let (mut r, mut j) = pb.residuals(&theta);
    let mut rss = r.norm_squared();
    let mut lambda = 1e-3;
    for iter in 1..=LM_MAX_ITER {
        let jtj = j.transpose() * &j;
        let jtr = j.transpose() * &r;
        let dmax = jtj.diagonal().max();
        let accepted = loop {
            let mut a = jtj.clone();
            for k in 0..a.nrows() {
                a[(k, k)] += lambda * jtj[(k, k)].max(1e-12 * dmax);
            }
            if let Some(step) = a.cholesky().map(|c| c.solve(&(-&jtr))) {
                if step.iter().all(|v| v.is_finite()) {
                    let mut trial = theta;
                    for (col, &k) in pb.free.iter().enumerate() {
                        trial[k] += step[col];
                    }
                    let (tr, tj) = pb.residuals(&trial);
                    let trss = tr.norm_squared();
                    if trss.is_finite() && trss < rss {
                        let small_step =
                            pb.free.iter().enumerate().all(|(col, &k)| {
                                step[col].abs() <= 1e-10 * (theta[k].abs() + 1e-8)
                            });
                        let small_gain = rss - trss <= 1e-14 * rss;
                        (theta, r, j, rss) = (trial, tr, tj, trss);
                        lambda = (lambda / 10.0).max(1e-15);
                        break Some(small_step || small_gain);
                    }
                }
            }
            lambda *= 10.0;
            if lambda > 1e16 {
                break None;
            }
        };
        // No damped step lowers χ² (None), or the last one changed nothing: a minimum.
        if accepted != Some(false) || rss == 0.0 {
            return Ok((theta, iter));
        }
    }
    Err(FitError::NotConverged {
        iterations: LM_MAX_ITER,
        rss,
    })
}

/// Fits the full Oka model (Oka & Yoshida 2005 eq. 4; seed eqs. 35, 38) to `cells` by weighted
/// least squares in erosion, weights 1/s.e.²; parameters in `options.fixed` are held.
pub fn fit_full_oka(cells: &[FitCell], options: &FitOptions) -> Result<FullOkaFit, FitError> {
    check_inputs(cells, options)?;
    let (shaped, free) = free_params(cells, options)?;
    let o = options;
    let published = |p: Param| p.published(o.hv_gpa);
    let mut start_model = FullOkaModel {
        e90_ref: 1.0,
        n1: published(Param::N1).unwrap_or(0.0),
        n2: published(Param::N2).unwrap_or(0.0),
        k2: published(Param::K2).unwrap_or(0.0),
        k3: published(Param::K3).unwrap_or(0.0),
        hv_gpa: o.hv_gpa,
        v_ref_m_s: o.v_ref_m_s,
        d_ref_m: o.d_ref_m,
        reference: o.reference,
        shape_exponents: shaped.then_some(ShapeExponents::SEED),
    };
    let mut theta0 = theta_of(&start_model);
    for (p, v) in &o.fixed {
        let k = Param::ALL.iter().position(|q| q == p).unwrap_or(0);
        theta0[k] = if *p == Param::E90Ref { v.ln() } else { *v };
    }
    let pb = Problem {
        rows: cells.iter().map(|c| design_row(c, o)).collect(),
        cells,
        free: free
            .iter()
            .map(|p| Param::ALL.iter().position(|q| q == p).unwrap_or(0))
            .collect(),
    };
    // The Jacobian's rank at the start is the design's (J = diag(E/s.e.) X): a parameter the
    // cells cannot separate from the others shows here, before any iteration.
    let (_, j0) = pb.residuals(&theta0);
    let svd = j0.clone().svd(false, false);
    let smax = svd.singular_values.max();
    let rank = svd.rank(1e-10 * smax);
    if smax == 0.0 || rank < free.len() {
        let names: Vec<&str> = free.iter().map(|p| p.name()).collect();
        return Err(FitError::Underdetermined(format!(
            "the cells determine only {rank} of the {} fitted parameters ({}); fix some, or add \
             cells that vary what they describe",
            free.len(),
            names.join(", ")
        )));
    }
    let (theta, iterations) = levenberg_marquardt(&pb, pb.start(theta0))?;
    let get = |p: Param| theta[Param::ALL.iter().position(|q| *q == p).unwrap_or(0)];
    start_model = FullOkaModel {
        e90_ref: theta[0].exp(),
        n1: get(Param::N1),
        n2: get(Param::N2),
        k2: get(Param::K2),
        k3: get(Param::K3),
        shape_exponents: shaped.then(|| ShapeExponents {
            n3: get(Param::N3),
            n4: get(Param::N4),
            n5: get(Param::N5),
            n6: get(Param::N6),
        }),
        ..start_model
    };
    let model = start_model;
    let (r, j) = pb.residuals(&theta);
    let chi2 = r.norm_squared();
    let dof = cells.len() - free.len();
    let chi2_per_dof = (dof > 0).then(|| chi2 / dof as f64);
    let error_scale = chi2_per_dof.map_or(1.0, |c| c.max(1.0).sqrt());
    let cov_theta = (j.transpose() * &j).try_inverse().ok_or_else(|| {
        FitError::Underdetermined("JᵀWJ is singular at the minimum; fix some parameters".into())
    })?;
    // Covariance in the parameters' own units: E90 = exp(θ0), so its row scales by E90.
    let unit = |k: usize| {
        if free[k] == Param::E90Ref {
            model.e90_ref
        } else {
            1.0
        }
    };
    let n = free.len();
    let matrix: Vec<Vec<f64>> = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| error_scale * error_scale * unit(a) * unit(b) * cov_theta[(a, b)])
                .collect()
        })
        .collect();
    let parameters = Param::ALL
        .into_iter()
        .filter(|p| shaped || !p.is_shape())
        .map(|p| {
            let at = free.iter().position(|q| *q == p);
            ParamEstimate {
                name: p,
                value: model.value(p),
                std_error: at.map(|k| matrix[k][k].sqrt()),
                fixed: at.is_none(),
                published: published(p),
            }
        })
        .collect();
    let cells = cells
        .iter()
        .map(|c| {
            let e = model.erosion_shaped(
                c.angle_deg,
                c.velocity_m_s,
                c.diameter_m,
                c.aspect_ratio,
                c.angularity,
            );
            CellResidual {
                cell: c.clone(),
                model: e,
                residual: c.erosion - e,
                pull: (c.erosion - e) / c.erosion_sem,
            }
        })
        .collect();
    Ok(FullOkaFit {
        model,
        parameters,
        covariance: Covariance {
            params: free,
            matrix,
        },
        chi2,
        dof,
        chi2_per_dof,
        error_scale,
        cells,
        iterations,
    })
}

#[cfg(test)]
#[path = "fit_tests.rs"]
mod tests;
