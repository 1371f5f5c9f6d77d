//! Hertz contact of an elastic half cylinder on a rigid flat (seed section 3.3.3): the aluminium
//! half cylinder (E 70 GPa, ν 0.3, R 25 mm, plane strain) is pressed onto a rigid flat by its
//! top boundary; the peak contact pressure follows eq. 31, the pressure profile eq. 32 and the
//! stresses on the symmetry axis eq. 33. Hertz's cylinder on a rigid flat in plane strain uses
//! the contact modulus E* = E / (1 − ν²) (docs/references.md#contact), and so does every comparison here.

use super::{CaseReport, Chart, Row, Series};
use crate::body::Motion;
use crate::contact::{cfl_matched_stiffness, ContactModel, ContactParams};
use crate::error::SimError;
use crate::geometry::Polygon;
use crate::material::Material;
use crate::math::Vector;
use crate::world::{Settings, World};

/// Cylinder radius (m), seed section 3.3.3.
pub const RADIUS: f64 = 0.025;
/// Speed of the top boundary (m/s). Against the P-wave speed of 5.9 km/s it is Mach 8e-4, and
/// the 50 MN/m load takes about 0.2 ms, some 50 wave transits of the radius (4.2 µs): the
/// cylinder is loaded quasi-statically, as the seed's 0.1 m/s does, at 1/50 of the cost.
pub const SPEED: f64 = 5.0;
/// Ramp of the top boundary's speed (s): five wave transits, so the start sends no shock.
pub const RAMP_S: f64 = 20e-6;
/// Loads (N/m) at which the peak pressure is compared with eq. 31.
pub const LOADS: [f64; 5] = [10e6, 20e6, 30e6, 40e6, 50e6];
/// Depth range of the axis-stress comparison, in contact half-widths: Hertz's half-space
/// solution (eq. 33) stops describing a finite cylinder deeper down.
pub const AXIS_DEPTH: f64 = 2.0;
/// Stop if the load has not reached 50 MN/m by then (s): five times the expected time.
pub const T_MAX: f64 = 1e-3;
/// Repulsion stiffness over the engine's default ρc²/(h/Δx)² (whose spring–particle period is
/// the CFL step). The spring lets a surface particle sink p Δx / k_r into the flat, a soft
/// layer that widens the contact and lowers p0: at the default k_r it is 0.13 Δx at 7 GPa, of
/// the order of the elastic approach over the contact width. Four times stiffer costs 1.55 times
/// the steps: the contact step, set by the innermost ring's light particles, falls below the CFL
/// step.
pub const STIFFNESS_FACTOR: f64 = 4.0;
/// Density filter period (steps) of this case: none. Eq. 12 smooths density over the kernel;
/// applied every 40 steps through the ~10⁴ steps of quasi-static loading it diffuses the
/// pressure peak, which the `hertz_peak_pressure_density_filter` row measures.
pub const DENSITY_FILTER: u32 = 0;
/// Bound on the relative error of p0 at the finest spacing (docs/design.md#targets).
pub const P0_BOUND: f64 = 0.05;
/// Regression bound on the pressure-profile RMS error over p0 (docs/design.md#targets asks
/// for the value only; measured 0.03–0.04 at 20–50 particles per radius).
pub const PRESSURE_RMS_BOUND: f64 = 0.1;
/// Regression bound on the axis-stress RMS error over p0 (docs/design.md#targets asks for
/// the value only; measured 0.09–0.11 at 20–50 particles per radius, most of it the finite cylinder's own
/// horizontal tension, which the half-space solution of eq. 33 leaves out).
pub const AXIS_RMS_BOUND: f64 = 0.15;

/// Contact modulus of a cylinder on a rigid flat in plane strain, E* = E / (1 − ν²) (Pa).
pub fn contact_modulus(m: &Material) -> f64 {
    m.youngs_modulus_pa / (1.0 - m.poisson_ratio * m.poisson_ratio)
}

/// Hertz peak pressure p0 = sqrt(Q E* / (π R)) for load `q` (N/m), eq. 31 (Pa).
pub fn peak_pressure(q: f64, e_star: f64) -> f64 {
    (q * e_star / (std::f64::consts::PI * RADIUS)).sqrt()
}

/// Hertz contact half-width a = 2 sqrt(Q R / (π E*)), eq. 31 (m).
pub fn half_width(q: f64, e_star: f64) -> f64 {
    2.0 * (q * RADIUS / (std::f64::consts::PI * e_star)).sqrt()
}

/// Hertz pressure p(x) = p0 sqrt(1 − (x/a)²) inside the contact, eq. 32 (Pa).
pub fn pressure(x: f64, q: f64, e_star: f64) -> f64 {
    let a = half_width(q, e_star);
    let u = 1.0 - (x / a).powi(2);
    peak_pressure(q, e_star) * u.max(0.0).sqrt()
}

/// Stresses on the symmetry axis at depth `z` below the contact centre, eq. 33 (Tripp):
/// (horizontal σ_xx, vertical σ_zz, out-of-plane σ_yy = ν (σ_xx + σ_zz)) (Pa, compression < 0).
pub fn axis_stresses(z: f64, q: f64, e_star: f64, nu: f64) -> [f64; 3] {
    let p0 = peak_pressure(q, e_star);
    let zeta = z / half_width(q, e_star);
    let s = (1.0 + zeta * zeta).sqrt();
    let sxx = -p0 / s * (2.0 * zeta * zeta + 1.0 - 2.0 * zeta * s);
    let szz = -p0 / s;
    [sxx, szz, nu * (sxx + szz)]
}

/// Particles of a half disc (the half below `centre`) of radius `radius` on concentric rings
/// Δx apart, ring k at radius R − (k + ½)Δx with an odd number of particles evenly spread over
/// its half circle, so every ring has one on the symmetry axis; returns (points, areas (m²)).
///
/// A square lattice would give the disc a staircase bottom, flat over several particles, which
/// spreads the load as a flat punch does; rings follow the curved surface.
pub fn half_disc_rings(radius: f64, dx: f64, centre: Vector) -> (Vec<Vector>, Vec<f64>) {
    let n_rings = (radius / dx).round() as usize;
    let mut pts = Vec::new();
    let mut vols = Vec::new();
    for k in 0..n_rings {
        let r = radius - (k as f64 + 0.5) * dx;
        let mut m = (std::f64::consts::PI * r / dx).round().max(1.0) as usize;
        if m.is_multiple_of(2) {
            m += 1;
        }
        // The half annulus between r ± Δx/2 shared equally.
        let area = std::f64::consts::PI * r * dx / m as f64;
        for j in 0..m {
            let th = std::f64::consts::PI * (1.0 + (j as f64 + 0.5) / m as f64);
            pts.push(centre + Vector::new(r * th.cos(), r * th.sin()));
            vols.push(area);
        }
    }
    (pts, vols)
}

/// The state of the contact when the load first reaches one of LOADS.
#[derive(Debug, Clone, Default)]
pub struct Snapshot {
    /// Load Q: total contact force on the cylinder (N/m).
    pub load_n_m: f64,
    /// Peak contact pressure: largest contact force on a surface particle over its arc spacing (Pa).
    pub peak_pa: f64,
    /// Surface particles: (x (m), contact pressure (Pa)).
    pub surface: Vec<(f64, f64)>,
    /// Axis particles: (depth below the contact centre (m), [σ_xx, σ_zz, σ_yy] (Pa)).
    pub axis: Vec<(f64, [f64; 3])>,
    /// Simulated time (s).
    pub time_s: f64,
}

/// Presses the half cylinder, `n_radius` particles along its radius, until the load passes
/// each of LOADS; returns one snapshot per load. `shepard_interval` is the density filter's
/// (eq. 12) period in steps, 0 for none (this case's choice, see DENSITY_FILTER).
pub fn simulate(n_radius: usize, shepard_interval: u32) -> Result<Vec<Snapshot>, SimError> {
    simulate_with(
        n_radius,
        Settings {
            shepard_interval,
            ..Settings::default()
        },
    )
}

/// `simulate` with other engine settings (kernel, Courant number, …); their spacing is
/// replaced by the radius over `n_radius`. For the speed–accuracy sweep.
pub fn simulate_with(n_radius: usize, settings: Settings) -> Result<Vec<Snapshot>, SimError> {
    let dx = RADIUS / n_radius as f64;
    let mat = Material::elastic_aluminium();
    let bulk = mat.bulk_modulus();
    let mut w = World::new(Settings {
        spacing_m: dx,
        ..settings
    })
    .map_err(|e| SimError {
        step: 0,
        time_s: 0.0,
        what: e.to_string(),
    })?;
    let flat = Polygon::rectangle(-RADIUS, -3.0 * dx, RADIUS, 0.0);
    let flat_b = w
        .add_rigid("flat", &flat, 7800.0, Vector::zeros(), 0.0, Motion::Fixed)
        .expect("flat");
    // The outer ring sits Δx/2 inside the surface, so the lowest particle is at the contact
    // distance Δx from the flat's top particle layer (at −Δx/2): touching, without force.
    let centre = Vector::new(0.0, RADIUS);
    let (pts, vols) = half_disc_rings(RADIUS, dx, centre);
    let base = w.particles().len();
    let cyl = w
        .add_deformable("cylinder", mat.clone(), &pts, &vols, Vector::zeros())
        .expect("cylinder");
    // Top layers, one kernel support deep, move as the loading plate.
    let top = centre.y - 3.0 * w.h();
    w.set_kinematic(
        cyl,
        Motion::Velocity {
            velocity_m_s: Vector::new(0.0, -SPEED),
            ramp_s: RAMP_S,
        },
        |x| x.y > top,
    )
    .expect("deformable");
    let k_default = cfl_matched_stiffness(&mat, w.settings().h_over_dx);
    w.add_contact(
        flat_b,
        cyl,
        ContactParams {
            model: ContactModel::Extrapolated,
            normal_stiffness_pa: Some(STIFFNESS_FACTOR * k_default),
            // Frictionless (μ = 0, as Hertz assumes): the friction spring only enters the
            // contact time step, so it keeps the default stiffness.
            tangential_stiffness_pa: Some(k_default),
            ..ContactParams::default()
        },
    )
    .expect("contact");
    let r0 = RADIUS - 0.5 * dx;
    let m0 = pts
        .iter()
        .filter(|&&p| ((p - centre).norm() - r0).abs() < 1e-9 * RADIUS)
        .count();
    let arc = std::f64::consts::PI * r0 / m0 as f64;
    let surface: Vec<usize> = (base..base + m0).collect();
    let axis: Vec<usize> = (base..base + pts.len())
        .filter(|&i| pts[i - base].x.abs() < 1e-9 * RADIUS && pts[i - base].y < top)
        .collect();
    let mut out = Vec::new();
    while out.len() < LOADS.len() {
        w.step()?;
        let cf = w.contact_forces();
        let q: f64 = (base..base + pts.len()).map(|i| cf[i].y).sum();
        if q < LOADS[out.len()] {
            if w.time() > T_MAX {
                return Err(SimError {
                    step: w.steps(),
                    time_s: w.time(),
                    what: format!(
                        "load {q:.4e} N/m still below {:.4e} N/m at the end of the run",
                        LOADS[out.len()]
                    ),
                });
            }
            continue;
        }
        let p = w.particles();
        let surf: Vec<(f64, f64)> = surface
            .iter()
            .map(|&i| (p.pos[i].x, cf[i].y / arc))
            .collect();
        let peak = surf.iter().map(|s| s.1).fold(0.0, f64::max);
        // The contact centre is the surface, Δx/2 below the lowest axis particle.
        let y_c = p.pos[axis[0]].y - 0.5 * dx;
        let ax = axis
            .iter()
            .map(|&i| {
                let s = p.sdev[i];
                let pr = p.pressure(i, bulk);
                let out_of_plane = -(s[(0, 0)] + s[(1, 1)]) - pr;
                (
                    p.pos[i].y - y_c,
                    [s[(0, 0)] - pr, s[(1, 1)] - pr, out_of_plane],
                )
            })
            .collect();
        out.push(Snapshot {
            load_n_m: q,
            peak_pa: peak,
            surface: surf,
            axis: ax,
            time_s: w.time(),
        });
    }
    Ok(out)
}

/// The largest relative error of p0 over the loads of `snapshots` (the verification's figure).
pub fn max_peak_error(snapshots: &[Snapshot]) -> Option<f64> {
    let e_star = contact_modulus(&Material::elastic_aluminium());
    snapshots
        .iter()
        .map(|s| peak_error(s, e_star))
        .reduce(f64::max)
}

/// Relative error of the simulated peak pressure against eq. 31 at the simulated load.
pub fn peak_error(s: &Snapshot, e_star: f64) -> f64 {
    let r = peak_pressure(s.load_n_m, e_star);
    (s.peak_pa - r).abs() / r
}

/// RMS difference between the simulated and eq. 32 pressure over the surface particles within
/// 1.5 a of the centre, over p0 (both at the simulated load).
pub fn pressure_rms(s: &Snapshot, e_star: f64) -> f64 {
    let a = half_width(s.load_n_m, e_star);
    let d: Vec<f64> = s
        .surface
        .iter()
        .filter(|(x, _)| x.abs() <= 1.5 * a)
        .map(|&(x, p)| p - pressure(x, s.load_n_m, e_star))
        .collect();
    rms(&d) / peak_pressure(s.load_n_m, e_star)
}

/// RMS difference between the simulated and eq. 33 axis stresses (all three components) down
/// to AXIS_DEPTH half-widths, over p0.
pub fn axis_rms(s: &Snapshot, e_star: f64, nu: f64) -> f64 {
    let a = half_width(s.load_n_m, e_star);
    let mut d = Vec::new();
    for &(z, sim) in s.axis.iter().filter(|(z, _)| *z <= AXIS_DEPTH * a) {
        let r = axis_stresses(z, s.load_n_m, e_star, nu);
        d.extend((0..3).map(|k| sim[k] - r[k]));
    }
    rms(&d) / peak_pressure(s.load_n_m, e_star)
}

fn rms(d: &[f64]) -> f64 {
    if d.is_empty() {
        return f64::NAN;
    }
    (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt()
}

/// Runs the case at each of `n_radius` (coarse to fine) and reports p0 against eq. 31 at every
/// load, and the pressure profile and axis stresses at 50 MN/m against eqs. 32–33.
pub fn run(n_radius: &[usize]) -> Result<CaseReport, SimError> {
    let mat = Material::elastic_aluminium();
    let e_star = contact_modulus(&mat);
    let nu = mat.poisson_ratio;
    let mut rep = CaseReport::default();
    let mut p0_chart = Chart {
        name: "hertz_peak_pressure".into(),
        title: "Hertz contact: peak pressure against load (seed 3.3.3, eq. 31)".into(),
        x_label: "load Q (MN/m)".into(),
        y_label: "peak pressure p0 (GPa)".into(),
        series: vec![],
    };
    let mut profile = Chart {
        name: "hertz_pressure_profile".into(),
        title: "Hertz contact: pressure at 50 MN/m (eq. 32)".into(),
        x_label: "x (mm)".into(),
        y_label: "contact pressure (GPa)".into(),
        series: vec![],
    };
    let mut axis_chart = Chart {
        name: "hertz_axis_stress".into(),
        title: "Hertz contact: stresses on the axis at 50 MN/m (eq. 33)".into(),
        x_label: "depth z / a".into(),
        y_label: "stress / p0".into(),
        series: vec![],
    };
    let mut prev_err = f64::INFINITY;
    let mut first_err = f64::NAN;
    for (k, &n) in n_radius.iter().enumerate() {
        let snaps = simulate(n, DENSITY_FILTER)?;
        let dx_mm = RADIUS / n as f64 * 1e3;
        let res = format!("dx={dx_mm:.3} mm ({n} per radius)");
        let errs: Vec<f64> = snaps.iter().map(|s| peak_error(s, e_star)).collect();
        let worst = errs.iter().cloned().fold(0.0, f64::max);
        let last = snaps.last().expect("one snapshot per load");
        let finest = k + 1 == n_radius.len();
        let shrinks = worst < prev_err;
        rep.rows.push(Row {
            case: "hertz_peak_pressure".into(),
            resolution: res.clone(),
            value: last.peak_pa,
            reference: peak_pressure(last.load_n_m, e_star),
            error_rel: worst,
            pass: shrinks && (!finest || worst <= P0_BOUND),
            expected_fail: false,
            note: format!(
                "p0 (Pa) at Q = {:.2} MN/m, reached at t = {:.3} ms; error = max relative error of p0 over Q = {} MN/m ({}), E* = E/(1-nu^2); bound: smaller than at the coarser spacing, and {:.0}% at the finest",
                last.load_n_m / 1e6,
                last.time_s * 1e3,
                LOADS.map(|q| format!("{}", q / 1e6)).join("/"),
                errs.iter().map(|e| format!("{:.1}%", e * 100.0)).collect::<Vec<_>>().join("/"),
                P0_BOUND * 100.0
            ),
        });
        prev_err = worst;
        if k == 0 {
            first_err = worst;
        }
        let prms = pressure_rms(last, e_star);
        rep.rows.push(Row {
            case: "hertz_pressure_profile_rms".into(),
            resolution: res.clone(),
            value: prms,
            reference: 0.0,
            error_rel: prms,
            pass: prms <= PRESSURE_RMS_BOUND,
            expected_fail: false,
            note: format!(
                "RMS(p - eq. 32) / p0 over surface particles with |x| <= 1.5 a at Q = {:.2} MN/m; regression bound {PRESSURE_RMS_BOUND}",
                last.load_n_m / 1e6
            ),
        });
        let arms = axis_rms(last, e_star, nu);
        rep.rows.push(Row {
            case: "hertz_axis_stress_rms".into(),
            resolution: res.clone(),
            value: arms,
            reference: 0.0,
            error_rel: arms,
            pass: arms <= AXIS_RMS_BOUND,
            expected_fail: false,
            note: format!(
                "RMS(sigma - eq. 33) / p0 over sxx, szz, syy of axis particles down to z = {AXIS_DEPTH} a at Q = {:.2} MN/m; regression bound {AXIS_RMS_BOUND}",
                last.load_n_m / 1e6
            ),
        });
        p0_chart.series.push(Series {
            label: format!("SPH {res}"),
            x: snaps.iter().map(|s| s.load_n_m / 1e6).collect(),
            y: snaps.iter().map(|s| s.peak_pa / 1e9).collect(),
            reference: false,
        });
        let mut surf = last.surface.clone();
        surf.retain(|(x, _)| x.abs() <= 1.5 * half_width(last.load_n_m, e_star));
        surf.sort_by(|a, b| a.0.total_cmp(&b.0));
        profile.series.push(Series {
            label: format!("SPH {res}"),
            x: surf.iter().map(|s| s.0 * 1e3).collect(),
            y: surf.iter().map(|s| s.1 / 1e9).collect(),
            reference: false,
        });
        if finest {
            let a = half_width(last.load_n_m, e_star);
            let p0 = peak_pressure(last.load_n_m, e_star);
            let pts: Vec<&(f64, [f64; 3])> = last
                .axis
                .iter()
                .filter(|(z, _)| *z <= 2.0 * AXIS_DEPTH * a)
                .collect();
            for (c, name) in ["sigma_xx", "sigma_zz (vertical)", "sigma_yy (out of plane)"]
                .iter()
                .enumerate()
            {
                axis_chart.series.push(Series {
                    label: format!("SPH {name}, {res}"),
                    x: pts.iter().map(|s| s.0 / a).collect(),
                    y: pts.iter().map(|s| s.1[c] / p0).collect(),
                    reference: false,
                });
                let zs: Vec<f64> = (0..=80)
                    .map(|i| i as f64 * 2.0 * AXIS_DEPTH / 80.0)
                    .collect();
                axis_chart.series.push(Series {
                    label: format!("eq. 33 {name}"),
                    y: zs
                        .iter()
                        .map(|&z| axis_stresses(z * a, last.load_n_m, e_star, nu)[c] / p0)
                        .collect(),
                    x: zs,
                    reference: true,
                });
            }
        }
    }
    // The same coarsest run with the seed's density filter, to show why this case goes without.
    let n0 = n_radius[0];
    let filtered = simulate(n0, 40)?;
    let errs: Vec<f64> = filtered.iter().map(|s| peak_error(s, e_star)).collect();
    let worst = errs.iter().cloned().fold(0.0, f64::max);
    let last = filtered.last().expect("one snapshot per load");
    rep.rows.push(Row {
        case: "hertz_peak_pressure_density_filter".into(),
        resolution: format!("dx={:.3} mm ({n0} per radius)", RADIUS / n0 as f64 * 1e3),
        value: last.peak_pa,
        reference: peak_pressure(last.load_n_m, e_star),
        error_rel: worst,
        pass: worst <= P0_BOUND,
        // A demonstration: the seed's filter smooths the peak of the contact pressure away.
        expected_fail: true,
        note: format!(
            "as hertz_peak_pressure with the density filter (eq. 12) every 40 steps; errors {}; expected to fail the {:.0}% bound (without the filter {:.1}%): the reason this case runs without it",
            errs.iter().map(|e| format!("{:.1}%", e * 100.0)).collect::<Vec<_>>().join("/"),
            P0_BOUND * 100.0,
            first_err * 100.0
        ),
    });
    let qs: Vec<f64> = (0..=50).map(|i| i as f64).collect();
    p0_chart.series.push(Series {
        label: "Hertz, eq. 31".into(),
        y: qs
            .iter()
            .map(|&q| peak_pressure(q * 1e6, e_star) / 1e9)
            .collect(),
        x: qs,
        reference: true,
    });
    let q = LOADS[LOADS.len() - 1];
    let a = half_width(q, e_star);
    let xs: Vec<f64> = (0..=120)
        .map(|i| (-1.5 + 3.0 * i as f64 / 120.0) * a)
        .collect();
    profile.series.push(Series {
        label: "Hertz, eq. 32 at 50 MN/m".into(),
        y: xs.iter().map(|&x| pressure(x, q, e_star) / 1e9).collect(),
        x: xs.iter().map(|x| x * 1e3).collect(),
        reference: true,
    });
    rep.charts.extend([p0_chart, profile, axis_chart]);
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rings_fill_the_half_disc_area_with_a_particle_on_every_ring_axis() {
        let (dx, r) = (1e-3, 0.025);
        let (pts, vols) = half_disc_rings(r, dx, Vector::zeros());
        let area: f64 = vols.iter().sum();
        let exact = 0.5 * std::f64::consts::PI * r * r;
        assert!((area - exact).abs() < 1e-12 * exact, "{area} vs {exact}");
        let on_axis = pts.iter().filter(|p| p.x.abs() < 1e-12).count();
        assert_eq!(on_axis, 25);
        assert!(pts.iter().all(|p| p.y < 0.0 && p.norm() < r));
    }

    #[test]
    fn axis_stresses_start_at_minus_p0_and_fade_with_depth() {
        let e = 7.7e10;
        let q = 5e7;
        let p0 = peak_pressure(q, e);
        let s0 = axis_stresses(0.0, q, e, 0.3);
        assert!((s0[0] + p0).abs() < 1e-9 * p0 && (s0[1] + p0).abs() < 1e-9 * p0);
        let deep = axis_stresses(10.0 * half_width(q, e), q, e, 0.3);
        assert!(deep[1].abs() < 0.1 * p0 && deep[0].abs() < 0.01 * p0);
        // Q = ∫ p dx = π a p0 / 2.
        let a = half_width(q, e);
        assert!((std::f64::consts::PI * a * p0 / 2.0 - q).abs() < 1e-9 * q);
    }
}
