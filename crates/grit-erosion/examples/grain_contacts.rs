//! How the jet's grains meet the target, slice by slice (docs/jet.md, "How fast the grains
//! arrive"): every start of a contact between a grain and the target (a grain's surface coming
//! within one spacing of a target particle, the reach of the penalty contact of the AWJ paper
//! eqs. 12–14), first touches and returns alike, with the grains' speeds then, and how many
//! grain-steps a grain spends in contact. The default scene, copper at 500 m/s and 0.02 kg/s.
//!
//! ```sh
//! cargo run --release -p grit-erosion --example grain_contacts -- SEED RELEASE_RATIO SPACING_M
//! ```
//!
//! Grains carry no identity across steps, so a grain is taken to be the one of the step before
//! nearest to it (within 20 µm): a grain deleted or fed in the meantime can be miscounted once.

use std::cell::{Cell, RefCell};

use grit_erosion::jet::{JetParams, JetRun};
use grit_sph::{Vector, World};

/// Argument `k` (`name`), or `default` when it is not given.
fn arg<T: std::str::FromStr>(k: usize, name: &str, default: T) -> Result<T, String> {
    std::env::args().nth(k).map_or(Ok(default), |s| {
        s.parse()
            .map_err(|_| format!("{name}: not a number: {s:?}"))
    })
}

fn main() -> Result<(), String> {
    let seed = arg(1, "SEED", 1u64)?;
    let ratio = arg(2, "RELEASE_RATIO", 1.0)?;
    let spacing = arg(3, "SPACING_M", 1e-4)?;
    let params = JetParams {
        time_ms: 0.2,
        slice_ms: 0.05,
        grain_speed_ratio: ratio,
        spacing_m: spacing,
        ..JetParams::default()
    };
    params.validate().map_err(|e| e.to_string())?;
    let mut run = JetRun::new(params, seed).map_err(|e| e.to_string())?;
    // Per grain of the last step: its position and whether it touched the target.
    let last: RefCell<Vec<(Vector, bool)>> = RefCell::new(Vec::new());
    // Per contact start in the slice: the grain's speed.
    let starts: RefCell<Vec<f64>> = RefCell::new(Vec::new());
    let in_contact = Cell::new(0u64);
    let mut watch = |w: &World| {
        let grains = &w.abrasives().expect("a jet has grains").dem.grains;
        let p = w.particles();
        let target: Vec<Vector> = (0..p.len())
            .filter(|&k| p.body[k] == 0)
            .map(|k| p.pos[k])
            .collect();
        let mut now = Vec::with_capacity(grains.len());
        for g in grains {
            let touching = target
                .iter()
                .any(|x| (x - g.pos).norm() - g.radius_m < spacing);
            let was = last
                .borrow()
                .iter()
                .min_by(|a, b| (a.0 - g.pos).norm().total_cmp(&(b.0 - g.pos).norm()))
                .is_some_and(|a| (a.0 - g.pos).norm() < 2e-5 && a.1);
            if touching && !was {
                starts.borrow_mut().push(g.vel.norm());
            }
            in_contact.set(in_contact.get() + u64::from(touching));
            now.push((g.pos, touching));
        }
        *last.borrow_mut() = now;
    };
    println!("seed {seed}, release at {ratio} of the jet's speed, spacing {spacing} m");
    println!("slice  contact starts  mean |v| (m/s)  sum v² (m²/s²)  grain-steps in contact  first touches  loss (g/m)");
    while !run.finished() {
        starts.borrow_mut().clear();
        in_contact.set(0);
        let s = run
            .run_next_slice_observed(&|| false, Some(&mut watch))
            .map_err(|e| e.to_string())?
            .ok_or("the slice was cancelled")?;
        let v = starts.borrow();
        let n = v.len().max(1) as f64;
        println!(
            "{:>5}  {:>14}  {:>14.0}  {:>14.3e}  {:>22}  {:>13}  {:>10.3}",
            s.slice,
            v.len(),
            v.iter().sum::<f64>() / n,
            v.iter().map(|x| x * x).sum::<f64>(),
            in_contact.get(),
            s.grain_hits.map_or(0, |h| h.count),
            s.sample.mass_loss_kg_m * 1e3
        );
    }
    Ok(())
}
