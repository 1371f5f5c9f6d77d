//! Prints the slope-slider error for a resolution: `cargo run --release --example slope -- 40`.
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(10);
    for mu in [0.0, 0.2, 0.4, 0.7] {
        for model in [
            grit_sph::ContactModel::Extrapolated,
            grit_sph::ContactModel::Penetration,
        ] {
            let t0 = std::time::Instant::now();
            match grit_sph::verification::slope::simulate(mu, model, n, 0.1) {
                Ok(s) => {
                    let e = grit_sph::verification::slope::worst_error(mu, &s);
                    println!(
                        "mu={mu} {model:?} err={e:.4} last={:?} ({:.2}s)",
                        s.last(),
                        t0.elapsed().as_secs_f64()
                    );
                }
                Err(e) => println!("mu={mu} {model:?} failed: {e}"),
            }
        }
    }
}
