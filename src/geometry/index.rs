//! A uniform grid over segments, built once per shape, so that containment, distance and
//! intersection queries touch only the few segments near the query instead of all of them.
//! With about two cells per segment a query costs O(1) on average, whatever the vertex count.

use super::segment::{self, orient, Point};

/// Cells are at most this many along an axis, which bounds memory for degenerate inputs.
const MAX_CELLS_PER_AXIS: usize = 2048;

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
        let (w, h) = (w + 2.0 * pad, h + 2.0 * pad);
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
        };
        grid.fill_cells();
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
        let c = j * self.nx + i;
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// Distance from `p` to the nearest segment and that segment's index; `None` if there are
    /// no segments. Searches rings of cells outwards until no closer segment can exist.
    pub fn nearest(&self, p: Point) -> Option<(f64, usize)> {
        if self.segs.is_empty() {
            return None;
        }
        let (ci, cj) = self.raw_cell(p);
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        // Rings closer than the grid are empty; start at the first that reaches it.
        let gap = |c: i64, n: i64| {
            if c < 0 {
                -c
            } else if c >= n {
                c - n + 1
            } else {
                0
            }
        };
        let k0 = gap(ci, nx).max(gap(cj, ny));
        let kmax = k0 + nx.max(ny);
        let mut best: Option<(f64, usize)> = None;
        for k in k0..=kmax {
            if let Some((d, _)) = best {
                // Anything in ring k is at least (k - 1) cells away.
                if d <= (k - 1) as f64 * self.cell {
                    break;
                }
            }
            let mut visit = |i: i64, j: i64| {
                if i < 0 || j < 0 || i >= nx || j >= ny {
                    return;
                }
                for &s in self.cell_items(i as usize, j as usize) {
                    let [a, b] = self.segs[s as usize];
                    let d = segment::distance(a, b, p);
                    if best.is_none_or(|(bd, bs)| d < bd || (d == bd && (s as usize) < bs)) {
                        best = Some((d, s as usize));
                    }
                }
            };
            if k == 0 {
                visit(ci, cj);
                continue;
            }
            let (jlo, jhi) = ((cj - k).max(0), (cj + k).min(ny - 1));
            let (ilo, ihi) = ((ci - k).max(0), (ci + k).min(nx - 1));
            for i in ilo..=ihi {
                visit(i, cj - k);
                visit(i, cj + k);
            }
            for j in jlo..=jhi {
                if j != cj - k && j != cj + k {
                    visit(ci - k, j);
                    visit(ci + k, j);
                }
            }
        }
        best
    }

    /// Pairs `(s, t)`, `s < t`, of segments sharing a cell, sorted: every pair of segments that
    /// meet is among them.
    pub fn candidate_pairs(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for c in 0..self.nx * self.ny {
            let items = &self.items[self.start[c] as usize..self.start[c + 1] as usize];
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

    /// Indices of segments whose cells overlap the box `[lo, hi]`, sorted, each once.
    pub fn near_box(&self, lo: Point, hi: Point) -> Vec<usize> {
        let (i0, j0) = self.cell_of(lo);
        let (i1, j1) = self.cell_of(hi);
        let mut out: Vec<usize> = Vec::new();
        for j in j0..=j1 {
            for i in i0..=i1 {
                out.extend(self.cell_items(i, j).iter().map(|&s| s as usize));
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Where a point lies relative to a closed region.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    Inside,
    Boundary,
    Outside,
}

/// Point location by parity in O(1): each cell stores a reference point, not on any segment,
/// whose inside/outside status was found once by walking along the cell row from outside the
/// grid. A query counts crossings only on the short segment from its cell's reference point.
#[derive(Debug, Clone)]
pub struct Locator {
    grid: EdgeGrid,
    refs: Vec<(Point, bool)>,
}

impl Locator {
    /// `segs` must form closed rings (every vertex shared by an even number of segments).
    pub fn new(segs: Vec<[Point; 2]>) -> Locator {
        let grid = EdgeGrid::new(segs);
        let (nx, ny) = grid.dims();
        let mut refs = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            let c0 = grid.centre(0, j);
            let mut prev = ([grid.origin()[0] - grid.cell_size(), c0[1]], false);
            for i in 0..nx {
                let r = reference_point(&grid, i, j);
                let mut odd = false;
                let cells: &[usize] = if i == 0 { &[0] } else { &[i - 1, i] };
                let mut seen: Vec<u32> = Vec::new();
                for &ci in cells {
                    seen.extend_from_slice(grid.cell_items(ci, j));
                }
                seen.sort_unstable();
                seen.dedup();
                for s in seen {
                    let [a, b] = grid.segments()[s as usize];
                    odd ^= crosses(prev.0, r, a, b);
                }
                prev = (r, prev.1 ^ odd);
                refs.push(prev);
            }
        }
        Locator { grid, refs }
    }

    pub fn grid(&self) -> &EdgeGrid {
        &self.grid
    }

    pub fn locate(&self, p: Point) -> Location {
        if !(p[0].is_finite() && p[1].is_finite() && self.grid.inside_grid(p)) {
            return Location::Outside;
        }
        let (i, j) = self.grid.cell_of(p);
        let items = self.grid.cell_items(i, j);
        let segs = self.grid.segments();
        if items.iter().any(|&s| {
            let [a, b] = segs[s as usize];
            segment::on_segment(a, b, p)
        }) {
            return Location::Boundary;
        }
        let (r, inside) = self.refs[j * self.grid.dims().0 + i];
        let mut odd = false;
        for &s in items {
            let [a, b] = segs[s as usize];
            odd ^= crosses(r, p, a, b);
        }
        if inside ^ odd {
            Location::Inside
        } else {
            Location::Outside
        }
    }
}

/// A point of cell `(i, j)` on none of the segments that may meet the cell.
fn reference_point(grid: &EdgeGrid, i: usize, j: usize) -> Point {
    let c = grid.centre(i, j);
    let h = grid.cell_size();
    let items = grid.cell_items(i, j);
    let clear = |p: Point| {
        items.iter().all(|&s| {
            let [a, b] = grid.segments()[s as usize];
            !segment::on_segment(a, b, p)
        })
    };
    // Each segment holds at most one of these points unless it is collinear with several, and
    // the cell meets finitely many segments, so the search ends.
    (0u32..)
        .map(|k| {
            if k == 0 {
                return c;
            }
            let t = k as f64;
            let u = (t * 0.618_033_988_749_895).fract() - 0.5;
            let v = (t * 0.414_213_562_373_095).fract() - 0.5;
            [c[0] + 0.3 * h * u, c[1] + 0.3 * h * v]
        })
        .find(|&p| clear(p))
        .unwrap_or(c)
}

/// Whether the segment from `r` to `p` (neither on any segment of the rings) crosses segment
/// `a b`. A vertex exactly on the line `r p` counts as lying on its right (simulation of
/// simplicity), so each vertex is counted consistently by the two segments that share it.
fn crosses(r: Point, p: Point, a: Point, b: Point) -> bool {
    let sa = orient(r, p, a) > 0.0;
    let sb = orient(r, p, b) > 0.0;
    if sa == sb {
        return false;
    }
    let o1 = orient(a, b, r);
    let o2 = orient(a, b, p);
    (o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(pts: &[Point]) -> Vec<[Point; 2]> {
        (0..pts.len())
            .map(|k| [pts[k], pts[(k + 1) % pts.len()]])
            .collect()
    }

    fn brute_parity(segs: &[[Point; 2]], p: Point) -> bool {
        // Reference: horizontal ray casting with the half-open rule.
        let mut inside = false;
        for &[a, b] in segs {
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                if p[0] < x {
                    inside = !inside;
                }
            }
        }
        inside
    }

    #[test]
    fn locator_agrees_with_ray_casting_on_a_star() {
        // A 200-vertex star: many reflex vertices, rows through vertices.
        let n = 200;
        let pts: Vec<Point> = (0..n)
            .map(|k| {
                let t = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                let r = if k % 2 == 0 { 1.0 } else { 0.45 };
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        let segs = ring(&pts);
        let loc = Locator::new(segs.clone());
        let mut state = 7u64;
        let mut disagreements = 0;
        for _ in 0..20_000 {
            let mut u = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 * 2.4 - 1.2
            };
            let p = [u(), u()];
            let got = loc.locate(p);
            let near = segs
                .iter()
                .any(|s| segment::distance(s[0], s[1], p) < 1e-12);
            if near {
                continue;
            }
            if (got == Location::Inside) != brute_parity(&segs, p) {
                disagreements += 1;
            }
        }
        assert_eq!(disagreements, 0);
    }

    #[test]
    fn vertices_and_edges_are_boundary_and_lattice_rows_through_vertices_work() {
        // Vertices on integer rows: every query row passes through vertices.
        let pts = [[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [2.0, 1.0], [0.0, 2.0]];
        let loc = Locator::new(ring(&pts));
        for p in pts {
            assert_eq!(loc.locate(p), Location::Boundary);
        }
        assert_eq!(loc.locate([3.0, 1.5]), Location::Boundary);
        assert_eq!(loc.locate([1.0, 1.0]), Location::Inside);
        assert_eq!(loc.locate([3.5, 1.0]), Location::Inside);
        assert_eq!(loc.locate([2.0, 1.5]), Location::Outside);
        assert_eq!(loc.locate([5.0, 1.0]), Location::Outside);
        assert_eq!(loc.locate([-1e300, 1.0]), Location::Outside);
        assert_eq!(loc.locate([f64::NAN, 1.0]), Location::Outside);
    }

    #[test]
    fn nearest_matches_brute_force() {
        let pts: Vec<Point> = (0..300)
            .map(|k| {
                let t = 2.0 * std::f64::consts::PI * k as f64 / 300.0;
                let r = 1.0 + 0.3 * (7.0 * t).sin();
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        let segs = ring(&pts);
        let grid = EdgeGrid::new(segs.clone());
        for k in 0..2000 {
            let t = k as f64 * 0.7548776662466927;
            let p = [
                3.0 * (t.fract() - 0.5) * (1.0 + (k % 7) as f64),
                3.0 * ((t * 1.3).fract() - 0.5),
            ];
            let brute = segs
                .iter()
                .map(|s| segment::distance(s[0], s[1], p))
                .fold(f64::INFINITY, f64::min);
            let (d, _) = grid.nearest(p).unwrap();
            assert_eq!(d, brute, "at {p:?}");
        }
    }
}

#[cfg(test)]
mod exact_tests {
    use super::*;

    /// Reference point location: boundary by exact on-segment tests, otherwise the crossing
    /// number of a ray to the right with the half-open rule (exact: it only compares y and
    /// uses orient for the side).
    fn brute(segs: &[[Point; 2]], p: Point) -> Location {
        if segs.iter().any(|s| segment::on_segment(s[0], s[1], p)) {
            return Location::Boundary;
        }
        let mut inside = false;
        for &[a, b] in segs {
            let (lo, hi) = if a[1] <= b[1] { (a, b) } else { (b, a) };
            if lo[1] <= p[1] && p[1] < hi[1] && orient(lo, hi, p) > 0.0 {
                inside = !inside;
            }
        }
        if inside {
            Location::Inside
        } else {
            Location::Outside
        }
    }

    #[test]
    fn integer_polygon_with_hole_at_every_grid_and_half_grid_point() {
        // A staircase with a diagonal edge and a hole whose vertices share rows and columns
        // with the outer ring: queries at integer points hit vertices and edges constantly.
        let outer = [
            [0.0, 0.0],
            [8.0, 0.0],
            [8.0, 2.0],
            [6.0, 2.0],
            [6.0, 4.0],
            [8.0, 6.0],
            [0.0, 6.0],
            [0.0, 4.0],
            [2.0, 4.0],
            [2.0, 2.0],
            [0.0, 2.0],
        ];
        let hole = [
            [3.0, 1.0],
            [3.0, 5.0],
            [5.0, 5.0],
            [5.0, 3.0],
            [4.0, 2.0],
            [5.0, 1.0],
        ];
        let mut segs: Vec<[Point; 2]> = Vec::new();
        for ring in [&outer[..], &hole[..]] {
            for k in 0..ring.len() {
                segs.push([ring[k], ring[(k + 1) % ring.len()]]);
            }
        }
        let loc = Locator::new(segs.clone());
        let mut counts = [0usize; 3];
        for i in -2..=36 {
            for j in -2..=28 {
                let p = [i as f64 * 0.25, j as f64 * 0.25];
                let want = brute(&segs, p);
                assert_eq!(loc.locate(p), want, "at {p:?}");
                counts[want as usize] += 1;
            }
        }
        assert!(counts.iter().all(|&c| c > 100), "{counts:?}");
    }
}
