//! What a world reports about itself: its energy, momentum and the work of numerical devices.

use serde::{Deserialize, Serialize};

use super::World;
use crate::body::Motion;
use crate::math::Vector;
use crate::particles::dev_contract;

/// Energy of the world and what the numerics have added or taken (J/m, per unit depth).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Energy {
    /// Kinetic energy of deformable and fluid particles, rigid bodies and abrasive grains (a
    /// grain's per metre of depth is its disc's, `plane_mass`).
    pub kinetic: f64,
    /// Elastic strain energy: V (p²/2K + s:s/4G) summed over deformable particles whose
    /// pressure law ignores the internal energy (seed eq. 11).
    pub elastic: f64,
    /// Internal energy Σ m e of the particles that integrate one (Mie–Grüneisen solids:
    /// compression, deviatoric and dissipated work, the e of AWJ paper eq. 24).
    #[serde(default)]
    pub internal: f64,
    /// Energy stored in the contact repulsion springs.
    pub contact: f64,
    /// Potential energy in gravity.
    pub gravity: f64,
}

impl Energy {
    /// Kinetic plus elastic plus internal plus contact plus gravity.
    pub fn total(&self) -> f64 {
        self.kinetic + self.elastic + self.internal + self.contact + self.gravity
    }
}

/// Running totals of work done by numerical devices (J/m); negative means dissipated.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct NumericalWork {
    /// Work of the hourglass forces (eq. 16).
    pub hourglass: f64,
    /// Change of elastic energy at the Shepard density filter (eq. 12).
    pub density_filter: f64,
    /// Work of the contact dashpots.
    pub contact_damping: f64,
    /// Plastic work (heat and stored work of plasticity).
    pub plastic: f64,
}

impl World {
    /// Each particle's pressure now (Pa): a solid's from its material's law, a fluid's from its
    /// EOS at its density, 0 for rigid bodies (for pictures and ParaView files).
    pub fn pressures(&self) -> Vec<f64> {
        let bc = self.body_consts();
        crate::stages::particle_state(&self.particles, &bc)
            .into_iter()
            .map(|(p, _)| p)
            .collect()
    }

    /// Kinetic, elastic, contact-spring and gravity energy (J/m).
    pub fn energy(&self) -> Energy {
        let bc = self.body_consts();
        let p = &self.particles;
        let mut e = Energy::default();
        for i in 0..p.len() {
            let b = p.body[i] as usize;
            if !(bc[b].deformable || bc[b].fluid.is_some()) {
                continue;
            }
            e.kinetic += 0.5 * p.mass[i] * p.vel[i].norm_squared();
            e.gravity -= p.mass[i] * self.settings.gravity_m_s2.dot(&p.pos[i]);
            if bc[b].fluid.is_some() {
                // The fluid runs on its EOS's cold curve; its compression energy is not booked.
                continue;
            }
            if bc[b].has_energy() {
                e.internal += p.mass[i] * p.energy[i];
                continue;
            }
            let vol = p.mass[i] / p.rho[i];
            let pr = bc[b].pressure(p.rho[i], p.rho0[i], 0.0);
            e.elastic += vol
                * (pr * pr / (2.0 * bc[b].bulk) + dev_contract(&p.sdev[i]) / (4.0 * bc[b].shear));
        }
        for b in &self.bodies {
            if let Some(r) = b.rigid() {
                if r.motion == Motion::Free {
                    e.kinetic += 0.5 * r.mass_kg_m * r.velocity_m_s.norm_squared()
                        + 0.5 * r.inertia_kg_m * r.omega_rad_s * r.omega_rad_s;
                    e.gravity -= r.mass_kg_m * self.settings.gravity_m_s2.dot(&r.com_m);
                }
            }
        }
        for g in self.abrasives.iter().flat_map(|a| &a.dem.grains) {
            let m = super::plane_mass(g);
            let inertia = g.inertia_kg_m2 / g.mass_kg * m;
            e.kinetic += 0.5 * m * g.vel.norm_squared() + 0.5 * inertia * g.omega * g.omega;
            e.gravity -= m * self.settings.gravity_m_s2.dot(&g.pos);
        }
        for c in &self.contacts {
            for (i, &pen) in c.penetration.iter().enumerate() {
                if pen > 0.0 {
                    e.contact += 0.5 * c.k_r * pen * pen + 0.5 * c.spring[i].norm_squared() * c.k_f;
                }
            }
        }
        e
    }

    /// Total linear momentum of deformable and fluid particles, free rigid bodies and abrasive
    /// grains (kg·m/s per m; a grain's is its disc's, `Abrasives::plane_momentum`).
    pub fn momentum(&self) -> Vector {
        let p = &self.particles;
        let mut m = Vector::zeros();
        for i in 0..p.len() {
            let b = &self.bodies[p.body[i] as usize];
            if b.material().is_some() || b.fluid().is_some() {
                m += p.vel[i] * p.mass[i];
            }
        }
        for b in &self.bodies {
            if let Some(r) = b.rigid() {
                if r.motion == Motion::Free {
                    m += r.velocity_m_s * r.mass_kg_m;
                }
            }
        }
        for g in self.abrasives.iter().flat_map(|a| &a.dem.grains) {
            m += super::Abrasives::plane_momentum(g);
        }
        m
    }
}
