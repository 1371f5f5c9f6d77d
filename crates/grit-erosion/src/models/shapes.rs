//! Grain shapes and their shape factors: angularity An (seed paper eq. 36, corrected to
//! reproduce Table 2) and aspect ratio e (max/min Feret diameter), seed paper section 4.
//!
//! Every grain is scaled to the area of a circle of diameter Dg, as in the seed paper
//! ("all grains have almost the same area that is equal to the area of a circle with the
//! diameter of 250 µm"), so shapes are compared at equal mass.
//!
//! # Angularity
//! The extracted text of eq. 36 reads An = √(2π) Σ aᵢ pᵢ with aᵢ = √(2π/βᵢ) and
//! pᵢ = (π − βᵢ)/(2π). That does not reproduce Table 2 (a square would get 2√(2π) ≈ 5.01).
//! The form that does is
//!
//! ```text
//! An = (Σ aᵢ pᵢ)²,   aᵢ = √(2π/βᵢ),   pᵢ = (π − βᵢ)/(2π)
//! ```
//!
//! For a regular n-gon every βᵢ = π(n − 2)/n and Σ pᵢ = 1, so An = 2π/β = 2n/(n − 2):
//! octagon 8/3 = 2.67, hexagon 3.0, square 4.0, rectangle 4.0, exactly Table 2 (checked by
//! the tests below). As n → ∞ every βᵢ → π and An → 2, which is what a circle reports.
//!
//! pᵢ is the probability that corner i is the lowest point of a randomly oriented grain,
//! i.e. the share of orientations in which it hits a flat surface first. Only corners of the
//! convex hull can do that, and corner i is lowest for an orientation range equal to the
//! hull's exterior angle there; so for a non-convex polygon pᵢ comes from the convex hull
//! while aᵢ keeps the corner's own interior angle (a sharp spike stays sharp even if the hull
//! around it is blunt). For convex polygons this is the formula above unchanged.

use std::fmt;

use grit_sph::{geometry, Vector};
use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Number of vertices of the polygon that stands in for a circular grain.
pub const CIRCLE_VERTICES: usize = 64;

/// Grain diameter Dg of the seed paper, section 4 (250 µm).
pub const PAPER_GRAIN_DIAMETER_M: f64 = 250e-6;

/// Angularity of a smooth circle: the n → ∞ limit of 2n/(n − 2) (seed paper eq. 36 as
/// corrected in this module's docs).
pub const CIRCLE_ANGULARITY: f64 = 2.0;

/// Names of the built-in shapes, in the order `Shape::builtins` returns them.
pub const BUILTIN_NAMES: [&str; 5] = ["octagon", "hexagon", "square", "rectangle", "circle"];

/// A grain outline (seed paper Fig. 7b, plus a circle and user polygons).
///
/// Serialised as a name string (`"hexagon"`) for the built-ins and as an object
/// `{"name": ..., "vertices_m": [[x, y], ...]}` for a custom polygon. The object form without
/// `vertices_m` names a built-in. Custom vertices give the outline only: like every grain,
/// the polygon is rescaled to the area of a circle of the campaign's diameter Dg, so a
/// diameter sweep applies to every shape alike.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// Regular octagon (Table 2: e = 1.082, An = 2.67).
    Octagon,
    /// Regular hexagon, the seed paper's reference grain (Table 2: e = 1.155, An = 3.0).
    Hexagon,
    /// Square (Table 2: e = 1.414, An = 4.0).
    Square,
    /// Rectangle with sides 2:1 (Table 2: e = 2.236, An = 4.0).
    Rectangle,
    /// Circle, simulated as a regular polygon of `CIRCLE_VERTICES` vertices; its shape
    /// factors are reported as the smooth circle's (An = 2, e = 1).
    Circle,
    /// Any simple polygon, given by its vertices in either orientation.
    Polygon {
        /// Name of the shape, used as the cell's `shape` in results.
        name: String,
        /// Vertices [x, y] in metres, in order around the outline.
        vertices_m: Vec<[f64; 2]>,
    },
}

/// Shape factors and size of a grain, as `grit shapes --json` prints them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShapeInfo {
    /// Shape name.
    pub name: String,
    /// Angularity An (seed paper eq. 36, corrected form; Table 2).
    pub angularity: f64,
    /// Aspect ratio e = max Feret / min Feret diameter (seed paper section 4, Table 2).
    pub aspect_ratio: f64,
    /// Grain area in m², π Dg²/4.
    pub area_m2: f64,
}

/// An invalid shape or grain size; names the offending field and the rule it breaks.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// A field breaks a rule, e.g. `shapes[2].vertices_m: edges 0 and 2 intersect`.
    #[error("{field}: {rule}")]
    Invalid {
        /// Path of the field, e.g. `shapes[2].vertices_m`.
        field: String,
        /// The rule broken, in words.
        rule: String,
    },
}

fn invalid(field: &str, rule: impl Into<String>) -> ShapeError {
    ShapeError::Invalid {
        field: field.to_string(),
        rule: rule.into(),
    }
}

impl Shape {
    /// The built-in shapes: octagon, hexagon, square, rectangle, circle.
    pub fn builtins() -> [Shape; 5] {
        [
            Shape::Octagon,
            Shape::Hexagon,
            Shape::Square,
            Shape::Rectangle,
            Shape::Circle,
        ]
    }

    /// The four shapes of the seed paper (Fig. 7b, Table 2).
    pub fn paper() -> [Shape; 4] {
        [
            Shape::Octagon,
            Shape::Hexagon,
            Shape::Square,
            Shape::Rectangle,
        ]
    }

    /// A built-in shape by name (`"hexagon"`), or `None`.
    pub fn from_name(name: &str) -> Option<Shape> {
        match name {
            "octagon" => Some(Shape::Octagon),
            "hexagon" => Some(Shape::Hexagon),
            "square" => Some(Shape::Square),
            "rectangle" => Some(Shape::Rectangle),
            "circle" => Some(Shape::Circle),
            _ => None,
        }
    }

    /// The shape's name, as used in results.
    pub fn name(&self) -> &str {
        match self {
            Shape::Octagon => "octagon",
            Shape::Hexagon => "hexagon",
            Shape::Square => "square",
            Shape::Rectangle => "rectangle",
            Shape::Circle => "circle",
            Shape::Polygon { name, .. } => name,
        }
    }

    /// Checks a custom polygon (by `grit_sph::geometry::validate_polygon`: ≥ 3 finite vertices,
    /// non-zero area, simple) and its name; `field` is the shape's path, e.g. `shapes[2]`, and
    /// errors name `shapes[2].vertices_m`.
    pub fn validate(&self, field: &str) -> Result<(), ShapeError> {
        let Shape::Polygon { name, vertices_m } = self else {
            return Ok(());
        };
        let name_field = format!("{field}.name");
        if name.trim().is_empty() {
            return Err(invalid(&name_field, "must not be empty"));
        }
        if Shape::from_name(name).is_some() {
            return Err(invalid(
                &name_field,
                format!("`{name}` is a built-in shape; give a custom polygon another name"),
            ));
        }
        geometry::validate_polygon(vertices_m, &format!("{field}.vertices_m"))
            .map_err(|e| invalid(&e.field, e.rule))
    }

    /// Unscaled outline in counter-clockwise order (before centring and scaling).
    fn outline(&self) -> Vec<[f64; 2]> {
        match self {
            Shape::Octagon => regular_polygon(8),
            Shape::Hexagon => regular_polygon(6),
            Shape::Square => regular_polygon(4),
            Shape::Rectangle => vec![[-1.0, -0.5], [1.0, -0.5], [1.0, 0.5], [-1.0, 0.5]],
            Shape::Circle => regular_polygon(CIRCLE_VERTICES),
            Shape::Polygon { vertices_m, .. } => {
                let mut v = vertices_m.clone();
                if signed_area(&v) < 0.0 {
                    v.reverse();
                }
                v
            }
        }
    }

    /// Grain outline for diameter Dg: counter-clockwise, area centroid at the origin, area
    /// π Dg²/4 (seed paper section 4: grains of equal area).
    pub fn vertices(&self, diameter_m: f64) -> Result<Vec<[f64; 2]>, ShapeError> {
        check_diameter(diameter_m)?;
        self.validate("shape")?;
        let mut v = self.outline();
        let c = centroid(&v);
        let target = std::f64::consts::PI * diameter_m * diameter_m / 4.0;
        let scale = (target / signed_area(&v)).sqrt();
        for p in &mut v {
            *p = [(p[0] - c[0]) * scale, (p[1] - c[1]) * scale];
        }
        Ok(v)
    }

    /// Angularity An and aspect ratio e, Table 2 of the seed paper; a circle reports its
    /// smooth limits (An = 2, e = 1) rather than those of its polygonal stand-in.
    pub fn factors(&self) -> Result<(f64, f64), ShapeError> {
        if *self == Shape::Circle {
            return Ok((CIRCLE_ANGULARITY, 1.0));
        }
        self.validate("shape")?;
        let v = self.outline();
        Ok((angularity(&v), aspect_ratio(&v)))
    }

    /// Name, shape factors and area of the grain for diameter Dg (`grit shapes --json`).
    pub fn info(&self, diameter_m: f64) -> Result<ShapeInfo, ShapeError> {
        check_diameter(diameter_m)?;
        let (angularity, aspect_ratio) = self.factors()?;
        Ok(ShapeInfo {
            name: self.name().to_string(),
            angularity,
            aspect_ratio,
            area_m2: std::f64::consts::PI * diameter_m * diameter_m / 4.0,
        })
    }
}

fn check_diameter(diameter_m: f64) -> Result<(), ShapeError> {
    if diameter_m.is_finite() && diameter_m > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            "diameter_m",
            format!("must be finite and > 0, got {diameter_m}"),
        ))
    }
}

/// Regular n-gon of unit circumradius with a flat bottom edge, so every built-in grain
/// starts in the same resting pose before the random orientation of each impact.
fn regular_polygon(n: usize) -> Vec<[f64; 2]> {
    use std::f64::consts::PI;
    (0..n)
        .map(|k| {
            let t = -PI / 2.0 + PI / n as f64 + 2.0 * PI * k as f64 / n as f64;
            let (s, c) = grit_sph::math::sin_cos(t);
            [c, s]
        })
        .collect()
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Signed area of an outline (positive when counter-clockwise), by the engine's shoelace
/// formula (`grit_sph::geometry::signed_area`).
pub fn signed_area(v: &[[f64; 2]]) -> f64 {
    geometry::signed_area(&vectors(v))
}

/// Area centroid of an outline, by the engine's formula (`grit_sph::geometry::centroid`).
pub fn centroid(v: &[[f64; 2]]) -> [f64; 2] {
    let c = geometry::centroid(&vectors(v));
    [c.x, c.y]
}

fn vectors(v: &[[f64; 2]]) -> Vec<Vector> {
    v.iter().map(|p| Vector::new(p[0], p[1])).collect()
}

/// Indices of the convex hull's vertices, counter-clockwise, collinear points dropped
/// (Andrew's monotone chain).
pub fn convex_hull(v: &[[f64; 2]]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..v.len()).collect();
    idx.sort_by(|&a, &b| {
        v[a][0]
            .total_cmp(&v[b][0])
            .then(v[a][1].total_cmp(&v[b][1]))
    });
    idx.dedup_by(|a, b| v[*a] == v[*b]);
    if idx.len() < 3 {
        return idx;
    }
    let mut hull: Vec<usize> = Vec::with_capacity(2 * idx.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &usize>> = if pass == 0 {
            Box::new(idx.iter())
        } else {
            Box::new(idx.iter().rev())
        };
        for &i in iter {
            while hull.len() >= start + 2
                && cross(v[hull[hull.len() - 2]], v[hull[hull.len() - 1]], v[i]) <= 0.0
            {
                hull.pop();
            }
            hull.push(i);
        }
        // The last point of each chain is the first of the other.
        hull.pop();
    }
    hull
}

/// Minimum and maximum Feret (caliper) diameters, by rotating calipers over the convex
/// hull: the width is attained with one caliper flush with a hull edge, and the diameter
/// by an antipodal pair met on the way.
pub fn feret_diameters(v: &[[f64; 2]]) -> (f64, f64) {
    let h: Vec<[f64; 2]> = convex_hull(v).into_iter().map(|i| v[i]).collect();
    let n = h.len();
    if n < 3 {
        let d = if n == 2 { dist(h[0], h[1]) } else { 0.0 };
        return (0.0, d);
    }
    let (mut min_w, mut max_d) = (f64::INFINITY, 0.0_f64);
    let mut j = 1;
    for i in 0..n {
        let (a, b) = (h[i], h[(i + 1) % n]);
        while cross(a, b, h[(j + 1) % n]) > cross(a, b, h[j]) {
            j = (j + 1) % n;
        }
        min_w = min_w.min(cross(a, b, h[j]) / dist(a, b));
        max_d = max_d.max(dist(a, h[j])).max(dist(b, h[j]));
    }
    (min_w, max_d)
}

/// Aspect ratio e = max Feret / min Feret diameter (seed paper section 4, Table 2).
pub fn aspect_ratio(v: &[[f64; 2]]) -> f64 {
    let (min, max) = feret_diameters(v);
    max / min
}

/// Angularity An = (Σ aᵢ pᵢ)² over the convex-hull corners, aᵢ = √(2π/βᵢ) from the
/// polygon's interior angle βᵢ, pᵢ = (π − βᵢ^hull)/(2π) (seed paper eq. 36 in the form that
/// reproduces Table 2; see the module docs). Vertices in either orientation.
pub fn angularity(v: &[[f64; 2]]) -> f64 {
    use std::f64::consts::PI;
    let sign = if signed_area(v) < 0.0 { -1.0 } else { 1.0 };
    let n = v.len();
    let hull = convex_hull(v);
    let m = hull.len();
    let turn = |p: [f64; 2], c: [f64; 2], q: [f64; 2]| {
        let (e1, e2) = ([c[0] - p[0], c[1] - p[1]], [q[0] - c[0], q[1] - c[1]]);
        (e1[0] * e2[1] - e1[1] * e2[0]).atan2(e1[0] * e2[0] + e1[1] * e2[1])
    };
    let mut sum = 0.0;
    for k in 0..m {
        let i = hull[k];
        let hull_exterior = turn(v[hull[(k + m - 1) % m]], v[i], v[hull[(k + 1) % m]]);
        let (prev, next) = (v[(i + n - 1) % n], v[(i + 1) % n]);
        let beta = PI - sign * turn(prev, v[i], next);
        sum += (2.0 * PI / beta).sqrt() * hull_exterior / (2.0 * PI);
    }
    sum * sum
}

/// Serde form of `Shape`: a built-in's name, or `{name, vertices_m}`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ShapeObject {
    name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    vertices_m: Option<Vec<[f64; 2]>>,
}

impl Serialize for Shape {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Shape::Polygon { name, vertices_m } => ShapeObject {
                name: name.clone(),
                vertices_m: Some(vertices_m.clone()),
            }
            .serialize(s),
            builtin => s.serialize_str(builtin.name()),
        }
    }
}

fn unknown_shape<E: de::Error>(name: &str) -> E {
    E::custom(format!(
        "unknown shape `{name}`; expected one of {} or an object {{\"name\", \"vertices_m\"}}",
        BUILTIN_NAMES.join(", ")
    ))
}

impl<'de> Deserialize<'de> for Shape {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ShapeVisitor;
        impl<'de> Visitor<'de> for ShapeVisitor {
            type Value = Shape;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(
                    f,
                    "a shape name ({}) or an object {{\"name\", \"vertices_m\"}}",
                    BUILTIN_NAMES.join(", ")
                )
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Shape, E> {
                Shape::from_name(v).ok_or_else(|| unknown_shape(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Shape, A::Error> {
                let o = ShapeObject::deserialize(de::value::MapAccessDeserializer::new(map))?;
                match o.vertices_m {
                    Some(vertices_m) => Ok(Shape::Polygon {
                        name: o.name,
                        vertices_m,
                    }),
                    None => Shape::from_name(&o.name).ok_or_else(|| unknown_shape(&o.name)),
                }
            }
        }
        d.deserialize_any(ShapeVisitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    const DG: f64 = PAPER_GRAIN_DIAMETER_M;

    #[test]
    fn shape_factors_equal_table_2_to_printed_digits() {
        let table = [
            (Shape::Octagon, "1.082", "2.67"),
            (Shape::Hexagon, "1.155", "3.0"),
            (Shape::Square, "1.414", "4.0"),
            (Shape::Rectangle, "2.236", "4.0"),
        ];
        for (shape, e, an) in table {
            let info = shape.info(DG).unwrap();
            assert_eq!(format!("{:.3}", info.aspect_ratio), e, "{}", shape.name());
            let digits = an.len() - 2;
            assert_eq!(
                format!("{:.*}", digits, info.angularity),
                an,
                "{}",
                shape.name()
            );
        }
    }

    #[test]
    fn shape_factors_match_closed_forms() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12 * b;
        let (an, e) = Shape::Octagon.factors().unwrap();
        assert!(close(an, 8.0 / 3.0) && close(e, 1.0 / (PI / 8.0).cos()));
        let (an, e) = Shape::Hexagon.factors().unwrap();
        assert!(close(an, 3.0) && close(e, 2.0 / 3f64.sqrt()));
        let (an, e) = Shape::Rectangle.factors().unwrap();
        assert!(close(an, 4.0) && close(e, 5f64.sqrt()));
    }

    #[test]
    fn printed_eq_36_does_not_reproduce_table_2() {
        // √(2π) Σ aᵢpᵢ for a square: the reason this module squares the sum instead.
        let printed = (2.0 * PI).sqrt() * 2.0;
        assert!((printed - 4.0).abs() > 1.0);
    }

    #[test]
    fn circle_reports_smooth_limits_and_its_polygon_approaches_them() {
        let (an, e) = Shape::Circle.factors().unwrap();
        assert_eq!((an, e), (2.0, 1.0));
        let v = Shape::Circle.vertices(DG).unwrap();
        let n = CIRCLE_VERTICES as f64;
        assert!((angularity(&v) - 2.0 * n / (n - 2.0)).abs() < 1e-12);
        assert!((aspect_ratio(&v) - 1.0 / (PI / n).cos()).abs() < 1e-12);
    }

    #[test]
    fn builtin_shapes_have_equal_area_ccw_and_centred() {
        let target = PI * DG * DG / 4.0;
        for shape in Shape::builtins() {
            let v = shape.vertices(DG).unwrap();
            let a = signed_area(&v);
            assert!(a > 0.0, "{} is not counter-clockwise", shape.name());
            assert!((a - target).abs() <= 1e-12 * target, "{}", shape.name());
            let c = centroid(&v);
            assert!(c[0].abs() < 1e-15 * DG && c[1].abs() < 1e-15 * DG);
            assert_eq!(shape.info(DG).unwrap().area_m2, target);
        }
    }

    #[test]
    fn custom_polygon_is_reoriented_centred_and_scaled() {
        // An L-shape given clockwise and far from the origin.
        let l = vec![
            [10.0, 10.0],
            [10.0, 12.0],
            [11.0, 12.0],
            [11.0, 11.0],
            [12.0, 11.0],
            [12.0, 10.0],
        ];
        let shape = Shape::Polygon {
            name: "ell".into(),
            vertices_m: l,
        };
        let v = shape.vertices(DG).unwrap();
        let target = PI * DG * DG / 4.0;
        assert!((signed_area(&v) - target).abs() <= 1e-12 * target);
        let c = centroid(&v);
        assert!(c[0].abs() < 1e-12 * DG && c[1].abs() < 1e-12 * DG);
        // Hull: the L's five convex corners at 90° plus the 135° cut across the notch; the
        // reflex corner is not on the hull. a = 2 for the four square corners on the hull.
        let (an, e) = shape.factors().unwrap();
        let hull_exterior = [PI / 2.0, PI / 2.0, PI / 2.0, PI / 4.0, PI / 4.0];
        let expected = (hull_exterior
            .iter()
            .map(|x| 2.0 * x / (2.0 * PI))
            .sum::<f64>())
        .powi(2);
        assert!((an - expected).abs() < 1e-12, "{an} vs {expected}");
        // Max Feret: the diagonal 2√2 across the hull; min Feret: the 2 m side widths.
        assert!((e - 2f64.sqrt()).abs() < 1e-12, "{e}");
    }

    #[test]
    fn spike_keeps_its_own_sharpness_on_a_blunt_hull() {
        // A dart (arrowhead): the tip is sharp; the reflex corner at the back never hits first.
        let dart = [[0.0, 0.0], [4.0, 1.0], [0.0, 2.0], [1.0, 1.0]];
        let an = angularity(&dart);
        let hull = convex_hull(&dart);
        assert_eq!(hull.len(), 3);
        // The tip's angle is the same on the polygon and the hull; the two back corners are
        // sharper on the polygon than on the hull, so An exceeds the hull's own angularity.
        assert!(an > angularity(&[[0.0, 0.0], [4.0, 1.0], [0.0, 2.0]]));
    }

    #[test]
    fn invalid_polygons_name_the_field_and_rule() {
        let cases: Vec<(Vec<[f64; 2]>, &str)> = vec![
            (vec![[0.0, 0.0], [1.0, 0.0]], "at least 3 vertices"),
            (
                vec![[0.0, 0.0], [1.0, f64::NAN], [0.0, 1.0]],
                "vertex 1 is not finite",
            ),
            (vec![[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], "area is zero"),
            (
                vec![[0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
                "coincide",
            ),
            (
                vec![[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 1.0]],
                "intersect",
            ),
            (
                vec![[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
                "fold back",
            ),
            (
                // Touches itself at a vertex: two triangles joined at (1, 1).
                vec![
                    [0.0, 0.0],
                    [1.0, 1.0],
                    [2.0, 0.0],
                    [2.0, 2.0],
                    [1.0, 1.0],
                    [0.0, 2.0],
                ],
                "coincide|intersect",
            ),
        ];
        for (vertices_m, rule) in cases {
            let shape = Shape::Polygon {
                name: "p".into(),
                vertices_m,
            };
            let err = shape.validate("shapes[2]").unwrap_err().to_string();
            assert!(err.starts_with("shapes[2].vertices_m: "), "{err}");
            assert!(
                rule.split('|').any(|r| err.contains(r)),
                "{err} lacks {rule}"
            );
            assert!(shape.vertices(DG).is_err());
        }
    }

    #[test]
    fn custom_polygon_names_are_checked() {
        let tri = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let hex = Shape::Polygon {
            name: "hexagon".into(),
            vertices_m: tri.clone(),
        };
        assert!(hex
            .validate("shapes[0]")
            .unwrap_err()
            .to_string()
            .starts_with("shapes[0].name"));
        let blank = Shape::Polygon {
            name: " ".into(),
            vertices_m: tri,
        };
        assert!(blank.validate("shapes[1]").is_err());
        assert!(Shape::Hexagon.vertices(0.0).is_err());
        assert!(Shape::Hexagon.info(f64::NAN).is_err());
    }

    #[test]
    fn serde_names_and_objects() {
        let shapes: Vec<Shape> = serde_json::from_str(
            r#"["hexagon", {"name": "square"}, {"name": "tri", "vertices_m": [[0,0],[1e-4,0],[0,1e-4]]}]"#,
        )
        .unwrap();
        assert_eq!(shapes[0], Shape::Hexagon);
        assert_eq!(shapes[1], Shape::Square);
        assert_eq!(shapes[2].name(), "tri");
        let json = serde_json::to_string(&shapes).unwrap();
        assert_eq!(
            json,
            r#"["hexagon","square",{"name":"tri","vertices_m":[[0.0,0.0],[0.0001,0.0],[0.0,0.0001]]}]"#
        );
        let err = serde_json::from_str::<Shape>(r#""pentagon""#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("unknown shape `pentagon`"), "{err}");
        let err = serde_json::from_str::<Shape>(r#"{"name": "x", "vertices": []}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("unknown field `vertices`"), "{err}");
        let info = serde_json::to_value(Shape::Hexagon.info(DG).unwrap()).unwrap();
        for key in ["name", "angularity", "aspect_ratio", "area_m2"] {
            assert!(info.get(key).is_some(), "{key}");
        }
    }

    fn brute_feret(v: &[[f64; 2]]) -> (f64, f64) {
        let mut max = 0.0_f64;
        for a in v {
            for b in v {
                max = max.max(dist(*a, *b));
            }
        }
        let h: Vec<[f64; 2]> = convex_hull(v).into_iter().map(|i| v[i]).collect();
        let mut min = f64::INFINITY;
        for i in 0..h.len() {
            let (a, b) = (h[i], h[(i + 1) % h.len()]);
            let w = h
                .iter()
                .map(|&p| cross(a, b, p) / dist(a, b))
                .fold(0.0, f64::max);
            min = min.min(w);
        }
        (min, max)
    }

    proptest! {
        #[test]
        fn calipers_match_brute_force(pts in prop::collection::vec((-1.0..1.0f64, -1.0..1.0f64), 3..40)) {
            let v: Vec<[f64; 2]> = pts.into_iter().map(|(x, y)| [x, y]).collect();
            prop_assume!(convex_hull(&v).len() >= 3);
            let (min, max) = feret_diameters(&v);
            let (bmin, bmax) = brute_feret(&v);
            prop_assert!((min - bmin).abs() <= 1e-12 && (max - bmax).abs() <= 1e-12);
        }

        #[test]
        fn factors_do_not_depend_on_pose_or_size(
            n in 3usize..12, angle in 0.0..6.3f64, scale in 1e-6..1e3f64, dx in -1.0..1.0f64,
        ) {
            let base = regular_polygon(n);
            let (s, c) = angle.sin_cos();
            let moved: Vec<[f64; 2]> = base
                .iter()
                .map(|p| [scale * (c * p[0] - s * p[1]) + dx, scale * (s * p[0] + c * p[1])])
                .collect();
            let expected_an = 2.0 * n as f64 / (n as f64 - 2.0);
            prop_assert!((angularity(&moved) - expected_an).abs() < 1e-9);
            prop_assert!((aspect_ratio(&moved) - aspect_ratio(&base)).abs() < 1e-9);
            let mut reversed = moved.clone();
            reversed.reverse();
            prop_assert!((angularity(&reversed) - expected_an).abs() < 1e-9);
        }

        #[test]
        fn convex_polygons_are_valid_and_scale_to_circle_area(
            angles in prop::collection::btree_set(0u32..3600, 3..30), d in 1e-6..1e-2f64,
        ) {
            // Distinct angles on a circle give a convex polygon.
            let v: Vec<[f64; 2]> = angles
                .iter()
                .map(|&a| {
                    let t = a as f64 / 3600.0 * 2.0 * PI;
                    [t.cos(), t.sin()]
                })
                .collect();
            prop_assume!(signed_area(&v) > 1e-6);
            let shape = Shape::Polygon { name: "p".into(), vertices_m: v };
            let out = shape.vertices(d).unwrap();
            let target = PI * d * d / 4.0;
            prop_assert!((signed_area(&out) - target).abs() <= 1e-12 * target);
            let (an, e) = shape.factors().unwrap();
            prop_assert!(an >= 2.0 - 1e-12 && e >= 1.0 - 1e-12);
        }
    }
}
