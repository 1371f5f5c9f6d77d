//! Erosion models fitted to simulated erosion and compared with published ones: Oka's model
//! and the seed's shape-modified form ([`oka`]), the grain shapes and their shape factors
//! ([`shapes`]), the comparison tables ([`compare`]), and the full Oka model E(α, v, d) fitted
//! jointly to steady cells ([`fit`]) and written for CFD and DEM codes ([`export`]).

pub mod compare;
pub mod export;
pub mod fit;
pub mod oka;
pub mod shapes;

/// Deterministic noise in [−1, 1] from a fixed LCG seeded `seed`, so the fits' noisy tests
/// never flake.
#[cfg(test)]
pub(crate) fn test_noise(n: usize, seed: u64) -> Vec<f64> {
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15 ^ seed;
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
        .collect()
}
