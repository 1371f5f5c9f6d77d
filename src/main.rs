//! `grit`: the command-line front end. Subcommands live in their own modules; this file only
//! parses arguments and dispatches.

mod charts;
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
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Verify(a) => verify::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::from(2)
        }
    }
}
