//! Dev aid: runs a few impacts of one sample and prints each outcome with its wall time.
use grit_erosion::{ImpactParams, Sample, Shape};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let angle: f64 = args.get(1).map_or(90.0, |s| s.parse().unwrap());
    let spacing: f64 = args.get(2).map_or(25e-6, |s| s.parse().unwrap());
    let n: u32 = args.get(3).map_or(3, |s| s.parse().unwrap());
    let mut p = ImpactParams::paper(angle, Shape::Hexagon);
    p.spacing_m = spacing;
    let mut s = Sample::new(p, 7).unwrap();
    println!("surface particles {}", s.surface().len());
    let mut cum = 0.0;
    for _ in 0..n {
        let t = Instant::now();
        let r = s.run_next().unwrap().clone();
        let sf = s.surface();
        let dmax = sf.damage.iter().cloned().fold(0.0, f64::max);
        let emax = sf.eps_p.iter().cloned().fold(0.0, f64::max);
        let n_half = sf.damage.iter().filter(|&&d| d > 0.5).count();
        print!("dmax {dmax:.3} epmax {emax:.3} n(D>.5) {n_half:3} ");
        cum += r.mass_loss_kg;
        println!(
            "impact {:3} loss {:.3e} cum/grain {:.3e} removed {:3} t {:.2e} s steps {:6} rebound {:.3} settled {} wall {:.2} s",
            r.impact,
            r.mass_loss_kg,
            cum / (r.grain_mass_kg * r.impact as f64),
            r.outcome.removed_particles,
            r.outcome.sim_time_s,
            r.outcome.steps,
            r.outcome.rebound_ratio,
            r.outcome.settled,
            t.elapsed().as_secs_f64()
        );
        for (name, sec) in s.last_timers().breakdown() {
            print!("{name} {sec:.2} ");
        }
        println!();
    }
}
