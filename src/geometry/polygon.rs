//! Simple polygons with holes, validated once and indexed for constant-time queries.

use super::bvh::SegmentTree;
use super::error::{RingRef, ShapeError};
use super::index::EdgeGrid;
use super::locate::{Location, Locator};
use super::segment::{self, Point};
use super::validate::{check_rings, is_ccw, open_ring, ring_segments};

/// A straight piece of a shape's boundary, oriented with the shape's interior on its left.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    pub a: Point,
    pub b: Point,
    /// The name the scene gave this edge (e.g. "seabed"), if any.
    pub name: Option<String>,
    pub ring: RingRef,
    /// The edge's index in the ring as the caller gave it (edge `k` joins input vertices `k`
    /// and `k + 1`), whatever the orientation.
    pub edge: usize,
}

/// A simple polygon with optional holes. The outer ring is stored counter-clockwise and holes
/// clockwise, so the interior is always on the left of every edge.
///
/// Points on an edge or vertex are contained ([`Polygon::contains`] is the closed set); the
/// test is exact, so a point is on the boundary only if it lies exactly on it in `f64`.
#[derive(Debug, Clone)]
pub struct Polygon {
    rings: Vec<Vec<Point>>,
    names: Vec<Vec<Option<String>>>,
    input_edge: Vec<Vec<usize>>,
    locator: Locator,
    tree: SegmentTree,
    area: f64,
    bbox: [Point; 2],
}

impl Polygon {
    /// Validates and indexes a polygon. Either orientation is accepted for every ring; a
    /// closing vertex equal to the first is dropped.
    pub fn new(outer: Vec<Point>, holes: Vec<Vec<Point>>) -> Result<Polygon, ShapeError> {
        Polygon::with_edge_names(outer, holes, Vec::new())
    }

    /// As [`Polygon::new`], naming edges: `names[0]` for the outer ring, `names[k]` for hole
    /// `k - 1`, each with one entry per edge in the order given (edge `k` from vertex `k` to
    /// `k + 1`). Rings past the end of `names` are unnamed.
    pub fn with_edge_names(
        outer: Vec<Point>,
        holes: Vec<Vec<Point>>,
        mut names: Vec<Vec<Option<String>>>,
    ) -> Result<Polygon, ShapeError> {
        let mut rings = vec![open_ring(&outer)];
        rings.extend(holes.iter().map(|h| open_ring(h)));
        check_rings(&rings)?;
        if names.len() > rings.len() {
            return Err(ShapeError::EdgeNamesForMissingRing {
                rings: rings.len(),
                names: names.len(),
            });
        }
        names.resize(rings.len(), Vec::new());
        let mut input_edge = Vec::with_capacity(rings.len());
        for (k, ring) in rings.iter_mut().enumerate() {
            let n = ring.len();
            let ring_names = &mut names[k];
            if ring_names.is_empty() {
                ring_names.resize(n, None);
            } else if ring_names.len() != n {
                let ring = if k == 0 {
                    RingRef::Outer
                } else {
                    RingRef::Hole(k - 1)
                };
                return Err(ShapeError::EdgeNameCount {
                    ring,
                    edges: n,
                    names: ring_names.len(),
                });
            }
            if is_ccw(ring) == (k == 0) {
                input_edge.push((0..n).collect());
            } else {
                // Keep vertex 0 first: new edge m is input edge n - 1 - m, reversed.
                let map: Vec<usize> = (0..n).map(|m| n - 1 - m).collect();
                *ring = (0..n).map(|m| ring[(n - m) % n]).collect();
                *ring_names = map.iter().map(|&e| ring_names[e].take()).collect();
                input_edge.push(map);
            }
        }
        let segs: Vec<[Point; 2]> = rings.iter().flat_map(|r| ring_segments(r)).collect();
        let area = rings.iter().map(|r| shoelace(r)).sum::<f64>();
        let mut bbox = [[f64::INFINITY; 2], [f64::NEG_INFINITY; 2]];
        for p in &rings[0] {
            for k in 0..2 {
                bbox[0][k] = bbox[0][k].min(p[k]);
                bbox[1][k] = bbox[1][k].max(p[k]);
            }
        }
        Ok(Polygon {
            rings,
            names,
            input_edge,
            tree: SegmentTree::new(segs.clone()),
            locator: Locator::new(segs),
            area,
            bbox,
        })
    }

    /// The outer ring, counter-clockwise.
    pub fn outer(&self) -> &[Point] {
        &self.rings[0]
    }

    /// The holes, each clockwise.
    pub fn holes(&self) -> &[Vec<Point>] {
        &self.rings[1..]
    }

    /// Every edge of every ring, outer ring first, in the stored orientation.
    pub(super) fn grid(&self) -> &EdgeGrid {
        self.locator.grid()
    }

    pub fn locate(&self, p: Point) -> Location {
        self.locator.locate(p)
    }

    /// Whether `p` is inside or on the boundary (exact).
    pub fn contains(&self, p: Point) -> bool {
        self.locate(p) != Location::Outside
    }

    /// Distance from `p` to the nearest edge of any ring.
    pub fn boundary_distance(&self, p: Point) -> f64 {
        self.tree.nearest(p).map_or(f64::INFINITY, |(d, _)| d)
    }

    /// Distance to the boundary, negative inside, zero on it.
    pub fn signed_distance(&self, p: Point) -> f64 {
        let d = self.boundary_distance(p);
        match self.locate(p) {
            Location::Inside => -d,
            Location::Boundary => 0.0,
            Location::Outside => d,
        }
    }

    pub fn area(&self) -> f64 {
        self.area
    }

    /// `[min, max]` corners of the outer ring's bounding box.
    pub fn bbox(&self) -> [Point; 2] {
        self.bbox
    }

    /// Every edge, outer ring first, each oriented with the interior on its left.
    pub fn boundary(&self) -> Vec<Segment> {
        let mut out = Vec::new();
        for (k, ring) in self.rings.iter().enumerate() {
            let n = ring.len();
            for m in 0..n {
                out.push(Segment {
                    a: ring[m],
                    b: ring[(m + 1) % n],
                    name: self.names[k][m].clone(),
                    ring: if k == 0 {
                        RingRef::Outer
                    } else {
                        RingRef::Hole(k - 1)
                    },
                    edge: self.input_edge[k][m],
                });
            }
        }
        out
    }
}

/// The edges of `p` cut at the vertices of `others` lying exactly inside them (T-junctions).
pub(super) fn cut_edges(p: &Polygon, others: &[&Polygon]) -> Vec<[Point; 2]> {
    let segs = p.grid().segments();
    let mut cuts: Vec<Vec<Point>> = vec![Vec::new(); segs.len()];
    for q in others {
        for &[v, _] in q.grid().segments() {
            for s in p.grid().near_box(v, v) {
                let [a, b] = segs[s];
                if segment::strictly_inside_segment(a, b, v) {
                    cuts[s].push(v);
                }
            }
        }
    }
    let mut out = Vec::with_capacity(segs.len());
    for (s, &[a, b]) in segs.iter().enumerate() {
        let mut pts = std::mem::take(&mut cuts[s]);
        // Collinear with a b: the order along the dominant axis is the order along the edge.
        let axis = if (b[0] - a[0]).abs() >= (b[1] - a[1]).abs() {
            0
        } else {
            1
        };
        let dir = (b[axis] - a[axis]).signum();
        pts.sort_by(|u, v| (dir * u[axis]).total_cmp(&(dir * v[axis])));
        pts.dedup();
        let mut prev = a;
        for c in pts {
            out.push([prev, c]);
            prev = c;
        }
        out.push([prev, b]);
    }
    out
}

fn shoelace(ring: &[Point]) -> f64 {
    let n = ring.len();
    // Relative to the first vertex, which keeps the sum accurate far from the origin.
    let o = ring[0];
    let mut s = 0.0;
    for i in 1..n - 1 {
        let (a, b) = (ring[i], ring[i + 1]);
        s += (a[0] - o[0]) * (b[1] - o[1]) - (b[0] - o[0]) * (a[1] - o[1]);
    }
    0.5 * s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn l_shape() -> Vec<Point> {
        vec![
            [0.0, 0.0],
            [4.0, 0.0],
            [4.0, 2.0],
            [2.0, 2.0],
            [2.0, 4.0],
            [0.0, 4.0],
        ]
    }

    #[test]
    fn normalises_orientation_and_keeps_edge_names_with_their_edges() {
        // Clockwise input: edge 0 runs (0,0) -> (0,4), the left side.
        let mut cw = l_shape();
        cw.reverse();
        cw.rotate_right(1);
        assert_eq!(cw[0], [0.0, 0.0]);
        let mut names = vec![None; 6];
        names[0] = Some("left".to_string());
        names[5] = Some("base".to_string());
        let hole = vec![[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]];
        let p = Polygon::with_edge_names(cw, vec![hole], vec![names]).unwrap();
        assert_eq!(p.area(), 12.0 - 1.0);
        let b = p.boundary();
        let left = b
            .iter()
            .find(|s| s.name.as_deref() == Some("left"))
            .unwrap();
        assert_eq!((left.a, left.b, left.edge), ([0.0, 4.0], [0.0, 0.0], 0));
        let base = b
            .iter()
            .find(|s| s.name.as_deref() == Some("base"))
            .unwrap();
        assert_eq!((base.a, base.b, base.edge), ([0.0, 0.0], [4.0, 0.0], 5));
        // Interior on the left of every edge: the midpoint nudged left is inside.
        for s in &b {
            let m = [0.5 * (s.a[0] + s.b[0]), 0.5 * (s.a[1] + s.b[1])];
            let left = [
                m[0] - 1e-6 * (s.b[1] - s.a[1]),
                m[1] + 1e-6 * (s.b[0] - s.a[0]),
            ];
            assert_eq!(p.locate(left), Location::Inside, "{s:?}");
        }
        assert_eq!(b.iter().filter(|s| s.ring == RingRef::Hole(0)).count(), 4);
    }

    #[test]
    fn queries_on_an_l_shape_with_a_hole() {
        let hole = vec![[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]];
        let p = Polygon::new(l_shape(), vec![hole]).unwrap();
        assert_eq!(p.locate([1.0, 1.0]), Location::Outside);
        assert_eq!(p.locate([3.0, 3.0]), Location::Outside);
        assert_eq!(p.locate([3.0, 1.0]), Location::Inside);
        assert_eq!(p.locate([2.0, 3.0]), Location::Boundary);
        assert_eq!(p.locate([1.5, 1.0]), Location::Boundary);
        assert!(p.contains([2.0, 2.0]));
        assert_eq!(p.signed_distance([3.0, 1.0]), -1.0);
        assert_eq!(p.signed_distance([3.0, 3.0]), 1.0);
        assert_eq!(p.signed_distance([1.0, 1.0]), 0.5);
        assert_eq!(p.signed_distance([4.0, 1.0]), 0.0);
        assert_eq!(p.bbox(), [[0.0, 0.0], [4.0, 4.0]]);
    }

    #[test]
    fn edge_name_counts_are_checked() {
        assert_eq!(
            Polygon::with_edge_names(l_shape(), vec![], vec![vec![None; 5]]).unwrap_err(),
            ShapeError::EdgeNameCount {
                ring: RingRef::Outer,
                edges: 6,
                names: 5
            }
        );
        assert_eq!(
            Polygon::with_edge_names(l_shape(), vec![], vec![vec![], vec![]]).unwrap_err(),
            ShapeError::EdgeNamesForMissingRing { rings: 1, names: 2 }
        );
    }

    /// A wavy disc of `n` vertices, and the mean work of 10k `contains` + 10k
    /// `signed_distance` queries over its bounding square: the segments (and tree boxes) the
    /// queries test, counted rather than timed so that a loaded machine cannot decide.
    fn query_work(n: usize) -> (Polygon, f64, usize) {
        let outer: Vec<Point> = (0..n)
            .map(|k| {
                let t = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                let r = 10.0 * (1.0 + 0.2 * (13.0 * t).sin());
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        let p = Polygon::new(outer, vec![]).unwrap();
        let (mut work, mut located) = (0, 0);
        let mut inside = 0;
        for k in 0..10_000 {
            let t = k as f64 * 0.618_033_988_749_895;
            let q = [24.0 * (t.fract() - 0.5), 24.0 * ((t * 7.1).fract() - 0.5)];
            inside += p.contains(q) as usize;
            located += super::super::locate::locate_work(&p.locator, q);
            let (nearest, w) = p.tree.nearest_counted(q);
            assert_eq!(nearest.map(|(d, _)| d), Some(p.boundary_distance(q)));
            work += w;
        }
        // `contains` locates; `signed_distance` locates and finds the nearest edge.
        work += 2 * located;
        (p, work as f64 / 1e4, inside)
    }

    #[test]
    fn query_cost_grows_far_slower_than_the_vertex_count() {
        let (p, small, inside) = query_work(1000);
        let (_, big, _) = query_work(16_000);
        eprintln!("mean work a query pair: 1000 vertices {small:.1}, 16000 vertices {big:.1}");
        // The area inside, from the queries, matches the polygon's to sampling accuracy.
        let frac = inside as f64 / 1e4;
        assert!((frac * 24.0 * 24.0 - p.area()).abs() / p.area() < 0.05);
        // Sixteen times the vertices: a linear search would do sixteen times the work. The
        // grid's cells hold a bounded number of segments (locating tests under one a query at
        // either size); the nearest-edge search grows with the tree's depth and with the leaves
        // at nearly the same distance from a point deep inside the wavy disc (2.5 times here).
        let ratio = big / small;
        assert!(
            ratio < 4.0,
            "{ratio:.2} times the work with 16 times the vertices"
        );
    }
}
