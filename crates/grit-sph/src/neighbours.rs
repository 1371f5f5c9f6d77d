//! Cell-list neighbour search with a Verlet skin: lists hold every pair within
//! support radius + skin and are reused until some particle has moved half the skin.

use rayon::prelude::*;

use crate::math::Vector;

/// Neighbour lists in compressed rows: the neighbours of `i` are `list[start[i]..start[i+1]]`,
/// in increasing index order, so every sum over them runs in one fixed order.
#[derive(Debug, Clone, Default)]
pub struct NeighbourLists {
    /// Row starts, length n + 1.
    pub start: Vec<u32>,
    /// Neighbour indices.
    pub list: Vec<u32>,
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

/// Builds neighbour lists with a cell list of cell size `radius`.
///
/// `searcher[i]` says whether `i` gets a list; `candidate[j]` whether `j` can be listed;
/// `accept(i, j)` filters pairs further (bodies that never interact). Points farther than
/// `radius` are never listed. Cells are found by binary search in the sorted cell keys, so a
/// particle flying far away costs nothing in memory.
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
    let mut cells: Vec<((i64, i64), u32)> = (0..pos.len())
        .filter(|&j| candidate[j])
        .map(|j| (key(&pos[j]), j as u32))
        .collect();
    // Row-major by (y, x) then index: neighbours come out sorted by cell, then by index.
    cells.sort_unstable_by_key(|&((cx, cy), j)| (cy, cx, j));
    let r2 = radius * radius;
    let rows: Vec<Vec<u32>> = (0..pos.len())
        .into_par_iter()
        .map(|i| {
            if !searcher[i] {
                return Vec::new();
            }
            let (cx, cy) = key(&pos[i]);
            let mut out = Vec::new();
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let c = (cy + dy, cx + dx);
                    let lo = cells.partition_point(|&((x, y), _)| (y, x) < c);
                    for &((x, y), j) in &cells[lo..] {
                        if (y, x) != c {
                            break;
                        }
                        let j = j as usize;
                        if j != i && (pos[j] - pos[i]).norm_squared() <= r2 && accept(i, j) {
                            out.push(j as u32);
                        }
                    }
                }
            }
            out.sort_unstable();
            out
        })
        .collect();
    let mut start = Vec::with_capacity(pos.len() + 1);
    start.push(0u32);
    let mut list = Vec::with_capacity(rows.iter().map(Vec::len).sum());
    for r in rows {
        list.extend_from_slice(&r);
        start.push(list.len() as u32);
    }
    NeighbourLists { start, list }
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
    NeighbourLists { start, list }
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
