//! The stability map (`grit bench stability`): one impact of the paper's scene run with the
//! numerical choices swept (Courant number against hourglass coefficient α of eq. 16; contact
//! spring stiffness of eqs. 24–25 against the time step, for both contact models), each point
//! marked stable or with the failure the engine raised.

use std::cell::Cell;
use std::time::Instant;

use grit_sph::{ContactModel, InputError};
use serde::{Deserialize, Serialize};

use super::StudyError;
use crate::impact::sample::{Sample, SampleError};
use crate::impact::{run_impact_observed, ImpactError, ImpactParams, Numerics};

/// A run whose total energy rises above this multiple of its start gained energy from the
/// numerics: it finished, but its numbers are not to be trusted.
pub const ENERGY_GAIN_LIMIT: f64 = 1.05;

/// Energy is sampled every this many steps (an O(N) sum; every step would cost 5–10 %).
const ENERGY_EVERY: u64 = 10;

/// How a point of the map ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The impact ran to its end and total energy never rose above `ENERGY_GAIN_LIMIT`.
    Stable,
    /// The impact ran to its end, but total energy rose above `ENERGY_GAIN_LIMIT`.
    EnergyGain,
    /// The engine stopped with a failure diagnostic, or the step budget ran out.
    Unstable,
}

/// Which failure stopped an unstable point, from the engine's diagnostic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Failure {
    /// A particle moved more than h in one step.
    MovedMoreThanH,
    /// A position, velocity, stress or density became NaN or infinite.
    NotFinite,
    /// Density went to zero or below.
    NegativeDensity,
    /// A grain particle passed through the surface (negative contact distance).
    PassedThrough,
    /// The time step collapsed: the step budget ran out before the impact ended.
    StepBudget,
    /// Any other diagnostic.
    Other,
}

impl Failure {
    /// Sorts a diagnostic of `World::step` into a failure kind.
    pub fn classify(what: &str) -> Failure {
        if what.contains("in one step, more than h") {
            Failure::MovedMoreThanH
        } else if what.contains("not finite") {
            Failure::NotFinite
        } else if what.contains("is not positive") {
            Failure::NegativeDensity
        } else if what.contains("passed through") {
            Failure::PassedThrough
        } else {
            Failure::Other
        }
    }

    /// One letter for maps and tables.
    pub fn code(self) -> &'static str {
        match self {
            Failure::MovedMoreThanH => "h",
            Failure::NotFinite => "N",
            Failure::NegativeDensity => "D",
            Failure::PassedThrough => "P",
            Failure::StepBudget => "T",
            Failure::Other => "?",
        }
    }

    /// All kinds, in the order legends list them.
    pub const ALL: [Failure; 6] = [
        Failure::MovedMoreThanH,
        Failure::NotFinite,
        Failure::NegativeDensity,
        Failure::PassedThrough,
        Failure::StepBudget,
        Failure::Other,
    ];

    /// The legend of the letters: "h moved > h in a step, N NaN or infinite, …".
    pub fn legend() -> String {
        Failure::ALL
            .iter()
            .map(|f| format!("{} {}", f.code(), f.label()))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// A short label for charts.
    pub fn label(self) -> &'static str {
        match self {
            Failure::MovedMoreThanH => "moved > h in a step",
            Failure::NotFinite => "NaN or infinite",
            Failure::NegativeDensity => "density ≤ 0",
            Failure::PassedThrough => "grain passed through",
            Failure::StepBudget => "time step collapsed",
            Failure::Other => "other",
        }
    }
}

/// The panels of the map: which pair of choices is swept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Panel {
    /// Courant number against hourglass coefficient, the paper's contact model.
    CflHourglass,
    /// Contact stiffness against time step (as a Courant number), the paper's contact model,
    /// with the contact springs not allowed to shorten the step.
    StiffnessStep,
    /// The same with the plain particle–particle penetration contact (seed Fig. 2b).
    StiffnessStepPenetration,
}

impl Panel {
    /// The panel's vertical axis value of a point: hourglass α, or the stiffness scale.
    pub fn y(self, p: &StabilityPoint) -> f64 {
        match self {
            Panel::CflHourglass => p.hourglass,
            _ => p.stiffness_scale,
        }
    }

    /// The contact model the panel runs.
    pub fn contact_model(self) -> ContactModel {
        match self {
            Panel::StiffnessStepPenetration => ContactModel::Penetration,
            _ => ContactModel::Extrapolated,
        }
    }
}

/// The distinct values of one axis of a panel, ascending.
pub fn levels(v: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = v.collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// One point of the map: the choices tried and how the impact went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StabilityPoint {
    /// The panel it belongs to.
    pub panel: Panel,
    /// Contact model.
    pub contact_model: ContactModel,
    /// Courant number.
    pub cfl: f64,
    /// Hourglass coefficient α (eq. 16).
    pub hourglass: f64,
    /// Contact spring stiffness over the CFL-matched default.
    pub stiffness_scale: f64,
    /// Whether the contact springs were allowed to shorten the step.
    pub contact_limits_dt: bool,
    /// The first step's time step (s).
    pub dt_s: f64,
    /// Steps run.
    pub steps: u64,
    /// Wall time (s).
    pub wall_s: f64,
    /// How it ended.
    pub verdict: Verdict,
    /// The failure kind, for unstable points.
    pub failure: Option<Failure>,
    /// The engine's diagnostic, for unstable points.
    pub diagnostic: Option<String>,
    /// Largest total energy (kinetic, elastic, contact) over the start, sampled every 10 steps.
    pub max_energy_ratio: f64,
    /// Surface mass removed (kg per m of depth), for points that finished.
    pub mass_loss_kg: Option<f64>,
    /// Grain speed after over before, for points that finished.
    pub rebound_ratio: Option<f64>,
}

/// The grid of the map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StabilityGrid {
    /// Courant numbers (both panels).
    pub cfl: Vec<f64>,
    /// Hourglass coefficients (first panel).
    pub hourglass: Vec<f64>,
    /// Contact stiffness over the default (second and third panels).
    pub stiffness_scale: Vec<f64>,
}

impl Default for StabilityGrid {
    fn default() -> Self {
        StabilityGrid {
            cfl: vec![0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.4, 2.0],
            hourglass: vec![0.0, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0],
            stiffness_scale: vec![0.25, 1.0, 4.0, 16.0, 64.0, 256.0],
        }
    }
}

impl StabilityGrid {
    /// The numerics of every point, panel by panel, in the order they are run.
    pub fn points(&self) -> Vec<(Panel, Numerics)> {
        let base = Numerics::seed();
        let mut v = Vec::new();
        for &hourglass in &self.hourglass {
            for &cfl in &self.cfl {
                let mut n = base.clone();
                n.engine.cfl = cfl;
                n.engine.hourglass = hourglass;
                v.push((Panel::CflHourglass, n));
            }
        }
        for panel in [Panel::StiffnessStep, Panel::StiffnessStepPenetration] {
            for &contact_stiffness_scale in &self.stiffness_scale {
                for &cfl in &self.cfl {
                    let mut n = Numerics {
                        contact_model: panel.contact_model(),
                        contact_stiffness_scale,
                        ..base.clone()
                    };
                    n.engine.cfl = cfl;
                    n.engine.contact_limits_dt = false;
                    v.push((panel, n));
                }
            }
        }
        v
    }

    /// Checks every value against what the engine accepts; the error names the list.
    pub fn validate(&self) -> Result<(), InputError> {
        let check = |name: &str, v: &[f64], ok: &dyn Fn(f64) -> bool, rule: &str| {
            let field = format!("--{name}");
            if v.is_empty() {
                return Err(InputError::new(field, "give at least one value"));
            }
            match v.iter().find(|x| !ok(**x)) {
                Some(x) => Err(InputError::new(
                    field,
                    format!("{x} is out of range ({rule})"),
                )),
                None => Ok(()),
            }
        };
        check(
            "cfl",
            &self.cfl,
            &|x| x > 0.0 && x <= grit_sph::world::MAX_CFL,
            "each must be in (0, 2]",
        )?;
        check(
            "hourglass",
            &self.hourglass,
            &|x| x.is_finite() && x >= 0.0,
            "each must be >= 0",
        )?;
        check(
            "stiffness",
            &self.stiffness_scale,
            &|x| x.is_finite() && x > 0.0,
            "each must be > 0",
        )
    }
}

/// The Courant number above which a contact spring of `stiffness_scale` times the default is
/// unstable on its own: dt < 2√(m/k) with m/k₀ = (h/c)², so CFL < 2/√scale.
pub fn spring_limit_cfl(stiffness_scale: f64) -> f64 {
    2.0 / stiffness_scale.sqrt()
}

/// The surface and grain every point starts from: the sample's surface after `after` impacts
/// with the scene's own numerics, and the grain of impact `after + 1`.
pub fn start(base: &ImpactParams, seed: u64, after: u32) -> Result<Sample, SampleError> {
    let mut s = Sample::new(base.clone(), seed)?;
    for _ in 0..after {
        s.run_next()?;
    }
    Ok(s)
}

/// Runs one point from `from`'s surface and next grain with `numerics` in place of the scene's.
/// The step budget is `budget_factor` times the steps the longest impact would take at the
/// first step's dt, so a collapsing step ends the point instead of running for hours.
pub fn run_point(
    from: &Sample,
    panel: Panel,
    numerics: Numerics,
    budget_factor: f64,
) -> Result<StabilityPoint, SampleError> {
    let params = ImpactParams {
        numerics: numerics.clone(),
        ..from.params().clone()
    };
    params.validate()?;
    let grain = from.next_grain()?;
    let steps = Cell::new(0u64);
    let first_dt = Cell::new(0.0f64);
    let e0 = Cell::new(0.0f64);
    let emax = Cell::new(1.0f64);
    let budget = Cell::new(u64::MAX);
    let t_max = crate::impact::max_impact_time(&params);
    let mut observe = |w: &grit_sph::World| {
        let n = w.steps();
        steps.set(n);
        if n == 1 {
            first_dt.set(w.dt());
            budget.set((budget_factor * t_max / w.dt()).ceil() as u64);
        }
        if n == 1 || n.is_multiple_of(ENERGY_EVERY) {
            let e = w.energy();
            let total = e.kinetic + e.elastic + e.contact;
            if e0.get() == 0.0 {
                e0.set(total);
            } else if total.is_finite() {
                emax.set(emax.get().max(total / e0.get()));
            }
        }
    };
    let cancel = || steps.get() > budget.get();
    let t0 = Instant::now();
    let run = run_impact_observed(&params, from.surface(), &grain, &cancel, Some(&mut observe));
    let wall_s = t0.elapsed().as_secs_f64();
    let mut point = StabilityPoint {
        panel,
        contact_model: numerics.contact_model,
        cfl: numerics.engine.cfl,
        hourglass: numerics.engine.hourglass,
        stiffness_scale: numerics.contact_stiffness_scale,
        contact_limits_dt: numerics.engine.contact_limits_dt,
        dt_s: first_dt.get(),
        steps: steps.get(),
        wall_s,
        verdict: Verdict::Stable,
        failure: None,
        diagnostic: None,
        max_energy_ratio: emax.get(),
        mass_loss_kg: None,
        rebound_ratio: None,
    };
    match run {
        Ok(r) => {
            point.mass_loss_kg = Some(r.outcome.mass_loss_kg);
            point.rebound_ratio = Some(r.outcome.rebound_ratio);
            if point.max_energy_ratio > ENERGY_GAIN_LIMIT {
                point.verdict = Verdict::EnergyGain;
            }
        }
        Err(ImpactError::Sim(e)) => {
            point.verdict = Verdict::Unstable;
            point.failure = Some(Failure::classify(&e.what));
            point.diagnostic = Some(e.to_string());
        }
        Err(ImpactError::Cancelled) => {
            point.verdict = Verdict::Unstable;
            point.failure = Some(Failure::StepBudget);
            point.diagnostic = Some(format!(
                "{} steps without the impact ending: the time step fell below {:.2e} s",
                steps.get(),
                t_max / steps.get().max(1) as f64
            ));
        }
        Err(ImpactError::Input(e)) => return Err(e.into()),
    }
    Ok(point)
}

/// What `grit bench stability` maps: one scene, one surface state, the grid of numerics.
#[derive(Debug, Clone)]
pub struct StabilityStudy {
    /// The scene (angle, spacing; its numerics are swept).
    pub params: ImpactParams,
    /// Seed of the sample the grain is drawn from.
    pub seed: u64,
    /// Impacts the surface takes (with the scene's own numerics) before the mapped one.
    pub after: u32,
    /// The grid.
    pub grid: StabilityGrid,
    /// Step budget over the steps the longest impact takes at the first step's dt.
    pub budget_factor: f64,
}

/// What the stability map reports while it runs.
#[derive(Debug, Clone, Copy)]
pub enum StabilityProgress<'a> {
    /// A point starts.
    Start {
        /// Its panel.
        panel: Panel,
        /// Its numerics.
        numerics: &'a Numerics,
    },
    /// A point finished.
    Done {
        /// Its panel.
        panel: Panel,
        /// Its numerics.
        numerics: &'a Numerics,
        /// How it went.
        point: &'a StabilityPoint,
    },
}

impl StabilityStudy {
    /// Checks the grid, the scene and the budget; errors name the option or scene field.
    pub fn validate(&self) -> Result<(), StudyError> {
        self.grid.validate()?;
        self.params.validate()?;
        if !(self.budget_factor.is_finite() && self.budget_factor > 0.0) {
            return Err(InputError::new(
                "--budget",
                format!("must be > 0, got {}", self.budget_factor),
            )
            .into());
        }
        Ok(())
    }

    /// Prepares the surface, then runs every point of the grid from it, one after the other
    /// (each on the current rayon pool), reporting each point's start and end to `progress`.
    pub fn run(
        &self,
        mut progress: impl FnMut(StabilityProgress<'_>),
    ) -> Result<Vec<StabilityPoint>, StudyError> {
        self.validate()?;
        let from = start(&self.params, self.seed, self.after)?;
        let todo = self.grid.points();
        let mut points = Vec::with_capacity(todo.len());
        for (panel, numerics) in todo {
            progress(StabilityProgress::Start {
                panel,
                numerics: &numerics,
            });
            let point = run_point(&from, panel, numerics.clone(), self.budget_factor)?;
            progress(StabilityProgress::Done {
                panel,
                numerics: &numerics,
                point: &point,
            });
            points.push(point);
        }
        Ok(points)
    }

    /// The chart's note on the scene.
    pub fn note(&self) -> String {
        let p = &self.params;
        format!(
            "Scene: hexagon at {}°, {} m/s, AISI 304, Δx = {:e} m ({:.0} particles per Dg), one impact on a surface after {} impacts, seed {}.",
            p.angle_deg,
            p.velocity_m_s,
            p.spacing_m,
            p.grain_diameter_m / p.spacing_m,
            self.after,
            self.seed
        )
    }
}

/// The map as text, one block per panel: the verdict of each Courant number (columns) at each
/// hourglass α or stiffness (rows), and a legend.
pub fn table(points: &[StabilityPoint]) -> String {
    let mut s = String::new();
    for panel in [
        Panel::CflHourglass,
        Panel::StiffnessStep,
        Panel::StiffnessStepPenetration,
    ] {
        let pts: Vec<&StabilityPoint> = points.iter().filter(|p| p.panel == panel).collect();
        if pts.is_empty() {
            continue;
        }
        let y = |p: &StabilityPoint| panel.y(p);
        let cfl = levels(pts.iter().map(|p| p.cfl));
        let ys = levels(pts.iter().map(|p| y(p)));
        let (name, yname) = match panel {
            Panel::CflHourglass => ("Courant number × hourglass α, seed contact", "α"),
            Panel::StiffnessStep => ("stiffness × step, seed contact", "k/k0"),
            Panel::StiffnessStepPenetration => ("stiffness × step, penetration contact", "k/k0"),
        };
        s.push_str(&format!("{name}\n{yname:>8} |"));
        for c in &cfl {
            s.push_str(&format!(" {c:>5}"));
        }
        s.push('\n');
        for yv in ys.iter().rev() {
            s.push_str(&format!("{yv:>8} |"));
            for c in &cfl {
                let mark = pts
                    .iter()
                    .find(|p| p.cfl == *c && y(p) == *yv)
                    .map(|p| match p.verdict {
                        Verdict::Stable => "ok".to_string(),
                        Verdict::EnergyGain => "E+".to_string(),
                        Verdict::Unstable => format!("x:{}", p.failure.map_or("?", |f| f.code())),
                    })
                    .unwrap_or_default();
                s.push_str(&format!(" {mark:>5}"));
            }
            s.push('\n');
        }
        s.push('\n');
    }
    s.push_str(&format!(
        "ok stable · E+ finished, but energy rose above {}× · x: unstable ({})\n",
        ENERGY_GAIN_LIMIT,
        Failure::legend()
    ));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diagnostics_are_sorted_into_kinds() {
        let c = Failure::classify;
        assert_eq!(
            c("particle 3 of body 'surface' at (0, 0) m: moved 1e-5 m in one step, more than h = 1e-5 m"),
            Failure::MovedMoreThanH
        );
        assert_eq!(
            c("rigid body 'grain': position or velocity is not finite"),
            Failure::NotFinite
        );
        assert_eq!(
            c("density -1.0e3 kg/m³ is not positive"),
            Failure::NegativeDensity
        );
        assert_eq!(
            c("particle 1 passed through the surface"),
            Failure::PassedThrough
        );
        assert_eq!(c("something new"), Failure::Other);
    }

    #[test]
    fn the_grid_covers_three_panels_and_rejects_bad_values() {
        let g = StabilityGrid::default();
        let pts = g.points();
        assert_eq!(pts.len(), 64 + 2 * 48);
        assert!(pts
            .iter()
            .filter(|(p, _)| *p == Panel::StiffnessStepPenetration)
            .all(|(_, n)| n.contact_model == ContactModel::Penetration
                && !n.engine.contact_limits_dt));
        let bad = StabilityGrid {
            cfl: vec![0.3, 2.5],
            ..g.clone()
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("--cfl: 2.5"));
        let empty = StabilityGrid {
            hourglass: vec![],
            ..g
        };
        assert!(empty
            .validate()
            .unwrap_err()
            .to_string()
            .contains("--hourglass"));
    }

    #[test]
    fn the_spring_limit_is_the_cfl_matched_period() {
        assert!((spring_limit_cfl(1.0) - 2.0).abs() < 1e-15);
        assert!((spring_limit_cfl(16.0) - 0.5).abs() < 1e-15);
    }
}
