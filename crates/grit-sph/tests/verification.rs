//! The verification cases at CI resolution, with the tolerances of the issue; `grit verify`
//! runs the same code at full resolution.

use grit_sph::verification::{elastic_impact, hourglass, slope};
use grit_sph::ContactModel;

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
fn elastic_impact_conserves_momentum() {
    let r = elastic_impact::run(20).unwrap();
    let m = r
        .rows
        .iter()
        .find(|r| r.case == "elastic_impact_momentum")
        .unwrap();
    assert!(m.pass, "{m:?}");
}

#[test]
fn hourglass_modes_grow_without_control_and_stay_bounded_with_it() {
    let r = hourglass::run(20, 0.1).unwrap();
    for row in &r.rows {
        assert!(row.pass, "{row:?}");
    }
}
