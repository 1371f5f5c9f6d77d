//! `grit sample --snapshots`: pictures and ParaView files of the surface after chosen impacts.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use grit_erosion::impact::PeakContact;
use grit_erosion::Sample;

/// Where `--snapshots` writes, which impacts it takes, and what it has written so far.
pub struct Snapshots {
    pub dir: PathBuf,
    at: BTreeSet<u32>,
    /// Digits of the impact number in file names, so they sort in impact order.
    width: usize,
    /// (impact, surface file, grain file if the grain touched) of every snapshot written.
    pub written: Vec<(u32, String, Option<String>)>,
}

impl Snapshots {
    /// Checks the flags before any impact runs: the impacts are this run's and the folder
    /// takes files.
    pub fn new(dir: &Path, at: Option<&[u32]>, done: u32, impacts: u32) -> anyhow::Result<Self> {
        let at: BTreeSet<u32> = match at {
            Some(list) => {
                for &k in list {
                    if k == 0 || k > impacts {
                        bail!(
                            "--snapshot-at: impact {k} is not one of this run's impacts 1..={impacts} (--impacts)"
                        );
                    }
                    if k <= done {
                        bail!(
                            "--snapshot-at: impact {k} was finished before the checkpoint, which holds {done} impacts"
                        );
                    }
                }
                list.iter().copied().collect()
            }
            None => std::iter::once(1)
                .chain((10..=impacts).step_by(10))
                .chain(std::iter::once(impacts))
                .filter(|&k| k > done)
                .collect(),
        };
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--snapshots {}: cannot create the folder", dir.display()))?;
        let s = Snapshots {
            dir: dir.to_path_buf(),
            at,
            width: impacts.to_string().len().max(4),
            written: Vec::new(),
        };
        // Empty collections now: an unwritable folder fails before hours of simulation.
        s.write_collections()
            .with_context(|| format!("--snapshots {}: cannot write there", dir.display()))?;
        Ok(s)
    }

    pub fn wants(&self, impact: u32) -> bool {
        self.at.contains(&impact)
    }

    fn write_collections(&self) -> std::io::Result<()> {
        let surface: Vec<(f64, &str)> = self
            .written
            .iter()
            .map(|(k, f, _)| (*k as f64, f.as_str()))
            .collect();
        let grain: Vec<(f64, &str)> = self
            .written
            .iter()
            .filter_map(|(k, _, g)| g.as_deref().map(|g| (*k as f64, g)))
            .collect();
        for (name, entries) in [("surface.pvd", surface), ("grain.pvd", grain)] {
            let f = std::fs::File::create(self.dir.join(name))?;
            grit_sph::vtk::write_collection(f, &entries)?;
        }
        Ok(())
    }

    /// Writes the pictures and ParaView files of the surface as `s` holds it after its last
    /// impact, with the grain at `peak`.
    pub fn write(&mut self, s: &Sample, peak: Option<&PeakContact>) -> anyhow::Result<()> {
        let k = s.impacts_done();
        let p = s.params();
        let tag = format!("{k:0w$}", w = self.width);
        let in_dir = |name: &str| self.dir.join(name);
        let create = |name: &str| {
            std::fs::File::create(in_dir(name))
                .with_context(|| format!("--snapshots: writing {}", in_dir(name).display()))
        };

        let surface_file = format!("surface-{tag}.vtu");
        grit_sph::vtk::write_particles(
            create(&surface_file)?,
            s.surface(),
            &[p.material.bulk_modulus()],
        )
        .with_context(|| format!("--snapshots: writing {surface_file}"))?;
        let grain_file = match peak {
            Some(pk) => {
                let name = format!("grain-{tag}.vtu");
                grit_sph::vtk::write_polygon(create(&name)?, &pk.outline_m)
                    .with_context(|| format!("--snapshots: writing {name}"))?;
                Some(name)
            }
            None => None,
        };

        let um = 1e6;
        let lost: f64 = s.records().iter().map(|r| r.mass_loss_kg).sum();
        let removed: u32 = s
            .records()
            .iter()
            .map(|r| r.outcome.removed_particles + r.outcome.detached_particles)
            .sum();
        let grain_note = match peak {
            Some(pk) => format!(
                "grey: the grain at its largest contact force in impact {k}, {:.3e} N/m at {:.2} µs; \
                 its lowest point {:.1} µm below the original surface (y = 0)",
                pk.force_n_m,
                pk.time_s * um,
                pk.depth_m * um
            ),
            None => format!("the grain of impact {k} never touched the surface"),
        };
        let picture = grit_plot::SurfacePicture {
            particles: s.surface(),
            spacing_m: p.spacing_m,
            outline_m: peak.map(|pk| pk.outline_m.as_slice()),
            title: format!(
                "after impact {k}, {}° {}, {} m/s, Δx {} µm, seed {}",
                p.angle_deg,
                p.shape.name(),
                p.velocity_m_s,
                p.spacing_m * um,
                s.seed()
            ),
            notes: vec![
                grain_note,
                if removed == 0 {
                    format!("no surface mass lost in impacts 1-{k}; pale: the fixed particles that hold the surface")
                } else {
                    format!(
                        "surface mass lost in impacts 1-{k}: {lost:.3e} kg per m of depth \
                         ({removed} particles); pale: the fixed particles that hold the surface"
                    )
                },
            ],
        };
        for field in grit_plot::SurfaceField::ALL {
            let path = in_dir(&format!("{}-{tag}.png", field.stem()));
            grit_plot::surface_png(&picture, field, &path)?;
        }
        self.written.push((k, surface_file, grain_file));
        self.write_collections()
            .with_context(|| format!("--snapshots: writing {}", self.dir.display()))
    }
}
