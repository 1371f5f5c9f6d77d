//! A farm database written before every scene's units shared one table (schema 5: impacts and
//! jet slices in tables of their own, jet cells with the placeholders angle 90 and shape
//! 'jet') opens with today's binary, is migrated, and its campaign resumes from the stored
//! units and checkpoints to the very bits an uninterrupted run of today's binary gives.
//!
//! The two databases in tests/data/schema5 were written by the binary of commit 58f8f9b with
//! today's radial return (7ee7c32's, which moved the engine's bits) put in operation for
//! operation (`58f8f9b-radial-return-7ee7c32.diff` there): `grit run SPEC --out DIR --workers 1
//! --threads 1`, stopped with SIGINT once the database held 10 impacts or 6 slices: an impact
//! campaign with one sample done and one released after 4 of 6 impacts with its checkpoint, and
//! a jet campaign with one run done and one released after 2 of 4 slices.

use std::path::Path;

mod common;
use common::results::{assert_bitwise_equal, grit_run, raw_series, raw_slices};

/// The stored spec and database `name` of tests/data/schema5, the database copied into
/// `dir/old` as that run folder's grit.db.
fn old_run(dir: &Path, name: &str) -> String {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/schema5");
    std::fs::create_dir_all(dir.join("old")).unwrap();
    std::fs::copy(
        data.join(format!("{name}.db")),
        dir.join("old").join("grit.db"),
    )
    .unwrap();
    std::fs::read_to_string(data.join(format!("{name}.json"))).unwrap()
}

/// The jobs of the one campaign in `dir/old`'s database, as (state, units done, last
/// change in Unix ms), read through the store after the migration.
fn stored_jobs(dir: &Path) -> Vec<(String, u32, i64)> {
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async {
        let store = grit_farm::Store::open(
            &dir.join("old").join("grit.db"),
            std::time::Duration::from_secs(60),
            3,
        )
        .await
        .unwrap();
        let campaigns = store.list_campaigns().await.unwrap();
        assert_eq!(
            campaigns.len(),
            1,
            "the old campaign, resumed, not a second one"
        );
        store
            .jobs(campaigns[0].id, None, 100)
            .await
            .unwrap()
            .into_iter()
            .map(|j| (format!("{:?}", j.state), j.impacts_done, j.updated_ms))
            .collect()
    })
}

/// Now, in Unix ms.
fn now_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_millis() as i64
}

/// Both jobs are done with `units` each, and the first, done in the stored database, did not
/// run again after `start_ms`.
fn first_job_kept(dir: &Path, units: u32, start_ms: i64) {
    let jobs = stored_jobs(dir);
    assert_eq!(jobs.len(), 2);
    assert_eq!((jobs[0].0.as_str(), jobs[0].1), ("Done", units));
    assert!(
        jobs[0].2 < start_ms,
        "the stored done job ran again: {jobs:?}"
    );
    assert_eq!((jobs[1].0.as_str(), jobs[1].1), ("Done", units));
}

#[test]
fn an_impact_campaign_stored_by_schema_5_resumes_to_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    let spec = old_run(dir.path(), "impact");
    let start_ms = now_ms();
    let resumed = grit_run(dir.path(), &spec, "old", true);
    let fresh = grit_run(dir.path(), &spec, "fresh", true);
    assert_bitwise_equal(&raw_series(&resumed), &raw_series(&fresh));
    assert_eq!(
        raw_series(&resumed)
            .iter()
            .map(|s| s.2.len())
            .sum::<usize>(),
        12
    );
    first_job_kept(dir.path(), 6, start_ms);
}

#[test]
fn a_jet_campaign_stored_by_schema_5_resumes_to_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    let spec = old_run(dir.path(), "jet");
    let start_ms = now_ms();
    let resumed = grit_run(dir.path(), &spec, "old", true);
    let fresh = grit_run(dir.path(), &spec, "fresh", true);
    let (a, b) = (raw_slices(&resumed), raw_slices(&fresh));
    assert_eq!(a, b, "resumed and fresh jet runs differ");
    assert_eq!(a.iter().map(|s| s.2.len()).sum::<usize>(), 8);
    first_job_kept(dir.path(), 4, start_ms);
}
