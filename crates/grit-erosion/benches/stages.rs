//! Criterion bench of the engine's hot loops (issue 5) on the reference impact scene (seed
//! section 4: hexagon, 45°, 100 m/s, AISI 304) caught mid-contact: neighbour search, kernel
//! sums (eqs. 8–9), velocity gradient (eq. 15), stress update (eqs. 11, 13, 18–20), forces
//! (eqs. 6, 16) and contact (eqs. 21–29). `cargo bench -p grit-erosion --bench stages`.

// criterion_group! defines an undocumented function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use grit_erosion::impact::impact_world;
use grit_erosion::{ImpactParams, Shape};
use grit_sph::{Stage, World};

/// The impact scene at `spacing_m`, stepped until the grain has pressed into the surface for
/// `contact_steps` steps.
fn mid_contact(spacing_m: f64, contact_steps: u32) -> World {
    let params = ImpactParams {
        spacing_m,
        ..ImpactParams::paper(45.0, Shape::Hexagon)
    };
    let surface = params.fresh_surface().expect("valid scene");
    let grain = params.grain_start(0.3, 0.5).expect("valid grain");
    let mut w = impact_world(&params, &surface, &grain).expect("valid scene");
    let mut touching = 0;
    while touching < contact_steps {
        w.step().expect("stable");
        if w.contact_forces().iter().any(|f| f.norm() > 0.0) {
            touching += 1;
        }
    }
    w
}

fn stages(c: &mut Criterion) {
    let stages = [
        ("neighbours", Stage::Neighbours),
        ("kernel_sums", Stage::KernelSums),
        ("rates", Stage::Rates),
        ("stress", Stage::Stress),
        ("forces", Stage::Forces),
        ("contact", Stage::Contact),
    ];
    for (label, spacing) in [("16um", 16e-6), ("8um", 8e-6)] {
        let mut w = mid_contact(spacing, 100);
        // Fills the caches the later stages read, so every stage is timed on its own.
        w.run_stage(Stage::Rates).expect("a step stage");
        let mut group = c.benchmark_group(format!("stage_{label}_{}p", w.particles().len()));
        group.sample_size(20);
        for (name, stage) in stages {
            // A fresh copy per batch: the stress stage changes the state it reads.
            group.bench_function(name, |b| {
                b.iter_batched_ref(
                    || w.clone(),
                    |w| w.run_stage(stage).expect("a step stage"),
                    BatchSize::LargeInput,
                )
            });
        }
        group.bench_function("full_step", |b| {
            b.iter_batched_ref(
                || w.clone(),
                |w| w.step().expect("stable"),
                BatchSize::LargeInput,
            )
        });
        group.finish();
    }
}

criterion_group!(benches, stages);
criterion_main!(benches);
