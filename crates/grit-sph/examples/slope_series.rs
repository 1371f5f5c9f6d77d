//! Prints the slope-slider speed series for one μ: `cargo run --release --example slope_series -- 40 0.4`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a[1].parse().unwrap();
    let mu: f64 = a[2].parse().unwrap();
    let s = grit_sph::verification::slope::simulate(
        mu,
        grit_sph::ContactModel::Extrapolated,
        n,
        std::env::var("SDT")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(0.05),
    )
    .unwrap();
    for (t, v) in s {
        let an = grit_sph::verification::slope::analytic_speed(mu, t);
        println!(
            "{t:.3} {v:.5} {an:.5} {:.4}",
            if an > 0.0 { (v - an) / an } else { v }
        );
    }
}
