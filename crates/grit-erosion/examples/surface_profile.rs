//! Dev aid: the shape of a worn surface. For each checkpoint, the free surface's top in columns
//! one Δx wide across the box: the highest point (the crater's lips or the unworn shoulders),
//! the lowest column top inside the band of aim points (the crater's floor), and the mean
//! recession of the column tops over that band, all in Dg below the fresh surface (y = 0).
//! The grain's flight is skipped only to one kernel reach below the highest point, so the
//! floor's depth below the lips is what a worn surface's impact flies through step by step
//! (docs/performance.md, *The flight over a crater*). Usage: `surface_profile CHECKPOINT…`.
use grit_erosion::Sample;
use grit_sph::particles::KINEMATIC;

fn main() {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        eprintln!("usage: surface_profile CHECKPOINT…");
        std::process::exit(2);
    }
    println!("checkpoint\timpacts\tlips_dg\tfloor_dg\tband_recession_dg\tfloor_below_lips_dg");
    for path in &paths {
        let bytes = std::fs::read(path).expect("read checkpoint");
        let s = Sample::from_checkpoint(&bytes).expect("checkpoint");
        let p = s.params();
        let (dg, dx) = (p.grain_diameter_m, p.spacing_m);
        let half = 0.5 * p.surface_width_dg * dg;
        let columns = (2.0 * half / dx).ceil() as usize;
        let mut top = vec![f64::NEG_INFINITY; columns];
        let surface = s.surface();
        for (x, flags) in surface.pos.iter().zip(&surface.flags) {
            if flags & KINEMATIC != 0 {
                continue;
            }
            let c = (((x.x + half) / dx).floor().max(0.0) as usize).min(columns - 1);
            top[c] = top[c].max(x.y);
        }
        let lips = top.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // The aim band's columns: centres within half the distribution range of the middle.
        let reach = 0.5 * p.distribution_range_dg * dg;
        let band: Vec<f64> = top
            .iter()
            .enumerate()
            .filter(|(c, t)| ((*c as f64 + 0.5) * dx - half).abs() <= reach && t.is_finite())
            .map(|(_, t)| *t)
            .collect();
        let floor = band.iter().copied().fold(f64::INFINITY, f64::min);
        let mean = band.iter().sum::<f64>() / band.len() as f64;
        println!(
            "{path}\t{}\t{:.3}\t{:.3}\t{:.3}\t{:.3}",
            s.impacts_done(),
            lips / dg,
            floor / dg,
            -mean / dg,
            (lips - floor) / dg
        );
    }
}
