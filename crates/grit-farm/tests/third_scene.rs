//! A scene the farm has never heard of runs on it unchanged: a coordinator (the library's
//! `app`) and a worker (`worker::run_scenes`), both given a scene set that adds a toy scene
//! to grit's own, store, lease, check, resume and complete its jobs through the same code
//! paths as impacts and jet slices. Nothing in grit-farm names the toy scene.

use std::time::Duration;

use grit_erosion::campaign::{results_json, CampaignPlan, CellRecords, PlannedCell, StoredJob};
use grit_erosion::{Scene, SceneError, SceneSet, SceneVisitor, Scenes};
use grit_farm::api::CampaignState;
use grit_farm::db::Reported;
use grit_farm::scenes::SceneRegistry;
use grit_farm::worker::{run_scenes, Stop, WorkerOptions};
use grit_farm::{app, AppState, Client, Config, Secret, Store};
use grit_sph::InputError;
use serde::{Deserialize, Serialize};

/// A toy scene: unit k of a run loses `rate · (1 + (seed + k) mod 3)` kg/m.
struct Drip {
    params: DripParams,
    seed: u64,
    records: Vec<Drop>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct DripParams {
    rate: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Drop {
    drop: u32,
    loss: f64,
}

impl Scene for Drip {
    const KIND: &'static str = "drip";
    const UNIT: &'static str = "drop";
    const CHECKPOINT_EACH_UNIT: bool = false;
    type Params = DripParams;
    type Record = Drop;

    fn engine() -> Result<String, SceneError> {
        // A toy scene's bits do not depend on the engine; a fixed fingerprint stands for it.
        Ok("d1d1d1d1d1d1d1d1".into())
    }

    fn start(params: &DripParams, seed: u64) -> Result<Self, SceneError> {
        Ok(Drip {
            params: params.clone(),
            seed,
            records: Vec::new(),
        })
    }

    fn resume(params: &DripParams, seed: u64, bytes: &[u8]) -> Result<Self, SceneError> {
        let (s, records): (u64, Vec<Drop>) = serde_json::from_slice(bytes)
            .map_err(|e| SceneError::Checkpoint(format!("checkpoint: {e}")))?;
        if s != seed {
            return Err(SceneError::Checkpoint("checkpoint: another run's".into()));
        }
        Ok(Drip {
            params: params.clone(),
            seed,
            records,
        })
    }

    fn checkpoint(&self) -> Vec<u8> {
        serde_json::to_vec(&(self.seed, &self.records)).unwrap()
    }

    fn units_done(&self) -> u32 {
        self.records.len() as u32
    }

    fn records(&self) -> Vec<Drop> {
        self.records.clone()
    }

    fn unit_of(record: &Drop) -> u32 {
        record.drop
    }

    fn run_next(&mut self, _cancel: &dyn Fn() -> bool) -> Result<Option<Drop>, SceneError> {
        let k = self.records.len() as u64 + 1;
        let rec = Drop {
            drop: k as u32,
            loss: self.params.rate * (1 + (self.seed + k) % 3) as f64,
        };
        self.records.push(rec.clone());
        Ok(Some(rec))
    }

    fn check_record(
        params: &DripParams,
        record: &Drop,
        lost_before_kg_m: f64,
    ) -> Result<f64, InputError> {
        if !(record.loss >= 0.0 && record.loss <= 3.0 * params.rate) {
            return Err(InputError::new("loss", "must be in [0, 3 rate]"));
        }
        Ok(lost_before_kg_m + record.loss)
    }

    /// Each cell's index and its samples' total losses.
    fn results(
        _spec: &str,
        cells: Vec<CellRecords<Drop>>,
        raw: Option<Vec<StoredJob<Drop>>>,
    ) -> Result<String, SceneError> {
        let totals: Vec<(u32, Vec<f64>)> = cells
            .iter()
            .map(|c| {
                let lost = c.samples.values().map(|d| d.iter().map(|x| x.loss).sum());
                (c.cell.index, lost.collect())
            })
            .collect();
        results_json::<Drip, _>(&serde_json::json!({ "cells": totals }), raw.as_deref())
    }
}

/// grit's scenes and the drip.
struct WithDrip;

impl SceneSet for WithDrip {
    fn kinds() -> &'static [&'static str] {
        &["impact", "jet", Drip::KIND]
    }

    fn visit<V: SceneVisitor>(kind: &str, v: V) -> Option<V::Output> {
        if kind == Drip::KIND {
            Some(v.visit::<Drip>())
        } else {
            Scenes::visit(kind, v)
        }
    }
}

/// Two cells of three samples of `units` drops each.
fn plan(units: u32) -> CampaignPlan {
    let cells: Vec<PlannedCell> = [1e-6, 2e-6]
        .iter()
        .enumerate()
        .map(|(i, rate)| PlannedCell {
            index: i as u32,
            angle_deg: None,
            shape: None,
            swept: [("rate".to_string(), *rate)].into(),
            units,
            params: serde_json::to_string(&DripParams { rate: *rate }).unwrap(),
            until_steady: None,
        })
        .collect();
    let jobs: Vec<_> = cells
        .iter()
        .flat_map(|c| (0..3).map(move |s| (c.index, s, units, 10 * c.index as u64 + s as u64)))
        .collect();
    CampaignPlan {
        kind: Drip::KIND,
        samples: 3,
        target_sem: None,
        units_total: jobs.len() as u64 * units as u64,
        cells,
        jobs,
        queue: grit_erosion::campaign::QueueOrder::Rounds,
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_scene_the_farm_does_not_name_runs_on_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut store = Store::open(&dir.path().join("farm.db"), Duration::from_secs(30), 3)
        .await
        .unwrap();
    store.scenes = SceneRegistry::of::<WithDrip>();
    let created = store
        .create_planned(&plan(7), r#"{"scene": "drip"}"#, Some("drip"), None, None)
        .await
        .unwrap();
    assert_eq!((created.jobs, created.impacts_total), (6, 42));

    let state = AppState {
        store: store.clone(),
        config: std::sync::Arc::new(Config::default()),
        told: Default::default(),
    };
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let url = format!("http://{}", listener.local_addr().unwrap());
    tokio::spawn(async move { axum::serve(listener, app(state)).await });

    let client = Client::new(&url, Secret::new(None)).unwrap();
    let opts = |name: &str| WorkerOptions {
        name: name.into(),
        threads: Some(1),
        checkpoint_every: 2,
        exit_when_idle: true,
        ..WorkerOptions::default()
    };
    // The drip worker runs every job through the farm's one path: claim, heartbeats with
    // units and checkpoints, complete.
    let summary = run_scenes::<WithDrip>(client.clone(), opts("drip"), Stop::default())
        .await
        .unwrap();
    assert_eq!((summary.jobs_done, summary.units), (6, 42));
    let status = store.status(created.id).await.unwrap();
    assert_eq!(status.state, CampaignState::Done);
    assert_eq!((status.impacts_done, status.impacts_total), (42, 42));
    for c in &status.cells {
        assert_eq!((c.angle_deg, c.shape.as_deref()), (None, None));
        assert_eq!(c.samples_done, 3);
    }
    // Its results are the scene's own, served through the farm's one results path.
    let results = client.results_value(created.id, true).await.unwrap();
    assert_eq!(results["cells"][1][0], 1, "{results}");
    assert_eq!(results["cells"][1][1].as_array().unwrap().len(), 3);
    assert_eq!(results["raw"][5]["units"].as_array().unwrap().len(), 7);

    // The scene's own rule on its records holds on the farm, the field named as a unit's.
    let second = store
        .create_planned(&plan(2), r#"{"scene": "drip", "n": 2}"#, None, None, None)
        .await
        .unwrap();
    let job = store
        .claim("hand")
        .await
        .unwrap()
        .expect("a queued drip job");
    assert_eq!(job.scene, "drip");
    let bad = Drop { drop: 1, loss: 1.0 };
    let e = store
        .heartbeat(
            job.job_id,
            job.lease_id,
            Reported::of::<Drip>(&[bad]).unwrap(),
        )
        .await
        .unwrap_err();
    assert!(
        matches!(&e, grit_farm::Error::Invalid { field, .. } if field == "units[0].loss"),
        "{e:?}"
    );

    // A worker without the drip fails the job it cannot run, naming the scene.
    let plain = grit_farm::worker::run(client, opts("plain"), Stop::default())
        .await
        .unwrap();
    assert_eq!(plain.jobs_done, 0);
    let jobs = store.jobs(second.id, None, 10).await.unwrap();
    assert!(
        jobs.iter().any(|j| j
            .last_error
            .as_deref()
            .is_some_and(|e| e.contains("not \"drip\""))),
        "{jobs:?}"
    );
}
