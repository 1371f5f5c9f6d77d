//! The absorbing layer (`Absorber`): a sponge along a body's fixed edges takes the energy of
//! the waves that reach it, and books what it takes as numerical work.

use grit_sph::verification::elastic_impact::{self, Disc, BLOCK};
use grit_sph::{Absorber, Material, NumericalWork, Settings, Vector, World};

const N: usize = 20;
const T_END: f64 = 2e-4;

/// The small-disc elastic impact on the free block, with or without a sponge of three layers
/// along its bottom and sides; E/E0 at T_END and the work done. (Free, not on a fixed band:
/// kinematic particles change their elastic energy without doing work, which would leave the
/// budget open.)
fn run(absorb: bool) -> (f64, NumericalWork) {
    let dx = BLOCK / N as f64;
    let mut w: World = elastic_impact::scene_with(N, Settings::default(), Disc::SMALL);
    if absorb {
        let l = 3.0 * dx;
        let c = Material::elastic_aluminium().sound_speed();
        w.set_absorber(
            0,
            Absorber {
                inner_lo: Vector::new(l, l),
                inner_hi: Vector::new(BLOCK - l, 2.0 * BLOCK),
                thickness_m: l,
                sigma_max_per_s: Absorber::sigma_for(c, l, 0.01),
            },
        )
        .unwrap();
    }
    let e0 = w.energy().total();
    while w.time() < T_END {
        w.step().unwrap();
    }
    let mut work = w.numerical_work();
    work.absorbed /= e0;
    work.hourglass /= e0;
    work.density_filter /= e0;
    (w.energy().total() / e0, work)
}

#[test]
fn the_sponge_takes_the_wave_energy_and_books_it() {
    let (plain, plain_work) = run(false);
    let (sponge, work) = run(true);
    assert_eq!(plain_work.absorbed, 0.0);
    assert!(work.absorbed < -0.05, "{work:?}");
    // Without the sponge the block keeps its waves (and its motion); with it that energy
    // leaves through the layer, and the books say so.
    assert!(
        sponge < plain,
        "E/E0 {sponge} with the sponge, {plain} without"
    );
    assert!(
        (sponge - 1.0 - work.absorbed - work.density_filter - work.hourglass).abs() <= 0.05,
        "budget: E/E0 {sponge}, work {work:?}"
    );
}

#[test]
fn sigma_grows_as_the_square_of_the_depth_into_the_layer() {
    let a = Absorber {
        inner_lo: Vector::new(0.0, 0.0),
        inner_hi: Vector::new(1.0, 1.0),
        thickness_m: 0.1,
        sigma_max_per_s: 8.0,
    };
    assert_eq!(a.sigma(Vector::new(0.5, 0.5)), 0.0);
    assert!((a.sigma(Vector::new(-0.05, 0.5)) - 2.0).abs() < 1e-12);
    assert!((a.sigma(Vector::new(0.5, 1.1)) - 8.0).abs() < 1e-12);
    assert_eq!(a.sigma(Vector::new(-3.0, -3.0)), 8.0);
}

#[test]
fn bad_layers_are_refused_with_the_field_named() {
    let mut w = elastic_impact::scene_with(8, Settings::default(), Disc::SMALL);
    let good = Absorber {
        inner_lo: Vector::new(0.0, 0.0),
        inner_hi: Vector::new(BLOCK, BLOCK),
        thickness_m: 1e-3,
        sigma_max_per_s: 1e6,
    };
    let e = w
        .set_absorber(
            0,
            Absorber {
                thickness_m: -1.0,
                ..good
            },
        )
        .unwrap_err();
    assert_eq!(e.field, "absorber.thickness_m");
    let e = w
        .set_absorber(
            0,
            Absorber {
                sigma_max_per_s: f64::NAN,
                ..good
            },
        )
        .unwrap_err();
    assert_eq!(e.field, "absorber.sigma_max_per_s");
    let e = w
        .set_absorber(
            0,
            Absorber {
                inner_lo: Vector::new(1.0, 0.0),
                ..good
            },
        )
        .unwrap_err();
    assert_eq!(e.field, "absorber.inner_lo");
    // Body 1 is the rigid disc.
    assert_eq!(w.set_absorber(1, good).unwrap_err().field, "absorber");
    assert!(w.set_absorber(0, good).is_ok());
}
