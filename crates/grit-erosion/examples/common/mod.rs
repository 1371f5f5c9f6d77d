//! What the jet examples share: their positional arguments and the default scene cut to the
//! 0.2 ms they study (docs/jet.md#results).

use grit_erosion::jet::{JetParams, JetRun};

/// Argument `k` (`name`), or `default` when it is not given.
pub fn arg<T: std::str::FromStr>(k: usize, name: &str, default: T) -> Result<T, String> {
    std::env::args().nth(k).map_or(Ok(default), |s| {
        s.parse()
            .map_err(|_| format!("{name}: not a number: {s:?}"))
    })
}

/// The default jet scene (copper, 500 m/s, 0.02 kg/s; docs/jet.md#the-scene) for 0.2 ms in
/// slices of 50 µs at spacing `spacing_m`, its grains released at `ratio` of the jet's speed.
pub fn short_run(seed: u64, ratio: f64, spacing_m: f64) -> Result<JetRun, String> {
    let params = JetParams {
        time_ms: 0.2,
        slice_ms: 0.05,
        grain_speed_ratio: ratio,
        spacing_m,
        ..JetParams::default()
    };
    params.validate().map_err(|e| e.to_string())?;
    JetRun::new(params, seed).map_err(|e| e.to_string())
}
