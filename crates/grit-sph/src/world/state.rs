//! A world's state for checkpoints, versioned apart from `World`'s own fields.

use serde::{Deserialize, Serialize};

use super::flow::Flow;
use super::{Abrasives, NumericalWork, Scratch, Settings, World};
use crate::body::Body;
use crate::contact::ContactPair;
use crate::error::InputError;
use crate::kernel::Kernel;
use crate::math::Vector;
use crate::neighbours::WorldLists;
use crate::particles::{Particles, ParticlesState};
use crate::timers::Timers;

/// The layout of [`WorldState`] this build writes and reads.
pub const WORLD_STATE_VERSION: u32 = 1;

/// What a checkpoint keeps of a world: everything its next step reads that the world does not
/// rebuild (neighbour lists, scratch arrays, timers and the bodies' constants are rebuilt), under
/// a layout version of its own, so `World`'s fields may change without changing checkpoints. A
/// change to these fields, or to the serde layout of a type they hold, is a new version.
///
/// For self-describing formats (JSON): bodies' materials and shapes are read by looking at the
/// data, and the open boundaries and grains are left out when the world has none.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WorldState {
    /// Layout version ([`WORLD_STATE_VERSION`]). A state without one is the JSON of `World`
    /// itself (checkpoints written before this type): the same fields, read as version 1.
    #[serde(default = "first_layout")]
    version: u32,
    settings: Settings,
    kernel: Kernel,
    bodies: Vec<Body>,
    contacts: Vec<ContactPair>,
    particles: ParticlesState,
    /// Simulated time (s).
    time: f64,
    /// Steps taken.
    steps: u64,
    /// The time step the next step takes (s); 0 before the first step.
    dt: f64,
    /// The id the next particle gets.
    next_id: u32,
    work: NumericalWork,
    /// Positions at the last neighbour build: where the resumed world's Verlet skin starts.
    x_build: Vec<Vector>,
    #[serde(default, skip_serializing_if = "Flow::is_empty")]
    flow: Flow,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    abrasives: Option<Abrasives>,
    /// The particles' JH-2 bulking pressures (Pa, AWJ paper eq. 41), one per particle; absent
    /// while all are zero (every world without rock), so those states keep their JSON. Kept
    /// beside `particles` because `ParticlesState`'s positional layout is pinned.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    bulking_pa: Vec<f64>,
}

/// The layout a state that names none was written in.
fn first_layout() -> u32 {
    1
}

impl WorldState {
    /// The layout version this state was written in.
    pub fn version(&self) -> u32 {
        self.version
    }

    /// Simulated time of the world (s).
    pub fn time(&self) -> f64 {
        self.time
    }
}

impl World {
    /// The world's state for a checkpoint: [`World::from_state`] gives a world whose steps are
    /// this one's, bit for bit.
    pub fn state(&self) -> WorldState {
        WorldState {
            version: WORLD_STATE_VERSION,
            settings: self.settings.clone(),
            kernel: self.kernel,
            bodies: self.bodies.clone(),
            contacts: self.contacts.clone(),
            particles: self.particles.state(),
            time: self.time,
            steps: self.steps,
            dt: self.dt,
            next_id: self.next_id,
            work: self.work,
            x_build: self.x_build.clone(),
            flow: self.flow.clone(),
            abrasives: self.abrasives.clone(),
            bulking_pa: if self.particles.bulking.iter().all(|&b| b == 0.0) {
                Vec::new()
            } else {
                self.particles.bulking.clone()
            },
        }
    }

    /// The world of a checkpoint's state. Refuses a layout version this build does not read,
    /// and particles, contact springs or body numbers that do not fit together; errors name
    /// `world.<field>`.
    pub fn from_state(state: WorldState) -> Result<World, InputError> {
        if state.version != WORLD_STATE_VERSION {
            return Err(InputError::new(
                "world.version",
                format!(
                    "layout {} is not the one this build reads ({WORLD_STATE_VERSION})",
                    state.version
                ),
            ));
        }
        let mut particles = Particles::from_state(state.particles)
            .map_err(|e| InputError::new(format!("world.{}", e.field), e.rule))?;
        let (n, bodies) = (particles.len(), state.bodies.len());
        if !state.bulking_pa.is_empty() {
            if state.bulking_pa.len() != n {
                return Err(InputError::new(
                    "world.bulking_pa",
                    format!("holds {} values for {n} particles", state.bulking_pa.len()),
                ));
            }
            particles.bulking = state.bulking_pa;
        }
        if let Some(i) = particles.body.iter().position(|&b| b as usize >= bodies) {
            return Err(InputError::new(
                format!("world.particles.body[{i}]"),
                format!("names body {} of {bodies}", particles.body[i]),
            ));
        }
        for (c, pair) in state.contacts.iter().enumerate() {
            if pair.primary >= bodies || pair.secondary >= bodies {
                return Err(InputError::new(
                    format!("world.contacts[{c}]"),
                    format!(
                        "joins bodies {} and {} of {bodies}",
                        pair.primary, pair.secondary
                    ),
                ));
            }
            if pair.spring.len() != n || pair.penetration.len() != n {
                return Err(InputError::new(
                    format!("world.contacts[{c}]"),
                    format!(
                        "holds {} springs and {} penetrations for {n} particles",
                        pair.spring.len(),
                        pair.penetration.len()
                    ),
                ));
            }
        }
        // The settings are not validated again: a world was built with them, and a rule added
        // since must not strand its checkpoints.
        Ok(World {
            settings: state.settings,
            kernel: state.kernel,
            bodies: state.bodies,
            contacts: state.contacts,
            particles,
            time: state.time,
            steps: state.steps,
            dt: state.dt,
            next_id: state.next_id,
            work: state.work,
            x_build: state.x_build,
            flow: state.flow,
            abrasives: state.abrasives,
            nbrs: WorldLists::default(),
            nbrs_valid: false,
            scratch: Scratch::default(),
            timers: Timers::default(),
            consts: None,
        })
    }
}
