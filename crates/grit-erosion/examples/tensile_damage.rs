//! Where the jet's target damage comes from (docs/jet.md, "What removes the first mass"):
//! after every step, each target particle's gain in Johnson–Cook damage D and in plastic strain
//! is booked as tensile when its stress triaxiality −p/σ_eq is positive after the step, else as
//! compressive. Per slice it prints the target's totals, and for every particle deleted at
//! D ≥ 1 so far the share of its damage and strain gained in tension and the lowest pressure it
//! saw. The default scene, copper at 500 m/s and 0.02 kg/s, 0.2 ms.
//!
//! ```sh
//! cargo run --release -p grit-erosion --example tensile_damage -- SEED SPACING_M
//! ```

use std::collections::HashMap;

mod common;

use common::{arg, short_run};
use grit_sph::particles::von_mises;
use grit_sph::physics::triaxiality;
use grit_sph::World;

/// One target particle's history: damage and plastic strain now, their gains in tension and in
/// compression, and the lowest pressure it saw (Pa).
#[derive(Default, Clone, Copy)]
struct History {
    damage: f64,
    eps_p: f64,
    damage_tension: f64,
    damage_compression: f64,
    eps_tension: f64,
    eps_compression: f64,
    min_pressure: f64,
}

/// Books each target particle's gains over the last step; a particle that is gone was deleted.
struct Books {
    target: u32,
    live: HashMap<u32, History>,
    deleted: Vec<History>,
    slice_tension: f64,
    slice_compression: f64,
}

impl Books {
    fn observe(&mut self, w: &World) {
        let p = w.particles();
        let pressure = w.pressures();
        let mut seen = HashMap::with_capacity(self.live.len());
        for i in (0..p.len()).filter(|&i| p.body[i] == self.target) {
            let mut h = self.live.get(&p.id[i]).copied().unwrap_or_default();
            let (dd, de) = (p.damage[i] - h.damage, p.eps_p[i] - h.eps_p);
            if triaxiality(pressure[i], von_mises(&p.sdev[i])) > 0.0 {
                h.damage_tension += dd;
                h.eps_tension += de;
                self.slice_tension += dd;
            } else {
                h.damage_compression += dd;
                h.eps_compression += de;
                self.slice_compression += dd;
            }
            h.damage = p.damage[i];
            h.eps_p = p.eps_p[i];
            h.min_pressure = h.min_pressure.min(pressure[i]);
            seen.insert(p.id[i], h);
        }
        // Fragments that leave the scene go too; only those near D = 1 were deleted for it.
        for (id, h) in &self.live {
            if !seen.contains_key(id) && h.damage > 0.8 {
                self.deleted.push(*h);
            }
        }
        self.live = seen;
    }
}

fn main() -> Result<(), String> {
    let seed = arg(1, "SEED", 1u64)?;
    let spacing = arg(2, "SPACING_M", 1e-4)?;
    // Grains released at the jet's speed, the scene's default.
    let mut run = short_run(seed, 1.0, spacing)?;
    let mut books = Books {
        target: run.layout().target_body as u32,
        live: HashMap::new(),
        deleted: Vec::new(),
        slice_tension: 0.0,
        slice_compression: 0.0,
    };
    println!("seed {seed}, spacing {spacing} m");
    println!(
        "slice  D gained in tension  in compression  deleted  their D from tension  their eps_p from tension  their eps_p  their lowest p (GPa)"
    );
    while !run.finished() {
        books.slice_tension = 0.0;
        books.slice_compression = 0.0;
        let mut observe = |w: &World| books.observe(w);
        let s = run
            .run_next_slice_observed(&|| false, Some(&mut observe))
            .map_err(|e| e.to_string())?
            .ok_or("cancelled")?
            .slice;
        let d = &books.deleted;
        let n = d.len().max(1) as f64;
        let mean = |f: &dyn Fn(&History) -> f64| d.iter().map(f).sum::<f64>() / n;
        println!(
            "{:>5}  {:>19.2}  {:>14.2}  {:>7}  {:>20.3}  {:>24.3}  {:>11.2}  {:>20.2}",
            s,
            books.slice_tension,
            books.slice_compression,
            d.len(),
            mean(&|h| h.damage_tension / (h.damage_tension + h.damage_compression)),
            mean(&|h| h.eps_tension / (h.eps_tension + h.eps_compression)),
            mean(&|h| h.eps_p),
            mean(&|h| h.min_pressure) * 1e-9,
        );
    }
    Ok(())
}
