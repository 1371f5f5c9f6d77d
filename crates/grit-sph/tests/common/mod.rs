//! Helpers shared by the fluid tests: a world stepped on a given number of threads, and the
//! bits of its flow state for the thread-count determinism contract (docs/design.md).

use grit_sph::World;

/// `world` stepped `steps` times inside a rayon pool of `threads` threads.
pub fn stepped_on(threads: usize, steps: usize, world: impl FnOnce() -> World + Send) -> World {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut w = world();
        for _ in 0..steps {
            w.step().unwrap();
        }
        w
    })
}

/// The bits of every particle's position, velocity, density and internal energy, and of the
/// next step.
pub fn flow_bits(w: &World) -> Vec<u64> {
    let p = w.particles();
    p.pos
        .iter()
        .chain(&p.vel)
        .flat_map(|x| [x.x.to_bits(), x.y.to_bits()])
        .chain(p.rho.iter().chain(&p.energy).map(|r| r.to_bits()))
        .chain([w.dt().to_bits()])
        .collect()
}
