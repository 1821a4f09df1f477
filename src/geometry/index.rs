//! A grid over segments, built once per shape, so that containment, distance and intersection
//! queries touch only the few segments near the query instead of all of them.
//!
//! About two cells per segment give O(1) segments per cell when the segments are spread out.
//! Detail crowded into a small part of the shape (a finely drawn bench on a large site) would
//! put many segments in one cell; such a cell gets a finer grid of its own, recursively, so a
//! query costs O(depth) cells of O(1) segments. Distances go through [`super::bvh`] instead.

use super::segment::{self, Point};
use std::collections::BTreeMap;

/// Cells are at most this many along an axis, which bounds memory for degenerate inputs.
const MAX_CELLS_PER_AXIS: usize = 2048;

/// A cell with more segments than this gets a finer grid...
const CROWDED: usize = 32;

/// ...down to this many levels below the top grid.
const MAX_DEPTH: u32 = 4;

#[derive(Debug, Clone)]
pub struct EdgeGrid {
    segs: Vec<[Point; 2]>,
    origin: Point,
    cell: f64,
    nx: usize,
    ny: usize,
    /// Compressed rows: the segments of cell `c` are `items[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
    /// Finer grids over the segments of crowded cells, by cell index.
    subs: BTreeMap<usize, SubGrid>,
}

/// The finer grid of a crowded cell, over that cell's segments.
#[derive(Debug, Clone)]
pub struct SubGrid {
    pub grid: EdgeGrid,
    /// The parent grid's index of each of `grid`'s segments.
    pub map: Vec<u32>,
}

impl EdgeGrid {
    /// Segments must have finite coordinates.
    pub fn new(segs: Vec<[Point; 2]>) -> EdgeGrid {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in segs.iter().flatten() {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if segs.is_empty() {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
        let scale = w.max(h).max(lo[0].abs()).max(lo[1].abs()).max(1e-300);
        // Padding keeps every segment strictly inside the grid, so a point outside the grid is
        // outside every ring and the row walks of `Locator` start from an empty region.
        let pad = 1e-6 * scale;
        let origin = [lo[0] - pad, lo[1] - pad];
        EdgeGrid::build(segs, origin, [w + 2.0 * pad, h + 2.0 * pad], 0)
    }

    /// A grid over the box `[origin, origin + size]`.
    fn build(segs: Vec<[Point; 2]>, origin: Point, size: Point, depth: u32) -> EdgeGrid {
        let [w, h] = size;
        let target = (2 * segs.len()).max(1) as f64;
        let cell = (w * h / target)
            .sqrt()
            .max(w.max(h) / MAX_CELLS_PER_AXIS as f64);
        let nx = ((w / cell).ceil() as usize).clamp(1, MAX_CELLS_PER_AXIS);
        let ny = ((h / cell).ceil() as usize).clamp(1, MAX_CELLS_PER_AXIS);
        let mut grid = EdgeGrid {
            segs,
            origin,
            cell,
            nx,
            ny,
            start: Vec::new(),
            items: Vec::new(),
            subs: BTreeMap::new(),
        };
        grid.fill_cells();
        if depth < MAX_DEPTH {
            grid.refine_crowded(depth);
        }
        grid
    }

    fn fill_cells(&mut self) {
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        // Generous reach: a point rounded into a neighbouring cell still finds its segments.
        let reach = 0.5 * self.cell * std::f64::consts::SQRT_2 * 1.01;
        for (s, &[a, b]) in self.segs.iter().enumerate() {
            let (i0, j0) = self.cell_of([a[0].min(b[0]), a[1].min(b[1])]);
            let (i1, j1) = self.cell_of([a[0].max(b[0]), a[1].max(b[1])]);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    if segment::distance(a, b, self.centre(i, j)) <= reach {
                        pairs.push(((j * self.nx + i) as u32, s as u32));
                    }
                }
            }
        }
        pairs.sort_unstable();
        let ncell = self.nx * self.ny;
        self.start = vec![0; ncell + 1];
        for &(c, _) in &pairs {
            self.start[c as usize + 1] += 1;
        }
        for c in 0..ncell {
            self.start[c + 1] += self.start[c];
        }
        self.items = pairs.into_iter().map(|(_, s)| s).collect();
    }

    fn refine_crowded(&mut self, depth: u32) {
        for c in 0..self.nx * self.ny {
            let items = self.items_of(c);
            if items.len() <= CROWDED {
                continue;
            }
            let map: Vec<u32> = items.to_vec();
            let segs = map.iter().map(|&s| self.segs[s as usize]).collect();
            let (i, j) = (c % self.nx, c / self.nx);
            let corner = [
                self.origin[0] + i as f64 * self.cell,
                self.origin[1] + j as f64 * self.cell,
            ];
            let grid = EdgeGrid::build(segs, corner, [self.cell, self.cell], depth + 1);
            // Segments through one point crowd every finer cell too: then there is no gain.
            let busiest = (0..grid.nx * grid.ny)
                .map(|k| grid.items_of(k).len())
                .max()
                .unwrap_or(0);
            if busiest < map.len() {
                self.subs.insert(c, SubGrid { grid, map });
            }
        }
    }

    fn items_of(&self, c: usize) -> &[u32] {
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }

    pub fn segments(&self) -> &[[Point; 2]] {
        &self.segs
    }

    pub fn dims(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Cell of `p`, clamped to the grid.
    pub fn cell_of(&self, p: Point) -> (usize, usize) {
        let (i, j) = self.raw_cell(p);
        (
            i.clamp(0, self.nx as i64 - 1) as usize,
            j.clamp(0, self.ny as i64 - 1) as usize,
        )
    }

    fn raw_cell(&self, p: Point) -> (i64, i64) {
        let f = |x: f64, o: f64| {
            let c = ((x - o) / self.cell).floor();
            // Saturating conversion keeps far-away points finite in index space.
            c.clamp(-1e15, 1e15) as i64
        };
        (f(p[0], self.origin[0]), f(p[1], self.origin[1]))
    }

    pub fn inside_grid(&self, p: Point) -> bool {
        let (i, j) = self.raw_cell(p);
        i >= 0 && j >= 0 && (i as usize) < self.nx && (j as usize) < self.ny
    }

    pub fn centre(&self, i: usize, j: usize) -> Point {
        [
            self.origin[0] + (i as f64 + 0.5) * self.cell,
            self.origin[1] + (j as f64 + 0.5) * self.cell,
        ]
    }

    pub fn cell_size(&self) -> f64 {
        self.cell
    }

    pub fn origin(&self) -> Point {
        self.origin
    }

    /// Indices of the segments that may meet cell `(i, j)`.
    pub fn cell_items(&self, i: usize, j: usize) -> &[u32] {
        self.items_of(j * self.nx + i)
    }

    /// The finer grid of cell `(i, j)`, if it is crowded.
    pub fn sub(&self, i: usize, j: usize) -> Option<&SubGrid> {
        self.subs.get(&(j * self.nx + i))
    }

    /// Pairs `(s, t)`, `s < t`, of segments sharing a cell, sorted: every pair of segments that
    /// meet is among them.
    pub fn candidate_pairs(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for c in 0..self.nx * self.ny {
            if let Some(sub) = self.subs.get(&c) {
                for (s, t) in sub.grid.candidate_pairs() {
                    let (s, t) = (sub.map[s] as usize, sub.map[t] as usize);
                    out.push((s.min(t), s.max(t)));
                }
                continue;
            }
            let items = self.items_of(c);
            for (k, &s) in items.iter().enumerate() {
                for &t in &items[k + 1..] {
                    out.push((s.min(t) as usize, s.max(t) as usize));
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Indices of segments whose cells overlap the box `[lo, hi]`, sorted, each once: every
    /// segment meeting the box is among them.
    pub fn near_box(&self, lo: Point, hi: Point) -> Vec<usize> {
        let (i0, j0) = self.cell_of(lo);
        let (i1, j1) = self.cell_of(hi);
        let mut out: Vec<usize> = Vec::new();
        for j in j0..=j1 {
            for i in i0..=i1 {
                match self.sub(i, j) {
                    Some(sub) => out.extend(
                        sub.grid
                            .near_box(lo, hi)
                            .into_iter()
                            .map(|s| sub.map[s] as usize),
                    ),
                    None => out.extend(self.cell_items(i, j).iter().map(|&s| s as usize)),
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}
