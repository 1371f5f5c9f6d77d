//! Criterion bench of the engine's hot loops on the reference impact scene (seed
//! section 4: hexagon, 45°, 100 m/s, AISI 304) caught mid-contact: neighbour search, kernel
//! sums with the velocity gradient (eqs. 8–9, 15), stress update (eqs. 11, 13, 18–20), forces
//! (eqs. 6, 16) and contact (eqs. 21–29). `cargo bench -p grit-erosion --bench stages`.

// criterion_group! defines an undocumented function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use grit_erosion::impact::mid_contact_world;
use grit_sph::Stage;

fn stages(c: &mut Criterion) {
    let stages = [
        ("neighbours", Stage::Neighbours),
        ("kernel_sums", Stage::KernelSums),
        ("stress", Stage::Stress),
        ("forces", Stage::Forces),
        ("contact", Stage::Contact),
    ];
    for (label, spacing) in [("16um", 16e-6), ("8um", 8e-6)] {
        let mut w = mid_contact_world(spacing, 100).expect("a stable scene");
        // Fills the caches the later stages read, so every stage is timed on its own.
        w.run_stage(Stage::KernelSums).expect("a step stage");
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
