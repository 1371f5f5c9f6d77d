//! Group commit: requests applied together in one transaction answer as each would alone,
//! and a refused one leaves nothing behind without failing the others.

use std::time::Duration;

use axum::http::StatusCode;
use grit_erosion::campaign::CampaignSpec;
use grit_erosion::ImpactRecord;
use uuid::Uuid;

use super::{imp, Store};

/// Impact `k` of a sample of the campaign below (default grain), losing a little.
fn record(k: u32) -> ImpactRecord {
    let grain = grit_erosion::ImpactParams::default().grain_mass_kg_m();
    crate::loadtest::placeholder_record(k, grain, 1e-6)
}

#[tokio::test]
async fn a_refused_request_in_a_group_leaves_nothing_and_fails_no_other() {
    let dir = tempfile::tempdir().unwrap();
    let s = Store::open(&dir.path().join("t.db"), Duration::from_secs(60), 2)
        .await
        .unwrap();
    let spec = CampaignSpec::from_json(
        r#"{"angles_deg": [90], "shapes": ["hexagon"], "samples": 3, "impacts": 2,
            "allow_short_samples": true, "spacing_m": 25e-6}"#,
    )
    .unwrap();
    s.create_campaign(&spec, None).await.unwrap();
    let a = s.claim("a").await.unwrap().unwrap();
    let b = s.claim("b").await.unwrap().unwrap();
    let (with_gap, one, both) = ([record(1), record(3)], [record(1)], [record(1), record(2)]);
    // The test runtime has one thread: all four are queued before the writer runs, so they
    // are applied in one group, in this order.
    let (gap, stale, good, claimed) = tokio::join!(
        // Impact 1 comes before the gap: nothing of the refused heartbeat may stay.
        s.heartbeat(a.job_id, a.lease_id, imp(&with_gap)),
        s.heartbeat(b.job_id, Uuid::new_v4(), imp(&one)),
        s.complete(b.job_id, b.lease_id, imp(&both)),
        s.claim("c"),
    );
    assert_eq!(gap.unwrap_err().status(), StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(stale.unwrap_err().status(), StatusCode::CONFLICT);
    good.unwrap();
    let c = claimed.unwrap().unwrap();
    assert_ne!(c.job_id, a.job_id);
    assert_ne!(c.job_id, b.job_id);
    let stored: i64 = sqlx::query_scalar("SELECT COUNT(*) FROM units WHERE job_id = ?")
        .bind(a.job_id)
        .fetch_one(&s.read)
        .await
        .unwrap();
    assert_eq!(stored, 0, "nothing of the refused heartbeat stays");
    let late = s
        .heartbeat(b.job_id, b.lease_id, imp(&[]))
        .await
        .unwrap_err();
    assert_eq!(
        late.status(),
        StatusCode::CONFLICT,
        "the completion committed"
    );
}
