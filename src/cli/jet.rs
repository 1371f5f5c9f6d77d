//! `grit jet`: one abrasive water-jet run on this machine (docs/jet.md): crater depth and width,
//! mass loss and plastic strain against time, with a progress bar, optional JSON and snapshots.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use grit_erosion::campaign::MaterialSpec;
use grit_erosion::jet::{JetParams, JetRun, JetSlice};
use grit_sph::cracks::RockDamage;
use grit_sph::crater::CraterSample;
use serde::Serialize;

use super::output::{check_writable, say, write_bytes, ResultArgs};
use super::{pool, progress};

mod snapshots;

/// Arguments of `grit jet`.
#[derive(clap::Args)]
pub struct JetArgs {
    /// A JSON file of scene parameters (any `JetParams` field: docs/jet.md#the-scene); the
    /// flags below override it.
    #[arg(long, value_name = "FILE")]
    scene: Option<PathBuf>,
    /// Target material: copper, al6061, aisi304, or a JH-2 rock: sandstone or granite.
    #[arg(long)]
    material: Option<String>,
    /// Jet speed at the nozzle (m/s).
    #[arg(long, allow_negative_numbers = true)]
    velocity_m_s: Option<f64>,
    /// Abrasive mass flow (kg/s); 0 for a pure water jet.
    #[arg(long, allow_negative_numbers = true)]
    mass_flow_kg_s: Option<f64>,
    /// Simulated time (ms).
    #[arg(long, allow_negative_numbers = true)]
    time_ms: Option<f64>,
    /// Time between crater samples (ms).
    #[arg(long, allow_negative_numbers = true)]
    slice_ms: Option<f64>,
    /// Particle spacing of water and target (m).
    #[arg(long, allow_negative_numbers = true)]
    spacing_m: Option<f64>,
    /// Coupling radius over grain diameter.
    #[arg(long, allow_negative_numbers = true)]
    coupling_radius_d: Option<f64>,
    /// Seed of the abrasive placement.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads of the engine (default: all cores).
    #[arg(long, value_parser = crate::cli::thread_count)]
    threads: Option<usize>,
    #[command(flatten)]
    result: ResultArgs,
    /// Write pictures (PNG: phase, pressure, damage) and ParaView files (VTU, PVD) of the scene
    /// at the end of every `--snapshot-every`-th slice into this folder.
    #[arg(long, value_name = "DIR")]
    snapshots: Option<PathBuf>,
    /// Slices between snapshots.
    #[arg(long, default_value_t = 1, requires = "snapshots")]
    snapshot_every: u32,
    /// Write the run's whole state to this file after every slice (atomically), so a killed
    /// run loses at most one slice.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Go on from a checkpoint file with the parameters and seed stored in it; `--time-ms` may
    /// run it longer, the other scene flags must be left out.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["scene", "material", "velocity_m_s", "mass_flow_kg_s", "slice_ms", "spacing_m", "coupling_radius_d"])]
    resume: Option<PathBuf>,
}

/// What `--json` prints.
#[derive(Serialize)]
struct JetOutput<'a> {
    params: &'a JetParams,
    seed: u64,
    /// One point per slice: t, mass loss per metre, Cd, Cw, largest plastic strain, and for a
    /// rock its detached mass and cracks.
    series: Vec<SeriesPoint>,
    /// The slices with their profiles and costs.
    slices: &'a [JetSlice],
    /// Wall-clock seconds of the run.
    wall_s: f64,
    /// Why the run stopped early, if it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
}

/// One point of the series: the crater sample, and on a rock target its damage
/// (docs/jet.md#rock-targets) in the same object; a metal's points keep the sample's fields only.
#[derive(Serialize)]
struct SeriesPoint {
    #[serde(flatten)]
    sample: CraterSample,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    rock: Option<RockDamage>,
}

impl JetArgs {
    /// The parameters: the scene file's, then the flags.
    fn params(&self) -> anyhow::Result<JetParams> {
        let mut p = match &self.scene {
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .with_context(|| format!("--scene {}", path.display()))?;
                JetParams::from_json(&text)
                    .with_context(|| format!("--scene {}", path.display()))?
            }
            None => JetParams::default(),
        };
        if let Some(m) = &self.material {
            p.material = MaterialSpec(grit_sph::Material::by_name(m)?);
        }
        let set = |dst: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *dst = v;
            }
        };
        set(&mut p.velocity_m_s, self.velocity_m_s);
        set(&mut p.mass_flow_kg_s, self.mass_flow_kg_s);
        set(&mut p.time_ms, self.time_ms);
        set(&mut p.slice_ms, self.slice_ms);
        // A run shorter than the default slice is one slice, unless a slice was asked for.
        if self.slice_ms.is_none() && self.scene.is_none() && p.time_ms < p.slice_ms {
            p.slice_ms = p.time_ms;
        }
        set(&mut p.spacing_m, self.spacing_m);
        set(&mut p.coupling_radius_d, self.coupling_radius_d);
        p.validate()?;
        Ok(p)
    }
}

/// Runs one jet with a progress bar over simulated time and prints its crater series.
pub fn jet(a: JetArgs) -> anyhow::Result<ExitCode> {
    for (flag, path) in [("--out", &a.result.out), ("--checkpoint", &a.checkpoint)] {
        if let Some(path) = path {
            check_writable(flag, path)?;
        }
    }
    let mut run = match &a.resume {
        Some(path) => {
            let bytes =
                std::fs::read(path).with_context(|| format!("--resume {}", path.display()))?;
            let mut run = JetRun::from_checkpoint(&bytes)
                .with_context(|| format!("--resume {}", path.display()))?;
            if let Some(t) = a.time_ms {
                run.extend(t)?;
            }
            run
        }
        None => JetRun::new(a.params()?, a.seed)?,
    };
    let params = run.params().clone();
    let seed = run.seed();
    let mut snaps = match &a.snapshots {
        Some(dir) => Some(snapshots::Snapshots::new(dir, a.snapshot_every)?),
        None => None,
    };
    let pool = pool(a.threads)?;
    // The bar counts simulated microseconds.
    let total_us = (params.time_ms * 1e3).ceil() as u64;
    let bar = progress::bar(total_us, "µs simulated", !a.result.json);
    bar.set_position(
        run.slices()
            .last()
            .map_or(0, |s| (s.sample.t_s * 1e6) as u64),
    );
    let t0 = Instant::now();
    let mut failure = None;
    while !run.finished() {
        let ran = grit_sph::polling::install_polling(&pool, || {
            run.run_next_slice_observed(
                &|| false,
                Some(&mut |w: &grit_sph::World| bar.set_position((w.time() * 1e6) as u64)),
            )
            .map(|_| ())
        });
        if let Err(e) = ran {
            failure = Some(e);
            break;
        }
        let s = run.slices().last().expect("a slice just finished");
        let msg = format!(
            "Cd {:.1} µm, Cw {:.1} µm, loss {:.3e} kg/m, {} grains",
            s.sample.crater_depth_m * 1e6,
            s.sample.crater_width_m * 1e6,
            s.sample.mass_loss_kg_m,
            s.grains
        );
        // Without a terminal (a log file) the bar is hidden: a line per slice instead.
        if bar.is_hidden() && !a.result.json {
            eprintln!(
                "slice {}/{}: t = {:.1} µs, {msg}, {:.1} s",
                s.slice,
                run.slices_total(),
                s.sample.t_s * 1e6,
                s.wall_s
            );
        }
        bar.set_message(msg);
        if let Some(sn) = snaps.as_mut() {
            sn.write(&run)?;
        }
        if let Some(path) = &a.checkpoint {
            write_bytes(path, &run.checkpoint())?;
        }
    }
    bar.finish();
    let out = JetOutput {
        params: &params,
        seed,
        series: run
            .slices()
            .iter()
            .map(|s| SeriesPoint {
                sample: s.sample,
                rock: s.rock,
            })
            .collect(),
        slices: run.slices(),
        wall_s: t0.elapsed().as_secs_f64(),
        error: failure.as_ref().map(|e| e.to_string()),
    };
    a.result.write(&out)?;
    if a.result.json {
        say!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        say!(
            "{:>9} {:>12} {:>10} {:>10} {:>8} {:>7} {:>5} {:>11}",
            "t (ms)",
            "loss (kg/m)",
            "Cd (µm)",
            "Cw (µm)",
            "eps_p",
            "grains",
            "hits",
            "hit v_n m/s"
        );
        for s in run.slices() {
            let c = &s.sample;
            // The grains that first touched the target in the slice, and their mean approach
            // speed along the contact normal.
            let (hits, v_n) = s.grain_hits.map_or((0, "-".to_string()), |h| {
                let v_n = h.normal_speed_m_s.map(|v| format!("{:.0}", v.mean));
                (h.count, v_n.unwrap_or_else(|| "-".to_string()))
            });
            say!(
                "{:>9.4} {:>12.4e} {:>10.1} {:>10.1} {:>8.3} {:>7} {:>5} {:>11}",
                c.t_s * 1e3,
                c.mass_loss_kg_m,
                c.crater_depth_m * 1e6,
                c.crater_width_m * 1e6,
                c.max_plastic_strain,
                s.grains,
                hits,
                v_n
            );
        }
        if run.slices().iter().any(|s| s.rock.is_some()) {
            say!(
                "{:>9} {:>12} {:>10} {:>7} {:>11} {:>11} {:>11}",
                "t (ms)",
                "detached",
                "fractured",
                "cracks",
                "length µm",
                "below Cd µm",
                "damage mm²"
            );
            for (s, r) in run.slices().iter().filter_map(|s| Some((s, s.rock?))) {
                say!(
                    "{:>9.4} {:>12.4e} {:>10} {:>7} {:>11.0} {:>11.0} {:>11.4}",
                    s.sample.t_s * 1e3,
                    r.detached_kg_m,
                    r.fractured_particles,
                    r.crack_count,
                    r.crack_length_m * 1e6,
                    r.crack_depth_below_crater_m * 1e6,
                    r.damaged_area_m2 * 1e6
                );
            }
        }
        say!("{:.1} s wall", out.wall_s);
    }
    match failure {
        Some(e) => Err(anyhow::anyhow!(e).context(format!(
            "the run stopped after {} of {} slices (the slices before are above)",
            run.slices_done(),
            run.slices_total()
        ))),
        None => Ok(ExitCode::SUCCESS),
    }
}
