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

/// A cell whose `until_steady.max` a later spec of the same campaign raises
/// (`docs/erosion.md`, "Raising the cap").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RaisedCap {
    /// The cell's index.
    pub cell: u32,
    /// Its cap so far (impacts per sample).
    pub from: u32,
    /// Its new cap.
    pub to: u32,
}

impl PlannedCell {
    /// `cell 3 (60°, hexagon)`, or `cell 3` for a scene without angles.
    fn label(&self) -> String {
        match (self.angle_deg, &self.shape) {
            (Some(a), Some(s)) => format!("cell {} ({a}°, {s})", self.index),
            _ => format!("cell {}", self.index),
        }
    }
}

impl CampaignPlan {
    /// The cells whose `until_steady.max` `new` raises, when `new` plans this same campaign
    /// (scene, samples, seeds, cells, parameters and every other rule) but for higher caps:
    /// a stored campaign whose cells stopped at their cap unsteady may so run on. `Err` names
    /// the first thing that differs, or says that nothing is raised.
    pub fn raised_caps(&self, new: &CampaignPlan) -> Result<Vec<RaisedCap>, String> {
        let same = |what: &str, equal: bool| {
            if equal {
                Ok(())
            } else {
                Err(format!("its {what} differ"))
            }
        };
        same("scenes", self.kind == new.kind)?;
        same("samples", self.samples == new.samples)?;
        same(
            "sample rules (samples.target_sem_rel, max)",
            self.target_sem == new.target_sem,
        )?;
        same("queue orders", self.queue == new.queue)?;
        same("cell counts", self.cells.len() == new.cells.len())?;
        same("jobs or seeds", self.jobs == new.jobs)?;
        let mut raised = Vec::new();
        for (old, cell) in self.cells.iter().zip(&new.cells) {
            let (Some(was), Some(now)) = (old.until_steady, cell.until_steady) else {
                same(&format!("{}'s plans", old.label()), old == cell)?;
                continue;
            };
            let mut kept = cell.clone();
            kept.until_steady = Some(UntilSteady {
                max: was.max,
                ..now
            });
            if *old != kept {
                return Err(format!(
                    "{} differs in more than until_steady.max",
                    old.label()
                ));
            }
            if now.max < was.max {
                return Err(format!(
                    "{}: until_steady.max may only be raised, from {} (got {})",
                    old.label(),
                    was.max,
                    now.max
                ));
            }
            if now.max > was.max {
                raised.push(RaisedCap {
                    cell: old.index,
                    from: was.max,
                    to: now.max,
                });
            }
        }
        if raised.is_empty() {
            return Err("it raises no cell's until_steady.max".into());
        }
        Ok(raised)
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

    fn planned(impacts: &str, extra: &str) -> CampaignPlan {
        AnySpec::from_json(&format!(
            r#"{{"seed": 4, "angles_deg": [15, 90], "shapes": ["hexagon"], "samples": 3, "impacts": {impacts}{extra}}}"#
        ))
        .unwrap()
        .plan()
        .unwrap()
    }

    #[test]
    fn a_later_spec_may_raise_the_caps_and_nothing_else() {
        let rule =
            |max: u32| format!(r#"{{"until_steady": {{"min": 40, "max": {max}, "step": 20}}}}"#);
        let old = planned(&rule(400), "");
        let raised = old.raised_caps(&planned(&rule(800), "")).unwrap();
        assert_eq!(
            raised,
            [0, 1].map(|cell| RaisedCap {
                cell,
                from: 400,
                to: 800
            })
        );
        // Per angle: only the 90° cell is raised.
        let per_angle = format!(r#"{{"90": {}, "default": {}}}"#, rule(600), rule(400));
        assert_eq!(
            old.raised_caps(&planned(&per_angle, "")).unwrap(),
            [RaisedCap {
                cell: 1,
                from: 400,
                to: 600
            }]
        );
        let refused = |new: CampaignPlan| old.raised_caps(&new).unwrap_err();
        assert_eq!(
            refused(planned(&rule(400), "")),
            "it raises no cell's until_steady.max"
        );
        assert!(refused(planned(&rule(300), "")).contains("may only be raised, from 400 (got 300)"));
        assert!(refused(planned(&rule(800), r#", "velocity_m_s": 80"#))
            .contains("more than until_steady.max"));
        assert!(
            refused(planned(&rule(800), r#", "seed": 5"#)).contains("seeds"),
            "a new seed: other samples"
        );
        let step = r#"{"until_steady": {"min": 40, "max": 800, "step": 10}}"#;
        assert!(refused(planned(step, "")).contains("cell 0 (15°, hexagon) differs"));
        assert!(refused(planned("40", "")).contains("cell 0 (15°, hexagon)'s plans"));
    }
}
