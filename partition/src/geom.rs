//! Pure 2D geometry used by the halo search: bounding boxes, a uniform cell grid and a cell list.

use std::collections::HashMap;

/// Axis-aligned box; empty when `min > max` on an axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BBox {
    pub min: [f64; 2],
    pub max: [f64; 2],
}

impl BBox {
    pub fn empty() -> Self {
        Self {
            min: [f64::INFINITY; 2],
            max: [f64::NEG_INFINITY; 2],
        }
    }

    pub fn of(points: &[[f64; 2]]) -> Self {
        let mut b = Self::empty();
        for p in points {
            b.include(*p);
        }
        b
    }

    pub fn include(&mut self, p: [f64; 2]) {
        for ((lo, hi), v) in self.min.iter_mut().zip(&mut self.max).zip(p) {
            *lo = lo.min(v);
            *hi = hi.max(v);
        }
    }

    pub fn union(&self, other: &Self) -> Self {
        Self {
            min: [self.min[0].min(other.min[0]), self.min[1].min(other.min[1])],
            max: [self.max[0].max(other.max[0]), self.max[1].max(other.max[1])],
        }
    }

    pub fn is_empty(&self) -> bool {
        !(self.min[0] <= self.max[0] && self.min[1] <= self.max[1])
    }

    /// Squared gap between two boxes (0 when they touch or overlap, +inf when either is empty).
    /// Symmetric by construction, so two ranks testing each other reach the same verdict.
    pub fn gap2(&self, other: &Self) -> f64 {
        if self.is_empty() || other.is_empty() {
            return f64::INFINITY;
        }
        let mut d2 = 0.0;
        for a in 0..2 {
            let g = (self.min[a] - other.max[a])
                .max(other.min[a] - self.max[a])
                .max(0.0);
            d2 += g * g;
        }
        d2
    }

    /// Largest absolute coordinate in the box (0 for an empty box).
    pub fn max_abs(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        self.min
            .iter()
            .chain(&self.max)
            .fold(0.0f64, |m, v| m.max(v.abs()))
    }
}

/// Squared distance between two points.
pub(crate) fn dist2(p: [f64; 2], q: [f64; 2]) -> f64 {
    let dx = p[0] - q[0];
    let dy = p[1] - q[1];
    dx * dx + dy * dy
}

/// Integer cell coordinates.
pub(crate) type Cell = (i64, i64);

/// Uniform grid of square cells anchored at `origin`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Grid {
    pub origin: [f64; 2],
    pub h: f64,
}

/// Cell indices are kept far below 2^53 so that cell arithmetic stays exact in f64.
pub(crate) const MAX_CELL_INDEX: f64 = (1u64 << 50) as f64;

impl Grid {
    pub fn cell_of(&self, p: [f64; 2]) -> Cell {
        (
            ((p[0] - self.origin[0]) / self.h).floor() as i64,
            ((p[1] - self.origin[1]) / self.h).floor() as i64,
        )
    }

    pub fn cell_box(&self, c: Cell) -> BBox {
        let x0 = self.origin[0] + c.0 as f64 * self.h;
        let y0 = self.origin[1] + c.1 as f64 * self.h;
        BBox {
            min: [x0, y0],
            max: [x0 + self.h, y0 + self.h],
        }
    }
}

/// Points binned by grid cell: a cell list answering "which points lie in the 3x3 block of
/// cells around this one" in O(1) per cell.
#[derive(Debug)]
pub(crate) struct Bins {
    /// Point indices sorted by cell.
    order: Vec<usize>,
    /// Per occupied cell (in sorted cell order): its key and range in `order`.
    runs: Vec<(Cell, usize, usize)>,
    lookup: HashMap<Cell, usize>,
}

impl Bins {
    pub fn new(grid: &Grid, points: &[[f64; 2]]) -> Self {
        let keys: Vec<Cell> = points.iter().map(|&p| grid.cell_of(p)).collect();
        let mut order: Vec<usize> = (0..points.len()).collect();
        order.sort_unstable_by_key(|&i| (keys[i], i));
        let mut runs = Vec::new();
        let mut start = 0;
        while start < order.len() {
            let key = keys[order[start]];
            let mut end = start + 1;
            while end < order.len() && keys[order[end]] == key {
                end += 1;
            }
            runs.push((key, start, end));
            start = end;
        }
        let lookup = runs
            .iter()
            .enumerate()
            .map(|(id, &(key, _, _))| (key, id))
            .collect();
        Self {
            order,
            runs,
            lookup,
        }
    }

    pub fn n_cells(&self) -> usize {
        self.runs.len()
    }

    /// Occupied cells with their member point indices, in cell order.
    pub fn cells(&self) -> impl Iterator<Item = (Cell, &[usize])> + '_ {
        self.runs
            .iter()
            .map(move |&(key, a, b)| (key, &self.order[a..b]))
    }

    /// Cell id and members of an occupied cell.
    pub fn get(&self, c: Cell) -> Option<(usize, &[usize])> {
        self.lookup.get(&c).map(|&id| {
            let (_, a, b) = self.runs[id];
            (id, &self.order[a..b])
        })
    }

    /// Whether any binned point lies within squared distance `r2` of `p`. Exact when the grid
    /// spacing is at least sqrt(r2).
    pub fn any_within(&self, grid: &Grid, points: &[[f64; 2]], p: [f64; 2], r2: f64) -> bool {
        let (ci, cj) = grid.cell_of(p);
        for di in -1..=1 {
            for dj in -1..=1 {
                if let Some((_, members)) = self.get((ci + di, cj + dj)) {
                    if members.iter().any(|&q| dist2(p, points[q]) <= r2) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_box_is_far_from_everything() {
        let e = BBox::empty();
        assert!(e.is_empty());
        let b = BBox::of(&[[0.0, 0.0], [1.0, 1.0]]);
        assert!(!b.is_empty());
        assert_eq!(e.gap2(&b), f64::INFINITY);
        assert_eq!(b.gap2(&e), f64::INFINITY);
        assert_eq!(e.max_abs(), 0.0);
    }

    #[test]
    fn box_gap_is_symmetric_and_correct() {
        let a = BBox::of(&[[0.0, 0.0], [1.0, 1.0]]);
        let b = BBox::of(&[[4.0, 5.0], [6.0, 7.0]]);
        assert_eq!(a.gap2(&b), 9.0 + 16.0);
        assert_eq!(b.gap2(&a), a.gap2(&b));
        let c = BBox::of(&[[0.5, -3.0], [0.7, 3.0]]);
        assert_eq!(a.gap2(&c), 0.0);
        assert_eq!(a.union(&b), BBox::of(&[[0.0, 0.0], [6.0, 7.0]]));
        assert_eq!(b.max_abs(), 7.0);
    }

    #[test]
    fn cells_and_cell_boxes_agree() {
        let g = Grid {
            origin: [-1.0, 2.0],
            h: 0.5,
        };
        assert_eq!(g.cell_of([-1.0, 2.0]), (0, 0));
        assert_eq!(g.cell_of([-0.74, 2.6]), (0, 1));
        assert_eq!(g.cell_of([-1.1, 1.9]), (-1, -1));
        let b = g.cell_box((3, -2));
        assert_eq!(b.min, [0.5, 1.0]);
        assert_eq!(b.max, [1.0, 1.5]);
    }

    #[test]
    fn bins_match_brute_force() {
        // Deterministic pseudo-random points; a tiny LCG keeps the test dependency-free.
        let mut s = 12345u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let pts: Vec<[f64; 2]> = (0..400).map(|_| [next() * 3.0, next() * 2.0]).collect();
        let probes: Vec<[f64; 2]> = (0..200).map(|_| [next() * 3.5, next() * 2.5]).collect();
        let r = 0.17;
        let g = Grid {
            origin: [0.0, 0.0],
            h: r,
        };
        let bins = Bins::new(&g, &pts);
        let total: usize = bins.cells().map(|(_, m)| m.len()).sum();
        assert_eq!(total, pts.len());
        assert!(bins.n_cells() > 1);
        for &p in &probes {
            let brute = pts.iter().any(|&q| dist2(p, q) <= r * r);
            assert_eq!(bins.any_within(&g, &pts, p, r * r), brute);
        }
    }
}
