//! What every scene's campaign shares (`docs/design.md`, "Campaign spec"): the errors that
//! name a spec's field and rule, sweeps of one or many values, the material, the limits on a
//! campaign's size, and the job seeds; the rules that grow a cell (`plan`); the spec of any
//! scene (`AnySpec`); a campaign as a farm stored it, handed back to its scene (`stored`).
//! Each scene's own spec lives with the scene (`crate::scenes::*::spec`).
//!
//! # Job seeds
//! A job's seed is a pure function of (campaign seed, cell index, sample index):
//!
//! ```text
//! job_seed = mix(mix(campaign_seed) XOR (cell << 32 | sample))
//! mix(z):  z = (z XOR z >> 30) * 0xbf58476d1ce4e5b9
//!          z = (z XOR z >> 27) * 0x94d049bb133111eb
//!          z XOR z >> 31                           (wrapping u64 arithmetic)
//! ```
//!
//! `mix` is the SplitMix64 finaliser, a bijection on u64, and so is XOR with a constant; so
//! within one campaign distinct (cell, sample) pairs always get distinct seeds. The formula is
//! fixed here (not std's `DefaultHasher`, whose output may change between Rust releases), so
//! a campaign resubmitted years later replays the same grains.

use grit_sph::Material;
use serde::{Serialize, Serializer};

mod any;
pub(crate) mod json;
mod plan;
mod stored;
pub use crate::scenes::impact::spec::{CampaignSpec, Cell, GrainSpec, Impacts, QueueOrder};
pub use crate::scenes::jet::spec::{JetCampaignSpec, JetCell, Scene};
pub use any::{AnySpec, CampaignPlan, PlannedCell, RaisedCap};
pub use plan::{
    annotate, next_step, sem_rel, ImpactPlan, NextStep, Samples, TargetSem, UntilSteady,
};
pub(crate) use stored::stored_error;
pub use stored::{results_json, CellRecords, StoredCell, StoredJob, UnitMasses};

/// Fewest impacts a sample may be planned with: the slope window (20) plus one.
pub const MIN_IMPACTS: u32 = 21;
/// Most jobs one campaign may expand into; a guard against a typo that would flood the queue.
pub const MAX_JOBS: usize = 1_000_000;
/// Most impacts one sample may be planned with (fixed, or `until_steady.max`): about a week of
/// one core at the seed's resolution, a guard against a typo that would hold a worker for years.
pub const MAX_IMPACTS: u32 = 100_000;
/// Most cells one campaign may have: each is a row with its scene in the database, checked at
/// submission (the paper's campaign has 24).
pub const MAX_CELLS: usize = 10_000;
/// Most impacts one campaign may plan at its largest (every sample at its `max`): about six
/// CPU-years at the seed's resolution, a guard against a typo that would fill the database.
pub const MAX_IMPACTS_TOTAL: u128 = 100_000_000;

/// Cells of a spec whose swept dimensions have lengths `dims` (each list's spec field and
/// length): their product. Bounded for a validated spec, so it fits.
pub(crate) fn cell_count(dims: &[(&'static str, usize)]) -> usize {
    dims.iter().map(|(_, n)| n).product()
}

/// Per swept dimension of `dims`, fastest first: (spec field, index of cell `cell`'s value,
/// whether swept), the mixed-radix digits of the cell index.
pub(crate) fn sweep_indices(
    dims: &[(&'static str, usize)],
    cell: u32,
) -> Vec<(&'static str, usize, bool)> {
    let mut rest = cell as usize;
    dims.iter()
        .map(|&(name, n)| {
            let i = rest % n.max(1);
            rest /= n.max(1);
            (name, i, n > 1)
        })
        .collect()
}

/// The rule on the cell count: at most [`MAX_CELLS`], named on the longest list of `dims`.
pub(crate) fn check_cells(dims: &[(&'static str, usize)]) -> Result<(), SpecError> {
    let cells = job_count(dims.iter().map(|(_, len)| *len), 1);
    if cells > MAX_CELLS as u128 {
        let longest = dims.iter().max_by_key(|(_, len)| *len).map_or("", |d| d.0);
        return Err(err(
            longest,
            format!("the lists multiply into {cells} cells, more than the limit of {MAX_CELLS}"),
        ));
    }
    Ok(())
}

/// Most values one list of a spec may hold (angles, shapes, each swept field): the product of
/// the lists is the cell count, which must stay countable and checkable at submission.
pub const MAX_LIST: usize = 1_000;

/// The rule every list of a spec keeps: at most [`MAX_LIST`] values.
pub(crate) fn check_list_len(field: &str, len: usize) -> Result<(), SpecError> {
    if len > MAX_LIST {
        return Err(err(
            field,
            format!("lists {len} values, more than the limit of {MAX_LIST}"),
        ));
    }
    Ok(())
}

/// The rules of one swept field: at least one value, each finite and > 0 (≥ 0 where not
/// `positive`), none twice, at most [`MAX_LIST`]. A field of one value is named without index.
pub(crate) fn check_sweep(name: &str, values: &[f64], positive: bool) -> Result<(), SpecError> {
    if values.is_empty() {
        return Err(err(name, "must give at least one value"));
    }
    check_list_len(name, values.len())?;
    for (i, v) in values.iter().enumerate() {
        let field = if values.len() > 1 {
            format!("{name}[{i}]")
        } else {
            name.to_string()
        };
        if !v.is_finite() || *v < 0.0 || (positive && *v <= 0.0) {
            let rule = if positive { "> 0" } else { "≥ 0" };
            return Err(err(
                field,
                format!("must be a finite number {rule}, got {v}"),
            ));
        }
        if values[..i].contains(v) {
            return Err(err(field, format!("{v} listed twice")));
        }
    }
    Ok(())
}

/// Jobs a campaign of these list lengths and samples per cell expands into, without overflow.
pub(crate) fn job_count(lengths: impl IntoIterator<Item = usize>, samples: u32) -> u128 {
    lengths
        .into_iter()
        .fold(samples as u128, |n, len| n.saturating_mul(len as u128))
}

/// A rejected campaign spec: `field` is the path of the offending value, `rule` what it broke.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {rule}")]
pub struct SpecError {
    /// Path of the field, e.g. `grain.diameter_m[1]` or `impacts["15"]`.
    pub field: String,
    /// The rule broken, in words.
    pub rule: String,
}

pub(crate) fn err(field: impl Into<String>, rule: impl Into<String>) -> SpecError {
    SpecError {
        field: field.into(),
        rule: rule.into(),
    }
}

/// One value, or a list of values to sweep over: a JSON value or a JSON array of them.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep<T>(pub Vec<T>);

impl<T> Sweep<T> {
    /// A sweep of one value (no sweep).
    pub fn one(v: T) -> Self {
        Sweep(vec![v])
    }

    /// The values in order.
    pub fn values(&self) -> &[T] {
        &self.0
    }

    /// Whether more than one value is given, so the value differs between cells.
    pub fn is_swept(&self) -> bool {
        self.0.len() > 1
    }
}

impl<T: Serialize> Serialize for Sweep<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.0.as_slice() {
            [one] => one.serialize(s),
            many => many.serialize(s),
        }
    }
}

/// The surface material: a preset name (`grit_sph::MATERIAL_NAMES`) or a full
/// `grit_sph::Material` object.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialSpec(pub Material);

impl Serialize for MaterialSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        // A preset left unchanged is written by name, so stored specs stay short and readable.
        if Material::by_name(&self.0.name).is_ok_and(|preset| preset == self.0) {
            s.serialize_str(&self.0.name)
        } else {
            self.0.serialize(s)
        }
    }
}

/// Checks a pinned engine fingerprint (`engine` of a spec; `crate::fingerprint`): 16
/// lowercase hex digits, as `grit version --json` prints them.
pub fn check_engine(engine: Option<&str>) -> Result<(), SpecError> {
    match engine {
        Some(e) if !is_fingerprint(e) => Err(err(
            "engine",
            format!(
                "`{e}` is no engine fingerprint: 16 lowercase hex digits, as `grit version \
                 --json` prints"
            ),
        )),
        _ => Ok(()),
    }
}

/// Whether `s` has the form of an engine fingerprint: 16 lowercase hex digits.
pub fn is_fingerprint(s: &str) -> bool {
    s.len() == 16
        && s.bytes()
            .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
}

/// SplitMix64 finaliser: a bijection on u64 that scrambles every input bit into every output bit.
pub(crate) fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The seed of sample `sample` of cell `cell` in a campaign seeded `campaign_seed` (module docs).
pub fn job_seed(campaign_seed: u64, cell: u32, sample: u32) -> u64 {
    mix(mix(campaign_seed) ^ ((cell as u64) << 32 | sample as u64))
}
