//! `grit jet --snapshots`: pictures (phase, pressure, damage) and ParaView files (water and
//! target, grains) at the end of chosen slices.

use std::path::{Path, PathBuf};

use anyhow::Context;
use grit_erosion::jet::JetRun;

/// Where `--snapshots` writes, every how many slices, and what it has written.
pub struct Snapshots {
    dir: PathBuf,
    every: u32,
    /// (time in µs, particles file, grains file) of every snapshot written.
    written: Vec<(f64, String, String)>,
}

impl Snapshots {
    /// Checks the folder takes files before any slice runs.
    pub fn new(dir: &Path, every: u32) -> anyhow::Result<Self> {
        if every == 0 {
            anyhow::bail!("--snapshot-every: must be at least 1");
        }
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--snapshots {}: cannot create the folder", dir.display()))?;
        let s = Snapshots {
            dir: dir.to_path_buf(),
            every,
            written: Vec::new(),
        };
        s.write_collections()
            .with_context(|| format!("--snapshots {}: cannot write there", dir.display()))?;
        Ok(s)
    }

    fn write_collections(&self) -> std::io::Result<()> {
        for (name, pick) in [("scene.pvd", 0), ("grains.pvd", 1)] {
            let entries: Vec<(f64, &str)> = self
                .written
                .iter()
                .map(|(t, a, b)| (*t, if pick == 0 { a.as_str() } else { b.as_str() }))
                .collect();
            let f = std::fs::File::create(self.dir.join(name))?;
            grit_sph::vtk::write_collection(f, &entries)?;
        }
        Ok(())
    }

    /// Writes the scene as `run` holds it, if its last slice is one to snapshot.
    pub fn write(&mut self, run: &JetRun) -> anyhow::Result<()> {
        let k = run.slices_done();
        if !(k.is_multiple_of(self.every) || run.finished()) {
            return Ok(());
        }
        let w = run.world();
        let p = run.params();
        let tag = format!("{k:04}");
        let path = |name: &str| self.dir.join(name);
        let create = |name: &str| {
            std::fs::File::create(path(name))
                .with_context(|| format!("--snapshots: writing {}", path(name).display()))
        };
        let pressure = w.pressures();
        let scene_file = format!("scene-{tag}.vtu");
        grit_sph::vtk::write_particles_with_pressure(
            create(&scene_file)?,
            w.particles(),
            &pressure,
        )?;
        let grains = w.abrasives().map_or(&[][..], |a| &a.dem.grains[..]);
        let grains_file = format!("grains-{tag}.vtu");
        grit_sph::vtk::write_grains(create(&grains_file)?, grains)?;
        let s = run.slices().last().expect("a slice is done");
        let picture = grit_plot::JetPicture {
            particles: w.particles(),
            pressure_pa: &pressure,
            fluid_body: run.layout().fluid_body as u32,
            spacing_m: p.spacing_m,
            grains: grains.iter().map(|g| (g.pos, g.radius_m)).collect(),
            view_m: Some((run.layout().box_min_m, run.layout().box_max_m)),
            title: format!(
                "t = {:.1} µs, {} at {} m/s, M = {} kg/s, Δx {} µm",
                w.time() * 1e6,
                p.material.0.name,
                p.velocity_m_s,
                p.mass_flow_kg_s,
                p.spacing_m * 1e6
            ),
            notes: vec![format!(
                "Cd {:.1} µm, Cw {:.1} µm, mass loss {:.3e} kg/m, largest plastic strain {:.3}; {} grains in the scene, {} fed; pale: fixed",
                s.sample.crater_depth_m * 1e6,
                s.sample.crater_width_m * 1e6,
                s.sample.mass_loss_kg_m,
                s.sample.max_plastic_strain,
                s.grains,
                s.grains_fed
            )],
        };
        for field in grit_plot::JetField::ALL {
            let png = path(&format!("{}-{tag}.png", field.stem()));
            grit_plot::jet_png(&picture, field, &png)?;
        }
        self.written.push((w.time() * 1e6, scene_file, grains_file));
        self.write_collections()
            .with_context(|| format!("--snapshots: writing {}", self.dir.display()))
    }
}
