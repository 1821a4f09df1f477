//! Exact point location in a set of closed rings through an [`EdgeGrid`].

use super::index::EdgeGrid;
use super::segment::{self, orient, Point};
use std::collections::BTreeMap;

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
/// A crowded cell's finer grid has its own reference points, found from the cell's.
#[derive(Debug, Clone)]
pub struct Locator {
    grid: EdgeGrid,
    table: RefTable,
}

/// Reference points and their status, per cell of a grid and of its finer grids.
#[derive(Debug, Clone)]
struct RefTable {
    refs: Vec<(Point, bool)>,
    subs: BTreeMap<usize, RefTable>,
}

impl Locator {
    /// `segs` must form closed rings (every vertex shared by an even number of segments).
    pub fn new(segs: Vec<[Point; 2]>) -> Locator {
        let grid = EdgeGrid::new(segs);
        let table = ref_table(&grid, None);
        Locator { grid, table }
    }

    pub fn grid(&self) -> &EdgeGrid {
        &self.grid
    }

    pub fn locate(&self, p: Point) -> Location {
        if !(p[0].is_finite() && p[1].is_finite() && self.grid.inside_grid(p)) {
            return Location::Outside;
        }
        locate_in(&self.grid, &self.table, p)
    }
}

/// The segments `locate` tests at `p`: those of the (sub)cell it ends in.
#[cfg(test)]
pub(super) fn locate_work(locator: &Locator, p: Point) -> usize {
    if !(p[0].is_finite() && p[1].is_finite() && locator.grid.inside_grid(p)) {
        return 0;
    }
    let (grid, _, i, j) = leaf(&locator.grid, &locator.table, p);
    grid.cell_items(i, j).len()
}

/// The finest grid holding `p`, its table and `p`'s cell there.
fn leaf<'a>(
    grid: &'a EdgeGrid,
    table: &'a RefTable,
    p: Point,
) -> (&'a EdgeGrid, &'a RefTable, usize, usize) {
    let (i, j) = grid.cell_of(p);
    let c = j * grid.dims().0 + i;
    match (grid.sub(i, j), table.subs.get(&c)) {
        (Some(sub), Some(sub_table)) => leaf(&sub.grid, sub_table, p),
        _ => (grid, table, i, j),
    }
}

fn locate_in(grid: &EdgeGrid, table: &RefTable, p: Point) -> Location {
    let (grid, table, i, j) = leaf(grid, table, p);
    let c = j * grid.dims().0 + i;
    let items = grid.cell_items(i, j);
    let segs = grid.segments();
    if items.iter().any(|&s| {
        let [a, b] = segs[s as usize];
        segment::on_segment(a, b, p)
    }) {
        return Location::Boundary;
    }
    let (r, inside) = table.refs[c];
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

/// Reference points of `grid`, walking each row from `start` (a point with known status from
/// which every row's first reference point is reached inside the grid's box) or, for the top
/// grid, from a point left of the grid, where nothing is inside.
fn ref_table(grid: &EdgeGrid, start: Option<(Point, bool)>) -> RefTable {
    let (nx, ny) = grid.dims();
    let segs = grid.segments();
    let count = |from: Point, to: Point, candidates: &mut dyn Iterator<Item = u32>| {
        let mut seen: Vec<u32> = candidates.collect();
        seen.sort_unstable();
        seen.dedup();
        seen.into_iter().fold(false, |odd, s| {
            let [a, b] = segs[s as usize];
            odd ^ crosses(from, to, a, b)
        })
    };
    let mut refs = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        let mut prev = start.unwrap_or((
            [grid.origin()[0] - grid.cell_size(), grid.centre(0, j)[1]],
            false,
        ));
        for i in 0..nx {
            let r = reference_point(grid, i, j);
            let odd = match (i, start) {
                // From the parent's reference point, anywhere in this finer grid's box: any
                // of the box's segments may be crossed.
                (0, Some(_)) => count(prev.0, r, &mut (0..segs.len() as u32)),
                (0, None) => count(prev.0, r, &mut grid.cell_items(0, j).iter().copied()),
                _ => count(
                    prev.0,
                    r,
                    &mut grid
                        .cell_items(i - 1, j)
                        .iter()
                        .chain(grid.cell_items(i, j))
                        .copied(),
                ),
            };
            prev = (r, prev.1 ^ odd);
            refs.push(prev);
        }
    }
    let mut subs = BTreeMap::new();
    for j in 0..ny {
        for i in 0..nx {
            if let Some(sub) = grid.sub(i, j) {
                let c = j * nx + i;
                subs.insert(c, ref_table(&sub.grid, Some(refs[c])));
            }
        }
    }
    RefTable { refs, subs }
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
}

#[cfg(test)]
mod exact_tests {
    use super::*;

    /// Reference point location: boundary by exact on-segment tests, otherwise the crossing
    /// number of a ray to the right with the half-open rule (exact: it only compares y and
    /// uses orient for the side).
    pub(super) fn brute(segs: &[[Point; 2]], p: Point) -> Location {
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

#[cfg(test)]
mod crowded_tests {
    use super::*;

    /// A 1000 m block whose top carries a 1000-vertex zigzag only 2 m wide: all that detail
    /// falls in one top-level cell, which must get finer grids and still answer exactly.
    #[test]
    fn crowded_detail_gets_finer_grids_and_exact_answers() {
        let mut ring = vec![[0.0, 0.0], [1000.0, 0.0], [1000.0, 100.0]];
        for k in 0..1000 {
            let x = 501.0 - 2.0 * k as f64 / 1000.0;
            ring.push([x, if k % 2 == 0 { 100.0 } else { 100.5 }]);
        }
        ring.push([0.0, 100.0]);
        let segs: Vec<[Point; 2]> = (0..ring.len())
            .map(|k| [ring[k], ring[(k + 1) % ring.len()]])
            .collect();
        let loc = Locator::new(segs.clone());
        let tree = crate::geometry::bvh::SegmentTree::new(segs.clone());
        let (nx, ny) = loc.grid().dims();
        let crowded = (0..nx * ny)
            .filter(|&c| loc.grid().sub(c % nx, c / nx).is_some())
            .count();
        assert!(crowded >= 1, "no finer grid was built");
        let mut state = 11u64;
        let mut u = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..3000 {
            let p = [498.0 + 4.0 * u(), 99.0 + 2.0 * u()];
            assert_eq!(loc.locate(p), exact_tests::brute(&segs, p), "at {p:?}");
            let brute = segs
                .iter()
                .map(|s| segment::distance(s[0], s[1], p))
                .fold(f64::INFINITY, f64::min);
            assert_eq!(tree.nearest(p).map(|(d, _)| d), Some(brute), "at {p:?}");
        }
        // Vertices of the zigzag are on the boundary.
        for v in &ring[3..50] {
            assert_eq!(loc.locate(*v), Location::Boundary);
        }
    }
}
