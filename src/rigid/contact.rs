//! Node-to-rigid-surface contact by penalty with augmentation (Uzawa), frictionless or with
//! the interface shear limited to α·cu.
//!
//! Each soil boundary node carries a weight: its share of the boundary length by Simpson's rule
//! on the P2 edges (L/6, 4L/6, L/6), so equal node pressures are the consistent nodal forces of
//! a uniform traction and a flat punch on a homogeneous block gives the exact uniform pressure.
//! The normal pressure is p = max(0, λ − ε_N g) with g the signed distance of the node to the
//! body at the end of the increment and λ the augmented multiplier; after Newton converges,
//! λ ← p until the multipliers settle, so the penetration vanishes however soft the penalty.
//! The shear τ is a stick penalty on the tangential slip of the increment; a node whose stick
//! shear exceeds α·cu slips with ±α·cu.
//!
//! Which nodes touch is fixed during a Newton solve (the active set): a node whose pressure
//! would pass through zero keeps its penalty spring until the solve converges, and only then is
//! released (or a free node that penetrated is taken in), before the next solve. Letting nodes
//! switch inside Newton makes a stiff penalty cycle: a full step pushes a node just out, the
//! next pulls it back in. Should the set itself keep changing between solves, it is kept after
//! half the allowed solves and only the multipliers converge.

use super::shape::Shape;

/// One soil node facing one rigid body in an increment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPair {
    /// Local node index.
    pub node: u32,
    /// Index of the rigid body.
    pub body: u32,
    /// Node position at the start of the increment.
    pub start: [f64; 2],
    /// Boundary length the node stands for (m per metre).
    pub weight: f64,
    /// Normal and tangential penalty (Pa/m).
    pub penalty: f64,
    /// Augmented normal pressure (Pa), updated between Newton solves.
    pub multiplier: f64,
    /// Shear stress at the start of the increment (Pa), along t = (−n_y, n_x).
    pub shear_start: f64,
    /// α·cu (Pa); 0 = frictionless.
    pub shear_limit: f64,
    /// The body's displacement over the increment.
    pub body_increment: [f64; 2],
    /// Penetration tolerated without reaction (m, <= 0): the node's signed distance to the body
    /// at the start of the increment when it was already inside. A straight-sided P2 edge
    /// between two nodes on a curved face has its midside node inside by the sagitta h²/8R;
    /// pushing it out would fight the element's geometry, so the gap is measured from there.
    pub offset: f64,
    /// In the active set: its penalty spring acts during this Newton solve.
    pub active: bool,
    /// Suction (Pa, >= 0) the interface carries before it separates: the pressure may fall
    /// to −suction (an ambient pressure the soil is modelled without).
    pub suction: f64,
    /// Interface state during this Newton solve: 0 sticks (shear from the penalty), ±1 slips
    /// with shear ±α·cu. Decided between solves, like the active set.
    pub slip: i8,
    /// How much the multiplier changed at the last augmentation (Pa; 0 before the first): a
    /// node whose change does not shrink is stiffened (see `StepProblem::augment`).
    pub last_change: f64,
    /// How many times its penalty has been raised tenfold in this increment.
    pub raised: u8,
}

/// How many times [`ContactPair::stiffen_if_stalled`] may raise a node's penalty tenfold.
pub const MAX_PENALTY_RAISES: u8 = 3;

impl ContactPair {
    /// Called after each Newton solve with the change of the node's multiplier at this
    /// augmentation (Pa): raises the penalty tenfold (at most [`MAX_PENALTY_RAISES`] times) when
    /// the change is above `settled` and more than a quarter of the last change, and says so.
    ///
    /// The update contracts by K/(K + ε) for a node of stiffness K against its spring ε: an
    /// ordinary node is a thousand times softer than its spring and settles in two or three
    /// solves, but a node next to a very short boundary edge was measured ten times stiffer
    /// (the T-bar at 1.46D), where its multiplier crept by a factor 0.9 a solve and the step
    /// failed. The converged pressures do not depend on the penalty, so raising it changes how
    /// fast they are found, not what they are.
    pub fn stiffen_if_stalled(&mut self, change: f64, settled: f64) -> bool {
        let stalled = change > settled
            && self.last_change > 0.0
            && change > 0.25 * self.last_change
            && self.raised < MAX_PENALTY_RAISES;
        self.last_change = change;
        if stalled {
            self.penalty *= 10.0;
            self.raised += 1;
        }
        stalled
    }
}

/// Force of the body on the node, its derivative and the interface state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairForce {
    /// Force on the node (N per metre).
    pub force: [f64; 2],
    /// d force / d u, row-major.
    pub tangent: [[f64; 2]; 2],
    /// Normal pressure (Pa); for an inactive node the pressure it would have if it touched
    /// (the next active set takes it in when that is positive).
    pub pressure: f64,
    /// Shear stress along t (Pa).
    pub shear: f64,
    /// The stick shear the penalty would give (Pa), and the node's slip along t relative to the
    /// body over the increment (m): the next solve's stick/slip decision.
    pub shear_trial: f64,
    pub slip: f64,
    /// Signed distance to the body (m), negative inside, less the tolerated offset.
    pub gap: f64,
}

/// Evaluates the pair at the node's increment displacement `u`, against `shape` (the body at the
/// end of the increment).
pub fn pair_force(pair: &ContactPair, shape: &Shape, u: [f64; 2]) -> PairForce {
    let x = [pair.start[0] + u[0], pair.start[1] + u[1]];
    let prox = shape.closest(x);
    let n = prox.normal;
    let t = [-n[1], n[0]];
    let kappa = prox.curvature;
    let eps = pair.penalty;
    let p = pair.multiplier - eps * (prox.distance - pair.offset);
    let none = PairForce {
        force: [0.0; 2],
        tangent: [[0.0; 2]; 2],
        pressure: 0.0,
        shear: 0.0,
        shear_trial: 0.0,
        slip: 0.0,
        gap: prox.distance - pair.offset,
    };
    if !pair.active {
        return PairForce {
            pressure: p,
            ..none
        };
    }
    // Slip of the node relative to the body over the increment, along the current tangent.
    let d = [u[0] - pair.body_increment[0], u[1] - pair.body_increment[1]];
    let (mut tau, mut dtau, mut trial) = (0.0, 0.0, 0.0);
    let slip = d[0] * t[0] + d[1] * t[1];
    if pair.shear_limit > 0.0 {
        trial = pair.shear_start + eps * slip;
        if pair.slip == 0 {
            tau = trial;
            dtau = eps * (1.0 - kappa * (d[0] * n[0] + d[1] * n[1]));
        } else {
            tau = pair.shear_limit * f64::from(pair.slip);
        }
    }
    let w = pair.weight;
    let force = [w * (p * n[0] - tau * t[0]), w * (p * n[1] - tau * t[1])];
    // d(p n)/dx = −ε n nᵀ + p κ t tᵀ;  d(τ t)/dx = dτ t tᵀ − τ κ n tᵀ.
    let tangent = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            w * (-eps * n[i] * n[j] + p * kappa * t[i] * t[j] - dtau * t[i] * t[j]
                + tau * kappa * n[i] * t[j])
        })
    });
    PairForce {
        force,
        tangent,
        pressure: p,
        shear: tau,
        shear_trial: trial,
        slip,
        gap: prox.distance - pair.offset,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair(shear_limit: f64, shear_start: f64) -> ContactPair {
        ContactPair {
            node: 0,
            body: 0,
            start: [0.3, -1.02],
            weight: 0.05,
            penalty: 1e6,
            multiplier: 1e5,
            shear_start,
            shear_limit,
            body_increment: [0.001, -0.002],
            offset: 0.0,
            active: true,
            suction: 0.0,
            slip: 0,
            last_change: 0.0,
            raised: 0,
        }
    }

    fn check_tangent(pair: &ContactPair, shape: &Shape, u: [f64; 2]) {
        let f = pair_force(pair, shape, u);
        let h = 1e-7;
        for j in 0..2 {
            let mut up = u;
            let mut um = u;
            up[j] += h;
            um[j] -= h;
            let (fp, fm) = (pair_force(pair, shape, up), pair_force(pair, shape, um));
            for i in 0..2 {
                let fd = (fp.force[i] - fm.force[i]) / (2.0 * h);
                let scale = f
                    .tangent
                    .iter()
                    .flatten()
                    .fold(1e-12_f64, |m, v| m.max(v.abs()));
                assert!(
                    (fd - f.tangent[i][j]).abs() < 1e-6 * scale,
                    "d f{i}/d u{j}: analytic {} finite difference {fd}",
                    f.tangent[i][j]
                );
            }
        }
    }

    #[test]
    fn tangents_match_finite_differences() {
        let circle = Shape::circle([0.0, 0.0], 1.0).unwrap();
        let u = [0.002, 0.003];
        // Frictionless, stick and slip, on a curved surface.
        check_tangent(&pair(0.0, 0.0), &circle, u);
        check_tangent(&pair(1e9, 100.0), &circle, u);
        let mut slipping = pair(500.0, 450.0);
        slipping.slip = 1;
        check_tangent(&slipping, &circle, u);
        let square =
            Shape::polygon(&[[-1.0, -2.0], [1.0, -2.0], [1.0, -1.0], [-1.0, -1.0]], 0.0).unwrap();
        let mut p = pair(1e9, -30.0);
        p.start = [0.2, -0.99];
        check_tangent(&p, &square, u);
    }

    /// A node of stiffness `k` held by the soil at `d` (inside the body when negative) against
    /// a flat body at 0: the solve gives u = (k d + λ)/(k + ε), and the exact pressure is −k d.
    /// Returns the solves it takes the multiplier to settle to 1e-6, with or without stiffening.
    fn uzawa_solves(k: f64, stiffen: bool) -> usize {
        let mut c = pair(0.0, 0.0);
        let d = -1e-3;
        c.multiplier = 0.0;
        for solve in 1..10_000 {
            let u = (k * d + c.multiplier) / (k + c.penalty);
            let p = c.multiplier - c.penalty * u;
            let change = (p - c.multiplier).abs();
            if stiffen {
                c.stiffen_if_stalled(change, 1e-7 * k * d.abs());
            }
            c.multiplier = p;
            if change <= 1e-6 * p.abs() {
                assert!(
                    (p + k * d).abs() <= 1e-5 * p.abs(),
                    "{p} against {}",
                    -k * d
                );
                return solve;
            }
        }
        panic!("did not settle");
    }

    #[test]
    fn a_node_stiffer_than_its_penalty_settles_once_the_penalty_is_raised() {
        // An ordinary node, a thousand times softer than its spring: 3 solves either way.
        assert_eq!(uzawa_solves(1e3, false), 3);
        assert_eq!(uzawa_solves(1e3, true), 3);
        // Nine times stiffer (the creep of 0.9 a solve measured on the T-bar): about 150
        // solves without raising the penalty, a handful with it.
        let (slow, fast) = (uzawa_solves(9e6, false), uzawa_solves(9e6, true));
        assert!(slow > 100, "{slow}");
        assert!(fast <= 8, "{fast}");
    }

    #[test]
    fn frictionless_force_is_normal_and_shear_is_capped() {
        let circle = Shape::circle([0.0, 0.0], 1.0).unwrap();
        let f = pair_force(&pair(0.0, 0.0), &circle, [0.01, 0.0]);
        assert!(f.pressure > 0.0);
        let x = [0.31, -1.02];
        let cross = f.force[0] * x[1] - f.force[1] * x[0];
        assert!(cross.abs() < 1e-12 * f.force[0].abs().max(f.force[1].abs()));
        assert_eq!(f.shear, 0.0);
        let mut slipping = pair(500.0, 450.0);
        slipping.slip = -1;
        let f = pair_force(&slipping, &circle, [0.05, 0.0]);
        assert_eq!(f.shear, -500.0);
        let stuck = pair_force(&pair(500.0, 450.0), &circle, [0.05, 0.0]);
        assert!(stuck.shear_trial.abs() > 500.0, "the next solve slips");
        // Far from the body: no force.
        let mut away = pair(0.0, 0.0);
        away.start = [2.0, 2.0];
        away.multiplier = 0.0;
        away.active = false;
        assert_eq!(pair_force(&away, &circle, [0.0; 2]).force, [0.0; 2]);
    }
}
