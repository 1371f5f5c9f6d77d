//! Engine fingerprints: which bits an engine computes, measured rather than declared. A short
//! canonical run of each scene (one coarse impact with contact, plasticity and damage; a few
//! steps of a jet with water, grains and a copper target, and of one on sandstone that
//! fractures) is hashed bit for bit, so two builds that compute the same numbers share a
//! fingerprint whatever their commit, compiler or CPU, and builds that differ anywhere in those
//! numbers do not (grit's determinism contract, `docs/design.md`, "Rules the engine keeps").

use grit_sph::{Matrix, Particles, Vector};
use sha2::{Digest, Sha256};

use crate::impact::ImpactParams;
use crate::jet::{JetParams, JetRun};
use crate::models::shapes::Shape;
use crate::scene::{Scene, SceneError};
use crate::Sample;

/// Hex digits a fingerprint keeps of its SHA-256: 64 bits, no collision in any farm's life.
pub const FINGERPRINT_HEX: usize = 16;

/// The impact of the impact fingerprint: seed section 4's scene at 10 particles per Dg on a
/// 2 × 1.25 Dg surface, a hexagon at 45° and 150 m/s, fast enough to yield and damage the surface
/// within its few hundred steps.
pub fn canonical_impact() -> ImpactParams {
    ImpactParams {
        spacing_m: 25e-6,
        surface_width_dg: 2.0,
        surface_depth_dg: 1.25,
        distribution_range_dg: 0.0,
        velocity_m_s: 150.0,
        ..ImpactParams::paper(45.0, Shape::Hexagon)
    }
}

/// The jet of the jet fingerprint: the small jet ([`JetParams::small`]: a 3 × 0.8 mm copper
/// target 0.6 mm below a 0.6 mm nozzle at Δx = 100 µm) for one slice of 3 µs: the water and its
/// grains reach and dent the target within the run.
pub fn canonical_jet() -> JetParams {
    JetParams {
        time_ms: 0.003,
        slice_ms: 0.003,
        ..JetParams::small()
    }
}

/// Every number of `p` that a step writes, as bits, in particle order.
fn hash_particles(h: &mut Sha256, p: &Particles) {
    let v = |h: &mut Sha256, x: &Vector| {
        h.update(x.x.to_bits().to_le_bytes());
        h.update(x.y.to_bits().to_le_bytes());
    };
    let m = |h: &mut Sha256, a: &Matrix| {
        for x in a.iter() {
            h.update(x.to_bits().to_le_bytes());
        }
    };
    h.update((p.len() as u64).to_le_bytes());
    for i in 0..p.len() {
        h.update(p.id[i].to_le_bytes());
        v(h, &p.pos[i]);
        v(h, &p.vel[i]);
        for x in [p.mass[i], p.rho[i], p.eps_p[i], p.temp[i], p.damage[i]] {
            h.update(x.to_bits().to_le_bytes());
        }
        m(h, &p.sdev[i]);
        m(h, &p.def_grad[i]);
    }
}

/// `f`'s fingerprint, computed once per process: a fingerprint is a pure function of the
/// binary, and a worker process asks for it at every start of a job loop.
pub fn once(
    cell: &'static std::sync::OnceLock<Result<String, String>>,
    f: fn() -> Result<String, SceneError>,
) -> Result<String, SceneError> {
    cell.get_or_init(|| f().map_err(|e| e.to_string()))
        .clone()
        .map_err(SceneError::Run)
}

fn hex(h: Sha256) -> String {
    format!("{:x}", h.finalize())[..FINGERPRINT_HEX].to_string()
}

/// The impact engine's fingerprint: the bits [`canonical_impact`] leaves in the surface and
/// its record, hashed (SHA-256, first [`FINGERPRINT_HEX`] hex digits).
pub fn impact_engine() -> Result<String, SceneError> {
    impact_engine_of(&canonical_impact())
}

/// [`impact_engine`]'s hash of the first impact of `params` seeded 1.
pub fn impact_engine_of(params: &ImpactParams) -> Result<String, SceneError> {
    let mut s = Sample::start(params, 1)?;
    let rec = Scene::run_next(&mut s, &|| false)?
        .ok_or_else(|| SceneError::Run("the canonical impact was cancelled".into()))?;
    let mut h = Sha256::new();
    hash_particles(&mut h, s.surface());
    for x in [rec.mass_loss_kg, rec.orientation_rad, rec.aim_x_m] {
        h.update(x.to_bits().to_le_bytes());
    }
    Ok(hex(h))
}

/// The rock jet of the jet fingerprint: [`canonical_jet`] at 400 m/s with 0.04 kg/s of grains
/// on sandstone (JH-2, seed paper 002's rock targets) for 3 µs: the water hammer fractures the
/// rock and stretches fractured particles to their least density (`grit_sph::jh2`), so a change
/// to the rock's laws moves the fingerprint as a change to the metal's does.
pub fn canonical_rock_jet() -> JetParams {
    JetParams {
        material: crate::campaign::MaterialSpec(grit_sph::Material::sandstone()),
        velocity_m_s: 400.0,
        mass_flow_kg_s: 0.04,
        ..canonical_jet()
    }
}

/// The jet engine's fingerprint: the bits [`canonical_jet`] and [`canonical_rock_jet`] leave
/// in their worlds and crater samples, hashed as [`impact_engine`]'s.
pub fn jet_engine() -> Result<String, SceneError> {
    jet_engine_of(&[canonical_jet(), canonical_rock_jet()])
}

/// [`jet_engine`]'s hash of the runs of `jets`, each seeded 1, in order.
pub fn jet_engine_of(jets: &[JetParams]) -> Result<String, SceneError> {
    let mut h = Sha256::new();
    for p in jets {
        let (run, samples) = run_jet(p)?;
        for c in &samples {
            for x in [
                c.t_s,
                c.mass_loss_kg_m,
                c.crater_depth_m,
                c.crater_width_m,
                c.max_plastic_strain,
            ] {
                h.update(x.to_bits().to_le_bytes());
            }
        }
        let q = run.world().particles();
        hash_particles(&mut h, q);
        // The rock's compaction state, which the impact surface does not carry.
        for b in &q.bulking {
            h.update(b.to_bits().to_le_bytes());
        }
    }
    Ok(hex(h))
}

/// `p` run to its end seeded 1, with the crater sample of each slice.
fn run_jet(p: &JetParams) -> Result<(JetRun, Vec<grit_sph::crater::CraterSample>), SceneError> {
    let mut run = JetRun::start(p, 1)?;
    let mut samples = Vec::new();
    while run.units_done() < run.slices_total() {
        let slice = Scene::run_next(&mut run, &|| false)?
            .ok_or_else(|| SceneError::Run("the canonical jet was cancelled".into()))?;
        samples.push(slice.sample);
    }
    Ok((run, samples))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_canonical_impact_yields_and_damages_the_surface() {
        let mut s = Sample::start(&canonical_impact(), 1).unwrap();
        s.run_next().unwrap();
        let p = s.surface();
        assert!(p.eps_p.iter().any(|&e| e > 0.0), "no plastic strain");
        assert!(p.damage.iter().any(|&d| d > 0.0), "no damage");
    }

    #[test]
    fn the_canonical_jet_dents_the_target() {
        let mut run = JetRun::start(&canonical_jet(), 1).unwrap();
        let slice = Scene::run_next(&mut run, &|| false).unwrap().unwrap();
        assert!(slice.sample.max_plastic_strain > 0.0, "{:?}", slice.sample);
        assert!(slice.grain_hits.is_some(), "no grain touched the target");
    }

    #[test]
    fn the_canonical_rock_jet_fractures_and_stretches_the_rock_to_its_least_density() {
        let p = canonical_rock_jet();
        let laws = p.material.0.jh2().expect("sandstone is JH-2");
        let (run, _) = run_jet(&p).unwrap();
        let q = run.world().particles();
        let fractured = (0..q.len()).filter(|&i| q.damage[i] >= 1.0).count();
        let least = (0..q.len())
            .filter(|&i| {
                q.damage[i] > 0.0
                    && q.rho[i] == grit_sph::jh2::least_density(&laws, q.bulking[i], q.damage[i])
            })
            .count();
        assert!(fractured > 0, "no fractured rock");
        assert!(least > 0, "no rock particle at its least density");
    }

    #[test]
    fn a_one_ulp_change_of_the_rocks_tensile_strength_moves_the_jet_fingerprint() {
        let base = canonical_rock_jet();
        let mut moved = base.clone();
        let Some(grit_sph::material::Strength::JohnsonHolmquist2(s)) =
            moved.material.0.plasticity.as_mut()
        else {
            panic!("sandstone is JH-2");
        };
        s.t_pa = f64::from_bits(s.t_pa.to_bits() + 1);
        assert_ne!(
            jet_engine_of(&[base]).unwrap(),
            jet_engine_of(&[moved]).unwrap()
        );
    }

    #[test]
    fn fingerprints_are_the_same_on_one_and_two_threads() {
        let on = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| (impact_engine().unwrap(), jet_engine().unwrap()))
        };
        let one = on(1);
        assert_eq!(one, on(2));
        assert_eq!(
            (one.0.len(), one.1.len()),
            (FINGERPRINT_HEX, FINGERPRINT_HEX)
        );
    }

    #[test]
    fn a_one_ulp_change_of_one_constant_moves_the_fingerprint() {
        let base = canonical_impact();
        let mut moved = base.clone();
        let youngs = &mut moved.material.youngs_modulus_pa;
        *youngs = f64::from_bits(youngs.to_bits() + 1);
        assert_ne!(
            impact_engine_of(&base).unwrap(),
            impact_engine_of(&moved).unwrap()
        );
    }
}
