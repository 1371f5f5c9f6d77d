//! `grit verify`: the contact benchmarks of Mohseni-Mofidi et al. 2022 and the engine's own
//! checks, as a table.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context};
use grit_sph::verification::{
    elastic_impact, hertz, hourglass, jet, jet_grain, rock, sliding, slope, CaseReport, Row,
};

use crate::cli::output::say;

/// A verification case run at the chosen resolution.
type Case = Box<dyn Fn() -> Result<CaseReport, grit_sph::SimError>>;

/// Arguments of `grit verify`.
#[derive(clap::Args)]
pub struct Args {
    /// Run the CI resolutions only (the ones the tests use).
    #[arg(long)]
    quick: bool,
    /// Print the table as a JSON array of {case, resolution, value, reference, error_rel, pass,
    /// expected_fail, note}.
    #[arg(long)]
    json: bool,
    /// Write one SVG chart per case into this folder.
    #[arg(long)]
    charts: Option<PathBuf>,
    /// Run only the cases whose name contains this text, case-insensitive: a group (slope,
    /// sliding, hertz, impact, hourglass, jet, rock) runs alone; any other text runs every group and
    /// keeps the rows whose case holds it (e.g. hydrostatic).
    #[arg(long)]
    only: Option<String>,
}

/// How each group's case names begin (`docs/verification.md`), so `--only` can pick the
/// group of a case without running the others.
const CASE_NAMES: [(&str, &[&str]); 7] = [
    ("slope", &["slope_slider"]),
    ("sliding", &["controlled_sliding"]),
    ("hertz", &["hertz"]),
    ("impact", &["elastic_impact"]),
    ("hourglass", &["zero_energy_modes"]),
    (
        "jet",
        &[
            "jet_hugoniot",
            "jet_dem_drop",
            "jet_restitution",
            "jet_hydrostatic",
            "jet_settling",
            "jet_coupling",
            "jet_wall",
            "jet_rc",
        ],
    ),
    (
        "rock",
        &[
            "rock_strength",
            "rock_uniaxial",
            "rock_tensile",
            "rock_hugoniot",
            "rock_bulking",
            "rock_spall",
        ],
    ),
];

/// Runs the cases; exits 1 if any row fails its tolerance, except rows marked `expected_fail`
/// (they show where a method fails, and failing is their point).
pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let (slope_n, slide_n, impact_n, hg_n) = if a.quick {
        (20, 20, 40, 20)
    } else {
        (40, 40, 80, 40)
    };
    // Particles per cylinder radius, coarse to fine: the convergence of p0 needs three.
    let hertz_n: &'static [usize] = if a.quick {
        &[20, 25, 35]
    } else {
        &[25, 35, 50]
    };
    // The water-jet blocks' DEM rows, at the DEM step limit or half of it; the water column's
    // particles per height; the settling grain's steps per Stokes time; the jet on a wall's
    // particles across the jet and its speed.
    let (jet_dt, jet_n, jet_settle) = if a.quick {
        (1.0, 20, 100)
    } else {
        (0.5, 40, 400)
    };
    let wall = if a.quick { (16, 400.0) } else { (24, 400.0) };
    // The coupling-radius study's jet: the paper's d_ini = 50 µm is 20 across its 1 mm jet.
    let rc = jet_grain::RcScene::new(if a.quick { 16 } else { 20 }, 500.0, 1.0);
    // The spall block's particles along its length (half as many across).
    let rock_n = if a.quick { 24 } else { 40 };
    let only = a.only.as_deref().map(str::to_lowercase);
    let want = |name: &str| only.as_deref().is_none_or(|o| name.contains(o));
    let mut rep = CaseReport::default();
    let cases: [(&str, Case); 7] = [
        ("slope", Box::new(move || slope::run(slope_n))),
        ("sliding", Box::new(move || sliding::run(slide_n))),
        ("hertz", Box::new(move || hertz::run(hertz_n))),
        ("impact", Box::new(move || elastic_impact::run(impact_n))),
        ("hourglass", Box::new(move || hourglass::run(hg_n, 0.1))),
        (
            "jet",
            Box::new(move || jet::run(jet_dt, jet_n, jet_settle, wall, rc)),
        ),
        ("rock", Box::new(move || rock::run(rock_n))),
    ];
    // A text no group's name holds names cases inside the groups (`hydrostatic`,
    // `jet_wall_force`): the groups whose cases can hold it run, and only the rows whose case
    // holds it are kept.
    let by_case = !cases.iter().any(|(name, _)| want(name));
    let holds = |group: &str| {
        CASE_NAMES
            .iter()
            .filter(|(g, _)| *g == group)
            .flat_map(|(_, names)| names.iter())
            .any(|n| want(n) || only.as_deref().is_some_and(|o| o.starts_with(n)))
    };
    if by_case && !cases.iter().any(|(name, _)| holds(name)) {
        bail!(
            "--only: `{}` is in no case's name; the groups are {} and their cases start {}",
            a.only.as_deref().unwrap_or_default(),
            cases.map(|(name, _)| name).join(", "),
            CASE_NAMES
                .iter()
                .flat_map(|(_, names)| names.iter())
                .copied()
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    // The folder is made before the cases run, so a bad path costs nothing.
    if let Some(dir) = &a.charts {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    for (name, f) in cases.iter() {
        if !(if by_case { holds(name) } else { want(name) }) {
            continue;
        }
        eprintln!("running {name} ...");
        rep.extend(f().with_context(|| format!("case {name}"))?);
    }
    if by_case {
        rep.rows.retain(|r| want(&r.case.to_lowercase()));
        rep.charts.retain(|c| want(&c.name.to_lowercase()));
        if rep.rows.is_empty() {
            bail!(
                "--only: `{}` is in no case's name",
                a.only.as_deref().unwrap_or_default()
            );
        }
    }
    if a.json {
        say!("{}", serde_json::to_string_pretty(&rep.rows)?);
    } else {
        say!(
            "{:<42} {:<40} {:>12} {:>12} {:>10}  pass",
            "case",
            "resolution",
            "value",
            "reference",
            "error"
        );
        for r in &rep.rows {
            say!(
                "{:<42} {:<40} {:>12.5e} {:>12.5e} {:>10.3e}  {}",
                r.case,
                r.resolution,
                r.value,
                r.reference,
                r.error_rel,
                pass_label(r)
            );
        }
        say!();
        for r in &rep.rows {
            say!("{}: {}", r.case, r.note);
        }
    }
    if let Some(dir) = &a.charts {
        for c in &rep.charts {
            let path = dir.join(format!("{}.svg", c.name));
            crate::cli::plot::line_chart(c, &path)?;
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(if all_pass(&rep.rows) {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The pass column: `yes`, `NO`, or, for rows meant to fail, `no (expected)` / `yes (unexpected)`.
fn pass_label(r: &Row) -> &'static str {
    match (r.pass, r.expected_fail) {
        (true, false) => "yes",
        (false, false) => "NO",
        (false, true) => "no (expected)",
        (true, true) => "yes (unexpected)",
    }
}

/// True when every row not marked `expected_fail` passes: the exit status of `grit verify`.
fn all_pass(rows: &[Row]) -> bool {
    rows.iter().all(|r| r.pass || r.expected_fail)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(pass: bool, expected_fail: bool) -> Row {
        Row {
            case: "c".into(),
            resolution: "r".into(),
            value: 0.0,
            reference: 0.0,
            error_rel: 0.0,
            pass,
            expected_fail,
            note: String::new(),
        }
    }

    #[test]
    fn expected_failures_do_not_fail_the_run_but_other_failures_do() {
        assert!(all_pass(&[row(true, false), row(false, true)]));
        assert!(!all_pass(&[row(false, false), row(false, true)]));
        assert_eq!(pass_label(&row(false, true)), "no (expected)");
        assert_eq!(pass_label(&row(false, false)), "NO");
    }
}
