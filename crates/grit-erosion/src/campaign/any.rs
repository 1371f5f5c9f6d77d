//! A campaign spec of either scene: `"scene": "jet"` selects the jet spec
//! ([`super::JetCampaignSpec`]); `"scene": "impact"` or no `scene` key the impact spec
//! ([`super::CampaignSpec`]), so every spec written before jets existed parses as before.

use std::collections::BTreeMap;

use serde::{Serialize, Serializer};
use serde_json::Value;

use super::{
    err, job_seed, CampaignSpec, JetCampaignSpec, QueueOrder, Scene, SpecError, TargetSem,
    UntilSteady,
};
use crate::Scene as _;

/// A campaign spec of either scene.
#[derive(Debug, Clone, PartialEq)]
pub enum AnySpec {
    /// Single-grain impacts (no `scene`, or `"scene": "impact"`).
    Impact(CampaignSpec),
    /// The abrasive water jet (`"scene": "jet"`).
    Jet(JetCampaignSpec),
}

impl AnySpec {
    /// Parses JSON text by its `scene`; errors name the field as each spec's `from_json` does,
    /// and `scene` for a scene grit does not know.
    pub fn from_json(text: &str) -> Result<AnySpec, SpecError> {
        let v: Value = serde_json::from_str(text).map_err(|e| err("(json)", e.to_string()))?;
        let Value::Object(mut map) = v else {
            return Err(err("(campaign)", "must be a JSON object"));
        };
        let scene = match map.get("scene") {
            None | Some(Value::Null) => Scene::Impact,
            Some(Value::String(s)) => Scene::parse(s).ok_or_else(|| unknown_scene(s))?,
            Some(other) => return Err(unknown_scene(&other.to_string())),
        };
        match scene {
            Scene::Impact => {
                map.remove("scene");
                CampaignSpec::from_map(map).map(AnySpec::Impact)
            }
            Scene::Jet => JetCampaignSpec::from_map(map).map(AnySpec::Jet),
        }
    }

    /// The scene the campaign runs.
    pub fn scene(&self) -> Scene {
        match self {
            AnySpec::Impact(_) => Scene::Impact,
            AnySpec::Jet(_) => Scene::Jet,
        }
    }

    /// The campaign's name, if given.
    pub fn name(&self) -> Option<&str> {
        match self {
            AnySpec::Impact(s) => s.name.as_deref(),
            AnySpec::Jet(s) => s.name.as_deref(),
        }
    }

    /// The engine fingerprint the spec pins, if it names one.
    pub fn engine(&self) -> Option<&str> {
        match self {
            AnySpec::Impact(s) => s.engine.as_deref(),
            AnySpec::Jet(s) => s.engine.as_deref(),
        }
    }

    /// Checks every rule of the spec's scene.
    pub fn validate(&self) -> Result<(), SpecError> {
        match self {
            AnySpec::Impact(s) => s.validate(),
            AnySpec::Jet(s) => s.validate(),
        }
    }
}

/// One cell of a campaign as a farm stores it, whatever its scene (seed paper section 4: a
/// cell is one set of impact conditions, run as independent samples).
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedCell {
    /// Index in the spec's expansion order.
    pub index: u32,
    /// An impact cell's angle (degrees); `None` for a scene without one.
    pub angle_deg: Option<f64>,
    /// An impact cell's grain shape; `None` for a scene without one.
    pub shape: Option<String>,
    /// Values of the other swept dimensions, by name with unit.
    pub swept: BTreeMap<String, f64>,
    /// Units (impacts, slices) each sample is first planned for.
    pub units: u32,
    /// The scene's parameters of every job of the cell, as JSON.
    pub params: String,
    /// The rule growing the units until the cell is steady, if any.
    pub until_steady: Option<UntilSteady>,
}

/// A campaign as a farm stores it: its cells and jobs, from one validation of the spec.
#[derive(Debug, Clone, PartialEq)]
pub struct CampaignPlan {
    /// The scene's kind (`grit_erosion::Scene::KIND`).
    pub kind: &'static str,
    /// Samples every cell first gets.
    pub samples: u32,
    /// The rule growing the samples until the error bar is small, if any.
    pub target_sem: Option<TargetSem>,
    /// The cells in expansion order.
    pub cells: Vec<PlannedCell>,
    /// Units over every job as first planned.
    pub units_total: u64,
    /// Every job as (cell, sample, units planned, seed), cell by cell.
    pub jobs: Vec<(u32, u32, u32, u64)>,
    /// The order a farm hands out the jobs.
    pub queue: QueueOrder,
}

impl AnySpec {
    /// The campaign's cells and jobs, validating the spec once.
    pub fn plan(&self) -> Result<CampaignPlan, SpecError> {
        let (kind, seed, samples, target_sem, queue, cells) = match self {
            AnySpec::Impact(s) => (
                crate::Sample::KIND,
                s.seed,
                s.samples.initial(),
                s.samples.target_sem(),
                s.queue,
                s.cells()?
                    .into_iter()
                    .map(|c| PlannedCell {
                        index: c.index,
                        angle_deg: Some(c.params.angle_deg),
                        shape: Some(c.params.shape.name().to_string()),
                        swept: c.swept,
                        units: c.impacts,
                        params: json(&c.params),
                        until_steady: c.until_steady,
                    })
                    .collect::<Vec<_>>(),
            ),
            AnySpec::Jet(s) => (
                crate::jet::JetRun::KIND,
                s.seed,
                s.samples,
                None,
                QueueOrder::Rounds,
                s.cells()?
                    .into_iter()
                    .map(|c| PlannedCell {
                        index: c.index,
                        angle_deg: None,
                        shape: None,
                        swept: c.swept,
                        units: c.slices,
                        params: json(&c.params),
                        until_steady: None,
                    })
                    .collect(),
            ),
        };
        let jobs: Vec<_> = cells
            .iter()
            .flat_map(|c| {
                (0..samples).map(move |s| (c.index, s, c.units, job_seed(seed, c.index, s)))
            })
            .collect();
        Ok(CampaignPlan {
            kind,
            samples,
            target_sem,
            units_total: jobs.iter().map(|j| j.2 as u64).sum(),
            cells,
            jobs,
            queue,
        })
    }
}

/// A scene's parameters as the JSON a farm stores, with round-trip floats.
fn json<T: Serialize>(params: &T) -> String {
    serde_json::to_string(params).expect("scene parameters are plain data")
}

impl Serialize for AnySpec {
    /// As the scene's own spec: an impact spec exactly as before jets existed.
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            AnySpec::Impact(spec) => spec.serialize(s),
            AnySpec::Jet(spec) => spec.serialize(s),
        }
    }
}

fn unknown_scene(got: &str) -> SpecError {
    err("scene", format!("must be \"impact\" or \"jet\", got {got}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scene_key_picks_the_spec() {
        let old = r#"{"angles_deg": [45], "velocity_m_s": [80, 100]}"#;
        assert_eq!(
            AnySpec::from_json(old).unwrap(),
            AnySpec::Impact(CampaignSpec::from_json(old).unwrap()),
            "a spec without scene parses exactly as the impact spec"
        );
        let named = AnySpec::from_json(r#"{"scene": "impact", "angles_deg": [45]}"#).unwrap();
        let plain = CampaignSpec::from_json(r#"{"angles_deg": [45]}"#).unwrap();
        assert_eq!(named, AnySpec::Impact(plain.clone()));
        assert_eq!(
            serde_json::to_string(&named).unwrap(),
            serde_json::to_string(&plain).unwrap(),
            "an impact spec is stored as before"
        );
        let jet = AnySpec::from_json(r#"{"scene": "jet", "samples": 2}"#).unwrap();
        assert_eq!(jet.scene(), Scene::Jet);
        assert!(serde_json::to_string(&jet)
            .unwrap()
            .contains(r#""scene":"jet""#));
        assert_eq!(
            AnySpec::from_json(r#"{"scene": "laser"}"#)
                .unwrap_err()
                .field,
            "scene"
        );
        assert_eq!(
            AnySpec::from_json(r#"{"scene": 3}"#).unwrap_err().field,
            "scene"
        );
        // Impact fields in a jet spec, and jet fields in an impact one, are unknown fields.
        let e = AnySpec::from_json(r#"{"scene": "jet", "angles_deg": [45]}"#).unwrap_err();
        assert_eq!(e.field, "angles_deg");
        let e = AnySpec::from_json(r#"{"time_ms": 1}"#).unwrap_err();
        assert_eq!(e.field, "time_ms");
    }
}
