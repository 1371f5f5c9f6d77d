//! The density filters (eq. 12 and its first-order MLS form): both remove particle-scale
//! noise; only MLS leaves a linear density field alone, at the free surface too, which is why
//! it takes less energy out of resolved elastic waves (docs/verification.md, case 6).

use grit_sph::{DensityFilter, Material, Motion, Polygon, Settings, Vector, World};

const DX: f64 = 1e-3;

/// A free 20 × 12 block whose density is set by `rho(i, x, y)` (index and position).
fn block(filter: DensityFilter, rho: impl Fn(usize, f64, f64) -> f64) -> World {
    let settings = Settings {
        spacing_m: DX,
        density_filter: filter,
        ..Default::default()
    };
    let poly = Polygon::rectangle(0.0, 0.0, 20.0 * DX, 12.0 * DX);
    let mut w = World::new(settings.clone()).unwrap();
    let m = Material::elastic_aluminium();
    w.add_deformable_polygon(
        "block",
        m.clone(),
        &poly,
        Vector::new(0.5 * DX, 0.5 * DX),
        Vector::zeros(),
    )
    .unwrap();
    let mut state = w.body_state(0);
    for i in 0..state.len() {
        let r = rho(i, state.pos[i].x, state.pos[i].y);
        state.mass[i] *= r / state.rho[i];
        state.rho[i] = r;
    }
    let mut w = World::new(settings).unwrap();
    w.add_deformable_state("block", m, state, Motion::Free)
        .unwrap();
    w
}

/// Largest |ρ_filtered − ρ_expected| / ρ0 over the particles.
fn worst(w: &World, expected: impl Fn(usize, f64, f64) -> f64) -> f64 {
    let p = w.particles();
    (0..p.len())
        .map(|i| (p.rho[i] - expected(i, p.pos[i].x, p.pos[i].y)).abs() / 2700.0)
        .fold(0.0, f64::max)
}

#[test]
fn mls_keeps_a_linear_density_field_and_shepard_flattens_it_at_the_surface() {
    // A 1 % density gradient across the block, as an elastic wave of the block's size makes.
    let linear = |_: usize, x: f64, y: f64| 2700.0 * (1.0 + 0.01 * (x + 0.5 * y) / (20.0 * DX));
    let mut mls = block(DensityFilter::Mls, linear);
    let mut shepard = block(DensityFilter::Shepard, linear);
    mls.filter_density();
    shepard.filter_density();
    let (e_mls, e_shepard) = (worst(&mls, linear), worst(&shepard, linear));
    assert!(e_mls < 1e-10, "MLS moved a linear field by {e_mls:e}");
    assert!(e_shepard > 1e-4, "Shepard error {e_shepard:e}");
}

#[test]
fn both_filters_remove_particle_scale_noise() {
    // Alternate rows and columns ±0.5 %: the checkerboard SPH cannot see in its sums.
    let noisy = |i: usize, x: f64, y: f64| {
        let _ = i;
        let parity = ((x / DX).floor() as i64 + (y / DX).floor() as i64) % 2;
        2700.0 * (1.0 + if parity == 0 { 0.005 } else { -0.005 })
    };
    for filter in [DensityFilter::Shepard, DensityFilter::Mls] {
        let mut w = block(filter, noisy);
        w.filter_density();
        let left = worst(&w, |_, _, _| 2700.0);
        assert!(left < 0.0025, "{filter:?} left {left:e} of 0.005 noise");
        assert!(w.numerical_work().density_filter < 0.0);
    }
}
