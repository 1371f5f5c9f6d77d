//! Unresolved SPH–DEM coupling of the abrasive water-jet scene: porosity of the fluid from the
//! grains, the hydrodynamic (pressure-gradient and viscous) and drag forces on each grain, and
//! their reaction spread back onto the fluid so that the pair conserves momentum (the AWJ
//! paper, Sci. Rep. 14, 26115, 2024, eqs. 19–21 and 42–50; docs/jet.md#unresolved-coupling).
//!
//! The model is plane: a grain is a disc whose volume V_i is its area π R² per metre of depth,
//! the fluid's masses are per metre of depth, and every force here is in N/m. A DEM grain that
//! carries a sphere's mass takes [`sphere_force`] of it, which gives it the disc's acceleration.

mod drag;

pub use drag::{
    drag_coefficient, drag_coefficient_times_re, drag_per_volume, reynolds, stokes_relaxation_time,
    stokes_velocity, terminal_velocity, Settling, DEFAULT_SWITCH_POROSITY, NEWTON_REYNOLDS,
};

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

use crate::dem::Grain;
use crate::error::InputError;
use crate::fluid::Fluid;
use crate::kernel::{Kernel, KernelKind};
use crate::math::Vector;

/// Parameters of the coupling (docs/jet.md#unresolved-coupling).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CouplingParams {
    /// Coupling radius over grain diameter, R_c/d; the AWJ paper settles on 2.0 (its Fig. 11).
    pub radius_factor: f64,
    /// Kernel of the coupling sums; its support is R_c, so h_c = R_c / support factor (R_c = 2 h_c
    /// for the paper's cubic spline).
    pub kernel: KernelKind,
    /// Porosity at and below which the drag is Ergun's, above Wen–Yu's (eq. 47).
    pub switch_porosity: f64,
    /// Floor of a fluid particle's porosity: eq. 20 goes below zero where grains crowd (and
    /// near a lone grain for R_c ≲ 1.3 d), which would make ρ = ρ̄/ε and Ergun's 1/ε meaningless.
    pub min_porosity: f64,
}

impl Default for CouplingParams {
    /// R_c = 2 d with the cubic spline, the switch at ε = 0.8, the floor at ε = 0.2 (near the
    /// void fraction of randomly packed equal discs).
    fn default() -> Self {
        CouplingParams {
            radius_factor: 2.0,
            kernel: KernelKind::CubicSpline,
            switch_porosity: DEFAULT_SWITCH_POROSITY,
            min_porosity: 0.2,
        }
    }
}

impl CouplingParams {
    /// Checks the parameters; errors name `field.<parameter>` and the rule.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        InputError::require_positive(format!("{field}.radius_factor"), self.radius_factor)?;
        for (name, v) in [
            ("switch_porosity", self.switch_porosity),
            ("min_porosity", self.min_porosity),
        ] {
            if !(v.is_finite() && v > 0.0 && v < 1.0) {
                return Err(InputError::new(
                    format!("{field}.{name}"),
                    format!("must lie in (0, 1), got {v}"),
                ));
            }
        }
        Ok(())
    }

    /// The coupling kernel of a grain of radius `r` (m): support R_c = radius_factor · 2r.
    pub fn kernel(&self, r: f64) -> Kernel {
        let probe = Kernel::new(self.kernel, 1.0);
        Kernel::new(
            self.kernel,
            self.radius_factor * 2.0 * r / probe.support_factor(),
        )
    }
}

/// Volume V_i of a grain in the plane model: its disc area π R² (m² per metre of depth).
#[inline]
pub fn disc_area(r: f64) -> f64 {
    PI * r * r
}

/// The force (N) on a DEM grain that carries a sphere's mass, from a plane force `f` (N/m) on
/// its disc: f · 4R/3, the sphere's volume over the disc's area, so that both accelerate alike.
#[inline]
pub fn sphere_force(f: Vector, r: f64) -> Vector {
    f * (4.0 / 3.0 * r)
}

/// The fluid particles as the coupling reads them (slices of equal length).
#[derive(Debug, Clone, Copy)]
pub struct FluidView<'a> {
    /// Positions x_a (m).
    pub position: &'a [Vector],
    /// Velocities v_a (m/s).
    pub velocity: &'a [Vector],
    /// Masses m_a (kg/m).
    pub mass: &'a [f64],
    /// Porosity-weighted densities ρ̄_a = ε_a ρ_a (kg/m³), the AWJ paper eq. 21.
    pub rho_bar: &'a [f64],
}

impl FluidView<'_> {
    fn validate(&self) -> Result<(), InputError> {
        let n = self.position.len();
        for (name, len) in [
            ("fluid.velocity", self.velocity.len()),
            ("fluid.mass", self.mass.len()),
            ("fluid.rho_bar", self.rho_bar.len()),
        ] {
            if len != n {
                return Err(InputError::new(
                    name,
                    format!("has {len} entries for {n} fluid positions"),
                ));
            }
        }
        for a in 0..n {
            InputError::require_positive(format!("fluid.mass[{a}]"), self.mass[a])?;
            InputError::require_positive(format!("fluid.rho_bar[{a}]"), self.rho_bar[a])?;
        }
        Ok(())
    }

    /// V_a = m_a/ρ̄_a, the volume a particle stands for in the averaged sums.
    #[inline]
    fn volume(&self, a: usize) -> f64 {
        self.mass[a] / self.rho_bar[a]
    }
}

/// One grain–fluid pair within the grain's coupling radius, with its kernel weight W_ia(h_c).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair {
    /// Grain index i.
    pub grain: usize,
    /// Fluid particle index a.
    pub fluid: usize,
    /// W(|x_i − x_a|, h_c) (1/m²).
    pub w: f64,
}

/// The grain–fluid pairs within R_c (eqs. 20, 43, 45, 46, 50 all sum over them), ordered by
/// grain and then fluid index so that every sum is repeatable. Fluid particles are sorted on x
/// once and each grain scans its window; errors name a grain with a bad radius.
pub fn find_pairs(
    params: &CouplingParams,
    fluid_position: &[Vector],
    grains: &[Grain],
) -> Result<Vec<Pair>, InputError> {
    params.validate("coupling")?;
    for (i, g) in grains.iter().enumerate() {
        InputError::require_positive(format!("grains[{i}].radius_m"), g.radius_m)?;
    }
    let mut order: Vec<usize> = (0..fluid_position.len()).collect();
    order.sort_by(|&a, &b| fluid_position[a].x.total_cmp(&fluid_position[b].x));
    let xs: Vec<f64> = order.iter().map(|&a| fluid_position[a].x).collect();
    let mut pairs = Vec::new();
    let mut found = Vec::new();
    for (i, g) in grains.iter().enumerate() {
        let k = params.kernel(g.radius_m);
        let rc = k.radius();
        let start = xs.partition_point(|&x| x < g.pos.x - rc);
        let end = xs.partition_point(|&x| x <= g.pos.x + rc);
        found.clear();
        for &a in &order[start..end] {
            let r = (fluid_position[a] - g.pos).norm();
            if r < rc {
                found.push(Pair {
                    grain: i,
                    fluid: a,
                    w: k.w(r),
                });
            }
        }
        found.sort_by_key(|p| p.fluid);
        pairs.extend_from_slice(&found);
    }
    Ok(pairs)
}

/// Porosity of the fluid particles, eq. 20, and how many hit the floor.
#[derive(Debug, Clone, PartialEq)]
pub struct Porosity {
    /// ε_a = max(1 − Σ_j W_aj(h_c) V_j, floor), per fluid particle.
    pub values: Vec<f64>,
    /// Number of particles whose porosity was raised to the floor.
    pub floored: usize,
}

/// Porosity ε_a = 1 − Σ_j W_aj(h_c) V_j of `n_fluid` particles (the AWJ paper eq. 20), V_j the
/// disc area of grain j, floored at `params.min_porosity`; 1 away from every grain.
pub fn porosity(
    params: &CouplingParams,
    n_fluid: usize,
    grains: &[Grain],
    pairs: &[Pair],
) -> Porosity {
    let mut values = vec![1.0; n_fluid];
    for p in pairs {
        values[p.fluid] -= p.w * disc_area(grains[p.grain].radius_m);
    }
    let mut floored = 0;
    for e in &mut values {
        if *e < params.min_porosity {
            *e = params.min_porosity;
            floored += 1;
        }
    }
    Porosity { values, floored }
}

/// What the fluid looks like from one grain: Shepard averages over its coupling radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrainFluid {
    /// S_i = Σ_a (m_a/ρ̄_a) W_ia (eq. 50); 0 when no fluid is within R_c.
    pub shepard: f64,
    /// ε_i, the Shepard average of the fluid's porosity (eq. 45); 1 without fluid.
    pub porosity: f64,
    /// v̄_f, the Shepard average of the fluid's velocity (eq. 46); 0 without fluid.
    pub velocity: Vector,
}

/// Forces of one coupling evaluation (N/m), equal and opposite in sum.
#[derive(Debug, Clone, PartialEq)]
pub struct CouplingForces {
    /// F_af on each grain (eq. 42): hydrodynamic plus drag.
    pub on_grains: Vec<Vector>,
    /// The drag part F_d of each grain's force (eq. 44), for reports.
    pub drag: Vec<Vector>,
    /// F_fa on each fluid particle (eq. 50); its acceleration is F_fa/m_a.
    pub on_fluid: Vec<Vector>,
    /// The fluid as each grain sees it.
    pub grain_fluid: Vec<GrainFluid>,
}

/// The coupling forces of the AWJ paper eqs. 42–50 on every grain and fluid particle.
///
/// `porosity` is ε_a from [`porosity`]; `theta` is θ_a of eq. 43, each fluid particle's
/// pressure plus laminar-viscous acceleration Σ_b m_b[−(P_a/ρ̄_a² + P_b/ρ̄_b²) + Π^visc]∇W_ab
/// (m/s²), which the engine sums anyway. Per grain i:
///
/// - hydrodynamic force V_i Σ_a m_a θ_a W_ia / S_i (eq. 43 with the Shepard sum over
///   V_a = m_a/ρ̄_a: docs/jet.md#unresolved-coupling explains why not m_a/ρ_a);
/// - drag F_d = [β/(1 − ε_i)] V_i (v̄_f − v_i) ([`drag_per_volume`], eqs. 44–49), with ρ_f the
///   fluid's reference density and d = 2R;
/// - reaction on fluid particle a: −V_a Σ_i F_af,i W_ai / S_i (eq. 50), whose sum over a is
///   −F_af,i for every grain, so momentum is conserved to rounding.
///
/// Errors name the slice or entry at fault.
pub fn coupling_forces(
    params: &CouplingParams,
    fluid_props: &Fluid,
    fluid: FluidView<'_>,
    porosity: &[f64],
    theta: &[Vector],
    grains: &[Grain],
    pairs: &[Pair],
) -> Result<CouplingForces, InputError> {
    params.validate("coupling")?;
    fluid.validate()?;
    let n = fluid.position.len();
    for (name, len) in [("porosity", porosity.len()), ("theta", theta.len())] {
        if len != n {
            return Err(InputError::new(
                name,
                format!("has {len} entries for {n} fluid particles"),
            ));
        }
    }
    if let Some(p) = pairs
        .iter()
        .find(|p| p.grain >= grains.len() || p.fluid >= n)
    {
        return Err(InputError::new(
            "pairs",
            format!(
                "pair (grain {}, fluid {}) is out of range ({} grains, {n} fluid particles)",
                p.grain,
                p.fluid,
                grains.len()
            ),
        ));
    }
    let m = grains.len();
    let mut grain_fluid = vec![
        GrainFluid {
            shepard: 0.0,
            porosity: 0.0,
            velocity: Vector::zeros(),
        };
        m
    ];
    let mut hydro = vec![Vector::zeros(); m];
    for p in pairs {
        let vw = fluid.volume(p.fluid) * p.w;
        let gf = &mut grain_fluid[p.grain];
        gf.shepard += vw;
        gf.porosity += porosity[p.fluid] * vw;
        gf.velocity += fluid.velocity[p.fluid] * vw;
        hydro[p.grain] += theta[p.fluid] * (fluid.mass[p.fluid] * p.w);
    }
    let (rho_f, mu) = (fluid_props.density(), fluid_props.dynamic_viscosity_pa_s);
    let mut on_grains = vec![Vector::zeros(); m];
    let mut drag = vec![Vector::zeros(); m];
    for (i, g) in grains.iter().enumerate() {
        let gf = &mut grain_fluid[i];
        if gf.shepard <= 0.0 {
            gf.porosity = 1.0;
            continue;
        }
        gf.porosity /= gf.shepard;
        gf.velocity /= gf.shepard;
        let v_i = disc_area(g.radius_m);
        let slip = gf.velocity - g.vel;
        let k = drag_per_volume(
            gf.porosity,
            slip.norm(),
            2.0 * g.radius_m,
            rho_f,
            mu,
            params.switch_porosity,
        );
        drag[i] = slip * (k * v_i);
        on_grains[i] = hydro[i] * (v_i / gf.shepard) + drag[i];
    }
    let mut on_fluid = vec![Vector::zeros(); n];
    for p in pairs {
        let gf = &grain_fluid[p.grain];
        if gf.shepard > 0.0 {
            on_fluid[p.fluid] -= on_grains[p.grain] * (fluid.volume(p.fluid) * p.w / gf.shepard);
        }
    }
    Ok(CouplingForces {
        on_grains,
        drag,
        on_fluid,
        grain_fluid,
    })
}

#[cfg(test)]
mod tests;
