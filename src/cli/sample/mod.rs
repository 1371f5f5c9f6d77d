//! `grit sample`: one sample of sequential random impacts run locally (Mohseni-Mofidi et al.
//! 2022, section 4); with it, `grit shapes` (the grain shapes) and `grit verify` (the engine's
//! verification cases).

mod scene;
pub mod shapes;
mod snapshots;
pub mod verify;

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use grit_erosion::impact::aggregate::{cumulative_series, sample_erosion};
use grit_erosion::impact::PeakTracker;
use grit_erosion::{ImpactParams, Sample, SLOPE_WINDOW};
use serde::Serialize;

pub use scene::SceneArgs;
use snapshots::Snapshots;

use super::output::{check_writable, say, ResultArgs};
use super::{pool, progress};

/// Arguments of `grit sample`.
#[derive(clap::Args)]
pub struct SampleArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Number of impacts on the fresh surface.
    #[arg(long, default_value_t = 60, value_parser = crate::cli::impact_count)]
    impacts: u32,
    /// Seed of the random aim points and orientations [default: 1].
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads of the engine (default: all cores).
    #[arg(long, value_parser = crate::cli::thread_count)]
    threads: Option<usize>,
    #[command(flatten)]
    result: ResultArgs,
    /// Go on from a checkpoint file (a job's saved surface, e.g. taken from the farm's
    /// database) with the parameters and seed stored in it; `--impacts` is then the total.
    #[arg(long)]
    resume: Option<PathBuf>,
    /// Write pictures of the surface (PNG, coloured by damage and by plastic strain, with the
    /// grain at its largest contact force) and ParaView files (VTU, PVD) after chosen impacts
    /// into this folder (docs/snapshots.md).
    #[arg(long, value_name = "DIR")]
    snapshots: Option<PathBuf>,
    /// Impacts to snapshot, 1-based and comma-separated [default: the first, every 10th and
    /// the last].
    #[arg(
        long,
        value_delimiter = ',',
        requires = "snapshots",
        value_name = "K,..."
    )]
    snapshot_at: Option<Vec<u32>>,
}

#[derive(Serialize)]
struct Point {
    impact: u32,
    grain_mass_cum: f64,
    mass_loss_cum: f64,
}

#[derive(Serialize)]
struct SampleOutput<'a> {
    params: &'a ImpactParams,
    seed: u64,
    series: Vec<Point>,
    /// Least-squares slope of the last 20 points (dimensionless); null with fewer than 20.
    erosion_last20: Option<f64>,
    impacts: &'a [grit_erosion::ImpactRecord],
    /// Why the sample stopped early, if it did; the series holds the impacts before it.
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
}

/// A checkpoint file (a job's saved surface) as the sample it holds; errors name the file.
pub fn read_checkpoint(path: &std::path::Path) -> anyhow::Result<Sample> {
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    Sample::from_checkpoint(&bytes).with_context(|| format!("{}", path.display()))
}

/// The sample a command starts from: the checkpoint `resume` names, with its own scene and seed
/// (scene flags or `--seed` beside it are refused), or a fresh one of the scene flags and `seed`
/// (default 1).
pub fn start_sample(
    resume: Option<&std::path::Path>,
    scene: &SceneArgs,
    seed: Option<u64>,
) -> anyhow::Result<Sample> {
    match resume {
        Some(path) => {
            let seed = seed.is_some().then_some("--seed");
            if let Some(flag) = scene.first_given().or(seed) {
                bail!("{flag}: --resume runs the scene and seed stored in the checkpoint; leave the scene flags out");
            }
            read_checkpoint(path)
        }
        None => Ok(Sample::new(scene.params()?, seed.unwrap_or(1))?),
    }
}

/// Runs one sample locally with a progress bar and prints its mass-loss series.
pub fn sample(a: SampleArgs) -> anyhow::Result<ExitCode> {
    if let Some(path) = &a.result.out {
        check_writable("--out", path)?;
    }
    let mut s = start_sample(a.resume.as_deref(), &a.scene, a.seed)?;
    let p = s.params().clone();
    let seed = s.seed();
    if s.impacts_done() >= a.impacts {
        bail!(
            "impacts: the checkpoint already holds {} impacts; ask for more than that",
            s.impacts_done()
        );
    }
    let mut snapshots = match &a.snapshots {
        Some(dir) => Some(Snapshots::new(
            dir,
            a.snapshot_at.as_deref(),
            s.impacts_done(),
            a.impacts,
        )?),
        None => None,
    };
    let pool = pool(a.threads)?;
    let bar = progress::bar(a.impacts as u64, "impacts", true);
    bar.set_position(s.impacts_done() as u64);
    let t0 = Instant::now();
    let mut failure = None;
    for _ in s.impacts_done()..a.impacts {
        let k = s.impacts_done() + 1;
        // Only a snapshot impact is watched, so the others run exactly as without --snapshots.
        let mut tracker = match &snapshots {
            Some(snap) if snap.wants(k) => Some(PeakTracker::new(&s.next_grain()?)),
            _ => None,
        };
        let ran = grit_sph::polling::install_polling(&pool, || match tracker.as_mut() {
            Some(t) => s
                .run_next_observed(&|| false, Some(&mut |w| t.observe(w)))
                .map(|_| ()),
            None => s.run_next().map(|_| ()),
        });
        if let Err(e) = ran {
            // Keep what the finished impacts found: they are written below, then the error.
            failure = Some(e);
            break;
        }
        if let (Some(snap), Some(t)) = (snapshots.as_mut(), tracker) {
            snap.write(&s, t.peak())?;
        }
        bar.inc(1);
        bar.set_message(format!(
            "eta {}, loss so far {:.3e} kg/m",
            indicatif::HumanDuration(bar.eta()),
            s.records().iter().map(|r| r.mass_loss_kg).sum::<f64>()
        ));
    }
    bar.finish();
    let impacts: Vec<_> = s.records().iter().map(|r| r.impact()).collect();
    let error = failure.as_ref().map(|e| e.to_string());
    let cum = cumulative_series(&impacts);
    let out = SampleOutput {
        params: &p,
        seed,
        series: cum
            .iter()
            .zip(s.records())
            .map(|(c, r)| Point {
                impact: r.impact,
                grain_mass_cum: c.grain_mass_kg,
                mass_loss_cum: c.mass_loss_kg,
            })
            .collect(),
        erosion_last20: sample_erosion(&cum, SLOPE_WINDOW),
        impacts: s.records(),
        error,
    };
    a.result.write(&out)?;
    if a.result.json {
        #[derive(Serialize)]
        struct Short<'a> {
            series: &'a [Point],
            erosion_last20: Option<f64>,
        }
        let short = Short {
            series: &out.series,
            erosion_last20: out.erosion_last20,
        };
        say!("{}", serde_json::to_string(&short)?);
    } else {
        say!("impact  grain_mass_cum  mass_loss_cum  removed  steps  rebound");
        for (pt, r) in out.series.iter().zip(s.records()) {
            say!(
                "{:>6}  {:>14.4e}  {:>13.4e}  {:>7}  {:>5}  {:>7.3}",
                pt.impact,
                pt.grain_mass_cum,
                pt.mass_loss_cum,
                r.outcome.removed_particles,
                r.outcome.steps,
                r.outcome.rebound_ratio
            );
        }
        match out.erosion_last20 {
            Some(e) => say!("erosion (slope of the last {SLOPE_WINDOW} points): {e:.4e}"),
            None => say!("erosion: needs at least {SLOPE_WINDOW} impacts"),
        }
        say!("wall time {:.1} s", t0.elapsed().as_secs_f64());
        if let Some(snap) = &snapshots {
            say!(
                "snapshots of {} impacts in {} (surface.pvd and grain.pvd open in ParaView)",
                snap.written.len(),
                snap.dir.display()
            );
        }
    }
    if let Some(e) = failure {
        return Err(anyhow::Error::from(e).context(format!(
            "sample stopped after {} finished impacts",
            s.impacts_done()
        )));
    }
    Ok(ExitCode::SUCCESS)
}
