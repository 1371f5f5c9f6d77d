//! Which side of the drag switch the jet's grains fall on (docs/jet.md, "How fast the grains
//! arrive"): every `EVERY` steps of the default scene (copper, 500 m/s, 0.02 kg/s, 0.2 ms), each
//! grain's porosity ε_i, the Shepard average of the fluid's ε_a over its coupling radius (the
//! AWJ paper eqs. 20 and 45, recomputed here from the positions exactly as the coupling stage
//! does), binned by the grain's height above the target's surface. At or below the switch
//! (0.8) the drag is Ergun's, above it Wen–Yu's (eq. 47), 3.7 times weaker at high Re.
//!
//! ```sh
//! cargo run --release -p grit-erosion --example grain_porosity -- SEED [RELEASE_RATIO] [SPACING_M]
//! ```

mod common;

use common::{arg, short_run};
use grit_sph::{coupling, World};

/// Steps between samples: a grain crosses a spacing in about ten steps at the jet's speed.
const EVERY: u64 = 10;
/// Height bands above the target's initial surface, in grain diameters: in the crater or at
/// the surface, the stagnation zone, the free jet.
const BANDS_D: [f64; 3] = [1.0, 5.0, f64::INFINITY];

/// The porosities ε_i sampled in one height band.
#[derive(Default, Clone)]
struct Band {
    eps: Vec<f64>,
}

impl Band {
    fn line(&mut self, switch: f64) -> String {
        let n = self.eps.len();
        if n == 0 {
            return format!("{:>7}", 0);
        }
        self.eps.sort_by(f64::total_cmp);
        let q = |f: f64| self.eps[((n - 1) as f64 * f).round() as usize];
        let ergun = self.eps.iter().filter(|&&e| e <= switch).count();
        format!(
            "{n:>7} {:>7.1} % Ergun   ε p10/p50/p90 {:.3}/{:.3}/{:.3}",
            100.0 * ergun as f64 / n as f64,
            q(0.1),
            q(0.5),
            q(0.9)
        )
    }
}

/// Each grain's ε_i and its height above `surface_y` (m): the coupling's own Shepard average
/// (`World::grain_fluid`). Grains with no fluid within R_c are left out.
fn grain_porosities(w: &World, surface_y: f64) -> Result<Vec<(f64, f64)>, String> {
    let seen = w.grain_fluid().map_err(|e| e.to_string())?;
    let grains = w.abrasives().map_or(&[][..], |a| &a.dem.grains[..]);
    Ok(grains
        .iter()
        .zip(&seen)
        .filter(|(_, gf)| gf.shepard > 0.0)
        .map(|(g, gf)| (gf.porosity, g.pos.y - surface_y))
        .collect())
}

fn main() -> Result<(), String> {
    let seed = arg(1, "SEED", 1u64)?;
    let ratio = arg(2, "RELEASE_RATIO", 1.0)?;
    let spacing = arg(3, "SPACING_M", 1e-4)?;
    let mut run = short_run(seed, ratio, spacing)?;
    let surface_y = run.layout().surface_y_m;
    let switch = run
        .world()
        .abrasives()
        .map_or(coupling::DEFAULT_SWITCH_POROSITY, |a| {
            a.coupling.switch_porosity
        });
    println!(
        "seed {seed}, release at {ratio} of the jet's speed, spacing {spacing} m; grains sampled every {EVERY} steps"
    );
    println!("slice  band (height above the surface)     samples  on Ergun's side   porosity");
    let d = run.params().grain_diameter_m;
    let mut total = vec![Band::default(); BANDS_D.len()];
    while !run.finished() {
        let mut bands = vec![Band::default(); BANDS_D.len()];
        let mut steps = 0u64;
        let mut failed = None;
        let mut observe = |w: &World| {
            steps += 1;
            if failed.is_some() || !steps.is_multiple_of(EVERY) {
                return;
            }
            match grain_porosities(w, surface_y) {
                Ok(found) => {
                    for (eps, height) in found {
                        let b = BANDS_D
                            .iter()
                            .position(|&top| height < top * d)
                            .unwrap_or(0);
                        bands[b].eps.push(eps);
                    }
                }
                Err(e) => failed = Some(e),
            }
        };
        let s = run
            .run_next_slice_observed(&|| false, Some(&mut observe))
            .map_err(|e| e.to_string())?
            .ok_or("the slice was cancelled")?;
        if let Some(e) = failed {
            return Err(e);
        }
        let slice = s.slice;
        for (k, b) in bands.iter_mut().enumerate() {
            total[k].eps.extend_from_slice(&b.eps);
            println!("{slice:>5}  {:<34} {}", band_name(k), b.line(switch));
        }
    }
    for (k, b) in total.iter_mut().enumerate() {
        println!("  all  {:<34} {}", band_name(k), b.line(switch));
    }
    Ok(())
}

/// The name of height band `k`.
fn band_name(k: usize) -> String {
    let lo = if k == 0 {
        f64::NEG_INFINITY
    } else {
        BANDS_D[k - 1]
    };
    match (lo.is_finite(), BANDS_D[k].is_finite()) {
        (false, _) => format!("below {} d", BANDS_D[k]),
        (true, true) => format!("{lo} to {} d", BANDS_D[k]),
        (true, false) => format!("above {lo} d"),
    }
}
