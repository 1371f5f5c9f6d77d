//! The results endpoint's JSON, byte for byte, for databases of either scene: the schema 5
//! databases of tests/data/schema5 (real runs, part done) and an impact campaign whose cells
//! grew in impacts and samples. The digests were taken from the store before results went
//! through the scenes (issue 41), so any change to the bytes served shows here. The schema 5
//! databases' digests belong to their files (how they were written: tests/old_databases.rs):
//! when the files are rewritten, the old files must still give the old digests with today's
//! code before the new files' digests replace them, so the bytes served are seen not to move.

use std::path::Path;
use std::time::Duration;

use sha2::{Digest, Sha256};

use super::{imp, impact_params, Store};
use crate::loadtest::placeholder_record;

/// SHA-256 (hex) of the results JSON of the one campaign in `s`, with and without `raw`.
async fn digests(s: &Store) -> [String; 2] {
    let id = s.list_campaigns().await.unwrap()[0].id;
    let mut out = [String::new(), String::new()];
    for (i, raw) in [false, true].into_iter().enumerate() {
        let json = s.results_json(id, raw).await.unwrap();
        out[i] = format!("{:x}", Sha256::digest(json.as_bytes()));
    }
    out
}

/// The store of schema 5 database `name`, copied into `dir` and migrated.
async fn schema5(dir: &Path, name: &str) -> Store {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/schema5");
    std::fs::copy(data.join(format!("{name}.db")), dir.join("t.db")).unwrap();
    Store::open(&dir.join("t.db"), Duration::from_secs(60), 2)
        .await
        .unwrap()
}

#[tokio::test]
async fn schema5_results_keep_their_bytes() {
    for (name, want) in [
        (
            "impact",
            [
                "71eacf95448aba5fa5d38b8452072c2d8a7c70035b97b346ddbb98d303586ea5",
                "61a06d88e7ebaf3782987f9eb33adc0f099562dfce4eb49e30f6cb450d139c2f",
            ],
        ),
        (
            "jet",
            [
                "71d535f4d4396d78e4ba3405ab8be78140a48a11339e690ef4a9ccc9b7e90e49",
                "dfca1a81342a79ae3f03eb63c4c7125faf6bcb5e535dd010224abbe70d401bfd",
            ],
        ),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let s = schema5(dir.path(), name).await;
        assert_eq!(digests(&s).await, want.map(String::from), "{name}");
    }
}

#[tokio::test]
async fn grown_cells_results_keep_their_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let s = Store::open(&dir.path().join("t.db"), Duration::from_secs(60), 2)
        .await
        .unwrap();
    let spec = grit_erosion::campaign::AnySpec::from_json(
        r#"{"seed": 9, "angles_deg": [45, 90], "shapes": ["hexagon"], "spacing_m": 25e-6,
            "impacts": {"until_steady": {"min": 21, "max": 29, "step": 4}},
            "samples": {"target_sem_rel": 0.05, "min": 2, "max": 4}}"#,
    )
    .unwrap();
    let id = s.create(&spec, None).await.unwrap().id;
    while let Some(j) = s.claim("w").await.unwrap() {
        let grain = impact_params(&j).grain_mass_kg_m();
        let recs: Vec<_> = (j.impacts_done + 1..=j.impacts_planned)
            .map(|k| {
                let loss = 0.01 * (1 + j.sample + j.cell) as f64 * (k % 5) as f64;
                placeholder_record(k, grain, loss * grain)
            })
            .collect();
        let ckpt = j
            .extendable
            .then(|| crate::checkpoint::CheckpointBytes::new(j.impacts_planned, vec![0; 3]));
        s.complete(j.job_id, j.lease_id, imp(&recs).with_checkpoint(ckpt))
            .await
            .unwrap();
    }
    let cells = s.status(id).await.unwrap().cells;
    assert!(
        cells.iter().any(|c| c.impacts_total > 2 * 21) && cells.iter().any(|c| c.samples_total > 2),
        "the cells grew in impacts and in samples: {cells:?}"
    );
    assert_eq!(
        digests(&s).await,
        [
            "e1b904977786968df4cbf8b37e86e928050b404e92d99f66662afc6a23ac0b77",
            "71b4b7552808d07910938a990cda1d008258869b8bd87d2a94575ae4e8834c68",
        ]
        .map(String::from)
    );
}
