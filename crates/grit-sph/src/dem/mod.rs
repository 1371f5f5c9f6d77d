//! DEM abrasives of the water-jet scene: soft-sphere discs with rotation, grain–grain and
//! grain–wall contacts, integrated in a fixed order (docs/jet.md#dem-abrasives).
//!
//! The scene is 2D but a grain keeps the mass and moment of inertia of the sphere it stands for,
//! so k_n/m, the contact time and the restitution are the sphere's (the water-jet paper,
//! Sci. Rep. 14:26115, 2024, section on abrasives).

mod law;
#[cfg(test)]
mod tests;

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::error::InputError;
use crate::math::{cross, omega_cross, perp, Vector};

pub use law::{
    contact_time, damping_ratio, dashpot, pair_stiffness, penalty_force, wall_stiffness,
    ContactForce, PenaltyContact, SpringDashpot,
};

/// The paper's DEM time-step factor α_tn in Δt ≤ (2π/α_tn) √(m/k_n).
pub const ALPHA_TN: f64 = 300.0;

/// One abrasive grain: a disc in the plane with a sphere's mass and inertia.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Grain {
    /// Centre (m).
    pub pos: Vector,
    /// Velocity (m/s).
    pub vel: Vector,
    /// Rotation angle about z (rad).
    pub angle: f64,
    /// Angular velocity about z (rad/s).
    pub omega: f64,
    /// Radius R (m).
    pub radius_m: f64,
    /// Mass m (kg).
    pub mass_kg: f64,
    /// Moment of inertia about the centre (kg·m²).
    pub inertia_kg_m2: f64,
    /// Whether the grain has touched a deformable particle yet (the penalty contact of the AWJ
    /// paper eqs. 12–14); its first touch is logged as a [`crate::world::GrainHit`]. Absent from
    /// the JSON while false, so grains stored before it keep their bytes.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub touched: bool,
    /// Whether the grain touched a deformable particle in the last step: a step in which it
    /// touches and did not before starts a contact (logged as a [`crate::world::GrainHit`]).
    /// Absent from the JSON while false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub in_contact: bool,
}

impl Grain {
    /// A solid sphere of radius `r` and density `rho` at rest at `pos`: m = 4/3 π R³ ρ,
    /// I = 2/5 m R².
    pub fn sphere(pos: Vector, r: f64, rho: f64) -> Self {
        let mass = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * rho;
        Grain {
            pos,
            vel: Vector::zeros(),
            angle: 0.0,
            omega: 0.0,
            radius_m: r,
            mass_kg: mass,
            inertia_kg_m2: 0.4 * mass * r * r,
            touched: false,
            in_contact: false,
        }
    }

    /// Linear momentum m v (kg·m/s).
    pub fn momentum(&self) -> Vector {
        self.vel * self.mass_kg
    }

    /// Kinetic energy, translation plus rotation (J).
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.mass_kg * self.vel.norm_squared()
            + 0.5 * self.inertia_kg_m2 * self.omega * self.omega
    }
}

/// A rigid, fixed, infinite straight wall: grains stay on the side `normal` points to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Wall {
    /// A point on the wall (m).
    pub point: Vector,
    /// Unit normal pointing into the domain ([`Wall::new`] normalises it; [`Dem::new`] checks it).
    pub normal: Vector,
}

impl Wall {
    /// The wall through `point` with normal along `normal` (normalised here).
    pub fn new(point: Vector, normal: Vector) -> Result<Self, InputError> {
        let len = normal.norm();
        if !(len.is_finite() && len > 0.0) {
            return Err(InputError::new(
                "wall.normal",
                format!("must be a finite non-zero vector, got {normal:?}"),
            ));
        }
        Ok(Wall {
            point,
            normal: normal / len,
        })
    }
}

/// Contact constants shared by all grains (docs/jet.md#dem-abrasives).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemParams {
    /// Young's modulus E of the grains (Pa), for k_n = 2 E_i R_i E_j R_j / (E_i R_i + E_j R_j)
    /// (the paper's eq. 10).
    pub youngs_modulus_pa: f64,
    /// Restitution coefficient e in (0, 1]; sets the damping ratio ξ.
    pub restitution: f64,
    /// Coulomb friction coefficient μ (–).
    pub friction: f64,
    /// Poisson's ratio ν of the grains: the paper's eq. 10 makes k_t = ν k_n for one material.
    pub poisson_ratio: f64,
}

impl Default for DemParams {
    /// The paper's garnet-like abrasive (E 248 GPa, ν 0.3); e and μ are this project's choices,
    /// the paper gives none (docs/jet.md#dem-abrasives).
    fn default() -> Self {
        DemParams {
            youngs_modulus_pa: 248e9,
            poisson_ratio: 0.3,
            restitution: 0.8,
            friction: 0.3,
        }
    }
}

impl DemParams {
    /// Checks every constant; errors name `dem.<field>` and the rule.
    pub fn validate(&self) -> Result<(), InputError> {
        InputError::require_positive("dem.youngs_modulus_pa", self.youngs_modulus_pa)?;
        if !(self.poisson_ratio > 0.0 && self.poisson_ratio < 0.5) {
            return Err(InputError::new(
                "dem.poisson_ratio",
                format!(
                    "must lie in (0, 0.5) (k_t = ν k_n must be > 0), got {}",
                    self.poisson_ratio
                ),
            ));
        }
        if !(self.restitution > 0.0 && self.restitution <= 1.0) {
            return Err(InputError::new(
                "dem.restitution",
                format!("must lie in (0, 1], got {}", self.restitution),
            ));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(InputError::new(
                "dem.friction",
                format!("must be a finite number >= 0, got {}", self.friction),
            ));
        }
        Ok(())
    }

    /// Spring–dashpot of two grains. The dashpot uses the reduced mass m* = m_i m_j/(m_i + m_j),
    /// the mass for which the rebound has restitution e (the paper's eq. 11 writes m).
    pub fn pair_law(&self, a: &Grain, b: &Grain) -> SpringDashpot {
        let e = self.youngs_modulus_pa;
        let k_n = pair_stiffness(e, a.radius_m, e, b.radius_m);
        let m_star = a.mass_kg * b.mass_kg / (a.mass_kg + b.mass_kg);
        self.law(k_n, m_star)
    }

    /// Spring–dashpot of a grain on a rigid wall (k_n = 2 E R, m* = m).
    pub fn wall_law(&self, g: &Grain) -> SpringDashpot {
        self.law(
            wall_stiffness(self.youngs_modulus_pa, g.radius_m),
            g.mass_kg,
        )
    }

    fn law(&self, k_n: f64, m_star: f64) -> SpringDashpot {
        let xi = damping_ratio(self.restitution);
        // Eq. 10's k_t with one E and ν for all grains (and a rigid wall) is ν k_n.
        let k_t = self.poisson_ratio * k_n;
        SpringDashpot {
            k_n,
            d_n: dashpot(xi, m_star, k_n),
            k_t,
            d_t: dashpot(xi, m_star, k_t),
            friction: self.friction,
        }
    }

    /// The paper's DEM step limit (2π/α_tn) √(m/k_n) for a grain, taken on the stiffest
    /// contact it can have (a wall, 2 E R).
    pub fn time_step(&self, g: &Grain) -> f64 {
        2.0 * std::f64::consts::PI / ALPHA_TN
            * (g.mass_kg / wall_stiffness(self.youngs_modulus_pa, g.radius_m)).sqrt()
    }
}

/// Where two bodies touch in a step: along `n`, from the first body to the second, by `overlap`
/// (m), the second's contact point moving at `v_rel` relative to the first's.
#[derive(Debug, Clone, Copy)]
struct Touch {
    key: ContactKey,
    n: Vector,
    overlap: f64,
    v_rel: Vector,
}

/// Which bodies a contact joins: two grains (lower index first) or a grain and a wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum ContactKey {
    /// Grains i < j.
    Pair(u32, u32),
    /// Grain, wall.
    Wall(u32, u32),
}

/// One active contact of the last step, for diagnostics and verification.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactReport {
    /// The bodies in contact.
    pub key: ContactKey,
    /// Unit normal from the first body to the second (for a wall: from the grain into the wall).
    pub normal: Vector,
    /// Overlap δ (m).
    pub overlap: f64,
    /// Force on the second body along n and t = perp(n).
    pub force: ContactForce,
}

/// A set of grains and walls advanced together; loops run in grain index order, so a run is
/// bit-for-bit repeatable, also across a checkpoint (serde) and resume.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Dem {
    /// The grains; their index is their identity in contacts. Append freely (an inlet); remove
    /// only through [`Dem::retain`], which keeps the contact springs on the right grains.
    pub grains: Vec<Grain>,
    /// Fixed walls.
    pub walls: Vec<Wall>,
    /// Contact constants.
    pub params: DemParams,
    /// Gravity (m/s²).
    pub gravity: Vector,
    /// Tangential spring stretch δ_t per active contact; dropped when the contact opens.
    #[serde(with = "spring_list")]
    springs: BTreeMap<ContactKey, f64>,
    #[serde(skip)]
    reports: Vec<ContactReport>,
    #[serde(skip)]
    force: Vec<Vector>,
    #[serde(skip)]
    torque: Vec<f64>,
}

/// JSON maps need string keys: the springs travel as a list of (key, δ_t) in key order.
mod spring_list {
    use super::ContactKey;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    use std::collections::BTreeMap;

    pub fn serialize<S: Serializer>(
        m: &BTreeMap<ContactKey, f64>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        m.iter().collect::<Vec<_>>().serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<BTreeMap<ContactKey, f64>, D::Error> {
        Ok(Vec::<(ContactKey, f64)>::deserialize(d)?
            .into_iter()
            .collect())
    }
}

fn validate_grain(i: usize, g: &Grain) -> Result<(), InputError> {
    for (name, v) in [
        ("radius_m", g.radius_m),
        ("mass_kg", g.mass_kg),
        ("inertia_kg_m2", g.inertia_kg_m2),
    ] {
        InputError::require_positive(format!("grains[{i}].{name}"), v)?;
    }
    let finite = [g.pos.x, g.pos.y, g.vel.x, g.vel.y, g.angle, g.omega];
    if finite.iter().any(|v| !v.is_finite()) {
        return Err(InputError::new(
            format!("grains[{i}]"),
            "position, velocity, angle and spin must be finite",
        ));
    }
    Ok(())
}

impl Dem {
    /// A system of `grains` and `walls` under `gravity`; checks the inputs.
    pub fn new(
        grains: Vec<Grain>,
        walls: Vec<Wall>,
        params: DemParams,
        gravity: Vector,
    ) -> Result<Self, InputError> {
        params.validate()?;
        for (i, g) in grains.iter().enumerate() {
            validate_grain(i, g)?;
        }
        for (w, wall) in walls.iter().enumerate() {
            let finite = wall
                .point
                .iter()
                .chain(wall.normal.iter())
                .all(|v| v.is_finite());
            if !finite || (wall.normal.norm() - 1.0).abs() > 1e-9 {
                return Err(InputError::new(
                    format!("walls[{w}]"),
                    "point must be finite and normal a unit vector (build it with Wall::new)",
                ));
            }
        }
        if grains.len() > u32::MAX as usize {
            return Err(InputError::new("grains", "at most 2^32 - 1 grains"));
        }
        Ok(Dem {
            force: vec![Vector::zeros(); grains.len()],
            torque: vec![0.0; grains.len()],
            grains,
            walls,
            params,
            gravity,
            springs: BTreeMap::new(),
            reports: Vec::new(),
        })
    }

    /// Adds a grain (an inlet), checked like those given to [`Dem::new`].
    pub fn add(&mut self, g: Grain) -> Result<(), InputError> {
        validate_grain(self.grains.len(), &g)?;
        self.grains.push(g);
        Ok(())
    }

    /// Keeps the grains for which `keep` is true (an outlet deletes the others), in their order;
    /// the contact springs follow their grains to the new indices, those of removed grains go.
    pub fn retain(&mut self, mut keep: impl FnMut(&Grain) -> bool) {
        let mut new_index = vec![None; self.grains.len()];
        let mut next = 0u32;
        for (i, g) in self.grains.iter().enumerate() {
            if keep(g) {
                new_index[i] = Some(next);
                next += 1;
            }
        }
        let mut k = 0;
        self.grains.retain(|_| {
            k += 1;
            new_index[k - 1].is_some()
        });
        let remap = |key: &ContactKey| match *key {
            ContactKey::Pair(i, j) => Some(ContactKey::Pair(
                new_index[i as usize]?,
                new_index[j as usize]?,
            )),
            ContactKey::Wall(i, w) => Some(ContactKey::Wall(new_index[i as usize]?, w)),
        };
        self.springs = self
            .springs
            .iter()
            .filter_map(|(key, d)| remap(key).map(|k| (k, *d)))
            .collect();
        self.reports.clear();
    }

    /// The contacts of the last step, in key order.
    pub fn contacts(&self) -> &[ContactReport] {
        &self.reports
    }

    /// The largest stable step of the set: [`DemParams::time_step`] of its lightest, stiffest grain.
    pub fn time_step(&self) -> f64 {
        self.grains
            .iter()
            .map(|g| self.params.time_step(g))
            .fold(f64::INFINITY, f64::min)
    }

    /// Total linear momentum (kg·m/s).
    pub fn momentum(&self) -> Vector {
        self.grains.iter().map(Grain::momentum).sum()
    }

    /// Total kinetic energy (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.grains.iter().map(Grain::kinetic_energy).sum()
    }

    /// Advances by `dt` (symplectic Euler, the kick–drift form of leap-frog): contact forces
    /// from the current state plus gravity plus `external[i]` (a coupling force, N; empty for
    /// none) kick the velocities, which then move the grains.
    pub fn step(&mut self, dt: f64, external: &[Vector]) -> Result<(), InputError> {
        self.step_loaded(dt, external, &[])
    }

    /// [`Dem::step`] with external torques too (`external_torque[i]` about grain i's centre,
    /// N·m; empty for none): the penalty contact with a target acts at the grain's surface
    /// (the AWJ paper eq. 14).
    pub fn step_loaded(
        &mut self,
        dt: f64,
        external: &[Vector],
        external_torque: &[f64],
    ) -> Result<(), InputError> {
        InputError::require_positive("dt", dt)?;
        for (name, len, what) in [
            ("external", external.len(), "force"),
            ("external_torque", external_torque.len(), "torque"),
        ] {
            if len != 0 && len != self.grains.len() {
                return Err(InputError::new(
                    name,
                    format!(
                        "must be empty or hold one {what} per grain ({}), got {len}",
                        self.grains.len()
                    ),
                ));
            }
        }
        self.contact_forces(dt);
        for (i, g) in self.grains.iter_mut().enumerate() {
            let f_ext = external.get(i).copied().unwrap_or_else(Vector::zeros);
            let t_ext = external_torque.get(i).copied().unwrap_or(0.0);
            g.vel += (self.force[i] + f_ext) / g.mass_kg * dt + self.gravity * dt;
            g.omega += (self.torque[i] + t_ext) / g.inertia_kg_m2 * dt;
            g.pos += g.vel * dt;
            g.angle += g.omega * dt;
        }
        Ok(())
    }

    /// Fills `force`, `torque`, the contact reports, and advances the tangential springs.
    fn contact_forces(&mut self, dt: f64) {
        // Sized here, not at construction: grains may have been added or the set restored from
        // a checkpoint since the last step.
        let n = self.grains.len();
        self.force.clear();
        self.force.resize(n, Vector::zeros());
        self.torque.clear();
        self.torque.resize(n, 0.0);
        self.reports.clear();
        let mut springs = BTreeMap::new();
        for (i, j) in self.candidate_pairs() {
            let (a, b) = (&self.grains[i], &self.grains[j]);
            let d = b.pos - a.pos;
            let dist = d.norm();
            let overlap = a.radius_m + b.radius_m - dist;
            if overlap <= 0.0 || dist == 0.0 {
                continue;
            }
            let n = d / dist;
            let v_rel = b.vel + omega_cross(b.omega, -n * b.radius_m)
                - a.vel
                - omega_cross(a.omega, n * a.radius_m);
            let (law, ra, rb) = (self.params.pair_law(a, b), a.radius_m, b.radius_m);
            let touch = Touch {
                key: ContactKey::Pair(i as u32, j as u32),
                n,
                overlap,
                v_rel,
            };
            let fv = self.contact(&mut springs, touch, law, dt);
            self.force[i] -= fv;
            self.force[j] += fv;
            self.torque[i] += cross(n * ra, -fv);
            self.torque[j] += cross(-n * rb, fv);
        }
        for i in 0..self.grains.len() {
            for w in 0..self.walls.len() {
                let (g, wall) = (&self.grains[i], &self.walls[w]);
                let gap = (g.pos - wall.point).dot(&wall.normal);
                let overlap = g.radius_m - gap;
                if overlap <= 0.0 {
                    continue;
                }
                let n = -wall.normal;
                let v_rel = -(g.vel + omega_cross(g.omega, n * g.radius_m));
                let (law, r) = (self.params.wall_law(g), g.radius_m);
                let touch = Touch {
                    key: ContactKey::Wall(i as u32, w as u32),
                    n,
                    overlap,
                    v_rel,
                };
                let fv = self.contact(&mut springs, touch, law, dt);
                self.force[i] -= fv;
                self.torque[i] += cross(n * r, -fv);
            }
        }
        self.springs = springs;
        self.reports.sort_by_key(|r| r.key);
    }

    /// One contact, `touch`: `law` with the tangential spring carried over from the last step,
    /// kept in `springs` for the next, and its report. Returns the force on the second body; the
    /// first takes its opposite.
    fn contact(
        &mut self,
        springs: &mut BTreeMap<ContactKey, f64>,
        touch: Touch,
        law: SpringDashpot,
        dt: f64,
    ) -> Vector {
        let Touch {
            key,
            n,
            overlap,
            v_rel,
        } = touch;
        let mut delta_t = self.springs.get(&key).copied().unwrap_or(0.0);
        let f = law.force(n, overlap, v_rel, &mut delta_t, dt);
        springs.insert(key, delta_t);
        self.reports.push(ContactReport {
            key,
            normal: n,
            overlap,
            force: f,
        });
        n * f.normal + perp(n) * f.tangential
    }

    /// Grain pairs whose x-extents overlap (sweep and prune on x), as (i < j) in ascending
    /// order, so the force sums run in an order fixed by the indices alone.
    fn candidate_pairs(&self) -> Vec<(usize, usize)> {
        let mut order: Vec<usize> = (0..self.grains.len()).collect();
        let lo = |i: usize| self.grains[i].pos.x - self.grains[i].radius_m;
        order.sort_by(|&a, &b| lo(a).total_cmp(&lo(b)).then(a.cmp(&b)));
        let mut pairs = Vec::new();
        for (k, &i) in order.iter().enumerate() {
            let hi = self.grains[i].pos.x + self.grains[i].radius_m;
            for &j in &order[k + 1..] {
                if lo(j) > hi {
                    break;
                }
                let (y_i, y_j) = (self.grains[i].pos.y, self.grains[j].pos.y);
                if (y_i - y_j).abs() <= self.grains[i].radius_m + self.grains[j].radius_m {
                    pairs.push((i.min(j), i.max(j)));
                }
            }
        }
        pairs.sort_unstable();
        pairs
    }
}
