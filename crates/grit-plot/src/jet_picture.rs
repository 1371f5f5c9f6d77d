//! Pictures of the abrasive water-jet scene (docs/jet.md): water, target and grains, coloured
//! by phase, by pressure or by the target's damage, in the frame of the surface pictures.

use std::path::Path;

use grit_sph::particles::KINEMATIC;
use grit_sph::{Particles, Vector};
use plotters::prelude::*;

use crate::draw::de;
use crate::surface::{draw_frame, layout, viridis, Frame};
use crate::PlotError;

/// µm per metre, for the axes.
const UM: f64 = 1e6;
/// Pressure colours span this quantile range of the particles' pressures, so the water-hammer
/// peak of a few particles does not wash out the rest.
const PRESSURE_QUANTILES: (f64, f64) = (0.01, 0.99);
/// Colours of the phases.
const WATER: RGBColor = RGBColor(120, 170, 225);
const TARGET: RGBColor = RGBColor(196, 120, 64);
const GRAIN: RGBColor = RGBColor(70, 70, 70);

/// What a jet picture is coloured by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JetField {
    /// Water blue, target copper-coloured (its fixed sides pale), grains dark grey.
    Phase,
    /// Every particle's pressure (water's EOS, the target's), grains dark grey.
    Pressure,
    /// The target's Johnson–Cook damage D, water pale blue, grains dark grey.
    Damage,
}

impl JetField {
    /// All fields, in the order pictures are made.
    pub const ALL: [JetField; 3] = [JetField::Phase, JetField::Pressure, JetField::Damage];

    /// File-name stem.
    pub fn stem(self) -> &'static str {
        match self {
            JetField::Phase => "phase",
            JetField::Pressure => "pressure",
            JetField::Damage => "damage",
        }
    }
}

/// What one jet picture shows.
#[derive(Debug, Clone)]
pub struct JetPicture<'a> {
    /// Water and target particles (positions in m).
    pub particles: &'a Particles,
    /// Each particle's pressure (Pa).
    pub pressure_pa: &'a [f64],
    /// Body index of the water.
    pub fluid_body: u32,
    /// Particle spacing Δx (m): each particle is a disc of this diameter.
    pub spacing_m: f64,
    /// Grains: centre (m) and radius (m).
    pub grains: Vec<(Vector, f64)>,
    /// The part of the plane shown (lower-left and upper-right corners, m); what lies outside
    /// (fragments flung far off) is left out. `None` shows everything.
    pub view_m: Option<(Vector, Vector)>,
    /// Title line; the field's name is put in front of it.
    pub title: String,
    /// Lines of notes under the plot.
    pub notes: Vec<String>,
}

/// The `lo` and `hi` quantiles of `v` (finite values), widened to a non-empty range.
fn quantile_range(v: &[f64], (lo, hi): (f64, f64)) -> (f64, f64) {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return (0.0, 1.0);
    }
    s.sort_by(f64::total_cmp);
    let at = |q: f64| s[((s.len() - 1) as f64 * q).round() as usize];
    let (a, b) = (at(lo), at(hi));
    if b > a {
        (a, b)
    } else {
        (a - 1.0, a + 1.0)
    }
}

/// Draws `pic` coloured by `field` as a PNG at `path`.
pub fn jet_png(pic: &JetPicture, field: JetField, path: &Path) -> Result<(), PlotError> {
    let failed = |message| PlotError::Draw {
        path: path.to_path_buf(),
        message,
    };
    if pic.pressure_pa.len() != pic.particles.len() {
        return Err(PlotError::Input(format!(
            "{} pressures for {} particles",
            pic.pressure_pa.len(),
            pic.particles.len()
        )));
    }
    let mpa: Vec<f64> = pic.pressure_pa.iter().map(|p| p * 1e-6).collect();
    let (bar, label) = match field {
        JetField::Phase => (None, "phase"),
        JetField::Pressure => {
            let (lo, hi) = quantile_range(&mpa, PRESSURE_QUANTILES);
            (Some(("pressure (MPa)", lo, hi)), "pressure")
        }
        JetField::Damage => (Some(("damage D", 0.0, 1.0)), "damage"),
    };
    let inside = |x: &Vector| {
        pic.view_m
            .is_none_or(|(lo, hi)| x.x >= lo.x && x.x <= hi.x && x.y >= lo.y && x.y <= hi.y)
    };
    let l = match pic.view_m {
        Some((lo, hi)) => layout([lo, hi].into_iter(), pic.spacing_m, pic.notes.len()),
        None => {
            let pts = pic.particles.pos.iter().copied();
            let pts = pts.chain(pic.grains.iter().map(|g| g.0));
            layout(pts, pic.spacing_m, pic.notes.len())
        }
    };
    let root = BitMapBackend::new(path, l.size).into_drawing_area();
    let title = format!("{label}: {}", pic.title);
    let r_px = l.radius_px;
    let scale = r_px / (0.5 * pic.spacing_m * UM);
    draw_frame(
        &root,
        &title,
        &pic.notes,
        &l,
        bar,
        |chart: &mut Frame<'_, _>| {
            let p = pic.particles;
            let colour = |i: usize| -> RGBAColor {
                let water = p.body[i] == pic.fluid_body;
                let fixed = p.flags[i] & KINEMATIC != 0;
                let c = match (field, water) {
                    (JetField::Phase, true) => WATER,
                    (JetField::Phase, false) => TARGET,
                    (JetField::Pressure, _) => {
                        let (_, lo, hi) = bar.expect("pressure has a bar");
                        viridis((mpa[i] - lo) / (hi - lo))
                    }
                    (JetField::Damage, true) => WATER,
                    (JetField::Damage, false) => viridis(p.damage[i]),
                };
                let pale = fixed || (field == JetField::Damage && water);
                if pale {
                    c.mix(0.45)
                } else {
                    c.mix(1.0)
                }
            };
            chart
                .draw_series((0..p.len()).filter(|&i| inside(&p.pos[i])).map(|i| {
                    Circle::new((p.pos[i].x * UM, p.pos[i].y * UM), r_px, colour(i).filled())
                }))
                .map_err(de)?;
            chart
                .draw_series(pic.grains.iter().filter(|g| inside(&g.0)).map(|(c, r)| {
                    let px = (r * UM * scale).max(2.0);
                    Circle::new((c.x * UM, c.y * UM), px, GRAIN.filled())
                }))
                .map_err(de)?;
            Ok(())
        },
    )
    .map_err(failed)?;
    root.present().map_err(de).map_err(failed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pressure_range_leaves_out_the_extremes() {
        let mut v: Vec<f64> = (0..=100).map(f64::from).collect();
        v.push(1e9);
        v.push(f64::NAN);
        let (lo, hi) = quantile_range(&v, (0.01, 0.99));
        assert!(
            (0.0..=2.0).contains(&lo) && (98.0..=101.0).contains(&hi),
            "{lo} {hi}"
        );
        assert_eq!(quantile_range(&[], (0.01, 0.99)), (0.0, 1.0));
        assert_eq!(quantile_range(&[5.0, 5.0], (0.01, 0.99)), (4.0, 6.0));
    }
}
