//! The VTK files `grit_sph::vtk` writes are read back by an independent reader (vtkio) with
//! every particle, every field and every value as written, bit for bit; the grain outline is
//! one polygon cell; a collection lists its files; bad input is an error, not a broken file.

use grit_sph::particles::KINEMATIC;
use grit_sph::verification::elastic_impact;
use grit_sph::vtk::{self, PARTICLE_FIELDS};
use grit_sph::{Particles, Polygon, Settings, Vector};
use vtkio::model::{Attribute, CellType, DataSet, IOBuffer, Piece, UnstructuredGridPiece};
use vtkio::model::{ElementType, VertexNumbers};

fn read_grid(bytes: &[u8]) -> UnstructuredGridPiece {
    let vtk = vtkio::Vtk::parse_xml(bytes).expect("vtkio parses the file");
    match vtk.data {
        DataSet::UnstructuredGrid { mut pieces, .. } => {
            assert_eq!(pieces.len(), 1, "one piece");
            match pieces.remove(0) {
                Piece::Inline(p) => *p,
                _ => panic!("piece is not inline"),
            }
        }
        _ => panic!("not an UnstructuredGrid"),
    }
}

/// The point field `name`: its number of components and its values.
fn field(piece: &UnstructuredGridPiece, name: &str) -> (usize, IOBuffer) {
    let found = piece.data.point.iter().find_map(|a| match a {
        Attribute::DataArray(d) if d.name == name => Some((d.num_comp(), d.data.clone())),
        _ => None,
    });
    found.unwrap_or_else(|| panic!("no point field {name}"))
}

fn f64s(piece: &UnstructuredGridPiece, name: &str, comps: usize) -> Vec<f64> {
    let (c, data) = field(piece, name);
    assert_eq!(c, comps, "{name}: components");
    data.into_vec::<f64>()
        .unwrap_or_else(|| panic!("{name} is not Float64"))
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A disc pressed into an elastic block for a few steps (stress, pressure and velocity are
/// non-trivial), with damage, plastic strain and temperature set to distinct awkward values.
fn state() -> (Particles, Vec<f64>) {
    // The small disc: few rigid particles, so most of the state written is the loaded block's.
    let mut w = elastic_impact::scene_with(12, Settings::default(), elastic_impact::Disc::SMALL);
    for _ in 0..400 {
        w.step().unwrap();
    }
    let bulk = vtk::bulk_moduli(w.bodies());
    let mut p = w.particles().clone();
    for k in 0..p.len() {
        let x = k as f64;
        p.damage[k] = (x * 0.1).sin().abs() / 3.0;
        p.eps_p[k] = 1e-7 * x + 1.0 / 7.0;
        p.temp[k] = 293.0 + x / 9.0;
    }
    p.flags[3] |= KINEMATIC;
    (p, bulk)
}

#[test]
fn particles_read_back_bit_for_bit() {
    let (p, bulk) = state();
    let n = p.len();
    assert!(p.body.contains(&1), "scene has rigid particles too");
    let mut bytes = Vec::new();
    vtk::write_particles(&mut bytes, &p, &bulk).unwrap();
    let g = read_grid(&bytes);

    assert_eq!(g.num_points(), n, "particle count");
    let pts = g.points.clone().into_vec::<f64>().expect("Float64 points");
    let want: Vec<f64> = p.pos.iter().flat_map(|x| [x.x, x.y, 0.0]).collect();
    assert_eq!(bits(&pts), bits(&want), "positions");
    assert_eq!(g.cells.types.len(), n, "one cell per particle");
    assert!(g.cells.types.iter().all(|t| *t == CellType::Vertex));
    match &g.cells.cell_verts {
        VertexNumbers::XML {
            connectivity,
            offsets,
        } => {
            assert_eq!(connectivity, &(0..n as u64).collect::<Vec<_>>());
            assert_eq!(offsets, &(1..=n as u64).collect::<Vec<_>>());
        }
        other => panic!("cells not in XML form: {other:?}"),
    }

    for (name, comps) in PARTICLE_FIELDS {
        let (c, data) = field(&g, name);
        assert_eq!(c, comps, "{name}: components");
        assert_eq!(data.len(), n * comps, "{name}: values");
    }
    let damage = f64s(&g, "damage", 1);
    assert_eq!(bits(&damage), bits(&p.damage), "damage");
    for k in [0, 17, n - 1] {
        assert_eq!(damage[k], p.damage[k], "damage of particle {k}");
    }
    assert_eq!(
        bits(&f64s(&g, "plastic_strain", 1)),
        bits(&p.eps_p),
        "plastic strain"
    );
    assert_eq!(
        bits(&f64s(&g, "temperature_k", 1)),
        bits(&p.temp),
        "temperature"
    );
    assert_eq!(bits(&f64s(&g, "density_kg_m3", 1)), bits(&p.rho), "density");
    let vel = f64s(&g, "velocity_m_s", 3);
    let want: Vec<f64> = p.vel.iter().flat_map(|v| [v.x, v.y, 0.0]).collect();
    assert_eq!(bits(&vel), bits(&want), "velocity");

    // σ = s − p I with the EOS pressure (eq. 11); σ_zz = −(s_xx + s_yy) − p (plane strain).
    let stress = f64s(&g, "stress_pa", 9);
    let pressure = f64s(&g, "pressure_pa", 1);
    let mut loaded = 0;
    for k in 0..n {
        let pr = p.pressure(k, bulk[p.body[k] as usize]);
        assert_eq!(pressure[k].to_bits(), pr.to_bits(), "pressure of {k}");
        let s = p.sdev[k];
        let sig = &stress[9 * k..9 * k + 9];
        let want = [
            s[(0, 0)] - pr,
            s[(0, 1)],
            0.0,
            s[(1, 0)],
            s[(1, 1)] - pr,
            0.0,
            0.0,
            0.0,
            -(s[(0, 0)] + s[(1, 1)]) - pr,
        ];
        assert_eq!(bits(sig), bits(&want), "stress of particle {k}");
        if pr != 0.0 && s[(0, 1)] != 0.0 {
            loaded += 1;
        }
    }
    assert!(
        loaded > n / 4,
        "only {loaded} of {n} particles carry stress"
    );
    let vm = f64s(&g, "von_mises_pa", 1);
    assert_eq!(vm[5], grit_sph::particles::von_mises(&p.sdev[5]));

    let ids = field(&g, "id").1.into_vec::<u32>().expect("UInt32 ids");
    assert_eq!(ids, p.id);
    let fixed = field(&g, "fixed").1.into_vec::<u8>().expect("UInt8 flags");
    assert_eq!(fixed[3], 1);
    assert_eq!(fixed.iter().filter(|&&f| f == 1).count(), 1);

    // Damage and stress are the active scalars and tensors, velocity the active vectors, so
    // ParaView colours and glyphs by them without being told.
    let active = |name: &str| {
        g.data.point.iter().find_map(|a| match a {
            Attribute::DataArray(d) if d.name == name => Some(d.elem.clone()),
            _ => None,
        })
    };
    assert!(matches!(
        active("damage"),
        Some(ElementType::Scalars { .. })
    ));
    assert!(matches!(active("velocity_m_s"), Some(ElementType::Vectors)));
    assert!(matches!(active("stress_pa"), Some(ElementType::Tensors)));
}

#[test]
fn empty_state_is_a_valid_file() {
    let mut bytes = Vec::new();
    vtk::write_particles(&mut bytes, &Particles::default(), &[]).unwrap();
    let g = read_grid(&bytes);
    assert_eq!(g.num_points(), 0);
    assert_eq!(field(&g, "damage").1.len(), 0);
}

#[test]
fn polygon_is_one_closed_cell() {
    let hex = Polygon::regular(6, 125e-6, 0.3).translated(Vector::new(1e-5, -3e-5));
    let mut bytes = Vec::new();
    vtk::write_polygon(&mut bytes, hex.vertices()).unwrap();
    let g = read_grid(&bytes);
    assert_eq!(g.num_points(), 6);
    let pts = g.points.clone().into_vec::<f64>().unwrap();
    for (k, v) in hex.vertices().iter().enumerate() {
        assert_eq!(
            [pts[3 * k], pts[3 * k + 1], pts[3 * k + 2]],
            [v.x, v.y, 0.0]
        );
    }
    assert_eq!(g.cells.types, vec![CellType::Polygon]);
    match &g.cells.cell_verts {
        VertexNumbers::XML {
            connectivity,
            offsets,
        } => {
            assert_eq!(connectivity, &(0..6).collect::<Vec<u64>>());
            assert_eq!(offsets, &vec![6]);
        }
        other => panic!("cells not in XML form: {other:?}"),
    }
}

#[test]
fn collection_lists_every_file_with_its_time() {
    let mut bytes = Vec::new();
    vtk::write_collection(&mut bytes, &[(1.0, "surface-0001.vtu"), (10.0, "a&b.vtu")]).unwrap();
    let text = String::from_utf8(bytes).unwrap();
    assert!(text.contains(r#"<VTKFile type="Collection""#));
    assert!(text.contains(r#"<DataSet timestep="1" part="0" file="surface-0001.vtu"/>"#));
    assert!(text.contains(r#"<DataSet timestep="10" part="0" file="a&amp;b.vtu"/>"#));
    assert!(text.trim_end().ends_with("</VTKFile>"));
}

#[test]
fn bad_input_is_an_error() {
    let (p, bulk) = state();
    let err = vtk::write_particles(Vec::new(), &p, &bulk[..1]).unwrap_err();
    assert!(err.to_string().contains("body 1"), "{err}");
    let mut broken = p.clone();
    broken.damage.pop();
    assert!(vtk::write_particles(Vec::new(), &broken, &bulk).is_err());
    let two = [Vector::zeros(), Vector::new(1.0, 0.0)];
    assert!(vtk::write_polygon(Vec::new(), &two).is_err());
}
