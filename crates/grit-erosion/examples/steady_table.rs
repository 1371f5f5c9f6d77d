//! The steady-state check of every cell of a results file under this build's rule, beside
//! the verdict the file stored, as a markdown table:
//! `cargo run --release -p grit-erosion --example steady_table -- RESULTS.json…`.
//!
//! Files that store each sample's first loss are checked exactly; older files keep only the
//! range of first losses, and where that range cannot tell whether the samples had incubated
//! by the start of the rule's window the cell says "cannot tell".
use std::process::ExitCode;

use grit_erosion::impact::aggregate::CampaignResults;
use grit_erosion::impact::steady::reassess;
use grit_erosion::stats::SlopeFit;

/// Two slopes' difference (later minus earlier) in combined standard errors, the quantity of
/// condition 1.
fn z(a: Option<SlopeFit>, b: Option<SlopeFit>) -> String {
    match (a, b) {
        (Some(a), Some(b)) if a.sem.hypot(b.sem) > 0.0 => {
            format!("{:+.1}", (a.value - b.value) / a.sem.hypot(b.sem))
        }
        _ => "–".into(),
    }
}

fn show(fit: Option<SlopeFit>) -> String {
    fit.map_or("–".into(), |f| {
        format!("{:.2} ± {:.2}", f.value * 1e3, f.sem * 1e3)
    })
}

fn verdict(s: Option<bool>) -> &'static str {
    match s {
        Some(true) => "yes",
        Some(false) => "**no**",
        None => "not in the file (incubation)",
    }
}

fn run(path: &str) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let stored: CampaignResults =
        serde_json::from_str(&text).map_err(|e| format!("{path}: {e}"))?;
    println!("\n{path}\n");
    println!(
        "| cell | samples | impacts | last 20 (mg/g) | previous 20 (mg/g) | the 20 before (mg/g) \
         | differences: adjacent; ends (combined s.e.) | sees changes of | steady (stored rule) | steady (this rule) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for c in &stored.cells {
        let now = reassess(c);
        let (last, prev, before, zz, sees) = match now.as_ref().map(|r| &r.state) {
            Some(s) => (
                show(s.slope_last),
                show(s.slope_prev),
                show(s.slope_before),
                format!(
                    "{}, {}; ends {}",
                    z(s.slope_last, s.slope_prev),
                    z(s.slope_prev, s.slope_before),
                    z(s.slope_last, s.slope_before)
                ),
                s.detectable_change_rel
                    .map_or("–".into(), |d| format!("{:.0} %", 100.0 * d)),
            ),
            None => Default::default(),
        };
        println!(
            "| {} | {} | {} | {last} | {prev} | {before} | {zz} | {sees} | {} | {} |",
            c.label(),
            c.samples_reported,
            c.mean_series.len(),
            verdict(c.steady_state.as_ref().map(|s| s.steady)),
            verdict(now.as_ref().and_then(|r| r.steady())),
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        eprintln!("usage: steady_table RESULTS.json…");
        return ExitCode::FAILURE;
    }
    for path in &paths {
        if let Err(e) = run(path) {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}
