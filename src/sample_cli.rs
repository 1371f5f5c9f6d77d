//! `grit shapes` and `grit sample`: the grain shape factors (seed Table 2) and one sample of
//! sequential random impacts run locally (seed section 4).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use grit_erosion::aggregate::{cumulative_series, sample_erosion};
use grit_erosion::impact::{PeakContact, PeakTracker};
use grit_erosion::{ImpactParams, Sample, Shape, SLOPE_WINDOW};
use serde::Serialize;

/// Arguments of `grit shapes`.
#[derive(clap::Args)]
pub struct ShapesArgs {
    /// Print a JSON array of {name, angularity, aspect_ratio, area_m2}.
    #[arg(long)]
    json: bool,
    /// Grain diameter Dg the areas refer to (m).
    #[arg(long, default_value_t = 250e-6)]
    diameter_m: f64,
}

/// Prints the built-in shapes with their angularity and aspect ratio (seed Table 2).
pub fn shapes(a: ShapesArgs) -> anyhow::Result<ExitCode> {
    let infos = Shape::builtins()
        .iter()
        .map(|s| s.info(a.diameter_m))
        .collect::<Result<Vec<_>, _>>()
        .context("diameter_m")?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&infos)?);
    } else {
        println!(
            "{:<10} {:>10} {:>12} {:>12}",
            "shape", "angularity", "aspect_ratio", "area_m2"
        );
        for i in &infos {
            println!(
                "{:<10} {:>10.3} {:>12.3} {:>12.4e}",
                i.name, i.angularity, i.aspect_ratio, i.area_m2
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The impact scene as command-line flags (seed section 4 defaults).
#[derive(clap::Args)]
pub struct SceneArgs {
    /// Impact angle, degrees from the surface, in (0, 90] (required unless a scene file or
    /// checkpoint gives it).
    #[arg(long)]
    angle: Option<f64>,
    /// Grain shape: octagon, hexagon, square, rectangle or circle [default: hexagon].
    #[arg(long)]
    shape: Option<String>,
    /// Particle spacing Δx (m); the seed's is 8e-6.
    #[arg(long)]
    spacing_m: Option<f64>,
    /// Impact speed (m/s).
    #[arg(long)]
    velocity_m_s: Option<f64>,
    /// Aim-point range in grain diameters.
    #[arg(long)]
    distribution_range_dg: Option<f64>,
    /// Surface width in grain diameters.
    #[arg(long)]
    surface_width_dg: Option<f64>,
    /// Surface depth in grain diameters.
    #[arg(long)]
    surface_depth_dg: Option<f64>,
    /// End an impact once the surface kinetic energy is below this fraction of the grain's.
    #[arg(long)]
    settle_fraction: Option<f64>,
    /// Full scene as JSON (an ImpactParams object); flags above override its fields.
    #[arg(long)]
    scene: Option<PathBuf>,
}

impl SceneArgs {
    /// The validated scene; errors name the field and the rule.
    fn params(&self) -> anyhow::Result<ImpactParams> {
        let mut p = match &self.scene {
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .with_context(|| format!("reading {}", path.display()))?;
                serde_json::from_str(&text).with_context(|| format!("scene {}", path.display()))?
            }
            None => ImpactParams::default(),
        };
        match (self.angle, &self.scene) {
            (Some(a), _) => p.angle_deg = a,
            (None, Some(_)) => {}
            (None, None) => bail!("angle: required (--angle DEG, in (0, 90])"),
        }
        if let Some(name) = &self.shape {
            p.shape = Shape::from_name(name).with_context(|| {
                format!(
                    "shape: unknown `{name}`; expected one of {}",
                    grit_erosion::shapes::BUILTIN_NAMES.join(", ")
                )
            })?;
        }
        let set = |dst: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *dst = v;
            }
        };
        set(&mut p.spacing_m, self.spacing_m);
        set(&mut p.velocity_m_s, self.velocity_m_s);
        set(&mut p.distribution_range_dg, self.distribution_range_dg);
        set(&mut p.surface_width_dg, self.surface_width_dg);
        set(&mut p.surface_depth_dg, self.surface_depth_dg);
        set(&mut p.settle_fraction, self.settle_fraction);
        if let Err(e) = p.validate() {
            bail!("{}: {}", e.field, e.rule);
        }
        Ok(p)
    }
}

/// Arguments of `grit sample`.
#[derive(clap::Args)]
pub struct SampleArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Number of impacts on the fresh surface.
    #[arg(long, default_value_t = 60)]
    impacts: u32,
    /// Seed of the random aim points and orientations.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads of the engine (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Also write the JSON result (with every impact's details) to this file.
    #[arg(long, short)]
    out: Option<PathBuf>,
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

/// Where `--snapshots` writes, which impacts it takes, and what it has written so far.
struct Snapshots {
    dir: PathBuf,
    at: BTreeSet<u32>,
    /// Digits of the impact number in file names, so they sort in impact order.
    width: usize,
    /// (impact, surface file, grain file if the grain touched) of every snapshot written.
    written: Vec<(u32, String, Option<String>)>,
}

impl Snapshots {
    /// Checks the flags before any impact runs: the impacts are this run's and the folder
    /// takes files.
    fn new(dir: &Path, at: Option<&[u32]>, done: u32, impacts: u32) -> anyhow::Result<Self> {
        let at: BTreeSet<u32> = match at {
            Some(list) => {
                for &k in list {
                    if k == 0 || k > impacts {
                        bail!(
                            "--snapshot-at: impact {k} is not one of this run's impacts 1..={impacts} (--impacts)"
                        );
                    }
                    if k <= done {
                        bail!(
                            "--snapshot-at: impact {k} was finished before the checkpoint, which holds {done} impacts"
                        );
                    }
                }
                list.iter().copied().collect()
            }
            None => std::iter::once(1)
                .chain((10..=impacts).step_by(10))
                .chain(std::iter::once(impacts))
                .filter(|&k| k > done)
                .collect(),
        };
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--snapshots {}: cannot create the folder", dir.display()))?;
        let s = Snapshots {
            dir: dir.to_path_buf(),
            at,
            width: impacts.to_string().len().max(4),
            written: Vec::new(),
        };
        // Empty collections now: an unwritable folder fails before hours of simulation.
        s.write_collections()
            .with_context(|| format!("--snapshots {}: cannot write there", dir.display()))?;
        Ok(s)
    }

    fn wants(&self, impact: u32) -> bool {
        self.at.contains(&impact)
    }

    fn write_collections(&self) -> std::io::Result<()> {
        let surface: Vec<(f64, &str)> = self
            .written
            .iter()
            .map(|(k, f, _)| (*k as f64, f.as_str()))
            .collect();
        let grain: Vec<(f64, &str)> = self
            .written
            .iter()
            .filter_map(|(k, _, g)| g.as_deref().map(|g| (*k as f64, g)))
            .collect();
        for (name, entries) in [("surface.pvd", surface), ("grain.pvd", grain)] {
            let f = std::fs::File::create(self.dir.join(name))?;
            grit_sph::vtk::write_collection(f, &entries)?;
        }
        Ok(())
    }

    /// Writes the pictures and ParaView files of the surface as `s` holds it after its last
    /// impact, with the grain at `peak`.
    fn write(&mut self, s: &Sample, peak: Option<&PeakContact>) -> anyhow::Result<()> {
        let k = s.impacts_done();
        let p = s.params();
        let tag = format!("{k:0w$}", w = self.width);
        let in_dir = |name: &str| self.dir.join(name);
        let create = |name: &str| {
            std::fs::File::create(in_dir(name))
                .with_context(|| format!("--snapshots: writing {}", in_dir(name).display()))
        };

        let surface_file = format!("surface-{tag}.vtu");
        grit_sph::vtk::write_particles(
            create(&surface_file)?,
            s.surface(),
            &[p.material.bulk_modulus()],
        )
        .with_context(|| format!("--snapshots: writing {surface_file}"))?;
        let grain_file = match peak {
            Some(pk) => {
                let name = format!("grain-{tag}.vtu");
                grit_sph::vtk::write_polygon(create(&name)?, &pk.outline_m)
                    .with_context(|| format!("--snapshots: writing {name}"))?;
                Some(name)
            }
            None => None,
        };

        let um = 1e6;
        let lost: f64 = s.records().iter().map(|r| r.mass_loss_kg).sum();
        let removed: u32 = s
            .records()
            .iter()
            .map(|r| r.outcome.removed_particles + r.outcome.detached_particles)
            .sum();
        let grain_note = match peak {
            Some(pk) => format!(
                "grey: the grain at its largest contact force in impact {k}, {:.3e} N/m at {:.2} µs; \
                 its lowest point {:.1} µm below the original surface (y = 0)",
                pk.force_n_m,
                pk.time_s * um,
                pk.depth_m * um
            ),
            None => format!("the grain of impact {k} never touched the surface"),
        };
        let picture = grit_plot::SurfacePicture {
            particles: s.surface(),
            spacing_m: p.spacing_m,
            outline_m: peak.map(|pk| pk.outline_m.as_slice()),
            title: format!(
                "after impact {k}, {}° {}, {} m/s, Δx {} µm, seed {}",
                p.angle_deg,
                p.shape.name(),
                p.velocity_m_s,
                p.spacing_m * um,
                s.seed()
            ),
            notes: vec![
                grain_note,
                if removed == 0 {
                    format!("no surface mass lost in impacts 1-{k}; pale: the fixed particles that hold the surface")
                } else {
                    format!(
                        "surface mass lost in impacts 1-{k}: {lost:.3e} kg per m of depth \
                         ({removed} particles); pale: the fixed particles that hold the surface"
                    )
                },
            ],
        };
        for field in grit_plot::SurfaceField::ALL {
            let path = in_dir(&format!("{}-{tag}.png", field.stem()));
            grit_plot::surface_png(&picture, field, &path)?;
        }
        self.written.push((k, surface_file, grain_file));
        self.write_collections()
            .with_context(|| format!("--snapshots: writing {}", self.dir.display()))
    }
}

fn pool(threads: Option<usize>) -> anyhow::Result<rayon::ThreadPool> {
    Ok(rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()?)
}

fn impact_bar(n: u32) -> anyhow::Result<indicatif::ProgressBar> {
    let bar = indicatif::ProgressBar::new(n as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:30}] {pos}/{len} impacts, {per_sec}, eta {eta} {msg}",
        )?
        .progress_chars("=> "),
    );
    Ok(bar)
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

/// Runs one sample locally with a progress bar and prints its mass-loss series.
pub fn sample(a: SampleArgs) -> anyhow::Result<ExitCode> {
    if a.impacts == 0 {
        bail!("impacts: must be at least 1");
    }
    let mut s = match &a.resume {
        Some(path) => {
            let bytes =
                std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
            Sample::from_checkpoint(&bytes).with_context(|| format!("resume {}", path.display()))?
        }
        None => Sample::new(a.scene.params()?, a.seed)?,
    };
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
    let bar = impact_bar(a.impacts)?;
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
        let ran = pool.install(|| match tracker.as_mut() {
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
        bar.set_message(format!(
            "loss so far {:.3e} kg/m",
            s.records().iter().map(|r| r.mass_loss_kg).sum::<f64>()
        ));
        bar.inc(1);
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
    if let Some(path) = &a.out {
        std::fs::write(path, serde_json::to_string_pretty(&out)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if a.json {
        #[derive(Serialize)]
        struct Short<'a> {
            series: &'a [Point],
            erosion_last20: Option<f64>,
        }
        let short = Short {
            series: &out.series,
            erosion_last20: out.erosion_last20,
        };
        println!("{}", serde_json::to_string(&short)?);
    } else {
        println!("impact  grain_mass_cum  mass_loss_cum  removed  steps  rebound");
        for (pt, r) in out.series.iter().zip(s.records()) {
            println!(
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
            Some(e) => println!("erosion (slope of the last {SLOPE_WINDOW} points): {e:.4e}"),
            None => println!("erosion: needs at least {SLOPE_WINDOW} impacts"),
        }
        println!("wall time {:.1} s", t0.elapsed().as_secs_f64());
        if let Some(snap) = &snapshots {
            println!(
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

/// Runs one of the checks of the scene's own choices (issue 3).
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
            let bar = impact_bar(impacts)?;
            let rows = pool(threads)?.install(|| {
                grit_erosion::studies::settle_study(&p, seed, impacts, strict_fraction, |_| {
                    bar.inc(1)
                })
            })?;
            bar.finish();
            if json {
                println!("{}", serde_json::to_string_pretty(&rows)?);
                return Ok(ExitCode::SUCCESS);
            }
            println!(
                "settle_fraction {} against {strict_fraction}",
                p.settle_fraction
            );
            println!("impact  loss_kg_m   loss_strict  dD        dD_strict  t_s        t_strict_s");
            for r in &rows {
                println!(
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
            let sum = |f: fn(&grit_erosion::studies::SettleRow) -> f64| -> f64 {
                rows.iter().map(f).sum()
            };
            let (d, ds) = (sum(|r| r.damage_added), sum(|r| r.damage_added_strict));
            let (m, ms) = (sum(|r| r.mass_loss_kg), sum(|r| r.mass_loss_strict_kg));
            println!(
                "total damage added {d:.4} vs {ds:.4} ({:+.2}%), mass loss {m:.3e} vs {ms:.3e} kg/m",
                100.0 * (ds - d) / d.max(f64::MIN_POSITIVE)
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}
