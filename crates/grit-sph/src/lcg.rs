//! A small deterministic generator for tests and synthetic data: scattered values that are the
//! same on every machine and every run, so a test that reads them never flakes. The engine's
//! own randomness (aim points, orientations) comes from its callers' seeded generators instead.

/// Knuth's MMIX linear congruential generator, its state the last value drawn.
#[derive(Debug, Clone)]
pub struct Lcg(pub u64);

impl Lcg {
    /// The next value, uniform in [0, 1) (the top 53 bits of the state).
    pub fn next_unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}
