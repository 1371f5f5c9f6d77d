//! Polygons and how bodies are filled with particles: a square lattice for deformable bodies,
//! boundary-conforming layers for rigid bodies, so a grain's contact surface is as smooth as
//! the polygon it stands for (the extrapolated-normal contact of seed section 3.1 needs that).

use serde::{Deserialize, Serialize};

use crate::error::InputError;
use crate::math::{cross, Vector};

/// A simple polygon, vertices counter-clockwise (m).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Polygon {
    vertices: Vec<Vector>,
}

impl Polygon {
    /// Validates (`validate_polygon`) and builds a polygon; `field` names the input for
    /// errors. Clockwise input is reversed so every polygon is counter-clockwise.
    pub fn new(vertices: &[[f64; 2]], field: &str) -> Result<Self, InputError> {
        validate_polygon(vertices, field)?;
        let mut v = vectors(vertices);
        if signed_area(&v) < 0.0 {
            v.reverse();
        }
        Ok(Polygon { vertices: v })
    }

    /// Regular n-gon of circumradius `r`, first vertex at angle `phase` (rad).
    pub fn regular(n: usize, r: f64, phase: f64) -> Self {
        let vertices = (0..n)
            .map(|k| {
                let t = phase + 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                let (s, c) = crate::math::sin_cos(t);
                Vector::new(r * c, r * s)
            })
            .collect();
        Polygon { vertices }
    }

    /// Axis-aligned rectangle [x0, x1] × [y0, y1].
    pub fn rectangle(x0: f64, y0: f64, x1: f64, y1: f64) -> Self {
        Polygon {
            vertices: vec![
                Vector::new(x0, y0),
                Vector::new(x1, y0),
                Vector::new(x1, y1),
                Vector::new(x0, y1),
            ],
        }
    }

    /// Vertices, counter-clockwise.
    pub fn vertices(&self) -> &[Vector] {
        &self.vertices
    }

    /// Area (m²).
    pub fn area(&self) -> f64 {
        signed_area(&self.vertices)
    }

    /// Area centroid (m). Summed about the coordinate origin, unlike `centroid`: rigid bodies
    /// are placed by it, and another reference point would move them by rounding.
    pub fn centroid(&self) -> Vector {
        centroid_about(&self.vertices, Vector::zeros())
    }

    /// Polar second moment of area about the centroid (m⁴); times density gives the inertia.
    pub fn polar_moment(&self) -> f64 {
        let c = self.centroid();
        let v: Vec<Vector> = self.vertices.iter().map(|p| p - c).collect();
        let n = v.len();
        let mut j = 0.0;
        for i in 0..n {
            let (a, b) = (v[i], v[(i + 1) % n]);
            j += cross(a, b) * (a.dot(&a) + a.dot(&b) + b.dot(&b));
        }
        j / 12.0
    }

    /// The polygon moved by `d`.
    pub fn translated(&self, d: Vector) -> Self {
        Polygon {
            vertices: self.vertices.iter().map(|p| p + d).collect(),
        }
    }

    /// The polygon rotated by `theta` (rad) about `centre`.
    pub fn rotated(&self, theta: f64, centre: Vector) -> Self {
        Polygon {
            vertices: self
                .vertices
                .iter()
                .map(|p| centre + crate::math::rotate(p - centre, theta))
                .collect(),
        }
    }

    /// Even–odd point-in-polygon test.
    pub fn contains(&self, p: Vector) -> bool {
        let v = &self.vertices;
        let n = v.len();
        let mut inside = false;
        let mut j = n - 1;
        for i in 0..n {
            let (a, b) = (v[i], v[j]);
            if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
                inside = !inside;
            }
            j = i;
        }
        inside
    }

    /// Distance from `p` to the nearest edge (m).
    pub fn distance_to_boundary(&self, p: Vector) -> f64 {
        let v = &self.vertices;
        let n = v.len();
        (0..n)
            .map(|i| point_segment_distance(p, v[i], v[(i + 1) % n]))
            .fold(f64::INFINITY, f64::min)
    }

    /// Square lattice of spacing `dx` (cell-centred on `origin`) clipped to the polygon: the
    /// particle layout of a deformable body. Each point stands for dx² of area.
    pub fn fill_lattice(&self, dx: f64, origin: Vector) -> Vec<Vector> {
        let (lo, hi) = self.bbox();
        let i0 = ((lo.x - origin.x) / dx).floor() as i64 - 1;
        let i1 = ((hi.x - origin.x) / dx).ceil() as i64 + 1;
        let j0 = ((lo.y - origin.y) / dx).floor() as i64 - 1;
        let j1 = ((hi.y - origin.y) / dx).ceil() as i64 + 1;
        let mut out = Vec::new();
        for j in j0..=j1 {
            for i in i0..=i1 {
                let p = origin + Vector::new((i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx);
                if self.contains(p) {
                    out.push(p);
                }
            }
        }
        out
    }

    /// Rigid-body fill: an outer layer of particles spaced about `dx` along the polygon inset by
    /// dx/2, so the boundary layer is as straight as the edges, then interior lattice points at
    /// least `dx` inside. Returns (points, is_boundary).
    pub fn fill_layered(&self, dx: f64) -> (Vec<Vector>, Vec<bool>) {
        let inset = self.inset_vertices(0.5 * dx);
        let n = inset.len();
        let mut pts = Vec::new();
        let mut boundary = Vec::new();
        for i in 0..n {
            let (a, b) = (inset[i], inset[(i + 1) % n]);
            let len = (b - a).norm();
            let m = (len / dx).round().max(1.0) as usize;
            // Vertex a belongs to this edge, b to the next one, so corners appear once.
            for k in 0..m {
                pts.push(a + (b - a) * (k as f64 / m as f64));
                boundary.push(true);
            }
        }
        let c = self.centroid();
        for p in self.fill_lattice(dx, c - Vector::new(0.5 * dx, 0.5 * dx)) {
            if self.distance_to_boundary(p) >= 1.0 * dx - 1e-12 * dx {
                pts.push(p);
                boundary.push(false);
            }
        }
        (pts, boundary)
    }

    /// Vertices of the polygon offset inwards by `d` (mitred corners); valid for convex corners
    /// and gentle concave ones, which is what grains are.
    fn inset_vertices(&self, d: f64) -> Vec<Vector> {
        let v = &self.vertices;
        let n = v.len();
        (0..n)
            .map(|i| {
                let prev = v[(i + n - 1) % n];
                let cur = v[i];
                let next = v[(i + 1) % n];
                let e1 = (cur - prev).normalize();
                let e2 = (next - cur).normalize();
                // Inward normals of a counter-clockwise polygon point left of each edge.
                let n1 = Vector::new(-e1.y, e1.x);
                let n2 = Vector::new(-e2.y, e2.x);
                let bis = n1 + n2;
                let cos_half = (bis.norm() * 0.5).max(1e-6);
                cur + bis.normalize() * (d / cos_half)
            })
            .collect()
    }

    /// Bounding box (min, max).
    pub fn bbox(&self) -> (Vector, Vector) {
        bbox(&self.vertices)
    }
}

/// Signed polygon area by the shoelace formula (positive when counter-clockwise).
pub fn signed_area(v: &[Vector]) -> f64 {
    let n = v.len();
    (0..n).map(|i| cross(v[i], v[(i + 1) % n])).sum::<f64>() * 0.5
}

/// Area centroid of a simple polygon (not the vertex mean, which uneven vertex spacing would
/// bias), summed about the first vertex so outlines far from the origin stay well conditioned.
pub fn centroid(v: &[Vector]) -> Vector {
    centroid_about(v, v[0])
}

fn centroid_about(v: &[Vector], o: Vector) -> Vector {
    let n = v.len();
    let (mut a2, mut c) = (0.0, Vector::zeros());
    for i in 0..n {
        let (p, q) = (v[i] - o, v[(i + 1) % n] - o);
        let k = cross(p, q);
        a2 += k;
        c += (p + q) * k;
    }
    o + c / (3.0 * a2)
}

/// Below this fraction of its bounding box's larger side squared, a polygon's area counts as
/// zero: rounding in collinear vertices leaves an area of that order, which does not depend
/// on the unit of length.
pub const ZERO_AREA_TOLERANCE: f64 = 1e-12;

/// Checks that `v` is a simple polygon: at least 3 finite vertices, no vertex repeating the
/// one before it, an area above `ZERO_AREA_TOLERANCE`, no two edges folding back on each other
/// or crossing or touching. Errors name `field` and the rule broken.
pub fn validate_polygon(v: &[[f64; 2]], field: &str) -> Result<(), InputError> {
    let invalid = |rule: String| Err(InputError::new(field, rule));
    let n = v.len();
    if n < 3 {
        return invalid(format!("a polygon needs at least 3 vertices, got {n}"));
    }
    if let Some(i) = v
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return invalid(format!("vertex {i} is not finite"));
    }
    let v = vectors(v);
    for i in 0..n {
        if v[i] == v[(i + 1) % n] {
            return invalid(format!("vertices {i} and {} coincide", (i + 1) % n));
        }
    }
    // Two non-adjacent edges that touch; a zero area with such a pair is a crossing (a bow
    // tie), one without is collinear vertices.
    let crossing = (0..n)
        .flat_map(|i| (i + 2..n).map(move |j| (i, j)))
        .filter(|&(i, j)| !(i == 0 && j == n - 1))
        .find(|&(i, j)| segments_intersect(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n]));
    let crossed = |(i, j): (usize, usize)| {
        invalid(format!(
            "polygon is self-intersecting: edges {i} and {j} intersect; it must be simple"
        ))
    };
    let (lo, hi) = bbox(&v);
    let extent = (hi - lo).max();
    if signed_area(&v).abs() <= ZERO_AREA_TOLERANCE * extent * extent {
        return match crossing {
            Some(pair) => crossed(pair),
            None => invalid("area is zero: the vertices are collinear".into()),
        };
    }
    for i in 0..n {
        let (a, b, c) = (v[i], v[(i + 1) % n], v[(i + 2) % n]);
        if orient(a, b, c) == 0.0 && (b - a).dot(&(c - b)) < 0.0 {
            let j = (i + 1) % n;
            return invalid(format!(
                "edges {i} and {j} fold back on each other at vertex {j}: the polygon must be simple"
            ));
        }
    }
    if let Some(pair) = crossing {
        return crossed(pair);
    }
    Ok(())
}

fn vectors(v: &[[f64; 2]]) -> Vec<Vector> {
    v.iter().map(|p| Vector::new(p[0], p[1])).collect()
}

fn bbox(v: &[Vector]) -> (Vector, Vector) {
    let mut lo = Vector::new(f64::INFINITY, f64::INFINITY);
    let mut hi = -lo;
    for p in v {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

fn point_segment_distance(p: Vector, a: Vector, b: Vector) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (p - (a + ab * t)).norm()
}

fn orient(a: Vector, b: Vector, c: Vector) -> f64 {
    cross(b - a, c - a)
}

/// Whether the closed segments p1p2 and q1q2 share any point.
fn segments_intersect(p1: Vector, p2: Vector, q1: Vector, q2: Vector) -> bool {
    let d1 = orient(q1, q2, p1);
    let d2 = orient(q1, q2, p2);
    let d3 = orient(p1, p2, q1);
    let d4 = orient(p1, p2, q2);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |a: Vector, b: Vector, c: Vector, d: f64| {
        d == 0.0
            && c.x >= a.x.min(b.x)
            && c.x <= a.x.max(b.x)
            && c.y >= a.y.min(b.y)
            && c.y <= a.y.max(b.y)
    };
    on(q1, q2, p1, d1) || on(q1, q2, p2, d2) || on(p1, p2, q1, d3) || on(p1, p2, q2, d4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn self_intersecting_polygon_is_rejected_naming_the_field() {
        let bow = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
        let e = Polygon::new(&bow, "grain.vertices_m").unwrap_err();
        assert_eq!(e.field, "grain.vertices_m");
        assert!(e.rule.contains("self-intersecting"), "{e}");
    }

    #[test]
    fn degenerate_polygons_are_rejected() {
        assert!(Polygon::new(&[[0.0, 0.0], [1.0, 0.0]], "p").is_err());
        assert!(Polygon::new(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], "p").is_err());
        assert!(Polygon::new(&[[0.0, 0.0], [f64::NAN, 0.0], [0.0, 1.0]], "p").is_err());
    }

    #[test]
    fn clockwise_input_is_made_counter_clockwise() {
        let p = Polygon::new(&[[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]], "p").unwrap();
        assert!((p.area() - 1.0).abs() < 1e-15);
        assert!((p.centroid() - Vector::new(0.5, 0.5)).norm() < 1e-15);
        // Square of side 1: J = 1/6.
        assert!((p.polar_moment() - 1.0 / 6.0).abs() < 1e-15);
    }

    #[test]
    fn lattice_fill_matches_area() {
        let p = Polygon::regular(6, 1.0, 0.0);
        let dx = 0.01;
        let pts = p.fill_lattice(dx, Vector::zeros());
        let a = pts.len() as f64 * dx * dx;
        assert!(
            (a - p.area()).abs() / p.area() < 0.01,
            "{a} vs {}",
            p.area()
        );
    }

    #[test]
    fn layered_fill_puts_boundary_particles_half_a_spacing_inside() {
        let p = Polygon::regular(6, 1.0, 0.1);
        let dx = 0.05;
        let (pts, b) = p.fill_layered(dx);
        for (q, &isb) in pts.iter().zip(&b) {
            let d = p.distance_to_boundary(*q);
            if isb {
                assert!(
                    (d - 0.5 * dx).abs() < 1e-9 || d < 0.5 * dx + 1e-9,
                    "boundary particle at depth {d}"
                );
            } else {
                assert!(d >= dx - 1e-9);
            }
        }
    }
}
