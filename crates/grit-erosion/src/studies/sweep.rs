//! The speed–accuracy sweep (`grit bench sweep`): erosion of the hexagon at one angle (the
//! last-20 slope of Mohseni-Mofidi et al. 2022, section 4) and the Hertz p0 error (eq. 31) at
//! several resolutions and numerical variants, each against the wall time per impact.

use std::time::Instant;

use grit_sph::verification::hertz;
use grit_sph::{InputError, KernelKind, Settings};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::StudyError;
use crate::impact::aggregate::{aggregate_cell, CellInput, SampleInput, SLOPE_WINDOW};
use crate::impact::sample::{Sample, SampleError};
use crate::impact::{filter_interval_in_time, ImpactParams, Numerics, MIN_SURFACE_LAYERS};

/// A numerical variant of the sweep: the numerics of Mohseni-Mofidi et al. 2022 (`seed`), or one
/// choice changed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Variant {
    /// The paper's numerics (quintic kernel, eq. 4; Courant number 0.3; the density filter
    /// every 40 steps), `Numerics::seed`.
    Seed,
    /// The default scene's numerics (`Numerics::default`): the seed's at CFL 0.6 with the
    /// density filter's period kept in time.
    Default,
    /// The Wendland C2 kernel (support 2h, about 21 neighbours against the quintic's 48).
    WendlandC2,
    /// The cubic spline (support 2h, the kernel of the water-jet scene's paper).
    CubicSpline,
    /// The paper's numerics at another Courant number.
    Cfl(f64),
    /// The paper's numerics with the grain's approach flight simulated step by step, as before
    /// the flight skip (`Numerics::skip_flight`) became the default.
    FullFlight,
    /// The paper's numerics with the density filter (eq. 12) every this many steps instead of
    /// 40; 0 switches it off.
    Filter(u32),
    /// The paper's numerics at another Courant number, with the filter interval in steps scaled
    /// so that the filter runs as often in simulated time as the seed's 40 steps at CFL 0.3.
    CflFilterInTime(f64),
    /// The default scene's numerics with the density filter (eq. 12) every this many steps
    /// instead of its period in time; 0 switches it off.
    DefaultFilter(u32),
    /// The default scene's numerics with another smoothing length over spacing h/Δx (seed eq. 4
    /// with the seed's 1.3): fewer neighbours per particle, but a shorter step (dt ∝ h).
    HOverDx(f64),
}

impl Variant {
    /// Parses `seed`, `default`, `wendland_c2`, `cubic_spline`, `full_flight`, `cfl=X`,
    /// `cfl_time=X`, `filter=N`, `default_filter=N` or `h=X`.
    pub fn parse(s: &str) -> Result<Variant, InputError> {
        fn bad<T>(rule: String) -> Result<T, InputError> {
            Err(InputError::new("--variants", rule))
        }
        match s.trim() {
            "seed" | "quintic" => Ok(Variant::Seed),
            "default" => Ok(Variant::Default),
            "wendland_c2" | "wendland" => Ok(Variant::WendlandC2),
            "cubic_spline" => Ok(Variant::CubicSpline),
            "full_flight" => Ok(Variant::FullFlight),
            other if other.starts_with("default_filter=") => {
                match other["default_filter=".len()..].parse::<u32>() {
                    Ok(n) => Ok(Variant::DefaultFilter(n)),
                    _ => bad(format!(
                        "`{other}`: the filter interval is a whole number of steps (0 = off)"
                    )),
                }
            }
            other if other.starts_with("filter=") => {
                match other["filter=".len()..].parse::<u32>() {
                    Ok(n) => Ok(Variant::Filter(n)),
                    _ => bad(format!(
                        "`{other}`: the filter interval is a whole number of steps (0 = off)"
                    )),
                }
            }
            other if other.starts_with("cfl_time=") => {
                match other["cfl_time=".len()..].parse::<f64>() {
                    Ok(c) if c > 0.0 && c <= grit_sph::world::MAX_CFL => {
                        Ok(Variant::CflFilterInTime(c))
                    }
                    _ => bad(format!("`{other}`: the Courant number must be in (0, 2]")),
                }
            }
            other if other.starts_with("h=") => match other["h=".len()..].parse::<f64>() {
                // Below 1 the quintic's support (3h) holds too few neighbours for the
                // correction matrices (eq. 8) near a free surface.
                Ok(h) if (1.0..=2.0).contains(&h) => Ok(Variant::HOverDx(h)),
                _ => bad(format!("`{other}`: h/Δx must be in [1, 2]")),
            },
            other => match other.strip_prefix("cfl=").map(str::parse::<f64>) {
                Some(Ok(c)) if c > 0.0 && c <= grit_sph::world::MAX_CFL => Ok(Variant::Cfl(c)),
                Some(_) => bad(format!(
                    "`{other}`: the Courant number must be in (0, 2]"
                )),
                None => bad(format!(
                    "unknown variant `{other}` (known: seed, default, wendland_c2, cubic_spline, full_flight, cfl=X, cfl_time=X, filter=N, default_filter=N, h=X)"
                )),
            },
        }
    }

    /// The name in tables and legends.
    pub fn name(&self) -> String {
        match self {
            Variant::Seed => "seed (quintic, CFL 0.3)".into(),
            Variant::Default => format!(
                "default (CFL {}, density filter every {} steps)",
                crate::impact::DEFAULT_CFL,
                filter_interval_in_time(crate::impact::DEFAULT_CFL)
            ),
            Variant::WendlandC2 => "Wendland C2".into(),
            Variant::CubicSpline => "cubic spline".into(),
            Variant::Cfl(c) => format!("CFL {c}"),
            Variant::FullFlight => "seed, flight simulated".into(),
            Variant::Filter(0) => "seed, no density filter".into(),
            Variant::Filter(n) => format!("seed, density filter every {n} steps"),
            Variant::CflFilterInTime(c) => format!(
                "CFL {c}, density filter every {} steps",
                filter_interval_in_time(*c)
            ),
            Variant::HOverDx(h) => format!("default, h/Δx = {h}"),
            Variant::DefaultFilter(0) => "default, no density filter".into(),
            Variant::DefaultFilter(n) => format!("default, density filter every {n} steps"),
        }
    }

    /// The scene's numerics under this variant.
    pub fn numerics(&self) -> Numerics {
        let mut n = Numerics::seed();
        match *self {
            Variant::Seed => {}
            Variant::Default => n = Numerics::default(),
            Variant::WendlandC2 => n.engine.kernel = KernelKind::WendlandC2,
            Variant::CubicSpline => n.engine.kernel = KernelKind::CubicSpline,
            Variant::Cfl(cfl) => n.engine.cfl = cfl,
            Variant::FullFlight => n.skip_flight = false,
            Variant::Filter(every) => n.engine.shepard_interval = every,
            Variant::CflFilterInTime(cfl) => n = n.with_cfl_filter_in_time(cfl),
            Variant::DefaultFilter(every) => {
                n = Numerics::default();
                n.engine.shepard_interval = every;
            }
            Variant::HOverDx(h) => {
                n = Numerics::default();
                n.engine.h_over_dx = h;
            }
        }
        n
    }
}

/// One resolution of one variant: erosion with its spread, Hertz p0 error, and the cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRow {
    /// Variant name.
    pub variant: String,
    /// Impact angle (degrees); absent in rows written before it was recorded (all at 45°).
    #[serde(default)]
    pub angle_deg: Option<f64>,
    /// Particles per grain diameter, Dg/Δx.
    pub particles_per_dg: f64,
    /// Particle spacing Δx (m).
    pub spacing_m: f64,
    /// Surface depth (Dg): the scene's, or deeper where the lattice needs more layers.
    pub surface_depth_dg: f64,
    /// Samples run.
    pub samples: u32,
    /// Impacts per sample.
    pub impacts: u32,
    /// Mean erosion over samples (dimensionless, mass lost over grain mass); none without slopes.
    pub erosion_mean: Option<f64>,
    /// Sample standard deviation of the erosion.
    pub erosion_std: Option<f64>,
    /// Standard error of the mean erosion.
    pub erosion_sem: Option<f64>,
    /// Samples that lost any mass.
    pub samples_with_loss: u32,
    /// Particles of the scene (surface and grain) at the last impact of the first sample.
    pub particles: usize,
    /// Mean steps per impact.
    pub steps_per_impact: f64,
    /// Wall time of all samples over all impacts (s), on `threads` threads.
    pub wall_per_impact_s: f64,
    /// Process CPU time of all samples over all impacts (s): less skewed by other work on the
    /// machine than the wall time (absent in files from before it was recorded).
    #[serde(default)]
    pub cpu_per_impact_s: Option<f64>,
    /// Threads the samples ran on.
    pub threads: usize,
    /// Largest relative error of the Hertz p0 (eq. 31) over 10–50 MN/m, at `hertz_per_radius`.
    pub hertz_p0_error: Option<f64>,
    /// Particles per cylinder radius of the Hertz case (the sweep's particles per Dg).
    pub hertz_per_radius: usize,
    /// Why the Hertz case gave no error, when it failed.
    pub hertz_failure: Option<String>,
    /// Whether the erosion's last-20 window passed the steady-state check of its mean series
    /// (`steady::assess`, seed section 4); absent in files written before it was recorded.
    #[serde(default)]
    pub steady: Option<bool>,
    /// Mean over samples of the first impact with mass loss (the incubation); absent when no
    /// sample lost mass or in older files.
    #[serde(default)]
    pub first_loss_mean_impact: Option<f64>,
}

/// Runs `samples` samples of `impacts` impacts of `base` at spacing `Dg / ppd` under `variant`,
/// samples side by side on the current rayon pool, then the Hertz case at `ppd` particles per
/// radius; `tick` is called after every impact.
pub fn run_resolution(
    base: &ImpactParams,
    variant: Variant,
    ppd: f64,
    samples: u32,
    impacts: u32,
    seed: u64,
    tick: &(dyn Fn() + Sync),
) -> Result<SweepRow, SampleError> {
    // A coarse lattice needs more depth than the scene's for its fixed and free layers.
    // (A hair over the bound: 12/9 Dg at 9 per Dg rounds to 11.999… layers.)
    let min_depth = MIN_SURFACE_LAYERS / ppd * (1.0 + 1e-9);
    let params = ImpactParams {
        spacing_m: base.grain_diameter_m / ppd,
        numerics: variant.numerics(),
        surface_depth_dg: base.surface_depth_dg.max(min_depth),
        ..base.clone()
    };
    params.validate()?;
    let t0 = Instant::now();
    let cpu0 = cpu_time::ProcessTime::try_now().ok();
    let runs: Vec<Result<Sample, SampleError>> = (0..samples)
        .into_par_iter()
        .map(|k| {
            // One seed per sample index, the same at every resolution and variant.
            let mut s = Sample::new(params.clone(), seed.wrapping_add(k as u64))?;
            for _ in 0..impacts {
                s.run_next()?;
                tick();
            }
            Ok(s)
        })
        .collect();
    let wall = t0.elapsed().as_secs_f64();
    let cpu = cpu0
        .and_then(|c| c.try_elapsed().ok())
        .map(|d| d.as_secs_f64());
    let runs: Vec<Sample> = runs.into_iter().collect::<Result<_, _>>()?;
    let cell = CellInput {
        angle_deg: params.angle_deg,
        shape: params.shape.name().to_string(),
        swept: Default::default(),
        planned_samples: samples as usize,
        planned_impacts: impacts as usize,
        samples: runs
            .iter()
            .enumerate()
            .map(|(k, s)| SampleInput {
                sample: k as u32,
                impacts: s.records().iter().map(|r| r.impact()).collect(),
            })
            .collect(),
    };
    let agg =
        aggregate_cell(&cell, SLOPE_WINDOW).map_err(|e| SampleError::Checkpoint(e.to_string()))?;
    let steps: u64 = runs
        .iter()
        .flat_map(|s| s.records())
        .map(|r| r.outcome.steps)
        .sum();
    let n_impacts = (samples * impacts).max(1) as f64;
    let particles = runs.first().map_or(0, Sample::last_particles);
    let hertz_per_radius = ppd.round().max(1.0) as usize;
    let n = variant.numerics();
    let hertz = hertz::simulate_with(
        hertz_per_radius,
        Settings {
            kernel: n.engine.kernel,
            cfl: n.engine.cfl,
            h_over_dx: n.engine.h_over_dx,
            shepard_interval: hertz::DENSITY_FILTER,
            ..Settings::default()
        },
    );
    let (hertz_p0_error, hertz_failure) = match hertz {
        Ok(snaps) => (hertz::max_peak_error(&snaps), None),
        Err(e) => (None, Some(e.to_string())),
    };
    Ok(SweepRow {
        variant: variant.name(),
        angle_deg: Some(params.angle_deg),
        particles_per_dg: ppd,
        spacing_m: params.spacing_m,
        surface_depth_dg: params.surface_depth_dg,
        samples,
        impacts,
        erosion_mean: agg.erosion_mean,
        erosion_std: agg.erosion_std,
        erosion_sem: agg.erosion_sem,
        samples_with_loss: runs
            .iter()
            .filter(|s| s.records().iter().any(|r| r.mass_loss_kg > 0.0))
            .count() as u32,
        particles,
        steps_per_impact: steps as f64 / n_impacts,
        wall_per_impact_s: wall / n_impacts,
        cpu_per_impact_s: cpu.map(|c| c / n_impacts),
        threads: rayon::current_num_threads(),
        hertz_p0_error,
        hertz_per_radius,
        hertz_failure,
        steady: agg.steady_state.as_ref().map(|s| s.steady),
        first_loss_mean_impact: agg
            .steady_state
            .as_ref()
            .and_then(|s| s.incubation_impacts.as_ref())
            .map(|i| i.mean),
    })
}

/// What the rows' cost is measured in: process CPU seconds per impact when every row has them
/// (a loaded machine skews them less), else wall seconds per impact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cost {
    /// `cpu_per_impact_s`.
    Cpu,
    /// `wall_per_impact_s`.
    Wall,
}

impl Cost {
    /// The measure `rows` can all be compared by.
    pub fn of(rows: &[SweepRow]) -> Cost {
        if rows.iter().all(|r| r.cpu_per_impact_s.is_some()) {
            Cost::Cpu
        } else {
            Cost::Wall
        }
    }

    /// The row's cost in this measure (s per impact).
    pub fn get(self, r: &SweepRow) -> f64 {
        match self {
            Cost::Cpu => r.cpu_per_impact_s.unwrap_or(f64::NAN),
            Cost::Wall => r.wall_per_impact_s,
        }
    }

    /// Axis label.
    pub fn label(self) -> &'static str {
        match self {
            Cost::Cpu => "CPU time per impact (s, all threads)",
            Cost::Wall => "wall time per impact (s)",
        }
    }
}

/// The cheapest row whose erosion lies within ±1 standard deviation of the finest row of the
/// first variant (the error bars of the chart); `None` without a finest erosion.
pub fn cheapest_within(rows: &[SweepRow]) -> Option<&SweepRow> {
    let first = &rows.first()?.variant;
    let finest = rows
        .iter()
        .filter(|r| &r.variant == first)
        .max_by(|a, b| a.particles_per_dg.total_cmp(&b.particles_per_dg))?;
    let (m, s) = (finest.erosion_mean?, finest.erosion_std.unwrap_or(0.0));
    // No loss at the finest resolution judges nothing: every zero would "agree" with it.
    if m <= 0.0 {
        return None;
    }
    let cost = Cost::of(rows);
    rows.iter()
        .filter(|r| r.erosion_mean.is_some_and(|e| (e - m).abs() <= s))
        .min_by(|a, b| cost.get(a).total_cmp(&cost.get(b)))
}

/// What `grit bench sweep` runs: every variant at its resolutions, `samples` samples of
/// `impacts` impacts each.
#[derive(Debug, Clone)]
pub struct SweepStudy {
    /// The scene (angle; spacing and numerics are swept).
    pub params: ImpactParams,
    /// Particles per grain diameter.
    pub ppd: Vec<f64>,
    /// Numerical variants; the first is the reference whose finest row judges the others.
    pub variants: Vec<Variant>,
    /// Resolutions the variants after the first run at (all of `ppd` when empty).
    pub variant_ppd: Vec<f64>,
    /// Samples per resolution.
    pub samples: u32,
    /// Impacts per sample.
    pub impacts: u32,
    /// Seed of sample 0 (sample k uses seed + k).
    pub seed: u64,
}

/// What the sweep reports while it runs.
#[derive(Debug, Clone, Copy)]
pub enum SweepProgress {
    /// A (variant, resolution) point starts.
    Point {
        /// The variant.
        variant: Variant,
        /// Particles per grain diameter.
        ppd: f64,
    },
    /// An impact of the point finished (reported from the pool's threads).
    Impact,
}

impl SweepStudy {
    /// Checks the options and the scene; errors name the option or scene field.
    pub fn validate(&self) -> Result<(), StudyError> {
        let bad = |field: &str, rule: String| Err(InputError::new(field, rule).into());
        // The seed's finest is 32 per Dg; 128 is 16 times its particles and 4 times its steps.
        let fine = |p: &f64| p.is_finite() && (6.0..=128.0).contains(p);
        if self.ppd.is_empty() || !self.ppd.iter().all(fine) {
            return bad(
                "--ppd",
                "give resolutions of 6 to 128 particles per Dg".into(),
            );
        }
        if !self.variant_ppd.iter().all(fine) {
            return bad(
                "--variant-ppd",
                "give resolutions of 6 to 128 particles per Dg".into(),
            );
        }
        if self.variants.is_empty() {
            return bad("--variants", "give at least one".into());
        }
        if self.samples < 2 {
            return bad(
                "--samples",
                format!("at least 2 for error bars, got {}", self.samples),
            );
        }
        if (self.impacts as usize) < SLOPE_WINDOW + 1 {
            return bad(
                "--impacts",
                format!(
                    "at least {} (the last-{SLOPE_WINDOW} slope), got {}",
                    SLOPE_WINDOW + 1,
                    self.impacts
                ),
            );
        }
        Ok(self.params.validate()?)
    }

    /// The first row of `rows` (from an earlier run being resumed) with other samples or
    /// impacts than this study: such rows cannot be compared with the new ones.
    pub fn resume_clash<'a>(&self, rows: &'a [SweepRow]) -> Option<&'a SweepRow> {
        rows.iter()
            .find(|r| r.samples != self.samples || r.impacts != self.impacts)
    }

    /// The (variant, resolution) points `done` does not hold yet, in run order.
    pub fn plan(&self, done: &[SweepRow]) -> Vec<(Variant, f64)> {
        let mut plan: Vec<(Variant, f64)> = Vec::new();
        for (k, v) in self.variants.iter().enumerate() {
            let list = if k == 0 || self.variant_ppd.is_empty() {
                &self.ppd
            } else {
                &self.variant_ppd
            };
            plan.extend(list.iter().map(|p| (*v, *p)));
        }
        plan.retain(|(v, p)| {
            !done
                .iter()
                .any(|r| r.variant == v.name() && r.particles_per_dg == *p)
        });
        plan
    }

    /// Runs the points `rows` lacks and appends their rows; `on_row` gets every row so far
    /// after each point (the new one last), so a caller can save them and an interrupted sweep
    /// keeps what it finished.
    pub fn run<E: From<StudyError>>(
        &self,
        mut rows: Vec<SweepRow>,
        progress: &(dyn Fn(SweepProgress) + Sync),
        mut on_row: impl FnMut(&[SweepRow]) -> Result<(), E>,
    ) -> Result<Vec<SweepRow>, E> {
        self.validate()?;
        for (variant, ppd) in self.plan(&rows) {
            progress(SweepProgress::Point { variant, ppd });
            let tick = || progress(SweepProgress::Impact);
            let row = run_resolution(
                &self.params,
                variant,
                ppd,
                self.samples,
                self.impacts,
                self.seed,
                &tick,
            )
            .map_err(|source| StudyError::Point {
                variant: variant.name(),
                ppd,
                source,
            })?;
            rows.push(row);
            on_row(&rows)?;
        }
        Ok(rows)
    }

    /// The chart's notes: the scene, and the cheapest setting within the finest's bars.
    pub fn notes(&self, rows: &[SweepRow]) -> Vec<String> {
        let p = &self.params;
        let mut notes = vec![format!(
            "Scene: {} at {}°, {} m/s, AISI 304; {} samples × {} impacts per point, seeds {}–{}; erosion = last-{SLOPE_WINDOW} slope.",
            p.shape.name(),
            p.angle_deg,
            p.velocity_m_s,
            self.samples,
            self.impacts,
            self.seed,
            self.seed + self.samples as u64 - 1
        )];
        if let Some(best) = cheapest_within(rows) {
            notes.push(format!(
                "Cheapest within the finest's bars: {} at {} per Dg ({:.3} s per impact, {}).",
                best.variant,
                best.particles_per_dg,
                Cost::of(rows).get(best),
                Cost::of(rows).label()
            ));
        }
        notes
    }
}

impl SweepRow {
    /// One line of the sweep's text table.
    pub fn line(&self) -> String {
        let r = self;
        let mg = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{:.3}", x * 1e3));
        format!(
            "{:<24} {:>5} per Dg (depth {:.2} Dg)  {:>6} particles  {:>7.0} steps  {:>8.3} s/impact ({} CPU-s)  erosion {} ± {} (se {}) mg/g, {}/{} samples with loss  Hertz p0 error {}",
            r.variant,
            r.particles_per_dg,
            r.surface_depth_dg,
            r.particles,
            r.steps_per_impact,
            r.wall_per_impact_s,
            r.cpu_per_impact_s.map_or("–".to_string(), |c| format!("{c:.3}")),
            mg(r.erosion_mean),
            mg(r.erosion_std),
            mg(r.erosion_sem),
            r.samples_with_loss,
            r.samples,
            r.hertz_p0_error
                .map_or_else(|| r.hertz_failure.clone().unwrap_or_default(), |e| format!("{:.1} % at {} per radius", e * 100.0, r.hertz_per_radius)),
        ) + &match (r.steady, r.first_loss_mean_impact) {
            (Some(true), Some(f)) => format!("  steady (first loss at impact {f:.0} on average)"),
            (Some(false), Some(f)) => format!("  NOT steady (first loss at impact {f:.0} on average)"),
            (Some(false), None) => "  NOT steady (no sample lost mass)".to_string(),
            _ => String::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variants_parse_and_reject_bad_names() {
        assert_eq!(Variant::parse("seed"), Ok(Variant::Seed));
        assert_eq!(Variant::parse("default"), Ok(Variant::Default));
        assert_eq!(Variant::Seed.numerics(), Numerics::seed());
        assert_eq!(Variant::Default.numerics(), Numerics::default());
        assert_eq!(Variant::parse("wendland_c2"), Ok(Variant::WendlandC2));
        assert_eq!(Variant::parse("cubic_spline"), Ok(Variant::CubicSpline));
        assert_eq!(
            Variant::CubicSpline.numerics().engine.kernel,
            KernelKind::CubicSpline
        );
        assert_eq!(Variant::parse("cfl=0.5"), Ok(Variant::Cfl(0.5)));
        assert!(Variant::parse("cfl=3")
            .unwrap_err()
            .to_string()
            .contains("(0, 2]"));
        assert_eq!(Variant::parse("filter=0"), Ok(Variant::Filter(0)));
        assert_eq!(Variant::parse("h=1.1"), Ok(Variant::HOverDx(1.1)));
        let off = Variant::parse("default_filter=0").unwrap().numerics();
        assert_eq!(off.engine.shepard_interval, 0);
        assert_eq!(off.engine.cfl, Numerics::default().engine.cfl);
        assert_eq!(Variant::HOverDx(1.1).numerics().engine.h_over_dx, 1.1);
        assert_eq!(Variant::HOverDx(1.3).numerics(), Numerics::default());
        assert!(Variant::parse("h=0.8")
            .unwrap_err()
            .to_string()
            .contains("[1, 2]"));
        assert!(Variant::parse("filter=-1").is_err());
        assert_eq!(
            Variant::parse("cfl_time=0.6"),
            Ok(Variant::CflFilterInTime(0.6))
        );
        assert_eq!(filter_interval_in_time(0.6), 20);
        assert_eq!(filter_interval_in_time(0.45), 27);
        assert_eq!(filter_interval_in_time(0.3), 40);
        assert!(Variant::parse("absorbing=4")
            .unwrap_err()
            .to_string()
            .contains("unknown variant `absorbing=4`"));
        assert!(Variant::parse("cubic")
            .unwrap_err()
            .to_string()
            .contains("unknown variant `cubic`"));
    }

    fn row(variant: &str, ppd: f64, e: Option<f64>, std: f64, wall: f64) -> SweepRow {
        SweepRow {
            variant: variant.into(),
            angle_deg: Some(45.0),
            particles_per_dg: ppd,
            spacing_m: 250e-6 / ppd,
            surface_depth_dg: 1.25,
            samples: 5,
            impacts: 30,
            erosion_mean: e,
            erosion_std: Some(std),
            erosion_sem: Some(std / 5f64.sqrt()),
            samples_with_loss: 5,
            particles: 0,
            steps_per_impact: 0.0,
            wall_per_impact_s: wall,
            cpu_per_impact_s: Some(2.0 * wall),
            threads: 2,
            hertz_p0_error: None,
            hertz_per_radius: ppd as usize,
            hertz_failure: None,
            steady: None,
            first_loss_mean_impact: None,
        }
    }

    #[test]
    fn the_cheapest_setting_within_the_finest_bars_is_named() {
        let rows = vec![
            row("seed", 8.0, Some(5.0e-3), 1e-3, 0.1),
            row("seed", 16.0, Some(2.4e-3), 1e-3, 1.0),
            row("seed", 32.0, Some(2.0e-3), 0.5e-3, 10.0),
            row("Wendland C2", 16.0, Some(2.2e-3), 1e-3, 0.6),
            row("Wendland C2", 8.0, None, 0.0, 0.05),
        ];
        let best = cheapest_within(&rows).unwrap();
        assert_eq!(
            (best.variant.as_str(), best.particles_per_dg),
            ("Wendland C2", 16.0)
        );
        assert!(cheapest_within(&[]).is_none());
        // Judged by CPU time when every row has it: here the 8 per Dg row is CPU-cheapest.
        let mut cpu = rows.clone();
        for r in &mut cpu {
            r.cpu_per_impact_s = Some(if r.particles_per_dg == 8.0 { 0.01 } else { 5.0 });
        }
        cpu[0].erosion_mean = Some(2.1e-3);
        assert_eq!(Cost::of(&cpu), Cost::Cpu);
        assert_eq!(cheapest_within(&cpu).unwrap().particles_per_dg, 8.0);
        let mut mixed = cpu.clone();
        mixed[1].cpu_per_impact_s = None;
        assert_eq!(Cost::of(&mixed), Cost::Wall);
        let none = vec![
            row("seed", 8.0, Some(0.0), 0.0, 0.1),
            row("seed", 32.0, Some(0.0), 0.0, 9.0),
        ];
        assert!(
            cheapest_within(&none).is_none(),
            "zero erosion at the finest judges nothing"
        );
    }
}
