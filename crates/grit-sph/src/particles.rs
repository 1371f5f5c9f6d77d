//! Particle storage as a structure of arrays: one `Vec` per quantity, zipped by the stages.

use serde::{Deserialize, Serialize};

use crate::error::InputError;
use crate::math::{Matrix, Vector};

/// Particle sits in the layer of its body that can touch another body (contact, eqs. 21–22).
pub const BOUNDARY: u8 = 1;
/// Particle moves with its body's prescribed boundary motion instead of its own forces.
pub const KINEMATIC: u8 = 2;

/// All particles of a world, structure of arrays; index order is the deterministic loop order.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Particles {
    /// Stable id given at creation, kept through deletions (for diagnostics and output).
    pub id: Vec<u32>,
    /// Owning body.
    pub body: Vec<u32>,
    /// BOUNDARY / KINEMATIC bits.
    pub flags: Vec<u8>,
    /// Position (m).
    pub pos: Vec<Vector>,
    /// Velocity (m/s).
    pub vel: Vec<Vector>,
    /// Mass per unit depth (kg/m).
    pub mass: Vec<f64>,
    /// Density (kg/m³).
    pub rho: Vec<f64>,
    /// Initial density ρ0 of eq. 11 (kg/m³).
    pub rho0: Vec<f64>,
    /// Deviatoric stress, in-plane part (Pa); the out-of-plane part is −(s_xx + s_yy).
    pub sdev: Vec<Matrix>,
    /// Equivalent plastic strain (–).
    pub eps_p: Vec<f64>,
    /// Equivalent plastic strain rate of the last step (1/s).
    pub eps_p_rate: Vec<f64>,
    /// Temperature (K).
    pub temp: Vec<f64>,
    /// Specific internal energy above the reference state (J/kg), integrated for the bodies
    /// whose pressure law reads it (a Mie–Grüneisen EOS, AWJ paper eq. 24); 0 elsewhere. Written
    /// as an empty array while all zero, and read back as zeros then ([`deserialize_filled`]).
    #[serde(default, serialize_with = "zeros_as_empty")]
    pub energy: Vec<f64>,
    /// Damage D: Johnson–Cook (eq. 19) or JH-2 (AWJ paper eq. 39).
    pub damage: Vec<f64>,
    /// JH-2 bulking pressure ΔP (Pa, AWJ paper eq. 41); 0 for every other material. Kept out of
    /// this type's serde layout, which positional checkpoints read (version 5 and 6 samples):
    /// a world's state stores it on its own (`WorldState`), and a read fills zeros.
    #[serde(skip)]
    pub bulking: Vec<f64>,
    /// Deformation gradient since the reference configuration (hourglass stiffness, eq. 16).
    pub def_grad: Vec<Matrix>,
    /// Reference position for the hourglass stiffness term (m).
    pub x_ref: Vec<Vector>,
    /// Offset from the centre of mass in the body frame, for rigid-body particles (m).
    pub local: Vec<Vector>,
}

impl Particles {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// Pressure from the EOS, seed eq. 11: p = K (ρ/ρ0 − 1).
    #[inline]
    pub fn pressure(&self, i: usize, bulk_modulus: f64) -> f64 {
        bulk_modulus * (self.rho[i] / self.rho0[i] - 1.0)
    }

    /// Keeps the particles with `keep[i]`, preserving order (so loop order stays deterministic).
    pub fn retain(&mut self, keep: &[bool]) {
        *self = self.permuted(&kept(keep));
    }

    /// The particles in the order `order` gives: particle k of the result is `order[k]` here.
    pub fn permuted(&self, order: &[usize]) -> Particles {
        Particles {
            id: gather(&self.id, order),
            body: gather(&self.body, order),
            flags: gather(&self.flags, order),
            pos: gather(&self.pos, order),
            vel: gather(&self.vel, order),
            mass: gather(&self.mass, order),
            rho: gather(&self.rho, order),
            rho0: gather(&self.rho0, order),
            sdev: gather(&self.sdev, order),
            eps_p: gather(&self.eps_p, order),
            eps_p_rate: gather(&self.eps_p_rate, order),
            temp: gather(&self.temp, order),
            energy: gather(&self.energy, order),
            damage: gather(&self.damage, order),
            bulking: gather(&self.bulking, order),
            def_grad: gather(&self.def_grad, order),
            x_ref: gather(&self.x_ref, order),
            local: gather(&self.local, order),
        }
    }

    /// A copy of the particles with `keep[i]`, in order (a body's state, for a checkpoint).
    pub fn select(&self, keep: &[bool]) -> Particles {
        self.permuted(&kept(keep))
    }

    /// Appends `other`'s particles after these, unchanged.
    pub fn append(&mut self, mut other: Particles) {
        self.id.append(&mut other.id);
        self.body.append(&mut other.body);
        self.flags.append(&mut other.flags);
        self.pos.append(&mut other.pos);
        self.vel.append(&mut other.vel);
        self.mass.append(&mut other.mass);
        self.rho.append(&mut other.rho);
        self.rho0.append(&mut other.rho0);
        self.sdev.append(&mut other.sdev);
        self.eps_p.append(&mut other.eps_p);
        self.eps_p_rate.append(&mut other.eps_p_rate);
        self.temp.append(&mut other.temp);
        self.energy.append(&mut other.energy);
        self.damage.append(&mut other.damage);
        self.bulking.append(&mut other.bulking);
        self.def_grad.append(&mut other.def_grad);
        self.x_ref.append(&mut other.x_ref);
        self.local.append(&mut other.local);
    }

    /// True when every per-particle array has the same length (a decoded checkpoint, say).
    pub fn is_consistent(&self) -> bool {
        let n = self.id.len();
        [
            self.body.len(),
            self.flags.len(),
            self.pos.len(),
            self.vel.len(),
            self.mass.len(),
            self.rho.len(),
            self.rho0.len(),
            self.sdev.len(),
            self.eps_p.len(),
            self.eps_p_rate.len(),
            self.temp.len(),
            self.energy.len(),
            self.damage.len(),
            self.bulking.len(),
            self.def_grad.len(),
            self.x_ref.len(),
            self.local.len(),
        ]
        .iter()
        .all(|&l| l == n)
    }
}

/// The layout of [`ParticlesState`] this build writes and reads.
pub const PARTICLES_STATE_VERSION: u32 = 1;

/// Particles as a checkpoint keeps them (an impact sample's surface, a [`WorldState`]'s
/// particles), under a layout version of their own, so [`Particles`] may change without changing
/// checkpoints: every per-particle array, in this order, none ever left out, so a positional
/// format (postcard) reads it as well as JSON. A change to these fields is a new version.
///
/// [`WorldState`]: crate::world::WorldState
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParticlesState {
    /// Layout version ([`PARTICLES_STATE_VERSION`]). JSON without one is `Particles`' own
    /// (checkpoints written before this type): the same arrays, read as version 1.
    #[serde(default = "first_layout")]
    version: u32,
    id: Vec<u32>,
    body: Vec<u32>,
    flags: Vec<u8>,
    pos: Vec<Vector>,
    vel: Vec<Vector>,
    mass: Vec<f64>,
    rho: Vec<f64>,
    rho0: Vec<f64>,
    sdev: Vec<Matrix>,
    eps_p: Vec<f64>,
    eps_p_rate: Vec<f64>,
    temp: Vec<f64>,
    /// Empty while every particle's energy is zero (bodies without an energy equation), so such a
    /// state is no larger than one written before energies existed; JSON may leave it out.
    #[serde(default)]
    energy: Vec<f64>,
    damage: Vec<f64>,
    def_grad: Vec<Matrix>,
    x_ref: Vec<Vector>,
    local: Vec<Vector>,
}

/// The layout a state that names none was written in.
fn first_layout() -> u32 {
    1
}

impl ParticlesState {
    /// The layout version this state was written in.
    pub fn version(&self) -> u32 {
        self.version
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.id.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }
}

impl Particles {
    /// The particles' state for a checkpoint ([`Particles::from_state`] reads it back, bit for
    /// bit).
    pub fn state(&self) -> ParticlesState {
        let zero_energy = self.energy.iter().all(|&e| e == 0.0);
        ParticlesState {
            version: PARTICLES_STATE_VERSION,
            id: self.id.clone(),
            body: self.body.clone(),
            flags: self.flags.clone(),
            pos: self.pos.clone(),
            vel: self.vel.clone(),
            mass: self.mass.clone(),
            rho: self.rho.clone(),
            rho0: self.rho0.clone(),
            sdev: self.sdev.clone(),
            eps_p: self.eps_p.clone(),
            eps_p_rate: self.eps_p_rate.clone(),
            temp: self.temp.clone(),
            energy: if zero_energy {
                Vec::new()
            } else {
                self.energy.clone()
            },
            damage: self.damage.clone(),
            def_grad: self.def_grad.clone(),
            x_ref: self.x_ref.clone(),
            local: self.local.clone(),
        }
    }

    /// The particles of a checkpoint's state. Refuses a layout version this build does not read
    /// and arrays of different lengths; errors name `particles.<field>`.
    pub fn from_state(state: ParticlesState) -> Result<Particles, InputError> {
        if state.version != PARTICLES_STATE_VERSION {
            return Err(InputError::new(
                "particles.version",
                format!(
                    "layout {} is not the one this build reads ({PARTICLES_STATE_VERSION})",
                    state.version
                ),
            ));
        }
        let n = state.id.len();
        let mut p = Particles {
            id: state.id,
            body: state.body,
            flags: state.flags,
            pos: state.pos,
            vel: state.vel,
            mass: state.mass,
            rho: state.rho,
            rho0: state.rho0,
            sdev: state.sdev,
            eps_p: state.eps_p,
            eps_p_rate: state.eps_p_rate,
            temp: state.temp,
            energy: state.energy,
            damage: state.damage,
            bulking: vec![0.0; n],
            def_grad: state.def_grad,
            x_ref: state.x_ref,
            local: state.local,
        };
        if p.energy.is_empty() {
            p.energy = vec![0.0; n];
        }
        if !p.is_consistent() {
            return Err(InputError::new(
                "particles",
                format!("arrays of different lengths (id holds {n})"),
            ));
        }
        Ok(p)
    }
}

/// Von Mises equivalent stress of a plane-strain deviator: sqrt(3/2 s:s) with s_zz = −(s_xx + s_yy).
#[inline]
pub fn von_mises(s: &Matrix) -> f64 {
    (1.5 * dev_contract(s)).sqrt()
}

/// s:s of the full 3D deviator whose in-plane part is `s` (plane strain).
#[inline]
pub fn dev_contract(s: &Matrix) -> f64 {
    let szz = -(s[(0, 0)] + s[(1, 1)]);
    s[(0, 0)] * s[(0, 0)] + s[(1, 1)] * s[(1, 1)] + szz * szz + 2.0 * s[(0, 1)] * s[(0, 1)]
}

/// An all-zero array as an empty one: states of bodies without an energy equation keep their
/// size (and a field is never skipped, which a positional format such as postcard cannot do).
fn zeros_as_empty<S: serde::Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
    if v.iter().all(|&x| x == 0.0) {
        s.collect_seq(std::iter::empty::<f64>())
    } else {
        s.collect_seq(v)
    }
}

/// Reads particles whose JSON may leave out the all-zero `energy` (every state written before
/// it existed, and every state of bodies without an energy equation): the missing array reads
/// as zeros, one per particle. Use as `#[serde(deserialize_with = ...)]` on a `Particles` field.
pub fn deserialize_filled<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Particles, D::Error> {
    let mut p = Particles::deserialize(d)?;
    if p.energy.is_empty() {
        p.energy = vec![0.0; p.id.len()];
    }
    p.bulking = vec![0.0; p.id.len()];
    Ok(p)
}

/// The indices i with `keep[i]`, in order: the gather order that keeps those particles.
pub fn kept(keep: &[bool]) -> Vec<usize> {
    keep.iter()
        .enumerate()
        .filter_map(|(i, &k)| k.then_some(i))
        .collect()
}

/// `v[order[k]]` for every k: the one reordering every per-particle array goes through
/// (deletion keeps a subset in order, the cell sort permutes).
pub fn gather<T: Copy>(v: &[T], order: &[usize]) -> Vec<T> {
    order.iter().map(|&i| v[i]).collect()
}
