//! Elastic impact energy with filter/hourglass switched: `cargo run --release --example impact2 -- 30 40 0.1`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a[1].parse().unwrap();
    let s = grit_sph::Settings {
        shepard_interval: a[2].parse().unwrap(),
        hourglass: a[3].parse().unwrap(),
        ..Default::default()
    };
    let t_end: Option<f64> = a.get(4).map(|x| x.parse().unwrap());
    let h = match grit_sph::verification::elastic_impact::simulate_until(n, s, t_end) {
        Ok(h) => h,
        Err(e) => {
            println!("{e}");
            return;
        }
    };
    let lc = h.in_contact.iter().rposition(|&c| c).unwrap_or(0);
    println!(
        "peak {:.4} after {:.4} at contact end {:.4} hg {:.3e} filt {:.3e} steps {}",
        h.energy.iter().cloned().fold(0.0, f64::max),
        h.energy.last().unwrap(),
        h.energy[lc],
        h.work.hourglass,
        h.work.density_filter,
        h.t.len() * 10
    );
}
