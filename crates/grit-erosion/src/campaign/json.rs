//! The JSON form of the campaign spec: one value or an array of them, the per-angle impacts
//! map, the material by name or by constants, and the field paths that errors name.

use std::fmt;
use std::marker::PhantomData;

use grit_sph::Material;
use serde::de::value::{MapAccessDeserializer, SeqAccessDeserializer};
use serde::de::{
    self, DeserializeOwned, DeserializeSeed, IntoDeserializer, MapAccess, SeqAccess, Visitor,
};
use serde::{Deserialize, Deserializer};
use serde_json::{Map, Value};
use serde_path_to_error::Segment;

use super::{err, ImpactPlan, MaterialSpec, SpecError, Sweep, UntilSteady};
use crate::impact::spec::{same_angle, Impacts};

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Sweep<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        one_or_many(d).map(Sweep)
    }
}

/// A single value or an array of values. Each kind of JSON value goes straight to `T`, never
/// through a buffer, so an error inside keeps its path (`velocity_m_s[1]`) and serde's message.
pub(crate) fn one_or_many<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
    d: D,
) -> Result<Vec<T>, D::Error> {
    struct OneOrMany<T>(PhantomData<T>);
    impl<'de, T: Deserialize<'de>> Visitor<'de> for OneOrMany<T> {
        type Value = Vec<T>;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a value or an array of values")
        }
        fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Vec<T>, A::Error> {
            Vec::deserialize(SeqAccessDeserializer::new(seq))
        }
        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Vec<T>, A::Error> {
            T::deserialize(MapAccessDeserializer::new(map)).map(|v| vec![v])
        }
        fn visit_str<E: de::Error>(self, v: &str) -> Result<Vec<T>, E> {
            T::deserialize(v.into_deserializer()).map(|v| vec![v])
        }
        fn visit_bool<E: de::Error>(self, v: bool) -> Result<Vec<T>, E> {
            T::deserialize(v.into_deserializer()).map(|v| vec![v])
        }
        fn visit_i64<E: de::Error>(self, v: i64) -> Result<Vec<T>, E> {
            T::deserialize(v.into_deserializer()).map(|v| vec![v])
        }
        fn visit_u64<E: de::Error>(self, v: u64) -> Result<Vec<T>, E> {
            T::deserialize(v.into_deserializer()).map(|v| vec![v])
        }
        fn visit_f64<E: de::Error>(self, v: f64) -> Result<Vec<T>, E> {
            T::deserialize(v.into_deserializer()).map(|v| vec![v])
        }
        fn visit_unit<E: de::Error>(self) -> Result<Vec<T>, E> {
            T::deserialize(().into_deserializer()).map(|v| vec![v])
        }
    }
    d.deserialize_any(OneOrMany(PhantomData))
}

impl<'de> Deserialize<'de> for MaterialSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct MaterialVisitor;
        impl<'de> Visitor<'de> for MaterialVisitor {
            type Value = MaterialSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a material name (\"aisi304\", \"copper\", \"al6061\") or a material object",
                )
            }
            fn visit_str<E: de::Error>(self, name: &str) -> Result<MaterialSpec, E> {
                Material::by_name(name)
                    .map(MaterialSpec)
                    .map_err(|e| E::custom(e.rule))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<MaterialSpec, A::Error> {
                Material::deserialize(MapAccessDeserializer::new(map)).map(MaterialSpec)
            }
        }
        d.deserialize_any(MaterialVisitor)
    }
}

impl<'de> Deserialize<'de> for Impacts {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ImpactsVisitor;
        impl<'de> Visitor<'de> for ImpactsVisitor {
            type Value = Impacts;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a number, {\"until_steady\": {...}} or an object {\"15\": 140, \"default\": 60}",
                )
            }
            fn visit_u64<E: de::Error>(self, n: u64) -> Result<Impacts, E> {
                u32::try_from(n)
                    .map(|n| Impacts::All(ImpactPlan::Fixed(n)))
                    .map_err(|_| E::custom(not_a_count(n)))
            }
            fn visit_i64<E: de::Error>(self, n: i64) -> Result<Impacts, E> {
                match u64::try_from(n) {
                    Ok(n) => self.visit_u64(n),
                    Err(_) => Err(E::custom(not_a_count(n))),
                }
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<Impacts, E> {
                Err(E::custom(not_a_count(Value::from(x))))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Impacts, A::Error> {
                let (mut angles, mut default, mut whole) = (Vec::new(), None, None);
                while let Some(key) = map.next_key::<String>()? {
                    if key == "until_steady" {
                        whole = Some(map.next_value::<UntilSteady>()?);
                        continue;
                    }
                    map.next_value_seed(AngleEntry {
                        key: &key,
                        angles: &mut angles,
                        default: &mut default,
                    })?;
                }
                match whole {
                    Some(_) if !angles.is_empty() || default.is_some() => Err(de::Error::custom(
                        "`until_steady` is either the whole value or a value under each angle, not a key beside angles",
                    )),
                    Some(u) => Ok(Impacts::All(ImpactPlan::UntilSteady(u))),
                    None => Ok(Impacts::PerAngle { angles, default }),
                }
            }
        }
        d.deserialize_any(ImpactsVisitor)
    }
}

/// One entry of the per-angle impacts map. The key is checked while its value is read, so an
/// error about the key names it too (`impacts["fifteen"]`).
struct AngleEntry<'a> {
    key: &'a str,
    angles: &'a mut Vec<(f64, ImpactPlan)>,
    default: &'a mut Option<ImpactPlan>,
}

impl<'de> DeserializeSeed<'de> for AngleEntry<'_> {
    type Value = ();
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        let n = ImpactPlan::deserialize(d)?;
        if self.key == "default" {
            *self.default = Some(n);
            return Ok(());
        }
        let a: f64 = self.key.trim().parse().map_err(|_| {
            de::Error::custom("keys must be angles in degrees (e.g. \"15\") or \"default\"")
        })?;
        if self.angles.iter().any(|(b, _)| same_angle(*b, a)) {
            return Err(de::Error::custom("angle listed twice"));
        }
        self.angles.push((a, n));
        Ok(())
    }
}

pub(crate) fn not_a_count(v: impl fmt::Display) -> String {
    format!("must be a whole number ≥ 0, got {v}")
}

/// A count (`samples`, impacts): a whole number that fits in u32.
pub(crate) fn count<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let v = Value::deserialize(d)?;
    v.as_u64()
        .and_then(|n| u32::try_from(n).ok())
        .ok_or_else(|| de::Error::custom(not_a_count(&v)))
}

/// The field names serde derives for the struct `T`: asks its `Deserialize` for them without
/// any data, so the list of known fields is never written by hand.
fn field_names<T: DeserializeOwned>() -> &'static [&'static str] {
    struct Probe<'a>(&'a mut &'static [&'static str]);
    impl<'de> Deserializer<'de> for Probe<'_> {
        type Error = de::value::Error;
        fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Self::Error> {
            Err(de::Error::custom("not a struct"))
        }
        fn deserialize_struct<V: Visitor<'de>>(
            self,
            _: &'static str,
            fields: &'static [&'static str],
            _: V,
        ) -> Result<V::Value, Self::Error> {
            *self.0 = fields;
            Err(de::Error::custom("field names taken"))
        }
        serde::forward_to_deserialize_any! {
            bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes
            byte_buf option unit unit_struct newtype_struct seq tuple tuple_struct map enum
            identifier ignored_any
        }
    }
    let mut names: &'static [&'static str] = &[];
    let _ = T::deserialize(Probe(&mut names));
    names
}

/// The JSON object of a spec's text; errors name `(json)` for text that is not JSON and
/// `(campaign)` for JSON that is not an object.
pub(crate) fn spec_object(text: &str) -> Result<Map<String, Value>, SpecError> {
    match serde_json::from_str(text).map_err(|e| err("(json)", e.to_string()))? {
        Value::Object(map) => Ok(map),
        _ => Err(err("(campaign)", "must be a JSON object")),
    }
}

/// Every key of `map` that is not a field of `T`, named together with the known ones, so a
/// user sees all their typos at once (serde stops at the first).
pub(crate) fn reject_unknown<T: DeserializeOwned>(
    map: &Map<String, Value>,
    prefix: &str,
) -> Result<(), SpecError> {
    let known = field_names::<T>();
    let unknown: Vec<String> = map
        .keys()
        .filter(|k| !known.contains(&k.as_str()))
        .map(|k| format!("{prefix}{k}"))
        .collect();
    if unknown.is_empty() {
        return Ok(());
    }
    Err(err(
        unknown.join(", "),
        format!(
            "unknown field{}; known fields: {}",
            if unknown.len() > 1 { "s" } else { "" },
            known.join(", ")
        ),
    ))
}

/// The spec field a deserialisation error points at, written as users write it:
/// `grain.diameter_m[1]`, and the angle keys of `impacts` quoted, `impacts["15"]`.
pub(crate) fn field_path(path: &serde_path_to_error::Path) -> String {
    let mut out = String::new();
    for segment in path.iter() {
        match segment {
            Segment::Seq { index } => out.push_str(&format!("[{index}]")),
            Segment::Map { key } if out == "impacts" && key != "until_steady" => {
                out.push_str(&format!("[\"{key}\"]"))
            }
            Segment::Map { key } | Segment::Enum { variant: key } => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(key);
            }
            Segment::Unknown => out.push_str(if out.is_empty() { "?" } else { ".?" }),
        }
    }
    if out.is_empty() {
        "(campaign)".into()
    } else {
        out
    }
}
