//! How many impacts and samples a cell gets: a fixed count, or a rule the coordinator follows
//! as results come in (`docs/erosion.md`, "Extending a cell"): impacts grown until the cell's
//! steady-state check passes ([`crate::impact::steady`]), samples added until the erosion's standard
//! error over its mean is small enough.

use std::fmt;

use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::json::count;
use super::{err, SpecError, MAX_IMPACTS};
use crate::impact::aggregate::CellResult;

/// Grow every sample of a cell by `step` impacts until the cell is steady or reaches `max`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UntilSteady {
    /// Impacts every sample is first planned with.
    #[serde(deserialize_with = "count")]
    pub min: u32,
    /// Most impacts a sample may reach; a cell stopped here unsteady is reported so.
    #[serde(deserialize_with = "count")]
    pub max: u32,
    /// Impacts added to every sample of an unsteady cell at a time.
    #[serde(deserialize_with = "count")]
    pub step: u32,
    /// Grow also while the last window's loss does not pay for the damage its impacts added
    /// ([`crate::impact::balance`]): a steady cell counts as done only once it is stationary.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub balanced: bool,
}

impl UntilSteady {
    /// Checks `min ≥ least`, `min ≤ max ≤ MAX_IMPACTS`, `1 ≤ step ≤ max`; `field` is where the
    /// rule sits.
    pub fn validate(&self, field: &str, least: u32) -> Result<(), SpecError> {
        let at = |k: &str| format!("{field}.until_steady.{k}");
        if self.min < least {
            return Err(err(
                at("min"),
                format!("must be at least {least}, got {}", self.min),
            ));
        }
        if self.max < self.min {
            return Err(err(
                at("max"),
                format!("must be at least min ({}), got {}", self.min, self.max),
            ));
        }
        if self.max > MAX_IMPACTS {
            return Err(err(
                at("max"),
                format!(
                    "must be at most {MAX_IMPACTS} impacts per sample, got {}",
                    self.max
                ),
            ));
        }
        if self.step == 0 {
            return Err(err(at("step"), "must be at least 1"));
        }
        if self.step > self.max {
            return Err(err(
                at("step"),
                format!("must be at most max ({}), got {}", self.max, self.step),
            ));
        }
        Ok(())
    }
}

/// Impacts of every sample of a cell: a fixed number, or grown until steady.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImpactPlan {
    /// This many impacts.
    Fixed(u32),
    /// Start at `min`, extend by `step` until steady or `max`.
    UntilSteady(UntilSteady),
}

impl ImpactPlan {
    /// Impacts every sample is first planned with.
    pub fn initial(&self) -> u32 {
        match self {
            ImpactPlan::Fixed(n) => *n,
            ImpactPlan::UntilSteady(u) => u.min,
        }
    }

    /// The until-steady rule, if any.
    pub fn until_steady(&self) -> Option<UntilSteady> {
        match self {
            ImpactPlan::Fixed(_) => None,
            ImpactPlan::UntilSteady(u) => Some(*u),
        }
    }
}

/// The JSON form of the until-steady rule: `{"until_steady": {...}}`.
#[derive(Serialize)]
struct UntilSteadyForm<'a> {
    until_steady: &'a UntilSteady,
}

impl Serialize for ImpactPlan {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            ImpactPlan::Fixed(n) => s.serialize_u32(*n),
            ImpactPlan::UntilSteady(u) => UntilSteadyForm { until_steady: u }.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for ImpactPlan {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct PlanVisitor;
        impl<'de> Visitor<'de> for PlanVisitor {
            type Value = ImpactPlan;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or {\"until_steady\": {\"min\", \"max\", \"step\"}}")
            }
            fn visit_u64<E: de::Error>(self, n: u64) -> Result<ImpactPlan, E> {
                u32::try_from(n)
                    .map(ImpactPlan::Fixed)
                    .map_err(|_| E::custom(super::json::not_a_count(n)))
            }
            fn visit_i64<E: de::Error>(self, n: i64) -> Result<ImpactPlan, E> {
                match u64::try_from(n) {
                    Ok(n) => self.visit_u64(n),
                    Err(_) => Err(E::custom(super::json::not_a_count(n))),
                }
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<ImpactPlan, E> {
                Err(E::custom(super::json::not_a_count(x)))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<ImpactPlan, A::Error> {
                let mut rule = None;
                while let Some(key) = map.next_key::<String>()? {
                    if key != "until_steady" || rule.is_some() {
                        return Err(de::Error::custom(format!(
                            "unknown key `{key}`; expected a number or {{\"until_steady\": {{...}}}}"
                        )));
                    }
                    rule = Some(map.next_value::<UntilSteady>()?);
                }
                rule.map(ImpactPlan::UntilSteady)
                    .ok_or_else(|| de::Error::custom("expected {\"until_steady\": {...}}"))
            }
        }
        d.deserialize_any(PlanVisitor)
    }
}

/// Add samples to a cell until its erosion's standard error over its mean is at most
/// `target_sem_rel`, or it has `max` samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetSem {
    /// Largest standard error of the mean over |mean| accepted, e.g. 0.1.
    pub target_sem_rel: f64,
    /// Samples every cell starts with.
    #[serde(deserialize_with = "count")]
    pub min: u32,
    /// Most samples a cell may reach.
    #[serde(deserialize_with = "count")]
    pub max: u32,
}

/// Samples per cell: a fixed number, or added until the error bar is small.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Samples {
    /// This many samples.
    Fixed(u32),
    /// Start at `min`, add until `target_sem_rel` or `max`.
    TargetSem(TargetSem),
}

impl Samples {
    /// Samples every cell starts with.
    pub fn initial(&self) -> u32 {
        match self {
            Samples::Fixed(n) => *n,
            Samples::TargetSem(t) => t.min,
        }
    }

    /// Most samples a cell may reach.
    pub fn max(&self) -> u32 {
        match self {
            Samples::Fixed(n) => *n,
            Samples::TargetSem(t) => t.max,
        }
    }

    /// The error-bar rule, if any.
    pub fn target_sem(&self) -> Option<TargetSem> {
        match self {
            Samples::Fixed(_) => None,
            Samples::TargetSem(t) => Some(*t),
        }
    }

    /// Checks the counts and the target; errors name `samples` or `samples.<rule field>`.
    pub fn validate(&self) -> Result<(), SpecError> {
        match self {
            Samples::Fixed(0) => Err(err("samples", "must be at least 1")),
            Samples::Fixed(_) => Ok(()),
            Samples::TargetSem(t) => {
                if !(t.target_sem_rel.is_finite() && t.target_sem_rel > 0.0) {
                    return Err(err(
                        "samples.target_sem_rel",
                        format!("must be a finite number > 0, got {}", t.target_sem_rel),
                    ));
                }
                if t.min < 2 {
                    return Err(err(
                        "samples.min",
                        format!(
                            "must be at least 2 (a standard error needs two samples), got {}",
                            t.min
                        ),
                    ));
                }
                if t.max < t.min {
                    return Err(err(
                        "samples.max",
                        format!("must be at least min ({}), got {}", t.min, t.max),
                    ));
                }
                Ok(())
            }
        }
    }
}

impl Serialize for Samples {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Samples::Fixed(n) => s.serialize_u32(*n),
            Samples::TargetSem(t) => t.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Samples {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct SamplesVisitor;
        impl<'de> Visitor<'de> for SamplesVisitor {
            type Value = Samples;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or {\"target_sem_rel\", \"min\", \"max\"}")
            }
            fn visit_u64<E: de::Error>(self, n: u64) -> Result<Samples, E> {
                u32::try_from(n)
                    .map(Samples::Fixed)
                    .map_err(|_| E::custom(super::json::not_a_count(n)))
            }
            fn visit_i64<E: de::Error>(self, n: i64) -> Result<Samples, E> {
                match u64::try_from(n) {
                    Ok(n) => self.visit_u64(n),
                    Err(_) => Err(E::custom(super::json::not_a_count(n))),
                }
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<Samples, E> {
                Err(E::custom(super::json::not_a_count(x)))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Samples, A::Error> {
                TargetSem::deserialize(de::value::MapAccessDeserializer::new(map))
                    .map(Samples::TargetSem)
            }
        }
        d.deserialize_any(SamplesVisitor)
    }
}

/// What the coordinator does with a cell once every sample has its planned impacts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NextStep {
    /// Plan every sample of the cell for this many impacts and run them on.
    ExtendImpacts(u32),
    /// Add samples until the cell has this many.
    AddSamples(u32),
    /// The cell is finished.
    Final,
}

/// Standard error of the cell's erosion over its |mean|: 0 when every slope is equal,
/// infinite for a zero mean with scatter, `None` below two slopes.
pub fn sem_rel(cell: &CellResult) -> Option<f64> {
    let (mean, sem) = (cell.erosion_mean?, cell.erosion_sem?);
    Some(if sem == 0.0 {
        0.0
    } else if mean == 0.0 {
        f64::INFINITY
    } else {
        sem / mean.abs()
    })
}

/// The next step for a finished cell (`docs/erosion.md`, "Extending a cell"). Impacts come
/// first: while the steady-state check fails and `max` is not reached, every sample grows by
/// `step`. Then, while `sem/|mean| > target_sem_rel` and samples are below `max`, the cell
/// grows to `n·(rel/target)²` samples, the count at which the error bar would meet the
/// target if the scatter stayed as measured, at least one more and at most `max`.
pub fn next_step(
    cell: &CellResult,
    until: Option<UntilSteady>,
    target: Option<TargetSem>,
) -> NextStep {
    if let Some(u) = until {
        let steady = cell.steady_state.as_ref().is_some_and(|s| s.steady)
            && (!u.balanced || cell.damage_balance.is_some_and(|b| b.balanced));
        let planned = cell.impacts_planned as u32;
        if !steady && planned < u.max {
            return NextStep::ExtendImpacts(planned.saturating_add(u.step).min(u.max));
        }
    }
    if let Some(t) = target {
        let n = cell.samples_planned as u32;
        let rel = sem_rel(cell);
        if n < t.max && rel.is_none_or(|r| r > t.target_sem_rel) {
            let wanted = match rel {
                Some(r) if r.is_finite() => (n as f64 * (r / t.target_sem_rel).powi(2))
                    .ceil()
                    .min(t.max as f64) as u32,
                Some(_) => t.max,
                None => n + 1,
            };
            return NextStep::AddSamples(wanted.clamp(n + 1, t.max));
        }
    }
    NextStep::Final
}

/// Marks what the rules reached: the error bar reached under `target`, and a cell left
/// unsteady at its `max` impacts says so first in its steady-state reason.
pub fn annotate(cell: &mut CellResult, until: Option<UntilSteady>, target: Option<TargetSem>) {
    if target.is_some() {
        cell.erosion_sem_rel = sem_rel(cell);
    }
    if let (Some(u), Some(s)) = (until, cell.steady_state.as_mut()) {
        if !s.steady && !cell.partial && cell.impacts_planned as u32 >= u.max {
            s.reason = format!("reached max {} impacts; {}", u.max, s.reason);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::CampaignSpec;
    use super::*;

    fn field_of(json: &str) -> String {
        CampaignSpec::from_json(json)
            .and_then(|s| s.validate().map(|_| s))
            .expect_err("must be rejected")
            .field
    }

    #[test]
    fn until_steady_parses_whole_and_per_angle() {
        let rule = UntilSteady {
            min: 21,
            max: 60,
            step: 5,
            balanced: false,
        };
        let s = CampaignSpec::from_json(
            r#"{"angles_deg": [15, 45], "impacts": {"until_steady": {"min": 21, "max": 60, "step": 5}}}"#,
        )
        .unwrap();
        s.validate().unwrap();
        assert_eq!(s.impacts.plan_at(45.0), Some(ImpactPlan::UntilSteady(rule)));
        assert_eq!(s.impacts.at(15.0), Some(21));
        let cells = s.cells().unwrap();
        assert_eq!(cells[0].impacts, 21);
        assert_eq!(cells[0].until_steady, Some(rule));
        let total = crate::campaign::AnySpec::Impact(s)
            .plan()
            .unwrap()
            .units_total;
        assert_eq!(total, 21 * 2 * 4 * 25);

        let s = CampaignSpec::from_json(
            r#"{"angles_deg": [15, 45], "impacts": {"15": {"until_steady": {"min": 21, "max": 60, "step": 5}}, "default": 30}}"#,
        )
        .unwrap();
        s.validate().unwrap();
        assert_eq!(s.impacts.plan_at(15.0), Some(ImpactPlan::UntilSteady(rule)));
        assert_eq!(s.impacts.plan_at(45.0), Some(ImpactPlan::Fixed(30)));
        let cells = s.cells().unwrap();
        assert_eq!(cells[1].until_steady, None);
        // The serialised form reads back equal.
        let back = CampaignSpec::from_json(&serde_json::to_string(&s).unwrap()).unwrap();
        assert_eq!(back, s);
        assert!(serde_json::to_string(&s)
            .unwrap()
            .contains(r#""impacts":{"15":{"until_steady":{"#));
    }

    #[test]
    fn target_sem_parses() {
        let s =
            CampaignSpec::from_json(r#"{"samples": {"target_sem_rel": 0.1, "min": 3, "max": 40}}"#)
                .unwrap();
        s.validate().unwrap();
        assert_eq!(s.samples.initial(), 3);
        assert_eq!(s.samples.max(), 40);
        let plan = crate::campaign::AnySpec::Impact(s.clone()).plan().unwrap();
        assert_eq!(plan.jobs.len(), 24 * 3);
        let back = CampaignSpec::from_json(&serde_json::to_string(&s).unwrap()).unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn bad_rules_name_the_field() {
        let us = |body: &str| format!(r#"{{"impacts": {{"until_steady": {body}}}}}"#);
        assert_eq!(
            field_of(&us(r#"{"min": 21, "max": 30, "step": 0}"#)),
            "impacts.until_steady.step"
        );
        assert_eq!(
            field_of(&us(r#"{"min": 20, "max": 30, "step": 1}"#)),
            "impacts.until_steady.min"
        );
        assert_eq!(
            field_of(&us(r#"{"min": 30, "max": 21, "step": 1}"#)),
            "impacts.until_steady.max"
        );
        assert_eq!(
            field_of(&us(r#"{"min": 21, "max": 30, "step": -1}"#)),
            "impacts.until_steady.step"
        );
        assert_eq!(
            field_of(&us(r#"{"min": 21, "max": 30, "step": 1, "x": 1}"#)),
            "impacts.until_steady.x"
        );
        assert_eq!(
            field_of(
                r#"{"impacts": {"15": {"until_steady": {"min": 21, "max": 30, "step": 0}}, "default": 60}}"#
            ),
            "impacts[\"15\"].until_steady.step"
        );
        assert_eq!(
            field_of(r#"{"impacts": {"15": {"until": 3}, "default": 60}}"#),
            "impacts[\"15\"]"
        );
        // Short samples may start below 21 with the flag.
        CampaignSpec::from_json(
            r#"{"impacts": {"until_steady": {"min": 2, "max": 4, "step": 1}}, "allow_short_samples": true}"#,
        )
        .unwrap()
        .validate()
        .unwrap();
        assert_eq!(
            field_of(r#"{"samples": {"target_sem_rel": 0, "min": 2, "max": 5}}"#),
            "samples.target_sem_rel"
        );
        assert_eq!(
            field_of(r#"{"samples": {"target_sem_rel": 0.1, "min": 1, "max": 5}}"#),
            "samples.min"
        );
        assert_eq!(
            field_of(r#"{"samples": {"target_sem_rel": 0.1, "min": 4, "max": 3}}"#),
            "samples.max"
        );
        assert_eq!(
            field_of(r#"{"samples": {"target_sem_rel": 0.1, "min": 2.5, "max": 3}}"#),
            "samples.min"
        );
        assert_eq!(
            field_of(r#"{"samples": {"target_sem_rel": 0.1, "min": 2}}"#),
            "samples"
        );
    }
}
