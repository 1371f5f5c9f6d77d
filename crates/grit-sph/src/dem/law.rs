//! Contact force laws of the DEM abrasives: the soft-sphere spring–dashpot with a Coulomb cap
//! (Cundall & Strack 1979; the water-jet paper's eqs. 2–3, 10–11) and the abrasive–SPH-particle
//! penalty contact (its eqs. 12–14); the paper is Sci. Rep. 14:26115 (2024), docs/jet.md#dem-abrasives.

use crate::math::{perp, Vector};
use crate::world::PenaltyParams;

/// Damping ratio ξ = −ln e / √(π² + ln² e) that makes a linear spring–dashpot rebound with
/// restitution coefficient `e` (docs/jet.md#dem-abrasives).
pub fn damping_ratio(restitution: f64) -> f64 {
    let l = crate::math::ln(restitution);
    -l / (std::f64::consts::PI * std::f64::consts::PI + l * l).sqrt()
}

/// Normal stiffness k_n = 2 E_i R_i E_j R_j / (E_i R_i + E_j R_j) (N/m) of two grains; a rigid
/// flat wall (E_j R_j → ∞) gives [`wall_stiffness`].
pub fn pair_stiffness(e_i: f64, r_i: f64, e_j: f64, r_j: f64) -> f64 {
    let (a, b) = (e_i * r_i, e_j * r_j);
    2.0 * a * b / (a + b)
}

/// Normal stiffness 2 E R (N/m) of a grain on a rigid flat wall, the limit of [`pair_stiffness`].
pub fn wall_stiffness(e: f64, r: f64) -> f64 {
    2.0 * e * r
}

/// Dashpot coefficient d = 2 ξ √(m* k) (N·s/m) for reduced mass `m_star` and stiffness `k`.
pub fn dashpot(xi: f64, m_star: f64, k: f64) -> f64 {
    2.0 * xi * (m_star * k).sqrt()
}

/// Duration π / (ω0 √(1 − ξ²)), ω0 = √(k/m*), of a linear spring–dashpot contact (s).
pub fn contact_time(k: f64, m_star: f64, xi: f64) -> f64 {
    std::f64::consts::PI / ((k / m_star).sqrt() * (1.0 - xi * xi).sqrt())
}

/// Constants of one contact's spring–dashpot (normal and tangential).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpringDashpot {
    /// Normal stiffness k_n (N/m).
    pub k_n: f64,
    /// Normal dashpot d_n (N·s/m).
    pub d_n: f64,
    /// Tangential stiffness k_t (N/m).
    pub k_t: f64,
    /// Tangential dashpot d_t (N·s/m).
    pub d_t: f64,
    /// Coulomb friction coefficient μ (–).
    pub friction: f64,
}

/// Forces of one contact on its second body, along n and t = perp(n); the first body takes the
/// opposite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactForce {
    /// Normal force f_n (N; > 0 pushes the bodies apart).
    pub normal: f64,
    /// Tangential force f_t along t (N), |f_t| ≤ μ |f_n|.
    pub tangential: f64,
    /// True when the Coulomb cap was active (the contact slides).
    pub sliding: bool,
}

impl SpringDashpot {
    /// Soft-sphere contact: f_n = k_n δ − d_n v_n and f_t = −k_t δ_t − d_t v_t with
    /// |f_t| ≤ μ |f_n| (Cundall & Strack 1979; the paper's form, with no clamp of f_n at zero).
    ///
    /// `overlap` δ > 0, `v_rel` is the velocity of the second body's contact point minus the
    /// first's, `n` the unit normal from the first body to the second. `delta_t` is the
    /// tangential spring of this contact, advanced by v_t dt; while sliding it is reset to the
    /// stretch that carries the capped force alone, so the spring never stores more than μ |f_n|.
    pub fn force(
        &self,
        n: Vector,
        overlap: f64,
        v_rel: Vector,
        delta_t: &mut f64,
        dt: f64,
    ) -> ContactForce {
        let v_n = v_rel.dot(&n);
        let v_t = v_rel.dot(&perp(n));
        let normal = self.k_n * overlap - self.d_n * v_n;
        *delta_t += v_t * dt;
        let trial = -self.k_t * *delta_t - self.d_t * v_t;
        let cap = self.friction * normal.abs();
        if trial.abs() > cap {
            let tangential = cap.copysign(trial);
            *delta_t = -tangential / self.k_t;
            ContactForce {
                normal,
                tangential,
                sliding: true,
            }
        } else {
            ContactForce {
                normal,
                tangential: trial,
                sliding: false,
            }
        }
    }
}

/// One abrasive–particle penalty contact (the paper's eqs. 12–14).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PenaltyContact {
    /// Force on the SPH particle (N, or N/m when the mass is per unit depth); the grain takes
    /// the opposite.
    pub force_on_particle: Vector,
    /// Contact point p on the grain's surface, where the grain's reaction acts (its torque is
    /// (p − x_g) × (−force_on_particle), eq. 14).
    pub point: Vector,
}

/// Penalty contact between an SPH target particle and an abrasive grain (the paper's eqs. 12–13).
///
/// With d_p = |x_a − x_i| − R_i (particle a to the surface of grain i), contact when d_p < `d_ini`:
/// F^n = (1 − χ)(2 m_a/Δt²)(d_ini − d_p) n_p, n_p from the grain's centre to the particle, and
/// F^t = min(2 m_a/Δt |v_pa·t_p|, μ |F^n|) sign(v_pa·t_p) t_p, with v_pa = v_p − v_a the surface
/// point's velocity relative to the particle (eq. 13 prints min() of a vector and a scalar; it is
/// read as this magnitude cap with the direction of v_pa·t_p). `m_p` may be a mass per unit depth
/// (the force is then per unit depth). χ and μ are `law`'s. `None` when apart.
pub fn penalty_force(
    x_p: Vector,
    v_p: Vector,
    m_p: f64,
    grain: &super::Grain,
    d_ini: f64,
    law: PenaltyParams,
    dt: f64,
) -> Option<PenaltyContact> {
    let PenaltyParams { chi, friction } = law;
    let r = x_p - grain.pos;
    let dist = r.norm();
    let d_p = dist - grain.radius_m;
    if d_p >= d_ini || dist == 0.0 {
        return None;
    }
    let n = r / dist;
    let t = perp(n);
    let surface_v = grain.vel + crate::math::omega_cross(grain.omega, n * grain.radius_m);
    let v_t = (surface_v - v_p).dot(&t);
    let f_n = (1.0 - chi) * 2.0 * m_p / (dt * dt) * (d_ini - d_p);
    let f_t = (2.0 * m_p / dt * v_t.abs()).min(friction * f_n.abs());
    Some(PenaltyContact {
        force_on_particle: n * f_n + t * f_t.copysign(v_t),
        point: grain.pos + n * grain.radius_m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damping_ratio_inverts_the_restitution_law() {
        for e in [0.1, 0.5, 0.8, 0.99] {
            let xi = damping_ratio(e);
            let back = (-xi * std::f64::consts::PI / (1.0 - xi * xi).sqrt()).exp();
            assert!((back - e).abs() < 1e-14, "e {e}");
        }
        assert_eq!(damping_ratio(1.0), 0.0);
    }

    #[test]
    fn stiffness_of_the_garnet_grain_keeps_the_sphere_k_over_m() {
        // Garnet-like abrasive, d = 0.2 mm, E 248 GPa, ρ 4120: k_n/m ≈ 1.44e15 s⁻².
        let r = 1e-4;
        let k = pair_stiffness(248e9, r, 248e9, r);
        assert!((k - 248e9 * r).abs() < 1e-3);
        let m = 4120.0 * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
        assert!((k / m / 1.44e15 - 1.0).abs() < 0.01, "{}", k / m);
        // The rigid wall is the limit of an ever stiffer partner.
        let far = pair_stiffness(248e9, r, 248e9 * 1e12, 1.0);
        assert!((far / wall_stiffness(248e9, r) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn coulomb_cap_holds_and_resets_the_spring() {
        let law = SpringDashpot {
            k_n: 1e6,
            d_n: 0.0,
            k_t: 1e6,
            d_t: 0.0,
            friction: 0.3,
        };
        let n = Vector::new(0.0, 1.0);
        let mut delta_t = 0.0;
        // t = perp(n) = (−1, 0), so sliding along −x is v_t = +10: capped at μ f_n, along −t.
        let f = law.force(n, 1e-6, Vector::new(-10.0, 0.0), &mut delta_t, 1e-3);
        assert!((f.normal - 1.0).abs() < 1e-12);
        assert!(f.sliding);
        assert!((f.tangential.abs() - 0.3).abs() < 1e-12);
        assert!(f.tangential < 0.0);
        assert!((-law.k_t * delta_t - f.tangential).abs() < 1e-12);
        // A small slip stays elastic.
        let mut delta_t = 0.0;
        let f = law.force(n, 1e-6, Vector::new(-1e-3, 0.0), &mut delta_t, 1e-6);
        assert!(!f.sliding);
        assert!((f.tangential + 1e-3).abs() < 1e-15);
    }

    #[test]
    fn penalty_pushes_the_particle_out_and_friction_opposes_sliding() {
        let g = super::super::Grain::sphere(Vector::zeros(), 1e-4, 4120.0);
        let (m_p, d_ini, dt) = (1e-6, 5e-5, 1e-8);
        let law = |chi, friction| PenaltyParams { chi, friction };
        // Particle 20 µm off the surface along +y: inside the 50 µm range, overlap 30 µm.
        let x_p = Vector::new(0.0, 1.2e-4);
        let c = penalty_force(x_p, Vector::zeros(), m_p, &g, d_ini, law(0.0, 0.3), dt).unwrap();
        assert!((c.point - Vector::new(0.0, 1e-4)).norm() < 1e-18);
        let f = c.force_on_particle;
        let expect = 2.0 * m_p / (dt * dt) * 3e-5;
        assert!((f.y / expect - 1.0).abs() < 1e-12 && f.x == 0.0);
        // Half of it with χ = 0.5.
        let h = penalty_force(x_p, Vector::zeros(), m_p, &g, d_ini, law(0.5, 0.3), dt)
            .unwrap()
            .force_on_particle;
        assert!((h.y / (0.5 * expect) - 1.0).abs() < 1e-12);
        let sliding = |speed| {
            let v = Vector::new(speed, 0.0);
            penalty_force(x_p, v, m_p, &g, d_ini, law(0.0, 0.3), dt)
                .unwrap()
                .force_on_particle
        };
        // Sliding fast along +x: friction along −x, capped at μ F^n.
        let s = sliding(1e4);
        assert!((s.x / (-0.3 * expect) - 1.0).abs() < 1e-12, "{s:?}");
        // Slow sliding: the force that stops it in half a step, below the cap.
        let s = sliding(1e-3);
        assert!((s.x / (-2.0 * m_p / dt * 1e-3) - 1.0).abs() < 1e-12);
        // A spinning grain drags a resting particle along its surface: ω > 0 moves the top
        // point towards −x.
        let spun = super::super::Grain {
            omega: 1e5,
            ..g.clone()
        };
        let d = penalty_force(x_p, Vector::zeros(), m_p, &spun, d_ini, law(0.0, 0.3), dt)
            .unwrap()
            .force_on_particle;
        assert!(d.x < 0.0, "{d:?}");
        // Out of range.
        let far = Vector::new(0.0, 1.6e-4);
        assert!(penalty_force(far, Vector::zeros(), m_p, &g, d_ini, law(0.0, 0.3), dt).is_none());
    }
}
