//! The impact scene as flags, shared by `grit sample` and `grit study`.

use std::path::PathBuf;

use anyhow::{bail, Context};
use grit_erosion::{ImpactParams, Shape};

/// The impact scene as command-line flags (defaults: Mohseni-Mofidi et al. 2022, section 4).
#[derive(clap::Args)]
pub struct SceneArgs {
    /// Impact angle, degrees from the surface, in (0, 90] (required unless a scene file or
    /// checkpoint gives it).
    #[arg(long, allow_negative_numbers = true)]
    angle: Option<f64>,
    /// Grain shape: octagon, hexagon, square, rectangle or circle [default: hexagon].
    #[arg(long)]
    shape: Option<String>,
    /// Particle spacing Δx (m); Mohseni-Mofidi et al. 2022 use 8e-6.
    #[arg(long, allow_negative_numbers = true)]
    spacing_m: Option<f64>,
    /// Impact speed (m/s).
    #[arg(long, allow_negative_numbers = true)]
    velocity_m_s: Option<f64>,
    /// Aim-point range in grain diameters.
    #[arg(long, allow_negative_numbers = true)]
    distribution_range_dg: Option<f64>,
    /// Surface width in grain diameters.
    #[arg(long, allow_negative_numbers = true)]
    surface_width_dg: Option<f64>,
    /// Surface depth in grain diameters.
    #[arg(long, allow_negative_numbers = true)]
    surface_depth_dg: Option<f64>,
    /// End an impact once the surface kinetic energy is below this fraction of the grain's.
    #[arg(long, allow_negative_numbers = true)]
    settle_fraction: Option<f64>,
    /// Surface material by name: aisi304 (the seed's), copper or al6061 (Johnson–Cook with the
    /// Mie–Grüneisen EOS, docs/jet.md).
    #[arg(long)]
    material: Option<String>,
    /// File holding the full scene as a JSON object (ImpactParams fields); flags above
    /// override its fields.
    #[arg(long)]
    scene: Option<PathBuf>,
}

impl SceneArgs {
    /// The first scene flag given, by its name: a checkpoint carries its own scene.
    pub fn first_given(&self) -> Option<&'static str> {
        [
            ("--angle", self.angle.is_some()),
            ("--shape", self.shape.is_some()),
            ("--spacing-m", self.spacing_m.is_some()),
            ("--velocity-m-s", self.velocity_m_s.is_some()),
            (
                "--distribution-range-dg",
                self.distribution_range_dg.is_some(),
            ),
            ("--surface-width-dg", self.surface_width_dg.is_some()),
            ("--surface-depth-dg", self.surface_depth_dg.is_some()),
            ("--settle-fraction", self.settle_fraction.is_some()),
            ("--material", self.material.is_some()),
            ("--scene", self.scene.is_some()),
        ]
        .into_iter()
        .find_map(|(flag, given)| given.then_some(flag))
    }

    /// The validated scene; errors name the field and the rule.
    pub fn params(&self) -> anyhow::Result<ImpactParams> {
        let mut p = match &self.scene {
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .with_context(|| format!("reading {}", path.display()))?;
                grit_erosion::scene::scene_from_json(&text, "ImpactParams")
                    .with_context(|| format!("scene {}", path.display()))?
            }
            None => ImpactParams::default(),
        };
        match (self.angle, &self.scene) {
            (Some(a), _) => p.angle_deg = a,
            (None, Some(_)) => {}
            (None, None) => bail!("angle: required (--angle DEG, in (0, 90])"),
        }
        if let Some(name) = &self.shape {
            p.shape = Shape::from_name(name).with_context(|| {
                format!(
                    "shape: unknown `{name}`; expected one of {}",
                    grit_erosion::models::shapes::BUILTIN_NAMES.join(", ")
                )
            })?;
        }
        if let Some(name) = &self.material {
            p.material = grit_sph::Material::by_name(name)
                .map_err(|e| anyhow::anyhow!("{}: {}", e.field, e.rule))?;
        }
        let set = |dst: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *dst = v;
            }
        };
        set(&mut p.spacing_m, self.spacing_m);
        set(&mut p.velocity_m_s, self.velocity_m_s);
        set(&mut p.distribution_range_dg, self.distribution_range_dg);
        set(&mut p.surface_width_dg, self.surface_width_dg);
        set(&mut p.surface_depth_dg, self.surface_depth_dg);
        set(&mut p.settle_fraction, self.settle_fraction);
        if let Err(e) = p.validate() {
            bail!("{}: {}", e.field, e.rule);
        }
        Ok(p)
    }
}
