//! `grit`: the command-line front end. The commands live in `cli/`, one module per group; this
//! file only parses the arguments and dispatches.

mod cli;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use cli::{bench, campaign, fit, jet, plot, sample, serve, study, version};

/// Solid particle erosion predicted by SPH impact simulations.
#[derive(Parser)]
#[command(
    name = "grit",
    version,
    about,
    after_help = "Example: grit run examples/quick.json --out out/quick"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the engine's verification cases and print case, resolution, value, reference, error.
    #[command(after_help = "Example: grit verify --quick --only hertz")]
    Verify(sample::verify::Args),
    /// Print the built-in grain shapes with angularity and aspect ratio (Mohseni-Mofidi et al.
    /// 2022, Table 2).
    #[command(after_help = "Example: grit shapes --json")]
    Shapes(sample::shapes::ShapesArgs),
    /// Run one sample (N sequential random impacts on a fresh surface) locally.
    #[command(
        after_help = "Example: grit sample --angle 45 --shape hexagon --impacts 70 --seed 1"
    )]
    Sample(sample::SampleArgs),
    /// Run one abrasive water jet on a metal target (the AWJ paper's scene): crater depth and
    /// width, mass loss and plastic strain against time.
    #[command(
        after_help = "Example: grit jet --material copper --velocity-m-s 500 --mass-flow-kg-s 0.02 --time-ms 0.2 --spacing-m 1e-4 --seed 1"
    )]
    Jet(jet::JetArgs),
    /// Checks of the impact scene's own choices: `grit study settle`.
    #[command(after_help = "Example: grit study settle --angle 45 --impacts 20")]
    Study(study::StudyArgs),
    /// Charts of a results file (PNG and SVG): mass loss, erosion against angle with Oka's
    /// model, normalised erosion, modified Oka, convergence.
    #[command(after_help = "Example: grit plot out/quick/results.json --out out/charts")]
    Plot(plot::Args),
    /// Print a results file's erosion normalised at 45° beside Oka's g(α), and its shape ratios
    /// beside the seed's modified Oka, with standard errors and the project's goals; a cell that
    /// several files have, side by side.
    #[command(
        after_help = "Example: grit compare docs/erosion/reduced-results.json docs/erosion/resolution24-results.json"
    )]
    Compare(plot::CompareArgs),
    /// Fit the full Oka model E(α, v, d) = E90,ref g(α) (v/v_ref)^k2 (d/d_ref)^k3 jointly to
    /// every steady cell of the results files, weighted by their standard errors: parameters
    /// with standard errors beside Oka's, χ²/dof and each cell's residual.
    #[command(
        after_help = "Example: grit fit velocity/results.json size/results.json -o fit.json --eval 45,100,250e-6"
    )]
    Fit(fit::FitArgs),
    /// Write a fit from `grit fit -o` for a CFD or DEM code: Fluent's generic or Oka erosion
    /// model, an OpenFOAM cloud function object, EDEM's Oka wear model, or JSON.
    #[command(after_help = "Example: grit export fit.json --format fluent-oka -o oka.py")]
    Export(fit::ExportArgs),
    /// Run the coordinator: REST API under /api/v1 on a SQLite database.
    #[command(
        after_help = "Example: GRIT_SUBMIT_TOKEN=s3cret GRIT_WORKER_TOKEN=w0rker grit serve --db grit.db --listen 0.0.0.0:8080"
    )]
    Serve(serve::ServeArgs),
    /// Run a worker: lease jobs from a coordinator and simulate their impacts.
    #[command(
        after_help = "Example: grit work --coordinator http://coordinator:8080 --token-file worker.token --threads 4"
    )]
    Work(serve::WorkArgs),
    /// Run a whole campaign on this machine (coordinator + local workers) and write results.
    #[command(after_help = "Example: grit run examples/quick.json --out out/quick")]
    Run(campaign::RunArgs),
    /// Submit a campaign spec; prints the campaign id alone on the last line.
    #[command(
        after_help = "Example: grit submit examples/paper.json --coordinator http://coordinator:8080"
    )]
    Submit(campaign::SubmitArgs),
    /// Show a campaign's progress (or every campaign without an id).
    #[command(after_help = "Example: grit status 0b6f4a52-3c1e-4d2a-9f8e-2a7c5d1e9b40 --watch")]
    Status(campaign::StatusArgs),
    /// Fetch a campaign's aggregated results (partial while it runs).
    #[command(
        after_help = "Example: grit results 0b6f4a52-3c1e-4d2a-9f8e-2a7c5d1e9b40 --raw -o results.json"
    )]
    Results(campaign::ResultsArgs),
    /// Cancel a campaign: no more jobs are handed out; running workers drop theirs.
    #[command(after_help = "Example: grit cancel 0b6f4a52-3c1e-4d2a-9f8e-2a7c5d1e9b40")]
    Cancel(campaign::IdArgs),
    /// Raise a campaign's until_steady caps: the cells stopped at the old cap short of their
    /// rule run on from their samples' states there (`grit run` does so with the raised spec).
    #[command(
        after_help = "Example: grit raise-caps 0b6f4a52-3c1e-4d2a-9f8e-2a7c5d1e9b40 paper-800.json"
    )]
    RaiseCaps(campaign::RaiseCapsArgs),
    /// Put a campaign's failed jobs back in the queue.
    #[command(after_help = "Example: grit retry-failed 0b6f4a52-3c1e-4d2a-9f8e-2a7c5d1e9b40")]
    RetryFailed(campaign::IdArgs),
    /// Benchmarks and numerical studies: one impact timed, the speed–accuracy sweep, the
    /// stability map, and the coordinator's load test.
    #[command(after_help = "Example: grit bench impact --spacing-m 1.5625e-5 --repeat 3")]
    Bench(bench::BenchArgs),
    /// Print the version, the commit and the engine fingerprints: hashes of the bits a short
    /// canonical impact and jet leave, equal on every machine that computes the same numbers.
    #[command(after_help = "Example: grit version --json")]
    Version(version::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // plotters draws text only with registered fonts (the embedded DejaVu Sans), for every
    // chart in the binary, the verification SVGs included.
    grit_plot::register_fonts();
    let result = match cli.command {
        Command::Verify(a) => sample::verify::run(a),
        Command::Shapes(a) => sample::shapes::shapes(a),
        Command::Sample(a) => sample::sample(a),
        Command::Jet(a) => jet::jet(a),
        Command::Study(a) => study::study(a),
        Command::Plot(a) => plot::run(a),
        Command::Compare(a) => plot::compare(a),
        Command::Fit(a) => fit::fit(a),
        Command::Export(a) => fit::export_cmd(a),
        Command::Bench(a) => bench::run(a),
        Command::Version(a) => version::run(a),
        Command::Serve(a) => farm("info", serve::serve(a)),
        Command::Work(a) => farm("info", serve::work(a)),
        Command::Run(a) => farm("warn", campaign::run(a)),
        Command::Submit(a) => farm("warn", campaign::submit(a)),
        Command::Status(a) => farm("warn", campaign::status(a)),
        Command::Results(a) => farm("warn", campaign::results(a)),
        Command::Cancel(a) => farm("warn", campaign::cancel(a)),
        Command::RaiseCaps(a) => farm("warn", campaign::raise_caps(a)),
        Command::RetryFailed(a) => farm("warn", campaign::retry_failed(a)),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// Runs a farm command on the async runtime, logging at `log` level unless `RUST_LOG` says.
fn farm(
    log: &str,
    command: impl std::future::Future<Output = anyhow::Result<ExitCode>>,
) -> anyhow::Result<ExitCode> {
    cli::init_tracing(log);
    cli::runtime()?.block_on(command)
}
