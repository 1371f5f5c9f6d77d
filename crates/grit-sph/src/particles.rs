//! Particle storage as a structure of arrays: one `Vec` per quantity, zipped by the stages.

use serde::{Deserialize, Serialize};

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
    /// Johnson–Cook damage D (eq. 19).
    pub damage: Vec<f64>,
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
        fn r<T: Copy>(v: &mut Vec<T>, keep: &[bool]) {
            let mut k = 0;
            for i in 0..v.len() {
                if keep[i] {
                    v[k] = v[i];
                    k += 1;
                }
            }
            v.truncate(k);
        }
        r(&mut self.id, keep);
        r(&mut self.body, keep);
        r(&mut self.flags, keep);
        r(&mut self.pos, keep);
        r(&mut self.vel, keep);
        r(&mut self.mass, keep);
        r(&mut self.rho, keep);
        r(&mut self.rho0, keep);
        r(&mut self.sdev, keep);
        r(&mut self.eps_p, keep);
        r(&mut self.eps_p_rate, keep);
        r(&mut self.temp, keep);
        r(&mut self.damage, keep);
        r(&mut self.def_grad, keep);
        r(&mut self.x_ref, keep);
        r(&mut self.local, keep);
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
