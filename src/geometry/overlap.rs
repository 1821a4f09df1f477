//! Whether two zones overlap: their interiors intersect. Zones that only touch, along edges or
//! at vertices, do not overlap.
//!
//! For polygons the test is exact when shared boundaries are given with identical coordinates:
//! a vertex of one zone lying on an edge of another must lie on it exactly in `f64` (always true
//! for shared vertices, and for T-junctions on axis-aligned or otherwise exactly representable
//! edges). Circles are compared in floating point with a relative tolerance of 1e-12, so
//! tangent circles touch rather than overlap.

use super::error::ZonesOverlap;
use super::locate::Location;
use super::polygon::{cut_edges, Polygon};
use super::segment::{self, Contact, Point};
use super::shape::{Circle, Shape};
use std::collections::HashSet;

const CIRCLE_TOL: f64 = 1e-12;

/// Whether the interiors of `a` and `b` intersect.
pub fn overlap(a: &Shape, b: &Shape) -> bool {
    let ([alo, ahi], [blo, bhi]) = (a.bbox(), b.bbox());
    if alo[0] > bhi[0] || blo[0] > ahi[0] || alo[1] > bhi[1] || blo[1] > ahi[1] {
        return false;
    }
    match (a, b) {
        (Shape::Circle(c), Shape::Circle(d)) => circles_overlap(c, d),
        (Shape::Circle(c), other) | (other, Shape::Circle(c)) => other
            .as_polygon()
            .is_some_and(|p| circle_polygon_overlap(c, p)),
        _ => match (a.as_polygon(), b.as_polygon()) {
            (Some(p), Some(q)) => polygons_overlap(p, q),
            _ => false,
        },
    }
}

/// The first pair of overlapping zones, in order of the first index then the second.
pub fn validate_zones(zones: &[Shape]) -> Result<(), ZonesOverlap> {
    for i in 0..zones.len() {
        for j in i + 1..zones.len() {
            if overlap(&zones[i], &zones[j]) {
                return Err(ZonesOverlap { zones: [i, j] });
            }
        }
    }
    Ok(())
}

fn circles_overlap(c: &Circle, d: &Circle) -> bool {
    let dist = (c.centre()[0] - d.centre()[0]).hypot(c.centre()[1] - d.centre()[1]);
    dist < (c.radius() + d.radius()) * (1.0 - CIRCLE_TOL)
}

fn circle_polygon_overlap(c: &Circle, p: &Polygon) -> bool {
    // The open disc meets the polygon's interior iff its centre is in the closed polygon or
    // some boundary point is closer than the radius.
    p.contains(c.centre()) || p.boundary_distance(c.centre()) < c.radius() * (1.0 - CIRCLE_TOL)
}

fn polygons_overlap(p: &Polygon, q: &Polygon) -> bool {
    let (ps, qs) = (p.grid().segments(), q.grid().segments());
    for &[a, b] in ps {
        let lo = [a[0].min(b[0]), a[1].min(b[1])];
        let hi = [a[0].max(b[0]), a[1].max(b[1])];
        for t in q.grid().near_box(lo, hi) {
            let [c, d] = qs[t];
            if segment::contact(a, b, c, d) == Contact::Proper {
                return true;
            }
        }
    }
    // With no proper crossing, cutting each boundary at the other's vertices leaves pieces that
    // are either shared with the other boundary or have their interior wholly inside or wholly
    // outside the other polygon.
    let p_pieces = cut_edges(p, &[q]);
    let q_pieces = cut_edges(q, &[p]);
    let key = |a: Point, b: Point| (a.map(f64::to_bits), b.map(f64::to_bits));
    let q_set: HashSet<_> = q_pieces.iter().map(|&[a, b]| key(a, b)).collect();
    let p_set: HashSet<_> = p_pieces.iter().map(|&[a, b]| key(a, b)).collect();
    for &[a, b] in &p_pieces {
        if q_set.contains(&key(a, b)) {
            // Both interiors on the left of the same piece.
            return true;
        }
        if !q_set.contains(&key(b, a)) && piece_inside(a, b, q) {
            return true;
        }
    }
    q_pieces.iter().any(|&[a, b]| {
        !p_set.contains(&key(b, a)) && !p_set.contains(&key(a, b)) && piece_inside(a, b, p)
    })
}

/// Whether the open piece `a b`, which meets `other`'s boundary at most at its ends, lies inside
/// `other`. Its midpoint is rounded; if that lands exactly on the boundary, other interior
/// points decide.
fn piece_inside(a: Point, b: Point, other: &Polygon) -> bool {
    for t in [0.5, 0.25, 0.75, 0.375, 0.625] {
        let m = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
        match other.locate(m) {
            Location::Inside => return true,
            Location::Outside => return false,
            Location::Boundary => continue,
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::shape::Rectangle;

    fn poly(pts: &[Point]) -> Shape {
        Shape::Polygon(Polygon::new(pts.to_vec(), vec![]).unwrap())
    }

    fn rect(o: Point, s: Point) -> Shape {
        Shape::Rectangle(Rectangle::new(o, s).unwrap())
    }

    fn both(a: &Shape, b: &Shape) -> bool {
        let (x, y) = (overlap(a, b), overlap(b, a));
        assert_eq!(x, y, "overlap must be symmetric");
        x
    }

    #[test]
    fn touching_along_an_edge_or_at_a_vertex_is_allowed() {
        let a = rect([0.0, 0.0], [2.0, 1.0]);
        assert!(!both(&a, &rect([0.0, 1.0], [2.0, 1.0])));
        assert!(!both(&a, &rect([2.0, 1.0], [1.0, 1.0])));
        // T-junction: the upper zone's edge covers only part of the lower one's.
        assert!(!both(&a, &rect([0.5, 1.0], [1.0, 3.0])));
        // A slope face shared by two polygons, given by the same vertices.
        let lower = poly(&[[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [0.0, 3.0]]);
        let upper = poly(&[[0.0, 3.0], [4.0, 1.0], [4.0, 5.0], [0.0, 5.0]]);
        assert!(!both(&lower, &upper));
    }

    #[test]
    fn overlaps_by_crossing_containment_sharing_or_identity() {
        let a = rect([0.0, 0.0], [2.0, 2.0]);
        assert!(both(&a, &rect([1.0, 1.0], [2.0, 2.0])));
        assert!(both(&a, &rect([0.5, 0.5], [0.5, 0.5])));
        assert!(both(&a, &a.clone()));
        // Same edge, both interiors on the same side, no crossing anywhere.
        assert!(both(&a, &rect([0.0, 0.0], [2.0, 1.0])));
        // A triangle inside the square touching its edge from inside with a vertex.
        assert!(both(&a, &poly(&[[1.0, 0.0], [1.5, 1.0], [0.5, 1.0]])));
        // The same triangle flipped outside only touches.
        assert!(!both(&a, &poly(&[[1.0, 0.0], [1.5, -1.0], [0.5, -1.0]])));
    }

    #[test]
    fn a_zone_in_a_hole_does_not_overlap() {
        let hole = vec![[1.0, 1.0], [3.0, 1.0], [3.0, 3.0], [1.0, 3.0]];
        let outer = vec![[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]];
        let ring = Shape::Polygon(Polygon::new(outer, vec![hole.clone()]).unwrap());
        assert!(!both(&ring, &poly(&hole)));
        assert!(!both(&ring, &rect([1.5, 1.5], [1.0, 1.0])));
        assert!(both(&ring, &rect([0.5, 1.5], [1.0, 1.0])));
        let pile = Shape::Circle(Circle::new([2.0, 2.0], 1.0).unwrap());
        assert!(!both(&ring, &pile));
        let fat = Shape::Circle(Circle::new([2.0, 2.0], 1.1).unwrap());
        assert!(both(&ring, &fat));
    }

    #[test]
    fn circles() {
        let c = |x: f64, r: f64| Shape::Circle(Circle::new([x, 0.0], r).unwrap());
        assert!(!both(&c(0.0, 1.0), &c(2.0, 1.0)));
        assert!(both(&c(0.0, 1.0), &c(1.9, 1.0)));
        assert!(both(&c(0.0, 1.0), &c(0.0, 0.1)));
        assert!(!both(&c(0.0, 1.0), &rect([1.0, -1.0], [1.0, 2.0])));
        assert!(both(&c(0.0, 1.0), &rect([0.9, -1.0], [1.0, 2.0])));
        // Centre outside, the disc reaching past a corner.
        assert!(both(&c(0.0, 1.0), &rect([0.5, 0.5], [1.0, 1.0])));
    }

    #[test]
    fn validate_zones_names_the_first_overlapping_pair() {
        let zones = vec![
            rect([0.0, 0.0], [1.0, 1.0]),
            rect([1.0, 0.0], [1.0, 1.0]),
            rect([2.0, 0.0], [1.0, 1.0]),
            rect([1.5, 0.5], [1.0, 1.0]),
        ];
        assert_eq!(validate_zones(&zones), Err(ZonesOverlap { zones: [1, 3] }));
        assert_eq!(validate_zones(&zones[..3]), Ok(()));
    }
}

#[cfg(test)]
mod property_tests {
    use super::*;
    use crate::geometry::shape::Rectangle;

    /// Rectangles on a small integer grid touch, share edges and T-junctions all the time; their
    /// interiors intersect iff both axis intervals overlap with positive length.
    #[test]
    fn random_grid_rectangles_agree_with_interval_overlap() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |n: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) % n
        };
        let mut rects = Vec::new();
        for _ in 0..60 {
            let (x, y) = (next(6) as f64, next(6) as f64);
            let (w, h) = (1.0 + next(3) as f64, 1.0 + next(3) as f64);
            rects.push(([x, y], [w, h]));
        }
        let mut touching = 0;
        for a in &rects {
            for b in &rects {
                let sa = Shape::Rectangle(Rectangle::new(a.0, a.1).unwrap());
                // The second as a general polygon with an extra vertex mid-edge, so the exact
                // splitting and piece matching are exercised, not just the rectangle shortcut.
                let (o, s) = b;
                let pb = Polygon::new(
                    vec![
                        *o,
                        [o[0] + 0.5 * s[0], o[1]],
                        [o[0] + s[0], o[1]],
                        [o[0] + s[0], o[1] + s[1]],
                        [o[0], o[1] + s[1]],
                    ],
                    vec![],
                )
                .unwrap();
                let sb = Shape::Polygon(pb);
                let gap = |k: usize| (a.0[k] + a.1[k]).min(b.0[k] + b.1[k]) - a.0[k].max(b.0[k]);
                let want = gap(0) > 0.0 && gap(1) > 0.0;
                touching += (gap(0) >= 0.0 && gap(1) >= 0.0 && !want) as usize;
                assert_eq!(overlap(&sa, &sb), want, "{a:?} {b:?}");
                assert_eq!(overlap(&sb, &sa), want, "{b:?} {a:?}");
            }
        }
        assert!(touching > 100, "only {touching} touching pairs exercised");
    }
}
