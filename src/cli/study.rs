//! `grit study`: checks of the impact scene's own choices.

use std::process::ExitCode;

use anyhow::bail;
use grit_erosion::studies::settle::{settle_study, SettleRow};
use grit_sph::coupling::DEFAULT_SWITCH_POROSITY;
use grit_sph::verification::jet_grain::{self, GrainRide, RcScene, BEFORE_CONTACT_D, GRAIN_D};

use super::output::{check_writable, say};
use super::sample::{read_checkpoint, start_sample, SceneArgs};
use super::{pool, progress};

/// Arguments of `grit study`.
#[derive(clap::Args)]
pub struct StudyArgs {
    #[command(subcommand)]
    study: Study,
}

#[derive(clap::Subcommand)]
enum Study {
    /// The AWJ paper's coupling-radius study: one grain rides a settled jet onto a rigid wall,
    /// unresolved at each coupling radius and, with --resolved, fully resolved; prints each
    /// grain's speed at contact (docs/jet.md#one-grain-in-the-jet).
    #[command(
        after_help = "Example: grit study rc --across 32 --jet-speed-m-s 500 --release-ratio 1 --resolved"
    )]
    Rc {
        /// Water particles across the 1 mm jet (even; at 500 m/s a resolved grain runs from 32
        /// across, and from 48 across the jet needs --cfl 0.1: docs/jet.md#one-grain-in-the-jet).
        #[arg(long, default_value_t = 16)]
        across: usize,
        /// The jet's speed (m/s).
        #[arg(long, default_value_t = 500.0, allow_negative_numbers = true)]
        jet_speed_m_s: f64,
        /// The grain's speed at release over the jet's (0: at rest).
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        release_ratio: f64,
        /// The porosity at and below which the unresolved drag is Ergun's, above it Wen–Yu's
        /// (the paper's 0.8; eq. 44).
        #[arg(long, default_value_t = DEFAULT_SWITCH_POROSITY, allow_negative_numbers = true)]
        switch_porosity: f64,
        /// Courant number of the steps (the paper's 0.2; a 500 m/s jet 48 or more across fails
        /// at it while settling and runs at 0.1).
        #[arg(long, default_value_t = RcScene::DEFAULT_CFL, allow_negative_numbers = true)]
        cfl: f64,
        /// When the first grain leaves the nozzle, in transit times b/v from the jet's start (its
        /// head reaches the wall at 2; the default is once the jet has settled).
        #[arg(long, default_value_t = RcScene::DEFAULT_RELEASE_AT, allow_negative_numbers = true)]
        release_at_b_over_v: f64,
        /// Grains released per ride, one transit time b/v apart into the same settled jet; a
        /// ride's contact speed is then their mean (one landing scatters by 3–5 %).
        #[arg(long, default_value_t = 1)]
        releases: usize,
        /// Coupling radii R_c/d of the unresolved grains, comma-separated.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "1,1.5,2,2.5,3",
            allow_negative_numbers = true
        )]
        rc: Vec<f64>,
        /// Also ride a fully resolved grain (an elastic garnet disc of the water's spacing).
        #[arg(long)]
        resolved: bool,
        /// Write the grains' speed against time as an SVG chart here.
        #[arg(long)]
        chart: Option<std::path::PathBuf>,
        /// Worker threads of the engine (default: all cores).
        #[arg(long, value_parser = crate::cli::thread_count)]
        threads: Option<usize>,
        /// Print {scene, rides: [{label, contact_speed_m_s (the mean over releases),
        /// contact_speeds_m_s, contact_speed_std_m_s, speed_before_contact (the first release):
        /// [{distance_d, speed_m_s}]}]} as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Where erosion comes from, angle by angle: from worn surfaces (farm checkpoints), the
    /// plastic strain each impact adds, the damage it adds (eq. 19: Δε_p/ε_f, the steady-state
    /// mass loss it pays for) and the triaxiality it strains under (docs/erosion.md).
    #[command(
        after_help = "Example: grit study budget job-*.ckpt --impacts 3 --patch '{\"material\":{\"damage\":{\"d3\":0}}}'"
    )]
    Budget {
        /// Checkpoint files (a job's saved surface, as `grit sample --resume` takes them);
        /// without them, fresh samples of the scene flags, one per `--seeds`.
        checkpoints: Vec<std::path::PathBuf>,
        #[command(flatten)]
        scene: SceneArgs,
        /// Seeds of the fresh samples (without checkpoints), comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "1")]
        seeds: Vec<u64>,
        /// Impacts to run from each checkpoint or fresh surface.
        #[arg(long, default_value_t = 3, value_parser = crate::cli::impact_count)]
        impacts: u32,
        /// A JSON merge patch (RFC 7396) applied to every checkpoint's scene, e.g. a failure
        /// constant or the friction; the lattice (spacing, box, grain size) cannot change.
        #[arg(long)]
        patch: Option<String>,
        /// Worker threads (default: all cores); checkpoints run side by side.
        #[arg(long, value_parser = crate::cli::thread_count)]
        threads: Option<usize>,
        /// Print {rows, by_angle} as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Runs a sample and each of its impacts again, from the same surface, with another end
    /// criterion: a stricter one shows whether mass loss and damage depend on when an impact
    /// ends, a looser one what it would save and change (docs/erosion.md).
    #[command(
        after_help = "Example: grit study settle --angle 45 --impacts 20 --other-fraction 0.002\n         grit study settle --resume job.ckpt --impacts 20 --other-fraction 0.1"
    )]
    Settle {
        #[command(flatten)]
        scene: SceneArgs,
        /// Start from this checkpoint (a job's worn surface, as `grit sample --resume` takes it)
        /// with its own scene and seed, instead of a fresh surface.
        #[arg(long)]
        resume: Option<std::path::PathBuf>,
        /// Number of impacts to run (from the checkpoint, with --resume).
        #[arg(long, default_value_t = 20, value_parser = crate::cli::impact_count)]
        impacts: u32,
        /// Seed of the fresh sample.
        #[arg(long)]
        seed: Option<u64>,
        /// The other settle fraction each impact is run again with: below the scene's for a
        /// stricter end, above it for a looser one.
        #[arg(long, default_value_t = 0.002, allow_negative_numbers = true)]
        other_fraction: f64,
        /// Worker threads of the engine (default: all cores).
        #[arg(long, value_parser = crate::cli::thread_count)]
        threads: Option<usize>,
        /// Print the rows as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// Runs one of the checks of the scene's own choices.
pub fn study(a: StudyArgs) -> anyhow::Result<ExitCode> {
    match a.study {
        Study::Rc {
            across,
            jet_speed_m_s,
            release_ratio,
            switch_porosity,
            cfl,
            release_at_b_over_v,
            releases,
            rc,
            resolved,
            chart,
            threads,
            json,
        } => {
            let scene = RcScene {
                switch_porosity,
                cfl,
                release_at_b_over_v,
                ..RcScene::new(across, jet_speed_m_s, release_ratio)
            };
            check_rc_scene(&scene, &rc, releases)?;
            if let Some(path) = &chart {
                check_writable("--chart", path)?;
            }
            let series = pool(threads)?.install(|| -> anyhow::Result<Vec<Vec<GrainRide>>> {
                eprintln!(
                    "settling the jet and riding {} grain(s) ...",
                    releases * (rc.len() + usize::from(resolved))
                );
                Ok(jet_grain::release_series(&scene, &rc, resolved, releases)?)
            })?;
            let rides = &series[0];
            // Per ride: the mean and standard deviation of its releases' contact speeds.
            let stats: Vec<(Vec<f64>, f64, f64)> = (0..rides.len())
                .map(|k| jet_grain::contact_speeds(&series, k))
                .collect();
            if let Some(path) = &chart {
                super::plot::line_chart(&jet_grain::rides_chart(&scene, rides), path)?;
                eprintln!("wrote {}", path.display());
            }
            if json {
                let rides: Vec<_> = rides
                    .iter()
                    .zip(&stats)
                    .map(|(r, (speeds, mean, std))| {
                        let before: Vec<_> = BEFORE_CONTACT_D
                            .iter()
                            .map(|&d| {
                                serde_json::json!({
                                    "distance_d": d,
                                    "speed_m_s": r.speed_before_contact(d * GRAIN_D),
                                })
                            })
                            .collect();
                        serde_json::json!({
                            "label": r.label,
                            "contact_speed_m_s": mean,
                            "contact_speeds_m_s": speeds,
                            "contact_speed_std_m_s": std,
                            "speed_before_contact": before,
                        })
                    })
                    .collect();
                let scene = serde_json::json!({
                    "across": across,
                    "jet_speed_m_s": jet_speed_m_s,
                    "release_ratio": release_ratio,
                    "switch_porosity": switch_porosity,
                    "cfl": cfl,
                    "release_at_b_over_v": release_at_b_over_v,
                    "releases": releases,
                });
                say!(
                    "{}",
                    serde_json::to_string_pretty(
                        &serde_json::json!({"scene": scene, "rides": rides})
                    )?
                );
                return Ok(ExitCode::SUCCESS);
            }
            say!("jet {jet_speed_m_s} m/s, b/dx {across}, CFL {cfl}, grain released at {release_ratio} x the jet's speed, first at {release_at_b_over_v} b/v, {releases} release(s) 1 b/v apart");
            let heads: String = BEFORE_CONTACT_D
                .iter()
                .map(|d| format!(" {:>8}", format!("{d} d")))
                .collect();
            say!(
                "{:<14} {:>18}   speed (m/s) this far from contact (first release):",
                "grain",
                "contact speed m/s"
            );
            say!("{:<14} {:>18}  {heads}", "", "");
            for (r, (each, mean, std)) in rides.iter().zip(&stats) {
                let speeds: String = BEFORE_CONTACT_D
                    .iter()
                    .map(|&d| match r.speed_before_contact(d * GRAIN_D) {
                        Some(v) => format!(" {v:>8.1}"),
                        None => format!(" {:>8}", "-"),
                    })
                    .collect();
                let contact = if releases > 1 {
                    format!("{mean:.1} ± {std:.1}")
                } else {
                    format!("{mean:.1}")
                };
                say!("{:<14} {contact:>18}  {speeds}", r.label);
                if releases > 1 {
                    let each: Vec<String> = each.iter().map(|v| format!("{v:.1}")).collect();
                    say!("{:<14} releases: {}", "", each.join(", "));
                }
            }
            say!("the paper: 166 m/s unresolved at R_c = 2.0 d, 162 m/s resolved");
            Ok(ExitCode::SUCCESS)
        }
        Study::Budget {
            checkpoints,
            scene,
            seeds,
            impacts,
            patch,
            threads,
            json,
        } => {
            let start = if checkpoints.is_empty() {
                Start::Fresh(Box::new(scene.params()?), seeds)
            } else if let Some(flag) = scene.first_given() {
                bail!("{flag}: a checkpoint carries its own scene; give checkpoints or scene flags, not both")
            } else {
                Start::Checkpoints(checkpoints)
            };
            budget(start, impacts, patch.as_deref(), threads, json)
        }
        Study::Settle {
            scene,
            resume,
            impacts,
            seed,
            other_fraction,
            threads,
            json,
        } => {
            let s = start_sample(resume.as_deref(), &scene, seed)?;
            let own = s.params().settle_fraction;
            if !(other_fraction > 0.0 && other_fraction < 1.0 && other_fraction != own) {
                bail!(
                    "--other-fraction: must be > 0, below 1 and not the scene's settle_fraction {own}, got {other_fraction}"
                );
            }
            let start = s.impacts_done();
            let bar = progress::bar(impacts as u64, "impacts", true);
            let rows = pool(threads)?
                .install(|| settle_study(s, impacts, other_fraction, |_| bar.inc(1)))?;
            bar.finish();
            if json {
                say!("{}", serde_json::to_string_pretty(&rows)?);
                return Ok(ExitCode::SUCCESS);
            }
            say!("settle_fraction {own} against {other_fraction}, from impact {start}");
            say!("impact  loss_kg_m   loss_other   dD        dD_other   t_s        t_other_s  steps  steps_other");
            for r in &rows {
                say!(
                    "{:>6}  {:>10.3e}  {:>10.3e}  {:>8.4}  {:>8.4}  {:>9.3e}  {:>9.3e}  {:>5}  {:>11}",
                    r.impact,
                    r.mass_loss_kg,
                    r.mass_loss_other_kg,
                    r.damage_added,
                    r.damage_added_other,
                    r.sim_time_s,
                    r.sim_time_other_s,
                    r.steps,
                    r.steps_other
                );
            }
            let sum = |f: fn(&SettleRow) -> f64| -> f64 { rows.iter().map(f).sum() };
            let (d, ds) = (sum(|r| r.damage_added), sum(|r| r.damage_added_other));
            let (m, ms) = (sum(|r| r.mass_loss_kg), sum(|r| r.mass_loss_other_kg));
            let (n, ns) = (sum(|r| r.steps as f64), sum(|r| r.steps_other as f64));
            say!(
                "total damage added {d:.4} vs {ds:.4} ({:+.2}%), mass loss {m:.3e} vs {ms:.3e} kg/m, steps {n} vs {ns} ({:.2}x)",
                100.0 * (ds - d) / d.max(f64::MIN_POSITIVE),
                ns / n.max(1.0)
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// Where the budget's samples start.
enum Start {
    /// Worn surfaces saved by the farm.
    Checkpoints(Vec<std::path::PathBuf>),
    /// Fresh surfaces of one scene, one per seed.
    Fresh(Box<grit_erosion::impact::ImpactParams>, Vec<u64>),
}

/// `grit study budget`: every sample, patched, run `impacts` more impacts with the budget
/// observer; rows and the table by angle.
fn budget(
    start: Start,
    impacts: u32,
    patch: Option<&str>,
    threads: Option<usize>,
    json: bool,
) -> anyhow::Result<ExitCode> {
    use grit_erosion::studies::budget::{budget, by_angle, BudgetRow};
    use rayon::prelude::*;
    let patch: Option<serde_json::Value> = patch
        .map(serde_json::from_str)
        .transpose()
        .map_err(|e| anyhow::anyhow!("--patch: not JSON: {e}"))?;
    if patch.as_ref().is_some_and(|p| !p.is_object()) {
        bail!("--patch: must be a JSON object of scene fields");
    }
    let opened: Vec<(String, grit_erosion::Sample)> = match start {
        Start::Checkpoints(files) => files
            .iter()
            .map(|f| Ok((f.display().to_string(), read_checkpoint(f)?)))
            .collect::<anyhow::Result<_>>()?,
        Start::Fresh(params, seeds) => seeds
            .into_iter()
            .map(|seed| {
                let s = grit_erosion::Sample::new((*params).clone(), seed)?;
                Ok((format!("seed {seed}"), s))
            })
            .collect::<anyhow::Result<_>>()?,
    };
    let mut samples = Vec::new();
    for (f, s) in opened {
        let s = match &patch {
            None => s,
            Some(p) => {
                let mut v = serde_json::to_value(s.params())?;
                json_patch::merge(&mut v, p);
                let params = serde_json::from_value(v).map_err(|e| {
                    anyhow::anyhow!("--patch: the patched scene does not read: {e}")
                })?;
                s.with_params(params)
                    .map_err(|e| anyhow::anyhow!("--patch: {e}"))?
            }
        };
        samples.push((f, s));
    }
    let bar = progress::bar((samples.len() as u64) * impacts as u64, "impacts", true);
    let runs: Vec<anyhow::Result<Vec<BudgetRow>>> = pool(threads)?.install(|| {
        samples
            .par_iter_mut()
            .map(|(f, s)| {
                budget(s, impacts, |_| bar.inc(1)).map_err(|e| anyhow::anyhow!("{f}: {e}"))
            })
            .collect()
    });
    bar.finish();
    let rows: Vec<BudgetRow> = runs
        .into_iter()
        .collect::<anyhow::Result<Vec<_>>>()?
        .concat();
    let table = by_angle(&rows);
    if json {
        say!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({"rows": rows, "by_angle": table}))?
        );
        return Ok(ExitCode::SUCCESS);
    }
    say!("per impact, per grain mass (mg/g), mean ± standard error; dD/de = damage per plastic strain (mean 1/ε_f)");
    say!("angle impacts  mass loss      Σm·Δε_p        Σm·ΔD         dD/de  mean σ*  ΔD share by σ*: <-1/3  <0    <1/3  ≥1/3   removed with D0 <1/4  <1/2  <3/4  ≥3/4");
    let pm = |s: &grit_erosion::stats::Stats| {
        format!("{:>6.2} ± {:<5.2}", s.mean, s.sem.unwrap_or(f64::NAN))
    };
    for a in &table {
        let (sh, cut) = (
            a.damage_share_by_triaxiality,
            a.removed_share_by_start_damage,
        );
        say!(
            "{:>5} {:>7}  {}  {}  {}  {:>5.3}  {:>6.3}  {:>20.2} {:>5.2} {:>5.2} {:>5.2}  {:>20.2} {:>5.2} {:>5.2} {:>5.2}",
            a.angle_deg,
            a.impacts,
            pm(&a.mass_loss),
            pm(&a.plastic),
            pm(&a.damage),
            a.damage_per_strain,
            a.mean_triaxiality,
            sh[0],
            sh[1],
            sh[2],
            sh[3],
            cut[0],
            cut[1],
            cut[2],
            cut[3]
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Refuses a coupling-radius scene the study cannot run, naming the flag and the rule.
fn check_rc_scene(scene: &RcScene, rc: &[f64], releases: usize) -> anyhow::Result<()> {
    // The finest row documented runs 64 across (34 minutes); 128 is hours per ride.
    if scene.across < 2 || !scene.across.is_multiple_of(2) || scene.across > 128 {
        bail!(
            "--across: must be an even number from 2 to 128, got {}",
            scene.across
        );
    }
    let fastest = grit_erosion::jet::MAX_JET_SPEED_M_S;
    if !(scene.jet_speed_m_s.is_finite()
        && scene.jet_speed_m_s > 0.0
        && scene.jet_speed_m_s <= fastest)
    {
        bail!(
            "--jet-speed-m-s: must be > 0 and at most {fastest} m/s, got {}",
            grit_sph::InputError::shown(scene.jet_speed_m_s)
        );
    }
    if !(scene.release_ratio.is_finite() && (0.0..=2.0).contains(&scene.release_ratio)) {
        bail!(
            "--release-ratio: must lie in [0, 2], got {}",
            scene.release_ratio
        );
    }
    if !(scene.switch_porosity > 0.0 && scene.switch_porosity < 1.0) {
        bail!(
            "--switch-porosity: must lie in (0, 1), got {}",
            scene.switch_porosity
        );
    }
    if !(scene.cfl > 0.0 && scene.cfl <= 1.0) {
        bail!("--cfl: must lie in (0, 1], got {}", scene.cfl);
    }
    if !(scene.release_at_b_over_v.is_finite()
        && (0.0..=100.0).contains(&scene.release_at_b_over_v))
    {
        bail!(
            "--release-at-b-over-v: must lie in [0, 100], got {}",
            scene.release_at_b_over_v
        );
    }
    if !(1..=20).contains(&releases) {
        bail!("--releases: must lie in 1..=20, got {releases}");
    }
    // The bounds of a jet scene's coupling_radius_d; the paper's study spans 1 to 3 d.
    if let Some(f) = rc.iter().find(|f| !(0.5..=10.0).contains(*f)) {
        bail!(
            "--rc: every coupling radius must lie in [0.5, 10] grain diameters, got {}",
            grit_sph::InputError::shown(*f)
        );
    }
    Ok(())
}
