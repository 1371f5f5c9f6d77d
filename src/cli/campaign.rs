//! Commands on a campaign: `grit run` (the whole farm in this process) and the client
//! commands against a coordinator: submit, status, results, cancel, retry-failed.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Args;
use grit_erosion::campaign::{AnySpec, Scene};
use grit_erosion::CampaignResults;
use grit_farm::api::{AnyResults, CampaignState, CampaignStatus, CellProgress};
use grit_farm::embedded::{self, EmbeddedOptions, RunEvent};
use grit_farm::worker::Stop;
use grit_farm::{Client, ClientError};
use indicatif::{MultiProgress, ProgressBar};
use uuid::Uuid;

use super::output::{say, write_json};
use super::{on_signals, progress, read_token};

/// `grit run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Campaign spec JSON (as in examples/); `-` reads standard input.
    pub campaign: PathBuf,
    /// Local workers (default: one per core, each with one engine thread, since samples
    /// are independent and parallelise better than the threads inside one impact; with fewer
    /// jobs in the campaign than cores, one per job, sharing the cores).
    #[arg(long, value_parser = crate::cli::thread_count)]
    pub workers: Option<usize>,
    /// Engine threads per worker (default: cores / workers).
    #[arg(long, value_parser = crate::cli::thread_count)]
    pub threads: Option<usize>,
    /// Output folder: grit.db (resumable) and results.json.
    #[arg(long, default_value = "out/run")]
    pub out: PathBuf,
    /// Checkpoint every this many impacts.
    #[arg(long, default_value_t = 5, value_parser = crate::cli::at_least_one)]
    pub checkpoint_every: u32,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Include every sample's per-impact series in results.json (as `results --raw`).
    #[arg(long)]
    pub raw: bool,
    /// When --out holds this campaign pinned to another engine (another grit build that
    /// computes other bits), run the spec afresh in this new folder instead of refusing.
    /// Nothing is carried over: a campaign never mixes two engines' samples.
    #[arg(long, value_name = "NEW_DIR")]
    pub engine_upgrade: Option<PathBuf>,
    /// While the campaign runs, write the results so far (unfinished cells marked partial)
    /// to results.json at most every this many seconds, when jobs finished since.
    #[arg(long, value_name = "SECONDS", default_value_t = 600.0, value_parser = crate::cli::seconds)]
    pub interim_every: f64,
}

/// Where the coordinator is and how to authenticate: the client commands and `grit work`.
#[derive(Args, Debug)]
pub struct Remote {
    /// Coordinator base URL.
    #[arg(
        long,
        env = "GRIT_COORDINATOR",
        default_value = "http://127.0.0.1:8080"
    )]
    pub coordinator: String,
    /// Submit token (client commands) or worker token (`grit work`).
    #[arg(long, env = "GRIT_TOKEN", hide_env_values = true)]
    pub token: Option<String>,
    /// File holding the token.
    #[arg(long, env = "GRIT_TOKEN_FILE")]
    pub token_file: Option<PathBuf>,
}

/// How long a client command waits for the coordinator's answer: a coordinator that accepts
/// the connection and never answers fails the command instead of holding it.
const COMMAND_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(30);

impl Remote {
    fn client(self) -> anyhow::Result<Client> {
        let token = read_token(self.token, self.token_file, "token")?;
        Ok(Client::with_timeout(
            &self.coordinator,
            token,
            COMMAND_TIMEOUT,
        )?)
    }
}

/// `grit submit`.
#[derive(Args, Debug)]
pub struct SubmitArgs {
    /// Campaign spec JSON; `-` reads standard input.
    pub file: PathBuf,
    /// Idempotency key: submitting again with the same key returns the same campaign.
    #[arg(long)]
    pub idempotency_key: Option<String>,
    #[command(flatten)]
    remote: Remote,
}

/// `grit raise-caps`.
#[derive(Args, Debug)]
pub struct RaiseCapsArgs {
    /// Campaign id.
    pub id: String,
    /// The campaign's spec with higher `until_steady.max` values; `-` reads standard input.
    pub file: PathBuf,
    #[command(flatten)]
    remote: Remote,
}

/// `grit status`.
#[derive(Args, Debug)]
pub struct StatusArgs {
    /// Campaign id; without it, every campaign is listed.
    pub id: Option<String>,
    /// Refresh with progress bars until the campaign ends.
    #[arg(long)]
    pub watch: bool,
    /// Print the status JSON of the API.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    remote: Remote,
}

/// `grit results`.
#[derive(Args, Debug)]
pub struct ResultsArgs {
    /// Campaign id.
    pub id: String,
    /// Write to this file instead of standard output.
    #[arg(short = 'o', long)]
    pub output: Option<PathBuf>,
    /// Include every sample's per-impact series.
    #[arg(long)]
    pub raw: bool,
    #[command(flatten)]
    remote: Remote,
}

/// A campaign id and the coordinator: `grit cancel`, `grit retry-failed`.
#[derive(Args, Debug)]
pub struct IdArgs {
    /// Campaign id.
    pub id: String,
    #[command(flatten)]
    remote: Remote,
}

fn read_spec_text(path: &Path) -> anyhow::Result<String> {
    if path == Path::new("-") {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut std::io::stdin(), &mut s).context("stdin")?;
        return Ok(s);
    }
    std::fs::read_to_string(path).with_context(|| path.display().to_string())
}

fn parse_id(s: &str) -> anyhow::Result<Uuid> {
    s.parse()
        .map_err(|_| anyhow::anyhow!("campaign id `{s}` is not a uuid"))
}

fn fmt_eta(s: Option<f64>) -> String {
    s.map_or("–".into(), |s| {
        indicatif::HumanDuration(Duration::from_secs_f64(s.max(0.0))).to_string()
    })
}

/// `rate … units/s  ETA …` of `grit run`'s bar, `grit status` and its `--watch`, in the
/// campaign's progress `units` (impacts or slices).
fn fmt_rate_eta(s: &CampaignStatus, units: &str) -> String {
    format!(
        "rate {}  ETA {}",
        s.rate_impacts_per_s
            .map_or("–".into(), |r| format!("{r:.3} {units}/s")),
        fmt_eta(s.eta_s)
    )
}

/// The running jobs' replay of stored units, which the progress lines add since it keeps
/// the count still and the rate unknown: empty when none replays.
fn fmt_replay(s: &CampaignStatus) -> String {
    s.replaying.map_or(String::new(), |r| {
        format!(
            "  replaying {} stored {} ({} job{})",
            r.units_left,
            unit(s.scene),
            r.jobs,
            if r.jobs == 1 { "" } else { "s" }
        )
    })
}

/// A cell as `grit status` names it: angle and shape with any swept values, or its index
/// where the scene has no angle (the jet).
fn cell_label(s: &CampaignStatus, c: &CellProgress) -> String {
    let mut label = match (c.angle_deg, &c.shape) {
        (Some(angle), Some(shape)) => format!("{angle:.1}° {shape}"),
        _ => format!("{} cell {} ({})", s.scene.as_str(), c.cell, unit(s.scene)),
    };
    for (k, v) in &c.swept {
        label.push_str(&format!(", {k} {v}"));
    }
    label
}

fn fmt_state(s: &CampaignState) -> String {
    format!("{s:?}").to_lowercase()
}

/// What a campaign of `scene` counts its progress in.
fn unit(scene: Scene) -> &'static str {
    match scene {
        Scene::Impact => "impacts",
        Scene::Jet => "slices",
    }
}

/// `grit run`: the campaign on this machine, a progress bar, results.json and its charts.
pub async fn run(a: RunArgs) -> anyhow::Result<ExitCode> {
    let text = read_spec_text(&a.campaign)?;
    let spec = AnySpec::from_json(&text)
        .and_then(|s| s.validate().map(|_| s))
        .with_context(|| a.campaign.display().to_string())?;
    // Without --engine-upgrade, `embedded::run` itself refuses a folder of another engine.
    let mismatch = match &a.engine_upgrade {
        Some(_) => embedded::engine_mismatch(&spec, &a.out).await?,
        None => None,
    };
    let out = match (mismatch, &a.engine_upgrade) {
        (Some((pinned, own)), Some(fresh)) => {
            eprintln!(
                "--engine-upgrade: {} holds this campaign on engine {pinned}; running it afresh in {} on engine {own}",
                a.out.display(),
                fresh.display()
            );
            fresh.clone()
        }
        _ => a.out.clone(),
    };
    let opts = EmbeddedOptions {
        out: out.clone(),
        workers: a.workers,
        threads_per_worker: a.threads,
        checkpoint_every: a.checkpoint_every,
        raw: a.raw,
        commit: Some(env!("GRIT_COMMIT").to_string()),
        interim_every: Some(Duration::from_secs_f64(a.interim_every)),
    };
    let results_path = out.join("results.json");
    let stop = Stop::default();
    on_signals(stop.clone());
    let units = unit(spec.scene());
    let bar = progress::bar(0, units, !a.quiet);
    // Without a terminal (a log file, a batch job) the bar draws nothing: say the same in a
    // plain line now and then, so long campaigns still show progress.
    let plain = !a.quiet && !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let started = Instant::now();
    let mut last_line: Option<Instant> = None;
    let outcome = embedded::run(&spec, &opts, stop, |event| match event {
        RunEvent::Started { impacts_total } => bar.set_length(impacts_total),
        RunEvent::Status(status) => {
            // Cells that grow (until_steady, target_sem_rel) raise the total.
            bar.set_length(status.impacts_total);
            bar.set_position(status.impacts_done);
            bar.set_message(run_message(status, units));
            if plain && last_line.is_none_or(|t| t.elapsed() >= Duration::from_secs(30)) {
                last_line = Some(Instant::now());
                eprintln!(
                    "[{:>6.0} s] {}/{} {units}  {}",
                    started.elapsed().as_secs_f64(),
                    status.impacts_done,
                    status.impacts_total,
                    bar.message()
                );
            }
        }
        RunEvent::Interim(results) => {
            let (complete, cells) = results.cells_complete();
            let line = match write_json(&results_path, results) {
                Ok(()) => format!(
                    "interim results ({complete} of {cells} cells complete) in {}",
                    results_path.display()
                ),
                Err(e) => format!("interim results not written: {e:#}"),
            };
            progress::note(&bar, &line);
        }
        RunEvent::Note(line) => progress::note(&bar, &line),
    })
    .await?;
    bar.finish();
    // Taken before the series are dropped: the charts below need them.
    let charted = serde_json::to_string(&outcome.results);
    let mut written = outcome.results;
    if !a.raw {
        written.strip_raw();
    }
    write_json(&results_path, &written)?;
    eprintln!(
        "campaign {:?}; results in {}",
        outcome.state,
        results_path.display()
    );
    say_cells(&written);
    warn_unsteady_any(&written, true);
    // Charts beside results.json, from every sample's series even where results.json leaves
    // them out: the per-sample curves and the damage balance need them (`grit plot` on a
    // `--raw` file draws the same). A chart that fails leaves the results, already written,
    // standing.
    let charts = charted
        .map_err(|e| grit_plot::PlotError::Input(e.to_string()))
        .and_then(|text| grit_plot::parse_any(&text))
        .and_then(|input| grit_plot::plot_any(&input, &out));
    match charts {
        Ok(r) => eprintln!(
            "{} chart files (PNG, SVG) in {}",
            r.files.len(),
            out.display()
        ),
        Err(e) => eprintln!("charts not written: {e}"),
    }
    Ok(match outcome.state {
        CampaignState::Done => ExitCode::SUCCESS,
        _ => ExitCode::from(1),
    })
}

/// An impact cell's line: the seed's erosion (section 4, last-20 slope) as mean ± std over
/// samples, and the damage balance (docs/erosion.md): the last window's loss/damage added and
/// the loss over the last 60 impacts with its standard error.
fn impact_cell_line(c: &grit_erosion::CellResult) -> String {
    let fmt = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{x:.4e}"));
    // Below 1 while the surface still stores more damage than it loses.
    let paid = c
        .damage_balance
        .and_then(|b| b.ratio)
        .map_or(String::new(), |q| format!("  loss/damage added {q:.2}"));
    // The last window's slope swings with the cell's fluctuations; the last 60 impacts' loss
    // is the steadier figure beside it.
    let long = c.long_balance.map_or(String::new(), |b| {
        format!(
            "  last {} loss {:.4e} (s.e. {:.1e})",
            b.points, b.loss_rate, b.loss_rate_sem
        )
    });
    format!(
        "{:>6.1}°  {:<10} samples {:>3}  erosion {} ± {}{paid}{long}",
        c.angle_deg,
        c.shape,
        c.samples,
        fmt(c.erosion_mean),
        fmt(c.erosion_std)
    )
}

/// One line per cell of the results on stdout: erosion for impacts, Cd, Cw and mass loss at T
/// for a jet.
fn say_cells(results: &AnyResults) {
    match results {
        AnyResults::Impact(r) => {
            for c in &r.results.cells {
                say!("{}", impact_cell_line(c));
            }
        }
        AnyResults::Jet(r) => {
            let pm = |s: &Option<grit_erosion::stats::Stats>, scale: f64| {
                s.map_or("–".to_string(), |s| {
                    format!(
                        "{:.4} ± {}",
                        s.mean * scale,
                        s.std.map_or("–".into(), |d| format!("{:.4}", d * scale))
                    )
                })
            };
            for c in &r.results.cells {
                say!(
                    "cell {:>3}  v {:>6.1} m/s  samples {:>3}  Cd {} mm  Cw {} mm  loss {} mg/m  stage-3 {}",
                    c.cell,
                    c.velocity_m_s,
                    c.samples,
                    pm(&c.crater_depth_m, 1e3),
                    pm(&c.crater_width_m, 1e3),
                    pm(&c.mass_loss_kg_m, 1e6),
                    c.stage3.slope_kg_m_s.map_or("–".to_string(), |f| format!(
                        "{:.4e} ± {:.1e} kg/m/s",
                        f.value, f.sem
                    ))
                );
                if let Some(line) = c.rock_summary() {
                    say!("          {line}");
                }
            }
        }
    }
}

/// [`warn_unsteady`] for results of either scene: a jet cell warns when its stage-3 slope is
/// not steady (docs/jet-campaigns.md).
fn warn_unsteady_any(results: &AnyResults, all: bool) {
    match results {
        AnyResults::Impact(r) => warn_unsteady(&r.results, all),
        AnyResults::Jet(r) => {
            let mut judged = r.results.clone();
            if !all {
                judged.cells.retain(|c| !c.partial);
            }
            for line in judged.unsteady_warnings() {
                eprintln!("{line}");
            }
        }
    }
}

/// Warns on stderr of every cell whose erosion is not a steady-state rate (docs/erosion.md,
/// *Steady state*), and notes every cell whose loss does not yet pay for its damage, so stdout
/// and JSON output stay clean. Without `all`, only cells that
/// have all their samples are judged: a running cell is not yet at steady state by design.
fn warn_unsteady(results: &CampaignResults, all: bool) {
    let mut judged = results.clone();
    if !all {
        judged.cells.retain(|c| !c.partial);
    }
    for line in judged.unsteady_warnings() {
        eprintln!("{line}");
    }
    for line in judged.unbalanced_notes() {
        eprintln!("{line}");
    }
}

/// Warns of a campaign's unsteady cells from its results, if the coordinator sends them in
/// a form this grit reads; a status must not fail because the results could not be judged.
/// The campaign's last job error, if any, as `grit status` prints it.
fn say_last_error(s: &CampaignStatus) {
    if let Some(e) = &s.last_error {
        say!(
            "last error (cell {}, sample {}): {}",
            e.cell,
            e.sample,
            e.error
        );
    }
}

async fn warn_unsteady_remote(client: &Client, id: Uuid, finished: bool) {
    match client.results_value(id, false).await {
        Ok(v) => match serde_json::from_value::<AnyResults>(v) {
            Ok(r) => warn_unsteady_any(&r, finished),
            Err(e) => eprintln!("steady state not checked: results not readable ({e})"),
        },
        Err(e) => eprintln!("steady state not checked: results not fetched ({e})"),
    }
}

/// The bar's message while `grit run` runs: rate, ETA and jobs done.
fn run_message(status: &CampaignStatus, units: &str) -> String {
    let j = &status.jobs;
    format!(
        "{}  jobs {}/{} done{}{}",
        fmt_rate_eta(status, units),
        j.done,
        j.done + j.queued + j.leased + j.failed + j.cancelled,
        if j.failed > 0 {
            format!(", {} failed", j.failed)
        } else {
            String::new()
        },
        fmt_replay(status)
    )
}

/// The coordinator's refusal of the spec in `file`, naming the file; other errors as they are.
fn refused_spec(file: &Path, e: ClientError) -> anyhow::Error {
    match e {
        ClientError::Status { message, .. } => anyhow::anyhow!("{}: {message}", file.display()),
        other => other.into(),
    }
}

/// `grit submit`.
pub async fn submit(a: SubmitArgs) -> anyhow::Result<ExitCode> {
    let text = read_spec_text(&a.file)?;
    let client = a.remote.client()?;
    let created = client
        .submit(&text, a.idempotency_key.as_deref())
        .await
        .map_err(|e| refused_spec(&a.file, e))?;
    eprintln!(
        "{} campaign: {} jobs, {} impacts",
        if created.created {
            "submitted"
        } else {
            "already submitted"
        },
        created.jobs,
        created.impacts_total
    );
    say!("{}", created.id);
    Ok(ExitCode::SUCCESS)
}

/// `grit status`: every campaign, one campaign, or one watched to its end.
pub async fn status(a: StatusArgs) -> anyhow::Result<ExitCode> {
    let json = a.json;
    let client = a.remote.client()?;
    let Some(id) = a.id.as_deref() else {
        let list = client.list().await?;
        if json {
            say!("{}", serde_json::to_string_pretty(&list)?);
        } else {
            for c in list {
                say!(
                    "{}  {:<9}  {}/{} {}  {}",
                    c.id,
                    fmt_state(&c.state),
                    c.impacts_done,
                    c.impacts_total,
                    unit(c.scene),
                    c.name.unwrap_or_default()
                );
            }
        }
        return Ok(ExitCode::SUCCESS);
    };
    let id = parse_id(id)?;
    if a.watch {
        return watch(&client, id).await;
    }
    let s = client.status(id).await?;
    if json {
        say!("{}", serde_json::to_string_pretty(&s)?);
    } else {
        say!(
            "{}  {}  {}/{} {}  jobs: {} queued, {} leased, {} done, {} failed, {} cancelled  {}{}",
            s.id,
            fmt_state(&s.state),
            s.impacts_done,
            s.impacts_total,
            unit(s.scene),
            s.jobs.queued,
            s.jobs.leased,
            s.jobs.done,
            s.jobs.failed,
            s.jobs.cancelled,
            fmt_rate_eta(&s, unit(s.scene)),
            fmt_replay(&s)
        );
        say!(
            "engine {}",
            s.engine
                .as_deref()
                .unwrap_or("(not pinned: created before engine pins)")
        );
        for c in &s.cells {
            say!(
                "  {}  {}/{} samples  {}/{} {}",
                cell_label(&s, c),
                c.samples_done,
                c.samples_total,
                c.impacts_done,
                c.impacts_total,
                unit(s.scene)
            );
        }
        say_last_error(&s);
    }
    if let Some(warning) = engine_warning(&s) {
        eprintln!("{warning}");
    }
    if s.impacts_done > 0 {
        warn_unsteady_remote(&client, id, s.state.is_final()).await;
    }
    Ok(ExitCode::SUCCESS)
}

/// The warning for a campaign whose jobs wait for an engine no live worker has.
fn engine_warning(s: &CampaignStatus) -> Option<String> {
    let waiting = s.jobs.queued + s.jobs.leased > 0;
    match (&s.engine, s.engine_seen) {
        (Some(e), Some(false)) if waiting => Some(format!(
            "warning: no worker with engine {e} was seen in the last lease period; this \
             campaign's jobs are leased only to workers of that engine (`grit version --json`)"
        )),
        _ => None,
    }
}

/// `grit status ID --watch`: a bar for the campaign and one per cell, refreshed every 2 s.
async fn watch(client: &Client, id: Uuid) -> anyhow::Result<ExitCode> {
    let multi = MultiProgress::new();
    let total = multi.add(progress::bar(0, "all cells", true));
    let mut cells: Vec<ProgressBar> = Vec::new();
    loop {
        let s = match client.status(id).await {
            Ok(s) => s,
            Err(e) if e.is_transient() => {
                total.set_message(format!("(coordinator unreachable: {e})"));
                tokio::time::sleep(Duration::from_secs(2)).await;
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        total.set_length(s.impacts_total);
        total.set_position(s.impacts_done);
        total.set_message(format!(
            "{}  {}{}",
            fmt_state(&s.state),
            fmt_rate_eta(&s, unit(s.scene)),
            fmt_replay(&s)
        ));
        while cells.len() < s.cells.len() {
            let c = &s.cells[cells.len()];
            let prefix = cell_label(&s, c);
            cells.push(multi.add(progress::bar(c.impacts_total, &prefix, true)));
        }
        for (bar, c) in cells.iter().zip(&s.cells) {
            bar.set_length(c.impacts_total);
            bar.set_position(c.impacts_done);
            bar.set_message(format!("{}/{} samples", c.samples_done, c.samples_total));
        }
        if s.state.is_final() {
            total.finish();
            for b in &cells {
                b.finish();
            }
            say_last_error(&s);
            if s.impacts_done > 0 {
                warn_unsteady_remote(client, id, true).await;
            }
            return Ok(ExitCode::SUCCESS);
        }
        tokio::time::sleep(Duration::from_secs(2)).await;
    }
}

/// `grit results`: the aggregated results, to a file or standard output.
pub async fn results(a: ResultsArgs) -> anyhow::Result<ExitCode> {
    let id = parse_id(&a.id)?;
    let v = a.remote.client()?.results_value(id, a.raw).await?;
    match &a.output {
        Some(p) => {
            write_json(p, &v)?;
            eprintln!("results written to {}", p.display());
        }
        None => say!("{}", serde_json::to_string_pretty(&v)?),
    }
    // After the JSON, so a reader of the terminal sees the warnings last; the `raw` field,
    // when present, is not part of `CampaignResults` and is ignored here. Results alone do
    // not say whether the campaign still runs, so only complete cells are judged.
    match serde_json::from_value::<AnyResults>(v) {
        Ok(r) => warn_unsteady_any(&r, false),
        Err(e) => eprintln!("steady state not checked: results not readable ({e})"),
    }
    Ok(ExitCode::SUCCESS)
}

/// `grit cancel`.
pub async fn cancel(a: IdArgs) -> anyhow::Result<ExitCode> {
    let id = parse_id(&a.id)?;
    let r = a.remote.client()?.cancel(id).await?;
    say!("cancelled {id}: {} jobs stopped", r.jobs);
    Ok(ExitCode::SUCCESS)
}

/// `grit raise-caps`.
pub async fn raise_caps(a: RaiseCapsArgs) -> anyhow::Result<ExitCode> {
    let id = parse_id(&a.id)?;
    let text = read_spec_text(&a.file)?;
    let r = a
        .remote
        .client()?
        .raise_caps(id, &text)
        .await
        .map_err(|e| refused_spec(&a.file, e))?;
    for cell in &r.raised {
        say!("{}", cell.describe());
    }
    Ok(ExitCode::SUCCESS)
}

/// `grit retry-failed`.
pub async fn retry_failed(a: IdArgs) -> anyhow::Result<ExitCode> {
    let id = parse_id(&a.id)?;
    let r = a.remote.client()?.retry_failed(id).await?;
    say!("{id}: {} failed jobs queued again", r.jobs);
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::impact_cell_line;

    fn cell(balances: bool) -> grit_erosion::CellResult {
        let balance = |points: usize, loss: f64, damage: f64| {
            serde_json::json!({
                "points": points, "samples": 25, "loss_rate": loss, "loss_rate_sem": 7e-5,
                "damage_rate": damage, "damage_rate_sem": 6e-5, "difference_sem": 1e-4,
                "ratio": loss / damage, "balanced": false, "detectable_rel": 0.05,
            })
        };
        let mut json = serde_json::json!({
            "angle_deg": 45.0, "shape": "hexagon", "partial": false, "samples": 25,
            "samples_planned": 25, "samples_reported": 25, "samples_without_slope": 0,
            "impacts_planned": 420, "erosion_mean": 4.1385e-3, "erosion_std": 9.5548e-4,
            "erosion_sem": 1.9e-4, "per_sample": [], "mean_series": [], "convergence": [],
        });
        if balances {
            json["damage_balance"] = balance(20, 4.0e-3, 5.0e-3);
            json["long_balance"] = balance(60, 3.9006e-3, 4.2e-3);
        }
        serde_json::from_value(json).unwrap()
    }

    #[test]
    fn a_cells_line_gives_the_last_60_impacts_loss_beside_the_last_window() {
        assert_eq!(
            impact_cell_line(&cell(true)),
            "  45.0°  hexagon    samples  25  erosion 4.1385e-3 ± 9.5548e-4  \
             loss/damage added 0.80  last 60 loss 3.9006e-3 (s.e. 7.0e-5)"
        );
        // Records without the damage (older files) leave both figures out, not zeros.
        assert_eq!(
            impact_cell_line(&cell(false)),
            "  45.0°  hexagon    samples  25  erosion 4.1385e-3 ± 9.5548e-4"
        );
    }
}
