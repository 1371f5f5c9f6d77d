//! The impact scene of seed section 4 (Fig. 7a): a rigid grain, randomly oriented and aimed,
//! hitting an AISI 304 surface at speed V and angle α, run until the grain has left and the
//! surface has settled.

use grit_sph::{
    cfl_matched_stiffness, contact::ContactModel, neighbours, particles::KINEMATIC, ContactParams,
    InputError, KernelKind, Material, Motion, Particles, Polygon, Settings, SimError, Timers,
    Vector, World,
};
use serde::{Deserialize, Serialize};

use crate::shapes::Shape;

/// Everything that defines one impact scene (one cell of a campaign); SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImpactParams {
    /// Impact angle α between the grain path and the surface, degrees, in (0, 90].
    pub angle_deg: f64,
    /// Grain outline (seed Fig. 7b).
    pub shape: Shape,
    /// Impact speed V (seed: 100 m/s).
    pub velocity_m_s: f64,
    /// Grain diameter Dg: the grain has the area of a circle of this diameter (seed: 250 µm).
    pub grain_diameter_m: f64,
    /// Grain density (seed: glass, 2500 kg/m³).
    pub grain_density_kg_m3: f64,
    /// Particle spacing Δx (seed: 8 µm, about 32 particles per Dg).
    pub spacing_m: f64,
    /// Width of the band of aim points, in Dg (seed: 0.5, 1.0 or 1.5; default 1.0).
    pub distribution_range_dg: f64,
    /// Surface material (seed Table 1: AISI 304).
    pub material: Material,
    /// Grain–surface Coulomb friction μ (eq. 29). The seed does not state its value.
    pub friction: f64,
    /// Surface width in Dg (ours; the domain-size study in docs/erosion.md checks it).
    pub surface_width_dg: f64,
    /// Surface depth in Dg (ours; checked by the same study).
    pub surface_depth_dg: f64,
    /// The impact ends once the grain has left and the surface kinetic energy is below this
    /// fraction of the grain's initial kinetic energy.
    pub settle_fraction: f64,
    /// Numerical choices; the defaults are the seed's at CFL 0.6 with the density filter's
    /// period kept in time (the speed–accuracy sweep varies them).
    pub numerics: Numerics,
}

/// The numerical choices of an impact scene that the speed–accuracy and stability studies
/// vary; `Numerics::seed` holds the seed's sections 2–3, the default runs them at CFL 0.6.
///
/// In JSON it keeps one flat object of the choices a scene may set (`NumericsJson`): the
/// engine's `kernel`, `cfl`, `hourglass`, `contact_limits_dt`, and `grain_shell` for its
/// `rigid_shell`, beside the impact's own. The engine's other settings are not part of a scene,
/// so stored scenes and checkpoints read and write the same bytes as ever; the retired keys
/// are still written, `cell_order` as `false` (read with either value, ignored) and
/// `absorbing_layers` as `0.0` (read only as 0).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "NumericsJson", into = "NumericsJson")]
pub struct Numerics {
    /// Engine settings: kernel (seed: quintic spline, eq. 4), Courant number, hourglass α of
    /// eq. 16, whether the contact springs may shorten the time step (off only in the stability
    /// map), and the grain as its outline particles only (`rigid_shell`: its mass and inertia
    /// come from the polygon either way). Its `spacing_m` gives way to the scene's.
    pub engine: Settings,
    /// Contact detection (seed: extrapolated distance and normal, eqs. 21–23).
    pub contact_model: ContactModel,
    /// Repulsion and friction spring stiffness (eqs. 24–25) over the CFL-matched default.
    pub contact_stiffness_scale: f64,
    /// Move the grain along its straight, force-free path to just before its first contact
    /// instead of simulating the flight step by step (docs/performance.md, "model no more").
    pub skip_flight: bool,
}

/// Courant number of the default scene: twice the seed's, with the density filter kept at the
/// seed's period in simulated time (docs/erosion.md, "The density filter and the time step").
pub const DEFAULT_CFL: f64 = 0.6;

/// Steps between density filters (eq. 12) that keep the seed's period in simulated time, 40
/// steps at CFL 0.3, at Courant number `cfl`: the step is proportional to the Courant number.
pub fn filter_interval_in_time(cfl: f64) -> u32 {
    let seed = Settings::default();
    (seed.shepard_interval as f64 * seed.cfl / cfl)
        .round()
        .clamp(1.0, u32::MAX as f64) as u32
}

impl Numerics {
    /// The seed's numerics (sections 2–3: quintic kernel, CFL 0.3, the filter every 40 steps),
    /// plus the savings that change no result beyond rounding (`rigid_shell`, `skip_flight`).
    pub fn seed() -> Self {
        Numerics {
            engine: Settings {
                // Ours, not the seed's: bitwise the same results at less cost (tests/sample.rs).
                rigid_shell: true,
                ..Settings::default()
            },
            contact_model: ContactModel::Extrapolated,
            contact_stiffness_scale: 1.0,
            skip_flight: true,
        }
    }

    /// Sets the Courant number and the density filter's interval that keeps the seed's period
    /// in simulated time (`filter_interval_in_time`).
    pub fn with_cfl_filter_in_time(mut self, cfl: f64) -> Self {
        self.engine.cfl = cfl;
        self.engine.shepard_interval = filter_interval_in_time(cfl);
        self
    }
}

impl Default for Numerics {
    /// The seed's numerics at CFL 0.6 with the filter's period kept in time: within the
    /// sampling error of the seed's at 45° and 90° with 1.7× fewer steps (docs/erosion.md).
    fn default() -> Self {
        Numerics::seed().with_cfl_filter_in_time(DEFAULT_CFL)
    }
}

/// The JSON form of `Numerics`: the keys scenes have always been written with.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct NumericsJson {
    kernel: KernelKind,
    cfl: f64,
    hourglass: f64,
    contact_model: ContactModel,
    contact_stiffness_scale: f64,
    contact_limits_dt: bool,
    grain_shell: bool,
    skip_flight: bool,
    // The engine's Z-order re-sort of the surface's particles, deleted (docs/performance.md):
    // it changed results by rounding only, so a scene stored with `true` reads as one without
    // it. Written as `false` so that stored scenes keep their bytes.
    cell_order: bool,
    // The absorbing layer along the surface's fixed bands, deleted (docs/performance.md, "An
    // absorbing layer"): written as 0 so that stored scenes keep their bytes; a scene that
    // asks for a layer is refused rather than run without it.
    absorbing_layers: f64,
    // Absent, the filter keeps the seed's period in time at this scene's `cfl`; written only
    // where it differs from that, so scenes at CFL 0.3 stored before this key existed keep
    // their bytes and their meaning.
    #[serde(skip_serializing_if = "Option::is_none")]
    shepard_interval: Option<u32>,
}

impl Default for NumericsJson {
    fn default() -> Self {
        Numerics::default().into()
    }
}

impl From<Numerics> for NumericsJson {
    fn from(n: Numerics) -> Self {
        NumericsJson {
            kernel: n.engine.kernel,
            cfl: n.engine.cfl,
            hourglass: n.engine.hourglass,
            contact_model: n.contact_model,
            contact_stiffness_scale: n.contact_stiffness_scale,
            contact_limits_dt: n.engine.contact_limits_dt,
            grain_shell: n.engine.rigid_shell,
            skip_flight: n.skip_flight,
            cell_order: false,
            absorbing_layers: 0.0,
            shepard_interval: (n.engine.shepard_interval != filter_interval_in_time(n.engine.cfl))
                .then_some(n.engine.shepard_interval),
        }
    }
}

impl TryFrom<NumericsJson> for Numerics {
    type Error = String;

    fn try_from(j: NumericsJson) -> Result<Self, String> {
        if j.absorbing_layers != 0.0 {
            return Err(format!(
                "absorbing_layers: the absorbing layer was measured and not adopted \
                 (docs/performance.md); only 0 is read, got {}",
                j.absorbing_layers
            ));
        }
        Ok(Numerics {
            engine: Settings {
                kernel: j.kernel,
                cfl: j.cfl,
                hourglass: j.hourglass,
                contact_limits_dt: j.contact_limits_dt,
                rigid_shell: j.grain_shell,
                shepard_interval: j
                    .shepard_interval
                    .unwrap_or_else(|| filter_interval_in_time(j.cfl)),
                ..Settings::default()
            },
            contact_model: j.contact_model,
            contact_stiffness_scale: j.contact_stiffness_scale,
            skip_flight: j.skip_flight,
        })
    }
}

impl Default for ImpactParams {
    fn default() -> Self {
        ImpactParams {
            angle_deg: 90.0,
            shape: Shape::Hexagon,
            velocity_m_s: 100.0,
            grain_diameter_m: 250e-6,
            grain_density_kg_m3: 2500.0,
            spacing_m: 8e-6,
            distribution_range_dg: 1.0,
            material: Material::aisi304(),
            friction: 0.5,
            surface_width_dg: 4.0,
            surface_depth_dg: 1.5,
            settle_fraction: 0.02,
            numerics: Numerics::default(),
        }
    }
}

/// Layers of fixed particles at the bottom and the sides of the surface: at least the kernel
/// support (3h = 3.9 Δx), so free particles never see a truncated kernel there.
const FIXED_LAYERS: f64 = 4.0;

/// Fastest grain the impact scene takes (m/s): erosion speeds, with room above the seed's 100.
pub const MAX_VELOCITY_M_S: f64 = 1000.0;
/// Densest grain the impact scene takes (kg/m³): above osmium, the densest element.
pub const MAX_DENSITY_KG_M3: f64 = 25_000.0;
/// Finest resolution the impact scene takes, in particles per grain diameter.
pub const MAX_PPD: f64 = 512.0;
/// Widest or deepest surface the impact scene takes, in grain diameters.
pub const MAX_SURFACE_DG: f64 = 100.0;
/// Most particles a surface may hold: a guard against a typo in the spacing or the surface
/// size that would exhaust a worker's memory (the seed's scene has about 6 000).
pub const MAX_SURFACE_PARTICLES: f64 = 5e5;

/// A scene (`ImpactParams`, `JetParams`: `kind`) read from a JSON object, fields left out at
/// their defaults, the error naming the field at fault. Not validated: flags may still
/// override fields. Serde would read a JSON array as the struct's fields in order, so only an
/// object is a scene.
pub fn scene_from_json<T: serde::de::DeserializeOwned>(
    text: &str,
    kind: &str,
) -> Result<T, InputError> {
    if !text.trim_start().starts_with('{') {
        return Err(InputError::new(
            "(scene)",
            format!("must be a JSON object of {kind} fields"),
        ));
    }
    let de = &mut serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(de)
        .map_err(|e| InputError::new(e.path().to_string(), e.inner().to_string()))
}

/// The bound every scene keeps on its grains' density ([`MAX_DENSITY_KG_M3`]).
pub(crate) fn check_grain_density(rho: f64) -> Result<(), InputError> {
    InputError::require_at_most(
        "grain_density_kg_m3",
        rho,
        MAX_DENSITY_KG_M3,
        "kg/m³",
        "denser than any solid",
    )
}

/// Fewest particle layers a surface may have: fixed layers below, free layers between, and as
/// many again for the impact to work in.
pub const MIN_SURFACE_LAYERS: f64 = 3.0 * FIXED_LAYERS;
/// Height of the grain's lowest point above the surface line y = 0 at the start, in Δx. Lips
/// of earlier craters can stand above that line, so it cannot be much less; `skip_flight`
/// then takes the grain up to its first contact.
const START_GAP_DX: f64 = 1.5;
/// Step of the flight search (`flight_to_contact`), in Δx.
const FLIGHT_PROBE_DX: f64 = 0.05;
/// Flight left before the first contact the search finds, in Δx: the contact then starts from
/// zero penetration within the simulation, never at the first step.
const FLIGHT_MARGIN_DX: f64 = 0.2;
/// Steps without any contact force before the grain counts as gone.
const SEPARATED_STEPS: u32 = 50;
/// Give up on an impact after this many grain transit times Dg/V (the criterion never met).
const MAX_TRANSITS: f64 = 12.0;

impl ImpactParams {
    /// The seed's scene at angle `angle_deg` for `shape` (section 4 defaults).
    pub fn paper(angle_deg: f64, shape: Shape) -> Self {
        ImpactParams {
            angle_deg,
            shape,
            ..Default::default()
        }
    }

    /// Checks every field; the error names the field and the rule.
    pub fn validate(&self) -> Result<(), InputError> {
        let positive = |f: &str, v: f64| InputError::require_positive(f, v);
        if !(self.angle_deg > 0.0 && self.angle_deg <= 90.0) {
            return Err(InputError::new(
                "angle_deg",
                format!("must be in (0, 90], got {}", self.angle_deg),
            ));
        }
        positive("velocity_m_s", self.velocity_m_s)?;
        positive("grain_diameter_m", self.grain_diameter_m)?;
        positive("grain_density_kg_m3", self.grain_density_kg_m3)?;
        positive("spacing_m", self.spacing_m)?;
        positive("surface_width_dg", self.surface_width_dg)?;
        positive("surface_depth_dg", self.surface_depth_dg)?;
        positive("settle_fraction", self.settle_fraction)?;
        if self.settle_fraction >= 1.0 {
            return Err(InputError::new(
                "settle_fraction",
                format!(
                    "is a fraction of the grain's kinetic energy and must be below 1, got {}",
                    InputError::shown(self.settle_fraction)
                ),
            ));
        }
        InputError::require_at_most(
            "velocity_m_s",
            self.velocity_m_s,
            MAX_VELOCITY_M_S,
            "m/s",
            "solid particle erosion; the seed's grains fly at 100 m/s",
        )?;
        check_grain_density(self.grain_density_kg_m3)?;
        if self.grain_diameter_m / self.spacing_m < 6.0 {
            return Err(InputError::new(
                "spacing_m",
                format!(
                    "must give at least 6 particles per grain diameter, got {:.2}",
                    self.grain_diameter_m / self.spacing_m
                ),
            ));
        }
        if !(self.distribution_range_dg.is_finite() && self.distribution_range_dg >= 0.0) {
            return Err(InputError::new(
                "distribution_range_dg",
                format!("must be >= 0, got {}", self.distribution_range_dg),
            ));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(InputError::new(
                "friction",
                format!("must be >= 0, got {}", self.friction),
            ));
        }
        if self.surface_width_dg < self.distribution_range_dg + 2.0 {
            return Err(InputError::new(
                "surface_width_dg",
                format!(
                    "must be at least distribution_range_dg + 2 = {} so every grain lands on the surface",
                    self.distribution_range_dg + 2.0
                ),
            ));
        }
        let layers = self.surface_depth_dg * self.grain_diameter_m / self.spacing_m;
        if layers < MIN_SURFACE_LAYERS {
            return Err(InputError::new(
                "surface_depth_dg",
                format!(
                    "gives {layers:.1} particle layers; at least {MIN_SURFACE_LAYERS} are needed"
                ),
            ));
        }
        // Each size is bounded alone first, so the error names the field that is out of line.
        let ppd = self.grain_diameter_m / self.spacing_m;
        InputError::require_at_most(
            "spacing_m",
            ppd,
            MAX_PPD,
            "particles per grain diameter (grain_diameter_m / spacing_m)",
            "the seed's finest is 32",
        )?;
        for (field, v) in [
            ("surface_width_dg", self.surface_width_dg),
            ("surface_depth_dg", self.surface_depth_dg),
        ] {
            InputError::require_at_most(
                field,
                v,
                MAX_SURFACE_DG,
                "grain diameters",
                "the seed's surface is 4 × 1.5",
            )?;
        }
        let particles = self.surface_width_dg * self.surface_depth_dg * ppd * ppd;
        if particles > MAX_SURFACE_PARTICLES {
            return Err(InputError::new(
                "spacing_m",
                format!(
                    "gives a surface of {particles:.3e} particles (surface_width_dg × surface_depth_dg × (grain_diameter_m / spacing_m)²), more than the limit of {MAX_SURFACE_PARTICLES:.0e}; the seed's scene has about 6 000"
                ),
            ));
        }
        self.material
            .validate()
            .map_err(|e| InputError::new(format!("material.{}", e.field), e.rule))?;
        let k = self.numerics.contact_stiffness_scale;
        // The stability map spans 0.25 to 256 by default; beyond 1000 is a typo.
        if !(k.is_finite() && k > 0.0 && k <= 1e3) {
            return Err(InputError::new(
                "numerics.contact_stiffness_scale",
                format!("must lie in (0, 1000], got {}", InputError::shown(k)),
            ));
        }
        self.settings()
            .validate()
            .map_err(|e| InputError::new(format!("numerics.{}", e.field), e.rule))?;
        self.shape
            .validate("shape")
            .map_err(|e| InputError::new("shape", e.to_string()))?;
        Ok(())
    }

    /// Grain mass per unit depth (kg/m): density × π Dg²/4, the mass each impact adds to the
    /// abscissa of the erosion curve.
    pub fn grain_mass_kg_m(&self) -> f64 {
        self.grain_density_kg_m3 * std::f64::consts::PI * self.grain_diameter_m.powi(2) / 4.0
    }

    /// Surface mass per unit depth (kg/m): density × width × depth, the most any sample can
    /// lose (seed section 4's surface).
    pub fn surface_mass_kg_m(&self) -> f64 {
        let dg = self.grain_diameter_m;
        self.material.density_kg_m3 * self.surface_width_dg * dg * self.surface_depth_dg * dg
    }

    /// Engine settings for this scene (seed sections 2–3 defaults at this spacing).
    pub fn settings(&self) -> Settings {
        Settings {
            spacing_m: self.spacing_m,
            ..self.numerics.engine.clone()
        }
    }

    /// Half-width and depth of the surface rectangle (m): whole numbers of spacings, so the
    /// lattice fills it exactly.
    fn surface_extent(&self) -> (f64, f64) {
        let dx = self.spacing_m;
        let nx = (self.surface_width_dg * self.grain_diameter_m / dx).round();
        let ny = (self.surface_depth_dg * self.grain_diameter_m / dx).round();
        (0.5 * nx * dx, ny * dx)
    }

    /// The fresh surface: a lattice rectangle, top at y = 0, centred on x = 0, its bottom and
    /// side layers fixed (kinematic) so it needs no other support.
    pub fn fresh_surface(&self) -> Result<Particles, InputError> {
        self.validate()?;
        let dx = self.spacing_m;
        let (hw, depth) = self.surface_extent();
        let rect = Polygon::rectangle(-hw, -depth, hw, 0.0);
        let mut world = World::new(self.settings())?;
        let b = world.add_deformable_polygon(
            "surface",
            self.material.clone(),
            &rect,
            Vector::new(-hw, 0.0),
            Vector::zeros(),
        )?;
        let band = FIXED_LAYERS * dx;
        world.set_kinematic(b, Motion::Fixed, |x| {
            x.y < -depth + band || x.x < -hw + band || x.x > hw - band
        })?;
        Ok(world.body_state(b))
    }

    /// Where and how the grain starts, from two uniform numbers in [0, 1): the orientation and
    /// the aim point (seed section 4: aim points uniform over the distribution range about
    /// the middle, the path shifted so oblique grains hit around the middle too).
    pub fn grain_start(&self, u_angle: f64, u_aim: f64) -> Result<GrainStart, InputError> {
        let verts = self
            .shape
            .vertices(self.grain_diameter_m)
            .map_err(|e| InputError::new("shape", e.to_string()))?;
        let theta = std::f64::consts::TAU * u_angle;
        let rotated: Vec<Vector> = verts
            .iter()
            .map(|v| grit_sph::math::rotate(Vector::new(v[0], v[1]), theta))
            .collect();
        let lowest = rotated.iter().map(|v| v.y).fold(f64::INFINITY, f64::min);
        let aim_x = (u_aim - 0.5) * self.distribution_range_dg * self.grain_diameter_m;
        let a = self.angle_deg.to_radians();
        let (sin_a, cos_a) = grit_sph::math::sin_cos(a);
        let dir = Vector::new(cos_a, -sin_a);
        // Seed section 4: oblique grains are "shifted accordingly so that they hit the surface
        // around the midpoint". So the centroid is above the aim point when the lowest point
        // reaches y = 0. (Aiming the centroid path at y = 0 instead puts the touchdown
        // |lowest| / tan α upstream: 1.9 Dg at 15°, off a 2.5 Dg surface.) From there the
        // grain is backed up along its path until its lowest point is START_GAP_DX above the
        // surface. At 90° the shift is zero; it is skipped there so normal-incidence results
        // keep their bits.
        let shift = if self.angle_deg == 90.0 {
            0.0
        } else {
            -lowest / grit_sph::math::tan(a)
        };
        let back = (START_GAP_DX * self.spacing_m - lowest) / sin_a;
        let centre = Vector::new(aim_x + shift, 0.0) - dir * back;
        let vertices: Vec<[f64; 2]> = rotated
            .iter()
            .map(|v| [v.x + centre.x, v.y + centre.y])
            .collect();
        Ok(GrainStart {
            polygon: Polygon::new(&vertices, "shape")?,
            velocity_m_s: dir * self.velocity_m_s,
            orientation_rad: theta,
            aim_x_m: aim_x,
        })
    }
}

/// The grain of one impact as placed at the start.
#[derive(Debug, Clone)]
pub struct GrainStart {
    /// Outline in place, metres.
    pub polygon: Polygon,
    /// Initial velocity (m/s).
    pub velocity_m_s: Vector,
    /// Random orientation drawn for it (rad).
    pub orientation_rad: f64,
    /// Where its centroid path crosses the surface line (m).
    pub aim_x_m: f64,
}

/// What one impact did, beside the surface state it leaves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImpactOutcome {
    /// Surface mass removed (kg/m): failed particles (D ≥ 1, eq. 19) plus fragments torn off
    /// the surface (`detached_kg`).
    pub mass_loss_kg: f64,
    /// Failed particles removed.
    pub removed_particles: u32,
    /// Mass of fragments no longer connected to the surface when the impact ends (kg/m): chips
    /// whose particles did not reach D = 1 but left all the same.
    pub detached_kg: f64,
    /// Particles in those fragments.
    pub detached_particles: u32,
    /// Simulated time of the impact (s), the skipped flight included.
    pub sim_time_s: f64,
    /// Steps computed (a skipped flight's steps are not).
    pub steps: u64,
    /// Grain speed after the impact over before.
    pub rebound_ratio: f64,
    /// True when the end criterion was met; false when the time limit ended the impact.
    pub settled: bool,
}

/// Why an impact stopped without a result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// The scene was not valid.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The simulation went unstable (the engine's failure checks, docs/design.md).
    #[error(transparent)]
    Sim(#[from] SimError),
    /// Cancelled from outside; the surface state is untouched.
    #[error("impact cancelled")]
    Cancelled,
}

/// One finished impact: the surface it leaves, what it did, and where the time went.
#[derive(Debug, Clone)]
pub struct ImpactRun {
    /// Surface particles afterwards (the next impact's start).
    pub surface: Particles,
    /// Mass loss and engine figures.
    pub outcome: ImpactOutcome,
    /// Per-stage wall time (not part of any result: it differs between runs).
    pub timers: Timers,
    /// Particles in the scene at the start (surface and grain).
    pub particles: usize,
}

/// Runs one impact of `grain` on `surface` (seed section 4): temperature reset, surface at
/// rest, grain free; ends when the grain has left and the surface has settled. `cancel` is
/// polled every step.
pub fn run_impact(
    params: &ImpactParams,
    surface: &Particles,
    grain: &GrainStart,
    cancel: &dyn Fn() -> bool,
) -> Result<ImpactRun, ImpactError> {
    run_impact_observed(params, surface, grain, cancel, None)
}

/// Simulated time after which an impact is given up as never meeting its end criterion (s).
pub fn max_impact_time(params: &ImpactParams) -> f64 {
    MAX_TRANSITS * params.grain_diameter_m / params.velocity_m_s
}

/// The grain's body number in an impact's world (the surface is body 0).
pub const GRAIN_BODY: usize = 1;

/// The surface's body number in an impact's world.
pub const SURFACE_BODY: usize = 0;

/// The world of one impact before its first step (seed section 4): the surface at rest and at
/// room temperature, the grain free, and the seed's contact between them (eqs. 21–29).
pub fn impact_world(
    params: &ImpactParams,
    surface: &Particles,
    grain: &GrainStart,
) -> Result<World, InputError> {
    let mut world = World::new(params.settings())?;
    let mut state = surface.clone();
    // Grains arrive milliseconds apart in a blasting test: the surface is at rest and at room
    // temperature again by then (seed section 4), while stress, strain and damage remain.
    state.vel.iter_mut().for_each(|v| *v = Vector::zeros());
    let s = world.add_deformable_state("surface", params.material.clone(), state, Motion::Fixed)?;
    world.reset_temperature();
    let g = world.add_rigid(
        "grain",
        &grain.polygon,
        params.grain_density_kg_m3,
        grain.velocity_m_s,
        0.0,
        Motion::Free,
    )?;
    debug_assert_eq!(
        (s, g),
        (SURFACE_BODY, GRAIN_BODY),
        "the body numbers are documented"
    );
    world.add_contact(
        g,
        s,
        ContactParams {
            model: params.numerics.contact_model,
            friction: params.friction,
            normal_stiffness_pa: Some(
                params.numerics.contact_stiffness_scale
                    * cfl_matched_stiffness(&params.material, world.settings().h_over_dx),
            ),
            ..Default::default()
        },
    )?;
    Ok(world)
}

/// The reference impact (seed section 4: hexagon, 45°, 100 m/s, AISI 304) at `spacing_m` on a
/// fresh surface, stepped until the grain has pressed on it for `contact_steps` steps: the state
/// the stage benchmarks time (docs/performance.md).
pub fn mid_contact_world(spacing_m: f64, contact_steps: u32) -> Result<World, ImpactError> {
    let params = ImpactParams {
        spacing_m,
        ..ImpactParams::paper(45.0, Shape::Hexagon)
    };
    let surface = params.fresh_surface()?;
    let grain = params.grain_start(0.3, 0.5)?;
    let mut w = impact_world(&params, &surface, &grain)?;
    let mut touching = 0;
    while touching < contact_steps {
        w.step()?;
        if w.contact_forces().iter().any(|f| f.norm() > 0.0) {
            touching += 1;
        }
    }
    Ok(w)
}

/// A read-only look at the world after every step of an impact (surface body 0, grain body 1).
pub type StepObserver<'a> = &'a mut dyn FnMut(&World);

/// `run_impact`, calling `observe` after every step. The observer sees the world read-only, so
/// the impact's results are bit for bit those of `run_impact`.
pub fn run_impact_observed(
    params: &ImpactParams,
    surface: &Particles,
    grain: &GrainStart,
    cancel: &dyn Fn() -> bool,
    mut observe: Option<StepObserver>,
) -> Result<ImpactRun, ImpactError> {
    let mut world = impact_world(params, surface, grain)?;
    let mut skipped_steps = 0;
    if params.numerics.skip_flight {
        // Whole steps of the flight, each of the step the world would take (the surface is at
        // rest and the grain is rigid, so the step does not change in flight): the density
        // filter's passes then fall where they would without the skip.
        let dt = world.next_dt();
        let speed = grain.velocity_m_s.norm();
        let s = flight_to_contact(params, surface, grain);
        skipped_steps = (s / (speed * dt)).floor() as u64;
        if skipped_steps > 0 {
            let moved = GrainStart {
                polygon: grain
                    .polygon
                    .translated(grain.velocity_m_s * (skipped_steps as f64 * dt)),
                ..grain.clone()
            };
            world = impact_world(params, surface, &moved)?;
            world.count_skipped_steps(skipped_steps, dt);
        }
    }
    let (s, g) = (SURFACE_BODY, GRAIN_BODY);
    let e0 = world.energy().kinetic;
    let particles = world.particles().len();
    let dg = params.grain_diameter_m;
    let half_width = 0.5 * params.surface_width_dg * dg;
    let t_max = max_impact_time(params);
    let mut quiet = 0u32;
    let (mut detached_kg, mut detached_particles) = (0.0, 0u32);
    let mut settled = false;
    while world.time() < t_max {
        if cancel() {
            return Err(ImpactError::Cancelled);
        }
        world.step()?;
        if let Some(f) = observe.as_mut() {
            f(&world);
        }
        let touching = world
            .contact_forces()
            .iter()
            .any(|f| f.x != 0.0 || f.y != 0.0);
        quiet = if touching { 0 } else { quiet + 1 };
        let r = world.bodies()[g].rigid().expect("grain is rigid");
        // Past a side edge counts only while moving outward: a grazing grain can start
        // beyond the edge and fly in.
        let beyond = r.com_m.x.abs() > half_width + dg && r.com_m.x * r.velocity_m_s.x > 0.0;
        let away = r.velocity_m_s.y > 0.0 || beyond;
        if quiet >= SEPARATED_STEPS && away && quiet.is_multiple_of(10) {
            // Flying fragments would hold the surface's kinetic energy up forever.
            let keep = attached(&world, s, DETACH_LINK_DX * params.spacing_m);
            if keep.iter().any(|k| !k) {
                let p = world.particles();
                for (i, _) in keep.iter().enumerate().filter(|(_, k)| !**k) {
                    detached_kg += p.mass[i];
                    detached_particles += 1;
                }
                world.remove_particles(&keep)?;
            }
            let e = world.energy();
            let surface_ke = e.kinetic - grain_kinetic(&world, g);
            if surface_ke < params.settle_fraction * e0 {
                settled = true;
                break;
            }
        }
    }
    let r = world.bodies()[g].rigid().expect("grain is rigid");
    let outcome = ImpactOutcome {
        mass_loss_kg: world.bodies()[s].removed_mass_kg_m + detached_kg,
        removed_particles: world.bodies()[s].removed_particles as u32,
        detached_kg,
        detached_particles,
        sim_time_s: world.time(),
        steps: world.steps() - skipped_steps,
        rebound_ratio: r.velocity_m_s.norm() / params.velocity_m_s,
        settled,
    };
    Ok(ImpactRun {
        surface: world.body_state(s),
        outcome,
        timers: world.timers().clone(),
        particles,
    })
}

/// How far the grain can fly along its path before the contact of eqs. 21–24 (or the
/// penetration model) would first push on any surface particle (m), less a margin of
/// `FLIGHT_MARGIN_DX`; 0 when it starts within that margin. Searched in steps of
/// `FLIGHT_PROBE_DX` with the engine's own detection, over the grain's outline particles as the
/// world places them.
pub fn flight_to_contact(params: &ImpactParams, surface: &Particles, grain: &GrainStart) -> f64 {
    let dx = params.spacing_m;
    let settings = params.settings();
    let kernel = grit_sph::Kernel::new(settings.kernel, settings.h_over_dx * dx);
    let reach = kernel.radius();
    let (pts, boundary) = grain.polygon.fill_layered(dx);
    let outline: Vec<Vector> = pts
        .iter()
        .zip(boundary)
        .filter_map(|(x, b)| b.then_some(*x))
        .collect();
    let speed = grain.velocity_m_s.norm();
    if outline.is_empty() || surface.is_empty() || speed == 0.0 {
        return 0.0;
    }
    let dir = grain.velocity_m_s / speed;
    // Only surface particles that the outline can come within reach of along the path.
    let lowest = outline.iter().map(|x| x.y).fold(f64::INFINITY, f64::min);
    let top = surface
        .pos
        .iter()
        .map(|x| x.y)
        .fold(f64::NEG_INFINITY, f64::max);
    // The lowest outline particle sinks |dir.y| per metre of path. The search stops at `limit`,
    // where it is the reach below the highest surface particle: over a flat surface contact has
    // begun by then; over a crater it may not have, and the grain is left there, every probe
    // before it having been clear.
    let limit = if dir.y < 0.0 {
        (lowest - top + reach) / -dir.y
    } else {
        0.0
    };
    let touches = |s: f64| {
        let shift = dir * s;
        let moved: Vec<Vector> = outline.iter().map(|x| x + shift).collect();
        let (mut lo, mut hi) = (moved[0], moved[0]);
        for x in &moved {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        let near = |x: &Vector| {
            x.x > lo.x - reach && x.x < hi.x + reach && x.y > lo.y - reach && x.y < hi.y + reach
        };
        surface.pos.iter().filter(|x| near(x)).any(|&xi| {
            let js = (0..moved.len()).filter(|&j| (xi - moved[j]).norm() < reach);
            grit_sph::contact::detect(
                params.numerics.contact_model,
                &kernel,
                dx,
                1.0,
                xi,
                js,
                &moved,
                |_| 1.0,
            )
            .is_some_and(|d| d.penetration > 0.0)
        })
    };
    let step = FLIGHT_PROBE_DX * dx;
    let mut s = 0.0;
    while s <= limit.max(0.0) && !touches(s) {
        s += step;
    }
    (s - FLIGHT_MARGIN_DX * dx).max(0.0)
}

/// The grain at the step of an impact when its total contact force was largest: the moment a
/// picture of the eroded surface draws it at (seed Fig. 13 shows surface and grain together).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PeakContact {
    /// Grain outline at that step, counter-clockwise (m).
    pub outline_m: Vec<Vector>,
    /// Magnitude of the grain's total contact force then (N/m, eq. 17).
    pub force_n_m: f64,
    /// Simulated time of that step since the impact started (s).
    pub time_s: f64,
    /// Lowest point of the outline below the original surface line y = 0 (m; negative when
    /// the grain stayed above it).
    pub depth_m: f64,
}

/// Follows an impact step by step (an observer for `run_impact_observed`) and keeps the grain's
/// pose at the step of largest contact force: one force read and a comparison per step; the
/// outline is built only when a larger force is seen.
#[derive(Debug, Clone)]
pub struct PeakTracker {
    /// Outline vertices relative to the grain's starting centre of mass (m).
    offsets: Vec<Vector>,
    best_force_sq: f64,
    peak: Option<PeakContact>,
}

impl PeakTracker {
    /// A tracker for the impact that fires `grain`.
    pub fn new(grain: &GrainStart) -> Self {
        let c = grain.polygon.centroid();
        PeakTracker {
            offsets: grain.polygon.vertices().iter().map(|v| v - c).collect(),
            best_force_sq: 0.0,
            peak: None,
        }
    }

    /// Looks at the world after one step.
    pub fn observe(&mut self, world: &World) {
        let Some(r) = world.bodies().get(GRAIN_BODY).and_then(|b| b.rigid()) else {
            return;
        };
        let f2 = r.contact_force_n_m.norm_squared();
        if f2 > self.best_force_sq {
            self.best_force_sq = f2;
            // A rigid body's centre of mass starts at its polygon's centroid with angle 0
            // (World::add_rigid), so the outline follows from its pose alone.
            let outline_m: Vec<Vector> = self
                .offsets
                .iter()
                .map(|&o| r.com_m + grit_sph::math::rotate(o, r.angle_rad))
                .collect();
            let depth_m = -outline_m.iter().map(|v| v.y).fold(f64::INFINITY, f64::min);
            self.peak = Some(PeakContact {
                outline_m,
                force_n_m: f2.sqrt(),
                time_s: world.time(),
                depth_m,
            });
        }
    }

    /// The grain at the largest contact force seen; `None` if it never touched.
    pub fn peak(&self) -> Option<&PeakContact> {
        self.peak.as_ref()
    }

    /// The grain at the largest contact force seen, taken out.
    pub fn into_peak(self) -> Option<PeakContact> {
        self.peak
    }
}

/// Particles of the surface closer than this (in Δx) are connected; a lattice neighbour sits
/// at 1 Δx, a diagonal one at 1.41 Δx.
const DETACH_LINK_DX: f64 = 1.5;

/// Keep-mask over all particles: false for surface particles in a fragment that no chain of
/// neighbours closer than `link` joins to a fixed (kinematic) particle of body `s`.
fn attached(world: &World, s: usize, link: f64) -> Vec<bool> {
    let p = world.particles();
    let n = p.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let ours: Vec<bool> = (0..n).map(|i| p.body[i] as usize == s).collect();
    // The engine's cell grid, its radius a hair over `link` so that the strict test below,
    // not rounding in a squared distance, decides every pair.
    let near = neighbours::build(&p.pos, &ours, &ours, link * (1.0 + 1e-9), |i, j| {
        (p.pos[i] - p.pos[j]).norm() < link
    });
    for i in 0..n {
        for &j in near.of(i) {
            let (a, b) = (root(&mut parent, i), root(&mut parent, j as usize));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut anchored = vec![false; n];
    for i in (0..n).filter(|&i| p.body[i] as usize == s && p.flags[i] & KINEMATIC != 0) {
        let r = root(&mut parent, i);
        anchored[r] = true;
    }
    (0..n)
        .map(|i| p.body[i] as usize != s || anchored[root(&mut parent, i)])
        .collect()
}

fn grain_kinetic(world: &World, g: usize) -> f64 {
    let r = world.bodies()[g].rigid().expect("grain is rigid");
    0.5 * r.mass_kg_m * r.velocity_m_s.norm_squared() + 0.5 * r.inertia_kg_m * r.omega_rad_s.powi(2)
}

/// Number of particles of a surface state that are free (not fixed boundary).
pub fn free_particles(surface: &Particles) -> usize {
    surface
        .flags
        .iter()
        .filter(|&&f| f & KINEMATIC == 0)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numerics_keep_their_json_keys() {
        // Scenes are stored (farm cells, checkpoints) and compared as this JSON.
        let n = Numerics::default();
        let json = serde_json::to_string(&n).unwrap();
        assert_eq!(
            json,
            r#"{"kernel":"quintic","cfl":0.6,"hourglass":0.1,"contact_model":"extrapolated","contact_stiffness_scale":1.0,"contact_limits_dt":true,"grain_shell":true,"skip_flight":true,"cell_order":false,"absorbing_layers":0.0}"#
        );
        assert_eq!(serde_json::from_str::<Numerics>(&json).unwrap(), n);
        let n: Numerics = serde_json::from_str(r#"{"cfl": 0.2, "grain_shell": false}"#).unwrap();
        assert_eq!((n.engine.cfl, n.engine.rigid_shell), (0.2, false));
        assert!(serde_json::from_str::<Numerics>(r#"{"h_over_dx": 1.5}"#).is_err());
    }

    #[test]
    fn scenes_stored_with_the_retired_cell_order_key_still_read() {
        // The engine no longer re-sorts particles; either stored value reads as today's scene.
        for v in ["false", "true"] {
            let n: Numerics = serde_json::from_str(&format!(r#"{{"cell_order": {v}}}"#)).unwrap();
            assert_eq!(n, Numerics::default());
        }
        let n: Numerics = serde_json::from_str(r#"{"cfl": 0.3, "cell_order": true}"#).unwrap();
        assert!(serde_json::to_string(&n)
            .unwrap()
            .contains(r#""cell_order":false"#));
    }

    #[test]
    fn a_scene_asking_for_the_retired_absorbing_layer_is_refused() {
        let n: Numerics = serde_json::from_str(r#"{"absorbing_layers": 0.0}"#).unwrap();
        assert_eq!(n, Numerics::default());
        let e = serde_json::from_str::<Numerics>(r#"{"absorbing_layers": 4.0}"#).unwrap_err();
        assert!(e.to_string().contains("absorbing_layers"), "{e}");
        assert!(e.to_string().contains("not adopted"), "{e}");
    }

    #[test]
    fn the_density_filter_interval_is_written_only_where_it_is_not_the_seeds_period_in_time() {
        assert_eq!(Numerics::seed().engine.shepard_interval, 40);
        assert_eq!(Numerics::seed().engine.cfl, 0.3);
        let n = Numerics::default();
        assert_eq!((n.engine.cfl, n.engine.shepard_interval), (DEFAULT_CFL, 20));
        assert_eq!(filter_interval_in_time(0.45), 27);
        assert_eq!(filter_interval_in_time(100.0), 1);
        // A scene that only sets `cfl` keeps the seed's period in time; one stored at CFL 0.3
        // without the key reads as the seed's 40 steps.
        let at = |json: &str| {
            let n: Numerics = serde_json::from_str(json).unwrap();
            (n.engine.cfl, n.engine.shepard_interval)
        };
        assert_eq!(at(r#"{"cfl": 0.3}"#), (0.3, 40));
        assert_eq!(at(r#"{"cfl": 0.45}"#), (0.45, 27));
        assert_eq!(at(r#"{}"#), (0.6, 20));
        assert_eq!(at(r#"{"cfl": 0.6, "shepard_interval": 40}"#), (0.6, 40));
        assert_eq!(at(r#"{"shepard_interval": 80}"#), (0.6, 80));
        let mut n = Numerics::default();
        n.engine.shepard_interval = 0;
        let json = serde_json::to_string(&n).unwrap();
        assert!(
            json.ends_with(r#""absorbing_layers":0.0,"shepard_interval":0}"#),
            "{json}"
        );
        assert_eq!(serde_json::from_str::<Numerics>(&json).unwrap(), n);
        let seed = serde_json::to_string(&Numerics::seed()).unwrap();
        assert!(!seed.contains("shepard_interval"), "{seed}");
        assert!(serde_json::from_str::<Numerics>(r#"{"shepard_interval": -1}"#).is_err());
    }
}
