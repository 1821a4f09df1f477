//! Validation of a polygon's rings, with exact predicates so that a polygon accepted here
//! never makes containment or filling ambiguous.

use super::error::{RingRef, ShapeError};
use super::index::EdgeGrid;
use super::locate::{Location, Locator};
use super::segment::{self, orient, Contact, Point};

fn ring_ref(k: usize) -> RingRef {
    if k == 0 {
        RingRef::Outer
    } else {
        RingRef::Hole(k - 1)
    }
}

/// Drops one closing vertex equal to the first: many drawing tools repeat it.
pub(super) fn open_ring(ring: &[Point]) -> Vec<Point> {
    let mut v = ring.to_vec();
    if v.len() > 1 && v.first() == v.last() {
        v.pop();
    }
    v
}

fn check_ring(k: usize, ring: &[Point]) -> Result<(), ShapeError> {
    let ring_id = ring_ref(k);
    if let Some(vertex) = ring
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(ShapeError::NonFinite {
            ring: ring_id,
            vertex,
        });
    }
    if ring.len() < 3 {
        return Err(ShapeError::TooFewVertices {
            ring: ring_id,
            count: ring.len(),
        });
    }
    let n = ring.len();
    if let Some(vertex) = (0..n).find(|&i| ring[i] == ring[(i + 1) % n]) {
        return Err(ShapeError::RepeatedVertex {
            ring: ring_id,
            vertex,
        });
    }
    if ring.iter().all(|&p| orient(ring[0], ring[1], p) == 0.0) {
        return Err(ShapeError::ZeroArea { ring: ring_id });
    }
    Ok(())
}

/// Checks the rings (outer first, then holes, each already opened by [`open_ring`]):
/// vertex counts, finiteness, zero-length edges, zero area, every pair of edges that meet, and
/// the nesting of holes.
pub(super) fn check_rings(rings: &[Vec<Point>]) -> Result<(), ShapeError> {
    for (k, ring) in rings.iter().enumerate() {
        check_ring(k, ring)?;
    }
    // Segment s of the flat list belongs to ring `owner[s].0` as its edge `owner[s].1`.
    let mut segs = Vec::new();
    let mut owner = Vec::new();
    for (k, ring) in rings.iter().enumerate() {
        for i in 0..ring.len() {
            segs.push([ring[i], ring[(i + 1) % ring.len()]]);
            owner.push((k, i));
        }
    }
    let grid = EdgeGrid::new(segs);
    let segs = grid.segments();
    for (s, t) in grid.candidate_pairs() {
        let ((rs, es), (rt, et)) = (owner[s], owner[t]);
        let [a, b] = segs[s];
        let [c, d] = segs[t];
        let n = rings[rs].len();
        let adjacent = rs == rt && (et == es + 1 || (es == 0 && et == n - 1));
        let bad = if adjacent {
            segment::collinear_overlap(a, b, c, d)
        } else {
            segment::contact(a, b, c, d) != Contact::Disjoint
        };
        if !bad {
            continue;
        }
        return Err(match (rs, rt) {
            (r, q) if r == q => ShapeError::SelfIntersection {
                ring: ring_ref(r),
                edges: [es, et],
            },
            (0, h) => ShapeError::HoleCrossesOuter {
                hole: h - 1,
                hole_edge: et,
                outer_edge: es,
            },
            (h, g) => ShapeError::HolesOverlap {
                holes: [h - 1, g - 1],
            },
        });
    }
    // No two rings meet now, so one vertex of a ring tells on which side of another it lies.
    let locators: Vec<Locator> = rings
        .iter()
        .map(|r| Locator::new(ring_segments(r)))
        .collect();
    for (h, hole) in rings.iter().enumerate().skip(1) {
        if locators[0].locate(hole[0]) != Location::Inside {
            return Err(ShapeError::HoleOutside { hole: h - 1 });
        }
    }
    for a in 1..rings.len() {
        for b in a + 1..rings.len() {
            if locators[b].locate(rings[a][0]) == Location::Inside
                || locators[a].locate(rings[b][0]) == Location::Inside
            {
                return Err(ShapeError::HolesOverlap {
                    holes: [a - 1, b - 1],
                });
            }
        }
    }
    Ok(())
}

pub(super) fn ring_segments(ring: &[Point]) -> Vec<[Point; 2]> {
    (0..ring.len())
        .map(|i| [ring[i], ring[(i + 1) % ring.len()]])
        .collect()
}

/// Whether a valid ring runs counter-clockwise. Exact: at the lexicographically smallest vertex
/// the polygon is convex, and there its neighbours are never collinear with it in a valid ring.
pub(super) fn is_ccw(ring: &[Point]) -> bool {
    let n = ring.len();
    let k = (0..n)
        .min_by(|&i, &j| {
            ring[i][0]
                .total_cmp(&ring[j][0])
                .then(ring[i][1].total_cmp(&ring[j][1]))
        })
        .unwrap_or(0);
    orient(ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(outer: &[Point], holes: &[&[Point]]) -> Result<(), ShapeError> {
        let mut rings = vec![open_ring(outer)];
        rings.extend(holes.iter().map(|h| open_ring(h)));
        check_rings(&rings)
    }

    const SQUARE: [Point; 4] = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];

    #[test]
    fn accepts_a_square_with_holes_in_either_orientation() {
        let h1 = [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]];
        let h2 = [[5.0, 5.0], [5.0, 6.0], [6.0, 6.0], [6.0, 5.0]];
        assert_eq!(check(&SQUARE, &[&h1, &h2]), Ok(()));
        let mut rev = SQUARE.to_vec();
        rev.reverse();
        assert_eq!(check(&rev, &[]), Ok(()));
        // A closing repeat of the first vertex is tolerated.
        let mut closed = SQUARE.to_vec();
        closed.push(SQUARE[0]);
        assert_eq!(check(&closed, &[]), Ok(()));
    }

    #[test]
    fn reports_the_two_crossing_edges_of_a_bow_tie() {
        let bow = [[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 2.0]];
        assert_eq!(
            check(&bow, &[]),
            Err(ShapeError::SelfIntersection {
                ring: RingRef::Outer,
                edges: [0, 2]
            })
        );
    }

    #[test]
    fn a_ring_touching_itself_at_a_vertex_is_not_simple() {
        // Vertex 2 lies on edge 4 (from vertex 4 back to vertex 0).
        let pinch = [
            [0.0, 0.0],
            [4.0, 0.0],
            [2.0, 2.0],
            [4.0, 4.0],
            [0.0, 4.0],
            [2.0, 2.0],
        ];
        assert!(matches!(
            check(&pinch, &[]),
            Err(ShapeError::SelfIntersection {
                ring: RingRef::Outer,
                ..
            })
        ));
        let touch = [[0.0, 0.0], [4.0, 0.0], [0.0, 2.0], [4.0, 4.0], [0.0, 4.0]];
        assert_eq!(
            check(&touch, &[]),
            Err(ShapeError::SelfIntersection {
                ring: RingRef::Outer,
                edges: [1, 4]
            })
        );
    }

    #[test]
    fn a_spike_folding_back_is_refused() {
        let spike = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [4.0, 2.0], [0.0, 4.0]];
        assert_eq!(
            check(&spike, &[]),
            Err(ShapeError::SelfIntersection {
                ring: RingRef::Outer,
                edges: [1, 2]
            })
        );
    }

    #[test]
    fn counts_areas_and_numbers() {
        assert_eq!(
            check(&[[0.0, 0.0], [1.0, 0.0]], &[]),
            Err(ShapeError::TooFewVertices {
                ring: RingRef::Outer,
                count: 2
            })
        );
        assert_eq!(
            check(&[[0.0, 0.0], [1.0, 1.0], [3.0, 3.0]], &[]),
            Err(ShapeError::ZeroArea {
                ring: RingRef::Outer
            })
        );
        assert_eq!(
            check(&[[0.0, 0.0], [1.0, f64::NAN], [3.0, 3.0]], &[]),
            Err(ShapeError::NonFinite {
                ring: RingRef::Outer,
                vertex: 1
            })
        );
        assert_eq!(
            check(&[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]], &[]),
            Err(ShapeError::RepeatedVertex {
                ring: RingRef::Outer,
                vertex: 1
            })
        );
        let tiny_hole = [[1.0, 1.0], [2.0, 1.0]];
        assert_eq!(
            check(&SQUARE, &[&tiny_hole]),
            Err(ShapeError::TooFewVertices {
                ring: RingRef::Hole(0),
                count: 2
            })
        );
    }

    #[test]
    fn holes_outside_crossing_touching_or_nested() {
        let outside = [[20.0, 1.0], [21.0, 1.0], [21.0, 2.0]];
        assert_eq!(
            check(&SQUARE, &[&outside]),
            Err(ShapeError::HoleOutside { hole: 0 })
        );
        let crossing = [[9.0, 1.0], [11.0, 1.0], [11.0, 2.0], [9.0, 2.0]];
        assert_eq!(
            check(&SQUARE, &[&crossing]),
            Err(ShapeError::HoleCrossesOuter {
                hole: 0,
                hole_edge: 0,
                outer_edge: 1
            })
        );
        let touching = [[10.0, 5.0], [9.0, 6.0], [9.0, 4.0]];
        assert!(matches!(
            check(&SQUARE, &[&touching]),
            Err(ShapeError::HoleCrossesOuter {
                hole: 0,
                outer_edge: 1,
                ..
            })
        ));
        let big = [[1.0, 1.0], [8.0, 1.0], [8.0, 8.0], [1.0, 8.0]];
        let small = [[3.0, 3.0], [4.0, 3.0], [4.0, 4.0]];
        assert_eq!(
            check(&SQUARE, &[&big, &small]),
            Err(ShapeError::HolesOverlap { holes: [0, 1] })
        );
        let other = [[7.0, 7.0], [9.0, 7.0], [9.0, 9.0]];
        assert_eq!(
            check(&SQUARE, &[&small, &big, &other]),
            Err(ShapeError::HolesOverlap { holes: [1, 2] })
        );
    }

    #[test]
    fn orientation_is_exact() {
        assert!(is_ccw(&SQUARE));
        let mut rev = SQUARE.to_vec();
        rev.reverse();
        assert!(!is_ccw(&rev));
        // A sliver whose area underflows in a float shoelace sum.
        let sliver = [[0.0, 0.0], [1.0, 0.0], [0.5, 1e-300]];
        assert!(is_ccw(&sliver));
        assert!(!is_ccw(&[sliver[0], sliver[2], sliver[1]]));
    }
}

#[cfg(test)]
mod property_tests {
    use super::*;

    /// Whether a ring is simple, by testing every pair of edges.
    fn brute_simple(ring: &[Point]) -> bool {
        let n = ring.len();
        for s in 0..n {
            for t in s + 1..n {
                let (a, b) = (ring[s], ring[(s + 1) % n]);
                let (c, d) = (ring[t], ring[(t + 1) % n]);
                let adjacent = t == s + 1 || (s == 0 && t == n - 1);
                let bad = if adjacent {
                    segment::collinear_overlap(a, b, c, d)
                } else {
                    segment::contact(a, b, c, d) != Contact::Disjoint
                };
                if bad {
                    return false;
                }
            }
        }
        true
    }

    #[test]
    fn random_rings_on_a_small_grid_match_an_all_pairs_check() {
        // Vertices on a 5 x 5 grid: collinear runs, touching vertices and spikes are common.
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut next = |n: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) % n
        };
        let (mut accepted, mut refused) = (0, 0);
        for _ in 0..20_000 {
            let n = 3 + next(6) as usize;
            let ring: Vec<Point> = (0..n).map(|_| [next(5) as f64, next(5) as f64]).collect();
            let got = check_rings(std::slice::from_ref(&ring));
            let degenerate = (0..n).any(|i| ring[i] == ring[(i + 1) % n])
                || ring.iter().all(|&p| orient(ring[0], ring[1], p) == 0.0);
            let want = !degenerate && brute_simple(&ring);
            assert_eq!(got.is_ok(), want, "{ring:?}: {got:?}");
            if want {
                accepted += 1;
            } else {
                refused += 1;
            }
        }
        assert!(
            accepted > 1000 && refused > 1000,
            "{accepted} accepted, {refused} refused"
        );
    }
}
