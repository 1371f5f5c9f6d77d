//! Contact between a rigid primary body and a secondary body (seed section 3): the distance and
//! normal extrapolated from the primary surface (eqs. 21–23), the repulsion spring (eq. 24), the
//! Cundall–Strack friction spring with its Coulomb limit (eqs. 25–29); and, for comparison, the
//! plain particle–particle penetration model whose artificial roughness the seed's Fig. 2b shows.

use serde::{Deserialize, Serialize};

use crate::kernel::Kernel;
use crate::material::Material;
use crate::math::{perp, Vector};

/// How contact distance and normal are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ContactModel {
    /// The seed's model: distance and normal extrapolated from the primary surface (eqs. 21–22).
    #[default]
    Extrapolated,
    /// Each primary particle closer than Δx pushes along the line of centres (Fig. 2b).
    Penetration,
}

/// Contact parameters as given by a scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactParams {
    /// The detection model.
    pub model: ContactModel,
    /// Coulomb friction coefficient μ (eq. 27).
    pub friction: f64,
    /// Repulsion stiffness k_r (eq. 24) per unit depth (N/m²); `None` picks the stiffness whose
    /// spring–particle period equals the material's CFL step, so contact never shortens the step.
    pub normal_stiffness_pa: Option<f64>,
    /// Friction spring stiffness k_f (eq. 25) (N/m²); `None` takes k_r.
    pub tangential_stiffness_pa: Option<f64>,
    /// Damping ratio of a dashpot on the penetration rate dP/dt, in parallel with the repulsion
    /// spring, and of one in parallel with the friction spring inside the Coulomb cap (0: the
    /// seed's undamped springs). It damps approach and rebound but not sliding
    /// along a face, where P stays constant even where the smoothed normal tilts at a corner.
    pub damping_ratio: f64,
}

impl Default for ContactParams {
    fn default() -> Self {
        ContactParams {
            model: ContactModel::Extrapolated,
            friction: 0.0,
            normal_stiffness_pa: None,
            tangential_stiffness_pa: None,
            damping_ratio: 0.0,
        }
    }
}

/// The default repulsion stiffness k_r of eq. 24 (N/m²): the spring whose period on a particle of
/// mass ρΔx² equals the material's CFL step, m/k = (h/c)², so k = ρc²/(h/Δx)².
pub fn cfl_matched_stiffness(m: &Material, h_over_dx: f64) -> f64 {
    m.density_kg_m3 * m.sound_speed().powi(2) / h_over_dx.powi(2)
}

/// A primary–secondary pair with its resolved stiffnesses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactPair {
    /// Primary (rigid) body index.
    pub primary: usize,
    /// Secondary body index.
    pub secondary: usize,
    /// Parameters with stiffnesses resolved.
    pub params: ContactParams,
    /// k_r (N/m²).
    pub k_r: f64,
    /// k_f (N/m²).
    pub k_f: f64,
    /// Friction spring Δl of eq. 25 per particle (zero while out of contact).
    pub spring: Vec<Vector>,
    /// Penetration of the previous step per particle (0 while out of contact), for the dashpot.
    pub penetration: Vec<f64>,
    /// Smallest mass of a particle the springs act on (kg/m), for the contact time step.
    pub min_mass: f64,
}

impl ContactPair {
    /// Whether a particle of body `body` with `flags` carries this pair's springs: any particle
    /// of the secondary, boundary particles of the primary.
    pub fn touches(&self, body: usize, flags: u8) -> bool {
        body == self.secondary || (body == self.primary && flags & crate::particles::BOUNDARY != 0)
    }
}

/// Geometry of one secondary particle relative to the primary surface.
#[derive(Debug, Clone, Copy)]
pub struct Detection {
    /// Penetration P = Δx − d (eq. 23), positive in contact.
    pub penetration: f64,
    /// Distance d from the primary surface (eq. 21) (m).
    pub distance: f64,
    /// Outward unit normal of the primary surface seen by the particle (eq. 22).
    pub normal: Vector,
    /// Repulsion force (eq. 24) (N/m).
    pub repulsion: Vector,
    /// Nearest primary boundary particle.
    pub nearest: usize,
}

/// The contact detection of one pair (eqs. 21–24): its model, the kernel that weights the primary
/// surface, the equilibrium distance Δx and the repulsion stiffness k_r.
#[derive(Debug, Clone, Copy)]
pub struct Detector<'a> {
    /// How distance and normal are found.
    pub model: ContactModel,
    /// The kernel of eqs. 21–22's weights.
    pub kernel: &'a Kernel,
    /// Equilibrium distance Δx (m): the penetration is P = Δx − d (eq. 23).
    pub dx: f64,
    /// Repulsion stiffness k_r (eq. 24) (N/m²).
    pub k_r: f64,
}

impl Detector<'_> {
    /// Finds distance, normal and repulsion for the secondary particle at `xi` from the primary
    /// boundary particles `js` (positions `pos`, volumes `vol`); `None` if none is in range.
    pub fn detect(
        &self,
        xi: Vector,
        js: impl Iterator<Item = usize> + Clone,
        pos: &[Vector],
        vol: impl Fn(usize) -> f64,
    ) -> Option<Detection> {
        let Detector {
            model,
            kernel,
            dx,
            k_r,
        } = *self;
        let mut nearest = usize::MAX;
        let mut best = f64::INFINITY;
        match model {
            ContactModel::Extrapolated => {
                let (mut sw, mut nsum) = (0.0, Vector::zeros());
                for j in js.clone() {
                    let xij = xi - pos[j];
                    let r = xij.norm();
                    if r < best {
                        best = r;
                        nearest = j;
                    }
                    let w = vol(j) * kernel.w(r);
                    if w > 0.0 && r > 0.0 {
                        sw += w;
                        nsum += xij * (w / r);
                    }
                }
                if sw <= 0.0 || nsum.norm() == 0.0 {
                    return None;
                }
                // Eq. 22 averages unit vectors, so its length is below one; it is a direction.
                let n = nsum.normalize();
                let mut d = 0.0;
                for j in js {
                    let xij = xi - pos[j];
                    d += n.dot(&xij) * vol(j) * kernel.w(xij.norm());
                }
                d /= sw;
                let p = dx - d;
                Some(Detection {
                    penetration: p,
                    distance: d,
                    normal: n,
                    repulsion: n * (k_r * p.max(0.0)),
                    nearest,
                })
            }
            ContactModel::Penetration => {
                let mut f = Vector::zeros();
                for j in js {
                    let xij = xi - pos[j];
                    let r = xij.norm();
                    if r < best {
                        best = r;
                        nearest = j;
                    }
                    if r < dx && r > 0.0 {
                        f += xij * (k_r * (dx - r) / r);
                    }
                }
                if nearest == usize::MAX {
                    return None;
                }
                let fn_ = f.norm();
                let n = if fn_ > 0.0 {
                    f / fn_
                } else {
                    (xi - pos[nearest]).normalize()
                };
                let p = fn_ / k_r;
                Some(Detection {
                    penetration: p,
                    distance: best,
                    normal: n,
                    repulsion: f,
                    nearest,
                })
            }
        }
    }
}

/// The Cundall–Strack friction spring of eqs. 25–27: stiffness k_f, a dashpot c_t in parallel
/// with it and the Coulomb coefficient μ.
///
/// `c_t` is optional (0 in the seed); it sits inside the Coulomb cap, so it damps a sticking
/// contact's ringing and leaves sliding friction alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Friction {
    /// Spring stiffness k_f (eq. 25) (N/m²).
    pub k_f: f64,
    /// Dashpot coefficient c_t (N·s/m²).
    pub c_t: f64,
    /// Coulomb coefficient μ (eq. 27).
    pub mu: f64,
}

impl Friction {
    /// Advances the spring `dl` by the relative velocity over `dt` in the contact plane and
    /// returns the friction force, capped at μ|f_r| (eqs. 25–27).
    ///
    /// In 2D the contact plane is a line, so the tangent of eq. 26 is the normal turned by 90°
    /// (eq. 26 gives the same line up to sign, and is undefined when x_ij is parallel to n).
    /// While the cap is active the spring is shortened to match it, as Cundall & Strack do, so
    /// a sliding contact does not store energy that would snap back when it sticks again.
    pub fn force(
        &self,
        dl: &mut Vector,
        v_rel: Vector,
        normal: Vector,
        dt: f64,
        f_r: f64,
    ) -> Vector {
        let Friction { k_f, c_t, mu } = *self;
        let t = perp(normal);
        let vt = v_rel.dot(&t);
        let s = dl.dot(&t) + vt * dt;
        let mut ff = t * (-k_f * s - c_t * vt);
        let cap = mu * f_r;
        let mag = ff.norm();
        if mag > cap {
            ff *= if mag > 0.0 { cap / mag } else { 0.0 };
            *dl = -ff / k_f;
        } else {
            *dl = t * s;
        }
        ff
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extrapolated_distance_is_exact_above_a_flat_layer() {
        let dx = 1.0;
        let k = Kernel::new(crate::kernel::KernelKind::Quintic, 1.3 * dx);
        let pos: Vec<Vector> = (-10..=10)
            .map(|i| Vector::new(i as f64 * dx, 0.0))
            .collect();
        let probe = Detector {
            model: ContactModel::Extrapolated,
            kernel: &k,
            dx,
            k_r: 1.0,
        };
        for &(x, z) in &[(0.0, 0.9), (0.5, 0.95), (2.5, 1.2)] {
            let d = probe
                .detect(Vector::new(x, z), 0..pos.len(), &pos, |_| 1.0)
                .unwrap();
            assert!(
                (d.distance - z).abs() < 1e-12,
                "d = {} at z = {z}",
                d.distance
            );
            assert!((d.normal - Vector::new(0.0, 1.0)).norm() < 1e-12);
        }
        // Elsewhere the kernel-weighted normal tilts a little: the residual roughness of the
        // extrapolated model, four orders below the spacing.
        for &x in &[0.1, 0.3, 0.7] {
            let xi = Vector::new(x, 0.95);
            let d = probe.detect(xi, 0..pos.len(), &pos, |_| 1.0).unwrap();
            assert!(
                (d.distance - 0.95).abs() < 1e-4 * dx,
                "d = {} at x = {x}",
                d.distance
            );
        }
    }

    #[test]
    fn friction_caps_at_coulomb_and_sticks_below() {
        let n = Vector::new(0.0, 1.0);
        let law = Friction {
            k_f: 1e3,
            c_t: 0.0,
            mu: 0.5,
        };
        let mut dl = Vector::zeros();
        let f = law.force(&mut dl, Vector::new(1.0, 0.0), n, 1e-3, 10.0);
        assert!((f.x + 1.0).abs() < 1e-12, "stick: f = -k dl = -1, got {f}");
        let f = law.force(&mut dl, Vector::new(100.0, 0.0), n, 1e-3, 10.0);
        assert!((f.norm() - 5.0).abs() < 1e-12);
        assert!((dl.x - 5e-3).abs() < 1e-15, "spring shortened to the cap");
    }
}
