//! The steady-state check of every cell of a results file, as a markdown table:
//! `cargo run --release -p grit-erosion --example steady_table -- RESULTS.json`.
//!
//! With a `raw` array (`grit run --raw`) the cells are aggregated again from their samples,
//! so the check is complete. Without one only the mean series is there: the two slopes are
//! printed with the first impact at which the mean lost mass (the earliest sample's
//! incubation), and steadiness is left open.
use std::process::ExitCode;

use grit_erosion::aggregate::{aggregate_campaign, CampaignResults, CellInput, Impact};
use grit_erosion::steady::{mean_series_slopes, SlopeFit};
use grit_erosion::SLOPE_WINDOW;
use serde::Deserialize;

#[derive(Deserialize)]
struct Raw {
    cell: usize,
    sample: u32,
    impacts: Vec<Impact>,
}

/// The slopes' difference in combined standard errors, the quantity of condition 1.
fn z(last: Option<SlopeFit>, prev: Option<SlopeFit>) -> String {
    match (last, prev) {
        (Some(a), Some(b)) => {
            let combined = (a.sem * a.sem + b.sem * b.sem).sqrt();
            if combined > 0.0 {
                format!("{:.1}", (a.value - b.value).abs() / combined)
            } else {
                "–".into()
            }
        }
        _ => "–".into(),
    }
}

fn show(fit: Option<SlopeFit>) -> String {
    fit.map_or("–".into(), |f| {
        format!("{:.2} ± {:.2}", f.value * 1e3, f.sem * 1e3)
    })
}

fn run(path: &str) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let mut value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{path}: {e}"))?;
    let raw = value.as_object_mut().and_then(|o| o.remove("raw"));
    let stored: CampaignResults =
        serde_json::from_value(value).map_err(|e| format!("{path}: {e}"))?;
    println!(
        "| cell | impacts | first loss at impact (min–max, mean) | slope of the last 10 (mg/g) \
         | slope of the 10 before (mg/g) | difference (combined SE) | steady |"
    );
    println!("|---|---|---|---|---|---|---|");
    let Some(raw) = raw else {
        for c in &stored.cells {
            let (last, prev) = mean_series_slopes(&c.mean_series);
            let first = c.mean_series.iter().find(|p| p.mass_loss_kg > 0.0);
            println!(
                "| {} | {} | from {} (earliest sample; no raw series) | {} | {} | {} | not checked |",
                c.label(),
                c.mean_series.len(),
                first.map_or("never".into(), |p| p.impact.to_string()),
                show(last),
                show(prev),
                z(last, prev)
            );
        }
        return Ok(());
    };
    let raw: Vec<Raw> = serde_json::from_value(raw).map_err(|e| format!("{path}: raw: {e}"))?;
    let mut cells: Vec<CellInput> = stored
        .cells
        .iter()
        .map(|c| CellInput {
            angle_deg: c.angle_deg,
            shape: c.shape.clone(),
            swept: c.swept.clone(),
            planned_samples: c.samples_planned,
            planned_impacts: c.impacts_planned,
            samples: Vec::new(),
        })
        .collect();
    for (i, r) in raw.into_iter().enumerate() {
        let cell = cells
            .get_mut(r.cell)
            .ok_or_else(|| format!("{path}: raw[{i}].cell: {} is not a cell", r.cell))?;
        cell.samples.push(grit_erosion::SampleInput {
            sample: r.sample,
            impacts: r.impacts,
        });
    }
    let results = aggregate_campaign(&cells, SLOPE_WINDOW).map_err(|e| format!("{path}: {e}"))?;
    for (c, old) in results.cells.iter().zip(&stored.cells) {
        if c.erosion_mean != old.erosion_mean {
            return Err(format!(
                "{path}: cell {}: the raw series give erosion {:?}, the file {:?}",
                c.label(),
                c.erosion_mean,
                old.erosion_mean
            ));
        }
        let s = c
            .steady_state
            .as_ref()
            .expect("aggregation checks every cell");
        let incubation = s.incubation_impacts.map_or("none".into(), |i| {
            format!("{}–{}, {:.1}", i.min, i.max, i.mean)
        });
        let without = match s.samples_without_loss {
            0 => String::new(),
            n => format!(" ({n} of {} none)", c.samples_reported),
        };
        println!(
            "| {} | {} | {incubation}{without} | {} | {} | {} | {} |",
            c.label(),
            c.mean_series.len(),
            show(s.slope_last10),
            show(s.slope_prev10),
            z(s.slope_last10, s.slope_prev10),
            if s.steady { "yes" } else { "**no**" }
        );
    }
    println!();
    for w in results.unsteady_warnings() {
        println!("{w}");
    }
    Ok(())
}

fn main() -> ExitCode {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: steady_table RESULTS.json");
        return ExitCode::FAILURE;
    };
    match run(&path) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
