//! A fitted full Oka model (Oka & Yoshida 2005 eq. 4; [`super::fit`]) written in the forms CFD
//! and DEM codes read: ANSYS Fluent's generic and Oka wall erosion models (PyFluent settings
//! names), an OpenFOAM cloud function object, Altair EDEM's Oka wear model, and grit's own JSON.
//!
//! Every format carries the same model for the reference grain; only its notation differs, and
//! each states the units of its level and the 2D warning of [`LEVEL_WARNING`].

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use crate::models::fit::{FullOkaFit, FullOkaModel};
use crate::models::oka::FitError;

/// What grit's erosion is, in words (design.md, *erosion*).
pub const EROSION_UNITS: &str = "kg of target lost per kg of grains that hit; grit's impacts are \
2D plane strain, so both masses are per metre of depth and the ratio is taken as it stands";

/// The caveat every exported level carries until the 2D-to-3D factor is measured.
pub const LEVEL_WARNING: &str = "the level (E90, C) is grit's 2D plane-strain ratio of mass lost \
per unit depth to grain mass per unit depth, exported as a 3D kg/kg ratio with a factor of 1; \
the 2D-to-3D factor is not measured yet, so the level may be off by it (the angle, speed and \
size dependences are not affected). The numerics were grit's quick preset unless the \
provenance says otherwise.";

/// One results file behind a fit: what ran, with which grit, on which cells.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitSource {
    /// The results file as named on the command line.
    pub file: String,
    /// grit version that aggregated it; `null` in older files.
    pub grit_version: Option<String>,
    /// The campaign spec as run.
    pub spec: Option<serde_json::Value>,
    /// The numerics its impacts ran with.
    pub numerics: Option<serde_json::Value>,
    /// Particle spacing Δx (m), when the spec gives one value.
    pub spacing_m: Option<f64>,
    /// Labels of the cells that entered the fit.
    pub cells_used: Vec<String>,
}

/// A point where `grit fit --eval` evaluated the model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Impact angle, degrees from the surface.
    pub angle_deg: f64,
    /// Impact speed, m/s.
    pub velocity_m_s: f64,
    /// Grain diameter, m.
    pub diameter_m: f64,
    /// Erosion of the reference grain there, kg/kg.
    pub erosion: f64,
}

/// What `grit fit --json` writes and `grit export` reads: the fit, its units and provenance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitDocument {
    /// Always `grit-oka-fit`.
    pub kind: String,
    /// grit version that made the fit.
    pub grit_version: String,
    /// What the erosion values mean ([`EROSION_UNITS`]).
    pub erosion_units: String,
    /// The level's caveat ([`LEVEL_WARNING`]).
    pub level_warning: String,
    /// Density of the target (kg/m³), for codes that count volume (EDEM).
    pub wall_density_kg_m3: Option<f64>,
    /// The fit.
    pub fit: FullOkaFit,
    /// The results files and cells behind it.
    pub sources: Vec<FitSource>,
    /// Cells left out and other remarks.
    #[serde(default)]
    pub notes: Vec<String>,
    /// Points evaluated with `--eval`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub evaluations: Vec<Evaluation>,
}

/// The document's kind tag.
pub const FIT_KIND: &str = "grit-oka-fit";

/// An output format of `grit export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Fluent's generic model: C(d) f(α) v^b, as a PyFluent script.
    FluentGeneric,
    /// Fluent's Oka model, as a PyFluent script.
    FluentOka,
    /// An OpenFOAM cloud function object and its cloudProperties entry.
    OpenFoam,
    /// EDEM's Oka wear model parameters.
    Edem,
    /// The fit document itself.
    Json,
}

impl Format {
    /// Every format with its command-line name.
    pub const ALL: [(Format, &'static str); 5] = [
        (Format::FluentGeneric, "fluent-generic"),
        (Format::FluentOka, "fluent-oka"),
        (Format::OpenFoam, "openfoam"),
        (Format::Edem, "edem"),
        (Format::Json, "json"),
    ];
}

impl std::str::FromStr for Format {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Format::ALL
            .iter()
            .find(|(_, n)| *n == s)
            .map(|(f, _)| *f)
            .ok_or_else(|| {
                let names: Vec<&str> = Format::ALL.iter().map(|(_, n)| *n).collect();
                format!("unknown format `{s}`; one of {}", names.join(", "))
            })
    }
}

/// One file of an export, its path relative to the output.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportFile {
    /// Relative path (a single-file format has one, named after the format).
    pub path: String,
    /// Its text.
    pub text: String,
}

/// Angles of the piecewise-linear f(α) table, degrees: every degree.
fn angle_nodes() -> Vec<f64> {
    (0..=90).map(f64::from).collect()
}

/// Diameters of the C(d) table, m: 33 geometric steps from half the smallest fitted grain to
/// twice the largest.
fn diameter_nodes(fit: &FullOkaFit) -> Vec<f64> {
    let (lo, hi) = fit.cells.iter().fold((f64::MAX, 0.0f64), |(a, b), c| {
        (a.min(c.cell.diameter_m), b.max(c.cell.diameter_m))
    });
    let (lo, hi) = (0.5 * lo, 2.0 * hi);
    (0..33)
        .map(|k| lo * (hi / lo).powf(k as f64 / 32.0))
        .collect()
}

/// Largest |table − exact| between nodes, sampled at 16 points per interval, relative to `scale`.
fn interpolation_error(nodes: &[f64], f: impl Fn(f64) -> f64, scale: impl Fn(f64) -> f64) -> f64 {
    let mut worst = 0.0f64;
    for w in nodes.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (fa, fb) = (f(a), f(b));
        for k in 1..16 {
            let t = k as f64 / 16.0;
            let x = a + t * (b - a);
            let err = (fa + t * (fb - fa) - f(x)).abs() / scale(x);
            worst = worst.max(err);
        }
    }
    worst
}

fn header(out: &mut String, doc: &FitDocument, comment: &str, what: &str) {
    let m = &doc.fit.model;
    let _ = writeln!(
        out,
        "{comment} {what}, written by grit {} (`grit export`) from a fit by grit {}.",
        env!("CARGO_PKG_VERSION"),
        doc.grit_version
    );
    let _ = writeln!(
        out,
        "{comment} Model: E = E90 g(a) (v/vref)^k2 (d/dref)^k3, g(a) = sin(a)^n1 (1 + Hv (1 - sin a))^n2"
    );
    let _ = writeln!(
        out,
        "{comment} (Oka & Yoshida 2005, Wear 259, eq. 4), a in degrees from the wall, v in m/s, d in m."
    );
    if m.shape_exponents.is_some() {
        let _ = writeln!(
            out,
            "{comment} For the reference grain only (e = {}, An = {}); n3..n6 are in the JSON export.",
            m.reference.aspect_ratio, m.reference.angularity
        );
    }
    let _ = writeln!(out, "{comment} Units of E: {EROSION_UNITS}.");
    let _ = writeln!(out, "{comment} WARNING: {LEVEL_WARNING}");
    let files: Vec<&str> = doc.sources.iter().map(|s| s.file.as_str()).collect();
    let _ = writeln!(
        out,
        "{comment} Fitted to {} steady cells of {}; chi2/dof = {}.",
        doc.fit.cells.len(),
        files.join(", "),
        doc.fit
            .chi2_per_dof
            .map_or("n/a (no degrees of freedom)".into(), |c| format!("{c:.3}"))
    );
    for p in &doc.fit.parameters {
        let se = match (p.fixed, p.std_error) {
            (true, _) => "fixed, not fitted".to_string(),
            (false, Some(s)) => format!("+- {s:.3e}"),
            (false, None) => String::new(),
        };
        let _ = writeln!(out, "{comment}   {} = {:e} ({se})", p.name.name(), p.value);
    }
}

fn python_list(values: &[f64]) -> String {
    let parts: Vec<String> = values.iter().map(|v| format!("{v:e}")).collect();
    format!("[{}]", parts.join(", "))
}

/// Fluent's generic model (PyFluent names `impact_angle_function`, `diameter_function`,
/// `velocity_exponent_function`): f(α) = g(α)/g_max, b = k2, C(d) = E90 g_max (d/dref)^k3
/// vref^−k2, so that C(d) f(α) v^b is the fitted E.
fn fluent_generic(doc: &FitDocument, wall: &str) -> String {
    let m = &doc.fit.model;
    let gmax = m.g(crate::models::oka::OkaModel {
        n1: m.n1,
        n2: m.n2,
        e90: 1.0,
        hv_gpa: m.hv_gpa,
    }
    .max_angle_deg());
    let angles = angle_nodes();
    let f: Vec<f64> = angles.iter().map(|&a| m.g(a) / gmax).collect();
    let diameters = diameter_nodes(&doc.fit);
    let c_of = |d: f64| c_generic(m, gmax, d);
    let c: Vec<f64> = diameters.iter().map(|&d| c_of(d)).collect();
    let f_err = interpolation_error(&angles, |a| m.g(a) / gmax, |_| 1.0);
    let c_err = interpolation_error(&diameters, c_of, c_of);
    let mut out = String::new();
    header(&mut out, doc, "#", "ANSYS Fluent generic erosion model");
    let _ = writeln!(
        out,
        "# Fluent: erosion rate = sum over impacts of mdot_p C(d_p) f(a) v^b / A_face, kg/(m^2 s)."
    );
    let _ = writeln!(
        out,
        "# f(a): g(a)/g_max, g_max = {gmax:e}, piecewise-linear in degrees (largest error between nodes {f_err:.1e} of max f)."
    );
    let _ = writeln!(
        out,
        "# C(d): E90 g_max (d/dref)^k3 / vref^k2, kg of wall per kg of particles per (m/s)^b, piecewise-linear in d (m),"
    );
    let _ = writeln!(
        out,
        "# from {:.3e} to {:.3e} m (largest relative error between nodes {c_err:.1e}); b = k2.",
        diameters[0],
        diameters[diameters.len() - 1]
    );
    let _ = writeln!(
        out,
        "# Run in PyFluent: exec(open(this_file).read()); apply(solver). Names: PyFluent settings API (Fluent 2025 R1)."
    );
    let _ = writeln!(out, "WALL = {wall:?}");
    let _ = writeln!(out, "B = {:e}", m.k2);
    let _ = writeln!(out, "ANGLE_DEG = {}", python_list(&angles));
    let _ = writeln!(out, "F = {}", python_list(&f));
    let _ = writeln!(out, "DIAMETER_M = {}", python_list(&diameters));
    let _ = writeln!(out, "C = {}", python_list(&c));
    out.push_str(
        r#"

def apply(solver, wall=WALL):
    """Sets the generic erosion model of `wall` to the tables above."""
    generic = solver.settings.setup.boundary_conditions.wall[wall].dpm.erosion.generic
    generic.enabled = True
    f = generic.impact_angle_function
    f.option = "piecewise-linear"
    f.piecewise_linear.data_points = [[a, v] for a, v in zip(ANGLE_DEG, F)]
    c = generic.diameter_function
    c.option = "piecewise-linear"
    c.piecewise_linear.data_points = [[d, v] for d, v in zip(DIAMETER_M, C)]
    b = generic.velocity_exponent_function
    b.option = "constant"
    b.value = B
"#,
    );
    out
}

/// C(d) of Fluent's generic model for the fitted E: E90 g_max (d/dref)^k3 vref^−k2.
fn c_generic(m: &FullOkaModel, gmax: f64, d: f64) -> f64 {
    m.e90_ref * gmax * (d / m.d_ref_m).powf(m.k3) / m.v_ref_m_s.powf(m.k2)
}

/// Fluent's Oka model under its PyFluent names; E90 in kg/kg, Hv in GPa, dref in m, vref in m/s.
fn fluent_oka(doc: &FitDocument, wall: &str) -> String {
    let m = &doc.fit.model;
    let mut out = String::new();
    header(&mut out, doc, "#", "ANSYS Fluent Oka erosion model");
    let _ = writeln!(
        out,
        "# Fluent: E = E90 (v/vref)^k2 (d/dref)^k3 g(a); reference_erosion_rate_e90 in kg of wall per kg of particles."
    );
    let _ = writeln!(
        out,
        "# Run in PyFluent: exec(open(this_file).read()); apply(solver). Names: PyFluent settings API (Fluent 2025 R1)."
    );
    let _ = writeln!(out, "WALL = {wall:?}");
    let _ = writeln!(out, "OKA = {{");
    for (name, v) in [
        ("reference_erosion_rate_e90", m.e90_ref),
        ("wall_vickers_hardness_hv", m.hv_gpa),
        ("model_constant_n1", m.n1),
        ("model_constant_n2", m.n2),
        ("velocity_exponent_k2", m.k2),
        ("diameter_exponent_k3", m.k3),
        ("reference_diameter_dref", m.d_ref_m),
        ("reference_velocity_vref", m.v_ref_m_s),
    ] {
        let _ = writeln!(out, "    \"{name}\": {v:e},");
    }
    let _ = writeln!(out, "}}");
    out.push_str(
        r#"

def apply(solver, wall=WALL):
    """Sets the Oka erosion model of `wall` to the values above."""
    oka = solver.settings.setup.boundary_conditions.wall[wall].dpm.erosion.oka
    oka.enabled = True
    for name, value in OKA.items():
        setattr(oka, name, value)
"#,
    );
    out
}

/// EDEM's Oka wear model counts volume: E90 as mm³ per kg of particles, D' in mm.
fn edem(doc: &FitDocument) -> Result<String, FitError> {
    let m = &doc.fit.model;
    let rho = doc.wall_density_kg_m3.ok_or_else(|| FitError::Invalid {
        field: "wall_density_kg_m3".into(),
        rule: "EDEM's Oka model counts wear volume, so the fit needs the target's density".into(),
    })?;
    let mut out = String::new();
    header(&mut out, doc, "#", "Altair EDEM Oka wear model");
    let _ = writeln!(
        out,
        "# EDEM: wear volume = g(a) E(v, D) m_p, E = E90 (v/v')^k2 (D/D')^k3 in mm^3 per kg of particles, D in mm."
    );
    let _ = writeln!(
        out,
        "# EDEM's built-in Oka model takes only Hv and a wear constant and fixes n1, n2, k2, k3 at Oka's silica"
    );
    let _ = writeln!(
        out,
        "# values; the fitted exponents need a custom (API) wear model that reads the [oka] table below."
    );
    let _ = writeln!(
        out,
        "# e90_mm3_per_kg = E90 (kg/kg) / wall density (kg/m^3) * 1e9."
    );
    let _ = writeln!(out, "[oka]");
    for (name, v, unit) in [
        ("vickers_hardness_gpa", m.hv_gpa, "GPa"),
        ("n1", m.n1, "-"),
        ("n2", m.n2, "-"),
        ("k2", m.k2, "-"),
        ("k3", m.k3, "-"),
        ("reference_velocity_m_s", m.v_ref_m_s, "m/s (v')"),
        ("reference_diameter_mm", m.d_ref_m * 1e3, "mm (D')"),
        (
            "e90_mm3_per_kg",
            m.e90_ref / rho * 1e9,
            "mm^3 of wall per kg of particles",
        ),
        ("wall_density_kg_m3", rho, "kg/m^3"),
    ] {
        let _ = writeln!(out, "{name} = {v:e}  # {unit}");
    }
    let _ = writeln!(out, "level_warning = {LEVEL_WARNING:?}");
    Ok(out)
}

/// The OpenFOAM cloudProperties entry that configures the function object.
fn openfoam_entry(doc: &FitDocument, patches: &str) -> String {
    let m = &doc.fit.model;
    let mut out = String::new();
    header(
        &mut out,
        doc,
        "//",
        "OpenFOAM cloud function object gritOkaErosion",
    );
    let _ = writeln!(
        out,
        "// Paste into constant/<cloud>Properties; load the library in system/controlDict:"
    );
    let _ = writeln!(out, "//     libs (\"libgritOkaErosion.so\");");
    let _ = writeln!(
        out,
        "// Writes <cloud>:gritErosionMass, kg of wall eroded per boundary face, summed over the run.\n"
    );
    let _ = writeln!(out, "cloudFunctions\n{{\n    gritOkaErosion1\n    {{");
    let _ = writeln!(out, "        type    gritOkaErosion;");
    let _ = writeln!(out, "        patches ({patches});");
    for (name, v, unit) in [
        (
            "E90",
            m.e90_ref,
            "kg of wall per kg of particles at 90 deg, vRef, dRef",
        ),
        ("Hv", m.hv_gpa, "GPa"),
        ("n1", m.n1, ""),
        ("n2", m.n2, ""),
        ("k2", m.k2, ""),
        ("k3", m.k3, ""),
        ("vRef", m.v_ref_m_s, "m/s"),
        ("dRef", m.d_ref_m, "m"),
    ] {
        let _ = writeln!(out, "        {name:<7} {v:e};  // {unit}");
    }
    let _ = writeln!(out, "    }}\n}}");
    out
}

/// The function object's sources: generic, the fitted values live in the entry.
const OPENFOAM_SOURCES: [(&str, &str); 6] = [
    (
        "gritOkaErosion/gritOkaModel.H",
        include_str!("openfoam/gritOkaModel.H"),
    ),
    (
        "gritOkaErosion/GritOkaErosion.H",
        include_str!("openfoam/GritOkaErosion.H"),
    ),
    (
        "gritOkaErosion/GritOkaErosion.C",
        include_str!("openfoam/GritOkaErosion.C"),
    ),
    (
        "gritOkaErosion/makeGritOkaErosion.C",
        include_str!("openfoam/makeGritOkaErosion.C"),
    ),
    (
        "gritOkaErosion/Make/files",
        include_str!("openfoam/Make/files"),
    ),
    (
        "gritOkaErosion/Make/options",
        include_str!("openfoam/Make/options"),
    ),
];

/// The files of `format` for `doc`; `wall` names the Fluent wall zone or the OpenFOAM patches.
pub fn export(doc: &FitDocument, format: Format, wall: &str) -> Result<Vec<ExportFile>, FitError> {
    if doc.kind != FIT_KIND {
        return Err(FitError::Invalid {
            field: "kind".into(),
            rule: format!(
                "must be {FIT_KIND:?} (a file from `grit fit -o`), got {:?}",
                doc.kind
            ),
        });
    }
    for p in &doc.fit.parameters {
        if !p.value.is_finite() {
            return Err(FitError::Invalid {
                field: format!("fit.parameters.{}", p.name.name()),
                rule: "must be finite".into(),
            });
        }
    }
    let e90 = doc.fit.model.e90_ref;
    if !(e90.is_finite() && e90 > 0.0) || doc.fit.cells.is_empty() {
        return Err(FitError::Invalid {
            field: "fit".into(),
            rule: "needs E90 > 0 and the cells it was fitted to".into(),
        });
    }
    let one = |path: &str, text: String| {
        Ok(vec![ExportFile {
            path: path.into(),
            text,
        }])
    };
    match format {
        Format::FluentGeneric => one("fluent-generic.py", fluent_generic(doc, wall)),
        Format::FluentOka => one("fluent-oka.py", fluent_oka(doc, wall)),
        Format::Edem => one("edem-oka.txt", edem(doc)?),
        Format::Json => one(
            "fit.json",
            serde_json::to_string_pretty(doc).map_err(|e| FitError::Invalid {
                field: "fit".into(),
                rule: e.to_string(),
            })? + "\n",
        ),
        Format::OpenFoam => {
            let mut files = vec![ExportFile {
                path: "cloudProperties.gritOkaErosion".into(),
                text: openfoam_entry(doc, wall),
            }];
            files.extend(OPENFOAM_SOURCES.iter().map(|(p, t)| ExportFile {
                path: (*p).into(),
                text: (*t).into(),
            }));
            Ok(files)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_format_lists_the_known_ones() {
        let err = "fluent".parse::<Format>().unwrap_err();
        assert!(err.contains("unknown format `fluent`"), "{err}");
        assert!(err.contains("fluent-generic, fluent-oka, openfoam, edem, json"));
        assert_eq!("edem".parse::<Format>(), Ok(Format::Edem));
    }

    #[test]
    fn interpolation_error_is_zero_for_a_line_and_not_for_a_curve() {
        let nodes = [0.0, 1.0, 2.0];
        assert!(interpolation_error(&nodes, |x| 3.0 * x + 1.0, |_| 1.0) < 1e-15);
        let e = interpolation_error(&nodes, |x| x * x, |_| 1.0);
        assert!((e - 0.25).abs() < 1e-12, "{e}");
    }
}
