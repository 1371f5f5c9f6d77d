//! Checkpoint envelopes: the bytes of a scene's checkpoint (`grit_erosion::Scene::checkpoint`)
//! with the job they belong to, their length and their SHA-256, and the one check both ends run
//! on them, for every scene. The coordinator refuses an upload that fails it (nothing of that
//! request is stored), and a worker that gets a stored checkpoint failing it starts the job
//! again from its first unit.

use base64::Engine;
use grit_erosion::{Scene, SceneError};
use sha2::{Digest, Sha256};

use crate::api::Checkpoint;

/// Lowercase hex SHA-256 of `bytes` (FIPS 180-4), the checksum an envelope carries.
pub fn sha256_hex(bytes: &[u8]) -> String {
    format!("{:x}", Sha256::digest(bytes))
}

impl Checkpoint {
    /// The envelope of checkpoint `bytes` of job `job_id` after `impacts_done` impacts.
    pub fn from_bytes(job_id: i64, impacts_done: u32, bytes: &[u8]) -> Checkpoint {
        Checkpoint {
            job_id,
            impacts_done,
            size_bytes: bytes.len() as u64,
            sha256: sha256_hex(bytes),
            data_b64: base64::engine::general_purpose::STANDARD.encode(bytes),
        }
    }

    /// The envelope of `run`'s state after its last finished unit, as job `job_id`.
    pub fn of<S: Scene>(job_id: i64, run: &S) -> Checkpoint {
        Checkpoint::from_bytes(job_id, run.units_done(), &run.checkpoint())
    }
}

/// An uploaded checkpoint that passed [`verify_upload`]: its bytes and their SHA-256, decoded
/// and hashed once where the request is received, so the store only writes them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CheckpointBytes {
    /// Impacts the checkpoint contains.
    pub impacts_done: u32,
    /// `grit_erosion::Sample::checkpoint` bytes.
    pub bytes: Vec<u8>,
    /// Their SHA-256 (FIPS 180-4), lowercase hex.
    pub sha256: String,
}

impl CheckpointBytes {
    /// Checkpoint `bytes` after `impacts_done` impacts, hashed here (no other check).
    pub fn new(impacts_done: u32, bytes: Vec<u8>) -> CheckpointBytes {
        CheckpointBytes {
            impacts_done,
            sha256: sha256_hex(&bytes),
            bytes,
        }
    }
}

/// Why a checkpoint envelope was refused: the field at fault and the rule it broke. Every
/// rule starts with the word "checkpoint" or names it, so logs say what was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {rule}")]
pub struct CheckpointError {
    /// Path of the offending field (`checkpoint.sha256`, …).
    pub field: &'static str,
    /// What is wrong with it.
    pub rule: String,
}

fn refuse(field: &'static str, rule: impl Into<String>) -> CheckpointError {
    CheckpointError {
        field,
        rule: rule.into(),
    }
}

/// Checks `c` as job `job_id`'s checkpoint, whose scene is `params` and seed `seed`, and
/// returns the sample it resumes. In order: the envelope names this job; `data_b64` is base64
/// of exactly `size_bytes` bytes (fewer means the upload was cut short); their SHA-256 is
/// `sha256` (a flipped byte); they decode as a checkpoint (bytes cut short with the envelope
/// rebuilt around them) of this job's scene and seed (another job's bytes); and they hold
/// `impacts_done` impacts.
pub fn verify<S: Scene>(
    c: &Checkpoint,
    job_id: i64,
    params: &S::Params,
    seed: u64,
) -> Result<S, CheckpointError> {
    verify_upload::<S>(c, job_id, params, seed).map(|(run, _)| run)
}

/// [`verify`], also handing back the checked bytes and their SHA-256 for the store to keep.
pub fn verify_upload<S: Scene>(
    c: &Checkpoint,
    job_id: i64,
    params: &S::Params,
    seed: u64,
) -> Result<(S, CheckpointBytes), CheckpointError> {
    let (bytes, actual) = envelope(c, job_id)?;
    let run = S::resume(params, seed, &bytes).map_err(|e| {
        let rule = match e {
            // Its text starts with "checkpoint: " already.
            SceneError::Checkpoint(_) => e.to_string(),
            other => format!("checkpoint: {other}"),
        };
        refuse("checkpoint.data_b64", rule)
    })?;
    if run.units_done() != c.impacts_done {
        return Err(refuse(
            "checkpoint.impacts_done",
            format!(
                "is {} but the checkpoint holds {} {}s",
                c.impacts_done,
                run.units_done(),
                S::UNIT
            ),
        ));
    }
    let bytes = CheckpointBytes {
        impacts_done: c.impacts_done,
        bytes,
        sha256: actual,
    };
    Ok((run, bytes))
}

/// The envelope checks every checkpoint passes, in order: it names job `job_id`, `data_b64`
/// is base64 of exactly `size_bytes` bytes, and they hash to `sha256`. Returns the bytes and
/// their SHA-256.
fn envelope(c: &Checkpoint, job_id: i64) -> Result<(Vec<u8>, String), CheckpointError> {
    if c.job_id != job_id {
        return Err(refuse(
            "checkpoint.job_id",
            format!(
                "the checkpoint belongs to job {}, not job {job_id}",
                c.job_id
            ),
        ));
    }
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(&c.data_b64)
        .map_err(|e| {
            refuse(
                "checkpoint.data_b64",
                format!("checkpoint data is not base64 (standard alphabet, padded): {e}"),
            )
        })?;
    let got = bytes.len() as u64;
    if got < c.size_bytes {
        return Err(refuse(
            "checkpoint.data_b64",
            format!(
                "checkpoint truncated: {got} of its {} bytes arrived",
                c.size_bytes
            ),
        ));
    }
    if got > c.size_bytes {
        return Err(refuse(
            "checkpoint.size_bytes",
            format!(
                "checkpoint data has {got} bytes but size_bytes says {}",
                c.size_bytes
            ),
        ));
    }
    let hex = c.sha256.to_ascii_lowercase();
    if hex.len() != 64 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(refuse(
            "checkpoint.sha256",
            "must be the SHA-256 of the checkpoint bytes as 64 hexadecimal digits",
        ));
    }
    let actual = sha256_hex(&bytes);
    if actual != hex {
        return Err(refuse(
            "checkpoint.sha256",
            format!("checkpoint checksum mismatch: the {got} bytes hash to {actual}, not {hex}"),
        ));
    }
    Ok((bytes, actual))
}

#[cfg(test)]
mod tests {
    //! Each corruption of an envelope is caught by the check meant for it, with a message
    //! naming it; an intact envelope resumes the very sample it was taken of.

    use super::*;
    use grit_erosion::jet::{JetParams, JetRun};
    use grit_erosion::{ImpactParams, Sample};

    /// A scene coarse enough that a fresh surface is built in milliseconds.
    fn coarse() -> ImpactParams {
        ImpactParams {
            spacing_m: 40e-6,
            surface_width_dg: 2.0,
            surface_depth_dg: 2.0,
            distribution_range_dg: 0.0,
            ..ImpactParams::default()
        }
    }

    fn good() -> (ImpactParams, Checkpoint, Vec<u8>) {
        let params = coarse();
        let sample = Sample::new(params.clone(), 3).unwrap();
        let bytes = sample.checkpoint();
        (params, Checkpoint::of(7, &sample), bytes)
    }

    fn refused(c: &Checkpoint, params: &ImpactParams, seed: u64) -> CheckpointError {
        verify::<Sample>(c, 7, params, seed).expect_err("refused")
    }

    #[test]
    fn intact_checkpoint_resumes_its_sample() {
        let (params, c, bytes) = good();
        assert_eq!(c.size_bytes, bytes.len() as u64);
        assert_eq!(c.sha256.len(), 64);
        let s = verify::<Sample>(&c, 7, &params, 3).unwrap();
        assert_eq!(s.checkpoint(), bytes);
        // Upper-case hex is the same checksum.
        let upper = Checkpoint {
            sha256: c.sha256.to_ascii_uppercase(),
            ..c
        };
        assert!(verify::<Sample>(&upper, 7, &params, 3).is_ok());
        // What the store keeps: the very bytes, and their checksum in lowercase.
        let (_, kept) = verify_upload::<Sample>(&upper, 7, &params, 3).unwrap();
        assert_eq!(kept, CheckpointBytes::new(0, bytes));
        assert_eq!(kept.sha256, c.sha256);
    }

    /// The small jet scene, one slice of 1 µs.
    fn tiny_jet() -> JetParams {
        JetParams {
            time_ms: 0.002,
            ..JetParams::small()
        }
    }

    #[test]
    fn a_jet_checkpoint_resumes_its_run_and_only_its_own() {
        let p = tiny_jet();
        let run = JetRun::new(p.clone(), 5).unwrap();
        let c = Checkpoint::of(7, &run);
        let back = verify::<JetRun>(&c, 7, &p, 5).unwrap();
        assert_eq!(back.checkpoint(), run.checkpoint());
        let scenes = crate::scenes::SceneRegistry::default();
        let jet = scenes.get("jet").unwrap();
        let stored = |scene: &str, params: String, seed| crate::db::StoredJob {
            id: 7,
            scene: scene.into(),
            params,
            seed,
        };
        let p_json = serde_json::to_string(&p).unwrap();
        let kept = jet
            .verify_upload(&c, &stored("jet", p_json.clone(), 5))
            .unwrap();
        assert_eq!(kept.bytes, run.checkpoint());
        let e = verify::<JetRun>(&c, 7, &p, 6).unwrap_err();
        assert_eq!(e.field, "checkpoint.data_b64");
        assert!(e.rule.contains("belongs to another run"), "{e}");
        assert_eq!(
            verify::<JetRun>(&c, 8, &p, 5).unwrap_err().field,
            "checkpoint.job_id"
        );
        let count = Checkpoint {
            impacts_done: 1,
            ..c.clone()
        };
        let e = verify::<JetRun>(&count, 7, &p, 5).unwrap_err();
        assert_eq!(e.rule, "is 1 but the checkpoint holds 0 slices");
        // An impact checkpoint is no jet checkpoint, and the other way round.
        let (ip, ic, _) = good();
        assert!(jet.verify_upload(&ic, &stored("jet", p_json, 3)).is_err());
        let ip_json = serde_json::to_string(&ip).unwrap();
        let impact = scenes.get("impact").unwrap();
        assert!(impact
            .verify_upload(&c, &stored("impact", ip_json, 5))
            .is_err());
    }

    #[test]
    fn sha256_is_the_standard_digest() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn another_jobs_envelope_is_refused_naming_both_jobs() {
        let (params, c, _) = good();
        let e = verify::<Sample>(&c, 8, &params, 3).unwrap_err();
        assert_eq!(e.field, "checkpoint.job_id");
        assert_eq!(e.rule, "the checkpoint belongs to job 7, not job 8");
    }

    #[test]
    fn another_jobs_bytes_are_refused() {
        let (params, c, _) = good();
        let e = refused(&c, &params, 4);
        assert_eq!(e.field, "checkpoint.data_b64");
        assert!(e.rule.contains("belongs to another job"), "{e}");
    }

    #[test]
    fn bytes_cut_short_in_transit_are_truncated() {
        let (params, c, bytes) = good();
        let cut = Checkpoint {
            data_b64: base64::engine::general_purpose::STANDARD.encode(&bytes[..100]),
            ..c.clone()
        };
        let e = refused(&cut, &params, 3);
        assert_eq!(e.field, "checkpoint.data_b64");
        assert_eq!(
            e.rule,
            format!(
                "checkpoint truncated: 100 of its {} bytes arrived",
                bytes.len()
            )
        );
        // Base64 text cut mid-quantum is not base64 at all.
        let text = Checkpoint {
            data_b64: c.data_b64[..c.data_b64.len() - 3].to_string(),
            ..c
        };
        let e = refused(&text, &params, 3);
        assert!(e.rule.contains("not base64"), "{e}");
    }

    #[test]
    fn bytes_cut_short_with_a_matching_checksum_do_not_decode() {
        let (params, _, bytes) = good();
        let cut = Checkpoint::from_bytes(7, 0, &bytes[..bytes.len() / 2]);
        let e = refused(&cut, &params, 3);
        assert_eq!(e.field, "checkpoint.data_b64");
        assert!(e.rule.starts_with("checkpoint: truncated"), "{e}");
    }

    #[test]
    fn a_flipped_byte_is_a_checksum_mismatch() {
        let (params, c, mut bytes) = good();
        let mid = bytes.len() / 2;
        bytes[mid] ^= 0x10;
        let flipped = Checkpoint {
            data_b64: base64::engine::general_purpose::STANDARD.encode(&bytes),
            ..c
        };
        let e = refused(&flipped, &params, 3);
        assert_eq!(e.field, "checkpoint.sha256");
        assert!(e.rule.starts_with("checkpoint checksum mismatch"), "{e}");
    }

    #[test]
    fn extra_bytes_wrong_sizes_and_malformed_checksums_are_refused() {
        let (params, c, mut bytes) = good();
        bytes.push(0);
        let longer = Checkpoint {
            data_b64: base64::engine::general_purpose::STANDARD.encode(&bytes),
            ..c.clone()
        };
        assert_eq!(refused(&longer, &params, 3).field, "checkpoint.size_bytes");
        let no_hex = Checkpoint {
            sha256: "xyz".into(),
            ..c.clone()
        };
        assert_eq!(refused(&no_hex, &params, 3).field, "checkpoint.sha256");
        let count = Checkpoint {
            impacts_done: 2,
            ..c
        };
        let e = refused(&count, &params, 3);
        assert_eq!(e.field, "checkpoint.impacts_done");
        assert_eq!(e.rule, "is 2 but the checkpoint holds 0 impacts");
    }
}
