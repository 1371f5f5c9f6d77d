//! How the jet's grains meet the target, slice by slice (docs/jet.md, "How fast the grains
//! arrive"): every start of a contact between a grain and the target (the penalty contact of the
//! AWJ paper eqs. 12–14, as `World::take_grain_contacts` logs it), first touches and returns
//! alike, with the grains' speeds then, and how many grain-steps grains spend in contact. The
//! default scene, copper at 500 m/s and 0.02 kg/s, 0.2 ms.
//!
//! ```sh
//! cargo run --release -p grit-erosion --example grain_contacts -- SEED RELEASE_RATIO SPACING_M
//! ```

mod common;

use common::{arg, short_run};

fn main() -> Result<(), String> {
    let seed = arg(1, "SEED", 1u64)?;
    let ratio = arg(2, "RELEASE_RATIO", 1.0)?;
    let spacing = arg(3, "SPACING_M", 1e-4)?;
    let mut run = short_run(seed, ratio, spacing)?;
    println!("seed {seed}, release at {ratio} of the jet's speed, spacing {spacing} m");
    println!("slice  contact starts   rms |v| (m/s)  sum v² (m²/s²)  grain-steps in contact  first touches  loss (g/m)");
    while !run.finished() {
        let s = run.run_next_slice().map_err(|e| e.to_string())?;
        let (starts, sum_v2, steps, first) = s.grain_hits.map_or((0, 0.0, 0, 0), |h| {
            (
                h.count + h.returns,
                h.start_speed_sq_sum_m2_s2,
                h.steps_in_contact,
                h.count,
            )
        });
        // The mean speed of the starts is only known through Σ v² here: report its root.
        let rms = (sum_v2 / starts.max(1) as f64).sqrt();
        println!(
            "{:>5}  {:>14}  {:>14.0}  {:>14.3e}  {:>22}  {:>13}  {:>10.3}",
            s.slice,
            starts,
            rms,
            sum_v2,
            steps,
            first,
            s.sample.mass_loss_kg_m * 1e3
        );
    }
    Ok(())
}
