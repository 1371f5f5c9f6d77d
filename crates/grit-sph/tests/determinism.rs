//! Determinism contract: the same scene gives bitwise the same positions, stresses and damage on
//! 1 thread and on 2 (docs/design.md#rules-the-engine-keeps).

use grit_sph::verification::elastic_impact;
use grit_sph::{Settings, World};

/// The elastic impact at 16 particles per side after 600 steps.
fn run(threads: usize) -> World {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut w = elastic_impact::scene(16, Settings::default());
        for _ in 0..600 {
            w.step().unwrap();
        }
        w
    })
}

fn bits(w: &World) -> (Vec<u64>, Vec<u64>, Vec<u64>) {
    let p = w.particles();
    let pos = p
        .pos
        .iter()
        .flat_map(|x| [x.x.to_bits(), x.y.to_bits()])
        .collect();
    let s = p
        .sdev
        .iter()
        .flat_map(|m| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>())
        .collect();
    let d = p.damage.iter().chain(&p.rho).map(|v| v.to_bits()).collect();
    (pos, s, d)
}

#[test]
fn one_and_two_threads_give_identical_bits() {
    let a = bits(&run(1));
    let b = bits(&run(2));
    assert_eq!(a.0, b.0, "positions differ");
    assert_eq!(a.1, b.1, "stresses differ");
    assert_eq!(a.2, b.2, "damage or density differ");
}
