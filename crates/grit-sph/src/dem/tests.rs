//! Analytic checks of the DEM: drop and bounce heights, head-on restitution and contact time,
//! momentum, the Coulomb cap and the slide-to-roll transition.

use super::*;
use crate::lcg::Lcg;

const G: f64 = 9.81;

fn floor() -> Wall {
    Wall::new(Vector::zeros(), Vector::new(0.0, 1.0)).unwrap()
}

/// A softened garnet: the same laws at a stiffness that lets a unit test run whole seconds.
fn soft(restitution: f64, friction: f64) -> DemParams {
    DemParams {
        youngs_modulus_pa: 2.48e9,
        restitution,
        friction,
        ..DemParams::default()
    }
}

#[test]
fn dem_drop_contact_time_and_apex_heights() {
    // R = 5 mm dropped from a centre height of 50 mm: first contact at √(2 (h0 − R)/g) = 0.0958 s,
    // apex n at R + e^{2n} (h0 − R).
    let (r, h0, e) = (5e-3, 50e-3, 0.8);
    let grain = Grain::sphere(Vector::new(0.0, h0), r, 4120.0);
    let mut dem = Dem::new(
        vec![grain],
        vec![floor()],
        soft(e, 0.3),
        Vector::new(0.0, -G),
    )
    .unwrap();
    let dt = dem.time_step();
    let run = crate::verification::jet::drop_to_third_apex(&mut dem, dt, u64::MAX).unwrap();
    let (first_contact, apexes) = (run.first_contact, run.apexes);
    let tc = first_contact.unwrap();
    assert!((tc / 0.0958 - 1.0).abs() < 0.01, "first contact {tc}");
    assert!((tc / (2.0 * (h0 - r) / G).sqrt() - 1.0).abs() < 1e-3);
    for (n, y) in apexes.iter().enumerate() {
        let expect = r + e.powi(2 * (n as i32 + 1)) * (h0 - r);
        assert!(
            (y / expect - 1.0).abs() < 0.01,
            "apex {}: {y} vs {expect}",
            n + 1
        );
    }
    // Head-on on a wall: no spin.
    assert!(dem.grains[0].omega.abs() < 1e-9);
}

/// Runs two grains head-on until they part; returns (relative speed ratio, contact time, dem).
fn head_on(e: f64, params: DemParams) -> (f64, f64, Dem) {
    let [a, b] = crate::verification::jet::head_on_grains();
    let params = DemParams {
        restitution: e,
        ..params
    };
    let mut dem = Dem::new(vec![a, b], vec![], params, Vector::zeros()).unwrap();
    let dt = dem.time_step();
    let v0 = dem.grains[1].vel.x - dem.grains[0].vel.x;
    let (mut t, mut start, mut end) = (0.0, None, None);
    while end.is_none() {
        dem.step(dt, &[]).unwrap();
        t += dt;
        match (start, dem.contacts().is_empty()) {
            (None, false) => start = Some(t - dt),
            (Some(_), true) => end = Some(t - dt),
            _ => {}
        }
        assert!(t < 1e-5);
    }
    let v1 = dem.grains[1].vel.x - dem.grains[0].vel.x;
    (-v1 / v0, end.unwrap() - start.unwrap(), dem)
}

#[test]
fn head_on_restitution_contact_time_and_momentum() {
    for e in [0.3, 0.8, 0.95] {
        let (ratio, duration, dem) = head_on(e, DemParams::default());
        assert!(
            (ratio / e - 1.0).abs() < 0.01,
            "e {e}: rebound ratio {ratio}"
        );
        let (a, b) = (&dem.grains[0], &dem.grains[1]);
        let law = dem.params.pair_law(a, b);
        let m_star = a.mass_kg * b.mass_kg / (a.mass_kg + b.mass_kg);
        let expect = contact_time(law.k_n, m_star, damping_ratio(e));
        assert!(
            (duration / expect - 1.0).abs() < 0.02,
            "e {e}: contact {duration} vs {expect}"
        );
        let p0 = a.mass_kg * 5.0 - b.mass_kg * 3.0;
        let scale = a.mass_kg * 5.0 + b.mass_kg * 3.0;
        assert!((dem.momentum().x - p0).abs() < 1e-12 * scale);
        assert!(dem.momentum().y.abs() < 1e-12 * scale);
        assert!(a.omega.abs() < 1e-6 && b.omega.abs() < 1e-6);
    }
}

#[test]
fn coulomb_cap_then_rolling_at_five_sevenths() {
    // A sphere launched sliding at v0 without spin slides under μ m g until v = ω R, then rolls at
    // v0 / (1 + m R² / I) = 5/7 v0, after t = 2 v0 / (7 μ g).
    let (r, v0, mu) = (5e-3, 1.0, 0.3);
    let mut grain = Grain::sphere(Vector::zeros(), r, 4120.0);
    let params = soft(0.5, mu);
    let sag = grain.mass_kg * G / params.wall_law(&grain).k_n;
    grain.pos = Vector::new(0.0, r - sag);
    grain.vel = Vector::new(v0, 0.0);
    let mut dem = Dem::new(vec![grain], vec![floor()], params, Vector::new(0.0, -G)).unwrap();
    let dt = dem.time_step();
    let t_slide = 2.0 * v0 / (7.0 * mu * G);
    let mut t = 0.0;
    let mut slid = 0usize;
    while t < 1.5 * t_slide {
        dem.step(dt, &[]).unwrap();
        t += dt;
        let c = dem.contacts();
        assert_eq!(c.len(), 1, "the grain stays on the floor at t = {t}");
        let f = c[0].force;
        assert!(f.tangential.abs() <= mu * f.normal.abs() * (1.0 + 1e-12));
        if t < 0.9 * t_slide {
            assert!(f.sliding, "slides until t = {t_slide}, not at {t}");
            slid += 1;
        }
    }
    assert!(slid > 0);
    let g = &dem.grains[0];
    assert!(
        (g.vel.x / (5.0 / 7.0 * v0) - 1.0).abs() < 0.01,
        "{}",
        g.vel.x
    );
    assert!(
        (-g.omega * r / g.vel.x - 1.0).abs() < 0.01,
        "rolls without slip"
    );
}

#[test]
fn many_grains_conserve_momentum_and_lose_energy_deterministically() {
    // A loose cloud on a lattice with pseudo-random velocities, no walls, no gravity.
    let mut lcg = Lcg(12345);
    let mut rand = move || lcg.next_unit() - 0.5;
    let mut grains = Vec::new();
    for k in 0..36 {
        let (ix, iy) = ((k % 6) as f64, (k / 6) as f64);
        let r = 1e-4 * (1.0 + 0.3 * rand());
        let mut g = Grain::sphere(Vector::new(ix * 2.5e-4, iy * 2.5e-4), r, 4120.0);
        g.vel = Vector::new(rand(), rand()) * 50.0;
        g.omega = rand() * 1e4;
        grains.push(g);
    }
    let dem0 = Dem::new(grains, vec![], DemParams::default(), Vector::zeros()).unwrap();
    let run = |mut dem: Dem| {
        let dt = dem.time_step();
        let mut contacts = 0;
        for _ in 0..20_000 {
            dem.step(dt, &[]).unwrap();
            contacts += dem.contacts().len();
        }
        (dem, contacts)
    };
    let (a, contacts) = run(dem0.clone());
    let (b, _) = run(dem0.clone());
    assert!(
        contacts > 100,
        "the cloud collides ({contacts} contact-steps)"
    );
    assert_eq!(a.grains, b.grains, "bit-for-bit repeatable");
    let scale: f64 = dem0.grains.iter().map(|g| g.mass_kg * g.vel.norm()).sum();
    assert!((a.momentum() - dem0.momentum()).norm() < 1e-12 * scale);
    assert!(a.kinetic_energy() < dem0.kinetic_energy());
}

#[test]
fn sweep_and_prune_finds_every_overlap() {
    let mut grains = Vec::new();
    for k in 0..50 {
        let x = ((k * 37) % 50) as f64 * 0.7e-4;
        let y = ((k * 11) % 7) as f64 * 0.9e-4;
        grains.push(Grain::sphere(
            Vector::new(x, y),
            0.5e-4 + (k % 3) as f64 * 1e-5,
            4120.0,
        ));
    }
    let dem = Dem::new(grains, vec![], DemParams::default(), Vector::zeros()).unwrap();
    let mut brute = Vec::new();
    for i in 0..dem.grains.len() {
        for j in i + 1..dem.grains.len() {
            let (a, b) = (&dem.grains[i], &dem.grains[j]);
            if (b.pos - a.pos).norm() < a.radius_m + b.radius_m {
                brute.push((i, j));
            }
        }
    }
    let found: Vec<_> = dem
        .candidate_pairs()
        .into_iter()
        .filter(|&(i, j)| {
            let (a, b) = (&dem.grains[i], &dem.grains[j]);
            (b.pos - a.pos).norm() < a.radius_m + b.radius_m
        })
        .collect();
    assert!(!brute.is_empty());
    assert_eq!(found, brute);
}

#[test]
fn external_force_accelerates_and_bad_input_is_named() {
    let g = Grain::sphere(Vector::zeros(), 1e-4, 4120.0);
    let m = g.mass_kg;
    let mut dem = Dem::new(vec![g], vec![], DemParams::default(), Vector::zeros()).unwrap();
    dem.step(1e-6, &[Vector::new(m, 0.0)]).unwrap();
    assert!((dem.grains[0].vel.x - 1e-6).abs() < 1e-18);
    let err = dem.step(1e-6, &[Vector::zeros(); 2]).unwrap_err();
    assert_eq!(err.field, "external");
    assert_eq!(dem.step(0.0, &[]).unwrap_err().field, "dt");

    let bad = DemParams {
        restitution: 1.5,
        ..DemParams::default()
    };
    let err = Dem::new(vec![], vec![], bad, Vector::zeros()).unwrap_err();
    assert_eq!(err.field, "dem.restitution");
    let mut g = Grain::sphere(Vector::zeros(), 1e-4, 4120.0);
    g.radius_m = -1.0;
    let err = Dem::new(vec![g], vec![], DemParams::default(), Vector::zeros()).unwrap_err();
    assert_eq!(err.field, "grains[0].radius_m");
    let skew = Wall {
        point: Vector::zeros(),
        normal: Vector::new(0.0, 2.0),
    };
    let err = Dem::new(
        vec![],
        vec![floor(), skew],
        DemParams::default(),
        Vector::zeros(),
    );
    assert_eq!(err.unwrap_err().field, "walls[1]");
    assert_eq!(
        Wall::new(Vector::zeros(), Vector::zeros())
            .unwrap_err()
            .field,
        "wall.normal"
    );
    let bad = DemParams {
        poisson_ratio: 0.5,
        ..DemParams::default()
    };
    let err = Dem::new(vec![], vec![], bad, Vector::zeros()).unwrap_err();
    assert_eq!(err.field, "dem.poisson_ratio");
    let json = r#"{"youngs_modulus_pa": 248e9, "poisson_ratio": 0.3, "restitution": 0.8, "friction": 0.3}"#;
    let p: DemParams = serde_json::from_str(json).unwrap();
    assert_eq!(p, DemParams::default());
}

/// Grains 1 and 2 collide while grain 0 sits far away.
fn pair_with_bystander() -> Dem {
    let far = Grain::sphere(Vector::new(1.0, 1.0), 1e-4, 4120.0);
    let a = Grain {
        vel: Vector::new(5.0, 1.0),
        omega: 2e4,
        ..Grain::sphere(Vector::new(0.0, 1e-3), 1e-4, 4120.0)
    };
    let b = Grain {
        vel: Vector::new(-3.0, 0.0),
        ..Grain::sphere(Vector::new(1.937e-4, 1.05e-3), 1e-4, 4120.0)
    };
    Dem::new(
        vec![far, a, b],
        vec![floor()],
        DemParams::default(),
        Vector::zeros(),
    )
    .unwrap()
}

#[test]
fn retain_keeps_the_springs_on_their_grains() {
    let mut with = pair_with_bystander();
    let mut without = with.clone();
    without.retain(|g| g.pos.x < 0.5);
    assert_eq!(without.grains.len(), 2);
    let dt = with.time_step();
    let mut mid_contact = false;
    for k in 0..400 {
        with.step(dt, &[]).unwrap();
        if k == 60 {
            // Remove the bystander in the middle of the contact: the spring must follow.
            mid_contact = with.contacts().iter().any(|c| c.force.tangential != 0.0);
            with.retain(|g| g.pos.x < 0.5);
        }
        without.step(dt, &[]).unwrap();
    }
    assert!(
        mid_contact,
        "the removal fell inside a contact with a loaded spring"
    );
    assert_eq!(with.grains, without.grains);
}

#[test]
fn checkpoint_and_resume_is_bit_for_bit() {
    let mut a = pair_with_bystander();
    let dt = a.time_step();
    for _ in 0..60 {
        a.step(dt, &[]).unwrap();
    }
    assert!(!a.contacts().is_empty());
    let json = serde_json::to_string(&a).unwrap();
    let mut b: Dem = serde_json::from_str(&json).unwrap();
    for _ in 0..200 {
        a.step(dt, &[]).unwrap();
        b.step(dt, &[]).unwrap();
    }
    assert_eq!(a.grains, b.grains);
}

#[test]
fn added_grains_take_part() {
    let mut dem = Dem::new(
        vec![],
        vec![floor()],
        DemParams::default(),
        Vector::new(0.0, -G),
    )
    .unwrap();
    dem.add(Grain::sphere(Vector::new(0.0, 0.9e-4), 1e-4, 4120.0))
        .unwrap();
    dem.step(1e-10, &[]).unwrap();
    assert_eq!(dem.contacts().len(), 1);
    let mut bad = Grain::sphere(Vector::zeros(), 1e-4, 4120.0);
    bad.mass_kg = 0.0;
    assert_eq!(dem.add(bad).unwrap_err().field, "grains[1].mass_kg");
}
