//! `grit verify --only rock`: the JH-2 rock model (AWJ paper eqs. 38–41, `crate::jh2`) against
//! its formulas, for both presets (docs/verification.md#9-rock-jh-2-only-rock):
//!
//! - the strength surface at D = 0 and D = 1 (and the damaged mean at D = ½), through the
//!   engine's own stress update, against eq. 38 written out here;
//! - uniaxial compression and tension of a material point in the plane-strain form the stress
//!   stage works in, against the intact strength's closed root and the tensile limit T;
//! - the Hugoniot of the polynomial EOS: a uniaxial-strain shock driven through the engine's
//!   continuity and stress update, against ρ0 Us up = σ_x and Us = up (1 + μ)/μ;
//! - bulking energy: the hydrostatic energy (K1 μ + ΔP)²/(2 K1) gains β times the shear energy
//!   the damage released (eq. 41), and ΔP = √(2 β K1 ΔU) at μ = 0;
//! - a spall test in the engine: a block whose halves fly apart at ±v/2 fails at its midplane
//!   above the speed whose release tension reaches T, and stays whole below it.

use super::{fail_at, CaseReport, Row};
use crate::jh2::{self, Jh2Laws, Jh2State};
use crate::material::Material;
use crate::math::{Matrix, Vector};
use crate::particles::von_mises;
use crate::rock::uniaxial_compressive_strength;
use crate::{Motion, Polygon, Settings, World};

/// Relative tolerance of the rows that compare a function with its formula (round-off).
const FORMULA_TOL: f64 = 1e-9;

/// Relative tolerance of the stress-controlled uniaxial rows: the load steps are 0.01 % of the
/// strength.
const UNIAXIAL_TOL: f64 = 1e-3;

/// Relative tolerance of the Hugoniot row: the engine's continuity ρ ← ρ (1 − Δt tr D) is first
/// order in the step, 2 000 steps to μ = 0.1.
const HUGONIOT_TOL: f64 = 1e-3;

fn row(case: String, value: f64, reference: f64, err: f64, tol: f64, note: String) -> Row {
    Row {
        case,
        resolution: "material point".into(),
        value,
        reference,
        error_rel: err,
        pass: err <= tol,
        expected_fail: false,
        note,
    }
}

fn laws(m: &Material) -> Jh2Laws {
    m.jh2().expect("a rock preset has all three JH-2 laws")
}

/// Density of the polynomial EOS at pressure `p` (> 0), by bisection (no bulking).
fn density_at(l: &Jh2Laws, p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if l.eos.cold(mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    l.eos.rho0_kg_m3 * (1.0 + 0.5 * (lo + hi))
}

fn fresh(sdev: Matrix) -> Jh2State {
    Jh2State {
        sdev,
        eps_p: 0.0,
        damage: 0.0,
        bulking: 0.0,
    }
}

/// The strength surface rows of one preset.
fn strength_rows(m: &Material) -> Vec<Row> {
    let l = laws(m);
    let s = l.strength;
    let (phel, ts, shel) = (s.p_hel_pa, s.t_pa / s.p_hel_pa, s.sigma_hel());
    let g = m.shear_modulus();
    let pstars = [0.05, 0.2, 0.5, 1.0, 2.0];
    let mut rows = Vec::new();
    // D = 0 through the update: a trial far above yield returns onto σ_HEL A (P* + T*)^N.
    let (mut worst, mut at_hel) = (0.0f64, (0.0, 0.0));
    for &ps in &pstars {
        let rho = density_at(&l, ps * phel);
        let p = jh2::pressure_of(&l, rho, 0.0, 0.0);
        let formula = shel * s.a * (p / phel + ts).powf(s.n);
        let trial = Matrix::new(-10.0 * shel, 0.0, 0.0, 10.0 * shel);
        // A damage law that cannot damage within the step keeps D = 0 on the surface read.
        let mut frozen = l;
        frozen.damage.d1 = f64::INFINITY;
        let r = jh2::jh2_update(trial, fresh(trial), rho, 0.0, g, &frozen);
        let got = von_mises(&r.state.sdev);
        worst = worst.max((got / formula - 1.0).abs());
        if ps == 1.0 {
            at_hel = (got, formula);
        }
    }
    rows.push(row(
        format!("rock_strength_intact_{}", m.name),
        at_hel.0,
        at_hel.1,
        worst,
        FORMULA_TOL,
        format!(
            "von Mises stress (Pa) the JH-2 update returns a trial 10 σ_HEL above yield to, at D = 0, \
             against σ_HEL A (P* + T*)^N written out with the system's powf (eq. 38); value and \
             reference at P* = 1, error the largest over P* = {pstars:?}; tolerance {FORMULA_TOL:e}"
        ),
    ));
    // D = 1 and D = ½ on the surface the update reads: B P*^M capped at σ*_fmax, and the mean.
    let (mut worst1, mut worst_half, mut at1) = (0.0f64, 0.0f64, (0.0, 0.0));
    for &ps in &pstars {
        let p = ps * phel;
        let fractured = shel * (s.b * ps.powf(s.m)).min(s.sfmax);
        let got = s.yield_stress(p, 0.0, 1.0);
        worst1 = worst1.max((got / fractured - 1.0).abs());
        let intact = shel * s.a * (ps + ts).powf(s.n);
        let half = s.yield_stress(p, 0.0, 0.5);
        worst_half = worst_half.max((half / (0.5 * (intact + fractured)) - 1.0).abs());
        if ps == 1.0 {
            at1 = (got, fractured);
        }
    }
    rows.push(row(
        format!("rock_strength_fractured_{}", m.name),
        at1.0,
        at1.1,
        worst1.max(worst_half),
        FORMULA_TOL,
        format!(
            "yield stress (Pa) at D = 1 against σ_HEL min(B P*^M, σ*_fmax) written out (eq. 38), and at D = ½ against the mean of intact and fractured; value and reference \
             at P* = 1, error the largest over both and P* = {pstars:?}; tolerance {FORMULA_TOL:e}"
        ),
    ));
    rows
}

/// The stress σ > 0 at which a uniaxial stress path first yields in the update: compression
/// (`sign` = 1) has P = σ/3 and deviator diag(σ/3, −2σ/3) (its out-of-plane part σ/3, so
/// σ_xx = σ_zz = 0); tension (`sign` = −1) the opposite. Loaded in steps of 10⁻⁴ of `scale`.
fn uniaxial_yield(l: &Jh2Laws, g: f64, sign: f64, scale: f64) -> f64 {
    let mut frozen = *l;
    frozen.damage.d1 = f64::INFINITY;
    let step = 1e-4 * scale;
    let mut sigma = 0.0;
    loop {
        sigma += step;
        let p = sign * sigma / 3.0;
        let rho = l.eos.rho0_kg_m3 * (1.0 + p / l.eos.k1_pa);
        // The state's pressure must be the path's: in tension K1 μ is exact; in compression
        // the polynomial's root.
        let rho = if p > 0.0 { density_at(l, p) } else { rho };
        let trial = Matrix::new(sign * sigma / 3.0, 0.0, 0.0, -sign * 2.0 * sigma / 3.0);
        let r = jh2::jh2_update(trial, fresh(trial), rho, 0.0, g, &frozen);
        if r.d_eps > 0.0 || sigma > 10.0 * scale {
            return sigma - 0.5 * step;
        }
    }
}

/// The uniaxial tensile strength of intact JH-2 material: the root of
/// σ = σ_HEL A ((T − σ/3)/P_HEL)^N (P = −σ/3), by bisection; below 3T.
fn uniaxial_tensile_strength(l: &Jh2Laws) -> f64 {
    let s = &l.strength;
    crate::rock::bisect(
        |sig| sig - s.sigma_hel() * s.intact(-sig / 3.0, 0.0),
        0.0,
        3.0 * s.t_pa,
    )
}

/// Uniaxial compression and tension, and hydrostatic tension, of one preset.
fn uniaxial_rows(m: &Material) -> Vec<Row> {
    let l = laws(m);
    let g = m.shear_modulus();
    let ucs = uniaxial_compressive_strength(&l.strength);
    let got = uniaxial_yield(&l, g, 1.0, ucs);
    let uts = uniaxial_tensile_strength(&l);
    let got_t = uniaxial_yield(&l, g, -1.0, uts);
    // Hydrostatic tension past T: the pressure stops at −T while intact, at 0 once fractured.
    let rho = l.eos.rho0_kg_m3 * (1.0 - 10.0 * l.strength.t_pa / l.eos.k1_pa);
    let p_intact = jh2::pressure_of(&l, rho, 0.0, 0.0);
    let p_broken = jh2::pressure_of(&l, rho, 0.0, 1.0);
    let t = l.strength.t_pa;
    vec![
        row(
            format!("rock_uniaxial_compression_{}", m.name),
            got,
            ucs,
            (got / ucs - 1.0).abs(),
            UNIAXIAL_TOL,
            format!(
                "axial stress (Pa) at which a uniaxial compression (P = σ/3, σ_xx = σ_zz = 0), \
                 loaded in steps of 10⁻⁴ of the reference, first yields in the JH-2 update, \
                 against the intact strength's root σ = σ_HEL A (σ/(3 P_HEL) + T*)^N; tolerance \
                 {UNIAXIAL_TOL:e}"
            ),
        ),
        row(
            format!("rock_uniaxial_tension_{}", m.name),
            got_t,
            uts,
            (got_t / uts - 1.0).abs(),
            UNIAXIAL_TOL,
            format!(
                "axial stress (Pa) at which a uniaxial tension (P = −σ/3) first yields, against \
                 the root of σ = σ_HEL A ((T − σ/3)/P_HEL)^N ({:.3} T: the tension axis meets the \
                 intact surface before the pressure reaches −T); tolerance {UNIAXIAL_TOL:e}",
                uts / t
            ),
        ),
        row(
            format!("rock_tensile_limit_{}", m.name),
            -p_intact,
            t,
            (-p_intact / t - 1.0).abs() + p_broken.abs() / t,
            FORMULA_TOL,
            format!(
                "hydrostatic tension (Pa) the pressure holds at μ = −10 T/K1 while intact, against \
                 T; error adds the fractured particle's pressure over T (must be 0: −T (1 − D)); \
                 tolerance {FORMULA_TOL:e}"
            ),
        ),
    ]
}

/// The Hugoniot row of one preset: uniaxial strain to μ = 0.1 through the engine's continuity
/// and JH-2 update with damage frozen at 0 and no strength (a hydrodynamic shock), so σ_x = P.
fn hugoniot_row(m: &Material) -> Row {
    let l = laws(m);
    let g = m.shear_modulus();
    let mut frozen = l;
    frozen.damage.d1 = f64::INFINITY;
    frozen.strength.a = 1e-300;
    let rho0 = l.eos.rho0_kg_m3;
    let target: f64 = 0.1;
    let steps = 2000;
    // Constant strain rate d_y whose continuity steps ρ ← ρ (1 + Δt d_y) reach μ = 0.1.
    let dt = 1e-9;
    let dy = ((1.0 + target).powf(1.0 / steps as f64) - 1.0) / dt;
    let d = Matrix::new(0.0, 0.0, 0.0, -dy);
    let mut rho = rho0;
    let mut st = fresh(Matrix::zeros());
    for _ in 0..steps {
        rho *= 1.0 + dt * dy;
        let dev = d - Matrix::identity() * (d.trace() / 3.0);
        let s_trial = st.sdev + dev * (2.0 * g) * dt;
        st = jh2::jh2_update(s_trial, st, rho, dy, g, &frozen).state;
    }
    let mu = rho / rho0 - 1.0;
    let sigma_x = jh2::pressure_of(&l, rho, st.bulking, st.damage) - st.sdev[(1, 1)];
    // Rankine–Hugoniot from rest: ρ0 Us up = σ_x, ρ0 Us = ρ (Us − up) ⇒ Us² = σ_x (1 + μ)/(ρ0 μ).
    let us = (sigma_x * (1.0 + mu) / (rho0 * mu)).sqrt();
    let p_ref = target * (l.eos.k1_pa + target * (l.eos.k2_pa + target * l.eos.k3_pa));
    let us_ref = (p_ref * (1.0 + target) / (rho0 * target)).sqrt();
    let up_ref = us_ref * target / (1.0 + target);
    row(
        format!("rock_hugoniot_{}", m.name),
        us,
        us_ref,
        (us / us_ref - 1.0).abs(),
        HUGONIOT_TOL,
        format!(
            "shock speed Us (m/s) of a hydrodynamic uniaxial-strain shock to μ = 0.1, from the \
             stress the engine's continuity and update leave ({steps} steps, strength off), against \
             Us² = P(μ)(1 + μ)/(ρ0 μ) with P = K1 μ + K2 μ² + K3 μ³ (eq. 40; up = {up_ref:.1} m/s, \
             P = {p_ref:.4e} Pa); tolerance {HUGONIOT_TOL:e}"
        ),
    )
}

/// Bulking energy rows of one preset: a point held at μ = 0.01 sheared past yield until
/// fractured, and one at μ = 0.
fn bulking_rows(m: &Material) -> Vec<Row> {
    let l = laws(m);
    let g = m.shear_modulus();
    let k1 = l.eos.k1_pa;
    let mu = 0.01;
    let rho = l.eos.rho0_kg_m3 * (1.0 + mu);
    let mut st = fresh(Matrix::zeros());
    let (mut released, mut steps) = (0.0, 0);
    let shel = l.strength.sigma_hel();
    let energy = |dp: f64| (k1 * mu + dp).powi(2) / (2.0 * k1);
    let e0 = energy(0.0);
    // Pure shear loading in steps of 1 % of σ_HEL of trial stress.
    while st.damage < 1.0 && steps < 1_000_000 {
        let s_trial = st.sdev + Matrix::new(0.0, 0.01 * shel, 0.01 * shel, 0.0);
        let r = jh2::jh2_update(s_trial, st, rho, 0.0, g, &l);
        released += r.released;
        st = r.state;
        steps += 1;
    }
    let gained = energy(st.bulking) - e0;
    let want = l.eos.beta * released;
    // At μ = 0 one release gives ΔP = √(2 β K1 ΔU) from ΔP = 0.
    let du = 1e4;
    let dp = l.eos.bulked(0.0, 0.0, du);
    let dp_ref = (2.0 * l.eos.beta * k1 * du).sqrt();
    vec![
        row(
            format!("rock_bulking_energy_{}", m.name),
            gained,
            want,
            (gained / want - 1.0).abs(),
            FORMULA_TOL,
            format!(
                "gain (J/m³) of the hydrostatic energy (K1 μ + ΔP)²/(2 K1) at μ = {mu} while pure \
                 shear damages a point to D = 1 ({steps} steps, ΔP = {:.4e} Pa), against β ΣΔU, \
                 the shear energy σ_y²/(6G) the damage released times β (eq. 41); tolerance \
                 {FORMULA_TOL:e}",
                st.bulking
            ),
        ),
        row(
            format!("rock_bulking_zero_strain_{}", m.name),
            dp,
            dp_ref,
            (dp / dp_ref - 1.0).abs(),
            FORMULA_TOL,
            format!(
                "bulking pressure (Pa) after releasing ΔU = {du:e} J/m³ at μ = 0 from ΔP = 0, \
                 against √(2 β K1 ΔU); tolerance {FORMULA_TOL:e}"
            ),
        ),
    ]
}

/// The speed v at which a block's halves flying apart at ±v/2 put the hydrostatic tension T at
/// its midplane in uniaxial strain: the release stress ρ0 c_L v/2 has pressure part
/// K/(K + 4G/3) of it, so v = 2 T (K + 4G/3)/(K ρ0 c_L).
pub fn spall_speed(m: &Material) -> f64 {
    let l = laws(m);
    let (k, g) = (l.eos.k1_pa, m.shear_modulus());
    let m_mod = k + 4.0 / 3.0 * g;
    let c_l = (m_mod / l.eos.rho0_kg_m3).sqrt();
    2.0 * l.strength.t_pa * m_mod / (k * l.eos.rho0_kg_m3 * c_l)
}

/// Runs a block of `nx` × `ny` particles at spacing `dx` whose halves fly apart at ±v/2 for the
/// time a wave takes across half of it; returns (fractured particles, mean |x| of their start
/// over dx, largest damage, the lowest density over its least, `jh2::least_density`).
fn spall_run(
    m: &Material,
    nx: usize,
    ny: usize,
    dx: f64,
    v: f64,
) -> Result<(u64, f64, f64, f64), crate::SimError> {
    let settings = Settings::water_jet(dx, Vector::zeros());
    let (hx, hy) = (0.5 * nx as f64 * dx, 0.5 * ny as f64 * dx);
    let block = Polygon::rectangle(-hx, -hy, hx, hy);
    let pts = block.fill_lattice(dx, Vector::new(0.5 * dx, 0.5 * dx));
    let vols = vec![dx * dx; pts.len()];
    let mut w = World::new(settings.clone()).map_err(|e| super::fail(e.to_string()))?;
    let b = w
        .add_deformable("block", m.clone(), &pts, &vols, Vector::zeros())
        .map_err(|e| super::fail(e.to_string()))?;
    let mut state = w.body_state(b);
    for (vel, x) in state.vel.iter_mut().zip(&state.pos) {
        *vel = Vector::new(0.5 * v * x.x.signum(), 0.0);
    }
    let mut w = World::new(settings).map_err(|e| super::fail(e.to_string()))?;
    w.add_deformable_state("block", m.clone(), state, Motion::Free)
        .map_err(|e| super::fail(e.to_string()))?;
    let ids0: Vec<(u32, f64)> = {
        let p = w.particles();
        p.id.iter()
            .copied()
            .zip(p.pos.iter().map(|x| x.x))
            .collect()
    };
    let c_l = m.sound_speed();
    let t_end = hx / c_l;
    while w.time() < t_end {
        w.step()?;
        if w.steps() > 100_000 {
            return Err(fail_at(&w, "spall run took over 100 000 steps".into()));
        }
    }
    // Fractured rock stays in the world (docs/jet.md#rock-targets): failed = at D = 1.
    let p = w.particles();
    let failed: std::collections::HashSet<u32> =
        p.id.iter()
            .zip(&p.damage)
            .filter(|(_, &d)| d >= 1.0)
            .map(|(&id, _)| id)
            .collect();
    let gone: Vec<f64> = ids0
        .iter()
        .filter(|(id, _)| failed.contains(id))
        .map(|&(_, x)| x.abs() / dx)
        .collect();
    let mean_x = if gone.is_empty() {
        0.0
    } else {
        gone.iter().sum::<f64>() / gone.len() as f64
    };
    let dmax = p.damage.iter().copied().fold(0.0, f64::max);
    let l = laws(m);
    let thinnest = (0..p.len())
        .map(|i| p.rho[i] / crate::jh2::least_density(&l, p.bulking[i], p.damage[i]))
        .fold(f64::INFINITY, f64::min);
    Ok((gone.len() as u64, mean_x, dmax, thinnest))
}

/// Spall rows of one preset: below and above the spall speed.
fn spall_rows(m: &Material, nx: usize) -> Result<Vec<Row>, crate::SimError> {
    let dx = 5e-5;
    let ny = nx / 2;
    let vc = spall_speed(m);
    let (below, above) = (0.4, 2.0);
    let (n_lo, _, d_lo, _) = spall_run(m, nx, ny, dx, below * vc)?;
    let (n_hi, x_hi, _, thinnest) = spall_run(m, nx, ny, dx, above * vc)?;
    let res = format!("dx={dx} m, {nx}x{ny} particles");
    Ok(vec![
        Row {
            case: format!("rock_spall_below_{}", m.name),
            resolution: res.clone(),
            value: n_lo as f64,
            reference: 0.0,
            error_rel: n_lo as f64,
            pass: n_lo == 0,
            expected_fail: false,
            note: format!(
                "particles failed (D = 1) when the block's halves fly apart at ±{:.3} m/s, \
                 {below} of the spall speed {vc:.3} m/s = 2 T (K + 4G/3)/(K ρ0 c_L); must be 0 \
                 (largest damage {d_lo:.3})",
                0.5 * below * vc
            ),
        },
        Row {
            case: format!("rock_spall_above_{}", m.name),
            resolution: res,
            value: x_hi,
            reference: 0.0,
            error_rel: x_hi,
            // Rounding of ρ0 (1 + μ) against the clamp's own: a part in 10¹².
            pass: n_hi > 0 && x_hi <= 2.0 && thinnest >= 1.0 - 1e-12,
            expected_fail: false,
            note: format!(
                "mean distance, in spacings, of the failed particles' start from the midplane at \
                 {above} of the spall speed ({n_hi} failed); must fail, within 2 spacings of it, \
                 and no particle thinner than its least density (lowest ρ over it {thinnest:.6}; \
                 0.99 without it)"
            ),
        },
    ])
}

/// Every rock row for both presets; `nx` particles along the spall block.
pub fn run(nx: usize) -> Result<CaseReport, crate::SimError> {
    let mut rep = CaseReport::default();
    for m in [Material::sandstone(), Material::granite()] {
        rep.rows.extend(strength_rows(&m));
        rep.rows.extend(uniaxial_rows(&m));
        rep.rows.push(hugoniot_row(&m));
        rep.rows.extend(bulking_rows(&m));
        rep.rows.extend(spall_rows(&m, nx)?);
    }
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_rock_row_passes_at_the_ci_resolution() {
        let rep = run(24).unwrap();
        for r in &rep.rows {
            println!(
                "{} {} {} {} {}",
                r.case, r.value, r.reference, r.error_rel, r.pass
            );
        }
        for r in &rep.rows {
            assert!(
                r.pass,
                "{}: {} vs {} ({})",
                r.case, r.value, r.reference, r.note
            );
        }
        assert_eq!(rep.rows.len(), 2 * 10);
    }
}
