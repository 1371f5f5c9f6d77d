//! `grit plot RESULTS.json --out DIR`: the charts of a results file (grit-plot), a summary
//! table and the list of files written.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args as ClapArgs;

/// Arguments of `grit plot`.
#[derive(ClapArgs)]
pub struct Args {
    /// Results JSON from `grit run` (OUT/results.json) or `grit results -o FILE`; per-sample
    /// curves need the raw series (`--raw` on either). Several files are drawn as one; a cell
    /// (angle, shape) an earlier file already has is left out.
    #[arg(required = true)]
    pub results: Vec<PathBuf>,
    /// Folder for the PNG and SVG charts (default: the first results file's folder).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Draws the charts and prints the table, the notes and the files written.
pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let inputs = a
        .results
        .iter()
        .map(|p| Ok((p.display().to_string(), grit_plot::load(p)?)))
        .collect::<Result<Vec<_>, grit_plot::PlotError>>()?;
    let (input, merge_notes) = grit_plot::merge(inputs)?;
    let out = a.out.unwrap_or_else(|| match a.results[0].parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    });
    let report = grit_plot::plot(&input, &out)?;
    // A closed stdout (piping into head) is not an error worth a panic.
    let mut o = std::io::stdout().lock();
    let _ = write!(o, "{}", grit_plot::summary_table(&input.results));
    for n in merge_notes.iter().chain(&report.notes) {
        let _ = writeln!(o, "note: {n}");
    }
    let _ = writeln!(o, "wrote {} files:", report.files.len());
    for f in &report.files {
        let _ = writeln!(o, "  {}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}
