//! The jet campaign spec (`docs/jet-campaigns.md`): a campaign of abrasive water-jet runs
//! ([`crate::jet`]) submitted as `{"scene": "jet", ...}`, its validation and its deterministic
//! expansion into cells and jobs (one job = one sample, a seed of the abrasive placement, of
//! one cell).
//!
//! Swept (one value or a JSON array): `velocity_m_s` or `pump_pressure_mpa` (never both),
//! `mass_flow_kg_s`, `material`, `time_ms`, `spacing_m`, `coupling_radius_d`. Every other
//! [`JetParams`] field takes one value. Cells are the Cartesian product, ordered with the jet
//! speed varying fastest, then the mass flow, material, time, spacing and coupling radius
//! (slowest). Job seeds are [`super::job_seed`] of (campaign seed, cell, sample), as for
//! impact campaigns.

use std::collections::BTreeMap;

use grit_sph::dem::DemParams;
use grit_sph::PenaltyParams;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::campaign::json::{self, count, field_path, reject_unknown};
use crate::campaign::{
    cell_count, check_cells, check_list_len, check_sweep, err, job_count, sweep_indices,
    MaterialSpec, SpecError, Sweep, MAX_JOBS,
};
use crate::jet::JetParams;

/// The AWJ paper's jet speed coefficient: v_jet = 0.7 √(2P/ρ_w).
pub const JET_SPEED_COEFFICIENT: f64 = 0.7;
/// Water density ρ_w of the pump-pressure conversion (kg/m³).
pub const PUMP_WATER_DENSITY_KG_M3: f64 = 1000.0;

/// The jet speed (m/s) a pump pressure P (MPa) gives: v_jet = 0.7 √(2P/ρ_w) with
/// ρ_w = 1000 kg/m³ (the AWJ paper), about 31.3 √P[MPa].
pub fn jet_speed_from_pressure(pump_pressure_mpa: f64) -> f64 {
    JET_SPEED_COEFFICIENT * (2.0 * pump_pressure_mpa * 1e6 / PUMP_WATER_DENSITY_KG_M3).sqrt()
}

/// Which scene a campaign runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scene {
    /// Single-grain impacts, many in a row on one surface (`crate::impact`).
    #[default]
    Impact,
    /// The abrasive water jet (`crate::jet`), in slices of simulated time.
    Jet,
}

impl Scene {
    /// The name used in specs, the API and the database.
    pub fn as_str(self) -> &'static str {
        match self {
            Scene::Impact => "impact",
            Scene::Jet => "jet",
        }
    }

    /// The scene named `s`, if any.
    pub fn parse(s: &str) -> Option<Scene> {
        [Scene::Impact, Scene::Jet]
            .into_iter()
            .find(|x| x.as_str() == s)
    }
}

/// Samples a jet cell gets when the spec gives none.
pub const DEFAULT_JET_SAMPLES: u32 = 3;

/// A jet campaign as submitted: `"scene": "jet"` and the sweeps of the module documentation.
///
/// Parse with [`JetCampaignSpec::from_json`], which names every unknown field at once and the
/// path of a value of the wrong type; `validate` checks the rules, `cells` runs it first.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct JetCampaignSpec {
    /// Always `jet`: the key that tells a jet spec from an impact one.
    pub scene: Scene,
    /// Free-text name shown in listings.
    pub name: Option<String>,
    /// Seed of the whole campaign; every job's seed derives from it (`campaign::job_seed`).
    pub seed: u64,
    /// Samples per cell: runs of the same cell with other seeds of the abrasive placement.
    #[serde(deserialize_with = "count")]
    pub samples: u32,
    /// Jet speed v_jet at the nozzle (m/s); sweepable. Absent when `pump_pressure_mpa` is given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity_m_s: Option<Sweep<f64>>,
    /// Pump pressure P (MPa), converted by [`jet_speed_from_pressure`]; sweepable; instead of
    /// `velocity_m_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pump_pressure_mpa: Option<Sweep<f64>>,
    /// Abrasive mass flow (kg/s); sweepable; 0 is a pure water jet.
    pub mass_flow_kg_s: Sweep<f64>,
    /// Target material, a preset name or a full object; sweepable.
    pub material: Sweep<MaterialSpec>,
    /// Simulated time T (ms); sweepable.
    pub time_ms: Sweep<f64>,
    /// Particle spacing Δx (m); sweepable.
    pub spacing_m: Sweep<f64>,
    /// Coupling radius over grain diameter R_c/d; sweepable.
    pub coupling_radius_d: Sweep<f64>,
    /// Length of one slice, the unit of progress and checkpoints (ms).
    pub slice_ms: f64,
    /// Jet width (m).
    pub jet_width_m: f64,
    /// Nozzle height above the target (m).
    pub standoff_m: f64,
    /// Target width (m).
    pub target_width_m: f64,
    /// Target depth (m).
    pub target_depth_m: f64,
    /// Hold the target's bottom fixed (default) or leave it free ([`JetParams::fixed_bottom`]).
    #[serde(skip_serializing_if = "crate::jet::is_true")]
    pub fixed_bottom: bool,
    /// Grain diameter (m).
    pub grain_diameter_m: f64,
    /// Grain density (kg/m³).
    pub grain_density_kg_m3: f64,
    /// A grain's speed leaving the nozzle over the jet's.
    pub grain_speed_ratio: f64,
    /// The porosity of the Ergun/Wen–Yu drag switch (AWJ paper eq. 44).
    pub drag_switch_porosity: f64,
    /// The grains' contact constants.
    pub dem: DemParams,
    /// The grain–target penalty contact.
    pub penalty: PenaltyParams,
}

impl Default for JetCampaignSpec {
    /// One cell of `JetParams::default()`, [`DEFAULT_JET_SAMPLES`] samples.
    fn default() -> Self {
        let p = JetParams::default();
        JetCampaignSpec {
            scene: Scene::Jet,
            name: None,
            seed: 0,
            samples: DEFAULT_JET_SAMPLES,
            velocity_m_s: Some(Sweep::one(p.velocity_m_s)),
            pump_pressure_mpa: None,
            mass_flow_kg_s: Sweep::one(p.mass_flow_kg_s),
            material: Sweep::one(p.material.clone()),
            time_ms: Sweep::one(p.time_ms),
            spacing_m: Sweep::one(p.spacing_m),
            coupling_radius_d: Sweep::one(p.coupling_radius_d),
            slice_ms: p.slice_ms,
            jet_width_m: p.jet_width_m,
            standoff_m: p.standoff_m,
            target_width_m: p.target_width_m,
            target_depth_m: p.target_depth_m,
            fixed_bottom: p.fixed_bottom,
            grain_diameter_m: p.grain_diameter_m,
            grain_density_kg_m3: p.grain_density_kg_m3,
            grain_speed_ratio: p.grain_speed_ratio,
            drag_switch_porosity: p.drag_switch_porosity,
            dem: p.dem,
            penalty: p.penalty,
        }
    }
}

/// One point of a jet campaign's sweeps, with the run every sample of it makes.
#[derive(Debug, Clone, PartialEq)]
pub struct JetCell {
    /// Index in expansion order (module docs).
    pub index: u32,
    /// The run's parameters.
    pub params: JetParams,
    /// The pump pressure the jet speed came from, when the spec gives pressures (MPa).
    pub pump_pressure_mpa: Option<f64>,
    /// Slices each sample runs.
    pub slices: u32,
    /// Values of the swept dimensions, by spec name (a swept material as `material_index`).
    pub swept: BTreeMap<String, f64>,
}

/// The swept dimensions in expansion order, fastest first: (spec field, number of values).
type Dims = [(&'static str, usize); 6];

/// Most slices one jet campaign may plan: a slice is seconds to minutes of a core, so this is
/// CPU-years, a guard against a typo that would fill the database.
pub const MAX_SLICES_TOTAL: u128 = 10_000_000;

impl JetCampaignSpec {
    /// Parses JSON text; errors name the field (`(json)` for text that is not JSON,
    /// `(campaign)` for JSON that is not an object, `null` included).
    pub fn from_json(text: &str) -> Result<JetCampaignSpec, SpecError> {
        Self::from_map(json::spec_object(text)?)
    }

    /// Parses the spec's JSON object (see [`JetCampaignSpec::from_json`]).
    pub fn from_map(mut map: Map<String, Value>) -> Result<JetCampaignSpec, SpecError> {
        map.retain(|_, v| !v.is_null());
        reject_unknown::<JetCampaignSpec>(&map, "")?;
        let (speed, pressure) = (
            map.contains_key("velocity_m_s"),
            map.contains_key("pump_pressure_mpa"),
        );
        if speed && pressure {
            return Err(both_speeds());
        }
        let mut spec: JetCampaignSpec = serde_path_to_error::deserialize(&Value::Object(map))
            .map_err(|e| err(field_path(e.path()), e.into_inner().to_string()))?;
        // The default speed stands only when no pressure replaces it.
        if pressure {
            spec.velocity_m_s = None;
        }
        Ok(spec)
    }

    /// The jet speeds as given (m/s), or converted from the pump pressures.
    fn speeds(&self) -> Vec<f64> {
        match (&self.velocity_m_s, &self.pump_pressure_mpa) {
            (Some(v), _) => v.values().to_vec(),
            (None, Some(p)) => p
                .values()
                .iter()
                .map(|&p| jet_speed_from_pressure(p))
                .collect(),
            (None, None) => vec![],
        }
    }

    /// The spec field that sets the jet speed.
    fn speed_field(&self) -> &'static str {
        if self.velocity_m_s.is_none() && self.pump_pressure_mpa.is_some() {
            "pump_pressure_mpa"
        } else {
            "velocity_m_s"
        }
    }

    fn dims(&self) -> Dims {
        [
            (self.speed_field(), self.speeds().len()),
            ("mass_flow_kg_s", self.mass_flow_kg_s.0.len()),
            ("material", self.material.0.len()),
            ("time_ms", self.time_ms.0.len()),
            ("spacing_m", self.spacing_m.0.len()),
            ("coupling_radius_d", self.coupling_radius_d.0.len()),
        ]
    }

    /// Cells of a validated spec.
    fn cell_count(&self) -> usize {
        cell_count(&self.dims())
    }

    /// Per swept dimension: (spec field, index of cell `cell`'s value, whether swept).
    fn sweep_indices(&self, cell: u32) -> Vec<(&'static str, usize, bool)> {
        sweep_indices(&self.dims(), cell)
    }

    /// Checks every rule; the error names the field and the rule.
    pub fn validate(&self) -> Result<(), SpecError> {
        if self.scene != Scene::Jet {
            return Err(err("scene", "must be \"jet\" in a jet campaign spec"));
        }
        if self.name.as_ref().is_some_and(|n| n.len() > 200) {
            return Err(err("name", "must be at most 200 characters"));
        }
        if self.samples == 0 {
            return Err(err("samples", "must be at least 1"));
        }
        match (&self.velocity_m_s, &self.pump_pressure_mpa) {
            (Some(_), Some(_)) => return Err(both_speeds()),
            (None, None) => {
                return Err(err(
                    "velocity_m_s",
                    "give the jet speed as velocity_m_s or pump_pressure_mpa",
                ))
            }
            _ => {}
        }
        let speed = self
            .velocity_m_s
            .as_ref()
            .or(self.pump_pressure_mpa.as_ref())
            .map_or(&[][..], |s| s.values());
        let sweeps: [(&str, &[f64], bool); 6] = [
            (self.speed_field(), speed, true),
            ("mass_flow_kg_s", self.mass_flow_kg_s.values(), false),
            ("time_ms", self.time_ms.values(), true),
            ("spacing_m", self.spacing_m.values(), true),
            ("coupling_radius_d", self.coupling_radius_d.values(), true),
            ("slice_ms", std::slice::from_ref(&self.slice_ms), true),
        ];
        for (name, values, positive) in sweeps {
            check_sweep(name, values, positive)?;
        }
        check_list_len("material", self.material.values().len())?;
        if self.material.values().is_empty() {
            return Err(err("material", "must give at least one material"));
        }
        let jobs = job_count(self.dims().map(|(_, n)| n), self.samples);
        if jobs > MAX_JOBS as u128 {
            return Err(err(
                "samples",
                format!("the campaign expands into {jobs} jobs, more than the limit of {MAX_JOBS}"),
            ));
        }
        check_cells(&self.dims())?;
        // The run's own rules (resolution, sizes, slices) live with JetParams; each cell is
        // checked through it and the error names the spec field that set the value.
        let mut slices = 0u128;
        for cell in self.cells_unchecked() {
            cell.params.validate().map_err(|e| {
                let idx = self.sweep_indices(cell.index);
                err(self.spec_field(&e.field, &idx), e.rule)
            })?;
            slices += cell.slices as u128 * self.samples as u128;
        }
        if slices > MAX_SLICES_TOTAL {
            return Err(err(
                "time_ms",
                format!(
                    "the campaign plans {slices} slices (cells × samples × time_ms / slice_ms), more than the limit of {MAX_SLICES_TOTAL}"
                ),
            ));
        }
        Ok(())
    }

    /// Where the spec sets the `JetParams` field `params_field`, with the cell's index when
    /// that field is swept (`time_ms[1]`, `material[0].poisson_ratio`).
    fn spec_field(&self, params_field: &str, idx: &[(&str, usize, bool)]) -> String {
        let (head, rest) = match params_field.split_once('.') {
            Some((h, r)) => (h, Some(r)),
            None => (params_field, None),
        };
        let head = if head == "velocity_m_s" {
            self.speed_field()
        } else {
            head
        };
        let mut out = head.to_string();
        if let Some((_, i, true)) = idx.iter().find(|(n, _, _)| *n == head) {
            out = format!("{out}[{i}]");
        }
        if let Some(r) = rest {
            out = format!("{out}.{r}");
        }
        out
    }

    fn cells_unchecked(&self) -> Vec<JetCell> {
        let speeds = self.speeds();
        (0..self.cell_count() as u32)
            .map(|index| {
                let idx = self.sweep_indices(index);
                let at = |k: usize| idx[k].1;
                let params = JetParams {
                    material: self.material.0[at(2)].clone(),
                    velocity_m_s: speeds[at(0)],
                    mass_flow_kg_s: self.mass_flow_kg_s.0[at(1)],
                    time_ms: self.time_ms.0[at(3)],
                    slice_ms: self.slice_ms,
                    spacing_m: self.spacing_m.0[at(4)],
                    coupling_radius_d: self.coupling_radius_d.0[at(5)],
                    jet_width_m: self.jet_width_m,
                    standoff_m: self.standoff_m,
                    target_width_m: self.target_width_m,
                    target_depth_m: self.target_depth_m,
                    fixed_bottom: self.fixed_bottom,
                    grain_diameter_m: self.grain_diameter_m,
                    grain_density_kg_m3: self.grain_density_kg_m3,
                    grain_speed_ratio: self.grain_speed_ratio,
                    drag_switch_porosity: self.drag_switch_porosity,
                    dem: self.dem.clone(),
                    penalty: self.penalty,
                };
                let pump_pressure_mpa = self.pump_pressure_mpa.as_ref().map(|p| p.0[at(0)]);
                let named = [
                    (
                        self.speed_field(),
                        pump_pressure_mpa.unwrap_or(params.velocity_m_s),
                    ),
                    ("mass_flow_kg_s", params.mass_flow_kg_s),
                    ("material_index", at(2) as f64),
                    ("time_ms", params.time_ms),
                    ("spacing_m", params.spacing_m),
                    ("coupling_radius_d", params.coupling_radius_d),
                ];
                let swept = named
                    .iter()
                    .zip(&idx)
                    .filter(|(_, (_, _, swept))| *swept)
                    .map(|((name, value), _)| (name.to_string(), *value))
                    .collect();
                JetCell {
                    index,
                    slices: params.slices(),
                    params,
                    pump_pressure_mpa,
                    swept,
                }
            })
            .collect()
    }

    /// The cells in expansion order (module docs), after validation.
    pub fn cells(&self) -> Result<Vec<JetCell>, SpecError> {
        self.validate()?;
        Ok(self.cells_unchecked())
    }
}

fn both_speeds() -> SpecError {
    err(
        "pump_pressure_mpa",
        "give the jet speed either as velocity_m_s or as pump_pressure_mpa, not both",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::job_seed;

    /// A small, valid scene: the fields every test below shares.
    const SMALL: &str = r#""spacing_m": 1e-4, "jet_width_m": 6e-4, "target_width_m": 3e-3,
        "target_depth_m": 8e-4, "standoff_m": 6e-4, "grain_diameter_m": 2e-4,
        "time_ms": 0.004, "slice_ms": 0.001"#;

    fn parse(extra: &str) -> Result<JetCampaignSpec, SpecError> {
        let sep = if extra.is_empty() { "" } else { ", " };
        JetCampaignSpec::from_json(&format!(r#"{{"scene": "jet", {SMALL}{sep}{extra}}}"#))
    }

    fn field_of(extra: &str) -> String {
        parse(extra)
            .and_then(|s| s.validate().map(|_| s))
            .expect_err("must be rejected")
            .field
    }

    #[test]
    fn an_empty_jet_spec_is_one_cell_of_the_default_run() {
        let s = JetCampaignSpec::from_json(r#"{"scene": "jet"}"#).unwrap();
        assert_eq!(s, JetCampaignSpec::default());
        let cells = s.cells().unwrap();
        assert_eq!(cells.len(), 1);
        assert_eq!(cells[0].params, JetParams::default());
        assert!(cells[0].swept.is_empty());
        let plan = crate::campaign::AnySpec::Jet(s).plan().unwrap();
        assert_eq!(plan.jobs.len(), DEFAULT_JET_SAMPLES as usize);
        assert_eq!(
            plan.units_total,
            JetParams::default().slices() as u64 * DEFAULT_JET_SAMPLES as u64
        );
    }

    #[test]
    fn cells_are_the_product_with_the_speed_fastest() {
        let s = parse(
            r#""seed": 4, "samples": 2, "velocity_m_s": [300, 400, 500],
               "mass_flow_kg_s": [0, 0.01], "material": ["copper", "al6061"]"#,
        )
        .unwrap();
        let cells = s.cells().unwrap();
        assert_eq!(cells.len(), 12);
        let v: Vec<f64> = cells.iter().map(|c| c.params.velocity_m_s).collect();
        assert_eq!(&v[..4], &[300.0, 400.0, 500.0, 300.0]);
        assert_eq!(cells[2].params.mass_flow_kg_s, 0.0);
        assert_eq!(cells[3].params.mass_flow_kg_s, 0.01);
        assert_eq!(cells[5].params.material.0.name, "copper");
        assert_eq!(cells[6].params.material.0.name, "al6061");
        assert_eq!(cells[10].swept["velocity_m_s"], 400.0);
        assert_eq!(cells[10].swept["mass_flow_kg_s"], 0.01);
        assert_eq!(cells[10].swept["material_index"], 1.0);
        assert_eq!(cells[10].swept.len(), 3, "unswept fields are not listed");
        assert_eq!(cells[0].slices, 4);
        let plan = || crate::campaign::AnySpec::Jet(s.clone()).plan().unwrap();
        let jobs = plan().jobs;
        assert_eq!(jobs.len(), 24);
        assert_eq!(jobs, plan().jobs, "deterministic");
        assert_eq!((jobs[3].0, jobs[3].1, jobs[3].2), (1, 1, 4));
        assert_eq!(jobs[3].3, job_seed(4, 1, 1));
        let mut seeds: Vec<u64> = jobs.iter().map(|j| j.3).collect();
        seeds.sort_unstable();
        seeds.dedup();
        assert_eq!(seeds.len(), jobs.len());
    }

    #[test]
    fn pump_pressure_gives_the_papers_jet_speed() {
        // 0.7 √(2P/ρ_w): 31.3 √P[MPa].
        assert!((jet_speed_from_pressure(100.0) - 313.049).abs() < 1e-3);
        assert!((jet_speed_from_pressure(1.0) / 31.3 - 1.0).abs() < 1e-3);
        let s = parse(r#""pump_pressure_mpa": [100, 250]"#).unwrap();
        assert_eq!(s.velocity_m_s, None, "the default speed gives way");
        let cells = s.cells().unwrap();
        assert_eq!(cells[1].params.velocity_m_s, jet_speed_from_pressure(250.0));
        assert_eq!(cells[1].pump_pressure_mpa, Some(250.0));
        assert_eq!(cells[1].swept["pump_pressure_mpa"], 250.0);
        let json = serde_json::to_string(&s).unwrap();
        assert!(!json.contains("velocity_m_s"), "{json}");
        assert_eq!(JetCampaignSpec::from_json(&json).unwrap(), s);
        let e = parse(r#""pump_pressure_mpa": 100, "velocity_m_s": 300"#).unwrap_err();
        assert_eq!(e.field, "pump_pressure_mpa");
        assert!(e.rule.contains("not both"), "{e}");
    }

    #[test]
    fn a_spec_reads_back_equal_and_starts_with_its_scene() {
        let s = parse(r#""name": "x", "velocity_m_s": [300, 500], "material": "copper""#).unwrap();
        let json = serde_json::to_string(&s).unwrap();
        assert!(json.starts_with(r#"{"scene":"jet","name":"x""#), "{json}");
        assert!(json.contains(r#""material":"copper""#), "{json}");
        assert_eq!(JetCampaignSpec::from_json(&json).unwrap(), s);
    }

    #[test]
    fn errors_name_the_field_and_the_rule() {
        assert_eq!(field_of(r#""velocity_m_s": -5"#), "velocity_m_s");
        assert_eq!(field_of(r#""velocity_m_s": [300, 300]"#), "velocity_m_s[1]");
        assert_eq!(
            field_of(r#""pump_pressure_mpa": [100, 0]"#),
            "pump_pressure_mpa[1]"
        );
        assert_eq!(field_of(r#""mass_flow_kg_s": -0.1"#), "mass_flow_kg_s");
        assert_eq!(field_of(r#""time_ms": [0.004, "x"]"#), "time_ms[1]");
        assert_eq!(field_of(r#""samples": 0"#), "samples");
        assert_eq!(field_of(r#""samples": 1.5"#), "samples");
        assert_eq!(field_of(r#""material": "brass""#), "material");
        assert_eq!(
            field_of(r#""velocity": 3, "sampels": 2"#),
            "sampels, velocity"
        );
        assert_eq!(field_of(r#""dem": {"restitution": 0.5, "x": 1}"#), "dem.x");
        // Rules of the run itself, named as the spec sets them.
        assert_eq!(field_of(r#""jet_width_m": 6.5e-4"#), "jet_width_m");
        assert_eq!(
            field_of(r#""time_ms": [0.004, 0.0005]"#),
            "slice_ms",
            "a slice longer than one cell's time"
        );
        assert_eq!(field_of(r#""spacing_m": [1e-4, -1e-4]"#), "spacing_m[1]");
        let mut bad = serde_json::to_value(grit_sph::Material::copper()).unwrap();
        bad["poisson_ratio"] = Value::from(0.7);
        let two = serde_json::json!(["copper", bad]).to_string();
        assert_eq!(
            field_of(&format!(r#""material": {two}"#)),
            "material[1].poisson_ratio"
        );
        let e = parse(r#""samples": 0"#).unwrap().validate().unwrap_err();
        assert!(e.rule.contains("at least 1"), "{e}");
        // Sizes that would hold a worker for years or exhaust its memory.
        assert_eq!(field_of(r#""velocity_m_s": 1e300"#), "velocity_m_s");
        // A jet whose head would not reach the target within the run.
        let e = parse(r#""velocity_m_s": 1e-6"#)
            .unwrap()
            .validate()
            .unwrap_err();
        assert_eq!(e.field, "velocity_m_s");
        assert!(e.rule.contains("too slow for the run"), "{e}");
        assert_eq!(field_of(r#""time_ms": 2000, "slice_ms": 1"#), "time_ms");
        assert_eq!(
            field_of(r#""spacing_m": 1e-7, "jet_width_m": 6e-4"#),
            "spacing_m"
        );
        let e = parse(r#""time_ms": 1e12, "slice_ms": 1e-9"#)
            .unwrap()
            .validate()
            .unwrap_err();
        assert_eq!(e.field, "slice_ms");
        assert!(e.rule.contains("1.0000e21 slices"), "{e}");
        let many: Vec<String> = (1..=1001).map(|v| v.to_string()).collect();
        assert_eq!(
            field_of(&format!(r#""velocity_m_s": [{}]"#, many.join(","))),
            "velocity_m_s"
        );
        let e = parse(r#""time_ms": -1"#).unwrap().validate().unwrap_err();
        assert!(e.rule.contains("> 0"), "{e}");
        assert_eq!(
            JetCampaignSpec::from_json("[1]").unwrap_err().field,
            "(campaign)"
        );
    }
}
