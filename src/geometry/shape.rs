//! The shapes a zone can take, behind one enum.

use super::error::{RingRef, ShapeError};
use super::locate::Location;
use super::polygon::{Polygon, Segment};
use super::segment::Point;
use std::f64::consts::PI;

/// A disc. Its containment and distance tests are plain floating point (a circle has no exact
/// representation), so points within rounding of the circle may fall either way.
#[derive(Debug, Clone, PartialEq)]
pub struct Circle {
    centre: Point,
    radius: f64,
    name: Option<String>,
}

impl Circle {
    pub fn new(centre: Point, radius: f64) -> Result<Circle, ShapeError> {
        let ok =
            centre[0].is_finite() && centre[1].is_finite() && radius.is_finite() && radius > 0.0;
        if !ok {
            return Err(ShapeError::BadCircle { centre, radius });
        }
        Ok(Circle {
            centre,
            radius,
            name: None,
        })
    }

    /// Names the whole circumference as one boundary.
    pub fn named(mut self, name: impl Into<String>) -> Circle {
        self.name = Some(name.into());
        self
    }

    pub fn centre(&self) -> Point {
        self.centre
    }

    pub fn radius(&self) -> f64 {
        self.radius
    }

    pub fn name(&self) -> Option<&str> {
        self.name.as_deref()
    }

    pub fn signed_distance(&self, p: Point) -> f64 {
        (p[0] - self.centre[0]).hypot(p[1] - self.centre[1]) - self.radius
    }

    /// Number of equal arcs of length at most `h` (up to rounding) around the circle.
    pub fn arcs(&self, h: f64) -> usize {
        ((2.0 * PI * self.radius / h - 1e-9).ceil() as usize).max(3)
    }

    /// Point `k` of `n` equally spaced points, the first at angle 0.
    pub fn point(&self, k: usize, n: usize) -> Point {
        let t = 2.0 * PI * k as f64 / n as f64;
        [
            self.centre[0] + self.radius * t.cos(),
            self.centre[1] + self.radius * t.sin(),
        ]
    }

    /// The circle's vertices as a polygon ring at spacing about `h`: a circular hole in a
    /// polygon is this ring, so its boundary particles lie exactly on the circle.
    pub fn ring(&self, h: f64) -> Vec<Point> {
        let n = self.arcs(h);
        (0..n).map(|k| self.point(k, n)).collect()
    }
}

/// An axis-aligned rectangle `[origin, origin + size]`, kept with its polygon.
#[derive(Debug, Clone)]
pub struct Rectangle {
    origin: Point,
    size: Point,
    polygon: Polygon,
}

impl Rectangle {
    pub fn new(origin: Point, size: Point) -> Result<Rectangle, ShapeError> {
        Rectangle::with_edge_names(origin, size, Default::default())
    }

    /// Names in the order bottom, right, top, left.
    pub fn with_edge_names(
        origin: Point,
        size: Point,
        names: [Option<String>; 4],
    ) -> Result<Rectangle, ShapeError> {
        let finite = origin.iter().chain(size.iter()).all(|v| v.is_finite());
        let corner = [origin[0] + size[0], origin[1] + size[1]];
        // A size below the origin's resolution would make a degenerate polygon.
        let positive = size[0] > 0.0 && size[1] > 0.0;
        if !(finite && positive) || corner[0] == origin[0] || corner[1] == origin[1] {
            return Err(ShapeError::BadRectangle { origin, size });
        }
        let outer = vec![
            origin,
            [corner[0], origin[1]],
            corner,
            [origin[0], corner[1]],
        ];
        let polygon = Polygon::with_edge_names(outer, vec![], vec![names.to_vec()])?;
        Ok(Rectangle {
            origin,
            size,
            polygon,
        })
    }

    pub fn origin(&self) -> Point {
        self.origin
    }

    pub fn size(&self) -> Point {
        self.size
    }

    pub fn polygon(&self) -> &Polygon {
        &self.polygon
    }
}

/// What a zone is.
#[derive(Debug, Clone)]
pub enum Shape {
    Polygon(Polygon),
    Circle(Circle),
    Rectangle(Rectangle),
}

impl Shape {
    /// The polygon behind a polygon or rectangle; `None` for a circle.
    pub fn as_polygon(&self) -> Option<&Polygon> {
        match self {
            Shape::Polygon(p) => Some(p),
            Shape::Rectangle(r) => Some(r.polygon()),
            Shape::Circle(_) => None,
        }
    }

    /// Inside, on the boundary (exactly, for polygons; within one ulp of the radius, for
    /// circles) or outside.
    pub fn locate(&self, p: Point) -> Location {
        match self {
            Shape::Circle(c) => {
                let (dx, dy) = (p[0] - c.centre[0], p[1] - c.centre[1]);
                let (d2, r2) = (dx * dx + dy * dy, c.radius * c.radius);
                if d2 < r2 {
                    Location::Inside
                } else if d2 == r2 {
                    Location::Boundary
                } else {
                    Location::Outside
                }
            }
            _ => self.as_polygon().map_or(Location::Outside, |q| q.locate(p)),
        }
    }

    /// Closed containment: boundary points are contained.
    pub fn contains(&self, p: Point) -> bool {
        self.locate(p) != Location::Outside
    }

    /// Distance to the boundary, negative inside.
    pub fn signed_distance(&self, p: Point) -> f64 {
        match self {
            Shape::Circle(c) => c.signed_distance(p),
            _ => self
                .as_polygon()
                .map_or(f64::INFINITY, |q| q.signed_distance(p)),
        }
    }

    pub fn area(&self) -> f64 {
        match self {
            Shape::Circle(c) => PI * c.radius * c.radius,
            _ => self.as_polygon().map_or(0.0, Polygon::area),
        }
    }

    /// `[min, max]` corners.
    pub fn bbox(&self) -> [Point; 2] {
        match self {
            Shape::Circle(c) => {
                let (x, y, r) = (c.centre[0], c.centre[1], c.radius);
                [[x - r, y - r], [x + r, y + r]]
            }
            _ => self.as_polygon().map_or([[0.0; 2]; 2], Polygon::bbox),
        }
    }

    /// The boundary as segments, interior on the left. Polygon edges are returned whole; a
    /// circle is cut into [`Circle::arcs`]`(h)` chords (`h` is ignored for polygons).
    pub fn boundary(&self, h: f64) -> Vec<Segment> {
        match self {
            Shape::Circle(c) => {
                let n = c.arcs(h);
                (0..n)
                    .map(|k| Segment {
                        a: c.point(k, n),
                        b: c.point(k + 1, n),
                        name: c.name.clone(),
                        ring: RingRef::Outer,
                        edge: k,
                    })
                    .collect()
            }
            _ => self.as_polygon().map_or(Vec::new(), Polygon::boundary),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_queries() {
        let c = Shape::Circle(Circle::new([1.0, 2.0], 2.0).unwrap());
        assert_eq!(c.locate([1.0, 4.0]), Location::Boundary);
        assert_eq!(c.locate([2.0, 3.0]), Location::Inside);
        assert_eq!(c.locate([3.0, 4.0]), Location::Outside);
        assert_eq!(c.signed_distance([1.0, 2.5]), -1.5);
        assert_eq!(c.bbox(), [[-1.0, 0.0], [3.0, 4.0]]);
        assert!((c.area() - 4.0 * PI).abs() < 1e-12);
        let b = c.boundary(0.5);
        assert_eq!(b.len(), (4.0 * PI / 0.5).ceil() as usize);
        assert!(b
            .iter()
            .all(|s| (crate::geometry::segment::length(s.a, s.b) - 0.5).abs() < 0.03));
        assert_eq!(
            Circle::new([0.0, 0.0], 0.0),
            Err(ShapeError::BadCircle {
                centre: [0.0, 0.0],
                radius: 0.0
            })
        );
        assert!(Circle::new([f64::NAN, 0.0], 1.0).is_err());
    }

    #[test]
    fn rectangle_is_its_polygon_with_named_sides() {
        let names = [
            Some("base".to_string()),
            None,
            Some("top".to_string()),
            None,
        ];
        let r = Rectangle::with_edge_names([1.0, 1.0], [2.0, 3.0], names).unwrap();
        let s = Shape::Rectangle(r);
        assert_eq!(s.area(), 6.0);
        assert_eq!(s.bbox(), [[1.0, 1.0], [3.0, 4.0]]);
        assert_eq!(s.locate([3.0, 2.0]), Location::Boundary);
        assert_eq!(s.signed_distance([2.0, 2.0]), -1.0);
        let top = s
            .boundary(1.0)
            .into_iter()
            .find(|e| e.name.as_deref() == Some("top"))
            .unwrap();
        assert_eq!((top.a, top.b), ([3.0, 4.0], [1.0, 4.0]));
        assert!(Rectangle::new([0.0, 0.0], [1.0, -1.0]).is_err());
        assert!(Rectangle::new([1e20, 0.0], [1.0, 1.0]).is_err());
    }
}
