//! Gauss rules on the reference triangle.
//!
//! Reference triangle: vertices (0,0), (1,0), (0,1), area 1/2. Points are given in area
//! (barycentric) coordinates `[L0, L1, L2]`, where `Lk` is the weight of vertex k, so the
//! reference coordinates are ξ = L1, η = L2. Weights sum to 1/2, the reference area: the integral
//! over a physical element is Σ_q w_q f(x_q) |det J(ξ_q)|.

/// A quadrature rule on the reference triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleRule {
    /// Area coordinates `[L0, L1, L2]` of each point.
    pub points: &'static [[f64; 3]],
    /// Weights, summing to 1/2.
    pub weights: &'static [f64],
    /// Highest total polynomial degree integrated exactly.
    pub degree: usize,
}

impl TriangleRule {
    /// Number of points.
    pub fn n_points(&self) -> usize {
        self.points.len()
    }

    /// Reference coordinates (ξ, η) of point `q`.
    ///
    /// # Panics
    /// If `q >= self.n_points()` (a programming error, not user input).
    pub fn reference_point(&self, q: usize) -> [f64; 2] {
        area_to_reference(self.points[q])
    }
}

/// (ξ, η) of the point with area coordinates `l`.
pub fn area_to_reference(l: [f64; 3]) -> [f64; 2] {
    [l[1], l[2]]
}

/// Area coordinates of the 3-point, degree-2 rule. Point q sits on the median towards vertex q
/// (`Lq = 2/3`), which is what the Gauss→vertex extrapolation in `recovery` relies on.
pub const TRI3_POINTS: [[f64; 3]; 3] = [
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

/// Weights of the 3-point rule.
pub const TRI3_WEIGHTS: [f64; 3] = [1.0 / 6.0; 3];

/// 3-point rule, exact for degree 2; the rule used by the P2 element.
pub const TRI3: TriangleRule = TriangleRule {
    points: &TRI3_POINTS,
    weights: &TRI3_WEIGHTS,
    degree: 2,
};

// Radon's 7-point rule: a = (6 - √15)/21, b = (6 + √15)/21,
// weights (9/40, (155 - √15)/1200, (155 + √15)/1200) scaled by the reference area 1/2.
const R7_A: f64 = 0.101_286_507_323_456_33;
const R7_A2: f64 = 0.797_426_985_353_087_3;
const R7_B: f64 = 0.470_142_064_105_115_05;
const R7_B2: f64 = 0.059_715_871_789_769_89;
const R7_WA: f64 = 0.062_969_590_272_413_58;
const R7_WB: f64 = 0.066_197_076_394_253_08;

/// Area coordinates of the 7-point, degree-5 rule.
pub const TRI7_POINTS: [[f64; 3]; 7] = [
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [R7_A2, R7_A, R7_A],
    [R7_A, R7_A2, R7_A],
    [R7_A, R7_A, R7_A2],
    [R7_B2, R7_B, R7_B],
    [R7_B, R7_B2, R7_B],
    [R7_B, R7_B, R7_B2],
];

/// Weights of the 7-point rule.
pub const TRI7_WEIGHTS: [f64; 7] = [0.1125, R7_WA, R7_WA, R7_WA, R7_WB, R7_WB, R7_WB];

/// 7-point rule, exact for degree 5 (reference integrals in tests and diagnostics).
pub const TRI7: TriangleRule = TriangleRule {
    points: &TRI7_POINTS,
    weights: &TRI7_WEIGHTS,
    degree: 5,
};

#[cfg(test)]
mod tests {
    use super::*;

    fn factorial(n: u32) -> f64 {
        (1..=n).map(f64::from).product()
    }

    /// ∫ ξ^p η^q over the reference triangle = p! q! / (p + q + 2)!.
    fn exact_monomial(p: u32, q: u32) -> f64 {
        factorial(p) * factorial(q) / factorial(p + q + 2)
    }

    fn rule_monomial(rule: &TriangleRule, p: i32, q: i32) -> f64 {
        rule.points
            .iter()
            .zip(rule.weights)
            .map(|(l, w)| {
                let [x, y] = area_to_reference(*l);
                w * x.powi(p) * y.powi(q)
            })
            .sum()
    }

    fn check_rule(rule: &TriangleRule) {
        assert_eq!(rule.points.len(), rule.weights.len());
        for l in rule.points {
            assert!((l.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            assert!(l.iter().all(|v| *v > 0.0), "points must be interior");
        }
        let deg = rule.degree as u32;
        for p in 0..=deg {
            for q in 0..=(deg - p) {
                let got = rule_monomial(rule, p as i32, q as i32);
                let want = exact_monomial(p, q);
                assert!(
                    (got - want).abs() < 1e-15,
                    "degree {deg} rule: xi^{p} eta^{q}: {got} vs {want}"
                );
            }
        }
        // Degree is sharp: some monomial of degree+1 is missed, so the test above can fail.
        let d1 = deg + 1;
        let worst = (0..=d1)
            .map(|p| {
                (rule_monomial(rule, p as i32, (d1 - p) as i32) - exact_monomial(p, d1 - p)).abs()
            })
            .fold(0.0_f64, f64::max);
        assert!(worst > 1e-6, "rule unexpectedly exact at degree {d1}");
    }

    #[test]
    fn tri3_integrates_degree_2_exactly() {
        check_rule(&TRI3);
        assert!((TRI3.weights.iter().sum::<f64>() - 0.5).abs() < 1e-15);
        assert_eq!(TRI3.n_points(), 3);
        assert_eq!(TRI3.reference_point(1), [2.0 / 3.0, 1.0 / 6.0]);
    }

    #[test]
    fn tri7_integrates_degree_5_exactly() {
        check_rule(&TRI7);
        assert!((TRI7.weights.iter().sum::<f64>() - 0.5).abs() < 1e-15);
        assert_eq!(TRI7.n_points(), 7);
    }
}
