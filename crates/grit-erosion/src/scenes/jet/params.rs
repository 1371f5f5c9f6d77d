//! The parameters of one jet run (docs/jet.md#the-scene), their limits and validation.

use grit_sph::dem::DemParams;
use grit_sph::{InputError, PenaltyParams};
use serde::{Deserialize, Serialize};

use super::scene::FIXED_SIDE_LAYERS;
use crate::campaign::MaterialSpec;

/// Everything that defines one jet run (one sample of a jet campaign's cell); SI units except
/// where the name says. Defaults: the paper's copper case at 500 m/s on a reduced scene
/// (docs/jet.md#the-scene).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct JetParams {
    /// Target material: a preset name (`copper`, `al6061`, `aisi304`, `sandstone`, `granite`) or
    /// a full object.
    pub material: MaterialSpec,
    /// Jet speed v_jet at the nozzle (m/s).
    pub velocity_m_s: f64,
    /// Abrasive mass flow M (kg/s, the paper's eq. 55); 0 is a pure water jet.
    pub mass_flow_kg_s: f64,
    /// Simulated time T (ms).
    pub time_ms: f64,
    /// Length of one slice of simulated time, the unit of progress and checkpoints (ms).
    pub slice_ms: f64,
    /// Particle spacing Δx of water and target (m); the paper's d_ini is 50 µm.
    pub spacing_m: f64,
    /// Coupling radius over grain diameter, R_c/d (the paper settles on 2.0).
    pub coupling_radius_d: f64,
    /// Jet width d_jet (m; the paper's 1 mm); a whole number of spacings.
    pub jet_width_m: f64,
    /// Height of the nozzle's exit above the target's top (m; the paper gives none).
    pub standoff_m: f64,
    /// Target width (m).
    pub target_width_m: f64,
    /// Target depth (m).
    pub target_depth_m: f64,
    /// Hold the target's bottom layers fixed, as its sides (the default: the target is a window
    /// into a thick plate); false leaves the bottom free, as the paper does
    /// (docs/jet.md#the-scene). Written out only when false, so default scenes keep their bytes.
    #[serde(skip_serializing_if = "is_true")]
    pub fixed_bottom: bool,
    /// Grain diameter d (m; the paper's 0.2 mm garnet).
    pub grain_diameter_m: f64,
    /// Grain density (kg/m³; garnet 4120).
    pub grain_density_kg_m3: f64,
    /// A grain's speed as it leaves the nozzle over v_jet, in (0, 1] (the paper gives none; 1:
    /// grains move with the water; docs/jet.md#one-grain-in-the-jet). The feed keeps the mass
    /// flow M of eq. 55 whatever the ratio.
    pub grain_speed_ratio: f64,
    /// The porosity at and below which a grain's drag is Ergun's, above it Wen–Yu's (the AWJ
    /// paper's eq. 44 switch, 0.8 after Gidaspow; in (0, 1); docs/jet.md#one-grain-in-the-jet).
    pub drag_switch_porosity: f64,
    /// The grains' contact constants (E, ν, restitution e, friction μ).
    pub dem: DemParams,
    /// The grain–target penalty contact (χ, μ).
    pub penalty: PenaltyParams,
}

/// Serde's test for a field written out only when false.
pub(crate) fn is_true(b: &bool) -> bool {
    *b
}

impl Default for JetParams {
    fn default() -> Self {
        JetParams {
            material: MaterialSpec(grit_sph::Material::copper()),
            velocity_m_s: 500.0,
            mass_flow_kg_s: 0.02,
            time_ms: 1.0,
            slice_ms: 0.05,
            spacing_m: 50e-6,
            coupling_radius_d: 2.0,
            jet_width_m: 1e-3,
            standoff_m: 2e-3,
            target_width_m: 6e-3,
            target_depth_m: 2e-3,
            fixed_bottom: true,
            grain_diameter_m: 0.2e-3,
            grain_density_kg_m3: 4120.0,
            grain_speed_ratio: 1.0,
            drag_switch_porosity: grit_sph::coupling::DEFAULT_SWITCH_POROSITY,
            dem: DemParams::default(),
            penalty: PenaltyParams::default(),
        }
    }
}

/// Most slices one run may have: a guard against a typo that asks for years of steps.
pub const MAX_SLICES: u32 = 100_000;
/// Longest run (ms): past the seed's longest (60 ms), a guard against a typo in the units.
pub const MAX_TIME_MS: f64 = 1000.0;
/// Fastest jet (m/s): above any pump's (a 600 MPa pump gives about 770 m/s, AWJ eq. v = 0.7 √(2P/ρ)).
pub const MAX_JET_SPEED_M_S: f64 = 2000.0;
/// Most particles of the target and the jet's column: a guard against a spacing or size typo
/// that would exhaust a worker's memory.
pub const MAX_SCENE_PARTICLES: f64 = 5e5;

impl JetParams {
    /// A small, fast jet (the AWJ paper's scene reduced): 6 particles across a 0.6 mm jet, a
    /// 3 × 0.8 mm copper target, 0.6 mm standoff, 0.2 mm grains at 0.01 kg/s, 4 µs in slices of
    /// 1 µs; every stage of the scene runs in about a second, so tests use it.
    pub fn small() -> JetParams {
        JetParams {
            spacing_m: 1e-4,
            jet_width_m: 6e-4,
            target_width_m: 3e-3,
            target_depth_m: 8e-4,
            standoff_m: 6e-4,
            grain_diameter_m: 2e-4,
            mass_flow_kg_s: 0.01,
            time_ms: 0.004,
            slice_ms: 0.001,
            ..JetParams::default()
        }
    }

    /// Checks every field; the error names the field and the rule.
    pub fn validate(&self) -> Result<(), InputError> {
        self.material.0.validate()?;
        for (name, v) in [
            ("velocity_m_s", self.velocity_m_s),
            ("time_ms", self.time_ms),
            ("slice_ms", self.slice_ms),
            ("spacing_m", self.spacing_m),
            ("coupling_radius_d", self.coupling_radius_d),
            ("jet_width_m", self.jet_width_m),
            ("standoff_m", self.standoff_m),
            ("target_width_m", self.target_width_m),
            ("target_depth_m", self.target_depth_m),
            ("grain_diameter_m", self.grain_diameter_m),
            ("grain_density_kg_m3", self.grain_density_kg_m3),
        ] {
            InputError::require_positive(name, v)?;
        }
        crate::impact::check_grain_density(self.grain_density_kg_m3)?;
        // The paper studies 1.0 to 3.0 d; the pair search grows as R_c².
        if !(0.5..=10.0).contains(&self.coupling_radius_d) {
            return Err(InputError::new(
                "coupling_radius_d",
                format!(
                    "must lie in [0.5, 10] grain diameters (the paper's study spans 1 to 3), got {}",
                    InputError::shown(self.coupling_radius_d)
                ),
            ));
        }
        if !(self.grain_speed_ratio > 0.0 && self.grain_speed_ratio <= 1.0) {
            return Err(InputError::new(
                "grain_speed_ratio",
                format!("must lie in (0, 1], got {}", self.grain_speed_ratio),
            ));
        }
        if !(self.drag_switch_porosity > 0.0 && self.drag_switch_porosity < 1.0) {
            return Err(InputError::new(
                "drag_switch_porosity",
                format!("must lie in (0, 1), got {}", self.drag_switch_porosity),
            ));
        }
        if !(self.mass_flow_kg_s.is_finite() && self.mass_flow_kg_s >= 0.0) {
            return Err(InputError::new(
                "mass_flow_kg_s",
                format!(
                    "must be a finite number >= 0, got {}",
                    InputError::shown(self.mass_flow_kg_s)
                ),
            ));
        }
        self.dem.validate()?;
        self.penalty.validate("penalty")?;
        let cells = |len: f64| len / self.spacing_m;
        let across = cells(self.jet_width_m);
        if (across - across.round()).abs() > 1e-6 || across.round() < 2.0 {
            return Err(InputError::new(
                "jet_width_m",
                format!(
                    "must be a whole number (at least 2) of spacings {} m, got {} m ({across:.4} spacings)",
                    self.spacing_m, self.jet_width_m
                ),
            ));
        }
        if self.target_width_m < self.jet_width_m + 2.0 * FIXED_SIDE_LAYERS as f64 * self.spacing_m
        {
            return Err(InputError::new(
                "target_width_m",
                format!(
                    "must exceed the jet width {} m plus the fixed sides, got {} m",
                    self.jet_width_m, self.target_width_m
                ),
            ));
        }
        if cells(self.target_depth_m) < 2.0 * FIXED_SIDE_LAYERS as f64 + 1.0 {
            return Err(InputError::new(
                "target_depth_m",
                format!(
                    "must be at least {} spacings deep (the fixed bottom and free material)",
                    2 * FIXED_SIDE_LAYERS + 1
                ),
            ));
        }
        if self.standoff_m < self.jet_width_m {
            return Err(InputError::new(
                "standoff_m",
                format!(
                    "must be at least the jet width {} m, got {} m: the stagnation zone, about a jet width deep, would reach the nozzle, whose rows have no buffer, and break the jet (docs/jet.md#the-scene)",
                    self.jet_width_m, self.standoff_m
                ),
            ));
        }
        if self.grain_diameter_m >= self.jet_width_m {
            return Err(InputError::new(
                "grain_diameter_m",
                format!(
                    "must be smaller than the jet width {} m, got {} m",
                    self.jet_width_m, self.grain_diameter_m
                ),
            ));
        }
        if self.slice_ms > self.time_ms {
            return Err(InputError::new(
                "slice_ms",
                format!(
                    "must not exceed time_ms ({}), got {}",
                    self.time_ms, self.slice_ms
                ),
            ));
        }
        if self.slices() > MAX_SLICES {
            return Err(InputError::new(
                "slice_ms",
                format!(
                    "time_ms / slice_ms gives {:.4e} slices; at most {MAX_SLICES}",
                    (self.time_ms / self.slice_ms).ceil()
                ),
            ));
        }
        InputError::require_at_most(
            "time_ms",
            self.time_ms,
            MAX_TIME_MS,
            "ms",
            "the seed's longest run is 60 ms",
        )?;
        InputError::require_at_most(
            "mass_flow_kg_s",
            self.mass_flow_kg_s,
            1.0,
            "kg/s",
            "the paper's runs go to 0.07 kg/s",
        )?;
        InputError::require_at_most(
            "velocity_m_s",
            self.velocity_m_s,
            MAX_JET_SPEED_M_S,
            "m/s",
            "abrasive water jets run at 300-900 m/s",
        )?;
        let arrival_ms = self.standoff_m / self.velocity_m_s * 1e3;
        if arrival_ms >= self.time_ms {
            return Err(InputError::new(
                "velocity_m_s",
                format!(
                    "is too slow for the run: the jet's head needs standoff_m / velocity_m_s = {} ms to reach the target, and the run lasts time_ms = {} ms",
                    InputError::shown(arrival_ms),
                    InputError::shown(self.time_ms)
                ),
            ));
        }
        let area = self.target_width_m * self.target_depth_m + self.jet_width_m * self.standoff_m;
        let particles = area / (self.spacing_m * self.spacing_m);
        if particles > MAX_SCENE_PARTICLES {
            return Err(InputError::new(
                "spacing_m",
                format!(
                    "gives {particles:.3e} particles in the target and the jet (target_width_m × target_depth_m + jet_width_m × standoff_m, over spacing_m²), more than the limit of {MAX_SCENE_PARTICLES:.0e}; the default scene has about 1 800"
                ),
            ));
        }
        Ok(())
    }

    /// Parses and checks a JSON object of parameters (fields left out keep their defaults);
    /// the error names the field at fault.
    pub fn from_json(text: &str) -> Result<JetParams, InputError> {
        let p: JetParams = crate::scene::scene_from_json(text, "JetParams")?;
        p.validate()?;
        Ok(p)
    }

    /// Target mass per unit depth (kg/m): density × width × depth, the most a run can lose
    /// (AWJ paper's target, reduced as `docs/jet.md` says).
    pub fn target_mass_kg_m(&self) -> f64 {
        self.material.0.density_kg_m3 * self.target_width_m * self.target_depth_m
    }

    /// Number of slices: ⌈T / slice⌉ (the last may be shorter).
    pub fn slices(&self) -> u32 {
        let n = (self.time_ms / self.slice_ms - 1e-9).ceil();
        if n.is_finite() && n >= 1.0 {
            n.min(u32::MAX as f64) as u32
        } else {
            1
        }
    }

    /// End time of slice `k` (0-based), s.
    pub fn slice_end_s(&self, k: u32) -> f64 {
        (((k + 1) as f64) * self.slice_ms).min(self.time_ms) * 1e-3
    }
}
