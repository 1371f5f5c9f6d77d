//! `grit`: the command-line front end. Subcommands live in their own modules; this file only
//! parses arguments and dispatches.

mod charts;
mod plot_cli;
mod sample_cli;
mod verify;

use clap::{Parser, Subcommand};

/// Solid particle erosion predicted by SPH impact simulations.
#[derive(Parser)]
#[command(name = "grit", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the engine's verification cases and print case, resolution, value, reference, error.
    Verify(verify::Args),
    /// Print the built-in grain shapes with angularity and aspect ratio (seed Table 2).
    Shapes(sample_cli::ShapesArgs),
    /// Run one sample (N sequential random impacts on a fresh surface) locally.
    Sample(sample_cli::SampleArgs),
    /// Checks of the impact scene's own choices: `grit study settle`.
    Study(sample_cli::StudyArgs),
    /// Charts of a results file (PNG and SVG): mass loss, erosion against angle with Oka's
    /// model, normalised erosion, modified Oka, convergence.
    Plot(plot_cli::Args),
    /// Job farm: serve, work, run, submit, status, results, cancel, retry-failed, bench.
    #[command(flatten)]
    Farm(grit_farm::cli::FarmCommand),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    // plotters draws text only with registered fonts (the embedded DejaVu Sans), for every
    // chart in the binary, the verification SVGs included.
    grit_plot::register_fonts();
    let result = match cli.command {
        Command::Verify(a) => verify::run(a),
        Command::Shapes(a) => sample_cli::shapes(a),
        Command::Sample(a) => sample_cli::sample(a),
        Command::Study(a) => sample_cli::study(a),
        Command::Plot(a) => plot_cli::run(a),
        Command::Farm(c) => grit_farm::cli::dispatch(c).map_err(anyhow::Error::from),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::from(2)
        }
    }
}
