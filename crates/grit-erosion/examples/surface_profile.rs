//! Dev aid: the shape of a worn surface. For each checkpoint, the free surface's top in columns
//! one Δx wide across the box: the highest point (the crater's lips or the unworn shoulders),
//! the lowest column top inside the band of aim points (the crater's floor), and the mean
//! recession of the column tops over that band, all in Dg below the fresh surface (y = 0).
//! The grain's flight is skipped only to one kernel reach below the highest point, so the
//! floor's depth below the lips is what a worn surface's impact flies through step by step
//! (docs/performance.md, *The flight over a crater*).
//!
//! `--columns` prints every column's top instead. `--incidence` sweeps the seed's grains
//! (a grid of orientations and aim points, placed as `ImpactParams::grain_start` places them)
//! along their paths onto the column tops and prints, per grain, where it first touches and
//! the angle between its path and the surface there, the slope taken over ±0.1 Dg: how far a
//! trench's local incidence strays from the nominal angle. `--grains FILE` does the same for
//! the grains a campaign fired, read from FILE's rows (checkpoint, unit, orientation_rad,
//! aim_x_m, tab-separated, with a header), each on its checkpoint's surface
//! (notebook/erosion/trench-2026-11-28).
//! Usage: `surface_profile [--columns | --incidence] CHECKPOINT…` or
//! `surface_profile --grains FILE`.
use grit_erosion::impact::{GrainStart, ImpactParams};
use grit_erosion::Sample;
use grit_sph::particles::KINEMATIC;
use grit_sph::Vector;

/// Orientations and aim points of the incidence sweep (a 12 × 24 grid of the two uniforms).
const ORIENTATIONS: usize = 12;
const AIMS: usize = 24;
/// Half-width of the line fitted to the column tops for the local slope, in Dg.
const SLOPE_HALF_WIDTH_DG: f64 = 0.1;

#[derive(PartialEq)]
enum Mode {
    Summary,
    Columns,
    Incidence,
    Grains,
}

/// A fired grain to place on a checkpoint's surface: its impact number, orientation, aim.
struct Fired {
    unit: u32,
    orientation_rad: f64,
    aim_x_m: f64,
}

fn usage() -> ! {
    eprintln!("usage: surface_profile [--columns | --incidence] CHECKPOINT… | --grains FILE");
    std::process::exit(2);
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mode = match args.first().map(String::as_str) {
        Some("--columns") => Mode::Columns,
        Some("--incidence") => Mode::Incidence,
        Some("--grains") => Mode::Grains,
        _ => Mode::Summary,
    };
    if mode != Mode::Summary {
        args.remove(0);
    }
    // Checkpoints in order, each with the fired grains to place on it (`--grains` only).
    let mut work: Vec<(String, Vec<Fired>)> = Vec::new();
    if mode == Mode::Grains {
        let [file] = args.as_slice() else { usage() };
        let text = std::fs::read_to_string(file).expect("read grains file");
        for line in text.lines().skip(1) {
            let f: Vec<&str> = line.split('\t').collect();
            let [path, unit, orientation, aim] = f.as_slice() else {
                panic!("grains row needs 4 tab-separated fields: {line}")
            };
            let fired = Fired {
                unit: unit.parse().expect("unit"),
                orientation_rad: orientation.parse().expect("orientation_rad"),
                aim_x_m: aim.parse().expect("aim_x_m"),
            };
            match work.last_mut() {
                Some((p, v)) if p == path => v.push(fired),
                _ => work.push((path.to_string(), vec![fired])),
            }
        }
    } else {
        work = args.into_iter().map(|p| (p, Vec::new())).collect();
    }
    if work.is_empty() {
        usage();
    }
    println!(
        "{}",
        match mode {
            Mode::Summary =>
                "checkpoint\timpacts\tlips_dg\tfloor_dg\tband_recession_dg\tfloor_below_lips_dg",
            Mode::Columns => "checkpoint\timpacts\tangle_deg\tx_dg\ttop_dg",
            Mode::Incidence =>
                "checkpoint\timpacts\tangle_deg\taim_dg\tcontact_x_dg\tcontact_y_dg\tlocal_deg",
            Mode::Grains =>
                "checkpoint\tunit\timpacts\tangle_deg\taim_dg\tcontact_x_dg\tcontact_y_dg\tlocal_deg",
        }
    );
    for (path, fired) in &work {
        let bytes = std::fs::read(path).expect("read checkpoint");
        let s = Sample::from_checkpoint(&bytes).expect("checkpoint");
        let p = s.params();
        let (dg, dx) = (p.grain_diameter_m, p.spacing_m);
        let half = 0.5 * p.surface_width_dg * dg;
        let columns = (2.0 * half / dx).ceil() as usize;
        let mut top = vec![f64::NEG_INFINITY; columns];
        let surface = s.surface();
        for (x, flags) in surface.pos.iter().zip(&surface.flags) {
            if flags & KINEMATIC != 0 {
                continue;
            }
            let c = (((x.x + half) / dx).floor().max(0.0) as usize).min(columns - 1);
            top[c] = top[c].max(x.y);
        }
        let centre = |c: usize| (c as f64 + 0.5) * dx - half;
        let tops: Vec<Vector> = top
            .iter()
            .enumerate()
            .filter(|(_, t)| t.is_finite())
            .map(|(c, t)| Vector::new(centre(c), *t))
            .collect();
        let done = s.impacts_done();
        match mode {
            Mode::Columns => {
                for t in &tops {
                    println!(
                        "{path}\t{done}\t{}\t{:.4}\t{:.4}",
                        p.angle_deg,
                        t.x / dg,
                        t.y / dg
                    );
                }
            }
            Mode::Incidence => {
                for i in 0..ORIENTATIONS {
                    for j in 0..AIMS {
                        let u_angle = (i as f64 + 0.5) / ORIENTATIONS as f64;
                        let u_aim = (j as f64 + 0.5) / AIMS as f64;
                        let g = p.grain_start(u_angle, u_aim).expect("grain");
                        if let Some(row) = touch(p, &tops, &g) {
                            println!("{path}\t{done}\t{}\t{row}", p.angle_deg);
                        }
                    }
                }
            }
            Mode::Grains => {
                for f in fired {
                    let u_angle = f.orientation_rad / std::f64::consts::TAU;
                    let u_aim = f.aim_x_m / (p.distribution_range_dg * dg) + 0.5;
                    let g = p.grain_start(u_angle, u_aim).expect("grain");
                    if let Some(row) = touch(p, &tops, &g) {
                        println!("{path}\t{}\t{done}\t{}\t{row}", f.unit, p.angle_deg);
                    }
                }
            }
            Mode::Summary => {
                let lips = top.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                // The aim band's columns: centres within half the distribution range of the middle.
                let reach = 0.5 * p.distribution_range_dg * dg;
                let band: Vec<f64> = tops
                    .iter()
                    .filter(|t| t.x.abs() <= reach)
                    .map(|t| t.y)
                    .collect();
                let floor = band.iter().copied().fold(f64::INFINITY, f64::min);
                let mean = band.iter().sum::<f64>() / band.len() as f64;
                println!(
                    "{path}\t{done}\t{:.3}\t{:.3}\t{:.3}\t{:.3}",
                    lips / dg,
                    floor / dg,
                    -mean / dg,
                    (lips - floor) / dg
                );
            }
        }
    }
}

/// Where grain `g` first touches the column tops and the angle its path makes with the
/// surface's slope there, as the tab-separated aim, touch x and y (Dg) and angle (degrees).
fn touch(p: &ImpactParams, tops: &[Vector], g: &GrainStart) -> Option<String> {
    let dg = p.grain_diameter_m;
    let dir = g.velocity_m_s.normalize();
    let hit = first_touch(g.polygon.vertices(), dir, tops)?;
    let slope = local_slope(tops, hit.x, SLOPE_HALF_WIDTH_DG * dg);
    let tangent = Vector::new(1.0, slope).normalize();
    let local = (dir.x * tangent.y - dir.y * tangent.x).abs().asin();
    Some(format!(
        "{:.4}\t{:.4}\t{:.4}\t{:.2}",
        g.aim_x_m / dg,
        hit.x / dg,
        hit.y / dg,
        local.to_degrees()
    ))
}

/// The surface point the polygon, moving along `dir`, reaches first: each point cast back
/// along −dir onto the polygon's edges; the shortest cast wins.
fn first_touch(poly: &[Vector], dir: Vector, points: &[Vector]) -> Option<Vector> {
    let mut best: Option<(f64, Vector)> = None;
    for &q in points {
        for (k, &a) in poly.iter().enumerate() {
            let e = poly[(k + 1) % poly.len()] - a;
            // q − s·dir = a + u·e, i.e. s·dir + u·e = q − a, for s ≥ 0 and u in [0, 1].
            let det = dir.x * e.y - dir.y * e.x;
            if det.abs() < 1e-300 {
                continue;
            }
            let r = q - a;
            let s = (r.x * e.y - r.y * e.x) / det;
            let u = (dir.x * r.y - dir.y * r.x) / det;
            if s >= 0.0 && (0.0..=1.0).contains(&u) && best.is_none_or(|(b, _)| s < b) {
                best = Some((s, q));
            }
        }
    }
    best.map(|(_, q)| q)
}

/// Least-squares slope of the column tops within `half_width` of `x`.
fn local_slope(tops: &[Vector], x: f64, half_width: f64) -> f64 {
    let near: Vec<&Vector> = tops
        .iter()
        .filter(|t| (t.x - x).abs() <= half_width)
        .collect();
    let n = near.len() as f64;
    let (mx, my) = (
        near.iter().map(|t| t.x).sum::<f64>() / n,
        near.iter().map(|t| t.y).sum::<f64>() / n,
    );
    let sxy: f64 = near.iter().map(|t| (t.x - mx) * (t.y - my)).sum();
    let sxx: f64 = near.iter().map(|t| (t.x - mx).powi(2)).sum();
    if sxx > 0.0 {
        sxy / sxx
    } else {
        0.0
    }
}
