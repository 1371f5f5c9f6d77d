//! Erosion models fitted to simulated erosion and compared with published ones: Oka's model
//! and the seed's shape-modified form ([`oka`]), the grain shapes and their shape factors
//! ([`shapes`]), the comparison tables ([`compare`]), and the full Oka model E(α, v, d) fitted
//! jointly to steady cells ([`fit`]) and written for CFD and DEM codes ([`export`]).

pub mod compare;
pub mod export;
pub mod fit;
pub mod oka;
pub mod shapes;

/// Deterministic noise in [−1, 1] from an LCG seeded `seed`, so the fits' noisy tests
/// never flake.
#[cfg(test)]
pub(crate) fn test_noise(n: usize, seed: u64) -> Vec<f64> {
    let mut lcg = grit_sph::lcg::Lcg(0x9e37_79b9_7f4a_7c15 ^ seed);
    (0..n).map(|_| lcg.next_unit() * 2.0 - 1.0).collect()
}
