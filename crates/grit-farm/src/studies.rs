//! `grit bench stability` and `grit bench sweep`: the numerical studies of issue 5, run locally
//! on this machine's threads, each writing a CSV, a JSON copy and a chart.

use std::path::{Path, PathBuf};

use grit_erosion::aggregate::SLOPE_WINDOW;
use grit_erosion::stability::{self, Panel, StabilityGrid, StabilityPoint, Verdict};
use grit_erosion::sweep::{cheapest_within, Cost, SweepRow, Variant};
use grit_erosion::{ImpactParams, Shape};
use indicatif::{ProgressBar, ProgressStyle};

/// Writes `rows` as `out/stem.csv` (one header row, serde field names).
pub fn write_csv<T: serde::Serialize>(
    out: &Path,
    stem: &str,
    rows: &[T],
) -> Result<PathBuf, String> {
    let path = out.join(format!("{stem}.csv"));
    let mut w = csv::Writer::from_path(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    for r in rows {
        w.serialize(r)
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    w.flush().map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}

/// Writes `value` as pretty JSON to `out/stem.json`.
pub fn write_json<T: serde::Serialize>(
    out: &Path,
    stem: &str,
    value: &T,
) -> Result<PathBuf, String> {
    let path = out.join(format!("{stem}.json"));
    let text = serde_json::to_string_pretty(value).expect("serialises");
    std::fs::write(&path, text + "\n").map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}

fn bar(len: u64, prefix: &str) -> ProgressBar {
    let style =
        ProgressStyle::with_template("{prefix:>12} {wide_bar} {pos}/{len} {elapsed_precise} {msg}")
            .expect("valid template");
    let b = ProgressBar::new(len).with_style(style);
    b.set_prefix(prefix.to_string());
    b
}

/// What `grit bench stability` is asked to do.
#[derive(Debug, Clone)]
pub struct StabilityArgs {
    /// The scene (angle, spacing; numerics are swept).
    pub params: ImpactParams,
    /// Seed of the sample the grain is drawn from.
    pub seed: u64,
    /// Impacts the surface takes before the mapped one.
    pub after: u32,
    /// The grid.
    pub grid: StabilityGrid,
    /// Step budget over the longest impact at the first step's dt.
    pub budget_factor: f64,
    /// Output folder.
    pub out: PathBuf,
}

/// One line per panel row: the verdict of each Courant number, as a text map.
pub fn stability_table(points: &[StabilityPoint]) -> String {
    let mut s = String::new();
    for panel in [
        Panel::CflHourglass,
        Panel::StiffnessStep,
        Panel::StiffnessStepPenetration,
    ] {
        let pts: Vec<&StabilityPoint> = points.iter().filter(|p| p.panel == panel).collect();
        if pts.is_empty() {
            continue;
        }
        let y = |p: &StabilityPoint| panel.y(p);
        let cfl = stability::levels(pts.iter().map(|p| p.cfl));
        let ys = stability::levels(pts.iter().map(|p| y(p)));
        let (name, yname) = match panel {
            Panel::CflHourglass => ("Courant number × hourglass α, seed contact", "α"),
            Panel::StiffnessStep => ("stiffness × step, seed contact", "k/k0"),
            Panel::StiffnessStepPenetration => ("stiffness × step, penetration contact", "k/k0"),
        };
        s.push_str(&format!("{name}\n{yname:>8} |"));
        for c in &cfl {
            s.push_str(&format!(" {c:>5}"));
        }
        s.push('\n');
        for yv in ys.iter().rev() {
            s.push_str(&format!("{yv:>8} |"));
            for c in &cfl {
                let mark = pts
                    .iter()
                    .find(|p| p.cfl == *c && y(p) == *yv)
                    .map(|p| match p.verdict {
                        Verdict::Stable => "ok".to_string(),
                        Verdict::EnergyGain => "E+".to_string(),
                        Verdict::Unstable => format!("x:{}", p.failure.map_or("?", |f| f.code())),
                    })
                    .unwrap_or_default();
                s.push_str(&format!(" {mark:>5}"));
            }
            s.push('\n');
        }
        s.push('\n');
    }
    s.push_str(&format!(
        "ok stable · E+ finished, but energy rose above {}× · x: unstable ({})\n",
        stability::ENERGY_GAIN_LIMIT,
        stability::Failure::legend()
    ));
    s
}

/// Runs the stability map and writes `stability.csv`, `.json`, `.png` and `.svg` into `out`.
pub fn stability(a: &StabilityArgs) -> Result<Vec<StabilityPoint>, String> {
    a.grid.validate()?;
    a.params
        .validate()
        .map_err(|e| format!("{}: {}", e.field, e.rule))?;
    if !(a.budget_factor.is_finite() && a.budget_factor > 0.0) {
        return Err(format!("--budget: must be > 0, got {}", a.budget_factor));
    }
    std::fs::create_dir_all(&a.out).map_err(|e| format!("--out {}: {e}", a.out.display()))?;
    if a.after > 0 {
        eprintln!(
            "preparing the surface: {} impacts with the scene's own numerics",
            a.after
        );
    }
    let from = stability::start(&a.params, a.seed, a.after).map_err(|e| e.to_string())?;
    let todo = a.grid.points();
    let pb = bar(todo.len() as u64, "stability");
    let mut points = Vec::with_capacity(todo.len());
    for (panel, n) in todo {
        pb.set_message(format!(
            "{:?}: cfl {} α {} k×{} {:?}",
            panel, n.engine.cfl, n.engine.hourglass, n.contact_stiffness_scale, n.contact_model
        ));
        let p = stability::run_point(&from, panel, n.clone(), a.budget_factor)
            .map_err(|e| e.to_string())?;
        pb.inc(1);
        progress_line(
            &pb,
            &format!(
                "{}/{} {:?}: cfl {} α {} k×{}: {:?}{}",
                pb.position(),
                pb.length().unwrap_or(0),
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
        points.push(p);
    }
    pb.finish_and_clear();
    write_csv(&a.out, "stability", &points)?;
    write_json(&a.out, "stability", &points)?;
    let notes = vec![format!(
        "Scene: hexagon at {}°, {} m/s, AISI 304, Δx = {:e} m ({:.0} particles per Dg), one impact on a surface after {} impacts, seed {}.",
        a.params.angle_deg,
        a.params.velocity_m_s,
        a.params.spacing_m,
        a.params.grain_diameter_m / a.params.spacing_m,
        a.after,
        a.seed
    )];
    grit_plot::stability_chart(&points, &a.out, "stability", &notes).map_err(|e| e.to_string())?;
    Ok(points)
}

/// Prints one line of progress above the bar, or on its own where the bar is hidden (output not
/// a terminal, as in a log file), since a hidden bar prints nothing.
fn progress_line(pb: &ProgressBar, line: &str) {
    if pb.is_hidden() {
        println!("{line}");
    } else {
        pb.println(line);
    }
}

/// The reference scene of issue 5 at another spacing and angle.
pub fn scene(angle_deg: f64, spacing_m: f64) -> ImpactParams {
    ImpactParams {
        spacing_m,
        ..ImpactParams::paper(angle_deg, Shape::Hexagon)
    }
}

/// What `grit bench sweep` is asked to do.
#[derive(Debug, Clone)]
pub struct SweepArgs {
    /// The scene (angle; spacing and numerics are swept).
    pub params: ImpactParams,
    /// Particles per grain diameter.
    pub ppd: Vec<f64>,
    /// Numerical variants; the first is the reference whose finest row judges the others.
    pub variants: Vec<Variant>,
    /// Resolutions the variants after the first run at (all of `ppd` when empty).
    pub variant_ppd: Vec<f64>,
    /// Samples per resolution.
    pub samples: u32,
    /// Impacts per sample.
    pub impacts: u32,
    /// Seed of sample 0 (sample k uses seed + k).
    pub seed: u64,
    /// Output folder.
    pub out: PathBuf,
    /// Keep the rows of OUT/sweep.json and run only the missing (variant, resolution) points.
    pub resume: bool,
}

/// Runs the sweep and writes `sweep.csv`, `sweep.json` and the chart `speed-accuracy.png`/`.svg`
/// into `out`; rows are written after every resolution, so an interrupted sweep keeps what it
/// finished.
pub fn sweep(a: &SweepArgs) -> Result<Vec<SweepRow>, String> {
    if a.ppd.is_empty() || a.ppd.iter().any(|p| !(p.is_finite() && *p >= 6.0)) {
        return Err("--ppd: give resolutions of at least 6 particles per Dg".into());
    }
    if a.variants.is_empty() {
        return Err("--variants: give at least one".into());
    }
    if a.samples < 2 {
        return Err(format!(
            "--samples: at least 2 for error bars, got {}",
            a.samples
        ));
    }
    if (a.impacts as usize) < SLOPE_WINDOW + 1 {
        return Err(format!(
            "--impacts: at least {} (the last-{SLOPE_WINDOW} slope), got {}",
            SLOPE_WINDOW + 1,
            a.impacts
        ));
    }
    a.params
        .validate()
        .map_err(|e| format!("{}: {}", e.field, e.rule))?;
    std::fs::create_dir_all(&a.out).map_err(|e| format!("--out {}: {e}", a.out.display()))?;
    let mut plan: Vec<(Variant, f64)> = Vec::new();
    for (k, v) in a.variants.iter().enumerate() {
        let list = if k == 0 || a.variant_ppd.is_empty() {
            &a.ppd
        } else {
            &a.variant_ppd
        };
        plan.extend(list.iter().map(|p| (*v, *p)));
    }
    let mut rows: Vec<SweepRow> = Vec::new();
    if a.resume {
        let path = a.out.join("sweep.json");
        if path.exists() {
            let text =
                std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            rows = serde_json::from_str(&text)
                .map_err(|e| format!("{}: not a sweep file to resume: {e}", path.display()))?;
            let clash = rows
                .iter()
                .find(|r| r.samples != a.samples || r.impacts != a.impacts);
            if let Some(r) = clash {
                return Err(format!(
                    "--resume: {} has {} samples × {} impacts at {} per Dg, this run asks for {} × {}",
                    path.display(),
                    r.samples,
                    r.impacts,
                    r.particles_per_dg,
                    a.samples,
                    a.impacts
                ));
            }
        }
    }
    plan.retain(|(v, p)| {
        !rows
            .iter()
            .any(|r| r.variant == v.name() && r.particles_per_dg == *p)
    });
    let pb = bar(plan.len() as u64 * (a.samples * a.impacts) as u64, "sweep");
    for (v, ppd) in plan {
        pb.set_message(format!("{} at {ppd} per Dg", v.name()));
        let tick = || pb.inc(1);
        let row = grit_erosion::sweep::run_resolution(
            &a.params, v, ppd, a.samples, a.impacts, a.seed, &tick,
        )
        .map_err(|e| format!("{} at {ppd} per Dg: {e}", v.name()))?;
        progress_line(&pb, &sweep_line(&row));
        rows.push(row);
        write_csv(&a.out, "sweep", &rows)?;
        write_json(&a.out, "sweep", &rows)?;
    }
    pb.finish_and_clear();
    // Also when --resume found nothing left to run: the files then match the rows.
    write_csv(&a.out, "sweep", &rows)?;
    write_json(&a.out, "sweep", &rows)?;
    let mut notes = vec![format!(
        "Scene: {} at {}°, {} m/s, AISI 304; {} samples × {} impacts per point, seeds {}–{}; erosion = last-{SLOPE_WINDOW} slope.",
        a.params.shape.name(),
        a.params.angle_deg,
        a.params.velocity_m_s,
        a.samples,
        a.impacts,
        a.seed,
        a.seed + a.samples as u64 - 1
    )];
    if let Some(best) = cheapest_within(&rows) {
        notes.push(format!(
            "Cheapest within the finest's bars: {} at {} per Dg ({:.3} s per impact, {}).",
            best.variant,
            best.particles_per_dg,
            Cost::of(&rows).get(best),
            Cost::of(&rows).label()
        ));
    }
    grit_plot::sweep_chart(&rows, &a.out, "speed-accuracy", &notes).map_err(|e| e.to_string())?;
    Ok(rows)
}

/// One line of the sweep table.
pub fn sweep_line(r: &SweepRow) -> String {
    let mg = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{:.3}", x * 1e3));
    format!(
        "{:<24} {:>5} per Dg (depth {:.2} Dg)  {:>6} particles  {:>7.0} steps  {:>8.3} s/impact ({} CPU-s)  erosion {} ± {} (se {}) mg/g, {}/{} samples with loss  Hertz p0 error {}",
        r.variant,
        r.particles_per_dg,
        r.surface_depth_dg,
        r.particles,
        r.steps_per_impact,
        r.wall_per_impact_s,
        r.cpu_per_impact_s.map_or("–".to_string(), |c| format!("{c:.3}")),
        mg(r.erosion_mean),
        mg(r.erosion_std),
        mg(r.erosion_sem),
        r.samples_with_loss,
        r.samples,
        r.hertz_p0_error
            .map_or_else(|| r.hertz_failure.clone().unwrap_or_default(), |e| format!("{:.1} % at {} per radius", e * 100.0, r.hertz_per_radius))
    )
}
