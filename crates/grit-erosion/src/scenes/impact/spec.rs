//! The campaign spec (`docs/design.md`, "Campaign spec"): what a user submits, its validation,
//! and its deterministic expansion into cells and jobs (one job = one sample of one cell).
//!
//! Every field is optional and defaults to the seed paper (section 4): angles 15–90° in 15°
//! steps, the four shapes of Fig. 7b, 25 samples, 140/70/60 impacts at 15°/30°/other angles,
//! a 250 µm glass grain at 100 m/s, Δx = 8 µm, a 1.0 Dg distribution range, AISI 304.
//!
//! Besides angle and shape, velocity, grain diameter, grain density, spacing, distribution
//! range and material are swept when given as a JSON array (`"velocity_m_s": [80, 100]`); a
//! single value means no sweep. Cells are the Cartesian product, ordered with the angle
//! varying fastest, then the shape, then velocity, grain diameter, grain density, spacing,
//! distribution range and material (slowest).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize, Serializer};
use serde_json::{Map, Value};

use super::params::ImpactParams;
use crate::campaign::json::{self, field_path, one_or_many, reject_unknown};
use crate::campaign::{
    cell_count, check_cells, check_list_len, check_sweep, err, job_count, sweep_indices,
    ImpactPlan, MaterialSpec, Samples, SpecError, Sweep, UntilSteady, MAX_IMPACTS,
    MAX_IMPACTS_TOTAL, MAX_JOBS, MIN_IMPACTS,
};
use crate::models::shapes::Shape;

/// Impacts per sample: one plan for every angle, or per angle with a `default`; each plan a
/// number or `{"until_steady": {...}}` ([`ImpactPlan`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Impacts {
    /// The same plan at every angle.
    All(ImpactPlan),
    /// Per angle (keys are angles in degrees), with a default for angles not listed.
    PerAngle {
        /// (angle in degrees, plan), in the order given.
        angles: Vec<(f64, ImpactPlan)>,
        /// The plan at angles not listed; `None` requires every angle to be listed.
        default: Option<ImpactPlan>,
    },
}

impl Default for Impacts {
    /// The seed paper: 140 at 15°, 70 at 30°, 60 at every other angle.
    fn default() -> Self {
        Impacts::PerAngle {
            angles: vec![
                (15.0, ImpactPlan::Fixed(140)),
                (30.0, ImpactPlan::Fixed(70)),
            ],
            default: Some(ImpactPlan::Fixed(60)),
        }
    }
}

impl Impacts {
    /// Impacts first planned at `angle_deg` (an until-steady plan's `min`), or `None` when
    /// the map has neither it nor a default.
    pub fn at(&self, angle_deg: f64) -> Option<u32> {
        self.plan_at(angle_deg).map(|p| p.initial())
    }

    /// The plan at `angle_deg`, or `None` when the map has neither it nor a default.
    pub fn plan_at(&self, angle_deg: f64) -> Option<ImpactPlan> {
        match self {
            Impacts::All(n) => Some(*n),
            Impacts::PerAngle { angles, default } => angles
                .iter()
                .find(|(a, _)| same_angle(*a, angle_deg))
                .map(|(_, n)| *n)
                .or(*default),
        }
    }
}

impl Serialize for Impacts {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Impacts::All(n) => n.serialize(s),
            Impacts::PerAngle { angles, default } => {
                let value =
                    |p: &ImpactPlan| serde_json::to_value(p).map_err(serde::ser::Error::custom);
                let mut m = Map::new();
                for (a, n) in angles {
                    m.insert(format!("{a}"), value(n)?);
                }
                if let Some(d) = default {
                    m.insert("default".into(), value(d)?);
                }
                m.serialize(s)
            }
        }
    }
}

/// Angles from JSON keys ("15") and values (15.0) are compared to a tolerance far below any
/// meaningful difference in impact angle.
pub(crate) fn same_angle(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

/// The grain: diameter Dg (grains have the area of a circle of this diameter) and density.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GrainSpec {
    /// Grain diameter Dg in metres (seed: 250 µm); sweepable.
    pub diameter_m: Sweep<f64>,
    /// Grain density in kg/m³ (seed: glass, 2500); sweepable.
    pub density_kg_m3: Sweep<f64>,
}

impl Default for GrainSpec {
    fn default() -> Self {
        let p = ImpactParams::default();
        GrainSpec {
            diameter_m: Sweep::one(p.grain_diameter_m),
            density_kg_m3: Sweep::one(p.grain_density_kg_m3),
        }
    }
}

/// A campaign as submitted (`grit submit`, `POST /api/v1/campaigns`, `grit run`).
///
/// Deserialise it with `CampaignSpec::from_json`, which names every unknown field at once and
/// the path of any value of the wrong type, or with plain serde, which stops at the first.
/// Semantic rules (ranges, counts) are checked by `validate`, which `cells` runs first.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CampaignSpec {
    /// Free-text name shown in listings.
    pub name: Option<String>,
    /// Seed of the whole campaign; every job's seed derives from it (module docs).
    pub seed: u64,
    /// Impact angles in degrees, each in (0, 90]; one number or an array.
    #[serde(deserialize_with = "one_or_many")]
    pub angles_deg: Vec<f64>,
    /// Grain shapes: built-in names or `{name, vertices_m}` polygons; one or an array.
    #[serde(deserialize_with = "one_or_many")]
    pub shapes: Vec<Shape>,
    /// Samples per cell: a number, or `{"target_sem_rel", "min", "max"}` ([`Samples`]).
    pub samples: Samples,
    /// Impacts per sample, per angle.
    pub impacts: Impacts,
    /// Impact speed V in m/s; sweepable.
    pub velocity_m_s: Sweep<f64>,
    /// Grain size and density.
    pub grain: GrainSpec,
    /// Particle spacing Δx in metres; sweepable.
    pub spacing_m: Sweep<f64>,
    /// Width of the band of aim points in Dg; sweepable.
    pub distribution_range_dg: Sweep<f64>,
    /// Surface material; sweepable.
    pub material: Sweep<MaterialSpec>,
    /// Grain–surface friction μ (scene detail; default the impact scene's).
    pub friction: f64,
    /// Surface width in Dg (scene detail; default the impact scene's).
    pub surface_width_dg: f64,
    /// Surface depth in Dg (scene detail; default the impact scene's).
    pub surface_depth_dg: f64,
    /// Settling threshold ending an impact (scene detail; default the impact scene's).
    pub settle_fraction: f64,
    /// Permit fewer than 21 impacts per sample, for smoke tests of the farm; such samples
    /// give no last-20 slope, so their cells report no erosion.
    pub allow_short_samples: bool,
    /// The engine fingerprint the campaign runs on ([`crate::campaign::check_engine`]);
    /// absent, a farm pins the campaign to its coordinator's own.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub engine: Option<String>,
    /// The order a farm hands out the jobs ([`QueueOrder`]); absent, by rounds.
    #[serde(skip_serializing_if = "QueueOrder::is_rounds")]
    pub queue: QueueOrder,
}

/// The order a farm hands out a campaign's jobs (`docs/design.md`, *Claim*).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum QueueOrder {
    /// Every cell's first round before any cell's growth: all cells report early.
    #[default]
    Rounds,
    /// One cell to its end before the next, in expansion order: finished cells come one by
    /// one, and only one cell's samples hold checkpoints at a time.
    Cells,
}

impl QueueOrder {
    /// Whether this is the default order, which a stored spec leaves out so that specs
    /// written before the field existed keep their idempotency key.
    pub fn is_rounds(&self) -> bool {
        *self == QueueOrder::Rounds
    }
}

impl Default for CampaignSpec {
    /// The seed paper's campaign.
    fn default() -> Self {
        let p = ImpactParams::default();
        CampaignSpec {
            name: None,
            seed: 0,
            angles_deg: vec![15.0, 30.0, 45.0, 60.0, 75.0, 90.0],
            shapes: Shape::paper().to_vec(),
            samples: Samples::Fixed(25),
            impacts: Impacts::default(),
            velocity_m_s: Sweep::one(p.velocity_m_s),
            grain: GrainSpec::default(),
            spacing_m: Sweep::one(p.spacing_m),
            distribution_range_dg: Sweep::one(p.distribution_range_dg),
            material: Sweep::one(MaterialSpec(p.material.clone())),
            friction: p.friction,
            surface_width_dg: p.surface_width_dg,
            surface_depth_dg: p.surface_depth_dg,
            settle_fraction: p.settle_fraction,
            allow_short_samples: false,
            engine: None,
            queue: QueueOrder::Rounds,
        }
    }
}

/// One point of the swept parameters, with the scene every sample of it runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// Index of the cell in expansion order (module docs).
    pub index: u32,
    /// The impact scene.
    pub params: ImpactParams,
    /// Impacts each sample of this cell is first planned to receive.
    pub impacts: u32,
    /// The rule extending the impacts until the cell is steady, if the spec gives one.
    pub until_steady: Option<UntilSteady>,
    /// Values of the swept dimensions other than angle and shape, by name with unit; a swept
    /// material appears as `material_index` (its position in the spec's `material` list).
    pub swept: BTreeMap<String, f64>,
}

/// Maps a field of `ImpactParams` to where the spec sets it, so scene errors name spec fields.
fn spec_field(params_field: &str, sweeps: &[(&str, usize, bool)]) -> String {
    let (head, rest) = match params_field.split_once('.') {
        Some((h, r)) => (h, Some(r)),
        None => (params_field, None),
    };
    let base = match head {
        "grain_diameter_m" => "grain.diameter_m",
        "grain_density_kg_m3" => "grain.density_kg_m3",
        other => other,
    };
    let mut out = base.to_string();
    if let Some((_, i, true)) = sweeps.iter().find(|(n, _, _)| *n == base) {
        out = format!("{out}[{i}]");
    }
    if let Some(r) = rest {
        out = format!("{out}.{r}");
    }
    out
}

impl CampaignSpec {
    /// Parses JSON text; errors name the field (`(json)` for text that is not JSON,
    /// `(campaign)` for JSON that is not an object, `null` included).
    pub fn from_json(text: &str) -> Result<CampaignSpec, SpecError> {
        Self::from_map(json::spec_object(text)?)
    }

    /// Parses the spec's JSON object (see [`CampaignSpec::from_json`]).
    pub fn from_map(mut map: Map<String, Value>) -> Result<CampaignSpec, SpecError> {
        map.retain(|_, v| !v.is_null());
        reject_unknown::<CampaignSpec>(&map, "")?;
        if let Some(Value::Object(grain)) = map.get("grain") {
            reject_unknown::<GrainSpec>(grain, "grain.")?;
        }
        let v = Value::Object(map);
        serde_path_to_error::deserialize(&v)
            .map_err(|e| err(field_path(e.path()), e.into_inner().to_string()))
    }

    /// Checks every rule; the error names the field and the rule.
    pub fn validate(&self) -> Result<(), SpecError> {
        crate::campaign::check_engine(self.engine.as_deref())?;
        if let Some(n) = &self.name {
            if n.len() > 200 {
                return Err(err("name", "must be at most 200 characters"));
            }
        }
        if self.angles_deg.is_empty() {
            return Err(err("angles_deg", "must list at least one angle"));
        }
        check_list_len("angles_deg", self.angles_deg.len())?;
        check_list_len("shapes", self.shapes.len())?;
        check_list_len("material", self.material.values().len())?;
        for (i, a) in self.angles_deg.iter().enumerate() {
            if !(*a > 0.0 && *a <= 90.0) {
                return Err(err(
                    format!("angles_deg[{i}]"),
                    format!("must be in (0, 90] degrees, got {a}"),
                ));
            }
            if self.angles_deg[..i].iter().any(|b| same_angle(*a, *b)) {
                return Err(err(format!("angles_deg[{i}]"), format!("{a} listed twice")));
            }
        }
        if self.shapes.is_empty() {
            return Err(err("shapes", "must list at least one shape"));
        }
        for (i, s) in self.shapes.iter().enumerate() {
            s.validate(&format!("shapes[{i}]")).map_err(|e| match e {
                crate::models::shapes::ShapeError::Invalid { field, rule } => err(field, rule),
            })?;
            if self.shapes[..i].iter().any(|t| t.name() == s.name()) {
                return Err(err(
                    format!("shapes[{i}]"),
                    format!("shape `{}` listed twice", s.name()),
                ));
            }
        }
        self.samples.validate()?;
        if let Impacts::PerAngle { angles, .. } = &self.impacts {
            for (a, _) in angles {
                if !(*a > 0.0 && *a <= 90.0) {
                    return Err(err(
                        format!("impacts[\"{a}\"]"),
                        "key must be an angle in (0, 90] degrees",
                    ));
                }
            }
        }
        let min = if self.allow_short_samples {
            1
        } else {
            MIN_IMPACTS
        };
        for a in &self.angles_deg {
            let field = match &self.impacts {
                Impacts::All(_) => "impacts".to_string(),
                Impacts::PerAngle { angles, .. } => {
                    match angles.iter().find(|(b, _)| same_angle(*a, *b)) {
                        Some((b, _)) => format!("impacts[\"{b}\"]"),
                        None => "impacts[\"default\"]".to_string(),
                    }
                }
            };
            match self.impacts.plan_at(*a) {
                Some(ImpactPlan::UntilSteady(u)) => u.validate(&field, min)?,
                None => {
                    return Err(err(
                        "impacts",
                        format!("no entry for angle {a} and no \"default\""),
                    ))
                }
                Some(ImpactPlan::Fixed(n)) if n > MAX_IMPACTS => {
                    return Err(err(
                        field,
                        format!("must be at most {MAX_IMPACTS} impacts per sample, got {n}"),
                    ))
                }
                Some(ImpactPlan::Fixed(n)) if n < min => {
                    return Err(err(
                        field,
                        if self.allow_short_samples {
                            format!("must be at least 1, got {n}")
                        } else {
                            format!(
                                "must be at least {MIN_IMPACTS} (the last-20 slope needs 20 points after the first), got {n}; set allow_short_samples for smoke tests"
                            )
                        },
                    ))
                }
                Some(_) => {}
            }
        }
        let sweeps: [(&str, &[f64]); 5] = [
            ("velocity_m_s", self.velocity_m_s.values()),
            ("grain.diameter_m", self.grain.diameter_m.values()),
            ("grain.density_kg_m3", self.grain.density_kg_m3.values()),
            ("spacing_m", self.spacing_m.values()),
            ("distribution_range_dg", self.distribution_range_dg.values()),
        ];
        for (name, values) in sweeps {
            check_sweep(name, values, name != "distribution_range_dg")?;
        }
        if self.material.values().is_empty() {
            return Err(err("material", "must give at least one material"));
        }
        let jobs = job_count(self.dims().map(|(_, n)| n), self.samples.max());
        if jobs > MAX_JOBS as u128 {
            return Err(err(
                "samples",
                format!("the campaign expands into {jobs} jobs, more than the limit of {MAX_JOBS}"),
            ));
        }
        check_cells(&self.dims())?;
        let per_angle = (self.cell_count() / self.angles_deg.len()) as u128;
        let most: u128 = self
            .angles_deg
            .iter()
            .filter_map(|a| self.impacts.plan_at(*a))
            .map(|plan| match plan {
                ImpactPlan::Fixed(n) => n as u128,
                ImpactPlan::UntilSteady(u) => u.max as u128,
            })
            .sum::<u128>()
            * per_angle
            * self.samples.max() as u128;
        if most > MAX_IMPACTS_TOTAL {
            return Err(err(
                "impacts",
                format!(
                    "the campaign plans up to {most} impacts (cells × samples × impacts at their largest), more than the limit of {MAX_IMPACTS_TOTAL}"
                ),
            ));
        }
        // Scene rules (resolution, surface size, material constants) live with the scene;
        // check each distinct combination once through it.
        for cell in self.cells_unchecked() {
            cell.params.validate().map_err(|e| {
                let idx = self.sweep_indices(cell.index);
                err(spec_field(&e.field, &idx), e.rule)
            })?;
        }
        Ok(())
    }

    /// Each swept dimension's spec field and length, in the mixed-radix order of the cell
    /// index (fastest digit first).
    fn dims(&self) -> [(&'static str, usize); 8] {
        [
            ("angles_deg", self.angles_deg.len()),
            ("shapes", self.shapes.len()),
            ("velocity_m_s", self.velocity_m_s.0.len()),
            ("grain.diameter_m", self.grain.diameter_m.0.len()),
            ("grain.density_kg_m3", self.grain.density_kg_m3.0.len()),
            ("spacing_m", self.spacing_m.0.len()),
            ("distribution_range_dg", self.distribution_range_dg.0.len()),
            ("material", self.material.0.len()),
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

    fn cells_unchecked(&self) -> Vec<Cell> {
        (0..self.cell_count() as u32)
            .map(|index| {
                let idx = self.sweep_indices(index);
                let at = |k: usize| idx[k].1;
                let angle = self.angles_deg[at(0)];
                let mut params = ImpactParams::paper(angle, self.shapes[at(1)].clone());
                params.velocity_m_s = self.velocity_m_s.0[at(2)];
                params.grain_diameter_m = self.grain.diameter_m.0[at(3)];
                params.grain_density_kg_m3 = self.grain.density_kg_m3.0[at(4)];
                params.spacing_m = self.spacing_m.0[at(5)];
                params.distribution_range_dg = self.distribution_range_dg.0[at(6)];
                params.material = self.material.0[at(7)].0.clone();
                params.friction = self.friction;
                params.surface_width_dg = self.surface_width_dg;
                params.surface_depth_dg = self.surface_depth_dg;
                params.settle_fraction = self.settle_fraction;
                let mut swept = BTreeMap::new();
                let named = [
                    (2, "velocity_m_s", params.velocity_m_s),
                    (3, "grain_diameter_m", params.grain_diameter_m),
                    (4, "grain_density_kg_m3", params.grain_density_kg_m3),
                    (5, "spacing_m", params.spacing_m),
                    (6, "distribution_range_dg", params.distribution_range_dg),
                    (7, "material_index", at(7) as f64),
                ];
                for (k, name, value) in named {
                    if idx[k].2 {
                        swept.insert(name.to_string(), value);
                    }
                }
                let plan = self.impacts.plan_at(angle);
                Cell {
                    index,
                    impacts: plan.map_or(0, |p| p.initial()),
                    until_steady: plan.and_then(|p| p.until_steady()),
                    params,
                    swept,
                }
            })
            .collect()
    }

    /// The cells in expansion order (module docs), after validation.
    pub fn cells(&self) -> Result<Vec<Cell>, SpecError> {
        self.validate()?;
        Ok(self.cells_unchecked())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::{job_seed, mix, AnySpec, MAX_LIST};
    use grit_sph::Material;

    fn parse(json: &str) -> Result<CampaignSpec, SpecError> {
        CampaignSpec::from_json(json)
    }

    fn field_of(json: &str) -> String {
        let e = parse(json)
            .and_then(|s| s.validate().map(|_| s))
            .expect_err("must be rejected");
        e.field
    }

    #[test]
    fn empty_spec_is_the_paper_campaign() {
        let s = parse("{}").unwrap();
        assert_eq!(s, CampaignSpec::default());
        assert_eq!(s.angles_deg, vec![15.0, 30.0, 45.0, 60.0, 75.0, 90.0]);
        assert_eq!(
            s.shapes,
            vec![
                Shape::Octagon,
                Shape::Hexagon,
                Shape::Square,
                Shape::Rectangle
            ]
        );
        assert_eq!(s.samples, Samples::Fixed(25));
        assert_eq!(s.impacts.at(15.0), Some(140));
        assert_eq!(s.impacts.at(30.0), Some(70));
        for a in [45.0, 60.0, 75.0, 90.0] {
            assert_eq!(s.impacts.at(a), Some(60));
        }
        assert_eq!(s.spacing_m.values(), &[8e-6]);
        assert_eq!(s.distribution_range_dg.values(), &[1.0]);
        assert_eq!(s.velocity_m_s.values(), &[100.0]);
        assert_eq!(s.grain.diameter_m.values(), &[250e-6]);
        assert_eq!(s.grain.density_kg_m3.values(), &[2500.0]);
        assert_eq!(s.material.values()[0].0, Material::aisi304());
        let cells = s.cells().unwrap();
        assert_eq!(cells.len(), 24);
        assert_eq!(
            cells[0].params,
            ImpactParams::paper(15.0, Shape::Octagon),
            "cells use the paper scene"
        );
        let total: u64 = (140 + 70 + 4 * 60) * 4 * 25;
        let plan = crate::campaign::AnySpec::Impact(s).plan().unwrap();
        assert_eq!(plan.jobs.len(), 24 * 25);
        assert_eq!(plan.units_total, total);
    }

    #[test]
    fn full_example_parses() {
        let s = parse(
            r#"{"name": "paper", "seed": 7, "angles_deg": [15, 30, 45, 60, 75, 90],
                "shapes": ["octagon", {"name": "hexagon"}, "square",
                           {"name": "tri", "vertices_m": [[0,0],[1,0],[0,1]]}],
                "samples": 25, "impacts": {"15": 140, "30": 70, "default": 60},
                "velocity_m_s": 100, "grain": {"diameter_m": 250e-6, "density_kg_m3": 2500},
                "spacing_m": 8e-6, "distribution_range_dg": 1.0, "material": "aisi304"}"#,
        )
        .unwrap();
        s.validate().unwrap();
        assert_eq!(s.shapes[3].name(), "tri");
        assert_eq!(s.seed, 7);
    }

    #[test]
    fn serialised_spec_reads_back_equal() {
        let s = parse(
            r#"{"velocity_m_s": [80, 100], "impacts": 30, "shapes": ["hexagon"],
                "material": ["aisi304"], "grain": {"diameter_m": [2e-4, 2.5e-4]}}"#,
        )
        .unwrap();
        let back = parse(&serde_json::to_string(&s).unwrap()).unwrap();
        assert_eq!(s, back);
        let d = CampaignSpec::default();
        assert_eq!(parse(&serde_json::to_string(&d).unwrap()).unwrap(), d);
    }

    #[test]
    fn materials_by_name_read_and_write_as_names() {
        let s = parse(r#"{"material": ["copper", "al6061", "aisi304"]}"#).unwrap();
        let names: Vec<_> = s
            .material
            .values()
            .iter()
            .map(|m| m.0.name.clone())
            .collect();
        assert_eq!(names, ["copper", "al6061", "aisi304"]);
        let json = serde_json::to_string(&s).unwrap();
        assert!(
            json.contains(r#""material":["copper","al6061","aisi304"]"#),
            "{json}"
        );
        let e = parse(r#"{"material": "brass"}"#).unwrap_err();
        assert!(e.to_string().contains("brass") && e.to_string().contains("al6061"));
    }

    #[test]
    fn unknown_fields_are_named() {
        let e = parse(r#"{"angles": [45], "sampels": 3}"#).unwrap_err();
        assert!(
            e.field.contains("angles") && e.field.contains("sampels"),
            "{e}"
        );
        assert!(e.rule.contains("unknown field"), "{e}");
        assert_eq!(
            parse(r#"{"grain": {"diameter": 1}}"#).unwrap_err().field,
            "grain.diameter"
        );
    }

    #[test]
    fn validation_names_field_and_rule() {
        assert_eq!(field_of(r#"{"angles_deg": [45, 0]}"#), "angles_deg[1]");
        assert_eq!(field_of(r#"{"angles_deg": [95]}"#), "angles_deg[0]");
        let e = parse(r#"{"angles_deg": [91]}"#)
            .unwrap()
            .validate()
            .unwrap_err();
        assert!(e.rule.contains("(0, 90]"), "{e}");
        assert_eq!(field_of(r#"{"impacts": 20}"#), "impacts");
        assert_eq!(
            field_of(r#"{"impacts": {"15": 10, "default": 60}}"#),
            "impacts[\"15\"]"
        );
        assert_eq!(field_of(r#"{"impacts": {"15": 140}}"#), "impacts");
        assert_eq!(field_of(r#"{"shapes": ["pentagon"]}"#), "shapes[0]");
        assert_eq!(field_of(r#"{"shapes": ["square", "square"]}"#), "shapes[1]");
        assert_eq!(field_of(r#"{"samples": 0}"#), "samples");
        assert_eq!(field_of(r#"{"samples": -1}"#), "samples");
        assert_eq!(field_of(r#"{"velocity_m_s": -5}"#), "velocity_m_s");
        assert_eq!(field_of(r#"{"velocity_m_s": "fast"}"#), "velocity_m_s");
        assert_eq!(
            field_of(r#"{"grain": {"diameter_m": 0}}"#),
            "grain.diameter_m"
        );
        assert_eq!(
            field_of(r#"{"grain": {"density_kg_m3": [2500, -1]}}"#),
            "grain.density_kg_m3[1]"
        );
        assert_eq!(field_of(r#"{"spacing_m": 0}"#), "spacing_m");
        assert_eq!(field_of(r#"{"spacing_m": 1e-4}"#), "spacing_m");
        assert_eq!(
            field_of(r#"{"distribution_range_dg": -1}"#),
            "distribution_range_dg"
        );
        assert_eq!(field_of(r#"{"material": "steel"}"#), "material");
        assert_eq!(field_of(r#"{"material": {"name": "x"}}"#), "material");
        let mut bad = serde_json::to_value(Material::aisi304()).unwrap();
        bad["poisson_ratio"] = Value::from(0.7);
        let json = serde_json::json!({ "material": ["aisi304", bad] }).to_string();
        assert!(
            field_of(&json).starts_with("material[1]."),
            "{}",
            field_of(&json)
        );
        assert_eq!(field_of("[1, 2]"), "(campaign)");
        assert_eq!(field_of("{"), "(json)");
    }

    /// The rule of a rejected spec.
    fn rule_of(json: &str) -> String {
        parse(json)
            .and_then(|s| s.validate().map(|_| s))
            .expect_err("must be rejected")
            .rule
    }

    #[test]
    fn sizes_that_would_flood_the_queue_or_a_worker_are_refused() {
        let list = |n: usize, from: f64| -> String {
            let v: Vec<String> = (0..n).map(|i| format!("{}", from + i as f64)).collect();
            format!("[{}]", v.join(","))
        };
        // More values in one list than a spec may hold.
        let json = format!(r#"{{"velocity_m_s": {}}}"#, list(MAX_LIST + 1, 1.0));
        assert_eq!(field_of(&json), "velocity_m_s");
        assert!(rule_of(&json).contains("more than the limit of 1000"));
        // Lists whose product passes the 64-bit range (2^64 wraps a usize product to zero):
        // counted in full and refused.
        let values =
            |n: usize, scale: f64| -> Vec<f64> { (1..=n).map(|i| i as f64 * scale).collect() };
        let tri =
            |name: &str| serde_json::json!({"name": name, "vertices_m": [[0, 0], [1, 0], [0, 1]]});
        let json = serde_json::json!({
            "angles_deg": values(1000, 0.09),
            "shapes": ["octagon", "hexagon", "square", "rectangle", "circle", tri("a"), tri("b")],
            "material": ["aisi304", "copper", "al6061"],
            "samples": 1,
            "velocity_m_s": values(1000, 0.1),
            "grain": {"diameter_m": values(1000, 1e-6), "density_kg_m3": values(1000, 1.0)},
            "spacing_m": values(1000, 1e-8),
            "distribution_range_dg": values(1000, 1e-3),
        })
        .to_string();
        let rule = rule_of(&json);
        assert!(
            rule.contains(&format!("expands into {} jobs", 21 * 10u128.pow(18))),
            "{rule}"
        );
        assert_eq!(field_of(r#"{"impacts": 100001}"#), "impacts");
        assert_eq!(
            field_of(r#"{"impacts": {"until_steady": {"min": 30, "max": 100001, "step": 5}}}"#),
            "impacts.until_steady.max"
        );
        assert_eq!(
            field_of(r#"{"impacts": {"until_steady": {"min": 30, "max": 40, "step": 41}}}"#),
            "impacts.until_steady.step"
        );
        // The scene's own bounds, through the cells.
        assert_eq!(field_of(r#"{"settle_fraction": 2}"#), "settle_fraction");
        assert_eq!(field_of(r#"{"velocity_m_s": 1e300}"#), "velocity_m_s");
        assert_eq!(
            field_of(r#"{"grain": {"density_kg_m3": 1e6}}"#),
            "grain.density_kg_m3"
        );
        for (json, field) in [
            (r#"{"spacing_m": 1e-12}"#, "spacing_m"),
            (r#"{"grain": {"diameter_m": 1}}"#, "spacing_m"),
            (r#"{"surface_width_dg": 1e6}"#, "surface_width_dg"),
            (
                r#"{"surface_width_dg": 90, "surface_depth_dg": 90, "spacing_m": 1e-6}"#,
                "spacing_m",
            ),
        ] {
            assert_eq!(field_of(json), field, "{json}");
        }
        assert!(
            rule_of(r#"{"surface_width_dg": 90, "surface_depth_dg": 90, "spacing_m": 1e-6}"#)
                .contains("gives a surface of")
        );
        // Cells, and impacts in all.
        let many: Vec<f64> = (1..=200).map(|v| v as f64).collect();
        let json = serde_json::json!({"velocity_m_s": many, "grain": {"density_kg_m3": (1..=60).map(|v| v as f64 * 100.0).collect::<Vec<_>>()}, "samples": 1}).to_string();
        assert_eq!(field_of(&json), "velocity_m_s");
        assert!(rule_of(&json).contains("cells, more than the limit of 10000"));
        let json = r#"{"samples": 1000, "impacts": 100000}"#;
        assert_eq!(field_of(json), "impacts");
        assert!(rule_of(json).contains("more than the limit of 100000000"));
        // The seed's finest scene stays well inside.
        parse(r#"{"spacing_m": 7.8125e-6, "velocity_m_s": 1000}"#)
            .unwrap()
            .validate()
            .unwrap();
    }

    #[test]
    fn type_errors_name_the_element_and_the_angle_key() {
        assert_eq!(
            field_of(r#"{"velocity_m_s": [80, "x"]}"#),
            "velocity_m_s[1]"
        );
        assert_eq!(
            field_of(r#"{"grain": {"diameter_m": [2e-4, true]}}"#),
            "grain.diameter_m[1]"
        );
        assert_eq!(
            field_of(r#"{"impacts": {"fifteen": 30}}"#),
            "impacts[\"fifteen\"]"
        );
        assert_eq!(field_of(r#"{"impacts": {"15": -3}}"#), "impacts[\"15\"]");
        assert_eq!(
            field_of(r#"{"impacts": {"15": 30, "15.0": 40}}"#),
            "impacts[\"15.0\"]"
        );
        assert_eq!(field_of(r#"{"samples": 2.5}"#), "samples");
        assert_eq!(
            field_of(r#"{"shapes": [{"name": "x", "vertices": 1}]}"#),
            "shapes[0].vertices"
        );
        // A top-level null is the default, as if the field were left out.
        assert_eq!(parse(r#"{"seed": null}"#).unwrap(), CampaignSpec::default());
    }

    #[test]
    fn serialised_form_is_pinned() {
        // Stored specs are compared byte for byte (idempotent resubmission).
        let s = parse(r#"{"velocity_m_s": [80, 100], "angles_deg": 45, "impacts": {"45": 30}}"#)
            .unwrap();
        assert_eq!(
            serde_json::to_string(&s).unwrap(),
            r#"{"name":null,"seed":0,"angles_deg":[45.0],"shapes":["octagon","hexagon","square","rectangle"],"samples":25,"impacts":{"45":30},"velocity_m_s":[80.0,100.0],"grain":{"diameter_m":0.00025,"density_kg_m3":2500.0},"spacing_m":8e-6,"distribution_range_dg":1.0,"material":"aisi304","friction":0.5,"surface_width_dg":4.0,"surface_depth_dg":1.5,"settle_fraction":0.02,"allow_short_samples":false}"#
        );
    }

    #[test]
    fn the_queue_order_is_named_and_only_a_cell_order_is_stored() {
        let cells = parse(r#"{"queue": "cells"}"#).unwrap();
        assert_eq!(cells.queue, QueueOrder::Cells);
        assert!(serde_json::to_string(&cells)
            .unwrap()
            .contains(r#""queue":"cells""#));
        let rounds = parse(r#"{"queue": "rounds"}"#).unwrap();
        assert_eq!(rounds, CampaignSpec::default());
        assert!(!serde_json::to_string(&rounds).unwrap().contains("queue"));
        assert!(parse(r#"{"queue": "sideways"}"#).is_err());
        assert_eq!(
            parse(r#"{"queue": "sideways"}"#).unwrap_err().field,
            "queue"
        );
    }

    #[test]
    fn short_samples_need_the_flag() {
        let json = r#"{"impacts": 3, "allow_short_samples": true}"#;
        parse(json).unwrap().validate().unwrap();
        assert_eq!(
            field_of(r#"{"impacts": 0, "allow_short_samples": true}"#),
            "impacts"
        );
    }

    #[test]
    fn expansion_is_deterministic_and_seeds_distinct() {
        let json =
            r#"{"seed": 42, "velocity_m_s": [80, 100], "grain": {"diameter_m": [2e-4, 2.5e-4]}}"#;
        let plan = |json: &str| AnySpec::Impact(parse(json).unwrap()).plan().unwrap();
        let a = plan(json);
        assert_eq!(a, plan(json));
        assert_eq!(a.jobs.len(), 6 * 4 * 2 * 2 * 25);
        let mut seeds: Vec<u64> = a.jobs.iter().map(|j| j.3).collect();
        seeds.sort_unstable();
        seeds.dedup();
        assert_eq!(seeds.len(), a.jobs.len(), "every job has its own seed");
        assert_ne!(plan(r#"{"seed": 43}"#).jobs[0].3, a.jobs[0].3);
        // Angle varies fastest, then shape, then the other sweeps.
        let cells = parse(json).unwrap().cells().unwrap();
        let job = |k: usize| &cells[a.jobs[k].0 as usize].params;
        assert_eq!(job(0).angle_deg, 15.0);
        assert_eq!(job(25).angle_deg, 30.0);
        assert_eq!(job(6 * 25).shape, Shape::Hexagon);
        assert_eq!(job(24 * 25).velocity_m_s, 100.0);
    }

    #[test]
    fn job_seed_is_pinned() {
        // The documented formula, frozen: changing it would change every campaign's grains.
        assert_eq!(job_seed(0, 0, 0), 0);
        assert_eq!(job_seed(1, 0, 0), mix(mix(1)));
        assert_eq!(job_seed(0, 0, 1), 0x5692_161d_100b_05e5);
        assert_eq!(job_seed(7, 3, 5), mix(mix(7) ^ (3 << 32 | 5)));
    }

    #[test]
    fn a_planned_cell_carries_swept_values() {
        let s = parse(r#"{"angles_deg": [45], "shapes": ["hexagon"], "velocity_m_s": [80, 100]}"#)
            .unwrap();
        let plan = AnySpec::Impact(s).plan().unwrap();
        assert_eq!(plan.cells.len(), 2);
        let cell = &plan.cells[1];
        assert_eq!(cell.angle_deg, Some(45.0));
        assert_eq!(cell.shape.as_deref(), Some("hexagon"));
        assert_eq!(cell.swept.get("velocity_m_s"), Some(&100.0));
        assert_eq!(cell.units, 60);
        assert_eq!(plan.samples, 25);
    }
}
