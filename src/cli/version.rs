//! `grit version`: the crate version, the commit the binary was built from, and the engine
//! fingerprints of both scenes (`grit_erosion::fingerprint`), measured at start-up.

use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::Args as ClapArgs;
use serde::Serialize;

/// Options of `grit version`.
#[derive(ClapArgs)]
pub struct Args {
    /// Print JSON: {"version", "commit", "engine", "jet_engine", "seconds"}.
    #[arg(long)]
    json: bool,
}

/// What `grit version` reports.
#[derive(Serialize)]
struct Version {
    version: &'static str,
    commit: &'static str,
    engine: String,
    jet_engine: String,
    /// Wall time the two canonical runs took.
    seconds: f64,
}

/// Runs the canonical scenes and prints what they say.
pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let t0 = Instant::now();
    let engine = grit_erosion::fingerprint::impact_engine().context("impact fingerprint")?;
    let jet_engine = grit_erosion::fingerprint::jet_engine().context("jet fingerprint")?;
    let v = Version {
        version: env!("CARGO_PKG_VERSION"),
        commit: env!("GRIT_COMMIT"),
        engine,
        jet_engine,
        seconds: t0.elapsed().as_secs_f64(),
    };
    if a.json {
        println!("{}", serde_json::to_string(&v)?);
    } else {
        println!("grit {} (commit {})", v.version, v.commit);
        println!("impact engine {}", v.engine);
        println!("jet engine    {}", v.jet_engine);
        println!("fingerprints measured in {:.2} s", v.seconds);
    }
    Ok(ExitCode::SUCCESS)
}
