//! Tresca's prism with rounded edges: the criterion of undrained clay in full principal
//! stresses (axisymmetry, where the hoop stress is one of them).
//!
//! # Why rounded
//! On an edge of the hexagonal prism (σ1 = σ2 or σ2 = σ3, both faces active) the consistent
//! tangent of the exact return has no stiffness at all in the deviatoric principal plane. On the
//! axis of a body of revolution σr = σθ by symmetry, so every plastic point there sits on an
//! edge: a penetrometer's Newton steps then ran into inverted elements and crawled by line
//! search (a cone's fourth step: 19 iterations, the full step NaN twice), and a cylinder
//! squeezed uniformly, all of it on the edge, had a singular tangent. Rounding the edges gives
//! a smooth criterion whose tangent keeps a stiffness ~ (1/2G + Δλ/δ)⁻¹ along the edge.
//!
//! # Criterion
//! f(σ) = g(σ) − 2cu with g = ½ Σ_{i<j} h(σi − σj) and h(x) = √(x² + δ²), δ = ρ cu (ρ: the material's
//! `edge_rounding`, [`DEFAULT_ROUNDING`] unless the scene sets it).
//! Because |σ1 − σ2| + |σ2 − σ3| + |σ1 − σ3| = 2 (σmax − σmin), g is Tresca's σmax − σmin with
//! each |·| smoothed: symmetric in the principal values (an isotropic function, smooth across
//! their ties), convex, and pressure-independent (its gradient sums to zero, so associated flow
//! is isochoric). On a face away from the edges (all differences ≫ δ) it is Tresca's to
//! O(δ²/cu): 2.5e-5 cu at δ = 0.01 cu. On an edge the strength is lower by δ/2 of 2cu, ρ/4
//! (0.25 % at ρ = 0.01; [`edge_strength`] gives it exactly).
//!
//! # Why a parameter
//! A penetrometer's tip holds its whole plastic zone near the axis on the edge. There the
//! return's tangent along the edge scales with δ: on a fine cloud (the cone at D/8.6) Newton
//! stalled at free nodes under the tip with δ = 0.01 cu and went on with 0.05 cu. A wider
//! rounding buys that robustness with a weaker edge (ρ/4), so the scene chooses it.
//!
//! # Return
//! Associated flow with isotropic elasticity: σ = σ_tr − 2G Δλ ∇g(σ) (D∇g = 2G∇g because ∇g is
//! deviatoric), g(σ) = 2cu, solved by Newton on (σ, Δλ) from the exact prism's return, with
//! backtracking. The tangent dσ/dσ_tr = Ξ − (Ξn)(Ξn)ᵀ/(nᵀΞn), Ξ = (I + 2GΔλ ∇²g)⁻¹, n = ∇g:
//! symmetric.

use super::principal::solve_small;
use super::MaterialError;

/// δ / cu by default: 0.25 % of the strength on an edge; the tangent's stiffness along an
/// edge grows with it.
pub const DEFAULT_ROUNDING: f64 = 0.01;
/// The widest rounding a material may ask for: 2.5 % weaker on an edge.
pub const MAX_ROUNDING: f64 = 0.1;
/// Newton iterations of the return before it is reported as failed.
const MAX_ITERATIONS: usize = 60;

/// Returned principal stresses and their derivatives by the trial's.
pub type Returned = ([f64; 3], [[f64; 3]; 3]);

fn h(x: f64, d: f64) -> f64 {
    x.hypot(d)
}

/// Sorted-or-not principal stresses → (g, ∇g, ∇²g).
fn criterion(s: &[f64; 3], d: f64) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let mut g = 0.0;
    let mut grad = [0.0; 3];
    let mut hess = [[0.0; 3]; 3];
    for (i, j) in [(0, 1), (1, 2), (0, 2)] {
        let x = s[i] - s[j];
        let r = h(x, d);
        g += 0.5 * r;
        let d1 = 0.5 * x / r;
        let d2 = 0.5 * d * d / (r * r * r);
        grad[i] += d1;
        grad[j] -= d1;
        hess[i][i] += d2;
        hess[j][j] += d2;
        hess[i][j] -= d2;
        hess[j][i] -= d2;
    }
    (g, grad, hess)
}

/// I + k ∇²g: the matrix of the return's linearisation (Ξ⁻¹ of the module docs).
fn relaxed(hess: &[[f64; 3]; 3], k: f64) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 } + k * hess[i][j])
    })
}

/// The largest |σ1 − σ3| the rounded prism admits on an edge (two equal principal stresses):
/// 2cu less about δ/2, δ = `rounding` · cu.
pub fn edge_strength(cu: f64, rounding: f64) -> f64 {
    let d = rounding * cu;
    ((2.0 * cu - 0.5 * d).powi(2) - d * d).sqrt()
}

/// The return of principal trial stresses `tr` (any order) onto the rounded prism of strength
/// `cu`, edges rounded by `rounding` · cu, with shear modulus `shear`: None when elastic, else
/// the returned principal stresses (same order) and their derivatives by the trial's.
pub fn principal_return(
    tr: &[f64; 3],
    shear: f64,
    cu: f64,
    rounding: f64,
) -> Result<Option<Returned>, MaterialError> {
    let d = rounding * cu;
    let (g_tr, _, _) = criterion(tr, d);
    if g_tr <= 2.0 * cu {
        return Ok(None);
    }
    let two_g = 2.0 * shear;
    // From the deviator scaled onto the exact prism (a radial return), with the multiplier
    // that reaches it along ∇g there.
    let mean = (tr[0] + tr[1] + tr[2]) / 3.0;
    let spread = tr.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v))
        - tr.iter().fold(f64::INFINITY, |m, &v| m.min(v));
    let mut s: [f64; 3] = std::array::from_fn(|k| mean + (tr[k] - mean) * (2.0 * cu / spread));
    let (_, n0, _) = criterion(&s, d);
    let nn: f64 = n0.iter().map(|v| v * v).sum();
    let dist: f64 = (0..3).map(|k| (tr[k] - s[k]) * n0[k]).sum::<f64>();
    let mut dl = (dist / (two_g * nn)).max(0.0);
    let residual = |s: &[f64; 3], dl: f64| {
        let (g, n, _) = criterion(s, d);
        let rs: [f64; 3] = std::array::from_fn(|k| s[k] - tr[k] + two_g * dl * n[k]);
        let rf = g - 2.0 * cu;
        (
            rs,
            rf,
            (rs.iter().map(|v| v * v).sum::<f64>() + rf * rf).sqrt(),
        )
    };
    let scale = tr.iter().fold(cu, |m, v| m.max(v.abs()));
    let tol = 1e-12 * scale;
    let (mut rs, mut rf, mut norm) = residual(&s, dl);
    let mut iterations = 0;
    while norm > tol {
        iterations += 1;
        if iterations > MAX_ITERATIONS {
            return Err(MaterialError::ReturnMappingFailed {
                iterations,
                residual: norm / cu,
            });
        }
        let (_, n, hess) = criterion(&s, d);
        // [[I + 2GΔλH, 2Gn], [nᵀ, 0]] [ds; dλ] = −[rs; rf], by eliminating ds.
        let a = relaxed(&hess, two_g * dl);
        let xr = solve_small(3, &a, &rs);
        let xn = solve_small(3, &a, &n.map(|v| two_g * v));
        let (Some(xr), Some(xn)) = (xr, xn) else {
            return Err(MaterialError::ReturnMappingFailed {
                iterations,
                residual: norm / cu,
            });
        };
        // nᵀ ds = −rf with ds = −xr − xn dλ.
        let nxn: f64 = (0..3).map(|k| n[k] * xn[k]).sum();
        let nxr: f64 = (0..3).map(|k| n[k] * xr[k]).sum();
        let ddl = (rf - nxr) / nxn;
        let ds: [f64; 3] = std::array::from_fn(|k| -xr[k] - xn[k] * ddl);
        // Backtracking keeps Newton in the basin where the rounding's curvature is large.
        let mut step = 1.0;
        loop {
            let s_new: [f64; 3] = std::array::from_fn(|k| s[k] + step * ds[k]);
            let dl_new = (dl + step * ddl).max(0.0);
            let (r1, f1, n1) = residual(&s_new, dl_new);
            if n1 < norm {
                (s, dl, rs, rf, norm) = (s_new, dl_new, r1, f1, n1);
                break;
            }
            if step < 1e-6 {
                // No descent left: the round-off floor of g's differences of large stresses.
                if norm <= 1e-9 * scale {
                    break;
                }
                return Err(MaterialError::ReturnMappingFailed {
                    iterations,
                    residual: norm / cu,
                });
            }
            step *= 0.5;
        }
        if step < 1e-6 {
            break;
        }
    }
    let (_, n, hess) = criterion(&s, d);
    let a = relaxed(&hess, two_g * dl);
    let mut xi = [[0.0; 3]; 3];
    for c in 0..3 {
        let mut unit = [0.0; 3];
        unit[c] = 1.0;
        let col = solve_small(3, &a, &unit).ok_or(MaterialError::ReturnMappingFailed {
            iterations,
            residual: f64::NAN,
        })?;
        for r in 0..3 {
            xi[r][c] = col[r];
        }
    }
    let xn: [f64; 3] = std::array::from_fn(|i| (0..3).map(|k| xi[i][k] * n[k]).sum());
    let nxn: f64 = (0..3).map(|k| n[k] * xn[k]).sum();
    let ds = std::array::from_fn(|i| std::array::from_fn(|j| xi[i][j] - xn[i] * xn[j] / nxn));
    Ok(Some((s, ds)))
}

#[cfg(test)]
mod tests {
    use super::*;

    const CU: f64 = 5.0e3;
    const G: f64 = 100.0 * CU;
    const ROUNDINGS: [f64; 3] = [DEFAULT_ROUNDING, 0.05, MAX_ROUNDING];

    #[test]
    fn on_a_face_far_from_the_edges_it_is_tresca_to_the_rounding_squared() {
        let tr = [3.0 * CU, 0.2 * CU, -3.0 * CU];
        for rho in ROUNDINGS {
            let (s, _) = principal_return(&tr, G, CU, rho).unwrap().unwrap();
            let diff = (s[0] - s[2]) / (2.0 * CU);
            assert!((diff - 1.0).abs() < 2.0 * rho * rho, "{rho}: {diff}");
            // Isochoric: the mean is kept.
            let m = |v: &[f64; 3]| v.iter().sum::<f64>() / 3.0;
            assert!((m(&s) - m(&tr)).abs() < 1e-12 * CU);
        }
    }

    #[test]
    fn on_an_edge_the_strength_is_the_stated_edge_strength() {
        let tr = [CU, CU, -5.0 * CU];
        for rho in ROUNDINGS {
            let (s, _) = principal_return(&tr, G, CU, rho).unwrap().unwrap();
            assert!((s[0] - s[1]).abs() < 1e-12 * CU);
            assert!(
                ((s[0] - s[2]) - edge_strength(CU, rho)).abs() < 1e-10 * CU,
                "{rho}: {s:?}"
            );
            let (g, _, _) = criterion(&s, rho * CU);
            assert!((g - 2.0 * CU).abs() < 1e-10 * CU);
            // About ρ/4 weaker than the prism's 2cu.
            let weaker = 1.0 - edge_strength(CU, rho) / (2.0 * CU);
            assert!(
                (weaker - rho / 4.0).abs() < 0.1 * rho / 4.0,
                "{rho}: {weaker}"
            );
        }
    }

    #[test]
    fn a_wider_rounding_stiffens_the_tangent_along_an_edge() {
        // Drawing σ1 and σ2 apart on an edge, the exact prism's tangent has no stiffness
        // (every such trial returns to the corner); the rounded one keeps some, more with a
        // wider rounding.
        let tr = [1.5 * CU, 1.5 * CU, -5.0 * CU];
        let along = [1.0, -1.0, 0.0];
        let stiffness = |rho: f64| {
            let (_, ds) = principal_return(&tr, G, CU, rho).unwrap().unwrap();
            (0..3)
                .map(|i| along[i] * (0..3).map(|j| ds[i][j] * along[j]).sum::<f64>())
                .sum::<f64>()
        };
        let (narrow, wide) = (stiffness(0.01), stiffness(0.05));
        assert!(narrow > 0.0 && wide > 2.0 * narrow, "{narrow} {wide}");
    }

    #[test]
    fn tangent_matches_finite_differences_near_and_on_an_edge() {
        for (tr, rho) in [
            [CU, CU, -5.0 * CU],
            [1.01 * CU, CU, -4.0 * CU],
            [2.0 * CU, 1.0 * CU, -1.5 * CU],
            [3.0 * CU, -2.0 * CU, -2.0001 * CU],
        ]
        .into_iter()
        .flat_map(|tr| ROUNDINGS.map(|rho| (tr, rho)))
        {
            let (_, ds) = principal_return(&tr, G, CU, rho).unwrap().unwrap();
            for j in 0..3 {
                let eps = 1e-6 * CU;
                let mut p = tr;
                let mut m = tr;
                p[j] += eps;
                m[j] -= eps;
                let sp = principal_return(&p, G, CU, rho).unwrap().unwrap().0;
                let sm = principal_return(&m, G, CU, rho).unwrap().unwrap().0;
                for i in 0..3 {
                    let fd = (sp[i] - sm[i]) / (2.0 * eps);
                    assert!(
                        (fd - ds[i][j]).abs() < 1e-6,
                        "{tr:?} {rho} {i}{j}: {fd} vs {}",
                        ds[i][j]
                    );
                }
            }
        }
    }

    #[test]
    fn inside_it_is_elastic() {
        let tr = [CU, 0.0, -0.9 * CU];
        for rho in ROUNDINGS {
            assert!(principal_return(&tr, G, CU, rho).unwrap().is_none());
        }
    }
}
