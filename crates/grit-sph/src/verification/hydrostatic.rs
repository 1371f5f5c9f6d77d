//! The water column at rest in a tank (the water-jet scene's check 1, docs/jet.md): the fluid
//! body of the engine under gravity, held by wall particles of its own, against
//! p = ρ0 g (H − y).

use super::{fail, CaseReport, Chart, Row, Series};
use crate::error::SimError;
use crate::fluid::Fluid;
use crate::math::Vector;
use crate::particles::KINEMATIC;
use crate::world::{Settings, World};
use crate::Motion;

/// Height of the column (m).
pub const HYDRO_H: f64 = 0.01;
/// Gravity (m/s²).
pub const HYDRO_G: f64 = 9.81;
/// Layers of wall particles: the cubic spline reaches 2h = 2.5 Δx.
const WALL_LAYERS: i64 = 3;
/// Time the column is left to settle, in units of √(H/g), before the pressure is averaged.
const SETTLE_TIMES: f64 = 8.0;
/// Length of the averaging window after it, in units of √(H/g).
const WINDOW_TIMES: f64 = 2.0;
/// Steps between samples in the window.
const SAMPLE_EVERY: u64 = 10;
/// The tolerance for the hydrostatic check.
const TOL_HYDROSTATIC: f64 = 0.02;

/// Water with the sound speed of the check, c0 = 10 √(g H): the rest of the preset's EOS is
/// kept, so the engine evaluates the same law as for the jet, 150 times softer.
pub fn hydrostatic_water() -> Fluid {
    let mut w = Fluid::water();
    w.eos.c0_m_s = 10.0 * (HYDRO_G * HYDRO_H).sqrt();
    w
}

/// A water column of `n` × `n` particles (H = 10 mm, Δx = H/n) at the left of a tank
/// `width_n` particles wide inside (`width_n` ≥ `n`), at rest at the hydrostatic pressure
/// ρ0 g (H − y), with three layers of fixed wall particles of the fluid's own body along the
/// bottom and both sides, reaching three rows above the column. With `width_n` = `n` it stands;
/// wider, it is a dam break. Cubic spline, h = 1.25 Δx, CFL 0.2 (the AWJ paper's), gravity
/// `HYDRO_G` downwards.
pub fn tank(n: usize, width_n: usize) -> Result<World, SimError> {
    if n < 4 || width_n < n {
        return Err(fail(format!(
            "tank: n = {n}, width_n = {width_n}; needs n >= 4 and width_n >= n"
        )));
    }
    let dx = HYDRO_H / n as f64;
    let settings = Settings::water_jet(dx, Vector::new(0.0, -HYDRO_G));
    let water = hydrostatic_water();
    let p_ref = |y: f64| water.density() * HYDRO_G * (HYDRO_H - y).max(0.0);
    let mut world = World::new(settings).map_err(|e| fail(e.to_string()))?;
    let (n_i, w_i, walls) = (n as i64, width_n as i64, WALL_LAYERS);
    let mut points = Vec::new();
    for j in -walls..n_i + walls {
        for i in -walls..w_i + walls {
            let fluid = (0..n_i).contains(&i) && (0..n_i).contains(&j);
            let wall = j < 0 || i < 0 || i >= w_i;
            if fluid || wall {
                points.push(Vector::new((i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx));
            }
        }
    }
    let vols = vec![dx * dx; points.len()];
    let pressure: Vec<f64> = points.iter().map(|x| p_ref(x.y)).collect();
    let b = world
        .add_fluid("water", water, &points, &vols, &pressure, Vector::zeros())
        .map_err(|e| fail(e.to_string()))?;
    let inner = width_n as f64 * dx;
    let is_wall = move |x: Vector| x.y < 0.0 || x.x < 0.0 || x.x > inner;
    world
        .set_kinematic(b, Motion::Fixed, is_wall)
        .map_err(|e| fail(e.to_string()))?;
    Ok(world)
}

/// The column of [`tank`] standing in a tank of its own width (H = W = 10 mm, Δx = H/n), left
/// for 8 √(H/g) and then sampled every 10 steps for 2 √(H/g). Rows: the mean pressure of the
/// bottom particle row against ρ0 g (H − ȳ) (relative error), and the largest deviation of a
/// row's mean pressure from ρ0 g (H − ȳ_row) over the column, relative to ρ0 g H. Bound 2 %
/// each.
pub fn hydrostatic(n: usize) -> Result<CaseReport, SimError> {
    let mut world = tank(n, n)?;
    let dx = HYDRO_H / n as f64;
    let walls = WALL_LAYERS;
    let water = hydrostatic_water();
    let rho0 = water.density();
    let p_ref = |y: f64| rho0 * HYDRO_G * (HYDRO_H - y).max(0.0);
    let t_g = (HYDRO_H / HYDRO_G).sqrt();
    let t_settle = SETTLE_TIMES * t_g;
    world.run_until(t_settle, |_| false)?;
    // Per particle row: sums of pressure and height over the samples.
    let mut sum_p = vec![0.0; n + walls as usize];
    let mut sum_y = vec![0.0; n + walls as usize];
    let mut count = vec![0u64; n + walls as usize];
    let t_end = t_settle + WINDOW_TIMES * t_g;
    while world.time() < t_end {
        world.step()?;
        if world.steps() % SAMPLE_EVERY != 0 {
            continue;
        }
        let p = world.particles();
        for i in 0..p.len() {
            if p.flags[i] & KINEMATIC != 0 {
                continue;
            }
            let y = p.pos[i].y;
            let row = (y / dx).floor();
            if !(row >= 0.0 && (row as usize) < count.len()) {
                continue;
            }
            let row = row as usize;
            sum_p[row] += water.pressure(p.rho[i], 1.0, 0.0);
            sum_y[row] += y;
            count[row] += 1;
        }
    }
    let rows: Vec<(f64, f64)> = (0..count.len())
        .filter(|&k| count[k] > 0)
        .map(|k| (sum_y[k] / count[k] as f64, sum_p[k] / count[k] as f64))
        .collect();
    let Some(&(y_bottom, p_bottom)) = rows.first() else {
        return Err(fail(
            "hydrostatic: no fluid particle left in the tank".into(),
        ));
    };
    let scale = rho0 * HYDRO_G * HYDRO_H;
    let (worst_y, worst) = rows
        .iter()
        .map(|&(y, pr)| (y, (pr - p_ref(y)).abs() / scale))
        .fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    let res = format!(
        "dx = H/{n} = {dx:.3e} m, c0 = {:.3} m/s",
        hydrostatic_water().eos.c0_m_s
    );
    let mut rep = CaseReport::default();
    let reference = p_ref(y_bottom);
    let err = (p_bottom - reference).abs() / reference;
    rep.rows.push(Row {
        case: "jet_hydrostatic_bottom".into(),
        resolution: res.clone(),
        value: p_bottom,
        reference,
        error_rel: err,
        pass: err <= TOL_HYDROSTATIC,
        expected_fail: false,
        note: format!(
            "mean pressure (Pa) of the bottom fluid row against rho0 g (H - y) at its mean height \
             {y_bottom:.4e} m, averaged over {WINDOW_TIMES} sqrt(H/g) after {SETTLE_TIMES} \
             sqrt(H/g) ({} steps, {} particles); bound 2%",
            world.steps(),
            world.particles().len()
        ),
    });
    rep.rows.push(Row {
        case: "jet_hydrostatic_profile".into(),
        resolution: res,
        value: worst,
        reference: 0.0,
        error_rel: worst,
        pass: worst <= TOL_HYDROSTATIC,
        expected_fail: false,
        note: format!(
            "largest |p_row - rho0 g (H - y_row)| / (rho0 g H) over the {} fluid rows (at \
             y = {worst_y:.4e} m), same window; bound 2%",
            rows.len()
        ),
    });
    let ys: Vec<f64> = rows.iter().map(|r| r.0 * 1e3).collect();
    rep.charts.push(Chart {
        name: "jet_hydrostatic".into(),
        title: format!("Water column at rest, H = 10 mm, {n} x {n} particles"),
        x_label: "height y (mm)".into(),
        y_label: "pressure (Pa)".into(),
        series: vec![
            Series {
                label: "SPH, row means".into(),
                x: ys.clone(),
                y: rows.iter().map(|r| r.1).collect(),
                reference: false,
            },
            Series {
                label: "rho0 g (H - y)".into(),
                x: ys,
                y: rows.iter().map(|r| p_ref(r.0)).collect(),
                reference: true,
            },
        ],
    });
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_coarse_column_stands_within_the_tolerance() {
        let rep = hydrostatic(12).unwrap();
        assert_eq!(rep.rows.len(), 2);
        for r in &rep.rows {
            eprintln!(
                "{} {:.4e} {:.4e} {:.3e}",
                r.case, r.value, r.reference, r.error_rel
            );
            assert!(
                r.pass,
                "{}: {} vs {} ({})",
                r.case, r.value, r.reference, r.note
            );
        }
    }
}
