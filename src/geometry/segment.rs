//! Exact segment predicates. Every decision about which side of a line a point lies on goes
//! through `robust::orient2d`, so validation and containment never disagree with each other
//! because of rounding.

use robust::Coord;

pub type Point = [f64; 2];

/// Twice the signed area of `(a, b, c)`; the sign is exact (positive: `c` left of `a → b`).
#[inline]
pub fn orient(a: Point, b: Point, c: Point) -> f64 {
    let k = |p: Point| Coord { x: p[0], y: p[1] };
    robust::orient2d(k(a), k(b), k(c))
}

#[inline]
fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// Whether `p`, known to be collinear with `a` and `b`, lies within their closed bounding box.
#[inline]
fn within_box(a: Point, b: Point, p: Point) -> bool {
    p[0] >= a[0].min(b[0])
        && p[0] <= a[0].max(b[0])
        && p[1] >= a[1].min(b[1])
        && p[1] <= a[1].max(b[1])
}

/// Whether `p` lies on the closed segment `a b` (exact).
#[inline]
pub fn on_segment(a: Point, b: Point, p: Point) -> bool {
    orient(a, b, p) == 0.0 && within_box(a, b, p)
}

/// Whether `p` lies on the open segment `a b`, endpoints excluded (exact).
#[inline]
pub fn strictly_inside_segment(a: Point, b: Point, p: Point) -> bool {
    p != a && p != b && on_segment(a, b, p)
}

/// How two closed segments meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contact {
    /// No common point.
    Disjoint,
    /// One common point interior to both segments, the segments not collinear.
    Proper,
    /// They share at least one point, and it is an endpoint of one of them, or they are
    /// collinear and overlap.
    Touch,
}

/// Exact classification of how segments `a b` and `c d` meet.
pub fn contact(a: Point, b: Point, c: Point, d: Point) -> Contact {
    let o1 = sign(orient(a, b, c));
    let o2 = sign(orient(a, b, d));
    let o3 = sign(orient(c, d, a));
    let o4 = sign(orient(c, d, b));
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return Contact::Proper;
    }
    let touches = (o1 == 0 && within_box(a, b, c))
        || (o2 == 0 && within_box(a, b, d))
        || (o3 == 0 && within_box(c, d, a))
        || (o4 == 0 && within_box(c, d, b));
    if touches {
        Contact::Touch
    } else {
        Contact::Disjoint
    }
}

/// Whether `a b` and `c d` are collinear and share more than one point.
pub fn collinear_overlap(a: Point, b: Point, c: Point, d: Point) -> bool {
    if orient(a, b, c) != 0.0 || orient(a, b, d) != 0.0 {
        return false;
    }
    // Project on the dominant axis, where the order along the line is exact.
    let axis = if (b[0] - a[0]).abs() >= (b[1] - a[1]).abs() {
        0
    } else {
        1
    };
    let (lo1, hi1) = (a[axis].min(b[axis]), a[axis].max(b[axis]));
    let (lo2, hi2) = (c[axis].min(d[axis]), c[axis].max(d[axis]));
    lo1.max(lo2) < hi1.min(hi2)
}

/// Euclidean distance from `p` to the closed segment `a b`.
pub fn distance(a: Point, b: Point, p: Point) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (qx, qy) = (a[0] + t * dx - p[0], a[1] + t * dy - p[1]);
    qx.hypot(qy)
}

pub fn length(a: Point, b: Point) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_classes() {
        let (a, b) = ([0.0, 0.0], [2.0, 2.0]);
        assert_eq!(contact(a, b, [0.0, 2.0], [2.0, 0.0]), Contact::Proper);
        assert_eq!(contact(a, b, [1.0, 1.0], [2.0, 0.0]), Contact::Touch);
        assert_eq!(contact(a, b, [3.0, 3.0], [4.0, 4.0]), Contact::Disjoint);
        assert_eq!(contact(a, b, [1.0, 1.0], [3.0, 3.0]), Contact::Touch);
        assert_eq!(contact(a, b, [0.0, 1.0], [1.0, 2.0]), Contact::Disjoint);
        assert!(collinear_overlap(a, b, [1.0, 1.0], [3.0, 3.0]));
        assert!(!collinear_overlap(a, b, [2.0, 2.0], [3.0, 3.0]));
    }

    #[test]
    fn on_segment_is_exact() {
        assert!(on_segment([0.0, 0.0], [4.0, 2.0], [2.0, 1.0]));
        // One ulp above the line: a tolerance-free test must see it off the segment.
        let y = f64::from_bits(1.0f64.to_bits() + 1);
        assert!(!on_segment([0.0, 0.0], [4.0, 2.0], [2.0, y]));
        assert!(orient([0.0, 0.0], [4.0, 2.0], [2.0, y]) > 0.0);
        assert!(!strictly_inside_segment([0.0, 0.0], [4.0, 2.0], [4.0, 2.0]));
        assert!(strictly_inside_segment([0.0, 0.0], [4.0, 2.0], [1.0, 0.5]));
    }

    #[test]
    fn distance_to_segment() {
        assert_eq!(distance([0.0, 0.0], [2.0, 0.0], [1.0, 3.0]), 3.0);
        assert_eq!(distance([0.0, 0.0], [2.0, 0.0], [5.0, 4.0]), 5.0);
        assert_eq!(distance([1.0, 1.0], [1.0, 1.0], [4.0, 5.0]), 5.0);
    }
}
