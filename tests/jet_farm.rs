//! Jet campaigns on the farm (docs/jet-campaigns.md), end to end: the real `grit` binary as
//! coordinator and workers over loopback on a tiny jet scene, whose slices of 1 µs take a
//! fraction of a second. A farm's results equal `grit run`'s; a worker stopped with SIGTERM
//! and another killed with -9 leave a job that resumes, slice for slice, to the bits of an
//! unbroken run.

use std::process::Command;
use std::time::Duration;

use grit_erosion::jet::JetSlice;
use grit_farm::api::CampaignStatus;
use grit_farm::Client;
use serde_json::Value;
use uuid::Uuid;

mod common;
use common::results::{grit_run, raw_slices};
use common::{
    grit_cli, png_ok, start_coordinator, start_worker, submitter, succeeds, wait_for, Api, GRIT,
    SERIAL, SUBMIT,
};

/// The lead's tiny scene (crates/grit-erosion/tests/jet.rs): 6 particles across a 0.6 mm jet
/// on a 3 × 0.8 mm copper target, in slices of 1 µs, with `extra` fields.
fn spec(extra: &str) -> String {
    format!(
        r#"{{"scene": "jet", "name": "jet-e2e", "seed": 5, "spacing_m": 1e-4,
            "jet_width_m": 6e-4, "target_width_m": 3e-3, "target_depth_m": 8e-4,
            "standoff_m": 6e-4, "grain_diameter_m": 2e-4, "mass_flow_kg_s": 0.01,
            "slice_ms": 0.001, {extra}}}"#
    )
}

/// Waits up to 3 minutes for campaign `id` to finish as `done`.
async fn wait_done(c: &Client, id: Uuid) -> CampaignStatus {
    common::wait_done(c, id, Duration::from_secs(180)).await
}

/// Bit-for-bit equality of two sets of slices (serde_json writes every f64 so it reads back
/// bit for bit, so equal JSON is equal bits).
fn assert_same_bits(a: &[(u64, u64, Vec<JetSlice>)], b: &[(u64, u64, Vec<JetSlice>)]) {
    assert_eq!(a.len(), b.len());
    for ((ca, sa, ra), (cb, sb, rb)) in a.iter().zip(b) {
        assert_eq!((ca, sa), (cb, sb));
        assert_eq!(ra.len(), rb.len(), "cell {ca} sample {sa}: slice counts");
        for (x, y) in ra.iter().zip(rb) {
            assert_eq!(
                x.sample.mass_loss_kg_m.to_bits(),
                y.sample.mass_loss_kg_m.to_bits(),
                "slice {}",
                x.slice
            );
            assert_eq!(x.sample.t_s.to_bits(), y.sample.t_s.to_bits());
            assert_eq!(
                serde_json::to_string(x).unwrap(),
                serde_json::to_string(y).unwrap(),
                "cell {ca} sample {sa} slice {}",
                x.slice
            );
        }
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn a_jet_campaign_runs_on_the_farm_as_grit_run_runs_it() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let spec = spec(r#""samples": 2, "velocity_m_s": [400, 500], "time_ms": 0.004"#);
    let coord = start_coordinator(dir.path(), "a", "127.0.0.1:0", 30.0, &[], None);
    let api = Api::new(&coord.url);
    // The spec's rules are the API's 422s, naming the field.
    let both = spec.replace(
        r#""samples": 2,"#,
        r#""samples": 2, "pump_pressure_mpa": 100,"#,
    );
    let (status, body) = api
        .post(
            "/campaigns",
            SUBMIT,
            &serde_json::from_str::<Value>(&both).unwrap(),
        )
        .await;
    assert_eq!(
        (status, body["field"].as_str()),
        (422, Some("pump_pressure_mpa")),
        "{body}"
    );
    let id: Uuid = api.submit(&spec).await.parse().unwrap();
    let _w1 = start_worker(dir.path(), &coord.url, "w1", &[]);
    let _w2 = start_worker(dir.path(), &coord.url, "w2", &[]);
    let c = submitter(&coord.url);
    let s = wait_done(&c, id).await;
    assert_eq!(s.scene, grit_erosion::campaign::Scene::Jet);
    // Two cells of two samples of four slices: the units of progress are slices.
    assert_eq!((s.impacts_done, s.impacts_total), (16, 16));
    assert_eq!(s.cells.len(), 2);
    let farm = c.results_value(id, false).await.unwrap();
    assert_eq!(farm["scene"], "jet");
    assert_eq!(farm["partial"], false);
    assert_eq!(farm["spec"]["scene"], "jet");
    assert_eq!(farm["cells"][1]["velocity_m_s"], 500.0);
    assert_eq!(farm["cells"][1]["swept"]["velocity_m_s"], 500.0);
    assert_eq!(farm["cells"][0]["samples"], 2);
    assert_eq!(farm["cells"][0]["mean_series"].as_array().unwrap().len(), 4);
    assert!(
        farm["cells"][0]["crater_depth_m"]["mean"].is_number(),
        "{farm}"
    );
    // Four slices are far too few for the stage-3 window, and the results say so.
    assert_eq!(farm["steady"], false);
    let reason = farm["cells"][0]["stage3"]["reason"].as_str().unwrap();
    assert!(reason.contains("only 4 slices"), "{reason}");
    // The same campaign in one process gives the same results.
    let local = grit_run(dir.path(), &spec, "local", false);
    assert_eq!(farm, local, "farm results equal grit run results");
    assert!(dir.path().join("local/jet_depth_vs_time.png").exists());
    // The client commands know the scene: status counts slices, results warn on stderr.
    let id_text = id.to_string();
    let out = grit_cli(&coord.url, &["status", &id_text]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("16/16 slices"), "{stdout}");
    let out = grit_cli(&coord.url, &["results", &id_text, "--raw"]);
    assert!(out.status.success());
    let with_raw: Value = serde_json::from_slice(&out.stdout).expect("stdout stays JSON");
    let raw = raw_slices(&with_raw);
    assert_eq!(raw.len(), 4);
    assert!(raw.iter().all(|(_, _, s)| s.len() == 4));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("has no steady stage-3 slope"), "{stderr}");
    // grit plot draws the results it fetched.
    let file = dir.path().join("results.json");
    std::fs::write(&file, serde_json::to_vec(&with_raw).unwrap()).unwrap();
    let charts = dir.path().join("charts");
    succeeds(Command::new(GRIT).args([
        "plot",
        file.to_str().unwrap(),
        "--out",
        charts.to_str().unwrap(),
    ]));
    for stem in [
        "jet_profiles_c00_400_m_s",
        "jet_profiles_c01_500_m_s",
        "jet_depth_vs_time",
        "jet_width_vs_time",
        "jet_mass_loss_vs_time",
        "jet_depth_vs_speed",
    ] {
        for ext in ["png", "svg"] {
            assert!(
                charts.join(format!("{stem}.{ext}")).exists(),
                "{stem}.{ext}"
            );
        }
    }
    png_ok(&charts.join("jet_depth_vs_time.png"));
}

/// Sends SIGTERM to `w` and waits for it to exit 0.
fn terminate(w: &mut common::Proc) {
    w.signal("TERM");
    let code = w.wait_exit();
    assert!(code.success(), "exit status {code:?}");
}

#[tokio::test(flavor = "multi_thread")]
async fn a_stopped_and_a_killed_worker_leave_a_jet_job_that_resumes_bit_for_bit() {
    let _g = SERIAL.lock().await;
    let dir = tempfile::tempdir().unwrap();
    // One job of 30 slices: long enough to stop and kill mid-run.
    let spec = spec(r#""samples": 1, "time_ms": 0.03"#);
    let total = 30;
    let coord = start_coordinator(dir.path(), "a", "127.0.0.1:0", 2.0, &[], None);
    let c = submitter(&coord.url);
    let id = c.submit(&spec, None).await.unwrap().id;
    let done = |n: u64| {
        let c = &c;
        async move {
            wait_for(
                Duration::from_secs(120),
                "slices",
                || c.status(id),
                |s| s.impacts_done >= n,
            )
            .await
            .impacts_done
        }
    };
    // SIGTERM: the job goes back with the checkpoint after its last finished slice.
    let mut w1 = start_worker(dir.path(), &coord.url, "w1", &[]);
    let first = done(2).await;
    terminate(&mut w1);
    assert!(w1.log_text().contains("job released"), "{}", w1.log_text());
    let s = c.status(id).await.unwrap();
    assert!(
        s.impacts_done < total,
        "the job must still be running when stopped"
    );
    assert_eq!(
        (s.jobs.queued, s.jobs.leased),
        (1, 0),
        "back in the queue at once"
    );
    // kill -9: the lease expires and the next worker resumes from the last checkpoint.
    let mut w2 = start_worker(dir.path(), &coord.url, "w2", &[]);
    done(s.impacts_done.max(first) + 2).await;
    w2.kill9();
    assert!(
        w2.log_text().contains("resumed from checkpoint"),
        "{}",
        w2.log_text()
    );
    let killed = c.status(id).await.unwrap();
    assert!(
        killed.impacts_done < total,
        "the job must still be running when killed"
    );
    let w3 = start_worker(dir.path(), &coord.url, "w3", &[]);
    wait_done(&c, id).await;
    assert!(
        w3.log_text().contains("resumed from checkpoint"),
        "{}",
        w3.log_text()
    );
    let farm = raw_slices(&c.results_value(id, true).await.unwrap());
    assert_eq!(farm[0].2.len(), total as usize);
    let local = raw_slices(&grit_run(dir.path(), &spec, "local", true));
    assert_same_bits(&farm, &local);
}
