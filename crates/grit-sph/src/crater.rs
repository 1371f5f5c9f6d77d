//! Crater depth Cd and width Cw of a jet-eroded target, from its particle positions and the
//! original surface line (definitions: docs/jet.md#crater-metrics).
//!
//! The target's top is y = `surface_y_m` before erosion (the centres of the top particle row)
//! and the jet comes down along −y. Only the topmost particle of each column counts, so the
//! caller may pass every live particle of the target or only its surface ones; detached
//! fragments must be left out.

use serde::{Deserialize, Serialize};

use crate::error::InputError;
use crate::math::Vector;
use crate::particles::{Particles, KINEMATIC};

/// How the profile is sampled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CraterOptions {
    /// Column width for the surface profile (m); the particle spacing is the natural choice.
    pub bin_m: f64,
    /// A column counts as cratered when its surface lies more than this below the original
    /// line (m); half a particle spacing keeps surface roughness out of the width.
    pub depth_tol_m: f64,
    /// Two target particles closer than this hang together ([`attached`]); a piece joined to
    /// no fixed particle is a fragment, left out of the profile.
    pub link_m: f64,
}

impl CraterOptions {
    /// Columns one spacing wide, tolerance half a spacing, pieces linked within 1.5 spacings
    /// (the lattice's diagonal neighbours are 1.41 apart).
    pub fn for_spacing(spacing_m: f64) -> Self {
        CraterOptions {
            bin_m: spacing_m,
            depth_tol_m: 0.5 * spacing_m,
            link_m: 1.5 * spacing_m,
        }
    }
}

/// Crater measures of one profile (docs/jet.md#crater-metrics).
#[derive(Debug, Clone, PartialEq)]
pub struct Crater {
    /// Cd: largest depth of the surface below the original line (m), 0 when none lies below.
    pub depth_m: f64,
    /// Cw: width of the crater at `depth_tol_m` below the original line (m), 0 without a crater.
    pub width_m: f64,
    /// Width at half of Cd (m); `half_depth_width_m / width_m` is ½ for a V and 1 for a
    /// flat-bottomed U with vertical walls.
    pub half_depth_width_m: f64,
    /// Left and right ends of the width (m).
    pub edges_m: (f64, f64),
    /// x of the deepest column (the first, left to right, on ties) (m).
    pub deepest_x_m: f64,
    /// True when the crater reaches an end of the profile, so the width is a lower bound.
    pub open: bool,
    /// The surface profile (x, y) of the topmost particle per column, left to right.
    pub profile: Vec<Vector>,
}

/// One point of a jet run's time series (the fields `grit jet --json` is to print).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CraterSample {
    /// Simulated time (s).
    pub t_s: f64,
    /// Target mass removed so far, per metre of depth (kg/m).
    pub mass_loss_kg_m: f64,
    /// Cd (m).
    pub crater_depth_m: f64,
    /// Cw (m).
    pub crater_width_m: f64,
    /// Largest equivalent plastic strain left in the target (–).
    pub max_plastic_strain: f64,
}

impl CraterSample {
    /// The JSON keys of a sample: the fields every point of a jet series carries.
    pub const FIELDS: [&'static str; 5] = [
        "t_s",
        "mass_loss_kg_m",
        "crater_depth_m",
        "crater_width_m",
        "max_plastic_strain",
    ];
}

/// The indices of body `body`'s particles, in particle order: the order of the masks that
/// [`sample`] reads.
pub fn body_particles(particles: &Particles, body: u32) -> Vec<usize> {
    (0..particles.len())
        .filter(|&i| particles.body[i] == body)
        .collect()
}

/// Which of the particles `of_body` are fixed (kinematic).
pub fn fixed_of(particles: &Particles, of_body: &[usize]) -> Vec<bool> {
    of_body
        .iter()
        .map(|&i| particles.flags.get(i).is_some_and(|f| f & KINEMATIC != 0))
        .collect()
}

/// The time-series point of target body `body` at time `t_s`, and its crater: Cd and Cw from
/// the particles `keep` names, one entry per particle of [`body_particles`] (a rock keeps the
/// ones `cracks::held` names), or when `None` from those that hang together with its fixed
/// (kinematic) ones ([`attached`]; all of them when it has none); the largest plastic strain
/// among those, and `mass_loss_kg_m` as the caller books it.
pub fn sample(
    t_s: f64,
    particles: &Particles,
    body: u32,
    mass_loss_kg_m: f64,
    surface_y_m: f64,
    opts: CraterOptions,
    keep: Option<&[bool]>,
) -> Result<(CraterSample, Crater), InputError> {
    let of_body = body_particles(particles, body);
    let pos: Vec<Vector> = of_body.iter().map(|&i| particles.pos[i]).collect();
    let found;
    let keep = match keep {
        Some(k) => k,
        None => {
            let fixed = fixed_of(particles, &of_body);
            found = if fixed.iter().any(|&f| f) {
                attached(&pos, &fixed, opts.link_m)?
            } else {
                vec![true; pos.len()]
            };
            &found
        }
    };
    if keep.len() != of_body.len() {
        return Err(InputError::new(
            "crater.keep",
            format!(
                "has {} entries for {} particles of body {body}",
                keep.len(),
                of_body.len()
            ),
        ));
    }
    let mut kept = Vec::with_capacity(pos.len());
    let mut max_eps = 0.0f64;
    for (k, &i) in of_body.iter().enumerate() {
        if keep[k] {
            kept.push(pos[k]);
            max_eps = max_eps.max(particles.eps_p[i]);
        }
    }
    let c = crater(&kept, surface_y_m, opts)?;
    let s = CraterSample {
        t_s,
        mass_loss_kg_m,
        crater_depth_m: c.depth_m,
        crater_width_m: c.width_m,
        max_plastic_strain: max_eps,
    };
    Ok((s, c))
}

/// Which of `positions` hang together with a particle marked in `anchored`, through a chain of
/// particles each closer than `link_m` to the next: the rest are fragments cut loose from the
/// target (they still fly, and count as target, until deleted). A breadth-first search over a
/// grid of cells `link_m` wide.
pub fn attached(
    positions: &[Vector],
    anchored: &[bool],
    link_m: f64,
) -> Result<Vec<bool>, InputError> {
    InputError::require_positive("crater.link_m", link_m)?;
    if anchored.len() != positions.len() {
        return Err(InputError::new(
            "crater.anchored",
            format!(
                "has {} entries for {} positions",
                anchored.len(),
                positions.len()
            ),
        ));
    }
    let cell = |p: &Vector| ((p.x / link_m).floor() as i64, (p.y / link_m).floor() as i64);
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    for (i, p) in positions.iter().enumerate() {
        grid.entry(cell(p)).or_default().push(i);
    }
    let mut joined = anchored.to_vec();
    let mut queue: std::collections::VecDeque<usize> =
        (0..positions.len()).filter(|&i| anchored[i]).collect();
    let link2 = link_m * link_m;
    while let Some(i) = queue.pop_front() {
        let (cx, cy) = cell(&positions[i]);
        for dy in -1..=1 {
            for dx in -1..=1 {
                for &j in grid.get(&(cx + dx, cy + dy)).into_iter().flatten() {
                    if !joined[j] && (positions[j] - positions[i]).norm_squared() < link2 {
                        joined[j] = true;
                        queue.push_back(j);
                    }
                }
            }
        }
    }
    Ok(joined)
}

/// The topmost particle of each `bin_m`-wide column, columns centred on x_min + k·bin_m (so a
/// lattice of that spacing puts one particle column in each); empty columns are skipped.
pub fn surface_profile(positions: &[Vector], bin_m: f64) -> Result<Vec<Vector>, InputError> {
    InputError::require_positive("crater.bin_m", bin_m)?;
    if let Some(i) = positions
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(InputError::new(
            format!("crater.positions[{i}]"),
            "must be finite",
        ));
    }
    let Some(x_min) = positions.iter().map(|p| p.x).reduce(f64::min) else {
        return Ok(Vec::new());
    };
    let mut columns: std::collections::BTreeMap<u64, Vector> = Default::default();
    for p in positions {
        let k = ((p.x - x_min) / bin_m + 0.5).floor() as u64;
        let top = columns.entry(k).or_insert(*p);
        // Ties in height go to the smaller x, so the result does not depend on input order.
        if p.y > top.y || (p.y == top.y && p.x < top.x) {
            *top = *p;
        }
    }
    Ok(columns.into_values().collect())
}

/// Cd, Cw and the half-depth width of the target whose particles are at `positions`, against
/// the original surface line y = `surface_y_m` (docs/jet.md#crater-metrics).
pub fn crater(
    positions: &[Vector],
    surface_y_m: f64,
    opts: CraterOptions,
) -> Result<Crater, InputError> {
    if !surface_y_m.is_finite() {
        return Err(InputError::new("crater.surface_y_m", "must be finite"));
    }
    if !(opts.depth_tol_m.is_finite() && opts.depth_tol_m >= 0.0) {
        return Err(InputError::new(
            "crater.depth_tol_m",
            format!("must be a finite number >= 0, got {}", opts.depth_tol_m),
        ));
    }
    let profile = surface_profile(positions, opts.bin_m)?;
    if profile.is_empty() {
        return Err(InputError::new(
            "crater.positions",
            "must hold at least one particle",
        ));
    }
    let depth = |p: &Vector| surface_y_m - p.y;
    let mut deepest = 0;
    for (k, p) in profile.iter().enumerate() {
        if depth(p) > depth(&profile[deepest]) {
            deepest = k;
        }
    }
    let cd = depth(&profile[deepest]).max(0.0);
    let mut out = Crater {
        depth_m: cd,
        width_m: 0.0,
        half_depth_width_m: 0.0,
        edges_m: (profile[deepest].x, profile[deepest].x),
        deepest_x_m: profile[deepest].x,
        open: false,
        profile: Vec::new(),
    };
    if cd > opts.depth_tol_m {
        let (l, r, open) = span(&profile, deepest, surface_y_m - opts.depth_tol_m);
        out.width_m = r - l;
        out.edges_m = (l, r);
        out.open = open;
        let (l, r, _) = span(&profile, deepest, surface_y_m - 0.5 * cd);
        out.half_depth_width_m = r - l;
    }
    out.profile = profile;
    Ok(out)
}

/// The x-interval around column `from` where the profile lies below `level`, its ends
/// interpolated linearly between the last column below and the first at or above; `true` when
/// an end of the profile is reached first.
fn span(profile: &[Vector], from: usize, level: f64) -> (f64, f64, bool) {
    let crossing = |inside: Vector, outside: Vector| {
        let f = (level - inside.y) / (outside.y - inside.y);
        inside.x + f * (outside.x - inside.x)
    };
    let mut open = false;
    let mut k = from;
    while k > 0 && profile[k - 1].y < level {
        k -= 1;
    }
    let left = if k == 0 {
        open = true;
        profile[0].x
    } else {
        crossing(profile[k], profile[k - 1])
    };
    let mut k = from;
    while k + 1 < profile.len() && profile[k + 1].y < level {
        k += 1;
    }
    let right = if k + 1 == profile.len() {
        open = true;
        profile[k].x
    } else {
        crossing(profile[k], profile[k + 1])
    };
    (left, right, open)
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: f64 = 1e-5;

    /// A target block of spacing S from x = −L to L, 40 rows deep, whose surface depth at x is
    /// `d(x)` below y = 0 (columns filled from the bottom up to the surface).
    fn block(half_width_cols: i32, d: impl Fn(f64) -> f64) -> Vec<Vector> {
        let mut pts = Vec::new();
        for i in -half_width_cols..=half_width_cols {
            let x = i as f64 * S;
            let top = -d(x);
            let mut y = -40.0 * S;
            while y < top - 1e-12 {
                pts.push(Vector::new(x, y));
                y += S;
            }
            pts.push(Vector::new(x, top));
        }
        pts
    }

    #[test]
    fn v_crater() {
        // Depth D = 20 S at x = 0, top width W = 40 S: Cw at tol is W (1 − tol/D); half-depth width
        // W/2.
        let (d, w) = (20.0 * S, 40.0 * S);
        let pts = block(100, |x| (d * (1.0 - 2.0 * x.abs() / w)).max(0.0));
        let c = crater(&pts, 0.0, CraterOptions::for_spacing(S)).unwrap();
        assert!((c.depth_m - d).abs() < 1e-12);
        assert!(c.deepest_x_m.abs() < 1e-12);
        let expect = w * (1.0 - 0.5 * S / d);
        assert!(
            (c.width_m / expect - 1.0).abs() < 1e-9,
            "{} vs {expect}",
            c.width_m
        );
        assert!((c.half_depth_width_m / (0.5 * w) - 1.0).abs() < 1e-9);
        assert!(!c.open);
        assert_eq!(c.profile.len(), 201);
    }

    #[test]
    fn u_crater_with_lips_and_roughness() {
        // Flat bottom D = 10 S over |x| ≤ 20 S, walls down from |x| = 24 S; lips 2 S high beside
        // them and a rough surface (± 0.3 S < tol) elsewhere must not count.
        let (d, a, b) = (10.0 * S, 20.0 * S, 24.0 * S);
        let pts = block(100, |x| {
            let ax = x.abs();
            if ax <= a {
                d
            } else if ax <= b {
                d * (b - ax) / (b - a)
            } else if ax <= b + 3.0 * S {
                -2.0 * S
            } else {
                0.3 * S * ((x / S).round() as i64 % 2) as f64
            }
        });
        let c = crater(&pts, 0.0, CraterOptions::for_spacing(S)).unwrap();
        assert!((c.depth_m - d).abs() < 1e-12);
        let expect = 2.0 * (b - (b - a) * 0.5 * S / d);
        assert!(
            (c.width_m / expect - 1.0).abs() < 1e-9,
            "{} vs {expect}",
            c.width_m
        );
        // Half depth: 2 (b − (b − a)/2) = a + b.
        assert!((c.half_depth_width_m / (a + b) - 1.0).abs() < 1e-9);
        // A U is wider at half depth, relative to its width, than a V.
        assert!(c.half_depth_width_m / c.width_m > 0.8);
        assert!(
            (c.deepest_x_m + a).abs() < 1e-12,
            "first deepest column from the left"
        );
    }

    #[test]
    fn off_centre_asymmetric_crater_and_order_independence() {
        let pts = block(60, |x| {
            let u = (x - 15.0 * S) / S;
            if (-10.0..=0.0).contains(&u) {
                8.0 * S * (1.0 + u / 10.0)
            } else if (0.0..=4.0).contains(&u) {
                8.0 * S * (1.0 - u / 4.0)
            } else {
                0.0
            }
        });
        let c = crater(&pts, 0.0, CraterOptions::for_spacing(S)).unwrap();
        assert!((c.depth_m - 8.0 * S).abs() < 1e-12);
        assert!((c.deepest_x_m - 15.0 * S).abs() < 1e-12);
        let tol = 0.5 / 8.0;
        let (l, r) = c.edges_m;
        assert!((l - (15.0 - 10.0 * (1.0 - tol)) * S).abs() < 1e-12);
        assert!((r - (15.0 + 4.0 * (1.0 - tol)) * S).abs() < 1e-12);
        let mut rev = pts.clone();
        rev.reverse();
        assert_eq!(crater(&rev, 0.0, CraterOptions::for_spacing(S)).unwrap(), c);
    }

    #[test]
    fn flat_and_raised_surfaces_have_no_crater() {
        let flat = block(20, |_| 0.0);
        let c = crater(&flat, 0.0, CraterOptions::for_spacing(S)).unwrap();
        assert_eq!(
            (c.depth_m, c.width_m, c.half_depth_width_m),
            (0.0, 0.0, 0.0)
        );
        let shallow = block(20, |x| if x.abs() < 5.0 * S { 0.4 * S } else { 0.0 });
        let c = crater(&shallow, 0.0, CraterOptions::for_spacing(S)).unwrap();
        assert!((c.depth_m - 0.4 * S).abs() < 1e-15);
        assert_eq!(
            c.width_m, 0.0,
            "within the tolerance: roughness, not a crater"
        );
        let raised = block(20, |_| -3.0 * S);
        assert_eq!(
            crater(&raised, 0.0, CraterOptions::for_spacing(S))
                .unwrap()
                .depth_m,
            0.0
        );
    }

    #[test]
    fn crater_reaching_the_profile_end_is_open() {
        let pts = block(10, |x| 5.0 * S * (1.0 - x.abs() / (20.0 * S)));
        let c = crater(&pts, 0.0, CraterOptions::for_spacing(S)).unwrap();
        assert!(c.open);
        assert!((c.width_m - 20.0 * S).abs() < 1e-12);
    }

    #[test]
    fn sample_reads_only_the_target_body() {
        let target = block(30, |x| (5.0 * S * (1.0 - x.abs() / (10.0 * S))).max(0.0));
        let mut p = Particles::default();
        for (k, &x) in target.iter().enumerate() {
            p.pos.push(x);
            p.body.push(1);
            p.eps_p.push(if k == 7 { 0.25 } else { 0.01 });
        }
        // A grain above the surface, with a larger strain, belongs to another body.
        p.pos.push(Vector::new(0.0, 3.0 * S));
        p.body.push(0);
        p.eps_p.push(9.0);
        let (s, c) = sample(
            1e-3,
            &p,
            1,
            2.5e-6,
            0.0,
            CraterOptions::for_spacing(S),
            None,
        )
        .unwrap();
        assert_eq!(c.depth_m, s.crater_depth_m);
        assert!((s.crater_depth_m - 5.0 * S).abs() < 1e-15);
        assert!((s.crater_width_m - 20.0 * S * (1.0 - 0.1)).abs() < 1e-12);
        assert_eq!(
            (s.t_s, s.mass_loss_kg_m, s.max_plastic_strain),
            (1e-3, 2.5e-6, 0.25)
        );
        let json = serde_json::to_string(&s).unwrap();
        for key in CraterSample::FIELDS {
            assert!(json.contains(key), "{json}");
        }
        assert_eq!(
            sample(0.0, &p, 7, 0.0, 0.0, CraterOptions::for_spacing(S), None)
                .unwrap_err()
                .field,
            "crater.positions"
        );
    }

    #[test]
    fn fragments_cut_loose_are_left_out() {
        // A V crater in a block fixed along its bottom row, a fragment flying above the
        // crater's deepest point, and a chain hanging on the surface by diagonal links.
        let mut p = Particles::default();
        for x in block(30, |x| (5.0 * S * (1.0 - x.abs() / (10.0 * S))).max(0.0)) {
            p.pos.push(x);
            p.body.push(1);
            p.eps_p.push(0.1);
            p.flags.push(if x.y < -9.0 * S { KINEMATIC } else { 0 });
        }
        let deepest = -5.0 * S;
        let fragment = Vector::new(0.0, deepest + 3.0 * S);
        for x in [fragment, Vector::new(-0.2 * S, deepest + 3.5 * S)] {
            p.pos.push(x);
            p.body.push(1);
            p.eps_p.push(7.0);
            p.flags.push(0);
        }
        let (s, _) = sample(0.0, &p, 1, 0.0, 0.0, CraterOptions::for_spacing(S), None).unwrap();
        assert!(
            (s.crater_depth_m - 5.0 * S).abs() < 1e-12,
            "{}",
            s.crater_depth_m
        );
        assert_eq!(s.max_plastic_strain, 0.1);
        // Diagonal neighbours (1.41 S) link; a particle 2 S from all others does not.
        let chain = [Vector::zeros(), Vector::new(S, S), Vector::new(3.0 * S, S)];
        let joined = attached(&chain, &[true, false, false], 1.5 * S).unwrap();
        assert_eq!(joined, vec![true, true, false]);
        assert_eq!(
            attached(&chain, &[true], S).unwrap_err().field,
            "crater.anchored"
        );
    }

    #[test]
    fn bad_input_names_the_field() {
        let pts = block(5, |_| 0.0);
        let opts = CraterOptions::for_spacing(S);
        let bad = CraterOptions { bin_m: 0.0, ..opts };
        assert_eq!(crater(&pts, 0.0, bad).unwrap_err().field, "crater.bin_m");
        let bad = CraterOptions {
            depth_tol_m: -1.0,
            ..opts
        };
        assert_eq!(
            crater(&pts, 0.0, bad).unwrap_err().field,
            "crater.depth_tol_m"
        );
        assert_eq!(
            crater(&[], 0.0, opts).unwrap_err().field,
            "crater.positions"
        );
        assert_eq!(
            crater(&pts, f64::NAN, opts).unwrap_err().field,
            "crater.surface_y_m"
        );
        let mut nan = pts.clone();
        nan[3].y = f64::NAN;
        assert_eq!(
            crater(&nan, 0.0, opts).unwrap_err().field,
            "crater.positions[3]"
        );
    }
}
