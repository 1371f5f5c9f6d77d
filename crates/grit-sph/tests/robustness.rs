//! Heavily sheared metal can bring two particles almost on top of each other (seen in an
//! eroded surface at 75°). The hourglass force of eq. 16 must stay bounded there, or one step
//! throws the pair further than h and the impact fails.

use grit_sph::{Material, Motion, Polygon, Settings, Vector, World};

#[test]
fn nearly_coincident_particles_do_not_blow_up() {
    let dx = 8e-6;
    let settings = Settings {
        spacing_m: dx,
        ..Settings::default()
    };
    let side = 12.0 * dx;
    let block = Polygon::new(
        &[[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]],
        "block",
    )
    .unwrap();
    let mut w = World::new(settings.clone()).unwrap();
    let b = w
        .add_deformable_polygon(
            "block",
            Material::aisi304(),
            &block,
            Vector::zeros(),
            Vector::zeros(),
        )
        .unwrap();
    let mut state = w.body_state(b);
    // Two interior lattice neighbours: move one onto the other and let them close at 300 m/s,
    // the relative speed the failing impact showed.
    let centre = Vector::new(6.0 * dx, 6.0 * dx);
    let near = |x: Vector| (x - centre).norm();
    let i = (0..state.len())
        .min_by(|&a, &b| near(state.pos[a]).total_cmp(&near(state.pos[b])))
        .unwrap();
    let j = (0..state.len())
        .filter(|&j| j != i)
        .min_by(|&a, &b| {
            (state.pos[a] - state.pos[i])
                .norm()
                .total_cmp(&(state.pos[b] - state.pos[i]).norm())
        })
        .unwrap();
    state.pos[j] = state.pos[i] + Vector::new(0.01 * dx, 0.0);
    state.vel[i] = Vector::new(150.0, 0.0);
    state.vel[j] = Vector::new(-150.0, 0.0);
    let mut w = World::new(settings).unwrap();
    w.add_deformable_state("block", Material::aisi304(), state, Motion::Fixed)
        .unwrap();
    for _ in 0..200 {
        w.step().expect("the pair force stays bounded");
    }
}
