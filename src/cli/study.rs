//! `grit study`: checks of the impact scene's own choices.

use std::process::ExitCode;

use grit_erosion::studies::settle::{settle_study, SettleRow};

use super::output::say;
use super::sample::SceneArgs;
use super::{pool, progress};

/// Arguments of `grit study`.
#[derive(clap::Args)]
pub struct StudyArgs {
    #[command(subcommand)]
    study: Study,
}

#[derive(clap::Subcommand)]
enum Study {
    /// Runs a sample and each of its impacts again, from the same surface, with a stricter end
    /// criterion: mass loss and damage must not depend on when an impact ends.
    #[command(
        after_help = "Example: grit study settle --angle 45 --impacts 20 --strict-fraction 0.002"
    )]
    Settle {
        #[command(flatten)]
        scene: SceneArgs,
        /// Number of impacts.
        #[arg(long, default_value_t = 20)]
        impacts: u32,
        /// Seed of the sample.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// The stricter settle fraction.
        #[arg(long, default_value_t = 0.002)]
        strict_fraction: f64,
        /// Worker threads of the engine (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Print the rows as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// Runs one of the checks of the scene's own choices.
pub fn study(a: StudyArgs) -> anyhow::Result<ExitCode> {
    match a.study {
        Study::Settle {
            scene,
            impacts,
            seed,
            strict_fraction,
            threads,
            json,
        } => {
            let p = scene.params()?;
            let bar = progress::bar(impacts as u64, "impacts", true);
            let rows = pool(threads)?
                .install(|| settle_study(&p, seed, impacts, strict_fraction, |_| bar.inc(1)))?;
            bar.finish();
            if json {
                say!("{}", serde_json::to_string_pretty(&rows)?);
                return Ok(ExitCode::SUCCESS);
            }
            say!(
                "settle_fraction {} against {strict_fraction}",
                p.settle_fraction
            );
            say!("impact  loss_kg_m   loss_strict  dD        dD_strict  t_s        t_strict_s");
            for r in &rows {
                say!(
                    "{:>6}  {:>10.3e}  {:>10.3e}  {:>8.4}  {:>8.4}  {:>9.3e}  {:>9.3e}",
                    r.impact,
                    r.mass_loss_kg,
                    r.mass_loss_strict_kg,
                    r.damage_added,
                    r.damage_added_strict,
                    r.sim_time_s,
                    r.sim_time_strict_s
                );
            }
            let sum = |f: fn(&SettleRow) -> f64| -> f64 { rows.iter().map(f).sum() };
            let (d, ds) = (sum(|r| r.damage_added), sum(|r| r.damage_added_strict));
            let (m, ms) = (sum(|r| r.mass_loss_kg), sum(|r| r.mass_loss_strict_kg));
            say!(
                "total damage added {d:.4} vs {ds:.4} ({:+.2}%), mass loss {m:.3e} vs {ms:.3e} kg/m",
                100.0 * (ds - d) / d.max(f64::MIN_POSITIVE)
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}
