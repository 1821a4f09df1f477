//! Geometric selections of particles: `where = "x <= 0"`, `where = "y >= 10 and x <= 1"`.
//!
//! A selector is a conjunction of axis comparisons, i.e. an axis-aligned (possibly unbounded)
//! box. Points on the box boundary are selected within a tolerance so that lattice particles
//! lying exactly on a plane like `x <= 0` are not lost to round-off.

use std::fmt;

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    X,
    Y,
}

impl Axis {
    /// Component index into a point `[x, y]`.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Comparison {
    /// `<=`
    AtMost,
    /// `>=`
    AtLeast,
}

/// One term `axis op value` of a selector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Condition {
    pub axis: Axis,
    pub comparison: Comparison,
    pub value: f64,
}

impl Condition {
    /// True when `p` satisfies the condition, with `tol` of slack on the boundary.
    pub fn holds(&self, p: [f64; 2], tol: f64) -> bool {
        let c = p[self.axis.index()];
        match self.comparison {
            Comparison::AtMost => c <= self.value + tol,
            Comparison::AtLeast => c >= self.value - tol,
        }
    }
}

/// A conjunction of conditions; written in TOML as a string like `"y >= 10 and x <= 1"`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct Selector {
    conditions: Vec<Condition>,
    /// The entry's `within` polygon, when it has one: kept here so that every test of `where`
    /// applies it too (it is written as its own key, not in the string).
    polygon: Option<std::sync::Arc<[[f64; 2]]>>,
}

const SYNTAX_HELP: &str = "expected comparisons like \"x <= 1.5\" joined by \"and\" \
                           (axis x or y, operator <= or >=, a finite number)";

impl Selector {
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut conditions = Vec::new();
        for term in text.split(" and ") {
            let term = term.trim();
            conditions.push(parse_condition(term).ok_or_else(|| {
                if term == text.trim() {
                    format!("cannot read \"{term}\": {SYNTAX_HELP}")
                } else {
                    format!("cannot read \"{term}\" in \"{text}\": {SYNTAX_HELP}")
                }
            })?);
        }
        Ok(Selector {
            conditions,
            polygon: None,
        })
    }

    /// Every point (a `where` left out).
    pub fn all() -> Self {
        Selector {
            conditions: Vec::new(),
            polygon: None,
        }
    }

    /// The same selection, also within the closed polygon `vertices` (a simple ring).
    pub fn within(self, vertices: &[[f64; 2]]) -> Self {
        Selector {
            polygon: Some(vertices.into()),
            ..self
        }
    }

    /// Selects every point: no condition and no polygon.
    pub fn is_all(&self) -> bool {
        self.conditions.is_empty() && self.polygon.is_none()
    }

    /// No `where` conditions (what the `where` string holds).
    pub fn has_no_conditions(&self) -> bool {
        self.conditions.is_empty()
    }

    pub fn conditions(&self) -> &[Condition] {
        &self.conditions
    }

    /// True when `p` satisfies every condition (boundary slack `tol`).
    pub fn matches(&self, p: [f64; 2], tol: f64) -> bool {
        self.conditions.iter().all(|c| c.holds(p, tol))
            && self.polygon.as_deref().is_none_or(|v| in_ring(v, p, tol))
    }

    /// The selected closed interval along `axis`, as `(lo, hi)` (infinite when unbounded).
    pub fn interval(&self, axis: Axis) -> (f64, f64) {
        let mut lo = f64::NEG_INFINITY;
        let mut hi = f64::INFINITY;
        for c in self.conditions.iter().filter(|c| c.axis == axis) {
            match c.comparison {
                Comparison::AtMost => hi = hi.min(c.value),
                Comparison::AtLeast => lo = lo.max(c.value),
            }
        }
        (lo, hi)
    }
}

fn parse_condition(term: &str) -> Option<Condition> {
    let mut chars = term.chars();
    let axis = match chars.next()? {
        'x' => Axis::X,
        'y' => Axis::Y,
        _ => return None,
    };
    let rest = chars.as_str().trim_start();
    let (comparison, number) = if let Some(n) = rest.strip_prefix("<=") {
        (Comparison::AtMost, n)
    } else if let Some(n) = rest.strip_prefix(">=") {
        (Comparison::AtLeast, n)
    } else {
        return None;
    };
    let value: f64 = number.trim().parse().ok()?;
    value.is_finite().then_some(Condition {
        axis,
        comparison,
        value,
    })
}

impl TryFrom<String> for Selector {
    type Error = String;

    fn try_from(text: String) -> Result<Self, String> {
        Selector::parse(&text)
    }
}

impl From<Selector> for String {
    fn from(s: Selector) -> String {
        s.to_string()
    }
}

impl fmt::Display for Selector {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, c) in self.conditions.iter().enumerate() {
            if i > 0 {
                write!(f, " and ")?;
            }
            let axis = match c.axis {
                Axis::X => "x",
                Axis::Y => "y",
            };
            let op = match c.comparison {
                Comparison::AtMost => "<=",
                Comparison::AtLeast => ">=",
            };
            write!(f, "{axis} {op} {}", c.value)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_conjunctions_and_round_trips() {
        let s = Selector::parse("y >= 10 and x<=1").unwrap();
        assert_eq!(s.conditions().len(), 2);
        assert_eq!(s.to_string(), "y >= 10 and x <= 1");
        assert_eq!(Selector::parse(&s.to_string()).unwrap(), s);
        assert_eq!(s.interval(Axis::Y), (10.0, f64::INFINITY));
    }

    #[test]
    fn boundary_points_match_within_tolerance() {
        let s = Selector::parse("x <= 0").unwrap();
        assert!(s.matches([1e-12, 5.0], 1e-9));
        assert!(!s.matches([1e-6, 5.0], 1e-9));
    }

    #[test]
    fn rejects_bad_syntax_with_help() {
        for bad in [
            "z <= 1",
            "x < 1",
            "x <= one",
            "x <= inf",
            "",
            "x <= 1 or y >= 2",
        ] {
            let e = Selector::parse(bad).unwrap_err();
            assert!(e.contains("expected comparisons"), "{bad}: {e}");
        }
    }
}

/// Whether `p` lies inside the ring `v` or within `tol` of its edges (crossing number).
fn in_ring(v: &[[f64; 2]], p: [f64; 2], tol: f64) -> bool {
    let n = v.len();
    let mut inside = false;
    for k in 0..n {
        let (a, b) = (v[k], v[(k + 1) % n]);
        if crate::geometry::distance_to_segment(a, b, p) <= tol {
            return true;
        }
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod polygon_tests {
    use super::*;

    #[test]
    fn a_polygon_selects_its_inside_and_its_edges() {
        let tri = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
        let s = Selector::all().within(&tri);
        assert!(!s.is_all() && s.has_no_conditions());
        assert!(s.matches([0.5, 0.5], 1e-9));
        assert!(s.matches([1.0, 1.0], 1e-9), "on the slanted edge");
        assert!(s.matches([0.0, 1.0], 1e-9) && s.matches([2.0, 0.0], 1e-9));
        assert!(!s.matches([1.0, 1.0 + 1e-6], 1e-9));
        assert!(!s.matches([-0.1, 0.5], 1e-9));
        let both = Selector::parse("x >= 0.5").unwrap().within(&tri);
        assert!(both.matches([0.6, 0.2], 1e-9) && !both.matches([0.4, 0.2], 1e-9));
    }
}
