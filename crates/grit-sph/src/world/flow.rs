//! Open boundaries of a fluid body (docs/jet.md#inflow-and-outflow): a nozzle that feeds it rows
//! of particles at the jet speed, and a box outside which its particles are deleted, with the
//! mass each books so a run can check in − out − held = 0.

use serde::{Deserialize, Serialize};

use super::World;
use crate::body::BodyKind;
use crate::error::InputError;
use crate::math::Vector;
use crate::particles::KINEMATIC;

/// Fraction of a spacing by which the distance travelled may fall short of a whole spacing and
/// still release a row: a step that should end exactly on the spacing lands a rounding error
/// below it, and waiting a step for that would shift the row by v Δt.
const ROW_SLACK: f64 = 1e-9;

/// A nozzle of an inflow (the AWJ paper's jet inlet): the exit's centre, the jet's direction,
/// its width across and its speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Nozzle {
    /// Centre of the exit (m); rows are released on the exit line through it.
    pub centre_m: Vector,
    /// Direction of the jet (any length > 0; normalised when the inflow is added).
    pub direction: Vector,
    /// Width of the jet (m): a whole number of the world's spacings.
    pub width_m: f64,
    /// Jet speed (m/s), > 0.
    pub speed_m_s: f64,
}

/// An inflow of fluid body `body` and what it has released so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Inflow {
    /// The fluid body fed.
    pub body: usize,
    /// The nozzle (direction normalised).
    pub nozzle: Nozzle,
    /// Particles per row: width / spacing.
    pub per_row: usize,
    /// Rows released.
    pub rows: u64,
    /// Mass released (kg per metre of depth).
    pub mass_kg_m: f64,
    /// Distance the last row has travelled since its release (m).
    travelled_m: f64,
}

/// An outflow of fluid body `body`: its free particles outside the box are deleted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outflow {
    /// The fluid body drained.
    pub body: usize,
    /// Lower-left corner of the box the fluid may stay in (m).
    pub min_m: Vector,
    /// Upper-right corner (m).
    pub max_m: Vector,
    /// Particles deleted.
    pub particles: u64,
    /// Mass deleted (kg per metre of depth).
    pub mass_kg_m: f64,
}

/// The world's inflows and outflows, in the order they were added.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct Flow {
    pub inflows: Vec<Inflow>,
    pub outflows: Vec<Outflow>,
}

impl Flow {
    /// True when the world has no open boundary (its checkpoint then leaves the key out).
    pub fn is_empty(&self) -> bool {
        self.inflows.is_empty() && self.outflows.is_empty()
    }
}

fn finite(v: Vector) -> bool {
    v.x.is_finite() && v.y.is_finite()
}

impl World {
    fn fluid_body(&self, b: usize, field: &str) -> Result<(), InputError> {
        match self.bodies.get(b).map(|x| &x.kind) {
            Some(BodyKind::Fluid { .. }) => Ok(()),
            _ => Err(InputError::new(
                field,
                format!("body {b} is not a fluid body"),
            )),
        }
    }

    /// Adds an inflow to fluid body `b` (docs/jet.md#inflow-and-outflow): a row of
    /// width/spacing particles, on the lattice across the nozzle, at rest pressure (ρ = ρ0, the
    /// EOS's zero) and the jet velocity, released on the exit line now and then each time the
    /// last row has moved one spacing at the jet speed. Returns the inflow's index. Errors name
    /// `nozzle.<field>`.
    pub fn add_inflow(&mut self, b: usize, nozzle: Nozzle) -> Result<usize, InputError> {
        self.fluid_body(b, "nozzle.body")?;
        if !finite(nozzle.centre_m) {
            return Err(InputError::new("nozzle.centre_m", "must be finite"));
        }
        let len = nozzle.direction.norm();
        if !(len.is_finite() && len > 0.0) {
            return Err(InputError::new(
                "nozzle.direction",
                "must be a finite, non-zero vector",
            ));
        }
        InputError::require_positive("nozzle.speed_m_s", nozzle.speed_m_s)?;
        InputError::require_positive("nozzle.width_m", nozzle.width_m)?;
        let dx = self.settings.spacing_m;
        let per = (nozzle.width_m / dx).round();
        if per < 1.0 || (nozzle.width_m / dx - per).abs() > 1e-6 {
            return Err(InputError::new(
                "nozzle.width_m",
                format!(
                    "must be a whole number of spacings ({dx:e} m), got {:e} m",
                    nozzle.width_m
                ),
            ));
        }
        let nozzle = Nozzle {
            direction: nozzle.direction / len,
            ..nozzle
        };
        self.flow.inflows.push(Inflow {
            body: b,
            nozzle,
            per_row: per as usize,
            rows: 0,
            mass_kg_m: 0.0,
            travelled_m: 0.0,
        });
        let k = self.flow.inflows.len() - 1;
        self.release_row(k, 0.0);
        Ok(k)
    }

    /// Deletes the free particles of fluid or deformable body `b` that leave the box
    /// `min_m`–`max_m` from now on, at the end of each step, booking their number and mass
    /// (docs/jet.md#inflow-and-outflow; for a target, the fragments it loses). Returns the
    /// outflow's index. Errors name `outflow.<field>`.
    pub fn add_outflow(
        &mut self,
        b: usize,
        min_m: Vector,
        max_m: Vector,
    ) -> Result<usize, InputError> {
        if !matches!(
            self.bodies.get(b).map(|x| &x.kind),
            Some(BodyKind::Fluid { .. } | BodyKind::Deformable { .. })
        ) {
            return Err(InputError::new(
                "outflow.body",
                format!("body {b} is neither a fluid nor a deformable body"),
            ));
        }
        if !(finite(min_m) && finite(max_m)) {
            return Err(InputError::new("outflow.min_m", "corners must be finite"));
        }
        if !(max_m.x > min_m.x && max_m.y > min_m.y) {
            return Err(InputError::new(
                "outflow.max_m",
                "must lie above and right of outflow.min_m",
            ));
        }
        self.flow.outflows.push(Outflow {
            body: b,
            min_m,
            max_m,
            particles: 0,
            mass_kg_m: 0.0,
        });
        Ok(self.flow.outflows.len() - 1)
    }

    /// The inflows, in the order they were added.
    pub fn inflows(&self) -> &[Inflow] {
        &self.flow.inflows
    }

    /// The outflows, in the order they were added.
    pub fn outflows(&self) -> &[Outflow] {
        &self.flow.outflows
    }

    /// Appends inflow `k`'s next row, `s` downstream of the exit line, in order across the
    /// nozzle (left of the jet first), so ids and order follow from the inputs alone.
    fn release_row(&mut self, k: usize, s: f64) {
        let dx = self.settings.spacing_m;
        let inflow = &self.flow.inflows[k];
        let (b, nz, per) = (inflow.body, inflow.nozzle, inflow.per_row);
        let fluid = self.bodies[b]
            .fluid()
            .expect("an inflow feeds a fluid body");
        let rho0 = fluid.density();
        let mass = rho0 * dx * dx;
        let across = Vector::new(-nz.direction.y, nz.direction.x);
        let v = nz.direction * nz.speed_m_s;
        for j in 0..per {
            let off = (j as f64 + 0.5 - 0.5 * per as f64) * dx;
            let x = nz.centre_m + nz.direction * s + across * off;
            self.push_particle(b, super::build::NewParticle::free(x, v, mass, rho0));
            // As in `add_fluid`: ρ0 is the fluid's reference density.
            *self.particles.rho0.last_mut().expect("just pushed") = rho0;
        }
        let inflow = &mut self.flow.inflows[k];
        inflow.rows += 1;
        inflow.mass_kg_m += mass * per as f64;
    }

    /// The open boundaries' part of a step of `dt`: outflows delete, then inflows release the
    /// rows whose predecessors have moved a spacing.
    pub(super) fn flow_step(&mut self, dt: f64) {
        if self.flow.is_empty() {
            return;
        }
        if !self.flow.outflows.is_empty() {
            let p = &self.particles;
            let mut keep = vec![true; p.len()];
            for o in &mut self.flow.outflows {
                for (i, kept) in keep.iter_mut().enumerate() {
                    let x = p.pos[i];
                    let inside = x.x >= o.min_m.x
                        && x.x <= o.max_m.x
                        && x.y >= o.min_m.y
                        && x.y <= o.max_m.y;
                    let free = p.flags[i] & KINEMATIC == 0;
                    if *kept && free && p.body[i] as usize == o.body && !inside {
                        *kept = false;
                        o.particles += 1;
                        o.mass_kg_m += p.mass[i];
                    }
                }
            }
            if keep.iter().any(|k| !k) {
                self.retain_particles(&keep);
            }
        }
        let dx = self.settings.spacing_m;
        for k in 0..self.flow.inflows.len() {
            let inflow = &mut self.flow.inflows[k];
            inflow.travelled_m += inflow.nozzle.speed_m_s * dt;
            while self.flow.inflows[k].travelled_m >= dx * (1.0 - ROW_SLACK) {
                let inflow = &mut self.flow.inflows[k];
                inflow.travelled_m = (inflow.travelled_m - dx).max(0.0);
                let s = inflow.travelled_m;
                self.release_row(k, s);
            }
        }
    }
}
