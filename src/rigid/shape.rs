//! Convex rigid shapes for contact in plane strain: a convex core (one point or a CCW polygon)
//! swept by a disk of radius `radius`. Circles, sharp and rounded polygons are all this one form,
//! so one signed-distance routine serves them all. Every query is closed-form (no iteration, no
//! randomness) so the MPI ranks holding a copy of the same data take bit-identical decisions.

use super::edge_tree::EdgeTree;
use std::f64::consts::PI;

type P = [f64; 2];

fn add(a: P, b: P) -> P {
    [a[0] + b[0], a[1] + b[1]]
}
fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1]]
}
fn mul(s: f64, a: P) -> P {
    [s * a[0], s * a[1]]
}
fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn cross(a: P, b: P) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn norm(a: P) -> f64 {
    a[0].hypot(a[1])
}
fn orient(a: P, b: P, c: P) -> f64 {
    cross(sub(b, a), sub(c, a))
}
/// Outward unit normal of the edge a→b of a CCW polygon.
fn outward(a: P, b: P) -> P {
    let e = sub(b, a);
    mul(1.0 / norm(e), [e[1], -e[0]])
}
fn point_segment(p: P, a: P, b: P) -> f64 {
    let e = sub(b, a);
    let ee = dot(e, e);
    let t = if ee > 0.0 {
        (dot(sub(p, a), e) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(p, add(a, mul(t, e))))
}
fn segment_segment(a: P, b: P, c: P, d: P) -> f64 {
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return 0.0;
    }
    let m = point_segment(a, c, d).min(point_segment(b, c, d));
    m.min(point_segment(c, a, b)).min(point_segment(d, a, b))
}
/// Closed triangle containment; a degenerate triangle contains nothing (its edges cover it).
fn in_triangle(t: &[P; 3], p: P) -> bool {
    let s = orient(t[0], t[1], t[2]);
    s != 0.0 && (0..3).all(|i| s * orient(t[i], t[(i + 1) % 3], p) >= 0.0)
}

/// Polygons with more vertices than this answer from an edge tree and by golden-section
/// search (cost logarithmic in the vertex count); smaller ones by scanning every edge.
const SCANNED: usize = 16;
/// Golden-section steps: the interval shrinks below 1e-16 of its length.
const GOLDEN_STEPS: usize = 80;

/// Maximiser and maximum of a concave function on [0, 1] (ends included).
fn golden_max(f: impl Fn(f64) -> f64) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (0.0, 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..GOLDEN_STEPS {
        if fc >= fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    [(0.0, f(0.0)), (1.0, f(1.0)), (c, fc), (d, fd)]
        .into_iter()
        .fold(
            (0.0, f64::NEG_INFINITY),
            |m, x| if x.1 > m.1 { x } else { m },
        )
}

/// The Minkowski sum of a convex core and a disk of radius `radius` >= 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    /// CCW; 1 point (circle) or >= 3 (polygon), starting at the lowest, then rightmost vertex.
    core: Vec<[f64; 2]>,
    radius: f64,
    /// Over the core's edges, when there are more than [`SCANNED`].
    tree: Option<EdgeTree>,
    /// Bounding box, and a deepest point with its depth: computed once, moved with the shape.
    bbox: [[f64; 2]; 2],
    deep: (P, f64),
}

/// A polygon's corner: the arc of radius `radius` round a core vertex between the outward
/// normals of the edges before and after it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    pub vertex: [f64; 2],
    pub normals: [[f64; 2]; 2],
    pub radius: f64,
}

impl Corner {
    /// The angle through which the outline turns here (radians; negative where it turns in).
    pub fn turn(&self) -> f64 {
        let [a, b] = self.normals;
        cross(a, b).atan2(dot(a, b))
    }

    /// The middle of the arc.
    pub fn middle(&self) -> [f64; 2] {
        let bis = add(self.normals[0], self.normals[1]);
        add(self.vertex, mul(self.radius / norm(bis), bis))
    }
}

/// Result of a closest-point query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proximity {
    /// Signed distance from x to the shape's surface: negative inside.
    pub distance: f64,
    /// Unit outward normal of the surface at the closest point (the gradient of `distance`).
    pub normal: [f64; 2],
    /// d(normal)/dx = curvature t tᵀ (t the unit tangent): 1/|x - c| when the closest core
    /// feature is a core vertex c and x is outside the core, else 0.
    pub curvature: f64,
}

impl Shape {
    /// A disk; `radius` must be positive and finite.
    pub fn circle(centre: [f64; 2], radius: f64) -> Result<Shape, String> {
        if !(centre[0].is_finite() && centre[1].is_finite()) {
            return Err(format!("circle centre {centre:?} is not finite"));
        }
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(format!(
                "circle radius must be positive and finite, got {radius}"
            ));
        }
        Ok(Shape::finish(vec![centre], radius))
    }

    /// The shape of `core` and `radius` with its edge tree, box and deepest point.
    fn finish(core: Vec<P>, radius: f64) -> Shape {
        let tree = (core.len() > SCANNED).then(|| EdgeTree::new(&core));
        let init = [[f64::INFINITY; 2], [f64::NEG_INFINITY; 2]];
        let [lo, hi] = core.iter().fold(init, |[lo, hi], c| {
            [
                [lo[0].min(c[0]), lo[1].min(c[1])],
                [hi[0].max(c[0]), hi[1].max(c[1])],
            ]
        });
        let bbox = [
            [lo[0] - radius, lo[1] - radius],
            [hi[0] + radius, hi[1] + radius],
        ];
        let mut shape = Shape {
            deep: (core[0], radius),
            core,
            radius,
            tree,
            bbox,
        };
        shape.deep = shape.find_deepest();
        shape
    }

    /// A strictly convex polygon (>= 3 vertices, either orientation) with its corners rounded to
    /// `corner_radius` >= 0: the core is the polygon offset inward by `corner_radius`, which must
    /// stay below the limit (named in the error) where an offset edge shrinks to zero length.
    pub fn polygon(vertices: &[[f64; 2]], corner_radius: f64) -> Result<Shape, String> {
        let n = vertices.len();
        if n < 3 {
            return Err(format!("a polygon needs at least 3 vertices, got {n}"));
        }
        if vertices.iter().flatten().any(|c| !c.is_finite()) {
            return Err("polygon vertices must be finite".into());
        }
        if !(corner_radius >= 0.0 && corner_radius.is_finite()) {
            return Err(format!(
                "corner radius must be >= 0 and finite, got {corner_radius}"
            ));
        }
        let mut v = vertices.to_vec();
        if (0..n).map(|i| cross(v[i], v[(i + 1) % n])).sum::<f64>() < 0.0 {
            v.reverse();
        }
        // A canonical first vertex (lowest, then rightmost) makes CW and CCW input equal shapes.
        let key = |p: P| (p[1], -p[0]);
        let first = (0..n).fold(0, |s, i| if key(v[i]) < key(v[s]) { i } else { s });
        v.rotate_left(first);
        let mut turning = 0.0;
        for i in 0..n {
            let (a, b, c) = (v[i], v[(i + 1) % n], v[(i + 2) % n]);
            let (e1, e2) = (sub(b, a), sub(c, b));
            let s = cross(e1, e2);
            if s.abs() <= 1e-12 * norm(e1) * norm(e2) {
                return Err(format!(
                    "polygon vertices {a:?}, {b:?}, {c:?} are collinear or repeated: the polygon must be strictly convex"
                ));
            }
            if s < 0.0 {
                return Err(format!(
                    "polygon has a reflex corner at {b:?}: it must be convex"
                ));
            }
            turning += s.atan2(dot(e1, e2));
        }
        if turning > 3.0 * PI {
            return Err("polygon winds around more than once (self-intersecting)".into());
        }
        let nrm: Vec<P> = (0..n).map(|i| outward(v[i], v[(i + 1) % n])).collect();
        let pair = |i: usize| (nrm[(i + n - 1) % n], nrm[i]);
        // Offsetting moves corner i along its edges by r tan(θ_i / 2), θ_i the exterior angle.
        let tan_half: Vec<f64> = (0..n)
            .map(|i| {
                let (a, b) = pair(i);
                cross(a, b) / (1.0 + dot(a, b))
            })
            .collect();
        let limit = (0..n)
            .map(|i| norm(sub(v[(i + 1) % n], v[i])) / (tan_half[i] + tan_half[(i + 1) % n]))
            .fold(f64::INFINITY, f64::min);
        if corner_radius >= limit {
            return Err(format!(
                "corner radius {corner_radius} is too large: it must be below {limit} so that every edge of the inward offset (core) polygon keeps a positive length"
            ));
        }
        let core = (0..n)
            .map(|i| {
                let (a, b) = pair(i);
                sub(v[i], mul(corner_radius / (1.0 + dot(a, b)), add(a, b)))
            })
            .collect();
        Ok(Shape::finish(core, corner_radius))
    }

    /// The same shape moved by `d`.
    pub fn translated(&self, d: [f64; 2]) -> Shape {
        let [lo, hi] = self.bbox;
        Shape {
            core: self.core.iter().map(|&c| add(c, d)).collect(),
            radius: self.radius,
            tree: self.tree.as_ref().map(|t| t.translated(d)),
            bbox: [add(lo, d), add(hi, d)],
            deep: (add(self.deep.0, d), self.deep.1),
        }
    }

    /// Radius of the disk swept around the core (0 for a sharp polygon).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The core's points, counter-clockwise.
    pub fn core(&self) -> &[[f64; 2]] {
        &self.core
    }

    /// The corners of a polygon, one per core vertex (none for a circle).
    pub fn corners(&self) -> Vec<Corner> {
        let n = self.core.len();
        if n < 3 {
            return Vec::new();
        }
        (0..n)
            .map(|i| Corner {
                vertex: self.core[i],
                normals: [self.edge_normal((i + n - 1) % n), self.edge_normal(i)],
                radius: self.radius,
            })
            .collect()
    }

    fn edge_normal(&self, i: usize) -> P {
        outward(self.core[i], self.core[(i + 1) % self.core.len()])
    }

    /// Signed distance, outward normal and curvature at x. Inside the core the nearest edge
    /// decides (lowest index on ties); at the centre of a circle the normal is [0, 1].
    pub fn closest(&self, x: [f64; 2]) -> Proximity {
        let (r, n) = (self.radius, self.core.len());
        let from_vertex = |c: P| {
            let d = sub(x, c);
            let l = norm(d);
            if l == 0.0 {
                return Proximity {
                    distance: -r,
                    normal: [0.0, 1.0],
                    curvature: 0.0,
                };
            }
            Proximity {
                distance: l - r,
                normal: mul(1.0 / l, d),
                curvature: 1.0 / l,
            }
        };
        if n == 1 {
            return from_vertex(self.core[0]);
        }
        if let Some(tree) = &self.tree {
            let (d, k, t) = tree.nearest(&self.core, x);
            let line = |i: usize| dot(sub(x, self.core[i]), self.edge_normal(i));
            // Outside a convex core, x is beyond the line of the nearest edge or of one of the
            // two edges at its nearest vertex; inside, the nearest lines are the nearest edges.
            if [k + n - 1, k, k + 1].iter().all(|&i| line(i % n) <= 0.0) {
                let mut best = (f64::NEG_INFINITY, usize::MAX);
                tree.within(&self.core, x, d * (1.0 + 8.0 * f64::EPSILON), &mut |i| {
                    let si = line(i);
                    if si > best.0 || (si == best.0 && i < best.1) {
                        best = (si, i);
                    }
                });
                return Proximity {
                    distance: best.0 - r,
                    normal: self.edge_normal(best.1),
                    curvature: 0.0,
                };
            }
            return self.beyond_edge(x, k, t, from_vertex);
        }
        // Signed distances to the edge lines: their maximum is <= 0 exactly inside the core.
        let (mut s, mut k) = (f64::NEG_INFINITY, 0);
        for i in 0..n {
            let si = dot(sub(x, self.core[i]), self.edge_normal(i));
            if si > s {
                (s, k) = (si, i);
            }
        }
        if s <= 0.0 {
            return Proximity {
                distance: s - r,
                normal: self.edge_normal(k),
                curvature: 0.0,
            };
        }
        let (mut best, mut k, mut t) = (f64::INFINITY, 0, 0.0);
        for i in 0..n {
            let (a, e) = (self.core[i], sub(self.core[(i + 1) % n], self.core[i]));
            let ti = (dot(sub(x, a), e) / dot(e, e)).clamp(0.0, 1.0);
            let d = norm(sub(x, add(a, mul(ti, e))));
            if d < best {
                (best, k, t) = (d, i, ti);
            }
        }
        self.beyond_edge(x, k, t, from_vertex)
    }

    /// Proximity of a point outside the core whose nearest core point is at parameter `t` of
    /// edge `k`: a vertex at an end, else the edge.
    fn beyond_edge(
        &self,
        x: P,
        k: usize,
        t: f64,
        from_vertex: impl Fn(P) -> Proximity,
    ) -> Proximity {
        let n = self.core.len();
        if t == 0.0 {
            from_vertex(self.core[k])
        } else if t == 1.0 {
            from_vertex(self.core[(k + 1) % n])
        } else {
            let m = self.edge_normal(k);
            Proximity {
                distance: dot(sub(x, self.core[k]), m) - self.radius,
                normal: m,
                curvature: 0.0,
            }
        }
    }

    /// Max over the segment [a, b] of -signed distance.
    fn segment_depth(&self, a: P, b: P) -> f64 {
        let (r, n) = (self.radius, self.core.len());
        if n == 1 {
            return r - point_segment(self.core[0], a, b);
        }
        if self.tree.is_some() {
            // -signed distance is concave (the core is convex): its maximum on the segment.
            let at = |t: f64| add(a, mul(t, sub(b, a)));
            return golden_max(|t| -self.closest(at(t)).distance).1;
        }
        // Depth inside the core along the segment, f(τ) = min_i (α_i + β_i τ), is concave and
        // piecewise linear: its maximum on [0, 1] is at an end or where two of the lines cross.
        let lines: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let m = self.edge_normal(i);
                (dot(sub(self.core[i], a), m), -dot(sub(b, a), m))
            })
            .collect();
        let f = |t: f64| {
            lines
                .iter()
                .fold(f64::INFINITY, |m, &(al, be)| m.min(al + be * t))
        };
        let mut best = f(0.0).max(f(1.0));
        for (i, &(ai, bi)) in lines.iter().enumerate() {
            for &(aj, bj) in &lines[i + 1..] {
                let t = (aj - ai) / (bi - bj);
                if bi != bj && t > 0.0 && t < 1.0 {
                    best = best.max(f(t));
                }
            }
        }
        if best >= 0.0 {
            return r + best;
        }
        // The segment misses the core: disjoint convex sets are nearest between their boundaries.
        let d = (0..n)
            .map(|i| segment_segment(a, b, self.core[i], self.core[(i + 1) % n]))
            .fold(f64::INFINITY, f64::min);
        r - d
    }

    /// One deepest point of the shape (a maximiser of -signed distance) and its depth.
    fn deepest(&self) -> (P, f64) {
        self.deep
    }

    /// [`Shape::deepest`], computed once by [`Shape::finish`].
    fn find_deepest(&self) -> (P, f64) {
        let n = self.core.len();
        let mut p = self.core[0];
        if self.tree.is_some() {
            // The least distance inside the edge lines, min_i (c_i − m_i·y), is concave and
            // equals the depth in the core there: golden sections across the box, nested, at
            // O(n) multiply-adds an evaluation (measured: 10 ms for 1000 vertices, where
            // visiting every triple of edges took 1 s).
            let rows: Vec<(P, f64)> = (0..n)
                .map(|i| (self.edge_normal(i), dot(self.edge_normal(i), self.core[i])))
                .collect();
            let inside = |y: P| {
                rows.iter()
                    .fold(f64::INFINITY, |m, &(mi, ci)| m.min(ci - dot(mi, y)))
            };
            let [lo, hi] = self.bbox;
            let at = |u: f64, v: f64| [lo[0] + u * (hi[0] - lo[0]), lo[1] + v * (hi[1] - lo[1])];
            let column = |u: f64| golden_max(|v| inside(at(u, v)));
            let (u, _) = golden_max(|u| column(u).1);
            let (v, depth) = column(u);
            return (at(u, v), depth + self.radius);
        }
        if n >= 3 {
            // Largest circle in the core: the linear programme max t s.t. m_i·y + t <= m_i·v_i,
            // solved by visiting every vertex (triple of active constraints) of its feasible set.
            let rows: Vec<(P, f64)> = (0..n)
                .map(|i| (self.edge_normal(i), dot(self.edge_normal(i), self.core[i])))
                .collect();
            let [lo, hi] = self.bounding_box();
            let tol = 1e-9 * norm(sub(hi, lo));
            let mut best = f64::NEG_INFINITY;
            for (i, &(mi, ci)) in rows.iter().enumerate() {
                for (j, &(mj, cj)) in rows.iter().enumerate().skip(i + 1) {
                    for &(mk, ck) in &rows[j + 1..] {
                        // Subtracting row i from rows j and k leaves a 2×2 system for y.
                        let (a, b, ra, rb) = (sub(mi, mj), sub(mi, mk), ci - cj, ci - ck);
                        let det = cross(a, b);
                        if det.abs() < 1e-12 {
                            continue;
                        }
                        let y = [(ra * b[1] - rb * a[1]) / det, (a[0] * rb - b[0] * ra) / det];
                        let t = ci - dot(mi, y);
                        if t > best && rows.iter().all(|&(m, c)| dot(m, y) + t <= c + tol) {
                            (best, p) = (t, y);
                        }
                    }
                }
            }
        }
        (p, -self.closest(p).distance)
    }

    /// Radius of the largest disk inside the shape: half the body's thickness where it is
    /// thinnest across its middle (a plate's half width, a circle's radius).
    pub fn inradius(&self) -> f64 {
        self.deepest().1
    }

    /// Depth by which the closed triangle `tri` reaches into the shape: max over the triangle of
    /// -signed distance, clamped to >= 0. -signed distance is concave, so its maximum over the
    /// triangle is on an edge (computed exactly by `segment_depth`) or is the global maximum at
    /// an interior deepest point. The set of deepest points is convex: if it meets the triangle
    /// but not its edges, it lies wholly inside, so testing one deepest point suffices.
    /// Cost: O(n²) per edge for n <= 16 core vertices, else O(log n) (golden sections over the
    /// edge tree's distance); the deepest point is computed once per shape.
    pub fn triangle_depth(&self, tri: [[f64; 2]; 3]) -> f64 {
        let [lo, hi] = self.bounding_box();
        if (0..2).any(|k| tri.iter().all(|p| p[k] < lo[k]) || tri.iter().all(|p| p[k] > hi[k])) {
            return 0.0;
        }
        let mut depth = (0..3)
            .map(|i| self.segment_depth(tri[i], tri[(i + 1) % 3]))
            .fold(f64::NEG_INFINITY, f64::max);
        // No edge reaching the core and no core point inside: the triangle misses the core.
        if depth >= self.radius || in_triangle(&tri, self.core[0]) {
            let (p, h) = self.deepest();
            if h > depth && in_triangle(&tri, p) {
                depth = h;
            }
        }
        depth.max(0.0)
    }

    /// Surface points, counter-clockwise, at spacing <= `spacing`. A circle starts at its lowest
    /// point; a polygon at the start of the arc of its lowest (then rightmost) corner (the vertex
    /// itself when sharp). Each edge and each corner arc is divided evenly, so corners are kept.
    /// Panics unless `spacing` is positive and finite.
    pub fn surface_points(&self, spacing: f64) -> Vec<[f64; 2]> {
        assert!(
            spacing > 0.0 && spacing.is_finite(),
            "surface spacing must be positive, got {spacing}"
        );
        let (r, n) = (self.radius, self.core.len());
        let steps = |len: f64| (len / spacing).ceil() as usize;
        let at = |c: P, phi: f64| add(c, mul(r, [phi.cos(), phi.sin()]));
        if n == 1 {
            let m = steps(2.0 * PI * r).max(3);
            return (0..m)
                .map(|k| at(self.core[0], -0.5 * PI + 2.0 * PI * k as f64 / m as f64))
                .collect();
        }
        // Each piece emits its points after its start, so a zero-radius arc adds nothing and
        // its vertex comes once, as the end of the edge before it.
        let mut pts = Vec::new();
        for i in 0..n {
            let (prev, next) = (self.edge_normal((i + n - 1) % n), self.edge_normal(i));
            let angle = cross(prev, next).atan2(dot(prev, next));
            let m = if r > 0.0 { steps(r * angle) } else { 0 };
            let phi0 = prev[1].atan2(prev[0]);
            pts.extend((1..=m).map(|k| at(self.core[i], phi0 + angle * k as f64 / m as f64)));
            let (a, b) = (
                add(self.core[i], mul(r, next)),
                add(self.core[(i + 1) % n], mul(r, next)),
            );
            let m = steps(norm(sub(b, a)));
            pts.extend((1..=m).map(|k| add(a, mul(k as f64 / m as f64, sub(b, a)))));
        }
        pts.rotate_right(1);
        pts
    }

    /// Length of the shape's projection on the unit vector `n`: its width across `n`'s normal.
    pub fn extent_along(&self, n: [f64; 2]) -> f64 {
        let (lo, hi) = self
            .core
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                (lo.min(dot(n, *c)), hi.max(dot(n, *c)))
            });
        hi - lo + 2.0 * self.radius
    }

    /// Axis-aligned bounding box [[xmin, ymin], [xmax, ymax]].
    pub fn bounding_box(&self) -> [[f64; 2]; 2] {
        self.bbox
    }

    /// Area: core area + perimeter(core) r + π r².
    pub fn area(&self) -> f64 {
        let n = self.core.len();
        let (mut a2, mut perimeter) = (0.0, 0.0);
        for i in 0..n {
            let (a, b) = (self.core[i], self.core[(i + 1) % n]);
            a2 += cross(a, b);
            perimeter += norm(sub(b, a));
        }
        0.5 * a2 + perimeter * self.radius + PI * self.radius * self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// Reproducible uniform numbers in [lo, hi) from `seed` (a linear congruential stream).
    fn uniform(seed: u64) -> impl FnMut(f64, f64) -> f64 {
        let mut state = seed;
        move |lo, hi| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Gradient of distance = normal and d(normal)/dx = curvature t tᵀ, by central differences.
    fn check_derivatives(s: &Shape, x: P) {
        let (h, p) = (1e-6, s.closest(x));
        let t = [-p.normal[1], p.normal[0]];
        for j in 0..2 {
            let (mut xp, mut xm) = (x, x);
            xp[j] += h;
            xm[j] -= h;
            let (qp, qm) = (s.closest(xp), s.closest(xm));
            let g = (qp.distance - qm.distance) / (2.0 * h);
            assert!(
                close(g, p.normal[j], 1e-6),
                "at {x:?}: d dist/dx{j} = {g}, normal {:?}",
                p.normal
            );
            for i in 0..2 {
                let dn = (qp.normal[i] - qm.normal[i]) / (2.0 * h);
                assert!(
                    close(dn, p.curvature * t[i] * t[j], 1e-5),
                    "at {x:?}: dn{i}/dx{j} = {dn}, {p:?}"
                );
            }
        }
    }

    fn square(r: f64) -> Shape {
        Shape::polygon(&[[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]], r).unwrap()
    }

    /// Irregular, so the largest inscribed circle is not where the bisectors of a corner meet.
    fn pentagon() -> Shape {
        let v = [
            [-1.2, -0.7],
            [0.9, -0.8],
            [1.3, 0.1],
            [0.2, 0.9],
            [-1.0, 0.4],
        ];
        Shape::polygon(&v, 0.0).unwrap()
    }

    fn rounded_rectangle() -> Shape {
        Shape::polygon(&[[-1.0, -0.5], [1.0, -0.5], [1.0, 0.5], [-1.0, 0.5]], 0.2).unwrap()
    }

    #[test]
    fn circle_distance_normal_curvature() {
        let c = Shape::circle([1.0, -2.0], 0.5).unwrap();
        let p = c.closest([1.0 + 0.6, -2.0 + 0.8]);
        assert!(close(p.distance, 0.5, 1e-15) && close(p.curvature, 1.0, 1e-15));
        assert!(close(p.normal[0], 0.6, 1e-15) && close(p.normal[1], 0.8, 1e-15));
        let p = c.closest([1.2, -2.0]);
        assert!(
            close(p.distance, -0.3, 1e-15)
                && close(p.curvature, 5.0, 1e-12)
                && p.normal == [1.0, 0.0]
        );
        let centre = c.closest([1.0, -2.0]);
        assert_eq!(
            centre,
            Proximity {
                distance: -0.5,
                normal: [0.0, 1.0],
                curvature: 0.0
            }
        );
        for x in [[1.7, -1.1], [0.9, -2.2], [-0.5, -3.0], [1.3, -1.95]] {
            check_derivatives(&c, x);
        }
        assert!(
            Shape::circle([0.0, 0.0], 0.0).is_err() && Shape::circle([0.0, f64::NAN], 1.0).is_err()
        );
        assert!(close(c.area(), PI * 0.25, 1e-15));
        assert_eq!(c.bounding_box(), [[0.5, -2.5], [1.5, -1.5]]);
    }

    #[test]
    fn squares_sharp_and_rounded() {
        let s = square(0.0);
        for (x, d) in [
            ([1.0, 0.5], -0.5),
            ([1.0, 2.5], 0.5),
            ([3.0, 3.0], 2f64.sqrt()),
            ([1.9, 1.0], -0.1),
        ] {
            assert!(close(s.closest(x).distance, d, 1e-15), "{x:?}");
        }
        assert_eq!(s.closest([1.0, 0.5]).normal, [0.0, -1.0]);
        assert_eq!(
            s.closest([1.0, 1.0]).normal,
            [1.0, 0.0],
            "tie: lowest edge index, edge 0 starting at the lowest, rightmost vertex"
        );
        assert!(close(s.area(), 4.0, 1e-15));
        let r = 0.25;
        let q = square(r);
        assert_eq!(
            q.core(),
            &[[1.75, 0.25], [1.75, 1.75], [0.25, 1.75], [0.25, 0.25]]
        );
        let arc = |x: P| norm(sub(x, [1.75, 1.75])) - r;
        for (x, d) in [
            ([2.5, 1.0], 0.5),
            ([1.0, 0.5], -0.5),
            ([2.1, 2.2], arc([2.1, 2.2])),
            ([1.9, 1.85], arc([1.9, 1.85])),
        ] {
            assert!(close(q.closest(x).distance, d, 1e-15), "{x:?}");
        }
        assert!(close(
            q.closest([1.9, 1.85]).curvature,
            1.0 / norm([0.15, 0.1]),
            1e-12
        ));
        assert!(close(q.area(), 4.0 - (4.0 - PI) * r * r, 1e-14));
        for shape in [&s, &q] {
            for x in [
                [1.0, 0.3],
                [2.4, 1.2],
                [2.3, 2.6],
                [-0.4, -0.2],
                [1.95, 1.9],
                [0.6, 1.3],
            ] {
                check_derivatives(shape, x);
            }
        }
    }

    #[test]
    fn polygon_validation() {
        let err = |v: &[P], r: f64| Shape::polygon(v, r).unwrap_err();
        assert!(err(&[[0.0, 0.0], [1.0, 0.0]], 0.0).contains("at least 3"));
        assert!(err(
            &[[0.0, 0.0], [2.0, 0.0], [1.0, 0.5], [2.0, 2.0], [0.0, 2.0]],
            0.0
        )
        .contains("reflex"));
        assert!(err(
            &[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]],
            0.0
        )
        .contains("collinear"));
        let pentagram: Vec<P> = (0..5)
            .map(|k| [(2.5133 * k as f64).cos(), (2.5133 * k as f64).sin()])
            .collect();
        assert!(err(&pentagram, 0.0).contains("more than once"));
        let sq = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        assert!(err(&sq, 1.0).contains("below 1"), "{}", err(&sq, 1.0));
        assert!(err(&sq, 1.5).contains("too large") && err(&sq, -0.1).contains(">= 0"));
        assert!(Shape::polygon(&sq, 0.99).is_ok());
        let mut cw = sq;
        cw.reverse();
        cw.rotate_left(2);
        for r in [0.0, 0.3] {
            assert_eq!(
                Shape::polygon(&cw, r).unwrap(),
                Shape::polygon(&sq, r).unwrap()
            );
        }
    }

    #[test]
    fn triangle_depth_cases() {
        let c = Shape::circle([0.0, 0.0], 1.0).unwrap();
        let s = square(0.0);
        let cases = [
            (&c, [[5.0, 5.0], [6.0, 5.0], [5.0, 6.0]], 0.0, "far away"),
            (&c, [[1.5, 0.0], [3.0, 1.0], [3.0, -1.0]], 0.0, "near"),
            (
                &c,
                [[0.9, 0.0], [3.0, 1.0], [3.0, -1.0]],
                0.1,
                "vertex poking in",
            ),
            (
                &c,
                [[-3.0, -0.05], [3.0, -0.05], [3.0, 0.1]],
                1.0,
                "thin, across the centre",
            ),
            (
                &c,
                [[-5.0, -5.0], [5.0, -5.0], [0.0, 10.0]],
                1.0,
                "enclosing",
            ),
            (
                &s,
                [[0.5, 2.0], [1.5, 2.0], [1.0, 3.0]],
                0.0,
                "edge on the face",
            ),
            (
                &s,
                [[-1.0, 0.98], [3.0, 0.98], [1.0, 1.05]],
                1.0,
                "thin, across the centre",
            ),
            (
                &s,
                [[-1.0, 0.5], [3.0, 0.5], [1.0, 0.55]],
                0.55,
                "thin, off-centre",
            ),
            (&s, [[-1.0, 1.0], [3.0, 1.0], [1.0, 1.0]], 1.0, "degenerate"),
        ];
        for (shape, tri, want, what) in cases {
            let got = shape.triangle_depth(tri);
            assert!(close(got, want, 1e-12), "{what}: {got} instead of {want}");
        }
    }

    #[test]
    fn triangle_depth_matches_sampling() {
        let mut rnd = uniform(12345);
        let n = 60;
        for shape in [
            Shape::circle([0.1, -0.2], 0.8).unwrap(),
            pentagon(),
            rounded_rectangle(),
        ] {
            let mut overlapping = 0;
            for _ in 0..200 {
                let (c, size) = ([rnd(-1.5, 1.5), rnd(-1.5, 1.5)], rnd(0.05, 2.0));
                let tri: [P; 3] =
                    std::array::from_fn(|_| add(c, [rnd(-size, size), rnd(-size, size)]));
                let exact = shape.triangle_depth(tri);
                let mut sampled = 0.0f64;
                for i in 0..=n {
                    for j in 0..=n - i {
                        let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
                        let y = add(
                            add(mul(a, tri[0]), mul(b, tri[1])),
                            mul(1.0 - a - b, tri[2]),
                        );
                        sampled = sampled.max(-shape.closest(y).distance);
                    }
                }
                let diam = (0..3)
                    .map(|i| norm(sub(tri[i], tri[(i + 1) % 3])))
                    .fold(0.0, f64::max);
                assert!(
                    exact >= sampled - 1e-12 && exact <= sampled + diam / n as f64 + 1e-12,
                    "{tri:?}: exact {exact} sampled {sampled}"
                );
                overlapping += (exact > 0.0) as usize;
            }
            assert!(overlapping > 50, "only {overlapping} overlapping triangles");
        }
    }

    /// A 200-gon answers from its edge tree what a scan of every edge answers (issue 32,
    /// finding 5): distance and normal to round-off, depths and the inradius to 1e-12.
    #[test]
    fn many_vertices_answer_as_a_scan_does() {
        let n = 200;
        let v: Vec<P> = (0..n)
            .map(|k| {
                let a = 2.0 * PI * (k as f64 + 0.3) / n as f64;
                [0.3 + 0.8 * a.cos(), -0.1 + 0.35 * a.sin()]
            })
            .collect();
        for r in [0.0, 0.05] {
            let fast = Shape::polygon(&v, r).unwrap();
            assert!(fast.tree.is_some());
            let mut scan = fast.clone();
            scan.tree = None;
            scan.deep = scan.find_deepest();
            assert!(close(fast.inradius(), scan.inradius(), 1e-12));
            let mut rnd = uniform(99);
            for _ in 0..2000 {
                let x = [rnd(-1.0, 1.6), rnd(-0.8, 0.6)];
                let (a, b) = (fast.closest(x), scan.closest(x));
                assert!(close(a.distance, b.distance, 1e-14), "{x:?}: {a:?} {b:?}");
                assert!(close(a.normal[0], b.normal[0], 1e-12), "{x:?}: {a:?} {b:?}");
                assert!(close(a.normal[1], b.normal[1], 1e-12), "{x:?}: {a:?} {b:?}");
                let tri = [x, [x[0] + rnd(-0.3, 0.3), x[1] + 0.1], [x[0] + 0.2, x[1]]];
                let (da, db) = (fast.triangle_depth(tri), scan.triangle_depth(tri));
                assert!(close(da, db, 1e-12), "{tri:?}: {da} against {db}");
            }
        }
    }

    /// Seconds for 400 distance and triangle-depth queries near the boundary of a regular
    /// `n`-gon of radius 1.
    fn query_seconds(n: usize) -> f64 {
        let v: Vec<P> = (0..n)
            .map(|k| {
                let a = 2.0 * PI * k as f64 / n as f64;
                [a.cos(), a.sin()]
            })
            .collect();
        let shape = Shape::polygon(&v, 0.0).unwrap();
        let start = std::time::Instant::now();
        let mut sum = 0.0;
        for j in 0..400 {
            let a = 0.0157 * j as f64;
            let x = [1.01 * a.cos(), 1.01 * a.sin()];
            sum += shape.closest(x).distance;
            let tri = [x, mul(0.97, x), add(mul(0.97, x), [0.02, 0.0])];
            sum += shape.triangle_depth(tri);
        }
        assert!(sum.is_finite());
        start.elapsed().as_secs_f64()
    }

    /// Issue 32, finding 5: a 1000-vertex polygon took 5–10 s a remesh on 341 particles, its
    /// queries scanning every edge (and every triple of edges for the deepest point). 32 times
    /// the vertices now cost a few times the time, not 32 (closest) or 1000 (depth) times.
    #[test]
    fn query_cost_grows_with_the_logarithm_of_the_vertex_count() {
        let (small, large) = (query_seconds(64), query_seconds(2048));
        assert!(
            large < 8.0 * small + 0.01,
            "64 vertices {small} s, 2048 {large} s"
        );
    }

    #[test]
    fn surface_points_on_surface_and_evenly_spaced() {
        let circle = Shape::circle([0.3, 0.4], 1.0).unwrap();
        assert_eq!(circle.surface_points(0.1).len(), 63);
        assert_eq!(square(0.0).surface_points(0.1)[0], [2.0, 0.0]);
        assert_eq!(square(0.0).surface_points(0.5).len(), 16);
        for shape in [
            circle,
            square(0.0),
            square(0.3),
            pentagon(),
            rounded_rectangle(),
        ] {
            let [lo, hi] = shape.bounding_box();
            let size = norm(sub(hi, lo));
            let pts = shape.surface_points(0.1);
            let mut area2 = 0.0;
            for (k, &p) in pts.iter().enumerate() {
                assert!(shape.closest(p).distance.abs() < 1e-12 * size, "{p:?}");
                let q = pts[(k + 1) % pts.len()];
                let d = norm(sub(q, p));
                assert!((0.05..=0.1 + 1e-12).contains(&d), "spacing {d} from {p:?}");
                area2 += cross(p, q);
            }
            assert!(area2 > 0.0, "counter-clockwise");
        }
    }

    #[test]
    fn translated_shifts_everything() {
        let d = [3.0, -1.5];
        for s in [rounded_rectangle(), Shape::circle([0.0, 0.0], 0.7).unwrap()] {
            let t = s.translated(d);
            assert_eq!(t.radius(), s.radius());
            assert!(close(t.area(), s.area(), 1e-14));
            let ([lo, hi], [tlo, thi]) = (s.bounding_box(), t.bounding_box());
            assert!((0..2)
                .all(|k| close(tlo[k], lo[k] + d[k], 1e-14) && close(thi[k], hi[k] + d[k], 1e-14)));
            for x in [[0.3, 0.2], [1.5, 1.0], [-0.2, -0.9]] {
                let (a, b) = (s.closest(x), t.closest(add(x, d)));
                assert!(
                    close(a.distance, b.distance, 1e-14) && close(a.curvature, b.curvature, 1e-12)
                );
            }
            // A spacing far from dividing any length evenly, so both get the same point count.
            let (sp, tp) = (s.surface_points(0.17), t.surface_points(0.17));
            assert_eq!(sp.len(), tp.len());
            for (p, q) in sp.iter().zip(tp) {
                assert!(close(q[0], p[0] + d[0], 1e-14) && close(q[1], p[1] + d[1], 1e-14));
            }
            let tri = [[-0.5, 0.1], [0.9, 0.2], [0.1, 1.4]];
            let moved = tri.map(|p| add(p, d));
            assert!(close(s.triangle_depth(tri), t.triangle_depth(moved), 1e-14));
        }
    }
}
