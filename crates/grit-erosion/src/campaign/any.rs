//! A campaign spec of either scene: `"scene": "jet"` selects the jet spec
//! ([`super::JetCampaignSpec`]); `"scene": "impact"` or no `scene` key the impact spec
//! ([`super::CampaignSpec`]), so every spec written before jets existed parses as before.

use serde::{Serialize, Serializer};
use serde_json::Value;

use super::{err, CampaignSpec, JetCampaignSpec, Scene, SpecError};

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

    /// Checks every rule of the spec's scene.
    pub fn validate(&self) -> Result<(), SpecError> {
        match self {
            AnySpec::Impact(s) => s.validate(),
            AnySpec::Jet(s) => s.validate(),
        }
    }
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
