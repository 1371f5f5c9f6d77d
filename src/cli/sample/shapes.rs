//! `grit shapes`: the built-in grain shapes with their shape factors (Mohseni-Mofidi et al.
//! 2022, Table 2).

use std::process::ExitCode;

use anyhow::Context;
use grit_erosion::Shape;

use crate::cli::output::say;

/// Arguments of `grit shapes`.
#[derive(clap::Args)]
pub struct ShapesArgs {
    /// Print a JSON array of {name, angularity, aspect_ratio, area_m2}.
    #[arg(long)]
    json: bool,
    /// Grain diameter Dg the areas refer to (m).
    #[arg(long, default_value_t = 250e-6, allow_negative_numbers = true)]
    diameter_m: f64,
}

/// Prints the built-in shapes with their angularity and aspect ratio (Mohseni-Mofidi et al. 2022, Table 2).
pub fn shapes(a: ShapesArgs) -> anyhow::Result<ExitCode> {
    // Grains from a micrometre to a metre: any more and the areas overflow.
    if !(a.diameter_m.is_finite() && (1e-6..=1.0).contains(&a.diameter_m)) {
        anyhow::bail!(
            "--diameter-m: must lie in [1e-6, 1] m, got {}",
            grit_sph::InputError::shown(a.diameter_m)
        );
    }
    let infos = Shape::builtins()
        .iter()
        .map(|s| s.info(a.diameter_m))
        .collect::<Result<Vec<_>, _>>()
        .context("diameter_m")?;
    if a.json {
        say!("{}", serde_json::to_string_pretty(&infos)?);
    } else {
        say!(
            "{:<10} {:>10} {:>12} {:>12}",
            "shape",
            "angularity",
            "aspect_ratio",
            "area_m2"
        );
        for i in &infos {
            say!(
                "{:<10} {:>10.3} {:>12.3} {:>12.4e}",
                i.name,
                i.angularity,
                i.aspect_ratio,
                i.area_m2
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
