//! Node-to-rigid-surface contact as a complementarity law solved inside Newton (a primal–dual
//! active set in its semi-smooth Newton form), frictionless or with the interface shear limited
//! to α·cu (Tresca).
//!
//! The contact force is not an unknown of its own: at a contact node it is what the soil needs
//! there, the node's residual `R` (internal less external force, contact aside). Its normal
//! pressure p = n·R/w and shear τ = −t·R/w (w the boundary length the node stands for, by
//! Simpson's rule on the P2 edges) must satisfy, with g the gap to the body:
//! - normal: p ≥ 0, g ≥ 0, p g = 0, i.e. C_N = p − max(0, p − c g) = 0;
//! - tangential (Tresca): τ = proj[−s, s](τ + c v), v the slip of the increment along t.
//!
//! The max and the projection pick, at every residual, which nodes touch (p − c g > 0) and which
//! stick (|τ + c v| ≤ s); the node's two residual rows are then replaced by the active branch:
//! g = 0 (scaled by E/h so its size is a force's), v = 0 when it sticks, t·R + w s sign = 0
//! when it slips, R = 0 when it is free. The Jacobian is the derivative of that branch, with
//! the turning of n and t on a curved body (friction's non-symmetric part). So the active set
//! is decided at every Newton iteration and Newton converges quadratically once it settles.
//!
//! The complementarity constant c only weighs pressure against gap in the decision while
//! Newton is away from the solution: the converged pressures and gaps do not depend on it.

use super::shape::{Proximity, Shape};

/// One soil node facing one rigid body in an increment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPair {
    /// Local node index.
    pub node: u32,
    /// Index of the rigid body.
    pub body: u32,
    /// A second body moved with `body` (a cone and the shaft above it; `body` itself when
    /// none): the node is held against their union, whichever of the two it is nearer at each
    /// iterate. Where a node slides from one onto the other within an increment, a law against
    /// the first alone would pull it into the second, around the first one's hidden corner.
    pub partner: u32,
    /// The partner's α·cu (Pa): a rough cone under a smooth shaft (the sleeve's friction is
    /// not the cone's resistance) holds a node by the strength of the face it is on.
    pub partner_shear_limit: f64,
    /// Node position at the start of the increment.
    pub start: [f64; 2],
    /// Boundary length the node stands for (m per metre).
    pub weight: f64,
    /// Complementarity constant c (Pa/m) of the active-set decision p − c g > floor.
    pub constant: f64,
    /// Scale (Pa/m, E/h) of the constraint rows g = 0 and v = 0: their residual then has the
    /// size of a force, like the equilibrium rows beside them.
    pub row_scale: f64,
    /// α·cu (Pa); 0 = frictionless.
    pub shear_limit: f64,
    /// The body's displacement over the increment.
    pub body_increment: [f64; 2],
    /// Penetration tolerated without reaction (m, <= 0): the node's signed distance to the body
    /// at the start of the increment when it was already inside. A straight-sided P2 edge
    /// between two nodes on a curved face has its midside node inside by the sagitta h²/8R;
    /// pushing it out would fight the element's geometry, so the gap is measured from there.
    pub offset: f64,
    /// Touching the body at the start of the increment: only such a node may hold suction
    /// (suction does not reach across a gap).
    pub touching: bool,
    /// Suction (Pa, >= 0) a touching node carries before it separates: the pressure may fall
    /// to −suction (an ambient pressure the soil is modelled without).
    pub suction: f64,
    /// Which of the node's components are free (not prescribed). A node with one prescribed
    /// component (on a symmetry plane) takes the normal law in its free component only.
    pub free: [bool; 2],
}

/// Where a contact node is at an iterate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Status {
    /// Not touching: no contact force.
    #[default]
    Free,
    /// Touching without slip (or frictionless and touching: then only the normal is held).
    Stick,
    /// Touching and slipping along ±t with shear ±α·cu.
    Slip(i8),
}

/// The contact law of one node at one iterate: its residual rows, their derivative, the
/// force and the interface state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeLaw {
    pub status: Status,
    /// The body the node is held against at this iterate (the pair's body or its partner).
    pub body: u32,
    /// The node's residual rows (component x, y; only free components are rows).
    pub rows: [f64; 2],
    /// The rows' dependence on the element rows: row i = Σ_j transform[i][j] R_j + (rest).
    pub transform: [[f64; 2]; 2],
    /// The rest of d rows / d u at the node's own displacement (row-major).
    pub local: [[f64; 2]; 2],
    /// Force of the body on the node (N per metre): R where it touches.
    pub force: [f64; 2],
    /// Normal pressure and shear along t = (−n_y, n_x) (Pa); 0 when free.
    pub pressure: f64,
    pub shear: f64,
    /// Signed distance to the body (m), negative inside, less the tolerated offset.
    pub gap: f64,
}

/// A normal this close to a prescribed component leaves too little of it in the free one to
/// hold the gap: such a node of a symmetry plane stays free (a body symmetric about the plane
/// meets it square, |n_free| = 1).
const MIN_FREE_NORMAL: f64 = 0.1;

/// The law of `pair` against the nearer of its body and its partner (`shapes`: every body at
/// the end of the increment, by index), the lower index on a tie. The union of two bodies is
/// the body with the smaller signed distance; where the two faces meet tangentially (the
/// built-in cone's face and its shaft's arc) the law changes body without a jump.
pub fn node_law_among(pair: &ContactPair, shapes: &[Shape], u: [f64; 2], r: [f64; 2]) -> NodeLaw {
    let (a, b) = (pair.body.min(pair.partner), pair.body.max(pair.partner));
    if a == b {
        return node_law(pair, &shapes[a as usize], u, r);
    }
    let x = [pair.start[0] + u[0], pair.start[1] + u[1]];
    let (near_a, near_b) = (shapes[a as usize].closest(x), shapes[b as usize].closest(x));
    let (nearer, prox) = if near_b.distance < near_a.distance {
        (b, near_b)
    } else {
        (a, near_a)
    };
    let facing = if nearer == pair.body {
        *pair
    } else {
        ContactPair {
            body: nearer,
            shear_limit: pair.partner_shear_limit,
            ..*pair
        }
    };
    law_at(&facing, &prox, u, r)
}

/// The law of `pair` at its increment displacement `u`, against `shape` (its body at the end
/// of the increment), where the soil's residual at the node is `r`.
pub fn node_law(pair: &ContactPair, shape: &Shape, u: [f64; 2], r: [f64; 2]) -> NodeLaw {
    let x = [pair.start[0] + u[0], pair.start[1] + u[1]];
    law_at(pair, &shape.closest(x), u, r)
}

/// [`node_law`] with the body's proximity at the node's position already found.
fn law_at(pair: &ContactPair, prox: &Proximity, u: [f64; 2], r: [f64; 2]) -> NodeLaw {
    let n = prox.normal;
    let t = [-n[1], n[0]];
    let kappa = prox.curvature;
    let gap = prox.distance - pair.offset;
    let w = pair.weight;
    let (c, scale) = (pair.constant, pair.row_scale);
    let floor = if pair.touching { -pair.suction } else { 0.0 };
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    // Let go, a touching node is still pulled by its suction: the ambient pressure the soil is
    // modelled without acts on it across the opening gap (the branch p = −suction, which keeps
    // the law semi-smooth: such a node comes back when it would penetrate).
    let pull = -floor;
    let free = NodeLaw {
        status: Status::Free,
        body: pair.body,
        rows: [r[0] + pull * w * n[0], r[1] + pull * w * n[1]],
        transform: [[1.0, 0.0], [0.0, 1.0]],
        local: std::array::from_fn(|i| std::array::from_fn(|j| pull * w * kappa * t[i] * t[j])),
        force: [-pull * w * n[0], -pull * w * n[1]],
        pressure: -pull,
        shear: 0.0,
        gap,
    };
    match pair.free {
        [true, true] => {}
        [false, false] => return free,
        [fx, _] => {
            let f = if fx { 0 } else { 1 };
            if n[f].abs() < MIN_FREE_NORMAL {
                return NodeLaw {
                    rows: r,
                    local: [[0.0; 2]; 2],
                    force: [0.0; 2],
                    pressure: 0.0,
                    ..free
                };
            }
            // The prescribed component's reaction takes the rest of the force.
            let p = r[f] / (w * n[f]);
            if p - c * gap <= floor {
                return free;
            }
            let mut law = NodeLaw {
                status: Status::Stick,
                rows: [0.0; 2],
                transform: [[0.0; 2]; 2],
                local: [[0.0; 2]; 2],
                force: [p * w * n[0], p * w * n[1]],
                pressure: p,
                ..free
            };
            law.rows[f] = scale * w * gap;
            law.local[f] = [scale * w * n[0], scale * w * n[1]];
            return law;
        }
    }
    let p = dot(n, r) / w;
    if p - c * gap <= floor {
        return free;
    }
    let tau = -dot(t, r) / w;
    // The normal row takes the slot of the normal's larger component, the tangential row the
    // other: each row then keeps a diagonal of the size of its own.
    let (a, b) = if n[0].abs() > n[1].abs() {
        (0, 1)
    } else {
        (1, 0)
    };
    let mut law = NodeLaw {
        status: Status::Stick,
        body: pair.body,
        rows: [0.0; 2],
        transform: [[0.0; 2]; 2],
        local: [[0.0; 2]; 2],
        force: r,
        pressure: p,
        shear: tau,
        gap,
    };
    // Normal: the gap closes; dg/dx = n.
    law.rows[a] = scale * w * gap;
    law.local[a] = [scale * w * n[0], scale * w * n[1]];
    // dn/dx = κ t tᵀ and dt/dx = −κ n tᵀ, so d(t·R) = tᵀ dR − κ (n·R) tᵀ dx.
    let turning = -kappa * dot(n, r);
    let d = [u[0] - pair.body_increment[0], u[1] - pair.body_increment[1]];
    let slip = dot(d, t);
    let trial = tau + c * slip;
    if pair.shear_limit > 0.0 && trial.abs() <= pair.shear_limit {
        // Sticks: no slip over the increment along the current tangent.
        let dv = scale * w * (1.0 - kappa * dot(d, n));
        law.rows[b] = scale * w * slip;
        law.local[b] = [dv * t[0], dv * t[1]];
        return law;
    }
    // Slips (frictionless: always, with no shear): t·R = −w s sign.
    let sign = if pair.shear_limit > 0.0 {
        trial.signum()
    } else {
        0.0
    };
    law.status = if pair.shear_limit > 0.0 {
        Status::Slip(sign as i8)
    } else {
        Status::Stick
    };
    law.rows[b] = dot(t, r) + w * pair.shear_limit * sign;
    law.transform[b] = t;
    law.local[b] = [turning * t[0], turning * t[1]];
    law.shear = pair.shear_limit * sign;
    law
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair(shear_limit: f64) -> ContactPair {
        ContactPair {
            node: 0,
            body: 0,
            partner: 0,
            partner_shear_limit: 0.0,
            start: [0.3, -0.96],
            weight: 0.05,
            constant: 1e6,
            row_scale: 1e6,
            shear_limit,
            body_increment: [0.001, -0.002],
            offset: 0.0,
            touching: false,
            suction: 0.0,
            free: [true, true],
        }
    }

    /// The soil as a linear spring at the node: R(u) = K u + f.
    const K: [[f64; 2]; 2] = [[3e5, -4e4], [1e4, 2e5]];

    fn soil(u: [f64; 2], f: [f64; 2]) -> [f64; 2] {
        std::array::from_fn(|i| K[i][0] * u[0] + K[i][1] * u[1] + f[i])
    }

    /// The rows' derivative transform·K + local against central differences of the rows.
    fn check_tangent(pair: &ContactPair, shape: &Shape, u: [f64; 2], f: [f64; 2]) -> Status {
        let law = node_law(pair, shape, u, soil(u, f));
        let analytic: [[f64; 2]; 2] = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                law.transform[i][0] * K[0][j] + law.transform[i][1] * K[1][j] + law.local[i][j]
            })
        });
        let h = 1e-8;
        let scale = analytic
            .iter()
            .flatten()
            .fold(1e-12_f64, |m, v| m.max(v.abs()));
        for j in 0..2 {
            let (mut up, mut um) = (u, u);
            up[j] += h;
            um[j] -= h;
            let (lp, lm) = (
                node_law(pair, shape, up, soil(up, f)),
                node_law(pair, shape, um, soil(um, f)),
            );
            assert_eq!(lp.status, law.status, "the branch is the same either side");
            for (i, row) in analytic.iter().enumerate() {
                let fd = (lp.rows[i] - lm.rows[i]) / (2.0 * h);
                assert!(
                    (fd - row[j]).abs() < 1e-5 * scale,
                    "d row{i}/d u{j}: analytic {} finite difference {fd} ({:?})",
                    row[j],
                    law.status
                );
            }
        }
        law.status
    }

    #[test]
    fn tangents_match_finite_differences_on_every_branch() {
        let circle = Shape::circle([0.0, 0.0], 1.0).unwrap();
        // Near the circle's bottom, the soil pushing the node against it: touching.
        let u = [0.002, 0.003];
        let push = [2e3, -5e3];
        assert_eq!(check_tangent(&pair(0.0), &circle, u, push), Status::Stick);
        assert_eq!(check_tangent(&pair(1e9), &circle, u, push), Status::Stick);
        assert!(matches!(
            check_tangent(&pair(50.0), &circle, u, push),
            Status::Slip(_)
        ));
        // Pulled away from the body with a gap: free.
        let mut away = pair(0.0);
        away.start = [0.3, -1.2];
        assert_eq!(
            check_tangent(&away, &circle, [0.0; 2], [0.0; 2]),
            Status::Free
        );
        // Let go while it held suction: pulled by it across the gap.
        away.touching = true;
        away.suction = 1e4;
        assert_eq!(
            check_tangent(&away, &circle, [0.0; 2], [0.0; 2]),
            Status::Free
        );
        assert_eq!(node_law(&away, &circle, [0.0; 2], [0.0; 2]).pressure, -1e4);
        // A flat face, and a node on a symmetry plane (x prescribed).
        let square =
            Shape::polygon(&[[-1.0, -2.0], [1.0, -2.0], [1.0, -1.0], [-1.0, -1.0]], 0.0).unwrap();
        let mut p = pair(1e9);
        p.start = [0.2, -0.99];
        assert_eq!(check_tangent(&p, &square, u, [3e2, 4e3]), Status::Stick);
        p.free = [false, true];
        assert_eq!(check_tangent(&p, &square, u, [3e2, 4e3]), Status::Stick);
    }

    #[test]
    fn touching_rows_hold_the_gap_and_the_force_is_the_soils() {
        let square =
            Shape::polygon(&[[-1.0, -2.0], [1.0, -2.0], [1.0, -1.0], [-1.0, -1.0]], 0.0).unwrap();
        let mut p = pair(0.0);
        p.start = [0.2, -0.99];
        // On the face (gap 0), the soil pushing up with 400 N/m: p = 400 / w.
        let law = node_law(&p, &square, [0.0, -0.01], [0.0, 400.0]);
        assert_eq!(law.status, Status::Stick);
        assert!(law.rows[1].abs() < 1e-9, "the gap row: {}", law.rows[1]);
        assert_eq!(law.rows[0], 0.0, "frictionless: no shear");
        assert!((law.pressure - 400.0 / 0.05).abs() < 1e-9);
        assert_eq!(law.force, [0.0, 400.0]);
        // Pulling (tension) lets go, unless the node touched and suction holds it.
        let pull = node_law(&p, &square, [0.0, -0.01], [0.0, -400.0]);
        assert_eq!(pull.status, Status::Free);
        p.touching = true;
        p.suction = 1e4;
        let held = node_law(&p, &square, [0.0, -0.01], [0.0, -400.0]);
        assert_eq!(held.status, Status::Stick);
        // Slipping shear is α·cu against the slip.
        let mut rough = pair(500.0);
        rough.start = [0.2, -0.99];
        rough.body_increment = [0.0, 0.0];
        let slide = node_law(&rough, &square, [0.01, -0.01], [0.0, 400.0]);
        assert_eq!(
            slide.status,
            Status::Slip(-1),
            "t = (-1, 0) on the top face"
        );
        assert_eq!(slide.shear, -500.0);
        assert!((slide.rows[0] - (-0.05 * 500.0)).abs() < 1e-12);
    }

    /// The built-in cone and its shaft in units of the shaft's radius: the shaft's corner arc
    /// is tangent to the cone's face just below the cone's (hidden) top corner.
    fn cone_and_shaft() -> (Vec<Shape>, [f64; 2], f64) {
        let (top, base, r2) = ([0.928_18, 1.607_66], 1.189_40, 0.745_1);
        let cone = Shape::polygon(&[[0.0, 0.0], top, [-top[0], top[1]]], 0.028).unwrap();
        let shaft =
            Shape::polygon(&[[1.0, base], [1.0, 10.0], [-1.0, 10.0], [-1.0, base]], r2).unwrap();
        (vec![cone, shaft], [1.0 - r2, base + r2], r2)
    }

    #[test]
    fn a_node_held_against_two_bodies_follows_their_union() {
        let (shapes, centre, r2) = cone_and_shaft();
        let on_arc = |deg: f64| {
            let a = deg.to_radians();
            [centre[0] + r2 * a.cos(), centre[1] + r2 * a.sin()]
        };
        // On the shaft's arc 15° past where it leaves the cone's face (the face's normal points
        // 30° below the horizontal), the soil's residual along the normal: it presses on.
        let x = on_arc(-15.0);
        let n = [(-15f64).to_radians().cos(), (-15f64).to_radians().sin()];
        let push = [400.0 * n[0], 400.0 * n[1]];
        let mut p = pair(0.0);
        p.start = x;
        p.body_increment = [0.0; 2];
        p.partner = 1;
        let law = node_law_among(&p, &shapes, [0.0; 2], push);
        assert_eq!((law.status, law.body), (Status::Stick, 1));
        assert!(law.gap.abs() < 1e-9, "on the union's face: gap {}", law.gap);
        // Against the cone alone the node is off its face: held there, it would be pulled into
        // the shaft around the cone's top corner.
        let cone_only = node_law(&p, &shapes[0], [0.0; 2], push);
        assert!(cone_only.gap > 0.05, "gap to the cone {}", cone_only.gap);
        // The pair's order does not matter, and below the tangent point the cone holds it.
        let swapped = ContactPair {
            body: 1,
            partner: 0,
            ..p
        };
        assert_eq!(node_law_among(&swapped, &shapes, [0.0; 2], push), law);
        // A rough shaft over a smooth cone: on the arc the node takes the shaft's strength
        // (it sticks and carries the soil's shear), on the cone's face none.
        let tangential = [push[0] - 100.0 * n[1], push[1] + 100.0 * n[0]];
        let rough_shaft = ContactPair {
            partner_shear_limit: 1e9,
            ..p
        };
        let on_shaft = node_law_among(&rough_shaft, &shapes, [0.0; 2], tangential);
        assert_eq!((on_shaft.status, on_shaft.body), (Status::Stick, 1));
        assert!(
            (on_shaft.shear.abs() - 100.0 / p.weight).abs() < 1e-6,
            "{}",
            on_shaft.shear
        );
        let smooth = node_law_among(&p, &shapes, [0.0; 2], tangential);
        assert_eq!(smooth.shear, 0.0);
        let face = [0.5 * 0.928_18, 0.5 * 1.607_66];
        let below = ContactPair { start: face, ..p };
        let law = node_law_among(&below, &shapes, [0.0; 2], [346.4, -200.0]);
        assert_eq!((law.status, law.body), (Status::Stick, 0));
        assert!(law.gap.abs() < 1e-9, "on the cone's face: gap {}", law.gap);
    }
}
