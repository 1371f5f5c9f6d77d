//! Building a world: adding bodies, particles and contact pairs, and removing them again.

use super::World;
use crate::body::{Body, BodyKind, ExternalForce, Motion, Rigid};
use crate::contact::{self, ContactPair, ContactParams};
use crate::error::InputError;
use crate::fluid::Fluid;
use crate::geometry::Polygon;
use crate::material::Material;
use crate::math::{omega_cross, Matrix, Vector};
use crate::particles::{Particles, BOUNDARY, KINEMATIC};

/// A particle about to join a body: where, how fast, its mass per unit depth and density, its
/// `BOUNDARY` / `KINEMATIC` bits, and its offset in a rigid body's frame.
pub(super) struct NewParticle {
    pub pos: Vector,
    pub vel: Vector,
    pub mass: f64,
    pub rho: f64,
    pub flags: u8,
    pub local: Vector,
}

impl NewParticle {
    /// A particle of a deformable or fluid body: no flags, no rigid-body offset.
    pub fn free(pos: Vector, vel: Vector, mass: f64, rho: f64) -> NewParticle {
        NewParticle {
            pos,
            vel,
            mass,
            rho,
            flags: 0,
            local: Vector::zeros(),
        }
    }
}

impl World {
    /// Appends particle `np` to body `body` with a new id, unstressed, undamaged and at the
    /// settings' temperature.
    pub(super) fn push_particle(&mut self, body: usize, np: NewParticle) {
        let NewParticle {
            pos: x,
            vel: v,
            mass,
            rho,
            flags,
            local,
        } = np;
        let p = &mut self.particles;
        p.id.push(self.next_id);
        self.next_id += 1;
        p.body.push(body as u32);
        p.flags.push(flags);
        p.pos.push(x);
        p.vel.push(v);
        p.mass.push(mass);
        p.rho.push(rho);
        p.rho0.push(rho);
        p.sdev.push(Matrix::zeros());
        p.eps_p.push(0.0);
        p.eps_p_rate.push(0.0);
        p.temp.push(self.settings.temperature_k);
        p.energy.push(0.0);
        p.damage.push(0.0);
        p.bulking.push(0.0);
        p.def_grad.push(Matrix::identity());
        p.x_ref.push(x);
        p.local.push(local);
        for c in &mut self.contacts {
            c.spring.push(Vector::zeros());
            c.penetration.push(0.0);
            if c.touches(body, flags) {
                c.min_mass = c.min_mass.min(mass);
            }
        }
        self.nbrs_valid = false;
    }

    /// Adds a deformable body of particles at `points`, each standing for `volume_m2` (area per
    /// unit depth); returns its index. The body's surface particles are found geometrically.
    pub fn add_deformable(
        &mut self,
        name: &str,
        material: Material,
        points: &[Vector],
        volume_m2: &[f64],
        velocity_m_s: Vector,
    ) -> Result<usize, InputError> {
        material.validate()?;
        if points.is_empty() {
            return Err(InputError::new(
                format!("{name}.points"),
                "a body needs at least one particle",
            ));
        }
        if points.len() != volume_m2.len() {
            return Err(InputError::new(
                format!("{name}.volume_m2"),
                "needs one volume per point",
            ));
        }
        if let Some(k) = volume_m2.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(InputError::new(
                format!("{name}.volume_m2[{k}]"),
                "must be a finite number > 0",
            ));
        }
        let b = self.bodies.len();
        let rho = material.density_kg_m3;
        self.consts = None;
        self.bodies.push(Body {
            name: name.to_string(),
            kind: BodyKind::Deformable {
                material,
                boundary_motion: Motion::Fixed,
            },
            removed_mass_kg_m: 0.0,
            removed_particles: 0,
        });
        for (x, v) in points.iter().zip(volume_m2) {
            self.push_particle(b, NewParticle::free(*x, velocity_m_s, rho * v, rho));
        }
        Ok(b)
    }

    /// Adds a fluid body (the AWJ paper eqs. 21–27) of particles at `points`, each standing for
    /// `volume_m2` (area per unit depth) at gauge pressure `pressure_pa`: its density is the
    /// EOS's at that pressure (`Fluid::density_at`) and its mass that density times the volume.
    /// Walls that hold it are its own particles made kinematic (`set_kinematic`). It may start
    /// empty when an inflow (`add_inflow`) is to fill it.
    pub fn add_fluid(
        &mut self,
        name: &str,
        fluid: Fluid,
        points: &[Vector],
        volume_m2: &[f64],
        pressure_pa: &[f64],
        velocity_m_s: Vector,
    ) -> Result<usize, InputError> {
        fluid.validate(&format!("{name}.fluid"))?;
        for (field, len) in [
            ("volume_m2", volume_m2.len()),
            ("pressure_pa", pressure_pa.len()),
        ] {
            if len != points.len() {
                return Err(InputError::new(
                    format!("{name}.{field}"),
                    format!("needs one value per point ({}), got {len}", points.len()),
                ));
            }
        }
        if let Some(k) = points
            .iter()
            .position(|x| !(x.x.is_finite() && x.y.is_finite()))
        {
            return Err(InputError::new(
                format!("{name}.points[{k}]"),
                "must be finite",
            ));
        }
        if let Some(k) = volume_m2.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(InputError::new(
                format!("{name}.volume_m2[{k}]"),
                "must be a finite number > 0",
            ));
        }
        if !(velocity_m_s.x.is_finite() && velocity_m_s.y.is_finite()) {
            return Err(InputError::new(
                format!("{name}.velocity_m_s"),
                "must be finite",
            ));
        }
        let rho = pressure_pa
            .iter()
            .enumerate()
            .map(|(k, &pr)| fluid.density_at(pr, &format!("{name}.pressure_pa[{k}]")))
            .collect::<Result<Vec<f64>, InputError>>()?;
        let rho0 = fluid.density();
        let b = self.bodies.len();
        self.consts = None;
        self.bodies.push(Body {
            name: name.to_string(),
            kind: BodyKind::Fluid {
                fluid,
                boundary_motion: Motion::Fixed,
            },
            removed_mass_kg_m: 0.0,
            removed_particles: 0,
        });
        for ((x, v), r) in points.iter().zip(volume_m2).zip(rho) {
            self.push_particle(b, NewParticle::free(*x, velocity_m_s, r * v, r));
            // ρ0 is the fluid's reference density, not the initial one.
            *self.particles.rho0.last_mut().expect("just pushed") = rho0;
        }
        Ok(b)
    }

    /// Sets the velocity of each free (not kinematic) particle of fluid body `b` to `field` at
    /// its position; returns how many were set. A non-finite velocity is an error on
    /// `<body>.velocity_m_s`, and nothing is changed.
    pub fn set_fluid_velocity(
        &mut self,
        b: usize,
        field: impl Fn(Vector) -> Vector,
    ) -> Result<usize, InputError> {
        let Some(body) = self.bodies.get(b).filter(|x| x.fluid().is_some()) else {
            return Err(InputError::new("fluid_velocity", "needs a fluid body"));
        };
        let p = &self.particles;
        let free: Vec<usize> = (0..p.len())
            .filter(|&i| p.body[i] as usize == b && p.flags[i] & KINEMATIC == 0)
            .collect();
        let v: Vec<Vector> = free.iter().map(|&i| field(p.pos[i])).collect();
        if v.iter().any(|v| !(v.x.is_finite() && v.y.is_finite())) {
            return Err(InputError::new(
                format!("{}.velocity_m_s", body.name),
                "must be finite",
            ));
        }
        for (&i, v) in free.iter().zip(v) {
            self.particles.vel[i] = v;
        }
        Ok(free.len())
    }

    /// Adds a deformable body filling `polygon` on a square lattice of the world's spacing.
    pub fn add_deformable_polygon(
        &mut self,
        name: &str,
        material: Material,
        polygon: &Polygon,
        lattice_origin: Vector,
        velocity_m_s: Vector,
    ) -> Result<usize, InputError> {
        let dx = self.settings.spacing_m;
        let pts = polygon.fill_lattice(dx, lattice_origin);
        let vols = vec![dx * dx; pts.len()];
        self.add_deformable(name, material, &pts, &vols, velocity_m_s)
    }

    /// Adds a deformable body from a saved particle state (`body_state` of an earlier world):
    /// stress, strain, damage and flags carry over unchanged, so a sample can go on from one
    /// impact to the next in a fresh world (seed section 4).
    pub fn add_deformable_state(
        &mut self,
        name: &str,
        material: Material,
        mut state: Particles,
        boundary_motion: Motion,
    ) -> Result<usize, InputError> {
        material.validate()?;
        if state.is_empty() || !state.is_consistent() {
            return Err(InputError::new(
                format!("{name}.state"),
                "needs at least one particle and equal lengths of every per-particle array",
            ));
        }
        let finite = state
            .pos
            .iter()
            .chain(&state.vel)
            .all(|v| v.iter().all(|x| x.is_finite()))
            && state
                .mass
                .iter()
                .chain(&state.rho)
                .all(|&x| x.is_finite() && x > 0.0);
        if !finite {
            return Err(InputError::new(
                format!("{name}.state"),
                "positions and velocities must be finite, masses and densities > 0",
            ));
        }
        let b = self.bodies.len();
        self.consts = None;
        self.bodies.push(Body {
            name: name.to_string(),
            kind: BodyKind::Deformable {
                material,
                boundary_motion,
            },
            removed_mass_kg_m: 0.0,
            removed_particles: 0,
        });
        let n = state.len();
        state.body.iter_mut().for_each(|x| *x = b as u32);
        self.next_id = self.next_id.max(state.id.iter().max().map_or(0, |m| m + 1));
        for c in &mut self.contacts {
            c.spring.resize(self.particles.len() + n, Vector::zeros());
            c.penetration.resize(self.particles.len() + n, 0.0);
        }
        self.particles.append(state);
        self.refresh_contact_masses();
        self.nbrs_valid = false;
        Ok(b)
    }

    /// A copy of body `b`'s particles, in loop order (for `add_deformable_state`).
    pub fn body_state(&self, b: usize) -> Particles {
        let keep: Vec<bool> = self
            .particles
            .body
            .iter()
            .map(|&x| x as usize == b)
            .collect();
        self.particles.select(&keep)
    }

    /// Makes the particles of deformable or fluid body `b` that satisfy `select` kinematic: they
    /// move with `motion` (a prescribed-motion boundary) and take no forces. A fluid body's
    /// kinematic particles are its walls: they still carry a density and a pressure.
    pub fn set_kinematic(
        &mut self,
        b: usize,
        motion: Motion,
        select: impl Fn(Vector) -> bool,
    ) -> Result<usize, InputError> {
        match &mut self.bodies[b].kind {
            BodyKind::Deformable {
                boundary_motion, ..
            }
            | BodyKind::Fluid {
                boundary_motion, ..
            } => *boundary_motion = motion,
            BodyKind::Rigid(_) => {
                return Err(InputError::new(
                    "kinematic",
                    "only deformable and fluid bodies have kinematic particles",
                ))
            }
        }
        let mut n = 0;
        for i in 0..self.particles.len() {
            if self.particles.body[i] as usize == b && select(self.particles.pos[i]) {
                self.particles.flags[i] |= KINEMATIC;
                n += 1;
            }
        }
        Ok(n)
    }

    /// Adds a rigid polygon of `density_kg_m3` (mass and inertia from the polygon itself),
    /// filled with boundary-conforming particle layers; returns its index.
    pub fn add_rigid(
        &mut self,
        name: &str,
        polygon: &Polygon,
        density_kg_m3: f64,
        velocity_m_s: Vector,
        omega_rad_s: f64,
        motion: Motion,
    ) -> Result<usize, InputError> {
        if !(density_kg_m3.is_finite() && density_kg_m3 > 0.0) {
            return Err(InputError::new(
                format!("{name}.density_kg_m3"),
                format!("must be > 0, got {density_kg_m3}"),
            ));
        }
        let dx = self.settings.spacing_m;
        let (pts, boundary) = polygon.fill_layered(dx);
        if pts.is_empty() {
            return Err(InputError::new(
                format!("{name}.vertices_m"),
                "polygon is too small for the particle spacing",
            ));
        }
        let mass = density_kg_m3 * polygon.area();
        let inertia = density_kg_m3 * polygon.polar_moment();
        let com = polygon.centroid();
        let b = self.bodies.len();
        self.consts = None;
        self.bodies.push(Body {
            name: name.to_string(),
            kind: BodyKind::Rigid(Rigid {
                mass_kg_m: mass,
                inertia_kg_m: inertia,
                com_m: com,
                angle_rad: 0.0,
                velocity_m_s,
                omega_rad_s,
                motion,
                external: ExternalForce::default(),
                contact_force_n_m: Vector::zeros(),
                contact_torque_n: 0.0,
            }),
            removed_mass_kg_m: 0.0,
            removed_particles: 0,
        });
        // The particle mass of the full fill in either case: the contact's time-step limit and
        // stiffness read it, so a shell must not change it.
        let mp = mass / pts.len() as f64;
        let shell = self.settings.rigid_shell;
        for (x, isb) in pts.iter().zip(boundary) {
            if shell && !isb {
                continue;
            }
            let r = x - com;
            let v = velocity_m_s + omega_cross(omega_rad_s, r);
            let np = NewParticle {
                pos: *x,
                vel: v,
                mass: mp,
                rho: density_kg_m3,
                flags: if isb { BOUNDARY } else { 0 },
                local: r,
            };
            self.push_particle(b, np);
        }
        Ok(b)
    }

    /// Sets the external force on rigid body `b`.
    pub fn set_external_force(&mut self, b: usize, f: ExternalForce) -> Result<(), InputError> {
        match self.bodies[b].rigid_mut() {
            Some(r) => {
                r.external = f;
                Ok(())
            }
            None => Err(InputError::new(
                "external_force",
                "only rigid bodies take an external force",
            )),
        }
    }

    /// Declares that rigid `primary` and `secondary` touch with the seed's contact (section 3).
    pub fn add_contact(
        &mut self,
        primary: usize,
        secondary: usize,
        params: ContactParams,
    ) -> Result<usize, InputError> {
        if primary >= self.bodies.len() || secondary >= self.bodies.len() || primary == secondary {
            return Err(InputError::new(
                "contact",
                "primary and secondary must be two different existing bodies",
            ));
        }
        if !self.bodies[primary].is_rigid() {
            return Err(InputError::new(
                "contact.primary",
                "the primary body must be rigid: its surface gives the normal",
            ));
        }
        if !(params.friction.is_finite() && params.friction >= 0.0) {
            return Err(InputError::new(
                "contact.friction",
                format!("must be >= 0, got {}", params.friction),
            ));
        }
        if !(params.damping_ratio.is_finite() && params.damping_ratio >= 0.0) {
            return Err(InputError::new("contact.damping_ratio", "must be >= 0"));
        }
        let k_r = match params.normal_stiffness_pa {
            Some(k) => k,
            None => match self.bodies[secondary].material() {
                Some(m) => contact::cfl_matched_stiffness(m, self.settings.h_over_dx),
                None => {
                    return Err(InputError::new(
                        "contact.normal_stiffness_pa",
                        "must be given when both bodies are rigid",
                    ))
                }
            },
        };
        let k_f = params.tangential_stiffness_pa.unwrap_or(k_r);
        if !(k_r.is_finite() && k_r > 0.0 && k_f.is_finite() && k_f > 0.0) {
            return Err(InputError::new(
                "contact.normal_stiffness_pa",
                "stiffnesses must be > 0",
            ));
        }
        self.contacts.push(ContactPair {
            primary,
            secondary,
            params,
            k_r,
            k_f,
            spring: vec![Vector::zeros(); self.particles.len()],
            penetration: vec![0.0; self.particles.len()],
            min_mass: f64::INFINITY,
        });
        self.refresh_contact_masses();
        self.nbrs_valid = false;
        Ok(self.contacts.len() - 1)
    }

    /// Resets temperature of deformable bodies to the initial one (between impacts, section 4).
    pub fn reset_temperature(&mut self) {
        let t = self.settings.temperature_k;
        for x in &mut self.particles.temp {
            *x = t;
        }
    }

    /// Removes every particle of body `b` and the body's contacts (the old grain, section 4).
    /// Body indices of other bodies stay valid: the body entry remains, empty.
    pub fn clear_body(&mut self, b: usize) {
        let keep: Vec<bool> = self
            .particles
            .body
            .iter()
            .map(|&x| x as usize != b)
            .collect();
        self.retain_particles(&keep);
        self.contacts.retain(|c| c.primary != b && c.secondary != b);
        self.nbrs_valid = false;
    }

    /// Removes the particles with `keep[i] == false` (fragments a scene no longer follows),
    /// keeping the order of the rest; removed mass is not booked as failed.
    pub fn remove_particles(&mut self, keep: &[bool]) -> Result<(), InputError> {
        if keep.len() != self.particles.len() {
            return Err(InputError::new("keep", "needs one flag per particle"));
        }
        self.retain_particles(keep);
        Ok(())
    }

    pub(super) fn retain_particles(&mut self, keep: &[bool]) {
        self.reorder_particles(&crate::particles::kept(keep));
        self.refresh_contact_masses();
    }

    /// Puts particle `order[k]` at index k, dropping those not listed: every per-particle array
    /// and the contact springs move together, and the neighbour lists are stale.
    pub(super) fn reorder_particles(&mut self, order: &[usize]) {
        use crate::particles::gather;
        self.particles = self.particles.permuted(order);
        for c in &mut self.contacts {
            c.spring = gather(&c.spring, order);
            c.penetration = gather(&c.penetration, order);
        }
        self.nbrs_valid = false;
    }

    /// Smallest particle mass each contact's springs act on, for the contact time step; kept
    /// here so the step does not scan every particle for it.
    fn refresh_contact_masses(&mut self) {
        let p = &self.particles;
        for c in &mut self.contacts {
            c.min_mass = (0..p.len())
                .filter(|&i| c.touches(p.body[i] as usize, p.flags[i]))
                .map(|i| p.mass[i])
                .fold(f64::INFINITY, f64::min);
        }
    }
}
