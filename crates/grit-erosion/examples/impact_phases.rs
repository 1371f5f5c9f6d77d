//! Dev aid: where an impact's steps go on a worn surface. For each checkpoint, runs the next
//! impact as the campaign did (the record it prints is the stored one) and reports the steps
//! before the first contact (the flight left after the skip), in contact, and after the grain
//! last touched, with the mass removed and the damage added (failed particles counted at
//! D = 1) by each point; then the same impact with each settle fraction given, from the same
//! surface. Usage:
//! `impact_phases SETTLE[,SETTLE…] CHECKPOINT…` (settle fractions in (0, 1); `-` for none).
use grit_erosion::impact::{damage_stock, GRAIN_BODY, SURFACE_BODY};
use grit_erosion::{ImpactParams, Sample};
use grit_sph::World;
use std::time::Instant;

/// What the observer keeps: the first and last steps in contact, the contact episodes, and the
/// first step after the last contact with the grain moving up, with the mass removed and the
/// damage added by each.
#[derive(Default)]
struct Trace {
    first_touch: u64,
    damage_at_first_touch: f64,
    episodes: u32,
    touching_steps: u64,
    first_end: u64,
    removed_at_first_end: f64,
    last_touch: u64,
    first_away: Option<u64>,
    removed_at_touch: f64,
    damage_at_touch: f64,
    removed_at_away: f64,
    damage_at_away: f64,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: impact_phases SETTLE[,SETTLE…] CHECKPOINT…");
        std::process::exit(2);
    }
    let settles: Vec<f64> = args[1]
        .split(',')
        .filter(|s| *s != "-")
        .map(|s| s.parse().expect("settle fraction"))
        .collect();
    println!(
        "checkpoint\tsettle\tsteps\tfirst_touch\tepisodes\ttouching_steps\tfirst_end\tremoved_at_first_end\tlast_touch\tfirst_away\tloss_kg\tremoved_at_touch\tremoved_at_away\tdamage_added\tdamage_at_first_touch\tdamage_at_touch\tdamage_at_away\tsettled\twall_s"
    );
    for path in &args[2..] {
        let bytes = std::fs::read(path).expect("read checkpoint");
        let base = Sample::from_checkpoint(&bytes).expect("checkpoint");
        let default_settle = base.params().settle_fraction;
        for &settle in std::iter::once(&default_settle).chain(&settles) {
            let params = ImpactParams {
                settle_fraction: settle,
                ..base.params().clone()
            };
            let mut s = base.clone().with_params(params).expect("params");
            let mut tr = Trace::default();
            // The first observed step follows the skipped flight; steps count from there, as
            // the record's do.
            let mut start: Option<(u64, f64)> = None;
            let mut observe = |w: &World| {
                // Damage added as the record counts it: the surface's free particles (the grain
                // is rigid and carries none), and removed particles are failed ones (D = 1).
                let removed = w.bodies()[SURFACE_BODY].removed_mass_kg_m;
                let d = damage_stock(w.particles()) + removed;
                let (s0, d0) = *start.get_or_insert((w.steps() - 1, d));
                let touching = w.contact_forces().iter().any(|f| f.x != 0.0 || f.y != 0.0);
                let up = w.bodies()[GRAIN_BODY]
                    .rigid()
                    .is_some_and(|r| r.velocity_m_s.y > 0.0);
                if touching {
                    let step = w.steps() - s0;
                    if tr.episodes == 0 {
                        tr.first_touch = step;
                        tr.damage_at_first_touch = d - d0;
                    }
                    if tr.last_touch + 1 != step || tr.episodes == 0 {
                        tr.episodes += 1;
                    }
                    tr.touching_steps += 1;
                    if tr.episodes == 1 {
                        tr.first_end = step;
                        tr.removed_at_first_end = removed;
                    }
                    tr.last_touch = step;
                    tr.removed_at_touch = removed;
                    tr.damage_at_touch = d - d0;
                    tr.first_away = None;
                } else if up && tr.first_away.is_none() && tr.last_touch > 0 {
                    tr.first_away = Some(w.steps() - s0);
                    tr.removed_at_away = removed;
                    tr.damage_at_away = d - d0;
                }
            };
            let t = Instant::now();
            let r = s
                .run_next_observed(&|| false, Some(&mut observe))
                .expect("impact")
                .clone();
            let o = &r.outcome;
            println!(
                "{path}\t{settle}\t{}\t{}\t{}\t{}\t{}\t{:.6e}\t{}\t{}\t{:.6e}\t{:.6e}\t{:.6e}\t{:.6e}\t{:.6e}\t{:.6e}\t{:.6e}\t{}\t{:.2}",
                o.steps,
                tr.first_touch,
                tr.episodes,
                tr.touching_steps,
                tr.first_end,
                tr.removed_at_first_end,
                tr.last_touch,
                tr.first_away.map_or(-1, |s| s as i64),
                o.mass_loss_kg,
                tr.removed_at_touch,
                tr.removed_at_away,
                o.damage_added_kg.unwrap_or(f64::NAN),
                tr.damage_at_first_touch,
                tr.damage_at_touch,
                tr.damage_at_away,
                o.settled,
                t.elapsed().as_secs_f64()
            );
        }
    }
}
