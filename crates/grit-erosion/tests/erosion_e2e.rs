//! End to end on a coarse real sample: no mass loss during an incubation period,
//! then mass loss that grows, and a positive, finite erosion from the last 20 points.
//! 16 particles per Dg and a 0.5 Dg aim range, so that erosion starts within 70 impacts.

use grit_erosion::impact::aggregate::{cumulative_series, sample_erosion};
use grit_erosion::{ImpactParams, Sample, Shape, SLOPE_WINDOW};

#[test]
fn coarse_sample_incubates_then_erodes() {
    let params = ImpactParams {
        spacing_m: 16e-6,
        distribution_range_dg: 0.5,
        surface_width_dg: 2.5,
        surface_depth_dg: 1.25,
        ..ImpactParams::paper(45.0, Shape::Hexagon)
    };
    let mut s = Sample::new(params, 1).unwrap();
    for _ in 0..70 {
        s.run_next().unwrap();
    }
    let impacts: Vec<_> = s.records().iter().map(|r| r.impact()).collect();
    let cum = cumulative_series(&impacts);
    let first = cum
        .iter()
        .position(|p| p.mass_loss_kg > 0.0)
        .expect("the surface loses mass within 70 impacts");
    // Incubation: the first impacts only strain and damage the surface (seed Fig. 8).
    assert!(first >= 10, "mass loss already at impact {}", first + 1);
    let last = cum.last().unwrap().mass_loss_kg;
    assert!(
        last > cum[first].mass_loss_kg,
        "mass loss does not grow after impact {}",
        first + 1
    );
    assert!(cum
        .windows(2)
        .all(|w| w[1].mass_loss_kg >= w[0].mass_loss_kg));
    let e = sample_erosion(&cum, SLOPE_WINDOW).unwrap();
    assert!(e.is_finite() && e > 0.0, "erosion {e}");
    // Every impact ended by the criterion, not by the time limit.
    assert!(s.records().iter().all(|r| r.outcome.settled));
}
