//! `grit plot RESULTS.json --out DIR`: the charts of a results file (grit-plot), a summary
//! table and the list of files written; and the line charts of `grit verify`: simulation
//! curves solid, analytic references dashed.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::anyhow;
use clap::Args as ClapArgs;
use grit_sph::verification::Chart;
use plotters::prelude::*;

/// Arguments of `grit plot`.
#[derive(ClapArgs)]
pub struct Args {
    /// Results JSON from `grit run` (OUT/results.json) or `grit results -o FILE`; per-sample
    /// curves need the raw series (`--raw` on either). A fit document (`grit fit -o`) is drawn
    /// as the fitted model through its cells, against speed and against angle. Several files are drawn as one; a cell
    /// (angle, shape) an earlier file already has is left out. Files from `grit jet -o` are
    /// gathered into cells (equal parameters; seeds are samples) and drawn as a jet campaign.
    #[arg(required = true)]
    pub results: Vec<PathBuf>,
    /// Folder for the PNG and SVG charts (default: the first results file's folder).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Draw the files as a resolution ladder instead: each cell's erosion against particles
    /// per grain diameter, one file per spacing (`erosion_vs_resolution`), and print its table.
    #[arg(long)]
    pub resolution: bool,
}

/// Arguments of `grit compare`.
#[derive(ClapArgs)]
pub struct CompareArgs {
    /// Results JSON files, merged as `grit plot` merges them (a cell an earlier file already
    /// has is left out of the Oka and shape tables); a cell that several files have is also
    /// listed per file, against the first file's (a resolution or box check).
    #[arg(required = true)]
    pub results: Vec<PathBuf>,
    /// Print the comparison as JSON instead of Markdown tables.
    #[arg(long)]
    pub json: bool,
    /// Take every cell's erosion over the same impacts FIRST-LAST (e.g. `81-100`), as the slope
    /// of its mean series, instead of each sample's last 20: the seed's fixed-count basis for
    /// cells that ran to different counts.
    #[arg(long, value_name = "FIRST-LAST", value_parser = parse_window)]
    pub window: Option<(usize, usize)>,
}

/// Parses `FIRST-LAST`, two impact numbers.
fn parse_window(s: &str) -> Result<(usize, usize), String> {
    let bad = || format!("`{s}`: expected FIRST-LAST, two impact numbers such as 81-100");
    let (a, b) = s.split_once('-').ok_or_else(bad)?;
    let (a, b) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    Ok((a, b))
}

/// Prints the results beside Oka's g(α) and the seed's shape ratios, and any cell that several
/// files have side by side (`grit_erosion::models::compare`).
pub fn compare(a: CompareArgs) -> anyhow::Result<ExitCode> {
    let inputs = a
        .results
        .iter()
        .map(|p| Ok((p.display().to_string(), grit_plot::load(p)?)))
        .collect::<Result<Vec<_>, grit_plot::PlotError>>()?;
    let mut window_notes = Vec::new();
    let inputs = match a.window {
        None => inputs,
        Some((first, last)) => inputs
            .into_iter()
            .map(|(name, mut input)| {
                let (r, notes) =
                    grit_erosion::models::compare::on_window(&input.results, first, last)
                        .map_err(|e| anyhow!("{name}: {e}"))?;
                if r.cells.is_empty() {
                    return Err(anyhow!(
                        "--window {first}-{last}: no cell of {name} has those impacts ({})",
                        notes.join("; ")
                    ));
                }
                input.results = r;
                window_notes.extend(notes.into_iter().map(|n| format!("{name}: {n}")));
                Ok((name, input))
            })
            .collect::<anyhow::Result<Vec<_>>>()?,
    };
    if let Some((first, last)) = a.window {
        if !a.json {
            println!("Every cell's erosion is the slope of its mean series over impacts {first}-{last} (not the last 20 of each sample); standard errors of independent increments.\n");
        }
    }
    let named: Vec<_> = inputs
        .iter()
        .map(|(n, i)| (n.clone(), &i.results))
        .collect();
    let repeated = grit_erosion::models::compare::repeated_cells(&named);
    let (input, notes) = grit_plot::merge(inputs)?;
    let mut c = grit_erosion::models::compare::compare(&input.results);
    c.repeated = repeated;
    let mut o = std::io::stdout().lock();
    if a.json {
        let _ = writeln!(o, "{}", serde_json::to_string_pretty(&c)?);
    } else {
        let _ = write!(o, "{}", grit_erosion::models::compare::markdown(&c));
        let running: Vec<String> = input
            .results
            .cells
            .iter()
            .filter(|c| c.partial)
            .map(|c| format!("{}° {}", c.angle_deg, c.shape))
            .collect();
        if !running.is_empty() {
            let _ = writeln!(
                o,
                "note: interim results: {} still running ({}); their rows, marked partial, are what their finished samples give so far",
                running.len(),
                running.join(", ")
            );
        }
        for n in window_notes.into_iter().chain(notes) {
            let _ = writeln!(o, "note: {n}");
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Draws the charts and prints the table, the notes and the files written.
pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| match a.results[0].parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        });
    if a.resolution {
        let files = a
            .results
            .iter()
            .map(|p| Ok((p.display().to_string(), grit_plot::load(p)?.results)))
            .collect::<Result<Vec<_>, grit_plot::PlotError>>()?;
        let points = grit_plot::ladder(&files)?;
        let report = grit_plot::plot_ladder(&points, &out)?;
        let mut o = std::io::stdout().lock();
        let _ = write!(o, "{}", grit_plot::ladder_table(&points));
        print_report(&mut o, &[], &report);
        return Ok(ExitCode::SUCCESS);
    }
    // A fit document from `grit fit -o` is drawn as its model through its cells.
    if let [one] = a.results.as_slice() {
        if let Some(doc) = fit_document(one) {
            let report = grit_plot::plot_fit(&doc.fit, &out)?;
            print_report(&mut std::io::stdout().lock(), &[], &report);
            return Ok(ExitCode::SUCCESS);
        }
    }
    // Single `grit jet` runs are gathered into cells and drawn as a jet campaign.
    if let Some(r) = grit_plot::load_jet_runs(&a.results)? {
        return draw_jet(&r, &out);
    }
    // A jet campaign's results have their own charts, drawn one file at a time.
    if let [one] = a.results.as_slice() {
        if let grit_plot::AnyInput::Jet(r) = grit_plot::load_any(one)? {
            return draw_jet(&r, &out);
        }
    }
    let inputs = a
        .results
        .iter()
        .map(|p| Ok((p.display().to_string(), grit_plot::load(p)?)))
        .collect::<Result<Vec<_>, grit_plot::PlotError>>()?;
    let (input, merge_notes) = grit_plot::merge(inputs)?;
    let report = grit_plot::plot(&input, &out)?;
    let mut o = std::io::stdout().lock();
    let _ = write!(o, "{}", grit_plot::summary_table(&input.results));
    print_report(&mut o, &merge_notes, &report);
    Ok(ExitCode::SUCCESS)
}

/// The fit document in `path`, when it is one (its `kind` says so); anything else is left to
/// the results readers and their errors.
fn fit_document(path: &Path) -> Option<grit_erosion::models::export::FitDocument> {
    let text = std::fs::read_to_string(path).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    if v.get("kind")?.as_str()? != grit_erosion::models::export::FIT_KIND {
        return None;
    }
    serde_json::from_value(v).ok()
}

/// Draws a jet campaign's charts and prints its table and the files written.
fn draw_jet(
    r: &grit_erosion::jet::aggregate::JetCampaignResults,
    out: &Path,
) -> anyhow::Result<ExitCode> {
    let report = grit_plot::plot_jet(r, out)?;
    let mut o = std::io::stdout().lock();
    let _ = write!(o, "{}", grit_plot::jet_summary_table(r));
    print_report(&mut o, &[], &report);
    Ok(ExitCode::SUCCESS)
}

/// The notes and the files written, after the table.
fn print_report(o: &mut impl Write, notes: &[String], report: &grit_plot::Report) {
    // A closed stdout (piping into head) is not an error worth a panic.
    for n in notes.iter().chain(&report.notes) {
        let _ = writeln!(o, "note: {n}");
    }
    let _ = writeln!(o, "wrote {} files:", report.files.len());
    for f in &report.files {
        let _ = writeln!(o, "  {}", f.display());
    }
}

/// Writes `chart` as an SVG line chart with labelled axes and a legend.
pub fn line_chart(chart: &Chart, path: &Path) -> anyhow::Result<()> {
    let pts = chart
        .series
        .iter()
        .flat_map(|s| s.x.iter().zip(&s.y))
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in pts {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    if x0 > x1 {
        return Err(anyhow!("chart {} has no finite points", chart.name));
    }
    let pad = |a: f64, b: f64| {
        if b > a {
            0.05 * (b - a)
        } else {
            1e-9_f64.max(a.abs() * 0.05)
        }
    };
    let (px, py) = (pad(x0, x1), pad(y0, y1));
    let root = SVGBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
    let mut ctx = ChartBuilder::on(&root)
        .caption(&chart.title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((x0 - px)..(x1 + px), (y0 - py)..(y1 + py))
        .map_err(|e| anyhow!("{e}"))?;
    ctx.configure_mesh()
        .x_desc(&chart.x_label)
        .y_desc(&chart.y_label)
        .draw()
        .map_err(|e| anyhow!("{e}"))?;
    let mut colour = 0;
    for s in &chart.series {
        // A reference takes the colour of the simulation drawn just before it.
        let c = if s.reference && colour > 0 {
            grit_plot::colour(colour - 1)
        } else {
            grit_plot::colour(colour)
        };
        let data: Vec<(f64, f64)> = s.x.iter().copied().zip(s.y.iter().copied()).collect();
        if s.reference {
            let style = ShapeStyle {
                color: c.mix(0.9),
                filled: false,
                stroke_width: 1,
            };
            ctx.draw_series(DashedLineSeries::new(data, 6, 4, style))
                .map_err(|e| anyhow!("{e}"))?
                .label(&s.label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
        } else {
            ctx.draw_series(LineSeries::new(data, c.stroke_width(2)))
                .map_err(|e| anyhow!("{e}"))?
                .label(&s.label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
            colour += 1;
        }
    }
    ctx.configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| anyhow!("{e}"))?;
    root.present().map_err(|e| anyhow!("{e}"))?;
    Ok(())
}
