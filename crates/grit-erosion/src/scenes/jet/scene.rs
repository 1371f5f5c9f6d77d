//! The jet scene's world (docs/jet.md#the-scene): a rectangular target whose top is y = 0 and
//! whose sides and bottom are held fixed, a nozzle `standoff_m` above it pointing straight
//! down, and a box around both outside which water and grains are deleted.

use grit_sph::coupling::CouplingParams;
use grit_sph::dem::Dem;
use grit_sph::{Abrasives, Fluid, InputError, Motion, Nozzle, Settings, Vector, World};

use super::JetParams;

/// Layers of target particles held fixed along its sides and bottom: the cubic spline reaches
/// 2.5 Δx, so three layers give every free particle a full support. The paper fixes the sides
/// and leaves the bottom free; the target here is a window into a thick plate, and a free
/// bottom let a 2 mm slab bend under the jet by more than its crater was deep
/// (docs/jet.md#the-scene).
pub const FIXED_SIDE_LAYERS: u32 = 3;

/// Margin of the outflow box beyond the target and the nozzle, in spacings: water, grains and
/// target fragments leave once they are past the target's sides.
const OUTFLOW_MARGIN_DX: f64 = 4.0;

/// Gravity of the scene (m/s²): the paper's eq. 1 and 23 keep it, though at jet speeds it does
/// nothing measurable.
const GRAVITY_M_S2: f64 = 9.81;

/// Where the parts of a jet scene are; a pure function of the parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Index of the target body.
    pub target_body: usize,
    /// Index of the water body.
    pub fluid_body: usize,
    /// The original top of the target (the centres of its top row, m): the crater's zero line.
    pub surface_y_m: f64,
    /// Height of the nozzle's exit line (m).
    pub nozzle_y_m: f64,
    /// Lower-left corner of the outflow box (m).
    pub box_min_m: Vector,
    /// Upper-right corner of the outflow box (m).
    pub box_max_m: Vector,
}

impl Layout {
    /// The layout of `params`.
    pub fn of(params: &JetParams) -> Layout {
        let dx = params.spacing_m;
        let margin = OUTFLOW_MARGIN_DX * dx;
        let half_w = 0.5 * params.target_width_m;
        Layout {
            target_body: 0,
            fluid_body: 1,
            surface_y_m: -0.5 * dx,
            nozzle_y_m: params.standoff_m,
            box_min_m: Vector::new(-half_w - margin, -params.target_depth_m - margin),
            box_max_m: Vector::new(half_w + margin, params.standoff_m + margin),
        }
    }
}

/// δ of the water's density diffusion (`Fluid::density_diffusion`). Without it, the paper's
/// continuity alone, the water where jet, grains and crater walls meet broke into neighbours of
/// 3 and 2500 kg/m³ side by side within 36 µs until a density went negative; with δ = 0.1, the
/// usual value of DualSPHysics, the same run holds every density above 750 kg/m³
/// (docs/jet.md#the-scene).
pub const WATER_DENSITY_DIFFUSION: f64 = 0.1;

/// Densities, over water's, outside which a free water particle is deleted
/// (`Fluid::density_range`, DualSPHysics's `RhopOut` bounds 700 and 1300 kg/m³ widened to the
/// water hammer's 1.3 ρ0 and beyond). At 0.36 ms into the copper jet at 500 m/s, spray thrown
/// back from the crater towards the nozzle had thinned to ρ̄ = 2–10 kg/m³; volumes m/ρ̄ a
/// hundred times the water's swamped the continuity sums of the rows leaving the nozzle, and a
/// density went negative (docs/jet.md#the-scene).
pub const WATER_DENSITY_RANGE: [f64; 2] = [0.5, 2.0];

/// The jet's water: the preset with [`WATER_DENSITY_DIFFUSION`] and [`WATER_DENSITY_RANGE`].
fn jet_water() -> Fluid {
    Fluid {
        density_diffusion: WATER_DENSITY_DIFFUSION,
        density_range: Some(WATER_DENSITY_RANGE),
        ..Fluid::water()
    }
}

/// The target's lattice: columns and rows of spacing Δx filling its rectangle.
fn target_points(params: &JetParams) -> Vec<Vector> {
    let dx = params.spacing_m;
    let nx = (params.target_width_m / dx).round() as i64;
    let ny = (params.target_depth_m / dx).round() as i64;
    let x0 = -0.5 * nx as f64 * dx;
    let mut pts = Vec::with_capacity((nx * ny) as usize);
    for j in 0..ny {
        for i in 0..nx {
            pts.push(Vector::new(
                x0 + (i as f64 + 0.5) * dx,
                -(j as f64 + 0.5) * dx,
            ));
        }
    }
    pts
}

/// The world of `params` at t = 0: the target, the (empty) water body with its nozzle and
/// outflow, and, for an abrasive jet, the grains' coupling; the water paper's numerics
/// (`Settings::water_jet`).
pub fn build(params: &JetParams) -> Result<(World, Layout), InputError> {
    let layout = Layout::of(params);
    let dx = params.spacing_m;
    let g = Vector::new(0.0, -GRAVITY_M_S2);
    let mut world = World::new(Settings::water_jet(dx, g))?;
    let pts = target_points(params);
    let vols = vec![dx * dx; pts.len()];
    let material = params.material.0.clone();
    let target = world.add_deformable("target", material, &pts, &vols, Vector::zeros())?;
    let fixed = FIXED_SIDE_LAYERS as f64 * dx;
    let (inner, floor) = (
        0.5 * params.target_width_m - fixed,
        -params.target_depth_m + fixed,
    );
    let bottom = params.fixed_bottom;
    world.set_kinematic(target, Motion::Fixed, |x| {
        x.x.abs() > inner || (bottom && x.y < floor)
    })?;
    let water = world.add_fluid("water", jet_water(), &[], &[], &[], Vector::zeros())?;
    debug_assert_eq!((target, water), (layout.target_body, layout.fluid_body));
    world.add_outflow(water, layout.box_min_m, layout.box_max_m)?;
    // Fragments of the target that fly out of the scene are deleted and booked as loss.
    world.add_outflow(target, layout.box_min_m, layout.box_max_m)?;
    world.add_inflow(
        water,
        Nozzle {
            centre_m: Vector::new(0.0, layout.nozzle_y_m),
            direction: Vector::new(0.0, -1.0),
            width_m: params.jet_width_m,
            speed_m_s: params.velocity_m_s,
        },
    )?;
    if params.mass_flow_kg_s > 0.0 {
        let dem = Dem::new(Vec::new(), Vec::new(), params.dem.clone(), g)?;
        let coupling = CouplingParams {
            radius_factor: params.coupling_radius_d,
            switch_porosity: params.drag_switch_porosity,
            ..CouplingParams::default()
        };
        world.set_abrasives(Abrasives::new(dem, coupling, params.penalty, Some(water)))?;
        world.set_grain_outflow(layout.box_min_m, layout.box_max_m)?;
    }
    Ok((world, layout))
}

#[cfg(test)]
mod tests {
    use super::*;
    use grit_sph::particles::KINEMATIC;

    /// The target's fixed particles under the middle third of its width, where only a fixed
    /// bottom holds any.
    fn fixed_under_the_jet(params: &JetParams) -> usize {
        let (world, layout) = build(params).unwrap();
        let p = world.particles();
        (0..p.len())
            .filter(|&i| {
                p.body[i] as usize == layout.target_body
                    && p.flags[i] & KINEMATIC != 0
                    && p.pos[i].x.abs() < params.target_width_m / 6.0
            })
            .count()
    }

    #[test]
    fn the_bottom_is_fixed_unless_the_scene_frees_it_and_a_default_scene_keeps_its_bytes() {
        let fixed = JetParams {
            spacing_m: 1e-4,
            ..JetParams::default()
        };
        let free = JetParams {
            fixed_bottom: false,
            ..fixed.clone()
        };
        // Three layers under the middle third: 20 columns of 100 µm in 2 mm.
        assert_eq!(fixed_under_the_jet(&fixed), 3 * 20);
        assert_eq!(fixed_under_the_jet(&free), 0);
        let text = serde_json::to_string(&fixed).unwrap();
        assert!(!text.contains("fixed_bottom"), "{text}");
        let back: JetParams = serde_json::from_str(&serde_json::to_string(&free).unwrap()).unwrap();
        assert_eq!(back, free);
    }
}
