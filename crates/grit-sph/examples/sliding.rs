//! Prints controlled-sliding errors: `cargo run --release --example sliding -- 20`.
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(20);
    let s = grit_sph::verification::sliding::simulate(n, 0.001)
        .unwrap()
        .0;
    println!("{:?}", grit_sph::verification::sliding::errors(&s));
    for (t, v) in s.iter().step_by(100) {
        println!(
            "{t:.3} {v:.5} {:.5}",
            grit_sph::verification::sliding::analytic_speed(*t)
        );
    }
}
