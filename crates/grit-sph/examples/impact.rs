//! Prints the elastic-impact checks: `cargo run --release --example impact -- 40`.
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(40);
    let t0 = std::time::Instant::now();
    match grit_sph::verification::elastic_impact::run(n) {
        Ok(r) => {
            for row in r.rows {
                println!(
                    "{} {:.6e} pass={} {}",
                    row.case, row.value, row.pass, row.note
                );
            }
        }
        Err(e) => println!("failed: {e}"),
    }
    println!("{:.1} s", t0.elapsed().as_secs_f64());
}
