//! ParaView output in the VTK XML formats: particles as an UnstructuredGrid (`.vtu`) of vertex
//! cells with their fields, a polygon (a grain's outline) as a one-cell `.vtu`, and a `.pvd`
//! collection that makes a set of files one time series.
//!
//! The writers take any `Write`, so the engine itself does no I/O. Numbers are ASCII in Rust's
//! shortest round-trip form: a reader gets back the very bits that were written.

use std::fmt::Display;
use std::io::{self, Write};

use crate::body::Body;
use crate::math::{Matrix, Vector};
use crate::particles::{von_mises, Particles, KINEMATIC};

/// VTK cell type of a single point (`VTK_VERTEX`).
pub const VTK_VERTEX: u8 = 1;
/// VTK cell type of a simple polygon (`VTK_POLYGON`).
pub const VTK_POLYGON: u8 = 7;

/// Point fields `write_particles` writes, in file order: (name, components).
pub const PARTICLE_FIELDS: [(&str, usize); 11] = [
    ("velocity_m_s", 3),
    ("stress_pa", 9),
    ("pressure_pa", 1),
    ("von_mises_pa", 1),
    ("plastic_strain", 1),
    ("damage", 1),
    ("temperature_k", 1),
    ("density_kg_m3", 1),
    ("id", 1),
    ("body", 1),
    ("fixed", 1),
];

/// Bulk modulus of each body's EOS (seed eq. 11), indexed by body; 0 for rigid bodies, whose
/// particles carry no stress.
pub fn bulk_moduli(bodies: &[Body]) -> Vec<f64> {
    bodies
        .iter()
        .map(|b| b.material().map_or(0.0, |m| m.bulk_modulus()))
        .collect()
}

/// Full Cauchy stress σ = s − p I of a plane-strain particle as a 3×3 tensor, from its in-plane
/// deviator `sdev` and EOS pressure `p` (seed eqs. 10–11). The out-of-plane deviator is
/// −(s_xx + s_yy), as `Particles::sdev` defines it, so σ_zz = −(s_xx + s_yy) − p.
pub fn cauchy_stress_3d(sdev: &Matrix, p: f64) -> [[f64; 3]; 3] {
    let szz = -(sdev[(0, 0)] + sdev[(1, 1)]);
    [
        [sdev[(0, 0)] - p, sdev[(0, 1)], 0.0],
        [sdev[(1, 0)], sdev[(1, 1)] - p, 0.0],
        [0.0, 0.0, szz - p],
    ]
}

/// Writes `particles` as a VTK XML UnstructuredGrid: one vertex cell per particle at z = 0
/// (m), with the point fields of `PARTICLE_FIELDS`. `bulk_modulus_pa[b]` is body b's bulk
/// modulus (`bulk_moduli`), for the pressure of eq. 11.
pub fn write_particles<W: Write>(
    out: W,
    particles: &Particles,
    bulk_modulus_pa: &[f64],
) -> io::Result<()> {
    let p = particles;
    if let Some(&b) = p
        .body
        .iter()
        .find(|&&b| b as usize >= bulk_modulus_pa.len())
    {
        return Err(invalid(format!(
            "particle of body {b} but bulk moduli are given for {} bodies",
            bulk_modulus_pa.len()
        )));
    }
    // Over the shortest array: a mismatch is reported by the writer below, not a panic here.
    let n = [p.len(), p.body.len(), p.rho.len(), p.rho0.len()];
    let pressure: Vec<f64> = (0..n.into_iter().min().unwrap_or(0))
        .map(|i| p.pressure(i, bulk_modulus_pa[p.body[i] as usize]))
        .collect();
    write_particles_with_pressure(out, particles, &pressure)
}

/// [`write_particles`] with each particle's pressure given (`World::pressures`: a fluid's from
/// its EOS, a metal's from its Mie–Grüneisen law), for scenes the linear law does not describe.
pub fn write_particles_with_pressure<W: Write>(
    out: W,
    particles: &Particles,
    pressure: &[f64],
) -> io::Result<()> {
    let p = particles;
    if !p.is_consistent() {
        return Err(invalid("particle arrays have different lengths"));
    }
    if pressure.len() != p.len() {
        return Err(invalid(format!(
            "{} pressures for {} particles",
            pressure.len(),
            p.len()
        )));
    }
    let n = p.len();
    let mut w = io::BufWriter::new(out);
    header(&mut w, n, n)?;
    writeln!(
        w,
        r#"      <PointData Scalars="damage" Vectors="velocity_m_s" Tensors="stress_pa">"#
    )?;
    let f = |name: &str| {
        PARTICLE_FIELDS
            .iter()
            .find(|f| f.0 == name)
            .expect("listed")
    };
    array(
        &mut w,
        "Float64",
        f("velocity_m_s"),
        p.vel.iter().flat_map(xyz),
    )?;
    array(
        &mut w,
        "Float64",
        f("stress_pa"),
        p.sdev
            .iter()
            .zip(pressure)
            .flat_map(|(s, &pr)| cauchy_stress_3d(s, pr).into_iter().flatten()),
    )?;
    array(
        &mut w,
        "Float64",
        f("pressure_pa"),
        pressure.iter().copied(),
    )?;
    array(
        &mut w,
        "Float64",
        f("von_mises_pa"),
        p.sdev.iter().map(von_mises),
    )?;
    array(
        &mut w,
        "Float64",
        f("plastic_strain"),
        p.eps_p.iter().copied(),
    )?;
    array(&mut w, "Float64", f("damage"), p.damage.iter().copied())?;
    array(
        &mut w,
        "Float64",
        f("temperature_k"),
        p.temp.iter().copied(),
    )?;
    array(&mut w, "Float64", f("density_kg_m3"), p.rho.iter().copied())?;
    array(&mut w, "UInt32", f("id"), p.id.iter().copied())?;
    array(&mut w, "UInt32", f("body"), p.body.iter().copied())?;
    array(
        &mut w,
        "UInt8",
        f("fixed"),
        p.flags.iter().map(|&fl| u8::from(fl & KINEMATIC != 0)),
    )?;
    writeln!(w, "      </PointData>")?;
    points(&mut w, &p.pos)?;
    cells(&mut w, 0..n as u64, (1..=n as u64).collect(), VTK_VERTEX, n)?;
    footer(&mut w)?;
    w.flush()
}

/// Point fields `write_grains` writes, in file order: (name, components).
pub const GRAIN_FIELDS: [(&str, usize); 3] =
    [("velocity_m_s", 3), ("radius_m", 1), ("omega_rad_s", 1)];

/// Writes abrasive grains (the AWJ paper's DEM discs) as a VTK XML UnstructuredGrid of vertex
/// cells at their centres (m), with velocity, radius and spin; ParaView's glyph filter draws
/// them as discs.
pub fn write_grains<W: Write>(out: W, grains: &[crate::dem::Grain]) -> io::Result<()> {
    let n = grains.len();
    let mut w = io::BufWriter::new(out);
    header(&mut w, n, n)?;
    writeln!(
        w,
        r#"      <PointData Scalars="radius_m" Vectors="velocity_m_s">"#
    )?;
    let [vel, radius, omega] = &GRAIN_FIELDS;
    array(
        &mut w,
        "Float64",
        vel,
        grains.iter().flat_map(|g| xyz(&g.vel)),
    )?;
    array(&mut w, "Float64", radius, grains.iter().map(|g| g.radius_m))?;
    array(&mut w, "Float64", omega, grains.iter().map(|g| g.omega))?;
    writeln!(w, "      </PointData>")?;
    let pos: Vec<Vector> = grains.iter().map(|g| g.pos).collect();
    points(&mut w, &pos)?;
    cells(&mut w, 0..n as u64, (1..=n as u64).collect(), VTK_VERTEX, n)?;
    footer(&mut w)?;
    w.flush()
}

/// Writes a closed polygon (a grain's outline, m) as a VTK XML UnstructuredGrid of one
/// `VTK_POLYGON` cell at z = 0.
pub fn write_polygon<W: Write>(out: W, vertices: &[Vector]) -> io::Result<()> {
    if vertices.len() < 3 {
        return Err(invalid(format!(
            "a polygon needs at least 3 vertices, got {}",
            vertices.len()
        )));
    }
    let n = vertices.len();
    let mut w = io::BufWriter::new(out);
    header(&mut w, n, 1)?;
    points(&mut w, vertices)?;
    cells(&mut w, 0..n as u64, vec![n as u64], VTK_POLYGON, 1)?;
    footer(&mut w)?;
    w.flush()
}

/// Writes a ParaView collection (`.pvd`): each `(timestep, file)` becomes one time of a series,
/// `file` relative to the collection's folder.
pub fn write_collection<W: Write>(out: W, entries: &[(f64, &str)]) -> io::Result<()> {
    let mut w = io::BufWriter::new(out);
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        r#"<VTKFile type="Collection" version="1.0" byte_order="LittleEndian">"#
    )?;
    writeln!(w, "  <Collection>")?;
    for (t, file) in entries {
        writeln!(
            w,
            r#"    <DataSet timestep="{t}" part="0" file="{}"/>"#,
            xml_escape(file)
        )?;
    }
    writeln!(w, "  </Collection>")?;
    writeln!(w, "</VTKFile>")?;
    w.flush()
}

fn invalid(msg: impl Into<String>) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, msg.into())
}

fn xyz(v: &Vector) -> [f64; 3] {
    [v.x, v.y, 0.0]
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// A number as VTK's ASCII reader takes it and as Rust reads back bit for bit: integers as
/// they are, floats in shortest round-trip exponent form.
struct Num<T>(T);

impl Display for Num<f64> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:e}", self.0)
    }
}

macro_rules! int_num {
    ($($t:ty),*) => {$(
        impl Display for Num<$t> {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0)
            }
        }
    )*};
}
int_num!(u8, u32, u64);

fn header(w: &mut impl Write, points: usize, cells: usize) -> io::Result<()> {
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
    )?;
    writeln!(w, "  <UnstructuredGrid>")?;
    writeln!(
        w,
        r#"    <Piece NumberOfPoints="{points}" NumberOfCells="{cells}">"#
    )
}

fn footer(w: &mut impl Write) -> io::Result<()> {
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")
}

fn points(w: &mut impl Write, pos: &[Vector]) -> io::Result<()> {
    writeln!(w, "      <Points>")?;
    array(w, "Float64", &("points_m", 3), pos.iter().flat_map(xyz))?;
    writeln!(w, "      </Points>")
}

fn cells(
    w: &mut impl Write,
    connectivity: impl Iterator<Item = u64>,
    offsets: Vec<u64>,
    cell_type: u8,
    count: usize,
) -> io::Result<()> {
    writeln!(w, "      <Cells>")?;
    array(w, "Int64", &("connectivity", 1), connectivity)?;
    array(w, "Int64", &("offsets", 1), offsets.into_iter())?;
    array(w, "UInt8", &("types", 1), (0..count).map(|_| cell_type))?;
    writeln!(w, "      </Cells>")
}

/// One `DataArray`, ASCII, six tuples' worth of numbers a line for readable files.
fn array<T>(
    w: &mut impl Write,
    vtk_type: &str,
    (name, components): &(&str, usize),
    values: impl Iterator<Item = T>,
) -> io::Result<()>
where
    Num<T>: Display,
{
    write!(
        w,
        r#"        <DataArray type="{vtk_type}" Name="{name}" NumberOfComponents="{components}" format="ascii">"#
    )?;
    let per_line = 6 * components;
    for (k, v) in values.enumerate() {
        if k % per_line == 0 {
            write!(w, "\n          ")?;
        } else {
            write!(w, " ")?;
        }
        write!(w, "{}", Num(v))?;
    }
    writeln!(w, "\n        </DataArray>")
}
