//! Seed section 4: grains are placed so that they "hit the surface around the midpoint", at
//! every angle. Aiming the centroid path instead put the touchdown 1.9 Dg upstream at 15°, off
//! the surface, and most 15° grains never touched it.

use grit_erosion::impact::run_impact;
use grit_erosion::{ImpactParams, Shape};

#[test]
fn every_grain_touches_down_within_the_aim_range_about_the_middle() {
    for angle in [15.0, 30.0, 45.0, 60.0, 75.0, 90.0] {
        for shape in [Shape::Hexagon, Shape::Square, Shape::Rectangle] {
            let p = ImpactParams::paper(angle, shape.clone());
            let dg = p.grain_diameter_m;
            let half_range = 0.5 * p.distribution_range_dg * dg;
            let a = f64::to_radians(angle);
            for k in 0..40 {
                let (u_angle, u_aim) = (k as f64 / 40.0, ((k * 7) % 40) as f64 / 39.0 * 0.999);
                let g = p.grain_start(u_angle, u_aim).unwrap();
                let v = g.polygon.vertices();
                // Fly the outline along its path until its lowest point reaches y = 0.
                let lowest = v.iter().map(|v| v.y).fold(f64::INFINITY, f64::min);
                assert!(lowest > 0.0, "{angle}° starts above the surface");
                let travel = lowest / a.sin();
                let centroid_x = g.polygon.centroid().x + travel * a.cos();
                let touch = v
                    .iter()
                    .min_by(|p, q| p.y.total_cmp(&q.y))
                    .map(|p| p.x + travel * a.cos())
                    .unwrap();
                assert!(
                    (centroid_x - g.aim_x_m).abs() < 1e-9 * dg,
                    "{angle}° {shape:?}: centroid at touchdown {centroid_x:e}, aim {:e}",
                    g.aim_x_m
                );
                assert!(g.aim_x_m.abs() <= half_range);
                let c = g.polygon.centroid();
                let reach = v.iter().map(|v| (v - c).norm()).fold(0.0, f64::max);
                assert!(
                    touch.abs() <= half_range + reach,
                    "{angle}° {shape:?}: touchdown at {touch:e} m"
                );
            }
        }
    }
}

#[test]
fn a_grazing_grain_aimed_at_the_upstream_end_still_hits() {
    let p = ImpactParams {
        spacing_m: 25e-6,
        surface_width_dg: 2.5,
        distribution_range_dg: 0.5,
        ..ImpactParams::paper(15.0, Shape::Hexagon)
    };
    let surface = p.fresh_surface().unwrap();
    for u_angle in [0.0, 0.3, 0.7] {
        let grain = p.grain_start(u_angle, 0.0).unwrap();
        let run = run_impact(&p, &surface, &grain, &|| false).unwrap();
        // It hit: it lost speed and left the surface plastically deformed.
        let deformed = run.surface.eps_p.iter().any(|&e| e > 1e-3);
        assert!(
            run.outcome.rebound_ratio < 0.98 && deformed,
            "orientation {u_angle}: {:?}",
            run.outcome
        );
    }
}
