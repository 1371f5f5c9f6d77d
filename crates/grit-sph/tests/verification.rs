//! The verification cases at CI resolution, with the tolerances of docs/design.md#targets;
//! `grit verify` runs the same code at full resolution.

use grit_sph::verification::{elastic_impact, hertz, hourglass, sliding, slope};
use grit_sph::{ContactModel, Material};

#[test]
fn slope_slider_follows_eq_30_within_2_percent() {
    for mu in [0.0, 0.4] {
        let s = slope::simulate(mu, ContactModel::Extrapolated, 20, 0.05).unwrap();
        let e = slope::worst_error(mu, &s);
        assert!(e <= 0.02, "mu = {mu}: worst error {e}");
    }
}

#[test]
fn slope_slider_sticks_when_mu_exceeds_tan_theta() {
    let s = slope::simulate(0.7, ContactModel::Extrapolated, 20, 0.05).unwrap();
    let e = slope::worst_error(0.7, &s);
    assert!(e <= 0.02, "sticking slider moved: {e}");
}

#[test]
fn penetration_contact_fails_the_2_percent_bound() {
    let s = slope::simulate(0.0, ContactModel::Penetration, 20, 0.05).unwrap();
    let e = slope::worst_error(0.0, &s);
    assert!(
        e > 0.02,
        "the plain penetration contact should show the seed's Fig. 2b failure, error {e}"
    );
}

#[test]
fn elastic_impact_conserves_momentum_and_energy_at_40_per_side() {
    // The three bounds of docs/design.md#targets, with the seed's filter and hourglass control on: momentum to
    // 1e-8, peak E/E0 at most 1.01, E/E0 after contact within 5 %. 30 per side misses the
    // last by 0.2 % (docs/verification.md §6), so the CI resolution is 40.
    let r = elastic_impact::run(40).unwrap();
    assert_eq!(r.rows.len(), 3);
    for row in &r.rows {
        assert!(row.pass, "{row:?}");
    }
}

#[test]
fn elastic_impact_energy_is_conserved_without_the_density_filter() {
    // The seed's filter (eq. 12) is the one large sink of this case; without it the engine
    // must bring the energy back within 5% (docs/design.md#targets) once the disc has left.
    let s = grit_sph::Settings {
        shepard_interval: 0,
        ..Default::default()
    };
    let h = elastic_impact::simulate(20, s).unwrap();
    let after = *h.energy.last().unwrap();
    assert!((after - 1.0).abs() <= 0.05, "E/E0 after contact {after}");
    assert_eq!(h.work.density_filter, 0.0);
}

#[test]
fn elastic_impact_energy_budget_closes_with_filter_and_hourglass_work() {
    // With the filter on, what the energy lost is what the filter and hourglass control took:
    // E + |filter work| + |hourglass work| returns to E0 within 5%.
    let h = elastic_impact::simulate(20, grit_sph::Settings::default()).unwrap();
    let after = *h.energy.last().unwrap();
    let closed = after - h.work.density_filter - h.work.hourglass;
    assert!(h.work.density_filter < 0.0 && h.work.hourglass < 0.0);
    assert!((closed - 1.0).abs() <= 0.05, "E/E0 + removed = {closed}");
}

#[test]
fn hourglass_modes_grow_without_control_and_stay_bounded_with_it() {
    let r = hourglass::run(20, 0.1).unwrap();
    for row in &r.rows {
        assert!(row.pass, "{row:?}");
    }
}

#[test]
fn controlled_sliding_sticks_until_0_625_s_then_follows_the_analytic_speed() {
    let r = sliding::run(20).unwrap();
    assert_eq!(r.rows.len(), 2);
    for row in &r.rows {
        assert!(row.pass, "{row:?}");
    }
}

#[test]
fn hertz_peak_pressure_converges_to_eq_31_and_profile_and_axis_follow_eqs_32_33() {
    let e = hertz::contact_modulus(&Material::elastic_aluminium());
    let worst = |snaps: &[hertz::Snapshot]| {
        snaps
            .iter()
            .map(|s| hertz::peak_error(s, e))
            .fold(0.0, f64::max)
    };
    let coarse = hertz::simulate(20, hertz::DENSITY_FILTER).unwrap();
    let fine = hertz::simulate(25, hertz::DENSITY_FILTER).unwrap();
    assert_eq!(fine.len(), hertz::LOADS.len());
    let (ec, ef) = (worst(&coarse), worst(&fine));
    assert!(
        ef < ec,
        "p0 error must shrink with the spacing: {ec} -> {ef}"
    );
    let last = fine.last().unwrap();
    assert!(last.load_n_m >= 50e6);
    let e50 = hertz::peak_error(last, e);
    assert!(e50 <= hertz::P0_BOUND, "p0 error at 50 MN/m: {e50}");
    let p = hertz::pressure_rms(last, e);
    assert!(p <= hertz::PRESSURE_RMS_BOUND, "pressure RMS {p}");
    let a = hertz::axis_rms(last, e, 0.3);
    assert!(a <= hertz::AXIS_RMS_BOUND, "axis-stress RMS {a}");
}
