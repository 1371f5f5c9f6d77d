//! `grit bench`: the engine's benchmarks and numerical studies (one impact timed, the
//! speed–accuracy sweep, the stability map) and the coordinator's load test.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context};
use clap::{Args, Subcommand};
use grit_erosion::studies;
use grit_erosion::studies::stability::{self, StabilityGrid, StabilityProgress, StabilityStudy};
use grit_erosion::studies::sweep::{
    cheapest_within, Cost, SweepProgress, SweepRow, SweepStudy, Variant,
};
use grit_erosion::{ImpactParams, Sample};

use super::output::{say, write_csv, write_json};
use super::{pool, progress};

/// `grit bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(subcommand)]
    what: BenchWhat,
}

#[derive(Subcommand, Debug)]
enum BenchWhat {
    /// The coordinator's load test: claims+completions/s at several client counts,
    /// heartbeat latency and failed requests, with jobs that do no simulation.
    #[command(after_help = "Example: grit bench farm --clients 1,8 --seconds 5")]
    Farm {
        /// Concurrent clients, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = vec![1, 8, 64], value_parser = crate::cli::thread_count)]
        clients: Vec<usize>,
        /// Seconds per client count.
        #[arg(long, default_value_t = 5.0, value_parser = crate::cli::seconds)]
        seconds: f64,
        /// Folder for the scratch database.
        #[arg(long, default_value = "target/bench-farm")]
        dir: PathBuf,
        /// Print JSON rows instead of a Markdown table.
        #[arg(long)]
        json: bool,
        /// The scratch database's commits: `full` (flushed to the disk, as `grit serve`
        /// does by default) or `normal` (see `grit serve --synchronous`).
        #[arg(long, default_value = "full")]
        synchronous: grit_farm::Synchronous,
    },
    /// One impact of the reference scene (hexagon, 45°, 100 m/s, AISI 304, 8 µm) timed on 1
    /// thread and on N threads from the same surface: particle-steps per second and stages.
    #[command(after_help = "Example: grit bench impact --threads 2 --repeat 5")]
    Impact {
        #[command(flatten)]
        scene: ImpactScene,
        /// Threads of the timed run (1 is always timed too).
        #[arg(long, default_value_t = 2, value_parser = crate::cli::thread_count)]
        threads: usize,
        /// Alternate the 1-thread and the N-thread run this many times and report medians.
        #[arg(long, default_value_t = 1, value_parser = crate::cli::repeat_count)]
        repeat: usize,
        /// Print the figures as JSON.
        #[arg(long)]
        json: bool,
    },
    /// The speed–accuracy sweep: erosion of the hexagon (samples × impacts) and the Hertz p0
    /// error at several resolutions and numerical variants, against wall time per impact.
    /// Writes OUT/sweep.{csv,json} and the chart OUT/speed-accuracy.{png,svg}, and names the
    /// cheapest setting within the finest's error bars.
    #[command(
        after_help = "Example: grit bench sweep --ppd 8,16,32 --variants seed,wendland_c2 --out out/sweep"
    )]
    Sweep(SweepArgs),
    /// The stability map: one impact with the Courant number swept against the hourglass
    /// coefficient, and the contact stiffness against the time step for both contact models;
    /// each point stable or with the engine's diagnostic. Writes OUT/stability.{csv,json,png,svg}.
    #[command(after_help = "Example: grit bench stability --cfl 0.3,1.0,2.0 --out out/stability")]
    Stability {
        /// Impact angle (degrees).
        #[arg(long, default_value_t = 45.0, allow_negative_numbers = true)]
        angle: f64,
        /// Particle spacing Δx (m): 1.5625e-5 is 16 particles per Dg.
        #[arg(long, default_value_t = 1.5625e-5, allow_negative_numbers = true)]
        spacing_m: f64,
        /// Impacts the surface takes (with the default numerics) before the mapped one.
        #[arg(long, default_value_t = 0, value_parser = crate::cli::impacts_before)]
        after: u32,
        /// Seed of the sample the grain comes from.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Courant numbers, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = StabilityGrid::default().cfl, allow_negative_numbers = true)]
        cfl: Vec<f64>,
        /// Hourglass coefficients α, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = StabilityGrid::default().hourglass, allow_negative_numbers = true)]
        hourglass: Vec<f64>,
        /// Contact stiffness over the default k, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = StabilityGrid::default().stiffness_scale, allow_negative_numbers = true)]
        stiffness: Vec<f64>,
        /// A point is stopped as collapsed after this many times the steps the longest impact
        /// takes at its first step's dt.
        #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
        budget: f64,
        /// Output folder.
        #[arg(long, default_value = "out/stability")]
        out: PathBuf,
        /// Threads (default: all cores).
        #[arg(long, value_parser = crate::cli::thread_count)]
        threads: Option<usize>,
    },
}

/// The settings of `grit bench sweep`: the study's, where it writes, and its threads.
#[derive(Debug, clap::Args)]
pub struct SweepArgs {
    /// Impact angle (degrees).
    #[arg(long, default_value_t = 45.0, allow_negative_numbers = true)]
    angle: f64,
    /// Resolutions, particles per grain diameter, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![8.0, 12.0, 16.0, 24.0, 32.0])]
    ppd: Vec<f64>,
    /// Numerical variants, comma-separated: seed (the numerics of Mohseni-Mofidi et al.
    /// 2022: CFL 0.3, the density filter every 40 steps), default (grit's default scene),
    /// wendland_c2, cubic_spline, full_flight, cfl=X, cfl_time=X (CFL X with the density filter's
    /// seed period in simulated time), filter=N (the density filter every N steps, 0 = off),
    /// default_filter=N (the default numerics with the filter every N steps, 0 = off),
    /// h=X (the default numerics with h/Δx = X, in [1, 2]); the first is the reference.
    #[arg(long, value_delimiter = ',', default_values_t = vec!["seed".to_string(), "wendland_c2".to_string()])]
    variants: Vec<String>,
    /// Resolutions of the variants after the first (default: all of --ppd).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    variant_ppd: Vec<f64>,
    /// Samples per point.
    #[arg(long, default_value_t = 5)]
    samples: u32,
    /// Impacts per sample.
    #[arg(long, default_value_t = 30)]
    impacts: u32,
    /// Seed of sample 0; sample k uses seed + k.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Width of the band of aim points (Dg); the reduced campaign's 0.5 by default.
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    range_dg: f64,
    /// Surface width (Dg); the reduced campaign's 2.5 (checked by its domain study).
    #[arg(long, default_value_t = 2.5, allow_negative_numbers = true)]
    width_dg: f64,
    /// Surface depth (Dg); the reduced campaign's 1.25.
    #[arg(long, default_value_t = 1.25, allow_negative_numbers = true)]
    depth_dg: f64,
    /// Output folder.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
    /// Keep the points already in OUT/sweep.json and run only the missing ones.
    #[arg(long)]
    resume: bool,
    /// Threads (default: all cores).
    #[arg(long, value_parser = crate::cli::thread_count)]
    threads: Option<usize>,
}

impl SweepArgs {
    /// The study these settings describe: the reduced campaign's scene at `angle`.
    fn study(&self) -> anyhow::Result<SweepStudy> {
        let variants = self
            .variants
            .iter()
            .map(|v| Variant::parse(v))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(SweepStudy {
            params: ImpactParams {
                distribution_range_dg: self.range_dg,
                surface_width_dg: self.width_dg,
                surface_depth_dg: self.depth_dg,
                ..studies::scene(self.angle, 8e-6)
            },
            ppd: self.ppd.clone(),
            variants,
            variant_ppd: self.variant_ppd.clone(),
            samples: self.samples,
            impacts: self.impacts,
            seed: self.seed,
        })
    }
}

/// The scene `grit bench impact` times: the reference scene, or a variant of it.
#[derive(Debug, Clone, clap::Args)]
pub struct ImpactScene {
    /// Impact angle (degrees).
    #[arg(long, default_value_t = 45.0, allow_negative_numbers = true)]
    angle: f64,
    /// Particle spacing Δx (m); 8e-6 is the reference, coarser ones are quicker.
    #[arg(long, default_value_t = 8e-6, allow_negative_numbers = true)]
    spacing_m: f64,
    /// Impacts the surface takes before the timed one (the second reference scene: 30).
    #[arg(long, default_value_t = 0, value_parser = crate::cli::impacts_before)]
    after: u32,
    /// Seed of the sample.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Simulate every particle of the grain, not only its outline (the model before the
    /// grain-shell saving; the results are bitwise the same, the cost is not).
    #[arg(long)]
    full_grain: bool,
    /// Simulate the grain's approach step by step instead of skipping to just before its
    /// first contact (the model before the flight skip).
    #[arg(long)]
    full_flight: bool,
}

/// Runs one `grit bench` subcommand.
pub fn run(a: BenchArgs) -> anyhow::Result<ExitCode> {
    match a.what {
        BenchWhat::Farm {
            clients,
            seconds,
            dir,
            json,
            synchronous,
        } => {
            super::init_tracing("warn");
            super::runtime()?.block_on(farm(&dir, &clients, seconds, json, synchronous))
        }
        BenchWhat::Impact {
            scene,
            threads,
            repeat,
            json,
        } => impact(scene, threads, repeat, json),
        BenchWhat::Sweep(a) => {
            let study = a.study()?;
            pool(a.threads)?.install(|| sweep(&study, &a.out, a.resume))
        }
        BenchWhat::Stability {
            angle,
            spacing_m,
            after,
            seed,
            cfl,
            hourglass,
            stiffness,
            budget,
            out,
            threads,
        } => {
            let study = StabilityStudy {
                params: studies::scene(angle, spacing_m),
                seed,
                after,
                grid: StabilityGrid {
                    cfl,
                    hourglass,
                    stiffness_scale: stiffness,
                },
                budget_factor: budget,
            };
            pool(threads)?.install(|| stability_map(&study, &out))
        }
    }
}

/// `grit bench farm`: the load test's rows as a Markdown table or JSON.
async fn farm(
    dir: &std::path::Path,
    clients: &[usize],
    seconds: f64,
    json: bool,
    synchronous: grit_farm::Synchronous,
) -> anyhow::Result<ExitCode> {
    let rows = grit_farm::loadtest::run(dir, clients, seconds, synchronous).await?;
    if json {
        say!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        let _ = write!(std::io::stdout(), "{}", grit_farm::loadtest::table(&rows));
    }
    Ok(ExitCode::SUCCESS)
}

/// `grit bench impact`: the engine runs on rayon pools of its own.
fn impact(
    scene: ImpactScene,
    threads: usize,
    repeat: usize,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let ImpactScene {
        angle,
        spacing_m,
        after,
        seed,
        full_grain,
        full_flight,
    } = scene;
    let mut params = studies::scene(angle, spacing_m);
    params.numerics.engine.rigid_shell &= !full_grain;
    params.numerics.skip_flight &= !full_flight;
    params.validate()?;
    let mut s = Sample::new(params, seed)?;
    for k in 0..after {
        eprintln!("preparing the surface: impact {} of {after}", k + 1);
        s.run_next()?;
    }
    let b = studies::bench::impact(&s, threads, repeat)?;
    if json {
        say!("{}", serde_json::to_string_pretty(&b)?);
        return Ok(ExitCode::SUCCESS);
    }
    say!(
        "scene: hexagon {angle} deg, 100 m/s, AISI 304, spacing {spacing_m:e} m, surface after {after} impacts, grain {}, flight {}",
        if full_grain { "filled" } else { "outline only" },
        if full_flight { "simulated" } else { "skipped" }
    );
    say!("particles                 {}", b.particles);
    say!("steps                     {}", b.steps);
    let runs = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.2}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if b.repeats > 1 {
        say!("repeats                   {} (medians below)", b.repeats);
        say!(
            "wall runs ({} threads)     {} s",
            b.threads,
            runs(&b.wall_s_runs)
        );
        say!(
            "wall runs (1 thread)      {} s",
            runs(&b.wall_1_thread_s_runs)
        );
    }
    say!("pair pass                 {}", b.pair_pass);
    say!("wall ({} threads)          {:.2} s", b.threads, b.wall_s);
    say!("wall (1 thread)           {:.2} s", b.wall_1_thread_s);
    say!("particle-steps/s          {:.3e}", b.particle_steps_per_s);
    say!(
        "particle-steps/s/thread   {:.3e}",
        b.particle_steps_per_s_per_thread
    );
    if let Some(x) = b.speedup_1_to_2 {
        say!("speed-up 1 -> 2 threads   {x:.2}");
    }
    if let Some(c) = &b.ceiling {
        say!(
            "ceiling (1 thread)        {:.3e} s/step, {:.3e} pair terms/s, {:.3e} particle-steps/s",
            c.s_per_step,
            c.pair_terms_per_s,
            c.particle_steps_per_s
        );
        say!(
            "full step / ceiling       {:.2} (1 thread)",
            c.full_step_over_ceiling
        );
    }
    let total: f64 = b.stages.values().sum();
    say!(
        "  {:<14} {:>8} {:>7} {:>10} {:>8}",
        "stage",
        format!("{} thr", b.threads),
        "share",
        "1 thread",
        "speed-up"
    );
    for (k, v) in &b.stages {
        let one = b.stages_1_thread.get(k).copied().unwrap_or(f64::NAN);
        let ratio = if *v > 0.0 && one.is_finite() {
            format!("{:.2}", one / v)
        } else {
            "-".to_string()
        };
        say!(
            "  {k:<14} {v:>6.3} s {:>6.1}% {one:>8.3} s {ratio:>8}",
            100.0 * v / total.max(1e-12)
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `grit bench stability`: the map with a progress bar, its text table, CSV, JSON and chart.
fn stability_map(study: &StabilityStudy, out: &std::path::Path) -> anyhow::Result<ExitCode> {
    study.validate()?;
    std::fs::create_dir_all(out).with_context(|| format!("--out {}", out.display()))?;
    if study.after > 0 {
        eprintln!(
            "preparing the surface: {} impacts with the scene's own numerics",
            study.after
        );
    }
    let total = study.grid.points().len() as u64;
    let pb = progress::bar(total, "stability", true);
    let points = study.run(|event| match event {
        StabilityProgress::Start { panel, numerics: n } => pb.set_message(format!(
            "{:?}: cfl {} α {} k×{} {:?}",
            panel, n.engine.cfl, n.engine.hourglass, n.contact_stiffness_scale, n.contact_model
        )),
        StabilityProgress::Done {
            panel,
            numerics: n,
            point: p,
        } => {
            pb.inc(1);
            progress::line(
                &pb,
                &format!(
                    "{}/{total} {:?}: cfl {} α {} k×{}: {:?}{}",
                    pb.position(),
                    panel,
                    n.engine.cfl,
                    n.engine.hourglass,
                    n.contact_stiffness_scale,
                    p.verdict,
                    p.failure
                        .map(|f| format!(" ({})", f.label()))
                        .unwrap_or_default()
                ),
            );
        }
    })?;
    pb.finish_and_clear();
    write_csv(&out.join("stability.csv"), &points)?;
    write_json(&out.join("stability.json"), &points)?;
    grit_plot::stability_chart(&points, out, "stability", &[study.note()])?;
    let _ = write!(std::io::stdout(), "{}", stability::table(&points));
    say!(
        "wrote {0}/stability.csv, .json, .png and .svg",
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// `grit bench sweep`: the sweep with a progress bar, its rows saved after every point, the
/// chart, and the cheapest setting within the finest's error bars.
fn sweep(study: &SweepStudy, out: &std::path::Path, resume: bool) -> anyhow::Result<ExitCode> {
    study.validate()?;
    std::fs::create_dir_all(out).with_context(|| format!("--out {}", out.display()))?;
    let (csv, json) = (out.join("sweep.csv"), out.join("sweep.json"));
    let mut rows: Vec<SweepRow> = Vec::new();
    if resume && json.exists() {
        let text = std::fs::read_to_string(&json).with_context(|| json.display().to_string())?;
        rows = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a sweep file to resume", json.display()))?;
        if let Some(r) = study.resume_clash(&rows) {
            bail!(
                "--resume: {} has {} samples × {} impacts at {} per Dg, this run asks for {} × {}",
                json.display(),
                r.samples,
                r.impacts,
                r.particles_per_dg,
                study.samples,
                study.impacts
            );
        }
    }
    let impacts = (study.samples * study.impacts) as u64;
    let pb = progress::bar(study.plan(&rows).len() as u64 * impacts, "sweep", true);
    let tick = |event: SweepProgress| match event {
        SweepProgress::Point { variant, ppd } => {
            pb.set_message(format!("{} at {ppd} per Dg", variant.name()))
        }
        SweepProgress::Impact => pb.inc(1),
    };
    let rows = study.run(rows, &tick, |rows: &[SweepRow]| -> anyhow::Result<()> {
        if let Some(row) = rows.last() {
            progress::line(&pb, &row.line());
        }
        write_csv(&csv, rows)?;
        write_json(&json, &rows)
    })?;
    pb.finish_and_clear();
    // Also when --resume found nothing left to run: the files then match the rows.
    write_csv(&csv, &rows)?;
    write_json(&json, &rows)?;
    grit_plot::sweep_chart(&rows, out, "speed-accuracy", &study.notes(&rows))?;
    say!("summary of {}:", json.display());
    for r in &rows {
        say!("{}", r.line());
    }
    match cheapest_within(&rows) {
        Some(b) => {
            let cost = Cost::of(&rows);
            say!(
                "cheapest within the finest's ±1 std: {} at {} per Dg, {:.3} s per impact ({})",
                b.variant,
                b.particles_per_dg,
                cost.get(b),
                cost.label()
            )
        }
        None => say!("no erosion at the finest resolution: no setting can be judged against it"),
    }
    say!(
        "wrote {0}/sweep.csv, {0}/sweep.json and {0}/speed-accuracy.png, .svg",
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}
