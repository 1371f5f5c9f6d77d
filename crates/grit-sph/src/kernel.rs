//! SPH smoothing kernels (seed eq. 4 and a Wendland C2 alternative), 2D normalisation.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which kernel function W(r, h) the engine uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum KernelKind {
    /// Quintic spline of Morris et al., seed eq. 4, support 3h.
    #[default]
    Quintic,
    /// Wendland C2 (Wendland 1995), support 2h; a cheaper kernel for the speed–accuracy study.
    WendlandC2,
}

/// A kernel of fixed smoothing length h, with its normalisation precomputed.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct Kernel {
    /// The kernel function.
    pub kind: KernelKind,
    /// Smoothing length h (m).
    pub h: f64,
    inv_h: f64,
    norm: f64,
}

impl Kernel {
    /// A kernel of smoothing length `h`, normalised in 2D (seed eq. 4: k = 7/(478π)).
    pub fn new(kind: KernelKind, h: f64) -> Self {
        let k = match kind {
            KernelKind::Quintic => 7.0 / (478.0 * PI),
            KernelKind::WendlandC2 => 7.0 / (4.0 * PI),
        };
        Kernel {
            kind,
            h,
            inv_h: 1.0 / h,
            norm: k / (h * h),
        }
    }

    /// Support radius in units of h (3 for the quintic, 2 for Wendland C2).
    pub fn support_factor(&self) -> f64 {
        match self.kind {
            KernelKind::Quintic => 3.0,
            KernelKind::WendlandC2 => 2.0,
        }
    }

    /// Support radius (m): W = 0 beyond it.
    pub fn radius(&self) -> f64 {
        self.support_factor() * self.h
    }

    /// W(r) (1/m²), seed eq. 4.
    #[inline]
    pub fn w(&self, r: f64) -> f64 {
        self.w_dw(r).0
    }

    /// W(r) and dW/dr together (dW/dr in 1/m³); shares the powers of (3 − q).
    #[inline]
    pub fn w_dw(&self, r: f64) -> (f64, f64) {
        let q = r * self.inv_h;
        match self.kind {
            KernelKind::Quintic => {
                // Clamped powers instead of branches on q: pairs come in random order of q, and
                // mispredicted branches cost more than the spare arithmetic. A term that is
                // clamped to zero adds exactly +0, so the values equal the branchy form's.
                let a = (3.0 - q).max(0.0);
                let b = (2.0 - q).max(0.0);
                let c = (1.0 - q).max(0.0);
                let (a4, b4, c4) = (a * a * a * a, b * b * b * b, c * c * c * c);
                let mut w = a4 * a;
                let mut dw = -5.0 * a4;
                w -= 6.0 * b4 * b;
                dw += 30.0 * b4;
                w += 15.0 * c4 * c;
                dw -= 75.0 * c4;
                (self.norm * w, self.norm * self.inv_h * dw)
            }
            KernelKind::WendlandC2 => {
                if q >= 2.0 {
                    return (0.0, 0.0);
                }
                let a = 1.0 - 0.5 * q;
                let a3 = a * a * a;
                let w = a3 * a * (2.0 * q + 1.0);
                // d/dq [(1-q/2)^4 (2q+1)] = -5 q (1-q/2)^3
                let dw = -5.0 * q * a3;
                (self.norm * w, self.norm * self.inv_h * dw)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn integrate(k: &Kernel) -> (f64, f64) {
        // ∫ W dA = 1 and ∫ r² W dA gives the second moment; midpoint rule in r.
        let n = 20000;
        let rmax = k.radius();
        let dr = rmax / n as f64;
        let (mut m0, mut m2) = (0.0, 0.0);
        for i in 0..n {
            let r = (i as f64 + 0.5) * dr;
            let w = k.w(r);
            m0 += 2.0 * PI * r * w * dr;
            m2 += 2.0 * PI * r * r * r * w * dr;
        }
        (m0, m2)
    }

    #[test]
    fn kernels_are_normalised_in_2d() {
        for kind in [KernelKind::Quintic, KernelKind::WendlandC2] {
            let k = Kernel::new(kind, 1.3e-3);
            let (m0, _) = integrate(&k);
            assert!((m0 - 1.0).abs() < 1e-6, "{kind:?}: ∫W = {m0}");
        }
    }

    #[test]
    fn derivative_matches_finite_difference() {
        for kind in [KernelKind::Quintic, KernelKind::WendlandC2] {
            let k = Kernel::new(kind, 0.7);
            for i in 1..60 {
                let r = i as f64 * 0.035;
                let e = 1e-6;
                let fd = (k.w(r + e) - k.w(r - e)) / (2.0 * e);
                let (_, dw) = k.w_dw(r);
                assert!(
                    (fd - dw).abs() < 1e-6 * (1.0 + dw.abs()),
                    "{kind:?} r={r}: {fd} vs {dw}"
                );
            }
        }
    }
}
