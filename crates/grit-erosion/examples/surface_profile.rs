//! Dev aid: the shape of a worn surface. For each checkpoint, the free surface's top in columns
//! one Δx wide across the box: the highest point (the crater's lips or the unworn shoulders),
//! the lowest column top inside the band of aim points (the crater's floor), and the mean
//! recession of the column tops over that band, all in Dg below the fresh surface (y = 0).
//! The grain's flight is skipped only to one kernel reach below the highest point, so the
//! floor's depth below the lips is what a worn surface's impact flies through step by step
//! (docs/performance.md, *The flight over a crater*).
//!
//! `--columns` prints every column's top instead. `--stock` splits the damage stock Σ m D of
//! the free particles by each particle's distance below the surface (to the nearest column top)
//! and by whether it lies under the aim band, beside the length of the surface line: where a
//! worn surface keeps the damage its impacts added and have not yet removed. `--walls` gives
//! the stock within 0.1, 0.25 and 0.5 Dg of the box's fixed bottom and sides: whether the
//! damage reaches the edges the box holds fixed. `--across` gives the stock in strips 0.25 Dg
//! wide across the box. `--removed` gives, for each pair of consecutive checkpoints of one
//! sample, the mass of the particles the later one no longer has, in the same strips, placed
//! where they were in the earlier one: where across the box the loss is made. `--band-depth`
//! splits the stock under the aim band by depth below the surface in Δx: whether a rung's
//! stock is a layer a few particles thick or a physical depth.
//! `--incidence` sweeps the seed's grains (a grid of orientations and aim points, placed as `ImpactParams::grain_start` places them)
//! along their paths onto the column tops and prints, per grain, where it first touches and
//! the angle between its path and the surface there, the slope taken over ±0.1 Dg: how far a
//! trench's local incidence strays from the nominal angle. `--grains FILE` does the same for
//! the grains a campaign fired, read from FILE's rows (checkpoint, unit, orientation_rad,
//! aim_x_m, tab-separated, with a header), each on its checkpoint's surface
//! (notebook/erosion/trench-2026-11-28).
//! `--run ANGLE SPACING_M SAMPLES IMPACTS SEED OUT` runs fresh samples of the ladder's scene
//! (the seed's, on a 3.0 × 1.25 Dg surface with a 1.0 Dg aim band, one thread) and writes, for
//! every impact, where its grain first touched the surface just before it and at what local
//! angle, with its damage added and loss (OUT-impacts.tsv), and every 20 impacts each sample's
//! column tops (OUT-columns.tsv).
//! Usage: `surface_profile [--columns | --incidence | --stock | --walls | --across |
//! --removed | --band-depth] CHECKPOINT…`,
//! `surface_profile --grains FILE` or `surface_profile --run …`.
use grit_erosion::impact::{GrainStart, ImpactParams};
use grit_erosion::{Sample, Shape};
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
    Stock,
    Walls,
    Across,
    BandDepth,
}

/// A fired grain to place on a checkpoint's surface: its impact number, orientation, aim.
struct Fired {
    unit: u32,
    orientation_rad: f64,
    aim_x_m: f64,
}

fn usage() -> ! {
    eprintln!(
        "usage: surface_profile [--columns | --incidence | --stock | --walls | --across | --removed | --band-depth] CHECKPOINT… | --grains FILE | --run …"
    );
    std::process::exit(2);
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mode = match args.first().map(String::as_str) {
        Some("--columns") => Mode::Columns,
        Some("--incidence") => Mode::Incidence,
        Some("--grains") => Mode::Grains,
        Some("--stock") => Mode::Stock,
        Some("--walls") => Mode::Walls,
        Some("--across") => Mode::Across,
        Some("--band-depth") => Mode::BandDepth,
        Some("--removed") => return removed(&args[1..]),
        Some("--run") => return run(&args[1..]),
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
            Mode::Stock => STOCK_HEADER,
            Mode::Walls => WALLS_HEADER,
            Mode::Across => "checkpoint\timpacts\tangle_deg\tx_from_dg\tx_to_dg\tstock",
            Mode::BandDepth => "checkpoint\timpacts\tangle_deg\tppd\tband_line_dg\tfrom_dx\tto_dx\tstock\tmass",
        }
    );
    for (path, fired) in &work {
        let s = load(path);
        let p = s.params();
        let dg = p.grain_diameter_m;
        let tops = column_tops(&s);
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
            Mode::Stock => println!("{path}\t{done}\t{}\t{}", p.angle_deg, stock_row(&s, &tops)),
            Mode::Walls => println!("{path}\t{done}\t{}\t{}", p.angle_deg, walls_row(&s, &tops)),
            Mode::Across => {
                for (from, to, stock) in stock_across(&s) {
                    println!(
                        "{path}\t{done}\t{}\t{from:.2}\t{to:.2}\t{stock:.1}",
                        p.angle_deg
                    );
                }
            }
            Mode::BandDepth => {
                let (band_line, bins) = band_depth(&s, &tops);
                for (from, to, stock, mass) in bins {
                    println!(
                        "{path}\t{done}\t{}\t{:.1}\t{band_line:.3}\t{from}\t{to}\t{stock:.2}\t{mass:.1}",
                        p.angle_deg,
                        dg / p.spacing_m
                    );
                }
            }
            Mode::Summary => {
                let lips = tops.iter().map(|t| t.y).fold(f64::NEG_INFINITY, f64::max);
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

/// Upper edges of the depth bins of `--stock`, in Dg below the surface; the last bin is open.
const STOCK_DEPTHS_DG: [f64; 4] = [0.05, 0.1, 0.2, 0.4];

const STOCK_HEADER: &str = "checkpoint\timpacts\tangle_deg\tline_dg\tband_line_dg\tstock\t\
    band_stock\td<0.05\td<0.1\td<0.2\td<0.4\td>=0.4\tstock_per_line_dg";

/// `--stock`'s columns after the angle: the surface line's length over the box and over the aim
/// band (Dg); the damage stock, all and under the band, then per depth bin, in mg per g of one
/// grain; the stock per Dg of surface line.
fn stock_row(s: &Sample, tops: &[Vector]) -> String {
    let p = s.params();
    let dg = p.grain_diameter_m;
    let per_grain = 1e3 / p.grain_mass_kg_m();
    let reach = 0.5 * p.distribution_range_dg * dg;
    let (line, band_line) = surface_lines(tops, reach);
    let surface = s.surface();
    let (mut stock, mut band_stock) = (0.0, 0.0);
    let mut by_depth = [0.0; STOCK_DEPTHS_DG.len() + 1];
    for i in 0..surface.len() {
        if surface.flags[i] & KINEMATIC != 0 {
            continue;
        }
        let md = surface.mass[i] * surface.damage[i];
        if md == 0.0 {
            continue;
        }
        let x = surface.pos[i];
        let depth = depth_below(tops, x) / dg;
        let bin = STOCK_DEPTHS_DG
            .iter()
            .position(|&edge| depth < edge)
            .unwrap_or(STOCK_DEPTHS_DG.len());
        by_depth[bin] += md;
        stock += md;
        if x.x.abs() <= reach {
            band_stock += md;
        }
    }
    let mut row = format!(
        "{:.3}\t{:.3}\t{:.1}\t{:.1}",
        line / dg,
        band_line / dg,
        stock * per_grain,
        band_stock * per_grain
    );
    for b in by_depth {
        row.push_str(&format!("\t{:.1}", b * per_grain));
    }
    row.push_str(&format!("\t{:.1}", stock * per_grain * dg / line));
    row
}

/// Upper edges of the distance bins of `--walls`, in Dg from the box's fixed bottom or sides.
const WALL_DISTANCES_DG: [f64; 3] = [0.1, 0.25, 0.5];

const WALLS_HEADER: &str = "checkpoint\timpacts\tangle_deg\tfloor_above_bottom_dg\tstock\t\
    bottom<0.1\tbottom<0.25\tbottom<0.5\tsides<0.1\tsides<0.25\tsides<0.5\t\
    sides<0.5_d<0.2\tleft<0.5\tright<0.5\tedges<0.5";

/// `--walls`' columns after the angle: the aim band's lowest column top above the box's bottom
/// (Dg); the damage stock, all, then within each distance of the fixed bottom and of the fixed
/// sides (cumulative), of the last within 0.2 Dg of the surface, and within 0.5 Dg of the
/// left (−x, where a grain at an angle comes from) and the right side, and within 0.5 Dg of
/// any fixed edge (bottom or side; the rest is the interior), in mg per g of one grain:
/// whether the damage reaches the box's edges, and whether it lies deep along them.
fn walls_row(s: &Sample, tops: &[Vector]) -> String {
    let p = s.params();
    let dg = p.grain_diameter_m;
    let per_grain = 1e3 / p.grain_mass_kg_m();
    let reach = 0.5 * p.distribution_range_dg * dg;
    let surface = s.surface();
    let free = || (0..surface.len()).filter(|&i| surface.flags[i] & KINEMATIC == 0);
    let bottom = free()
        .map(|i| surface.pos[i].y)
        .fold(f64::INFINITY, f64::min);
    let left = free()
        .map(|i| surface.pos[i].x)
        .fold(f64::INFINITY, f64::min);
    let right = free()
        .map(|i| surface.pos[i].x)
        .fold(f64::NEG_INFINITY, f64::max);
    let floor = tops
        .iter()
        .filter(|t| t.x.abs() <= reach)
        .map(|t| t.y)
        .fold(f64::INFINITY, f64::min);
    let (mut stock, mut sides_shallow, mut left_side, mut right_side) = (0.0, 0.0, 0.0, 0.0);
    let mut edges = 0.0;
    let (mut near_bottom, mut near_sides) = ([0.0; 3], [0.0; 3]);
    for i in free() {
        let md = surface.mass[i] * surface.damage[i];
        let x = surface.pos[i];
        stock += md;
        let up = (x.y - bottom) / dg;
        let side = (x.x - left).min(right - x.x) / dg;
        for (k, &edge) in WALL_DISTANCES_DG.iter().enumerate() {
            if up < edge {
                near_bottom[k] += md;
            }
            if side < edge {
                near_sides[k] += md;
            }
        }
        if side < WALL_DISTANCES_DG[2] && md > 0.0 && depth_below(tops, x) < 0.2 * dg {
            sides_shallow += md;
        }
        if up.min(side) < WALL_DISTANCES_DG[2] {
            edges += md;
        }
        if (x.x - left) / dg < WALL_DISTANCES_DG[2] {
            left_side += md;
        } else if (right - x.x) / dg < WALL_DISTANCES_DG[2] {
            right_side += md;
        }
    }
    let mut row = format!("{:.3}\t{:.1}", (floor - bottom) / dg, stock * per_grain);
    for b in near_bottom.iter().chain(&near_sides) {
        row.push_str(&format!("\t{:.2}", b * per_grain));
    }
    for b in [sides_shallow, left_side, right_side, edges] {
        row.push_str(&format!("\t{:.2}", b * per_grain));
    }
    row
}

/// Width of `--across`'s strips, in Dg.
const ACROSS_DG: f64 = 0.25;

/// `--across`: the damage stock in vertical strips ACROSS_DG wide from the box's left side
/// (x in Dg from the box's middle, stock in mg per g of one grain): where across the box the
/// stock lies, upstream, under the aim band and downstream.
fn stock_across(s: &Sample) -> Vec<(f64, f64, f64)> {
    let p = s.params();
    let mut stock = vec![0.0; strips(p)];
    let surface = s.surface();
    for i in (0..surface.len()).filter(|&i| surface.flags[i] & KINEMATIC == 0) {
        stock[strip(p, surface.pos[i].x)] += surface.mass[i] * surface.damage[i];
    }
    strip_rows(p, &stock)
}

/// Number of `--across` strips over the box.
fn strips(p: &ImpactParams) -> usize {
    (p.surface_width_dg / ACROSS_DG).ceil() as usize
}

/// The `--across` strip holding abscissa `x` (m from the box's middle).
fn strip(p: &ImpactParams, x: f64) -> usize {
    let k = ((x / p.grain_diameter_m + 0.5 * p.surface_width_dg) / ACROSS_DG).floor();
    (k.max(0.0) as usize).min(strips(p) - 1)
}

/// Per-strip masses (kg/m) as (from, to in Dg from the box's middle, mg per g of one grain).
fn strip_rows(p: &ImpactParams, masses: &[f64]) -> Vec<(f64, f64, f64)> {
    let per_grain = 1e3 / p.grain_mass_kg_m();
    let half = 0.5 * p.surface_width_dg;
    masses
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let from = k as f64 * ACROSS_DG - half;
            (from, from + ACROSS_DG, m * per_grain)
        })
        .collect()
}

/// A checkpoint file's sample.
fn load(path: &str) -> Sample {
    let bytes = std::fs::read(path).expect("read checkpoint");
    Sample::from_checkpoint(&bytes).expect("checkpoint")
}

/// `--removed`: per pair of consecutive checkpoints of one sample (the same seed, more impacts
/// in the later), the mass of the particles whose ids the later one lacks, in strips
/// ACROSS_DG wide at their places in the earlier one (mg per g of one grain). A pair whose
/// seeds differ or whose impacts do not grow is a new sample's start, not a pair.
fn removed(paths: &[String]) {
    if paths.len() < 2 {
        usage();
    }
    println!("checkpoint\timpacts_from\timpacts_to\tangle_deg\tx_from_dg\tx_to_dg\tremoved");
    let mut earlier = load(&paths[0]);
    for (i, path) in paths.iter().enumerate().skip(1) {
        let later = load(path);
        if later.seed() == earlier.seed() && later.impacts_done() > earlier.impacts_done() {
            let p = earlier.params();
            let kept: std::collections::HashSet<u32> = later.surface().id.iter().copied().collect();
            let mut lost = vec![0.0; strips(p)];
            let surface = earlier.surface();
            for j in (0..surface.len()).filter(|&j| !kept.contains(&surface.id[j])) {
                lost[strip(p, surface.pos[j].x)] += surface.mass[j];
            }
            for (from, to, removed) in strip_rows(p, &lost) {
                println!(
                    "{}\t{}\t{}\t{}\t{from:.2}\t{to:.2}\t{removed:.2}",
                    paths[i - 1],
                    earlier.impacts_done(),
                    later.impacts_done(),
                    p.angle_deg
                );
            }
        }
        earlier = later;
    }
}

/// Length of the surface line through the column tops, over the box and over the columns
/// within `reach` of the middle (m).
fn surface_lines(tops: &[Vector], reach: f64) -> (f64, f64) {
    let (mut line, mut band_line) = (0.0, 0.0);
    for w in tops.windows(2) {
        let l = (w[1] - w[0]).norm();
        line += l;
        if 0.5 * (w[0].x + w[1].x).abs() <= reach {
            band_line += l;
        }
    }
    (line, band_line)
}

/// Upper edges of `--band-depth`'s bins in Δx below the surface, centred on the lattice's
/// layers near the top; the last bin is open.
const BAND_DEPTHS_DX: [f64; 10] = [0.5, 1.5, 2.5, 3.5, 5.0, 8.0, 12.0, 16.0, 24.0, 32.0];

/// `--band-depth`: the surface line's length over the aim band (Dg) and, per depth bin, the
/// damage stock Σ m D and the mass Σ m of the free particles under the band (|x| within half
/// the aim range), as (from, to in Δx, stock, mass, both in mg per g of one grain; their ratio
/// is the bin's mean damage); the last bin's upper edge is infinite.
fn band_depth(s: &Sample, tops: &[Vector]) -> (f64, Vec<(f64, f64, f64, f64)>) {
    let p = s.params();
    let dg = p.grain_diameter_m;
    let per_grain = 1e3 / p.grain_mass_kg_m();
    let reach = 0.5 * p.distribution_range_dg * dg;
    let (_, band_line) = surface_lines(tops, reach);
    let mut stock = [0.0; BAND_DEPTHS_DX.len() + 1];
    let mut mass = [0.0; BAND_DEPTHS_DX.len() + 1];
    let surface = s.surface();
    for i in (0..surface.len()).filter(|&i| surface.flags[i] & KINEMATIC == 0) {
        let x = surface.pos[i];
        if x.x.abs() > reach {
            continue;
        }
        let depth = depth_below(tops, x) / p.spacing_m;
        let bin = BAND_DEPTHS_DX
            .iter()
            .position(|&edge| depth < edge)
            .unwrap_or(BAND_DEPTHS_DX.len());
        stock[bin] += surface.mass[i] * surface.damage[i];
        mass[bin] += surface.mass[i];
    }
    let bins = stock
        .iter()
        .zip(&mass)
        .enumerate()
        .map(|(k, (md, m))| {
            let from = if k == 0 { 0.0 } else { BAND_DEPTHS_DX[k - 1] };
            let to = BAND_DEPTHS_DX.get(k).copied().unwrap_or(f64::INFINITY);
            (from, to, md * per_grain, m * per_grain)
        })
        .collect();
    (band_line / dg, bins)
}

/// Distance from `x` to the nearest column top: its depth below the worn surface.
fn depth_below(tops: &[Vector], x: Vector) -> f64 {
    tops.iter()
        .map(|t| (t - x).norm())
        .fold(f64::INFINITY, f64::min)
}

/// The free surface's highest point per column one Δx wide, as (column centre, top) points;
/// empty columns are left out.
fn column_tops(s: &Sample) -> Vec<Vector> {
    let p = s.params();
    let dx = p.spacing_m;
    let half = 0.5 * p.surface_width_dg * p.grain_diameter_m;
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
    top.iter()
        .enumerate()
        .filter(|(_, t)| t.is_finite())
        .map(|(c, t)| Vector::new((c as f64 + 0.5) * dx - half, *t))
        .collect()
}

/// `--run`: fresh samples, each impact's touch and local angle on the surface just before it.
fn run(args: &[String]) {
    let [angle, spacing, samples, impacts, seed, out] = args else {
        eprintln!("usage: surface_profile --run ANGLE SPACING_M SAMPLES IMPACTS SEED OUT");
        std::process::exit(2);
    };
    let num = |v: &str, what: &str| -> f64 {
        v.parse()
            .unwrap_or_else(|_| panic!("{what} must be a number, got {v}"))
    };
    let mut params = ImpactParams::paper(num(angle, "ANGLE"), Shape::Hexagon);
    params.spacing_m = num(spacing, "SPACING_M");
    params.distribution_range_dg = 1.0;
    params.surface_width_dg = 3.0;
    params.surface_depth_dg = 1.25;
    let (samples, impacts) = (
        num(samples, "SAMPLES") as u64,
        num(impacts, "IMPACTS") as u32,
    );
    let seed = num(seed, "SEED") as u64;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let mut rows = String::from("sample\timpact\tangle_deg\taim_dg\tcontact_x_dg\tcontact_y_dg\tlocal_deg\tdamage_mg_g\tloss_mg_g\n");
    let mut cols = String::from("sample\timpacts\tangle_deg\tx_dg\ttop_dg\n");
    let dg = params.grain_diameter_m;
    for k in 0..samples {
        let mut s = Sample::new(params.clone(), seed + k).expect("sample");
        for n in 0..impacts {
            let tops = column_tops(&s);
            if n % 20 == 0 {
                for t in &tops {
                    cols += &format!("{k}\t{n}\t{angle}\t{:.4}\t{:.4}\n", t.x / dg, t.y / dg);
                }
            }
            let grain = s.next_grain().expect("grain");
            let touched = touch(s.params(), &tops, &grain);
            let record = pool.install(|| s.run_next()).expect("impact").clone();
            let per_g = 1e3 / record.grain_mass_kg;
            if let Some(t) = touched {
                rows += &format!(
                    "{k}\t{}\t{angle}\t{t}\t{:.5}\t{:.5}\n",
                    record.impact,
                    record.outcome.damage_added_kg.unwrap_or(f64::NAN) * per_g,
                    record.mass_loss_kg * per_g
                );
            }
        }
        eprintln!("sample {k}: {impacts} impacts");
        std::fs::write(format!("{out}-impacts.tsv"), &rows).expect("write impacts");
        std::fs::write(format!("{out}-columns.tsv"), &cols).expect("write columns");
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
