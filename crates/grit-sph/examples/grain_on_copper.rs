//! One garnet grain (d = 0.2 mm) lands on a copper block through the jet scene's penalty
//! contact, no water (docs/jet.md, "What removes the first mass"): how much tension the
//! surface carries after the landing, and how much damage it takes in tension and in
//! compression, at the spacing given. Each step's gain in D is booked by the sign of the
//! particle's triaxiality −p/σ_eq after the step, as the `tensile_damage` example of grit-erosion
//! does for the whole jet.
//!
//! ```sh
//! cargo run --release -p grit-sph --example grain_on_copper -- SPACING_M SPEED_M_S [CHI] [NUMERICS] [FRICTION]
//! ```
//!
//! CHI is the penalty contact's overlap coefficient χ (default 0.5, the jet scene's). NUMERICS
//! is `jet` (the jet scene's, `Settings::water_jet`; the default), `jet-shepard` (the same with
//! the impact scene's Shepard density filter every 40 steps) or `impact` (the impact scene's
//! `Settings::default()`: quintic kernel, h = 1.3 Δx, the filter, no artificial viscosity).
//! FRICTION is the contact's Coulomb μ (default 0.3, the jet scene's).

use grit_sph::coupling::CouplingParams;
use grit_sph::dem::{Dem, DemParams, Grain};
use grit_sph::particles::von_mises;
use grit_sph::physics::triaxiality;
use grit_sph::{Abrasives, Material, Motion, PenaltyParams, Settings, Vector, World};

/// Argument `k` (`name`), or `default` when it is not given.
fn arg<T: std::str::FromStr>(k: usize, name: &str, default: T) -> Result<T, String> {
    std::env::args().nth(k).map_or(Ok(default), |s| {
        s.parse()
            .map_err(|_| format!("{name}: not a number: {s:?}"))
    })
}

fn main() -> Result<(), String> {
    let dx = arg(1, "SPACING_M", 1e-4)?;
    let speed = arg(2, "SPEED_M_S", 150.0)?;
    let chi = arg(3, "CHI", PenaltyParams::default().chi)?;
    let numerics = arg(4, "NUMERICS", "jet".to_string())?;
    let friction = arg(5, "FRICTION", PenaltyParams::default().friction)?;
    let settings = match numerics.as_str() {
        "jet" => Settings::water_jet(dx, Vector::zeros()),
        "jet-shepard" => Settings {
            shepard_interval: Settings::default().shepard_interval,
            ..Settings::water_jet(dx, Vector::zeros())
        },
        "impact" => Settings {
            spacing_m: dx,
            ..Settings::default()
        },
        other => {
            return Err(format!(
                "NUMERICS: jet, jet-shepard or impact, got {other:?}"
            ))
        }
    };
    let e = |e: grit_sph::InputError| e.to_string();
    let (width, depth, r) = (2e-3, 1e-3, 1e-4);
    let mut w = World::new(settings).map_err(e)?;
    let (nx, ny) = ((width / dx).round() as i64, (depth / dx).round() as i64);
    let pts: Vec<Vector> = (0..ny)
        .flat_map(|j| {
            (0..nx).map(move |i| {
                Vector::new(-0.5 * width + (i as f64 + 0.5) * dx, -(j as f64 + 0.5) * dx)
            })
        })
        .collect();
    let vols = vec![dx * dx; pts.len()];
    let target = w
        .add_deformable("target", Material::copper(), &pts, &vols, Vector::zeros())
        .map_err(e)?;
    let fixed = 3.0 * dx;
    w.set_kinematic(target, Motion::Fixed, |x| {
        x.x.abs() > 0.5 * width - fixed || x.y < -depth + fixed
    })
    .map_err(e)?;
    let dem = Dem::new(
        Vec::new(),
        Vec::new(),
        DemParams::default(),
        Vector::zeros(),
    )
    .map_err(e)?;
    w.set_abrasives(Abrasives::new(
        dem,
        CouplingParams::default(),
        PenaltyParams { chi, friction },
        None,
    ))
    .map_err(e)?;
    // The grain's surface starts 1.2 spacings above the top row's centres, just outside the
    // penalty contact's reach of one spacing.
    let mut g = Grain::sphere(Vector::new(0.0, -0.5 * dx + 1.2 * dx + r), r, 4120.0);
    g.vel = Vector::new(0.0, -speed);
    w.add_grain(g).map_err(e)?;

    let n = w.particles().len();
    let (mut d_prev, mut tension, mut compression) = (vec![0.0; n], 0.0, 0.0);
    let (mut p_min, mut p_max, mut t_min, mut x_min) = (0.0f64, 0.0f64, 0.0, Vector::zeros());
    let mut y_grain_at_min = 0.0;
    let t_end = 3e-6;
    while w.time() < t_end {
        w.step().map_err(|e| e.to_string())?;
        let p = w.particles();
        let pressure = w.pressures();
        for i in 0..p.len() {
            let dd = p.damage[i] - d_prev[i];
            if triaxiality(pressure[i], von_mises(&p.sdev[i])) > 0.0 {
                tension += dd;
            } else {
                compression += dd;
            }
            d_prev[i] = p.damage[i];
            if pressure[i] < p_min {
                (p_min, t_min, x_min) = (pressure[i], w.time(), p.pos[i]);
                y_grain_at_min = w.abrasives().map_or(0.0, |a| a.dem.grains[0].pos.y);
            }
            p_max = p_max.max(pressure[i]);
        }
    }
    let p = w.particles();
    let eps_max = p.eps_p.iter().cloned().fold(0.0, f64::max);
    let d_max = p.damage.iter().cloned().fold(0.0, f64::max);
    let grain = &w.abrasives().ok_or("no grains")?.dem.grains[0];
    println!(
        "spacing {dx:e} m, grain at {speed} m/s, chi {chi}, friction {friction}, {numerics} numerics, {} particles, 3 µs: highest pressure {:.2} GPa, lowest {:.2} GPa (at {:.2} µs, x = {:.1} y = {:.1} µm, grain centre then {:.1} µm above the surface), largest eps_p {:.3}, largest D {:.3}, D gained in tension {:.4}, in compression {:.4}, grain's speed after {:.1} m/s upwards",
        p.len(),
        p_max * 1e-9,
        p_min * 1e-9,
        t_min * 1e6,
        x_min.x * 1e6,
        x_min.y * 1e6,
        y_grain_at_min * 1e6,
        eps_max,
        d_max,
        tension,
        compression,
        grain.vel.y
    );
    Ok(())
}
