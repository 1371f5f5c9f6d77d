//! SPH smoothing kernels (seed eq. 4, a Wendland C2 alternative and the cubic spline of the
//! water-jet scene), 2D normalisation.

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
    /// Cubic B-spline (M4) of Monaghan & Lattanzio 1985, support 2h: the kernel of the AWJ
    /// paper (Sci. Rep. 14, 26115, 2024; docs/jet.md#cubic-spline-kernel).
    CubicSpline,
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
    /// A kernel of smoothing length `h`, normalised in 2D (seed eq. 4: k = 7/(478π); Wendland C2
    /// 7/(4π); cubic spline 10/(7π)).
    pub fn new(kind: KernelKind, h: f64) -> Self {
        let k = match kind {
            KernelKind::Quintic => 7.0 / (478.0 * PI),
            KernelKind::WendlandC2 => 7.0 / (4.0 * PI),
            KernelKind::CubicSpline => 10.0 / (7.0 * PI),
        };
        Kernel {
            kind,
            h,
            inv_h: 1.0 / h,
            norm: k / (h * h),
        }
    }

    /// Support radius in units of h (3 for the quintic, 2 for Wendland C2 and the cubic spline).
    pub fn support_factor(&self) -> f64 {
        match self.kind {
            KernelKind::Quintic => 3.0,
            KernelKind::WendlandC2 | KernelKind::CubicSpline => 2.0,
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

    /// The quintic's W and dW/dr at q = r/h (seed eq. 4).
    #[inline(always)]
    fn quintic(&self, q: f64) -> (f64, f64) {
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

    /// `w_dw` of several distances, lane by lane by the same operations, so that the square
    /// roots and quotients around it can be packed.
    #[inline(always)]
    pub fn w_dw_lanes<const L: usize>(&self, r: [f64; L]) -> ([f64; L], [f64; L]) {
        let (mut w, mut dw) = ([0.0; L], [0.0; L]);
        if self.kind == KernelKind::Quintic {
            for n in 0..L {
                (w[n], dw[n]) = self.quintic(r[n] * self.inv_h);
            }
        } else {
            for n in 0..L {
                (w[n], dw[n]) = self.w_dw(r[n]);
            }
        }
        (w, dw)
    }

    /// W(r) and dW/dr together (dW/dr in 1/m³); shares the powers of (3 − q). Always inlined:
    /// the pair loops call it once per pair, where a call costs more than its arithmetic.
    #[inline(always)]
    pub fn w_dw(&self, r: f64) -> (f64, f64) {
        let q = r * self.inv_h;
        match self.kind {
            KernelKind::Quintic => self.quintic(q),
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
            KernelKind::CubicSpline => {
                // W/norm = 1 − 3q²/2 + 3q³/4 (q < 1), (2 − q)³/4 (1 ≤ q < 2), written as
                // [(2 − q)₊³ − 4 (1 − q)₊³]/4 with the same clamped powers as the quintic.
                let a = (2.0 - q).max(0.0);
                let c = (1.0 - q).max(0.0);
                let (a2, c2) = (a * a, c * c);
                let w = 0.25 * (a2 * a - 4.0 * c2 * c);
                let dw = 3.0 * c2 - 0.75 * a2;
                (self.norm * w, self.norm * self.inv_h * dw)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [KernelKind; 3] = [
        KernelKind::Quintic,
        KernelKind::WendlandC2,
        KernelKind::CubicSpline,
    ];

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
        for kind in ALL {
            let k = Kernel::new(kind, 1.3e-3);
            let (m0, _) = integrate(&k);
            assert!((m0 - 1.0).abs() < 1e-6, "{kind:?}: ∫W = {m0}");
        }
    }

    #[test]
    fn derivative_matches_finite_difference() {
        for kind in ALL {
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

    #[test]
    fn cubic_spline_values_and_serde_name() {
        let h = 2.0;
        let k = Kernel::new(KernelKind::CubicSpline, h);
        let norm = 10.0 / (7.0 * PI * h * h);
        // The piecewise form term by term, and its two joints.
        assert!((k.w(0.0) - norm).abs() < 1e-15);
        assert!((k.w(0.5 * h) - norm * (1.0 - 1.5 * 0.25 + 0.75 * 0.125)).abs() < 1e-15);
        assert!((k.w(h) - 0.25 * norm).abs() < 1e-15);
        assert!((k.w(1.5 * h) - norm * 0.25 * 0.125).abs() < 1e-15);
        assert_eq!(k.w_dw(2.0 * h), (0.0, 0.0));
        assert_eq!(k.w_dw(3.0 * h), (0.0, 0.0));
        assert_eq!(k.w_dw(0.0).1, 0.0);
        // dW/dq is continuous at q = 1 (−3/4 from both sides).
        let (_, d1) = k.w_dw(h);
        assert!((d1 + 0.75 * norm / h).abs() < 1e-15);
        assert_eq!(k.radius(), 2.0 * h);
        assert_eq!(
            serde_json::to_string(&KernelKind::CubicSpline).unwrap(),
            "\"cubic_spline\""
        );
        let back: KernelKind = serde_json::from_str("\"cubic_spline\"").unwrap();
        assert_eq!(back, KernelKind::CubicSpline);
    }

    #[test]
    fn lattice_sums_are_near_one() {
        // On a square lattice of spacing Δx = h/1.3 the sum Σ W Δx² is the discrete ∫W = 1:
        // quintic and cubic spline within 1e-4, Wendland C2 1 % high.
        for kind in ALL {
            let dx = 1.0;
            let k = Kernel::new(kind, 1.3 * dx);
            let n = 6;
            let mut s = 0.0;
            for i in -n..=n {
                for j in -n..=n {
                    let r = ((i * i + j * j) as f64).sqrt() * dx;
                    s += k.w(r) * dx * dx;
                }
            }
            assert!((s - 1.0).abs() < 0.02, "{kind:?}: lattice ΣW = {s}");
        }
    }
}
