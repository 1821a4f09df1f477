//! The fill judged the way the solver will see it: the crate's own Delaunay triangulation and
//! alpha shape (alpha 1.3, the scene default) of the generated cloud, compared with the drawn
//! zones.

use super::fill::{
    fill_zones, fill_zones_graded, FillParams, FilledPoint, FineRegion, DROP_FACTOR,
};
use super::fill_boundary::SNAP;
use super::locate::Location;
use super::polygon::Polygon;
use super::segment::{self, orient, Point};
use super::shape::{Circle, Rectangle, Shape};
use super::FillError;
use crate::mesh::alpha::{alpha_keep, boundary_edges};
use crate::mesh::delaunay::delaunay;

const ALPHA: f64 = 1.3;

/// What the alpha shape of a fill looks like against the zones.
#[derive(Debug)]
struct Recovery {
    mesh_area: f64,
    zone_area: f64,
    /// Kept triangles whose centroid lies outside every zone.
    spurious: Vec<[Point; 3]>,
    /// Alpha-boundary edges whose midpoint is off every zone boundary (notches, corner cuts).
    off_boundary: Vec<[Point; 2]>,
    /// Boundary particles that are not vertices of the alpha boundary.
    buried: usize,
    max_circumradius_over_h: f64,
    min_distance_over_h: f64,
}

fn recovery(zones: &[Shape], pts: &[FilledPoint], h: f64) -> Recovery {
    let xy: Vec<Point> = pts.iter().map(|p| p.position).collect();
    let ids: Vec<u64> = (0..xy.len() as u64).collect();
    let tris = delaunay(&xy, &ids).expect("triangulation");
    let hs: Vec<f64> = pts.iter().map(|p| p.h).collect();
    let keep = alpha_keep(&xy, &tris, &hs, ALPHA);
    let kept: Vec<[u32; 3]> = tris
        .iter()
        .zip(&keep)
        .filter(|(_, &k)| k)
        .map(|(t, _)| *t)
        .collect();
    let corner = |t: &[u32; 3]| t.map(|v| xy[v as usize]);
    let outside_all = |p: Point| zones.iter().all(|z| z.locate(p) == Location::Outside);
    let on_some_boundary = |p: Point| zones.iter().any(|z| z.signed_distance(p).abs() <= 1e-9 * h);
    let mut r = Recovery {
        mesh_area: 0.0,
        zone_area: zones.iter().map(Shape::area).sum(),
        spurious: Vec::new(),
        off_boundary: Vec::new(),
        buried: 0,
        max_circumradius_over_h: 0.0,
        min_distance_over_h: f64::INFINITY,
    };
    for t in &kept {
        let [a, b, c] = corner(t);
        r.mesh_area += 0.5 * orient(a, b, c);
        let g = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
        if outside_all(g) {
            r.spurious.push([a, b, c]);
        }
        r.max_circumradius_over_h = r
            .max_circumradius_over_h
            .max(crate::mesh::alpha::circumradius(a, b, c) / h);
    }
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (xy[t[k] as usize], xy[t[(k + 1) % 3] as usize]);
            r.min_distance_over_h = r.min_distance_over_h.min(segment::length(a, b) / h);
        }
    }
    let edges = boundary_edges(&kept);
    let mut on_alpha = vec![false; xy.len()];
    for e in &edges {
        let (a, b) = (xy[e[0] as usize], xy[e[1] as usize]);
        on_alpha[e[0] as usize] = true;
        on_alpha[e[1] as usize] = true;
        if !on_some_boundary([0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]) {
            r.off_boundary.push([a, b]);
        }
    }
    r.buried = pts
        .iter()
        .zip(&on_alpha)
        .filter(|(p, &on)| p.on_boundary && !on)
        .count();
    r
}

fn area_error(r: &Recovery) -> f64 {
    (r.mesh_area - r.zone_area).abs() / r.zone_area
}

/// Boundary particles on their zone's boundary; interior ones at least the drop distance from
/// it; each position once.
fn check_placement(zones: &[Shape], pts: &[FilledPoint], h: f64) {
    for p in pts {
        let d = zones[p.zone].signed_distance(p.position);
        if p.on_boundary {
            assert!(d.abs() <= SNAP * h, "{p:?} is {d} off");
        } else {
            assert!(d <= -DROP_FACTOR * h, "{p:?} only {d} from the boundary");
        }
    }
    for w in pts.windows(2) {
        assert!(w[0].position != w[1].position, "{:?} emitted twice", w[0]);
        let order = w[0].position[1]
            .total_cmp(&w[1].position[1])
            .then(w[0].position[0].total_cmp(&w[1].position[0]));
        assert!(order.is_lt(), "not sorted by y then x");
    }
}

/// Consecutive boundary particles along each drawn edge are between 0.5 h and h apart.
fn check_edge_spacing(shape: &Shape, pts: &[FilledPoint], h: f64) {
    for s in shape.boundary(h) {
        let len = segment::length(s.a, s.b);
        let mut along: Vec<f64> = pts
            .iter()
            .filter(|p| p.on_boundary && segment::distance(s.a, s.b, p.position) <= 1e-9 * h)
            .map(|p| segment::length(s.a, p.position))
            .collect();
        along.sort_by(f64::total_cmp);
        assert!(
            along[0] <= SNAP * h,
            "first particle {} from the vertex",
            along[0]
        );
        assert!((along.last().unwrap() - len).abs() <= 1e-9 * len);
        for w in along.windows(2) {
            let gap = (w[1] - w[0]) / h;
            assert!((0.5..=1.0 + 1e-9).contains(&gap), "gap {gap} h on {s:?}");
        }
    }
}

fn poly(outer: &[Point], holes: Vec<Vec<Point>>) -> Shape {
    Shape::Polygon(Polygon::new(outer.to_vec(), holes).unwrap())
}

#[test]
fn polygon_with_hole_recovers_its_area_boundary_and_hole() {
    // A site with a sloping top and a tunnel (a circular hole drawn as a ring at spacing h),
    // then also a tilted square cavity, at two spacings, with the lattice aligned and not.
    let tunnel = Circle::new([8.0, 4.5], 2.0).unwrap();
    let cavity = vec![[14.0, 3.0], [16.0, 4.0], [15.0, 6.0], [13.0, 5.0]];
    let outer = [
        [0.0, 0.0],
        [20.0, 0.0],
        [20.0, 8.0],
        [12.0, 10.0],
        [0.0, 10.0],
    ];
    for (h, anchor) in [(0.5, [0.0, 0.0]), (0.5, [0.13, 0.37]), (0.25, [0.0, 0.0])] {
        for with_cavity in [false, true] {
            let mut holes = vec![tunnel.ring(h)];
            if with_cavity {
                holes.push(cavity.clone());
            }
            let zones = [poly(&outer, holes.clone())];
            let pts = fill_zones(&zones, &FillParams::new(h, anchor)).unwrap();
            check_placement(&zones, &pts, h);
            check_edge_spacing(&zones[0], &pts, h);
            // The holes stay open: no particle inside them (boundary particles may be snapped
            // onto a lattice node by up to SNAP h).
            for hole in &holes {
                let hole = poly(hole, vec![]);
                for p in &pts {
                    let depth = -hole.signed_distance(p.position);
                    assert!(depth <= SNAP * h, "{p:?} is {depth} inside a hole");
                }
            }
            let r = recovery(&zones, &pts, h);
            eprintln!(
                "polygon with {} holes, h = {h}, anchor {anchor:?}: {} particles, mesh area \
                 {:.12} vs {:.12} (relative error {:.2e}), max R/h {:.3}, min distance/h {:.3}",
                holes.len(),
                pts.len(),
                r.mesh_area,
                r.zone_area,
                area_error(&r),
                r.max_circumradius_over_h,
                r.min_distance_over_h
            );
            assert!(area_error(&r) < 0.005);
            if !with_cavity {
                assert!(r.spurious.is_empty(), "h = {h}: {:?}", r.spurious);
                assert!(r.off_boundary.is_empty(), "h = {h}: {:?}", r.off_boundary);
                assert_eq!(r.buried, 0);
                assert!(area_error(&r) < 1e-12);
                continue;
            }
            // The cavity's four corners are re-entrant right angles for the body: each is cut
            // by one triangle (see `reentrant_right_angle_is_cut_by_exactly_one_corner_triangle`),
            // and nothing else is.
            assert_eq!(r.spurious.len(), 4, "{:?}", r.spurious);
            for t in &r.spurious {
                assert!(t.iter().any(|v| cavity.contains(v)), "{t:?}");
            }
            assert_eq!(r.off_boundary.len(), 4);
            assert_eq!(r.buried, 4);
        }
    }
    // The resolution limit: at h = 1 the cavity (2.2 h across, circumradius 1.58 h) is
    // spanned by small triangles between its own boundary particles and closes, while the
    // tunnel (radius 2 h > 1.3 h) stays open.
    let h = 1.0;
    let zones = [poly(&outer, vec![tunnel.ring(h), cavity.clone()])];
    let pts = fill_zones(&zones, &FillParams::new(h, [0.0, 0.0])).unwrap();
    let r = recovery(&zones, &pts, h);
    assert!((r.mesh_area - r.zone_area - 5.0).abs() < 1e-9, "{r:?}");
}

#[test]
fn slope_of_thirty_degrees_comes_out_without_notches() {
    let h = 0.5;
    let run = 6.0 / 30f64.to_radians().tan();
    let outer = [
        [0.0, 0.0],
        [30.0, 0.0],
        [30.0, 10.0],
        [8.0 + run, 10.0],
        [8.0, 4.0],
        [0.0, 4.0],
    ];
    let zones = [poly(&outer, vec![])];
    let pts = fill_zones(&zones, &FillParams::new(h, [0.0, 0.0])).unwrap();
    check_placement(&zones, &pts, h);
    check_edge_spacing(&zones[0], &pts, h);
    let r = recovery(&zones, &pts, h);
    eprintln!(
        "30° slope: area error {:.2e}, max R/h {:.3}",
        area_error(&r),
        r.max_circumradius_over_h
    );
    assert!(r.spurious.is_empty(), "{:?}", r.spurious);
    assert!(r.off_boundary.is_empty(), "{:?}", r.off_boundary);
    assert_eq!(r.buried, 0);
    assert!(area_error(&r) < 1e-12);
}

#[test]
fn reentrant_right_angle_is_cut_by_exactly_one_corner_triangle() {
    // Any triangle spanning a 90° notch between boundary particles s <= 1.6 h (the split
    // length) from the corner has circumradius s / sqrt(2) <= 1.13 h < 1.3 h: the alpha shape
    // keeps it. The fill can only make it the single smallest one, of area s^2 / 2.
    let h = 0.5;
    let outer = [
        [0.0, 0.0],
        [6.0, 0.0],
        [6.0, 3.0],
        [3.0, 3.0],
        [3.0, 6.0],
        [0.0, 6.0],
    ];
    let zones = [poly(&outer, vec![])];
    let pts = fill_zones(&zones, &FillParams::new(h, [0.1, 0.2])).unwrap();
    check_placement(&zones, &pts, h);
    check_edge_spacing(&zones[0], &pts, h);
    let r = recovery(&zones, &pts, h);
    eprintln!(
        "L-shape: area error {:.2e}, spurious {:?}",
        area_error(&r),
        r.spurious
    );
    assert_eq!(r.spurious.len(), 1);
    let t = r.spurious[0];
    let mut v = t.to_vec();
    v.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    assert_eq!(v, vec![[3.0, 3.0], [3.0, 3.5], [3.5, 3.0]]);
    assert_eq!(r.off_boundary.len(), 1);
    assert!((r.mesh_area - r.zone_area - 0.5 * h * h).abs() < 1e-9);
    // Only the corner particle itself ends up inside the alpha shape.
    assert_eq!(r.buried, 1);
}

#[test]
fn circular_hole_in_a_block_stays_open() {
    let h = 0.25;
    let hole = Circle::new([2.0, 2.0], 0.8).unwrap();
    let zones = [poly(
        &[[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]],
        vec![hole.ring(h)],
    )];
    let pts = fill_zones(&zones, &FillParams::new(h, [0.0, 0.0])).unwrap();
    check_placement(&zones, &pts, h);
    check_edge_spacing(&zones[0], &pts, h);
    let r = recovery(&zones, &pts, h);
    assert!(r.spurious.is_empty(), "{:?}", r.spurious);
    assert!(r.off_boundary.is_empty(), "{:?}", r.off_boundary);
    // Hole particles lie on the circle itself.
    for p in pts
        .iter()
        .filter(|p| (p.position[0] - 2.0).hypot(p.position[1] - 2.0) < 1.0)
    {
        assert!((Shape::Circle(hole.clone()).signed_distance(p.position)).abs() < 1e-12);
    }
    assert!(area_error(&r) < 1e-12);
}

#[test]
fn touching_zones_share_their_boundary_particles_once() {
    let h = 0.5;
    // A stiff layer under a soft one whose base is only part of the stiff top (T-junctions at
    // x = 2 and x = 8), a sloping soft top, and a circular boulder touching nothing.
    let stiff = Shape::Rectangle(Rectangle::new([0.0, 0.0], [10.0, 2.0]).unwrap());
    let soft = poly(&[[2.0, 2.0], [8.0, 2.0], [8.0, 4.0], [2.0, 5.0]], vec![]);
    let boulder = Shape::Circle(Circle::new([15.0, 1.5], 1.5).unwrap());
    let zones = [stiff, soft, boulder];
    let params = FillParams::new(h, [0.0, 0.0]);
    let pts = fill_zones(&zones, &params).unwrap();
    check_placement(&zones, &pts, h);
    // The shared stretch y = 2, 2 <= x <= 8 belongs to zone 0, each particle once.
    let shared: Vec<&FilledPoint> = pts
        .iter()
        .filter(|p| p.position[1] == 2.0 && (2.0..=8.0).contains(&p.position[0]))
        .collect();
    assert_eq!(shared.len(), 13);
    assert!(shared.iter().all(|p| p.zone == 0 && p.on_boundary));
    // Deterministic and independent of the zones' order, except for the owner of shared points.
    let again = fill_zones(&zones, &params).unwrap();
    assert_eq!(pts, again);
    let swapped = [zones[1].clone(), zones[0].clone(), zones[2].clone()];
    let other = fill_zones(&swapped, &params).unwrap();
    let pos = |v: &[FilledPoint]| v.iter().map(|p| p.position).collect::<Vec<_>>();
    assert_eq!(pos(&pts), pos(&other));
    assert!(other
        .iter()
        .filter(|p| p.position[1] == 2.0 && (2.0..=8.0).contains(&p.position[0]))
        .all(|p| p.zone == 0));
    // The alpha shape of the union: no triangle outside, no notch except the two re-entrant
    // right angles where the soft layer meets the stiff top (x = 2 is 90°, x = 8 is 90°).
    let r = recovery(
        &zones[..2],
        &pts.iter()
            .filter(|p| p.zone < 2)
            .copied()
            .collect::<Vec<_>>(),
        h,
    );
    eprintln!(
        "two layers: spurious {:?}, off-boundary {:?}",
        r.spurious, r.off_boundary
    );
    assert_eq!(r.spurious.len(), 2);
    assert!((r.mesh_area - r.zone_area - 2.0 * 0.5 * h * h).abs() < 1e-9);
}

#[test]
fn circle_zone_particles_lie_on_and_inside_the_circle() {
    let h = 0.3;
    let c = Shape::Circle(Circle::new([0.05, -0.1], 2.0).unwrap());
    let zones = [c];
    let pts = fill_zones(&zones, &FillParams::new(h, [0.0, 0.0])).unwrap();
    check_placement(&zones, &pts, h);
    let on = pts.iter().filter(|p| p.on_boundary).count();
    assert_eq!(on, (2.0 * std::f64::consts::PI * 2.0 / h).ceil() as usize);
    let r = recovery(&zones, &pts, h);
    // The alpha shape is the inscribed polygon: its area falls short by the circular segments.
    let n = on as f64;
    let polygon_area = 0.5 * n * 4.0 * (2.0 * std::f64::consts::PI / n).sin();
    assert!(
        (r.mesh_area - polygon_area).abs() < 1e-9,
        "{} vs {polygon_area}",
        r.mesh_area
    );
    assert_eq!(r.buried, 0);
}

#[test]
fn bad_parameters_and_overlapping_zones_are_refused() {
    let z = [Shape::Rectangle(
        Rectangle::new([0.0, 0.0], [1.0, 1.0]).unwrap(),
    )];
    for h in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            fill_zones(&z, &FillParams::new(h, [0.0, 0.0])),
            Err(FillError::BadSpacing { .. })
        ));
    }
    assert!(matches!(
        fill_zones(&z, &FillParams::new(0.1, [f64::NAN, 0.0])),
        Err(FillError::BadAnchor { .. })
    ));
    assert!(matches!(
        fill_zones(&z, &FillParams::new(1e-7, [0.0, 0.0])),
        Err(FillError::TooManyPoints { .. })
    ));
    let two = [
        z[0].clone(),
        Shape::Circle(Circle::new([1.0, 1.0], 0.5).unwrap()),
    ];
    assert_eq!(
        fill_zones(&two, &FillParams::new(0.1, [0.0, 0.0])),
        Err(FillError::Overlap(super::ZonesOverlap { zones: [0, 1] }))
    );
}

#[test]
fn a_rectangle_on_the_anchor_gives_the_plain_lattice() {
    // The old rectangle lattice is the special case: every lattice point, edges included, bit
    // for bit (0.1 is not a binary fraction, so edge subdivision alone would differ by ulps).
    let h = 0.1;
    let zones = [Shape::Rectangle(
        Rectangle::new([0.1, 0.7], [1.2, 0.5]).unwrap(),
    )];
    let pts = fill_zones(&zones, &FillParams::new(h, [0.1, 0.7])).unwrap();
    assert_eq!(pts.len(), 13 * 6);
    for (k, p) in pts.iter().enumerate() {
        let (i, j) = (k % 13, k / 13);
        assert_eq!(p.position, [0.1 + i as f64 * h, 0.7 + j as f64 * h]);
    }
}

#[test]
fn graded_fill_around_a_fine_polygon_region() {
    // A block with a fine quadrilateral under a footing at its top, at h / 4.
    let h = 0.5;
    let block = poly(&[[0.0, 0.0], [12.0, 0.0], [12.0, 6.0], [0.0, 6.0]], vec![]);
    let region = FineRegion {
        shape: poly(&[[4.0, 6.0], [4.5, 4.0], [7.5, 4.0], [8.0, 6.0]], vec![]),
        h: h / 4.0,
    };
    let zones = [block];
    let pts = fill_zones_graded(
        &zones,
        std::slice::from_ref(&region),
        &FillParams::new(h, [0.0, 0.0]),
    )
    .unwrap();
    // Fine particles exactly in the region or on its outline (to rounding); coarse ones at
    // least h / 2 away from it.
    for p in &pts {
        let inside = region.shape.signed_distance(p.position) <= 1e-12;
        assert_eq!(p.h, if inside { h / 4.0 } else { h }, "{p:?}");
        if !inside && !p.on_boundary {
            assert!(region.shape.signed_distance(p.position) >= 0.5 * h);
        }
    }
    let fine = pts.iter().filter(|p| p.h < h).count() as f64;
    let expect = region.shape.area() / (h / 4.0).powi(2);
    assert!(
        (fine / expect - 1.0).abs() < 0.15,
        "{fine} fine particles, about {expect} expected"
    );
    // The seabed inside the region is lined at the fine spacing.
    let top_fine = pts
        .iter()
        .filter(|p| p.position[1] == 6.0 && (4.0..=8.0).contains(&p.position[0]))
        .count();
    assert_eq!(top_fine, 33);
    let r = recovery(&zones, &pts, h);
    eprintln!(
        "graded: {} particles ({fine} fine), area error {:.2e}, max R/h {:.3}",
        pts.len(),
        area_error(&r),
        r.max_circumradius_over_h
    );
    assert!(r.spurious.is_empty(), "{:?}", r.spurious);
    assert!(r.off_boundary.is_empty(), "{:?}", r.off_boundary);
    assert!(area_error(&r) < 1e-12);
    // Without regions the graded fill is the plain one.
    let params = FillParams::new(h, [0.0, 0.0]);
    assert_eq!(
        fill_zones_graded(&zones, &[], &params).unwrap(),
        fill_zones(&zones, &params).unwrap()
    );
    let coarse_region = FineRegion {
        shape: region.shape.clone(),
        h: 2.0 * h,
    };
    assert_eq!(
        fill_zones_graded(&zones, &[coarse_region], &params),
        Err(FillError::BadSpacing { h: 2.0 * h })
    );
}

#[test]
fn random_star_polygons_fill_with_particles_in_place_and_once() {
    let mut state = 0x0000_ddb1_a5e5_u64;
    let mut u = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..40 {
        let n = 3 + (u() * 30.0) as usize;
        let outer: Vec<Point> = (0..n)
            .map(|k| {
                let t = 2.0 * std::f64::consts::PI * (k as f64 + 0.8 * u()) / n as f64;
                let r = 1.0 + 4.0 * u();
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        let h = 0.1 + 0.3 * u();
        let zones = [poly(&outer, vec![])];
        let pts = fill_zones(&zones, &FillParams::new(h, [u(), u()])).unwrap();
        check_placement(&zones, &pts, h);
        check_edge_spacing_upper(&zones[0], &pts, h);
    }
}

/// Consecutive boundary particles along each edge are at most h apart (edges shorter than
/// h / 2 make closer ones, which is the drawing's detail, not the fill's).
fn check_edge_spacing_upper(shape: &Shape, pts: &[FilledPoint], h: f64) {
    for s in shape.boundary(h) {
        let mut along: Vec<f64> = pts
            .iter()
            .filter(|p| p.on_boundary && segment::distance(s.a, s.b, p.position) <= 1e-9 * h)
            .map(|p| segment::length(s.a, p.position))
            .collect();
        along.sort_by(f64::total_cmp);
        for w in along.windows(2) {
            assert!(
                w[1] - w[0] <= h * (1.0 + 1e-9),
                "gap {} on {s:?}",
                w[1] - w[0]
            );
        }
    }
}
