//! Stored compression in a surface that takes many impacts: is the mean pressure of the free
//! particles away from the craters growing with the impact count and with a smaller box, and is
//! it mechanics or density drift?
//!
//! Runs one sample per configuration, impact by impact, and after every `--every`-th impact
//! writes, per region of free particles (and of the fixed bands; regions picked by the
//! reference position `x_ref`, so each follows the same material through the sample):
//! - the EOS pressure p = K(ρ/ρ0 − 1) (seed eq. 11) and the mean stress −tr σ/3 of the full
//!   plane-strain Cauchy stress (`grit_sph::vtk::cauchy_stress_3d`), and the in-plane mean
//!   −(σxx + σyy)/2;
//! - three densities: ρ as the engine carries it (continuity, eq. 5, plus the Shepard filter,
//!   eq. 12), ρ0/det F with F the deformation gradient integrated from the same velocity
//!   gradient (`Particles::def_grad`, never reset on a surface), and ρ0/det F_geo with F_geo the
//!   least-squares map of each particle's lattice neighbours from `x_ref` to their current
//!   positions, which depends on positions only.
//!
//! ρ − ρ0/det F is what the filter (and step rounding) changed that the motion did not;
//! ρ0/det F − ρ0/det F_geo is how far the integrated gradient strays from the positions.
//!
//! ```sh
//! cargo run --release -p grit-erosion --example stored_compression -- OUT_DIR \
//!     --config small --impacts 150 [--every 1] [--seed 1]
//! ```
//!
//! With `--probe-steps N` it runs no impacts but takes the surface of `OUT_DIR/<config>.ckpt`
//! alone (no grain) through one density-filter pass, and through N steps at rest with the Shepard
//! filter, without a filter and with the MLS filter, writing
//! `OUT_DIR/probe-<config>-<impact>.csv` (see `probe`).
//!
//! Configurations (45°, hexagon, Δx = 16 µm, aim range 0.5 Dg unless named):
//! `small` 2.5 × 1.25 Dg; `wide` 3.75 × 1.875 Dg; `wide-r1` the same with aim range 1.0 Dg;
//! `shallow` 2.5 × 1.024 Dg (16 particle layers). The `sponge` configuration of the records in
//! `notebook/erosion/compression/` (the shallow box with an absorbing layer) went with the layer
//! (docs/performance.md, "An absorbing layer").
//! Each config writes `OUT_DIR/<config>.csv` and a checkpoint `OUT_DIR/<config>.ckpt`; rerun
//! with a larger `--impacts` to go on from the checkpoint.

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use grit_erosion::{ImpactParams, Numerics, Sample, Shape};
use grit_sph::particles::{von_mises, KINEMATIC};
use grit_sph::{DensityFilter, Matrix, Motion, Particles, Settings, Vector, World};

const HEADER: &str = "impact,config,region,n,mean_p_eos,mean_p_stress,mean_p_inplane,\
mean_rho,mean_rho_kin,mean_rho_geo,n_geo,mean_drift,std_drift,mean_abs_drift,mean_kin_geo,\
std_kin_geo,mean_eps_p,mean_vm,n_surface,mass_loss_cum_kg,erosion_mg_g,steps,wall_s";

fn no_filter() -> Numerics {
    let mut numerics = Numerics::default();
    numerics.engine.shepard_interval = 0;
    numerics
}

fn params(config: &str) -> Result<ImpactParams, String> {
    let base = ImpactParams {
        angle_deg: 45.0,
        shape: Shape::Hexagon,
        spacing_m: 16e-6,
        distribution_range_dg: 0.5,
        surface_width_dg: 2.5,
        surface_depth_dg: 1.25,
        ..ImpactParams::default()
    };
    let p = match config {
        "small" => base,
        "wide" => ImpactParams {
            surface_width_dg: 3.75,
            surface_depth_dg: 1.875,
            ..base
        },
        "wide-r1" => ImpactParams {
            surface_width_dg: 3.75,
            surface_depth_dg: 1.875,
            distribution_range_dg: 1.0,
            ..base
        },
        "small-nofilter" => ImpactParams {
            numerics: no_filter(),
            ..base
        },
        "wide-nofilter" => ImpactParams {
            surface_width_dg: 3.75,
            surface_depth_dg: 1.875,
            numerics: no_filter(),
            ..base
        },
        "shallow" => ImpactParams {
            surface_depth_dg: 1.024,
            ..base
        },
        _ => return Err(format!("--config: unknown configuration {config:?}")),
    };
    p.validate().map_err(|e| e.to_string())?;
    Ok(p)
}

/// Least-squares deformation gradient of each particle's lattice neighbours (within 1.5 Δx
/// in the reference configuration): F = (Σ x_ij X_ijᵀ)(Σ X_ij X_ijᵀ)⁻¹. None where a neighbour
/// is gone (crater, removed particle), since a one-sided fit says little about volume.
fn geometric_def_grad(p: &Particles, dx: f64) -> Vec<Option<Matrix>> {
    let cell = 1.5 * dx;
    let key = |x: &Vector| ((x.x / cell).floor() as i64, (x.y / cell).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, x) in p.x_ref.iter().enumerate() {
        grid.entry(key(x)).or_default().push(i);
    }
    (0..p.len())
        .map(|i| {
            let (cx, cy) = key(&p.x_ref[i]);
            let mut a = Matrix::zeros();
            let mut b = Matrix::zeros();
            let mut n = 0;
            for gx in cx - 1..=cx + 1 {
                for gy in cy - 1..=cy + 1 {
                    for &j in grid.get(&(gx, gy)).map_or(&[][..], |v| v.as_slice()) {
                        let xr = p.x_ref[j] - p.x_ref[i];
                        let r = xr.norm();
                        if j == i || r > cell {
                            continue;
                        }
                        let xc = p.pos[j] - p.pos[i];
                        a += xc * xr.transpose();
                        b += xr * xr.transpose();
                        n += 1;
                    }
                }
            }
            // A square lattice has 8 neighbours within 1.5 Δx.
            if n < 8 {
                return None;
            }
            b.try_inverse().map(|bi| a * bi)
        })
        .collect()
}

#[derive(Default)]
struct Acc {
    n: usize,
    p_eos: f64,
    p_stress: f64,
    p_inplane: f64,
    rho: f64,
    rho_kin: f64,
    drift: f64,
    drift2: f64,
    abs_drift: f64,
    n_geo: usize,
    rho_geo: f64,
    kin_geo: f64,
    kin_geo2: f64,
    eps_p: f64,
    vm: f64,
}

impl Acc {
    fn row(&self) -> String {
        let n = self.n.max(1) as f64;
        let ng = self.n_geo.max(1) as f64;
        let std = |s: f64, s2: f64, n: f64| (s2 / n - (s / n).powi(2)).max(0.0).sqrt();
        format!(
            "{},{:.6e},{:.6e},{:.6e},{:.4},{:.4},{:.4},{},{:.5},{:.5},{:.5},{:.5},{:.5},{:.6},{:.6e}",
            self.n,
            self.p_eos / n,
            self.p_stress / n,
            self.p_inplane / n,
            self.rho / n,
            self.rho_kin / n,
            self.rho_geo / ng,
            self.n_geo,
            self.drift / n,
            std(self.drift, self.drift2, n),
            self.abs_drift / n,
            self.kin_geo / ng,
            std(self.kin_geo, self.kin_geo2, ng),
            self.eps_p / n,
            self.vm / n,
        )
    }
}

/// Region names and membership by reference position (Dg units, top at y = 0, middle x = 0).
/// `fixed` is the kinematic bands: they do not move, so any change of their ρ or det F is
/// drift of the continuity equation fed by their moving neighbours.
const REGIONS: [&str; 5] = ["all", "band_0.5_0.75", "deep_0.5", "side_0.8", "fixed"];

fn in_region(r: usize, xr: Vector, fixed: bool) -> bool {
    match r {
        0 => !fixed,
        1 => !fixed && xr.y < -0.5 && xr.y >= -0.75,
        2 => !fixed && xr.y < -0.5,
        3 => !fixed && xr.x.abs() > 0.8,
        _ => fixed,
    }
}

fn stats(prm: &ImpactParams, p: &Particles) -> Vec<(&'static str, Acc)> {
    let k = prm.material.bulk_modulus();
    let dg = prm.grain_diameter_m;
    let geo = geometric_def_grad(p, prm.spacing_m);
    let mut accs: Vec<Acc> = REGIONS.iter().map(|_| Acc::default()).collect();
    for (i, f_geo) in geo.iter().enumerate() {
        let fixed = p.flags[i] & KINEMATIC != 0;
        let xr = p.x_ref[i] / dg;
        let pe = p.pressure(i, k);
        let sig = grit_sph::vtk::cauchy_stress_3d(&p.sdev[i], pe);
        let p_stress = -(sig[0][0] + sig[1][1] + sig[2][2]) / 3.0;
        let p_inplane = -(sig[0][0] + sig[1][1]) / 2.0;
        let rho_kin = p.rho0[i] / p.def_grad[i].determinant();
        let drift = p.rho[i] - rho_kin;
        let rho_geo = f_geo.map(|f| p.rho0[i] / f.determinant());
        for (r, a) in accs.iter_mut().enumerate() {
            if !in_region(r, xr, fixed) {
                continue;
            }
            a.n += 1;
            a.p_eos += pe;
            a.p_stress += p_stress;
            a.p_inplane += p_inplane;
            a.rho += p.rho[i];
            a.rho_kin += rho_kin;
            a.drift += drift;
            a.drift2 += drift * drift;
            a.abs_drift += drift.abs();
            a.eps_p += p.eps_p[i];
            a.vm += von_mises(&p.sdev[i]);
            if let Some(rg) = rho_geo {
                let d = rho_kin - rg;
                a.n_geo += 1;
                a.rho_geo += rg;
                a.kin_geo += d;
                a.kin_geo2 += d * d;
            }
        }
    }
    REGIONS.iter().copied().zip(accs).collect()
}

fn run(out: &Path, config: &str, impacts: u32, every: u32, seed: u64) -> Result<(), String> {
    let prm = params(config)?;
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let csv_path = out.join(format!("{config}.csv"));
    let ckpt_path = out.join(format!("{config}.ckpt"));
    let mut sample = match std::fs::read(&ckpt_path) {
        Ok(bytes) => Sample::resume(&prm, seed, &bytes).map_err(|e| e.to_string())?,
        Err(_) => Sample::new(prm.clone(), seed).map_err(|e| e.to_string())?,
    };
    // Keep the rows up to the checkpoint, so a resumed run appends where it left off.
    let done = sample.impacts_done();
    let mut lines = vec![HEADER.to_string()];
    if done > 0 {
        let old = std::fs::read_to_string(&csv_path).unwrap_or_default();
        lines.extend(
            old.lines()
                .skip(1)
                .filter(|l| {
                    l.split(',')
                        .next()
                        .and_then(|x| x.parse::<u32>().ok())
                        .is_some_and(|k| k <= done)
                })
                .map(str::to_string),
        );
    }
    let mut csv = std::fs::File::create(&csv_path).map_err(|e| e.to_string())?;
    writeln!(csv, "{}", lines.join("\n")).map_err(|e| e.to_string())?;
    let mut write_rows = |s: &Sample, steps: u64, wall: f64| -> Result<(), String> {
        let lost: f64 = s.records().iter().map(|r| r.mass_loss_kg).sum();
        let fired: f64 = s.records().iter().map(|r| r.grain_mass_kg).sum();
        let erosion = if fired > 0.0 { lost / fired * 1e3 } else { 0.0 };
        let n_surface = s.surface().len();
        for (name, a) in stats(s.params(), s.surface()) {
            writeln!(
                csv,
                "{},{config},{name},{},{n_surface},{lost:.6e},{erosion:.5},{steps},{wall:.2}",
                s.impacts_done(),
                a.row()
            )
            .map_err(|e| e.to_string())?;
            if name == "band_0.5_0.75" {
                println!(
                    "{config} impact {:>3}: band 0.5-0.75 Dg p {:6.1} MPa, rho {:.2} kin {:.2} \
                     geo {:.2}, erosion {erosion:.3} mg/g, {steps} steps, {wall:.1} s",
                    s.impacts_done(),
                    a.p_eos / a.n.max(1) as f64 / 1e6,
                    a.rho / a.n.max(1) as f64,
                    a.rho_kin / a.n.max(1) as f64,
                    a.rho_geo / a.n_geo.max(1) as f64,
                );
            }
        }
        csv.flush().map_err(|e| e.to_string())
    };
    if done == 0 {
        write_rows(&sample, 0, 0.0)?;
    }
    while sample.impacts_done() < impacts {
        let t = Instant::now();
        let steps = sample.run_next().map_err(|e| e.to_string())?.outcome.steps;
        let wall = t.elapsed().as_secs_f64();
        let k = sample.impacts_done();
        if k % every == 0 || k == impacts {
            write_rows(&sample, steps, wall)?;
            std::fs::write(&ckpt_path, sample.checkpoint()).map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

/// The surface of a checkpoint alone, at rest as an impact starts it, in a world of `settings`.
fn rest_world(
    prm: &ImpactParams,
    surface: &Particles,
    settings: Settings,
) -> Result<World, String> {
    let mut world = World::new(settings).map_err(|e| e.to_string())?;
    let mut state = surface.clone();
    state.vel.iter_mut().for_each(|v| *v = Vector::zeros());
    world
        .add_deformable_state("surface", prm.material.clone(), state, Motion::Fixed)
        .map_err(|e| e.to_string())?;
    Ok(world)
}

/// Separates the density filter's share of the drift from the rest on the surface of
/// `OUT_DIR/<config>.ckpt`, without a grain: one filter pass on the state as it is, and
/// `steps` steps of the surface left alone with the Shepard filter every 40 steps (the engine
/// default, seed eq. 12), with it off, and with the engine's MLS filter instead. Writes
/// `OUT_DIR/probe-<config>-<impact>.csv`.
fn probe(out: &Path, config: &str, steps: u64) -> Result<(), String> {
    let bytes = std::fs::read(out.join(format!("{config}.ckpt"))).map_err(|e| e.to_string())?;
    let sample = Sample::from_checkpoint(&bytes).map_err(|e| e.to_string())?;
    let prm = sample.params().clone();
    let k = sample.impacts_done();
    let cols = HEADER["impact,config,region,".len()..]
        .split(",n_surface")
        .next()
        .unwrap_or_default();
    let mut rows = vec![format!("impact,config,case,region,{cols}")];
    let mut push = |case: &str, p: &Particles| {
        for (name, a) in stats(&prm, p) {
            rows.push(format!("{k},{config},{case},{name},{}", a.row()));
            if name == "band_0.5_0.75" {
                println!(
                    "{config} impact {k} {case:>12}: band p {:6.1} MPa, rho {:.3} kin {:.3} \
                     drift {:.4}",
                    a.p_eos / a.n.max(1) as f64 / 1e6,
                    a.rho / a.n.max(1) as f64,
                    a.rho_kin / a.n.max(1) as f64,
                    a.drift / a.n.max(1) as f64,
                );
            }
        }
    };
    push("start", sample.surface());
    let mut once = rest_world(&prm, sample.surface(), prm.settings())?;
    once.filter_density();
    push("one_filter", once.particles());
    for (case, interval, filter) in [
        ("rest_filter", 40, DensityFilter::Shepard),
        ("rest_nofilter", 0, DensityFilter::Shepard),
        ("rest_mls", 40, DensityFilter::Mls),
    ] {
        let settings = Settings {
            shepard_interval: interval,
            density_filter: filter,
            ..prm.settings()
        };
        let mut w = rest_world(&prm, sample.surface(), settings)?;
        for _ in 0..steps {
            w.step().map_err(|e| e.to_string())?;
        }
        push(case, w.particles());
    }
    let path = out.join(format!("probe-{config}-{k:03}.csv"));
    std::fs::write(&path, rows.join("\n") + "\n").map_err(|e| e.to_string())
}

fn main() {
    let mut args = std::env::args().skip(1);
    let mut out: Option<PathBuf> = None;
    let mut probe_steps: Option<u64> = None;
    let (mut config, mut impacts, mut every, mut seed) = ("small".to_string(), 150u32, 1u32, 1u64);
    let parsed = (|| -> Result<(), String> {
        while let Some(a) = args.next() {
            let mut val = |name: &str| args.next().ok_or(format!("{name} needs a value"));
            match a.as_str() {
                "--config" => config = val("--config")?,
                "--impacts" => {
                    impacts = val("--impacts")?
                        .parse()
                        .map_err(|e| format!("--impacts: {e}"))?
                }
                "--every" => {
                    every = val("--every")?
                        .parse()
                        .map_err(|e| format!("--every: {e}"))?;
                    if every == 0 {
                        return Err("--every must be at least 1".into());
                    }
                }
                "--probe-steps" => {
                    probe_steps = Some(
                        val("--probe-steps")?
                            .parse()
                            .map_err(|e| format!("--probe-steps: {e}"))?,
                    )
                }
                "--seed" => seed = val("--seed")?.parse().map_err(|e| format!("--seed: {e}"))?,
                _ if out.is_none() && !a.starts_with("--") => out = Some(PathBuf::from(a)),
                _ => return Err(format!("unexpected argument {a:?}")),
            }
        }
        Ok(())
    })();
    let result = parsed.and_then(|()| {
        let out = out.ok_or("usage: stored_compression OUT_DIR [--config NAME] [--impacts N] [--every K] [--seed S]")?;
        // One engine thread: the machine is shared, and several configs run side by side.
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .map_err(|e| e.to_string())?;
        pool.install(|| match probe_steps {
            Some(n) => probe(&out, &config, n),
            None => run(&out, &config, impacts, every, seed),
        })
    });
    if let Err(e) = result {
        eprintln!("stored_compression: {e}");
        std::process::exit(1);
    }
}
