//! Cell-list neighbour search with a Verlet skin: lists hold every pair within
//! support radius + skin and are reused until some particle has moved half the skin. Also which
//! bodies' particles list each other, and which unordered pair each same-body entry is, so the
//! SPH sums of a step evaluate each pair once.

use rayon::prelude::*;

use crate::body::Body;
use crate::contact::ContactPair;
use crate::kernel::Kernel;
use crate::math::Vector;
use crate::particles::{Particles, BOUNDARY};
use crate::stages::rows_mut;

/// Neighbour lists in compressed rows: the neighbours of `i` are `list[start[i]..start[i+1]]`,
/// in increasing index order, so every sum over them runs in one fixed order.
#[derive(Debug, Clone, Default)]
pub struct NeighbourLists {
    /// Row starts, length n + 1.
    pub start: Vec<u32>,
    /// Neighbour indices.
    pub list: Vec<u32>,
    /// For each entry of `list`: whether the pair's reference positions lie closer than the
    /// kernel support, |X_i − X_j| < 3h, the pairs the hourglass stiffness of eq. 16 acts on. The
    /// reference positions only change with the particle set, which forces a rebuild, so the test
    /// is made once per build (by `build_for_bodies`; empty from `build`).
    pub near_ref: Vec<bool>,
}

impl NeighbourLists {
    /// Neighbours of particle `i`.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.list[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Number of stored pairs (each direction counted).
    pub fn pairs(&self) -> usize {
        self.list.len()
    }
}

/// The candidate points of a neighbour search grouped by cell: `members(c)` lists the points
/// of cell `c` in increasing index order.
enum Cells {
    /// A dense grid over the candidates' bounding box, filled by a counting sort in O(n).
    Grid {
        lo: (i64, i64),
        nx: i64,
        ny: i64,
        /// Start of each cell's members in `idx`, row-major by (y, x); length nx·ny + 1.
        start: Vec<u32>,
        idx: Vec<u32>,
    },
    /// The occupied cells' keys, sorted row-major by (y, x), with the members in the same order:
    /// for points spread so far apart (a fragment flung off) that a grid would be mostly empty.
    Sorted {
        keys: Vec<(i64, i64)>,
        idx: Vec<u32>,
    },
}

impl Cells {
    /// Groups the points `keys[k]` (cell of point `idx[k]`, indices increasing) by cell.
    fn new(keys: Vec<(i64, i64)>, idx: Vec<u32>) -> Cells {
        let Some(&first) = keys.first() else {
            return Cells::Sorted { keys, idx };
        };
        let (lo, hi) = keys.iter().fold((first, first), |(lo, hi), &(x, y)| {
            ((lo.0.min(x), lo.1.min(y)), (hi.0.max(x), hi.1.max(y)))
        });
        let nx = hi.0 as i128 - lo.0 as i128 + 1;
        let ny = hi.1 as i128 - lo.1 as i128 + 1;
        // A grid a few times the point count costs about as much to clear as to fill.
        if nx * ny > 4 * keys.len() as i128 + 64 {
            let mut order: Vec<usize> = (0..keys.len()).collect();
            order.sort_unstable_by_key(|&k| (keys[k].1, keys[k].0, idx[k]));
            return Cells::Sorted {
                keys: order.iter().map(|&k| keys[k]).collect(),
                idx: order.iter().map(|&k| idx[k]).collect(),
            };
        }
        let (nx, ny) = (nx as i64, ny as i64);
        let cell = |(x, y): (i64, i64)| ((y - lo.1) * nx + (x - lo.0)) as usize;
        let mut start = vec![0u32; (nx * ny) as usize + 1];
        for &c in &keys {
            start[cell(c) + 1] += 1;
        }
        for c in 1..start.len() {
            start[c] += start[c - 1];
        }
        // Scattered in index order, so each cell's members stay in increasing index order.
        let mut fill = start.clone();
        let mut sorted = vec![0u32; idx.len()];
        for (&c, &j) in keys.iter().zip(&idx) {
            let f = &mut fill[cell(c)];
            sorted[*f as usize] = j;
            *f += 1;
        }
        Cells::Grid {
            lo,
            nx,
            ny,
            start,
            idx: sorted,
        }
    }

    /// The points in cell `(x, y)`.
    fn members(&self, (x, y): (i64, i64)) -> &[u32] {
        match self {
            Cells::Grid {
                lo,
                nx,
                ny,
                start,
                idx,
            } => {
                let (gx, gy) = (x - lo.0, y - lo.1);
                if gx < 0 || gy < 0 || gx >= *nx || gy >= *ny {
                    return &[];
                }
                let c = (gy * nx + gx) as usize;
                &idx[start[c] as usize..start[c + 1] as usize]
            }
            Cells::Sorted { keys, idx } => {
                let a = keys.partition_point(|&(kx, ky)| (ky, kx) < (y, x));
                let b = a + keys[a..].partition_point(|&(kx, ky)| (ky, kx) <= (y, x));
                &idx[a..b]
            }
        }
    }
}

/// Rows one rayon task of the neighbour search takes at least, as the stages' smallest task;
/// without an upper bound (the stages' `par_tasks`) it ran faster here.
const ROWS_PER_TASK: usize = 64;
/// Entries a row is allocated with: above the 60 or so a dense lattice lists within the reach.
const ROW_CAPACITY: usize = 96;

/// Builds neighbour lists with a cell list of cell size `radius`.
///
/// `searcher[i]` says whether `i` gets a list; `candidate[j]` whether `j` can be listed;
/// `accept(i, j)` filters pairs further. Points farther than `radius` are never listed. The
/// candidates are grouped by cell with a counting sort over their bounding box, or, when a
/// point far off would make that grid mostly empty, by sorting the occupied cells, so a particle
/// flying far away costs nothing in memory.
pub fn build(
    pos: &[Vector],
    searcher: &[bool],
    candidate: &[bool],
    radius: f64,
    accept: impl Fn(usize, usize) -> bool + Sync,
) -> NeighbourLists {
    let inv = 1.0 / radius;
    let key =
        |p: &Vector| -> (i64, i64) { ((p.x * inv).floor() as i64, (p.y * inv).floor() as i64) };
    let idx: Vec<u32> = (0..pos.len())
        .filter(|&j| candidate[j])
        .map(|j| j as u32)
        .collect();
    let keys: Vec<(i64, i64)> = idx.iter().map(|&j| key(&pos[j as usize])).collect();
    let cells = Cells::new(keys, idx);
    let r2 = radius * radius;
    let rows: Vec<Vec<u32>> = (0..pos.len())
        .into_par_iter()
        .with_min_len(ROWS_PER_TASK)
        .map(|i| {
            if !searcher[i] {
                return Vec::new();
            }
            let (cx, cy) = key(&pos[i]);
            // Room for a dense lattice's row at once: growing it by doubling took most of the
            // search's time, and more with two threads, in the allocator.
            let mut out = Vec::with_capacity(ROW_CAPACITY);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    for &j in cells.members((cx + dx, cy + dy)) {
                        let j = j as usize;
                        if j != i && (pos[j] - pos[i]).norm_squared() <= r2 && accept(i, j) {
                            out.push(j as u32);
                        }
                    }
                }
            }
            // Cell by cell, then by index: sorted by index, every sum over a row runs in one
            // fixed order.
            out.sort_unstable();
            out
        })
        .collect();
    let mut start = Vec::with_capacity(pos.len() + 1);
    start.push(0u32);
    for r in &rows {
        start.push(start[start.len() - 1] + r.len() as u32);
    }
    // Copied into place in parallel, each row by its own task.
    let mut list = Vec::new();
    rows_mut(&mut list, &start)
        .into_par_iter()
        .zip(rows)
        .with_min_len(ROWS_PER_TASK)
        .for_each(|(dst, src)| dst.copy_from_slice(&src));
    NeighbourLists {
        start,
        list,
        near_ref: Vec::new(),
    }
}

/// The O(N²) reference search the cell list is tested against.
pub fn build_naive(
    pos: &[Vector],
    searcher: &[bool],
    candidate: &[bool],
    radius: f64,
    accept: impl Fn(usize, usize) -> bool,
) -> NeighbourLists {
    let mut start = vec![0u32];
    let mut list = Vec::new();
    for i in 0..pos.len() {
        if searcher[i] {
            for j in 0..pos.len() {
                if j != i
                    && candidate[j]
                    && (pos[j] - pos[i]).norm_squared() <= radius * radius
                    && accept(i, j)
                {
                    list.push(j as u32);
                }
            }
        }
        start.push(list.len() as u32);
    }
    NeighbourLists {
        start,
        list,
        near_ref: Vec::new(),
    }
}

/// The neighbour lists of a world: same-body rows for the SPH sums of the deformable bodies, and
/// for each contact pair the rows from its secondary particles to its primary's boundary
/// particles. Kept apart, so no loop over pairs has to sort them by body.
#[derive(Debug, Clone, Default)]
pub(crate) struct WorldLists {
    /// Same-body neighbours of every deformable particle (empty rows for rigid ones), with the
    /// reference-distance marks.
    pub same: NeighbourLists,
    /// The unordered pair of each entry of `same`.
    pub half: HalfIndex,
    /// For contact pair c, the primary boundary particles each secondary particle can touch.
    pub contact: Vec<ContactLists>,
    /// Fluid–solid pairs (docs/jet.md#water-on-the-target): each fluid particle lists the
    /// deformable particles within reach and each deformable particle the fluid ones, so both
    /// sides gather their pairs in their own row's order. Empty rows without a fluid and a solid.
    pub cross: NeighbourLists,
}

impl WorldLists {
    /// Number of stored pairs (each direction counted), same-body, contact and fluid–solid.
    pub fn pairs(&self) -> usize {
        self.same.pairs()
            + self.contact.iter().map(|c| c.rows.pairs()).sum::<usize>()
            + self.cross.pairs()
    }
}

/// The contact candidates of one contact pair: only the secondary particles near the primary
/// have any, so the rows are kept for those alone.
#[derive(Debug, Clone, Default)]
pub(crate) struct ContactLists {
    /// Secondary particles with at least one primary boundary particle within reach, in
    /// increasing index order.
    pub particles: Vec<u32>,
    /// Row k: the primary boundary particles within reach of `particles[k]`, in index order.
    pub rows: NeighbourLists,
    /// Whether the secondary particles without candidates still have to have their contact
    /// springs cleared, as a contact stage does for a particle it finds nothing for; needed
    /// once after each build, since only particles with candidates ever get a spring.
    pub sweep: bool,
}

/// Builds the lists of a world's particles with reach `radius`: deformable particles see their own
/// body; for each contact pair, the secondary's particles (only its boundary particles when it is
/// rigid) see the primary's boundary particles. Only secondary particles inside the bounding box
/// of those boundary particles, widened by twice the reach, can list one, so only they search. Each
/// same-body entry is marked with whether its reference positions lie within `support`.
pub(crate) fn build_for_bodies(
    p: &Particles,
    bodies: &[Body],
    contacts: &[ContactPair],
    radius: f64,
    support: f64,
) -> WorldLists {
    let n = p.len();
    let body = &p.body;
    let deformable: Vec<bool> = (0..n)
        .map(|i| !bodies[body[i] as usize].is_rigid())
        .collect();
    let mut same = build(&p.pos, &deformable, &deformable, radius, |i, j| {
        body[i] == body[j]
    });
    let mut near_ref = Vec::new();
    rows_mut(&mut near_ref, &same.start)
        .into_par_iter()
        .with_min_len(ROWS_PER_TASK)
        .enumerate()
        .for_each(|(i, row)| {
            for (out, &j) in row.iter_mut().zip(same.of(i)) {
                *out = (p.x_ref[i] - p.x_ref[j as usize]).norm() < support;
            }
        });
    same.near_ref = near_ref;
    let half = HalfIndex::new(&same);
    let contact = contacts
        .iter()
        .map(|c| {
            let boundary_only = bodies[c.secondary].is_rigid();
            let candidate: Vec<bool> = (0..n)
                .map(|i| body[i] as usize == c.primary && p.flags[i] & BOUNDARY != 0)
                .collect();
            let inf = Vector::repeat(f64::INFINITY);
            let (lo, hi) = (0..n)
                .filter(|&j| candidate[j])
                .fold((inf, -inf), |(lo, hi), j| {
                    (lo.inf(&p.pos[j]), hi.sup(&p.pos[j]))
                });
            // Twice the reach: a margin no rounding of the distance test can cross.
            let (lo, hi) = (lo.add_scalar(-2.0 * radius), hi.add_scalar(2.0 * radius));
            let searcher: Vec<bool> = (0..n)
                .map(|i| {
                    let x = p.pos[i];
                    body[i] as usize == c.secondary
                        && (!boundary_only || p.flags[i] & BOUNDARY != 0)
                        && x.x >= lo.x
                        && x.y >= lo.y
                        && x.x <= hi.x
                        && x.y <= hi.y
                })
                .collect();
            let all = build(&p.pos, &searcher, &candidate, radius, |_, _| true);
            let particles: Vec<u32> = (0..n)
                .filter(|&i| !all.of(i).is_empty())
                .map(|i| i as u32)
                .collect();
            let mut start = Vec::with_capacity(particles.len() + 1);
            start.push(0);
            start.extend(particles.iter().map(|&i| all.start[i as usize + 1]));
            ContactLists {
                particles,
                rows: NeighbourLists {
                    start,
                    list: all.list,
                    near_ref: Vec::new(),
                },
                sweep: true,
            }
        })
        .collect();
    WorldLists {
        same,
        half,
        contact,
        cross: cross_lists(p, bodies, radius),
    }
}

/// The fluid–solid rows of [`WorldLists::cross`]: every pair of a fluid and a deformable
/// particle within `radius`, listed from both ends.
fn cross_lists(p: &Particles, bodies: &[Body], radius: f64) -> NeighbourLists {
    let n = p.len();
    let fluid: Vec<bool> = bodies.iter().map(|b| b.fluid().is_some()).collect();
    let solid: Vec<bool> = bodies.iter().map(|b| b.material().is_some()).collect();
    if !(fluid.iter().any(|&f| f) && solid.iter().any(|&s| s)) {
        return NeighbourLists {
            start: vec![0; n + 1],
            ..NeighbourLists::default()
        };
    }
    let body = &p.body;
    let either: Vec<bool> = (0..n)
        .map(|i| fluid[body[i] as usize] || solid[body[i] as usize])
        .collect();
    build(&p.pos, &either, &either, radius, |i, j| {
        let (bi, bj) = (body[i] as usize, body[j] as usize);
        (fluid[bi] && solid[bj]) || (solid[bi] && fluid[bj])
    })
}

/// The same-body pairs counted once each: pair (i, j) with i < j is kept in i's row, and both
/// entries of it, i's and j's, name it by one id. A sum over pairs then evaluates each pair once
/// and each particle gathers its pairs in its own row's order, so the sums keep a fixed order.
#[derive(Debug, Clone, Default)]
pub(crate) struct HalfIndex {
    /// The pairs (i, j) with j > i have ids `start[i]..start[i + 1]`, in the order of i's row.
    pub start: Vec<u32>,
    /// Where the entries j > i begin in `list` for row i: rows are sorted by index, so those
    /// entries close each row.
    pub upper: Vec<u32>,
    /// For each entry of the lists, the id of its pair.
    pub id: Vec<u32>,
}

impl HalfIndex {
    /// The index of same-body lists `nl`, which list j in i's row whenever they list i in j's
    /// (the distance test and the cells are symmetric).
    pub fn new(nl: &NeighbourLists) -> HalfIndex {
        let n = nl.start.len().saturating_sub(1);
        let upper: Vec<u32> = (0..n)
            .map(|i| nl.start[i] + nl.of(i).partition_point(|&j| (j as usize) < i) as u32)
            .collect();
        let mut start = Vec::with_capacity(n + 1);
        start.push(0u32);
        for i in 0..n {
            start.push(start[i] + (nl.start[i + 1] - upper[i]));
        }
        let id_of = |i: usize, k: usize| -> u32 {
            let j = nl.list[k] as usize;
            if j > i {
                return start[i] + (k as u32 - upper[i]);
            }
            let at = nl
                .of(j)
                .binary_search(&(i as u32))
                .expect("same-body lists are symmetric");
            start[j] + (nl.start[j] + at as u32 - upper[j])
        };
        let mut id = Vec::new();
        rows_mut(&mut id, &nl.start)
            .into_par_iter()
            .with_min_len(ROWS_PER_TASK)
            .enumerate()
            .for_each(|(i, row)| {
                let first = nl.start[i] as usize;
                for (k, out) in row.iter_mut().enumerate() {
                    *out = id_of(i, first + k);
                }
            });
        HalfIndex { start, upper, id }
    }

    /// The partners j > i of particle i, in row order: the pairs i holds, ids from `start[i]`.
    #[inline]
    pub fn upper_of<'a>(&self, nl: &'a NeighbourLists, i: usize) -> &'a [u32] {
        &nl.list[self.upper[i] as usize..nl.start[i + 1] as usize]
    }
}

/// Whether some particle has moved farther than `half_skin` from its position `x_build` at the
/// last build, so the lists may miss a pair.
pub(crate) fn stale(pos: &[Vector], x_build: &[Vector], half_skin: f64) -> bool {
    let lim = half_skin * half_skin;
    pos.par_iter()
        .zip(x_build)
        .any(|(x, x0)| (x - x0).norm_squared() > lim)
}

/// A neighbour j of particle i in i's own body inside the kernel support, with
/// x_ij = x_i − x_j and W_ij.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Pair {
    /// Index of the neighbour, 32 bits like the lists.
    pub j: u32,
    pub xij: Vector,
    pub w: f64,
}

/// The neighbours of `i` in the same-body lists `nl` with their kernel values, in the lists'
/// fixed order: the loop of the density filter (eq. 12), which runs after the particles have
/// moved, so the step's pair cache no longer holds its pairs.
pub(crate) fn body_pairs<'a>(
    p: &'a Particles,
    nl: &'a NeighbourLists,
    k: &'a Kernel,
    i: usize,
) -> impl Iterator<Item = Pair> + 'a {
    let xi = p.pos[i];
    let r2max = k.radius() * k.radius();
    nl.of(i).iter().filter_map(move |&j| {
        let xij = xi - p.pos[j as usize];
        let r2 = xij.norm_squared();
        // The lists reach a skin beyond the support; those pairs would add exact zeros.
        if r2 >= r2max {
            return None;
        }
        let w = k.w(r2.sqrt());
        Some(Pair { j, xij, w })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn cell_list_equals_naive_search(
            pts in prop::collection::vec((-5.0f64..5.0, -5.0f64..5.0), 1..300),
            radius in 0.05f64..2.0,
            mask in prop::collection::vec(any::<(bool, bool)>(), 300),
        ) {
            let pos: Vec<Vector> = pts.iter().map(|&(x, y)| Vector::new(x, y)).collect();
            let searcher: Vec<bool> = (0..pos.len()).map(|i| mask[i].0 || i % 3 == 0).collect();
            let candidate: Vec<bool> = (0..pos.len()).map(|i| mask[i].1 || i % 2 == 0).collect();
            let accept = |i: usize, j: usize| !(i + j).is_multiple_of(7);
            let a = build(&pos, &searcher, &candidate, radius, accept);
            let b = build_naive(&pos, &searcher, &candidate, radius, accept);
            prop_assert_eq!(a.start, b.start);
            prop_assert_eq!(a.list, b.list);
        }
    }

    #[test]
    fn far_flung_point_takes_the_sorted_cells_and_lists_the_same() {
        let mut pos: Vec<Vector> = (0..200)
            .map(|k| Vector::new((k % 20) as f64 * 0.3, (k / 20) as f64 * 0.3))
            .collect();
        pos.push(Vector::new(1e12, -1e12));
        pos.push(Vector::new(1e12 + 0.2, -1e12));
        let all = vec![true; pos.len()];
        let a = build(&pos, &all, &all, 0.7, |_, _| true);
        let b = build_naive(&pos, &all, &all, 0.7, |_, _| true);
        assert_eq!(a.start, b.start);
        assert_eq!(a.list, b.list);
    }

    #[test]
    fn half_index_names_each_pair_once_from_both_ends() {
        let pos: Vec<Vector> = (0..150)
            .map(|k| {
                Vector::new(
                    (k % 15) as f64 * 0.5 + 0.01 * (k % 7) as f64,
                    (k / 15) as f64 * 0.5,
                )
            })
            .collect();
        let all = vec![true; pos.len()];
        let nl = build(&pos, &all, &all, 1.3, |i, j| (i + j) % 5 != 0);
        let half = HalfIndex::new(&nl);
        let pairs = *half.start.last().unwrap() as usize;
        assert_eq!(2 * pairs, nl.pairs());
        let mut ends = vec![Vec::new(); pairs];
        for i in 0..pos.len() {
            for (k, &j) in nl.of(i).iter().enumerate() {
                ends[half.id[nl.start[i] as usize + k] as usize].push((i, j as usize));
            }
            for (t, &j) in half.upper_of(&nl, i).iter().enumerate() {
                assert!(j as usize > i);
                assert!(ends[half.start[i] as usize + t].contains(&(i, j as usize)));
            }
        }
        for e in ends {
            assert_eq!(e.len(), 2);
            assert_eq!((e[0].0, e[0].1), (e[1].1, e[1].0));
        }
    }

    #[test]
    fn dense_lattice_has_expected_neighbour_count() {
        let dx = 1.0;
        let mut pos = Vec::new();
        for j in 0..30 {
            for i in 0..30 {
                pos.push(Vector::new(i as f64 * dx, j as f64 * dx));
            }
        }
        let all = vec![true; pos.len()];
        let nl = build(&pos, &all, &all, 3.9 * dx, |_, _| true);
        // Interior point: lattice points within radius 3.9 minus itself.
        let centre = 15 * 30 + 15;
        let expected = (-4i32..=4)
            .flat_map(|a| (-4i32..=4).map(move |b| (a, b)))
            .filter(|&(a, b)| (a * a + b * b) as f64 <= 3.9 * 3.9 && (a, b) != (0, 0))
            .count();
        assert_eq!(nl.of(centre).len(), expected);
    }
}
