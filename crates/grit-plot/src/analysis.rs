//! The numbers behind the angle charts: cells grouped into one series per shape (and other
//! swept values), Oka's model per series (eqs. 34–35) and the shape-modified model
//! (eqs. 37–38), each with the reason when it cannot be had.

use std::collections::BTreeMap;

use grit_erosion::models::oka::{ErosionPoint, OkaFit, ShapedPoint};
use grit_erosion::{
    fit_modified_oka, fit_oka, CampaignResults, ModifiedOkaModel, OkaModel, Shape, ShapeExponents,
    ShapeReference, Stationarity, AISI304_HV_GPA,
};

/// "hexagon" or "hexagon, velocity_m_s 80": the shape and the cell's other swept values.
pub fn series_label(shape: &str, swept: &BTreeMap<String, f64>) -> String {
    let mut s = shape.to_string();
    for (k, v) in swept {
        s.push_str(&format!(", {k} {v}"));
    }
    s
}

/// A simulated erosion of one cell.
#[derive(Debug, Clone, Copy)]
pub struct Point {
    /// Impact angle, degrees.
    pub angle_deg: f64,
    /// Mean erosion over samples.
    pub mean: f64,
    /// Sample standard deviation, when 2 samples or more.
    pub std: Option<f64>,
    /// Whether the cell's erosion is a stationary rate, steady and balanced, and if not, why
    /// (`CellResult::stationarity`).
    pub stationarity: Stationarity,
}

/// Oka's model for one series, or why not.
#[derive(Debug, Clone)]
pub struct OkaCurves {
    /// Least-squares fit of n1, n2, E90 (seed Fig. 11a, 12a).
    pub fit: Result<OkaFit, String>,
    /// Oka's silica exponents scaled by the simulated E90 (the seed's dashed lines).
    pub published: Result<OkaModel, String>,
}

/// The cells with an erosion that share a shape and other swept values, by angle.
#[derive(Debug, Clone)]
pub struct Series {
    /// Shape name.
    pub shape: String,
    /// Legend label.
    pub label: String,
    /// Whether the cells sweep anything but angle and shape.
    pub has_swept: bool,
    /// Points sorted by angle.
    pub points: Vec<Point>,
    /// Oka's model for these points.
    pub oka: OkaCurves,
}

/// The shape-modified Oka model against the simulated shapes (seed Fig. 14).
#[derive(Debug, Clone)]
pub struct Modified {
    /// Indices into `Analysis::series` of the shapes shown.
    pub series: Vec<usize>,
    /// (e, An) of each shown series, in the same order.
    pub factors: Vec<(f64, f64)>,
    /// The model with the seed paper's n3..n6 on the hexagon's Oka fit.
    pub seed: ModifiedOkaModel,
    /// The model with n3..n6 fitted to the points, or why not.
    pub fitted: Result<ModifiedOkaModel, String>,
}

/// Everything the angle charts draw, with notes on what was fitted or skipped.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// One series per shape and swept values, in order of first appearance.
    pub series: Vec<Series>,
    /// The shape-modified model, or why there is none.
    pub modified: Result<Modified, String>,
    /// Fit parameters and skip reasons, in words.
    pub notes: Vec<String>,
    /// How the angle charts draw cells that are no stationary rate, when any are drawn.
    pub hollow_notes: Vec<String>,
}

/// Hardness of the surface the Oka curves use (the seed's AISI 304).
pub const HV_GPA: f64 = AISI304_HV_GPA;

fn oka_curves(points: &[Point]) -> OkaCurves {
    let pts: Vec<ErosionPoint> = points
        .iter()
        .map(|p| ErosionPoint {
            angle_deg: p.angle_deg,
            erosion: p.mean,
            weight: 1.0,
        })
        .collect();
    let fit = fit_oka(&pts, HV_GPA).map_err(|e| e.to_string());
    let published = match points.iter().find(|p| p.angle_deg == 90.0) {
        Some(p) if p.mean > 0.0 => Ok(OkaModel::silica(HV_GPA, p.mean)),
        Some(_) => Err("erosion at 90° is zero, so there is no E90 to scale by".to_string()),
        None => Err("no 90° cell, so there is no simulated E90 to scale by".to_string()),
    };
    OkaCurves { fit, published }
}

impl Analysis {
    /// Groups the cells with an erosion and fits the models.
    pub fn new(results: &CampaignResults) -> Self {
        let mut series: Vec<Series> = Vec::new();
        for c in &results.cells {
            let Some(mean) = c.erosion_mean else { continue };
            let label = series_label(&c.shape, &c.swept);
            let point = Point {
                angle_deg: c.angle_deg,
                mean,
                std: c.erosion_std,
                stationarity: c.stationarity(),
            };
            match series.iter_mut().find(|s| s.label == label) {
                Some(s) => s.points.push(point),
                None => series.push(Series {
                    shape: c.shape.clone(),
                    label,
                    has_swept: !c.swept.is_empty(),
                    points: vec![point],
                    oka: OkaCurves {
                        fit: Err(String::new()),
                        published: Err(String::new()),
                    },
                }),
            }
        }
        let mut notes = vec![format!(
            "Oka curves use Hv = {HV_GPA} GPa (AISI 304); silica exponents n1 = 0.71 Hv^0.14, \
             n2 = 2.4 Hv^-0.94"
        )];
        for s in &mut series {
            s.points.sort_by(|a, b| a.angle_deg.total_cmp(&b.angle_deg));
            s.oka = oka_curves(&s.points);
            let rms = |model: &OkaModel| {
                let ss: f64 = s
                    .points
                    .iter()
                    .map(|p| (p.mean - model.erosion(p.angle_deg)).powi(2))
                    .sum();
                (ss / s.points.len() as f64).sqrt()
            };
            match &s.oka.fit {
                Ok(f) => notes.push(format!(
                    "{}: Oka fit n1 = {:.3}, n2 = {:.3}, E90 = {:.3e}, maximum erosion at {:.1}°, \
                     RMS residual {:.2e}",
                    s.label,
                    f.model.n1,
                    f.model.n2,
                    f.model.e90,
                    f.angle_max_deg,
                    rms(&f.model)
                )),
                Err(e) => notes.push(format!("{}: no Oka fit ({e})", s.label)),
            }
            match &s.oka.published {
                Ok(m) => notes.push(format!(
                    "{}: Oka's silica exponents with the simulated E90 = {:.3e}: maximum erosion \
                     at {:.1}°, RMS residual {:.2e}",
                    s.label,
                    m.e90,
                    m.max_angle_deg(),
                    rms(m)
                )),
                Err(e) => notes.push(format!(
                    "{}: no published-exponent Oka curve ({e})",
                    s.label
                )),
            }
        }
        let modified = modified(&series);
        match &modified {
            Ok(m) => match &m.fitted {
                Ok(f) => {
                    let (n, s) = (f.exponents, ShapeExponents::SEED);
                    notes.push(format!(
                        "modified Oka fit: n3 {:.3}, n4 {:.3}, n5 {:.4}, n6 {:.4} \
                         (seed: {}, {}, {}, {})",
                        n.n3, n.n4, n.n5, n.n6, s.n3, s.n4, s.n5, s.n6
                    ))
                }
                Err(e) => notes.push(format!(
                    "modified Oka: no fit of n3..n6 ({e}); the seed's exponents are drawn"
                )),
            },
            Err(e) => notes.push(format!("no modified-Oka chart: {e}")),
        }
        let hollow_notes = crate::draw::hollow_notes(
            series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.stationarity)),
        );
        Analysis {
            series,
            modified,
            notes,
            hollow_notes,
        }
    }
}

fn modified(series: &[Series]) -> Result<Modified, String> {
    if series.iter().any(|s| s.has_swept) {
        return Err("the cells sweep values other than angle and shape".into());
    }
    let shown: Vec<(usize, (f64, f64))> = series
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            let (an, e) = Shape::from_name(&s.shape)?.factors().ok()?;
            Some((i, (e, an)))
        })
        .collect();
    if shown.len() < 2 {
        return Err("it needs two or more built-in shapes with an erosion".into());
    }
    let hex = series
        .iter()
        .find(|s| s.shape == "hexagon")
        .ok_or("it needs the hexagon, its reference grain")?;
    let oka = hex
        .oka
        .fit
        .as_ref()
        .map_err(|e| format!("it needs the hexagon's Oka fit, which failed: {e}"))?
        .model;
    let points: Vec<ShapedPoint> = shown
        .iter()
        .flat_map(|&(i, (e, an))| {
            // A cell with no loss at all is below what the resolution can show, not an
            // erosion of zero: the log-space fit cannot take it, so it is left out.
            series[i]
                .points
                .iter()
                .filter(|p| p.mean > 0.0)
                .map(move |p| ShapedPoint {
                    angle_deg: p.angle_deg,
                    aspect_ratio: e,
                    angularity: an,
                    erosion: p.mean,
                    weight: 1.0,
                })
        })
        .collect();
    let reference = ShapeReference::HEXAGON;
    let fitted = fit_modified_oka(&points, &oka, &reference)
        .map(|f| f.model)
        .map_err(|e| e.to_string());
    Ok(Modified {
        series: shown.iter().map(|s| s.0).collect(),
        factors: shown.iter().map(|s| s.1).collect(),
        seed: ModifiedOkaModel {
            oka,
            reference,
            exponents: ShapeExponents::SEED,
        },
        fitted,
    })
}
