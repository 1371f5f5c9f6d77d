//! `grit fit RESULTS.json…`: the full Oka model E(α, v, d) fitted to every steady cell
//! (`grit_erosion::models::fit`), and `grit export FIT.json --format …`: that fit written for
//! Fluent, OpenFOAM and EDEM (`grit_erosion::models::export`).

use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{anyhow, bail, Context};
use clap::Args as ClapArgs;
use grit_erosion::models::export::{
    export, Evaluation, FitDocument, FitSource, Format, EROSION_UNITS, FIT_KIND, LEVEL_WARNING,
};
use grit_erosion::models::fit::{cells_from_results, fit_full_oka, FitOptions, FullOkaFit, Param};
use grit_erosion::models::oka::{ShapeReference, AISI304_HV_GPA};

use super::output::{check_writable, write_bytes, write_json};

/// Arguments of `grit fit`.
#[derive(ClapArgs)]
pub struct FitArgs {
    /// Results JSON files (`grit run`'s OUT/results.json or `grit results -o`); every steady
    /// cell of every file enters one joint fit.
    #[arg(required = true)]
    pub results: Vec<PathBuf>,
    /// Print the fit document (what `-o` writes) as JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Write the fit document, the input of `grit export`, to FILE.
    #[arg(short = 'o', long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Evaluate the fitted model for the reference grain at ANGLE_DEG,SPEED_M_S,DIAMETER_M
    /// (repeatable), e.g. `--eval 45,100,250e-6`.
    #[arg(long, value_name = "A,V,D", value_parser = parse_eval)]
    pub eval: Vec<(f64, f64, f64)>,
    /// Hold parameters at values instead of fitting them: NAME=VALUE, NAME=oka (Oka's silica
    /// value at the fit's Hv: n1, n2, k2, k3) or NAME=seed (the seed's n3..n6); comma-separated
    /// or repeated. Needed when the cells cannot determine a parameter (one speed: k2).
    #[arg(long, value_name = "NAME=VALUE", value_delimiter = ',')]
    pub fix: Vec<String>,
    /// Vickers hardness of the target, GPa (default: 1.8 for aisi304; required for others).
    #[arg(long)]
    pub hv_gpa: Option<f64>,
    /// Reference speed v_ref, m/s.
    #[arg(long, default_value_t = 100.0)]
    pub v_ref_m_s: f64,
    /// Reference grain diameter d_ref, m.
    #[arg(long, default_value_t = 250e-6)]
    pub d_ref_m: f64,
    /// Leave out cells not at steady state, naming each, instead of refusing the fit.
    #[arg(long)]
    pub drop_unsteady: bool,
    /// Fit only the cells at these angles (degrees, comma-separated), e.g. to see whether k2
    /// depends on the angle.
    #[arg(long, value_name = "DEG,…", value_delimiter = ',')]
    pub angles: Vec<f64>,
}

/// Arguments of `grit export`.
#[derive(ClapArgs)]
pub struct ExportArgs {
    /// A fit document from `grit fit -o FILE`.
    pub fit: PathBuf,
    /// fluent-generic, fluent-oka, openfoam, edem or json.
    #[arg(long, value_parser = |s: &str| s.parse::<Format>())]
    pub format: Format,
    /// Output file (default: standard output); a folder for openfoam, which writes several.
    #[arg(short = 'o', long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    /// The Fluent wall zone, or the OpenFOAM patches (a wordRe list such as `walls "pipe.*"`).
    #[arg(long, default_value = "wall")]
    pub wall: String,
}

/// Parses `A,V,D`: angle in (0, 90] degrees, speed and diameter > 0.
fn parse_eval(s: &str) -> Result<(f64, f64, f64), String> {
    let bad = || format!("`{s}`: expected ANGLE_DEG,SPEED_M_S,DIAMETER_M such as 45,100,250e-6");
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
    let [a, vel, d] = v[..] else {
        return Err(bad());
    };
    if !(a > 0.0 && a <= 90.0) {
        return Err(format!("`{s}`: the angle must be in (0, 90] degrees"));
    }
    if !(vel.is_finite() && vel > 0.0 && d.is_finite() && d > 0.0) {
        return Err(format!("`{s}`: speed and diameter must be finite and > 0"));
    }
    Ok((a, vel, d))
}

/// `--fix` entries as values; `oka` and `seed` name the published value.
fn parse_fixed(entries: &[String], hv_gpa: f64) -> anyhow::Result<BTreeMap<Param, f64>> {
    let mut out = BTreeMap::new();
    for e in entries {
        let (name, value) = e
            .split_once('=')
            .ok_or_else(|| anyhow!("--fix {e}: expected NAME=VALUE, e.g. k2=oka or k3=0.19"))?;
        let p = Param::from_name(name.trim()).ok_or_else(|| {
            let names: Vec<&str> = Param::ALL.iter().map(|p| p.name()).collect();
            anyhow!(
                "--fix {e}: unknown parameter `{name}`; one of {}",
                names.join(", ")
            )
        })?;
        let v = match value.trim() {
            "oka" | "seed" => p.published(hv_gpa).ok_or_else(|| {
                anyhow!(
                    "--fix {e}: {} has no published value; give a number",
                    p.name()
                )
            })?,
            num => num
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| anyhow!("--fix {e}: `{num}` is not a finite number, oka or seed"))?,
        };
        out.insert(p, v);
    }
    Ok(out)
}

/// Hardness and density of the target of a results file's spec: AISI 304's when the spec
/// names it (or none); `None` for other materials.
fn target_of(spec: Option<&serde_json::Value>) -> (Option<f64>, Option<f64>, String) {
    match spec.and_then(|s| s.get("material")) {
        None => (Some(AISI304_HV_GPA), Some(7890.0), "aisi304".into()),
        Some(serde_json::Value::String(name)) => {
            let rho = grit_sph::material::Material::by_name(name)
                .ok()
                .map(|m| m.density_kg_m3);
            let hv = (name == "aisi304").then_some(AISI304_HV_GPA);
            (hv, rho, name.clone())
        }
        Some(other) => (
            None,
            other.get("density_kg_m3").and_then(|v| v.as_f64()),
            other.to_string(),
        ),
    }
}

/// The fit of `a`, with its provenance, or the reason it cannot be made.
fn make_fit(a: &FitArgs) -> anyhow::Result<FitDocument> {
    let mut cells = Vec::new();
    let mut sources = Vec::new();
    let mut notes = Vec::new();
    let mut targets = Vec::new();
    for path in &a.results {
        let name = path.display().to_string();
        let input = grit_plot::load(path)?;
        let r = &input.results;
        let (mut c, n) = cells_from_results(&name, r, a.drop_unsteady).map_err(|e| {
            anyhow!("{e}\n(pass --drop-unsteady to fit the other cells without it)")
        })?;
        notes.extend(n);
        if !a.angles.is_empty() {
            c.retain(|c| a.angles.iter().any(|x| (x - c.angle_deg).abs() < 1e-9));
        }
        targets.push(target_of(r.spec.as_ref()));
        let spec = r.spec.as_ref();
        sources.push(FitSource {
            file: name,
            grit_version: r.grit_version.clone(),
            spec: r.spec.clone(),
            numerics: r.numerics.as_ref().map(serde_json::to_value).transpose()?,
            spacing_m: spec.and_then(|s| s.get("spacing_m")).and_then(|v| match v {
                serde_json::Value::Array(x) if x.len() == 1 => x[0].as_f64(),
                v => v.as_f64(),
            }),
            cells_used: c.iter().map(|c| c.label.clone()).collect(),
        });
        cells.extend(c);
    }
    let names: Vec<&String> = targets.iter().map(|t| &t.2).collect();
    if names.windows(2).any(|w| w[0] != w[1]) {
        bail!("the results files have different targets ({names:?}); fit one material at a time");
    }
    let (hv_spec, rho, material) =
        targets
            .into_iter()
            .next()
            .unwrap_or((None, None, String::new()));
    let hv_gpa = match (a.hv_gpa, hv_spec) {
        (Some(h), _) | (None, Some(h)) => h,
        (None, None) => bail!(
            "--hv-gpa: the target is {material}, whose Vickers hardness grit does not know; give it in GPa"
        ),
    };
    if !(hv_gpa.is_finite() && hv_gpa > 0.0) {
        bail!("--hv-gpa {hv_gpa}: must be finite and > 0");
    }
    if cells.is_empty() {
        bail!("no cell to fit: {}", notes.join("; "));
    }
    let options = FitOptions {
        hv_gpa,
        v_ref_m_s: a.v_ref_m_s,
        d_ref_m: a.d_ref_m,
        reference: ShapeReference::HEXAGON,
        fixed: parse_fixed(&a.fix, hv_gpa)?,
    };
    let fit = fit_full_oka(&cells, &options).map_err(|e| {
        let hint = match &e {
            grit_erosion::models::oka::FitError::Underdetermined(_) => {
                "\n(hold a parameter with --fix NAME=VALUE or --fix NAME=oka)"
            }
            _ => "",
        };
        anyhow!("{e}{hint}")
    })?;
    let evaluations = a
        .eval
        .iter()
        .map(|&(angle_deg, velocity_m_s, diameter_m)| Evaluation {
            angle_deg,
            velocity_m_s,
            diameter_m,
            erosion: fit.model.erosion(angle_deg, velocity_m_s, diameter_m),
        })
        .collect();
    Ok(FitDocument {
        kind: FIT_KIND.into(),
        grit_version: env!("CARGO_PKG_VERSION").into(),
        erosion_units: EROSION_UNITS.into(),
        level_warning: LEVEL_WARNING.into(),
        wall_density_kg_m3: rho,
        fit,
        sources,
        notes,
        evaluations,
    })
}

/// The fit as Markdown tables: parameters beside the published values, then every cell.
fn print_tables(o: &mut impl Write, doc: &FitDocument) -> std::io::Result<()> {
    let f: &FullOkaFit = &doc.fit;
    let m = &f.model;
    writeln!(
        o,
        "Full Oka fit E = E90,ref g(α) (v/v_ref)^k2 (d/d_ref)^k3 to {} steady cells (Hv = {} GPa, v_ref = {} m/s, d_ref = {} m)\n",
        f.cells.len(),
        m.hv_gpa,
        m.v_ref_m_s,
        m.d_ref_m
    )?;
    writeln!(
        o,
        "| parameter | value | std. error | published (Oka silica / seed) |"
    )?;
    writeln!(o, "|---|---|---|---|")?;
    for p in &f.parameters {
        let se = match (p.fixed, p.std_error) {
            (true, _) => "fixed (not fitted)".to_string(),
            (false, Some(s)) => format!("{s:.4}"),
            (false, None) => "–".to_string(),
        };
        let published = p.published.map_or("–".to_string(), |v| format!("{v:.4}"));
        writeln!(
            o,
            "| {} | {:.6} | {se} | {published} |",
            p.name.name(),
            p.value
        )?;
    }
    writeln!(
        o,
        "\nχ² = {:.3}, dof = {}, χ²/dof = {}; standard errors scaled by {:.3} (√(χ²/dof) when above 1)\n",
        f.chi2,
        f.dof,
        f.chi2_per_dof.map_or("–".into(), |c| format!("{c:.3}")),
        f.error_scale
    )?;
    writeln!(
        o,
        "| cell | file | erosion | s.e. | model | residual | pull |"
    )?;
    writeln!(o, "|---|---|---|---|---|---|---|")?;
    for c in &f.cells {
        writeln!(
            o,
            "| {} | {} | {:.4e} | {:.2e} | {:.4e} | {:+.2e} | {:+.2} |",
            c.cell.label,
            c.cell.source,
            c.cell.erosion,
            c.cell.erosion_sem,
            c.model,
            c.residual,
            c.pull
        )?;
    }
    for e in &doc.evaluations {
        writeln!(
            o,
            "eval: angle_deg={} velocity_m_s={} diameter_m={:e} erosion={:e}",
            e.angle_deg, e.velocity_m_s, e.diameter_m, e.erosion
        )?;
    }
    writeln!(o, "\nerosion: {EROSION_UNITS}.\nwarning: {LEVEL_WARNING}")?;
    for n in &doc.notes {
        writeln!(o, "note: {n}")?;
    }
    Ok(())
}

/// `grit fit`: fits, prints, and writes the fit document with `-o`.
pub fn fit(a: FitArgs) -> anyhow::Result<ExitCode> {
    if let Some(p) = &a.out {
        check_writable("-o", p)?;
    }
    let doc = make_fit(&a)?;
    if let Some(p) = &a.out {
        write_json(p, &doc)?;
    }
    let mut o = std::io::stdout().lock();
    // A closed stdout (piping into head) is not an error worth a failure.
    let _ = if a.json {
        writeln!(o, "{}", serde_json::to_string_pretty(&doc)?)
    } else {
        print_tables(&mut o, &doc)
    };
    Ok(ExitCode::SUCCESS)
}

/// `grit export`: the fit in one code's format, to a file, a folder or standard output.
pub fn export_cmd(a: ExportArgs) -> anyhow::Result<ExitCode> {
    let text = std::fs::read_to_string(&a.fit)
        .with_context(|| format!("{}: cannot read", a.fit.display()))?;
    let doc: FitDocument = serde_json::from_str(&text).map_err(|e| {
        anyhow!(
            "{}: not a fit document from `grit fit -o` ({e})",
            a.fit.display()
        )
    })?;
    let files = export(&doc, a.format, &a.wall).map_err(|e| anyhow!("{}: {e}", a.fit.display()))?;
    match (&a.out, files.as_slice()) {
        (None, [one]) => {
            let _ = std::io::stdout().lock().write_all(one.text.as_bytes());
        }
        (Some(path), [one]) => {
            check_writable("-o", path)?;
            write_bytes(path, one.text.as_bytes())?;
        }
        (None, _) => bail!("--format openfoam writes several files: give -o FOLDER"),
        (Some(dir), many) => {
            if dir.is_file() {
                bail!("-o {}: is a file; openfoam writes a folder", dir.display());
            }
            for f in many {
                let path = dir.join(&f.path);
                if let Some(parent) = path.parent() {
                    std::fs::create_dir_all(parent)
                        .with_context(|| format!("-o {}: cannot create", parent.display()))?;
                }
                write_bytes(&path, f.text.as_bytes())?;
            }
            eprintln!("wrote {} files under {}", many.len(), dir.display());
        }
    }
    Ok(ExitCode::SUCCESS)
}
