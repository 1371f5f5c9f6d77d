//! Helpers shared by the fluid and state tests: a world stepped on a given number of threads,
//! the bits of its flow state for the thread-count determinism contract (docs/design.md), and
//! a lattice of particle positions. Each test file uses some of them.
#![allow(dead_code)]

use grit_sph::{Fluid, Material, Vector, World};

/// Cell centres of an `nx` × `ny` lattice of spacing `dx` whose lower left corner is `origin`.
pub fn lattice(dx: f64, nx: usize, ny: usize, origin: Vector) -> Vec<Vector> {
    let mut pts = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            pts.push(origin + Vector::new((i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx));
        }
    }
    pts
}

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

/// A 20 × 8 copper block below the surface line y = 0 and a 12-wide block of `rows` rows of
/// water on it, moving at `vel`, on a lattice of spacing `dx`; returns the water's body.
pub fn copper_under_water(w: &mut World, dx: f64, rows: usize, vel: Vector) -> usize {
    let target = lattice(dx, 20, 8, Vector::new(0.0, -8.0 * dx));
    let vols = vec![dx * dx; target.len()];
    w.add_deformable(
        "target",
        Material::copper(),
        &target,
        &vols,
        Vector::zeros(),
    )
    .unwrap();
    let water = lattice(dx, 12, rows, Vector::new(4.0 * dx, 0.0));
    let (vols, pres) = (vec![dx * dx; water.len()], vec![0.0; water.len()]);
    w.add_fluid("water", Fluid::water(), &water, &vols, &pres, vel)
        .unwrap()
}
