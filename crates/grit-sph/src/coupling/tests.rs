use super::*;
use crate::lcg::Lcg;

/// Garnet-like abrasive of the AWJ paper: d = 0.2 mm, ρ 4120 kg/m³.
const D: f64 = 0.2e-3;
const RHO_P: f64 = 4120.0;
/// The paper's fluid spacing d_ini = 50 µm.
const DX: f64 = 50e-6;

fn grain(x: f64, y: f64, vx: f64, vy: f64) -> Grain {
    let mut g = Grain::sphere(Vector::new(x, y), 0.5 * D, RHO_P);
    g.vel = Vector::new(vx, vy);
    g
}

/// A square block of fluid particles, `n` by `n` at spacing DX from the origin.
fn block(n: usize) -> Vec<Vector> {
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            out.push(Vector::new(i as f64 * DX, j as f64 * DX));
        }
    }
    out
}

#[test]
fn schiller_naumann_limits_and_its_step_at_re_1000() {
    // Stokes at small Re: C_d Re → 24.
    for re in [1e-8, 1e-6, 1e-4] {
        let cd = drag_coefficient(re);
        assert!((cd * re / 24.0 - 1.0).abs() < 0.15 * re.powf(0.687) + 1e-12);
    }
    assert_eq!(drag_coefficient_times_re(0.0), 24.0);
    assert!(drag_coefficient(0.0).is_infinite());
    // Newton's regime.
    for re in [1000.0, 5e3, 1e6] {
        assert_eq!(drag_coefficient(re), 0.44);
    }
    // The law as written steps from 0.4383 to 0.44 at Re = 1000: 0.39 %.
    let below = drag_coefficient(1000.0 - 1e-9);
    assert!((below - 0.024 * (1.0 + 0.15 * 1000f64.powf(0.687))).abs() < 1e-12);
    assert!(((0.44 - below) / 0.44 - 0.00390).abs() < 1e-4, "{below}");
}

#[test]
fn ergun_and_wen_yu_meet_with_a_jump_at_the_switch() {
    let w = Fluid::water();
    let (rho, mu) = (w.density(), w.dynamic_viscosity_pa_s);
    let s = DEFAULT_SWITCH_POROSITY;
    let at = |eps: f64, v: f64| drag_per_volume(eps, v, D, rho, mu, s);
    // Creeping flow: Ergun 150 (1 − ε)/ε = 37.5 against Wen–Yu 18 ε^−2.65 = 32.5 (× μ/d²).
    let ergun0 = at(s, 0.0) * D * D / mu;
    let wenyu0 = at(s + 1e-12, 0.0) * D * D / mu;
    assert!((ergun0 - 37.5).abs() < 1e-9, "{ergun0}");
    assert!(
        (wenyu0 - 18.0 * 0.8f64.powf(-2.65)).abs() < 1e-6,
        "{wenyu0}"
    );
    assert!((ergun0 / wenyu0 - 1.1533).abs() < 1e-3);
    // Inertial flow (Re ≫ 1000): Ergun's 1.75 against Wen–Yu's 0.33 ε^−1.65 (× ρ|v|/d).
    let v = 1e3;
    let ratio = at(s, v) / at(s + 1e-12, v);
    assert!((ratio - 3.67).abs() < 0.01, "{ratio}");
    // Wen–Yu at ε = 1 is the single-sphere drag 0.75 C_d ρ |v|/d.
    let v = 0.05;
    let re = reynolds(v, 1.0, D, rho, mu);
    let lone = at(1.0, v);
    assert!((lone / (0.75 * drag_coefficient(re) * rho * v / D) - 1.0).abs() < 1e-12);
}

#[test]
fn settling_reproduces_stokes_at_small_re_and_the_garnet_reference() {
    let w = Fluid::water();
    // A 10 µm garnet grain: Re ≈ 2e-3, within 1 % of Stokes.
    let d = 10e-6;
    let s = terminal_velocity(RHO_P, d, 1.0, &w, 9.81, DEFAULT_SWITCH_POROSITY).unwrap();
    let stokes = stokes_velocity(RHO_P, d, &w, 9.81);
    assert!(s.reynolds < 0.01, "{s:?}");
    assert!(
        (s.velocity_m_s / stokes - 1.0).abs() < 0.01,
        "{s:?} vs {stokes}"
    );
    assert!(
        s.velocity_m_s < stokes,
        "Schiller–Naumann drags more than Stokes"
    );
    // The paper's abrasive (d = 0.2 mm) settles at 0.0414 m/s (Re 8.3), 39 % below Stokes.
    let s = terminal_velocity(RHO_P, D, 1.0, &w, 9.81, DEFAULT_SWITCH_POROSITY).unwrap();
    assert!((s.velocity_m_s - 0.04144).abs() < 1e-5, "{s:?}");
    assert!((s.reynolds - 8.288).abs() < 1e-3);
    // The balance holds at the root.
    let k = drag_per_volume(1.0, s.velocity_m_s, D, 1000.0, 1e-3, 0.8);
    assert!((k * s.velocity_m_s / (3120.0 * 9.81) - 1.0).abs() < 1e-12);
    // A lighter grain rises; a neutral one stays.
    let up = terminal_velocity(500.0, D, 1.0, &w, 9.81, 0.8).unwrap();
    assert!(up.velocity_m_s < 0.0);
    let still = terminal_velocity(1000.0, D, 1.0, &w, 9.81, 0.8).unwrap();
    assert_eq!(still.velocity_m_s, 0.0);
    // Crowding slows settling.
    let dense = terminal_velocity(RHO_P, D, 0.7, &w, 9.81, 0.8).unwrap();
    assert!(dense.velocity_m_s < 0.5 * 0.04144);
    assert!((stokes_relaxation_time(RHO_P, D, &w) - 4120.0 * 4e-8 / 18e-3).abs() < 1e-15);
}

#[test]
fn a_released_grain_approaches_the_stokes_transient() {
    // ρ_p dv/dt = (ρ_p − ρ_f) g − [β/(1 − ε)] v from rest, integrated at τ/2000: in the Stokes
    // limit v = v_t (1 − e^{−t/τ}).
    let w = Fluid::water();
    let d = 10e-6;
    let tau = stokes_relaxation_time(RHO_P, d, &w);
    let vt = terminal_velocity(RHO_P, d, 1.0, &w, 9.81, 0.8)
        .unwrap()
        .velocity_m_s;
    let dt = tau / 2000.0;
    let mut v: f64 = 0.0;
    for step in 1..=6000 {
        let k = drag_per_volume(1.0, v.abs(), d, 1000.0, 1e-3, 0.8);
        v += dt * ((RHO_P - 1000.0) * 9.81 - k * v) / RHO_P;
        if step % 2000 == 0 {
            let t = step as f64 * dt;
            let expect = vt * (1.0 - (-t / tau).exp());
            assert!(
                (v / expect - 1.0).abs() < 0.01,
                "t/τ {}: {v} vs {expect}",
                t / tau
            );
        }
    }
}

#[test]
fn settling_rejects_bad_input_by_name() {
    let w = Fluid::water();
    let e = terminal_velocity(RHO_P, -1.0, 1.0, &w, 9.81, 0.8).unwrap_err();
    assert_eq!(e.field, "settling.diameter");
    let e = terminal_velocity(RHO_P, D, 1.5, &w, 9.81, 0.8).unwrap_err();
    assert_eq!(e.field, "settling.porosity");
    let e = terminal_velocity(RHO_P, D, 0.0, &w, 9.81, 0.8).unwrap_err();
    assert_eq!(e.field, "settling.porosity");
    let e = terminal_velocity(RHO_P, D, 1.0, &w, 9.81, 1.0).unwrap_err();
    assert_eq!(e.field, "settling.switch");
}

#[test]
fn params_default_json_and_validation() {
    let p = CouplingParams::default();
    assert!(p.validate("coupling").is_ok());
    // R_c = 2 d = 2 h_c for the cubic spline.
    let k = p.kernel(0.5 * D);
    assert!((k.radius() - 2.0 * D).abs() < 1e-18);
    assert!((k.h - D).abs() < 1e-18);
    let back: CouplingParams = serde_json::from_str("{}").unwrap();
    assert_eq!(back, p);
    let json = serde_json::to_string(&p).unwrap();
    assert!(json.contains("\"cubic_spline\""), "{json}");
    let bad = CouplingParams {
        min_porosity: 1.0,
        ..p
    };
    assert_eq!(
        bad.validate("coupling").unwrap_err().field,
        "coupling.min_porosity"
    );
    let bad = CouplingParams {
        radius_factor: 0.0,
        ..p
    };
    assert_eq!(
        bad.validate("coupling").unwrap_err().field,
        "coupling.radius_factor"
    );
}

#[test]
fn porosity_recovers_the_grain_area_and_is_floored() {
    // Grains well inside a block of fluid: Σ V_a (1 − ε_a) = Σ V_i.
    let fluid = block(60);
    let grains = vec![
        grain(1.0e-3, 1.0e-3, 0.0, 0.0),
        grain(1.7e-3, 1.2e-3, 0.0, 0.0),
        grain(1.3e-3, 2.0e-3, 0.0, 0.0),
    ];
    let p = CouplingParams::default();
    let pairs = find_pairs(&p, &fluid, &grains).unwrap();
    let eps = porosity(&p, fluid.len(), &grains, &pairs);
    assert_eq!(eps.floored, 0);
    let displaced: f64 = eps.values.iter().map(|e| (1.0 - e) * DX * DX).sum();
    let solid = 3.0 * disc_area(0.5 * D);
    assert!(
        // The reference allows 1 %; the lattice gives 1.3e-6.
        (displaced / solid - 1.0).abs() < 1e-5,
        "{displaced} vs {solid}"
    );
    // A lone grain at R_c = 2 d leaves ε = 1 − (10/7π) π/4 = 0.643 at its centre.
    let centre = fluid
        .iter()
        .position(|x| (x - Vector::new(1.0e-3, 1.0e-3)).norm() < 1e-12)
        .unwrap();
    assert!((eps.values[centre] - (1.0 - 10.0 / 28.0)).abs() < 1e-12);
    // At R_c = 1 d eq. 20 goes negative there; the floor holds it.
    let tight = CouplingParams {
        radius_factor: 1.0,
        ..p
    };
    let pairs = find_pairs(&tight, &fluid, &grains[..1]).unwrap();
    let eps = porosity(&tight, fluid.len(), &grains[..1], &pairs);
    assert!(eps.floored > 0);
    assert_eq!(eps.values[centre], tight.min_porosity);
    assert!(eps
        .values
        .iter()
        .all(|&e| e >= tight.min_porosity && e <= 1.0));
}

#[test]
fn pairs_are_those_within_rc_in_grain_then_fluid_order() {
    let fluid = block(40);
    let grains = vec![
        grain(0.9e-3, 0.5e-3, 0.0, 0.0),
        grain(0.2e-3, 1.1e-3, 0.0, 0.0),
    ];
    let p = CouplingParams::default();
    let pairs = find_pairs(&p, &fluid, &grains).unwrap();
    let mut brute = Vec::new();
    for (i, g) in grains.iter().enumerate() {
        for (a, x) in fluid.iter().enumerate() {
            if (x - g.pos).norm() < 2.0 * D {
                brute.push((i, a));
            }
        }
    }
    let got: Vec<(usize, usize)> = pairs.iter().map(|p| (p.grain, p.fluid)).collect();
    assert_eq!(got, brute);
    let mut bad = grains.clone();
    bad[1].radius_m = 0.0;
    assert_eq!(
        find_pairs(&p, &fluid, &bad).unwrap_err().field,
        "grains[1].radius_m"
    );
}

/// A block of fluid with scattered velocities, densities and θ, and grains inside and at its
/// edge; returns everything `coupling_forces` needs.
#[allow(clippy::type_complexity)]
fn scattered() -> (
    Vec<Vector>,
    Vec<Vector>,
    Vec<f64>,
    Vec<f64>,
    Vec<Vector>,
    Vec<Grain>,
) {
    let mut rng = Lcg(7);
    let mut pos = block(40);
    for x in &mut pos {
        *x += Vector::new(rng.next_unit() - 0.5, rng.next_unit() - 0.5) * (0.3 * DX);
    }
    let n = pos.len();
    let vel: Vec<Vector> = (0..n)
        .map(|_| Vector::new(200.0 * rng.next_unit(), -400.0 - 100.0 * rng.next_unit()))
        .collect();
    let rho_bar: Vec<f64> = (0..n).map(|_| 950.0 + 100.0 * rng.next_unit()).collect();
    let mass = vec![1000.0 * DX * DX; n];
    let theta: Vec<Vector> = (0..n)
        .map(|_| Vector::new(1e6 * (rng.next_unit() - 0.5), 1e7 * (rng.next_unit() - 0.5)))
        .collect();
    let grains = vec![
        grain(1.0e-3, 1.0e-3, 10.0, -300.0),
        grain(1.15e-3, 1.1e-3, -5.0, -350.0),
        grain(0.0, 1.9e-3, 0.0, -500.0),
        grain(0.5e-3, 0.6e-3, 0.0, 0.0),
    ];
    (pos, vel, mass, rho_bar, theta, grains)
}

/// The fluid particles as the coupling reads them.
fn fluid_view<'a>(
    position: &'a [Vector],
    velocity: &'a [Vector],
    mass: &'a [f64],
    rho_bar: &'a [f64],
) -> FluidView<'a> {
    FluidView {
        position,
        velocity,
        mass,
        rho_bar,
    }
}

/// The coupling forces of water with the default parameters on `view`.
fn water_forces(
    view: FluidView<'_>,
    porosity: &[f64],
    theta: &[Vector],
    grains: &[Grain],
    pairs: &[Pair],
) -> Result<CouplingForces, InputError> {
    let p = CouplingParams::default();
    coupling_forces(&p, &Fluid::water(), view, porosity, theta, grains, pairs)
}

#[test]
fn action_equals_minus_reaction_to_rounding() {
    let (pos, vel, mass, rho_bar, theta, grains) = scattered();
    let p = CouplingParams::default();
    let pairs = find_pairs(&p, &pos, &grains).unwrap();
    let eps = porosity(&p, pos.len(), &grains, &pairs);
    let view = fluid_view(&pos, &vel, &mass, &rho_bar);
    let f = water_forces(view, &eps.values, &theta, &grains, &pairs).unwrap();
    let on_grains: Vector = f.on_grains.iter().sum();
    let on_fluid: Vector = f.on_fluid.iter().sum();
    let scale: f64 = f.on_grains.iter().map(|v| v.norm()).sum();
    assert!(scale > 0.0);
    assert!(
        (on_grains + on_fluid).norm() < 1e-13 * scale,
        "{on_grains:?} vs {on_fluid:?}"
    );
    // Each grain's reaction alone also sums to minus its force.
    for i in 0..grains.len() {
        let gf = f.grain_fluid[i];
        let mut r = Vector::zeros();
        for q in pairs.iter().filter(|q| q.grain == i) {
            r -= f.on_grains[i] * (mass[q.fluid] / rho_bar[q.fluid] * q.w / gf.shepard);
        }
        assert!((r + f.on_grains[i]).norm() <= 1e-13 * f.on_grains[i].norm());
        assert!(gf.porosity > 0.0 && gf.porosity <= 1.0);
    }
    // Fluid that moves faster downwards than a grain drags it down.
    assert!(f.drag[0].y < 0.0);
}

#[test]
fn a_grain_in_still_hydrostatic_water_feels_archimedes_only() {
    let w = Fluid::water();
    let g = 9.81;
    let pos = block(40);
    let grains = vec![grain(1.0e-3, 1.0e-3, 0.0, 0.0)];
    let p = CouplingParams::default();
    let pairs = find_pairs(&p, &pos, &grains).unwrap();
    let eps = porosity(&p, pos.len(), &grains, &pairs);
    // ρ̄_a = ε_a ρ0 and θ_a = −∇P/ρ̄_a with ∇P = −ρ0 g ŷ.
    let rho_bar: Vec<f64> = eps.values.iter().map(|e| e * w.density()).collect();
    let theta: Vec<Vector> = rho_bar
        .iter()
        .map(|r| Vector::new(0.0, w.density() * g / r))
        .collect();
    let vel = vec![Vector::zeros(); pos.len()];
    let mass = vec![w.density() * DX * DX; pos.len()];
    let view = fluid_view(&pos, &vel, &mass, &rho_bar);
    let f = coupling_forces(&p, &w, view, &eps.values, &theta, &grains, &pairs).unwrap();
    let archimedes = disc_area(0.5 * D) * w.density() * g;
    assert_eq!(f.drag[0], Vector::zeros());
    assert!(f.on_grains[0].x.abs() < 1e-12 * archimedes);
    assert!((f.on_grains[0].y / archimedes - 1.0).abs() < 1e-12);
    assert!(f.grain_fluid[0].porosity < 1.0);
    // The sphere of the DEM grain takes its own Archimedes force.
    let sphere = sphere_force(f.on_grains[0], 0.5 * D);
    let v_sphere = 4.0 / 3.0 * PI * (0.5 * D).powi(3);
    assert!((sphere.y / (v_sphere * w.density() * g) - 1.0).abs() < 1e-12);
}

#[test]
fn grains_out_of_the_fluid_feel_nothing_and_bad_slices_are_named() {
    let (pos, vel, mass, rho_bar, theta, _) = scattered();
    let grains = vec![grain(1.0, 1.0, 0.0, -100.0)];
    let p = CouplingParams::default();
    let pairs = find_pairs(&p, &pos, &grains).unwrap();
    assert!(pairs.is_empty());
    let eps = porosity(&p, pos.len(), &grains, &pairs);
    let view = fluid_view(&pos, &vel, &mass, &rho_bar);
    let f = water_forces(view, &eps.values, &theta, &grains, &pairs).unwrap();
    assert_eq!(f.on_grains[0], Vector::zeros());
    assert_eq!(f.grain_fluid[0].porosity, 1.0);
    assert!(f.on_fluid.iter().all(|v| *v == Vector::zeros()));
    let e = water_forces(view, &eps.values[1..], &theta, &grains, &pairs).unwrap_err();
    assert_eq!(e.field, "porosity");
    let short = FluidView {
        mass: &mass[1..],
        ..view
    };
    let e = water_forces(short, &eps.values, &theta, &grains, &pairs).unwrap_err();
    assert_eq!(e.field, "fluid.mass");
    let stray = [Pair {
        grain: 3,
        fluid: 0,
        w: 1.0,
    }];
    let e = water_forces(view, &eps.values, &theta, &grains, &stray).unwrap_err();
    assert_eq!(e.field, "pairs");
}
