//! The store's side of jet jobs, without HTTP or simulation: a jet claim carries the run, its
//! slices are stored in order like impacts (repeats skipped, gaps refused), a jet job takes no
//! impacts and an impact job no slices, and completion needs every slice.

use std::time::Duration;

use grit_erosion::campaign::{AnySpec, Scene};
use grit_erosion::jet::JetSlice;
use grit_sph::crater::CraterSample;

use super::{imp, jet as slices, Reported, Store};
use crate::api::AnyResults;
use crate::error::Error;

const JET: &str = r#"{"scene": "jet", "samples": 1, "velocity_m_s": [400, 500],
    "spacing_m": 1e-4, "jet_width_m": 6e-4, "target_width_m": 3e-3, "target_depth_m": 8e-4,
    "standoff_m": 6e-4, "grain_diameter_m": 2e-4, "time_ms": 0.003, "slice_ms": 0.001}"#;

/// Slice `k` of a made-up run: time k µs, a crater k × 10 µm deep.
fn slice(k: u32) -> JetSlice {
    JetSlice {
        slice: k,
        sample: CraterSample {
            t_s: k as f64 * 1e-6,
            mass_loss_kg_m: 0.0,
            crater_depth_m: k as f64 * 1e-5,
            crater_width_m: 0.0,
            max_plastic_strain: 0.1,
        },
        half_depth_width_m: 0.0,
        profile: vec![[-1e-3, -0.5e-4], [1e-3, -0.5e-4]],
        steps: 10,
        particles: 100,
        grains: 0,
        grains_fed: 0,
        water_deleted_kg_m: 0.0,
        water_fed_kg_m: 0.0,
        wall_s: 0.1,
        grain_hits: None,
        rock: None,
    }
}

fn field(e: Error) -> String {
    match e {
        Error::Invalid { field, .. } => field,
        other => panic!("expected a 422, got {other}"),
    }
}

#[tokio::test]
async fn jet_jobs_store_slices_in_order_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let s = Store::open(&dir.path().join("t.db"), Duration::from_secs(60), 2)
        .await
        .unwrap();
    let spec = AnySpec::from_json(JET).unwrap();
    let created = s.create(&spec, Some("k")).await.unwrap();
    assert_eq!((created.jobs, created.impacts_total), (2, 6));
    let again = s.create(&spec, Some("k")).await.unwrap();
    assert!(
        !again.created,
        "the idempotency key holds for jet specs too"
    );
    let list = s.list_campaigns().await.unwrap();
    assert_eq!(list[0].scene, Scene::Jet);
    let j = s.claim("w").await.unwrap().unwrap();
    assert_eq!(j.scene, "jet", "a jet claim names its scene");
    let jet: grit_erosion::jet::JetParams = serde_json::from_value(j.params.clone()).unwrap();
    assert_eq!((jet.velocity_m_s, j.impacts_planned), (400.0, 3));
    // Slices continue the stored series; repeats are skipped, gaps refused.
    let beat = |recs: Vec<JetSlice>| {
        let s = &s;
        let j = &j;
        async move { s.heartbeat(j.job_id, j.lease_id, slices(&recs)).await }
    };
    assert_eq!(beat(vec![slice(1)]).await.unwrap().impacts_done, 1);
    assert_eq!(
        beat(vec![slice(1), slice(2)]).await.unwrap().impacts_done,
        2
    );
    assert_eq!(
        field(beat(vec![slice(4)]).await.unwrap_err()),
        "units[0].slice"
    );
    let mut bad = slice(3);
    bad.sample.t_s = f64::NAN;
    assert_eq!(
        field(beat(vec![bad]).await.unwrap_err()),
        "units[0].sample.t_s"
    );
    // Past the run's time and a slice (3 µs + 1 µs), or more mass than the target holds.
    let mut late = slice(3);
    late.sample.t_s = 4.1e-6;
    assert_eq!(
        field(beat(vec![late]).await.unwrap_err()),
        "units[0].sample.t_s"
    );
    let mut heavy = slice(3);
    heavy.sample.mass_loss_kg_m = 1e307;
    assert_eq!(
        field(beat(vec![heavy]).await.unwrap_err()),
        "units[0].sample.mass_loss_kg_m"
    );
    let impacts = s
        .heartbeat(j.job_id, j.lease_id, imp(&[placeholder()]))
        .await;
    assert_eq!(field(impacts.unwrap_err()), "units");
    let early = s.complete(j.job_id, j.lease_id, Reported::none()).await;
    assert_eq!(field(early.unwrap_err()), "units");
    s.complete(j.job_id, j.lease_id, slices(&[slice(3)]))
        .await
        .unwrap();
    let status = s.status(created.id).await.unwrap();
    assert_eq!((status.impacts_done, status.scene), (3, Scene::Jet));
    let AnyResults::Jet(r) = s.results_any(created.id, true).await.unwrap() else {
        panic!("jet results expected");
    };
    assert!(r.results.partial, "one of two cells is done");
    assert_eq!(r.results.cells[0].samples, 1);
    let cd = r.results.cells[0].crater_depth_m.unwrap();
    assert_eq!(
        cd.mean,
        3.0 * 1e-5,
        "the one sample's depth at its last slice"
    );
    assert_eq!(r.raw.unwrap()[0].slices.len(), 3);
}

#[tokio::test]
async fn an_impact_job_takes_no_slices() {
    let dir = tempfile::tempdir().unwrap();
    let s = Store::open(&dir.path().join("t.db"), Duration::from_secs(60), 2)
        .await
        .unwrap();
    let spec = AnySpec::from_json(
        r#"{"angles_deg": [90], "shapes": ["hexagon"], "samples": 1, "impacts": 2,
            "allow_short_samples": true, "spacing_m": 25e-6}"#,
    )
    .unwrap();
    s.create(&spec, None).await.unwrap();
    let j = s.claim("w").await.unwrap().unwrap();
    assert_eq!(j.scene, "impact");
    let wire = serde_json::to_value(&j).unwrap();
    assert!(
        wire["params"].is_object() && wire["scene"] == "impact",
        "{wire}"
    );
    let e = s
        .heartbeat(j.job_id, j.lease_id, slices(&[slice(1)]))
        .await
        .unwrap_err();
    assert_eq!(field(e), "units");
}

fn placeholder() -> grit_erosion::ImpactRecord {
    crate::loadtest::placeholder_record(1, 1e-6, 0.0)
}
