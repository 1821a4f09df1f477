//! P2 element residual and consistent tangent for one updated-Lagrangian load step.
//!
//! Reference configuration: the start-of-step positions x_n. Unknown: the step displacement Δu.
//! At each Gauss point of the 3-point rule ([`crate::fem::quadrature::TRI3`]):
//! - H = ∂Δu/∂x_n, F = I + H (F_zz = 1), J = det F;
//! - E = ½(FᵀF − I) = ½(H + Hᵀ + HᵀH), Voigt `[xx, yy, zz, xy]`, engineering shear, Ezz = 0
//!   (assembled from H rather than F so that tiny steps keep full relative precision);
//! - the material returns S = σ_n + ΔS(E) and D = dS/dE;
//! - f_int = ∫_{Ω_n} B_NLᵀ S dV, with δE = B_NL δu;
//! - K = ∫ B_NLᵀ D B_NL dV + ∫ (∇N_a · S ∇N_b) I₂ dV (geometric stiffness, in-plane S);
//! - residual = f_int − ∫_{Ω_n} N_a b dV, with b the body force per unit volume at x_n;
//! - σ_{n+1} = F S Fᵀ / J in-plane, σzz_{n+1} = S_zz / J.
//!
//! In axisymmetry ([`Analysis::Axisymmetric`], x the radius) F also has the hoop stretch
//! F_θθ = 1 + h_θ, h_θ = Δu_r/r, so E_zz = h_θ + ½h_θ² (δE_zz = F_θθ N_a δu_{a,r}/r), the
//! geometric stiffness gains S_zz N_a N_b/r² on the radial components, σzz_{n+1} = F_θθ² S_zz/J
//! with J = J_2D F_θθ, and every Gauss weight carries 2π r. In plane strain h_θ = 0 and the
//! measure is unit thickness. Dof order: node0 ux, node0 uy, node1 ux, …, node5 uy, with the
//! node order of [`crate::fem::p2`].

use std::fmt;

use crate::fem::analysis::{hoop_gradient, Analysis};
use crate::fem::p2::{self, N_NODES};
use crate::fem::quadrature::{area_to_reference, TRI3_POINTS, TRI3_WEIGHTS};
use crate::material::{GaussState, Material, MaterialError};

/// Degrees of freedom per element.
pub const N_DOFS: usize = 2 * N_NODES;
/// Gauss points per element (the 3-point rule).
pub const N_GAUSS: usize = 3;

/// Element contributions for one Newton iterate.
#[derive(Clone, Debug, PartialEq)]
pub struct ElementOutput {
    /// f_int − f_body.
    pub residual: [f64; N_DOFS],
    /// d residual / d Δu.
    pub tangent: [[f64; N_DOFS]; N_DOFS],
    /// Updated Gauss states; `stress` is the end-of-step Cauchy stress σ_{n+1}.
    pub states: [GaussState; N_GAUSS],
}

/// Why an element could not be evaluated.
#[derive(Clone, Debug, PartialEq)]
pub enum ElementError {
    /// The start-of-step geometry x_n has a non-positive isoparametric Jacobian.
    DegenerateGeometry {
        /// Gauss point index.
        gauss: usize,
        /// det(∂x_n/∂ξ).
        det_j: f64,
    },
    /// The step deformation inverts (or collapses) the element: J = det F ≤ 0 or not finite.
    Inverted {
        /// Gauss point index.
        gauss: usize,
        /// J = det F.
        j: f64,
    },
    /// The constitutive update failed.
    Material {
        /// Gauss point index.
        gauss: usize,
        /// The material's error.
        source: MaterialError,
    },
}

impl fmt::Display for ElementError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::DegenerateGeometry { gauss, det_j } => write!(
                f,
                "degenerate start-of-step element geometry at Gauss point {gauss}: \
                 det(dx/dxi) = {det_j:e}"
            ),
            Self::Inverted { gauss, j } => write!(
                f,
                "element inverted at Gauss point {gauss}: J = det F = {j:e} <= 0"
            ),
            Self::Material { gauss, source } => {
                write!(f, "material update failed at Gauss point {gauss}: {source}")
            }
        }
    }
}

impl std::error::Error for ElementError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Material { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Physical positions of the 3 Gauss points (same order as the states).
pub fn p2_gauss_points(x: &[[f64; 2]; N_NODES]) -> [[f64; 2]; N_GAUSS] {
    let mut out = [[0.0; 2]; N_GAUSS];
    for (o, l) in out.iter_mut().zip(TRI3_POINTS.iter()) {
        *o = p2::map_to_physical(x, area_to_reference(*l));
    }
    out
}

/// Displacement gradient `H[i][j]` = ∂Δu_i/∂x_j from nodal values and physical gradients.
pub fn displacement_gradient(
    grad: &[[f64; 2]; N_NODES],
    du: &[[f64; 2]; N_NODES],
) -> [[f64; 2]; 2] {
    let mut h = [[0.0; 2]; 2];
    for (ga, ua) in grad.iter().zip(du.iter()) {
        for (hi, ui) in h.iter_mut().zip(ua.iter()) {
            hi[0] += ui * ga[0];
            hi[1] += ui * ga[1];
        }
    }
    h
}

/// Green–Lagrange strain `[xx, yy, zz, xy]` (engineering shear) of F = I + H.
pub fn green_lagrange(h: &[[f64; 2]; 2]) -> [f64; 4] {
    let exx = h[0][0] + 0.5 * (h[0][0] * h[0][0] + h[1][0] * h[1][0]);
    let eyy = h[1][1] + 0.5 * (h[0][1] * h[0][1] + h[1][1] * h[1][1]);
    let gxy = h[0][1] + h[1][0] + h[0][0] * h[0][1] + h[1][0] * h[1][1];
    [exx, eyy, 0.0, gxy]
}

/// det(I + H), written so that it stays accurate when H is tiny.
pub fn jacobian_of(h: &[[f64; 2]; 2]) -> f64 {
    1.0 + h[0][0] + h[1][1] + (h[0][0] * h[1][1] - h[0][1] * h[1][0])
}

/// Cauchy stress F S Fᵀ / J (in-plane) and S_zz / J, Voigt `[xx, yy, zz, xy]`.
pub fn push_forward(f: &[[f64; 2]; 2], s: &[f64; 4], j: f64) -> [f64; 4] {
    let sm = [[s[0], s[3]], [s[3], s[1]]];
    // fs = F S
    let mut fs = [[0.0; 2]; 2];
    for i in 0..2 {
        for k in 0..2 {
            fs[i][k] = f[i][0] * sm[0][k] + f[i][1] * sm[1][k];
        }
    }
    let c = |i: usize, k: usize| (fs[i][0] * f[k][0] + fs[i][1] * f[k][1]) / j;
    [c(0, 0), c(1, 1), s[2] / j, c(0, 1)]
}

/// Internal force, consistent tangent and updated states of a P2 element for the step
/// displacement `du`; see the module docs for the formulation.
///
/// `x` are the start-of-step node positions x_n, `states_n` the Gauss states at x_n (Cauchy σ_n),
/// `body_force` the force per unit volume of Ω_n.
pub fn p2_element(
    x: &[[f64; 2]; N_NODES],
    du: &[[f64; 2]; N_NODES],
    states_n: &[GaussState; N_GAUSS],
    mat: &dyn Material,
    body_force: [f64; 2],
) -> Result<ElementOutput, ElementError> {
    p2_element_with(
        x,
        du,
        states_n,
        mat,
        body_force,
        Analysis::PlaneStrain,
        true,
    )
}

/// [`p2_element`], with the tangent formed only if `with_tangent` (else left zero), for
/// evaluations where no tangent is read or cached (`StepProblem::evaluate`: the line search's and
/// the converged state's residuals on the iterative path): forming it was most of their cost;
/// and in the `analysis` given ([`p2_element`] is plane strain).
pub fn p2_element_with(
    x: &[[f64; 2]; N_NODES],
    du: &[[f64; 2]; N_NODES],
    states_n: &[GaussState; N_GAUSS],
    mat: &dyn Material,
    body_force: [f64; 2],
    analysis: Analysis,
    with_tangent: bool,
) -> Result<ElementOutput, ElementError> {
    let mut residual = [0.0; N_DOFS];
    let mut tangent = [[0.0; N_DOFS]; N_DOFS];
    let mut states = states_n.clone();
    // Non-associated flow: the full product, nothing mirrored. Otherwise the upper triangle.
    let full = !mat.symmetric_tangent();

    for q in 0..N_GAUSS {
        let xi = area_to_reference(TRI3_POINTS[q]);
        let pg = p2::physical_gradients(x, xi).map_err(|e| ElementError::DegenerateGeometry {
            gauss: q,
            det_j: e.det_j,
        })?;
        let n = p2::shape(xi);
        // The radius and the hoop only where there is a hoop: assembly's hot path.
        let (r, h_hoop) = if analysis.has_hoop() {
            let r = p2::map_to_physical(x, xi)[0];
            let ur: f64 = n.iter().zip(du).map(|(na, ua)| na * ua[0]).sum();
            (r, hoop_gradient(analysis, r, ur))
        } else {
            (1.0, 0.0)
        };
        let w = TRI3_WEIGHTS[q] * pg.det_j * analysis.measure(r);
        let g = &pg.grad;

        let h = displacement_gradient(g, du);
        let f_hoop = 1.0 + h_hoop;
        let j = jacobian_of(&h) * f_hoop;
        if !j.is_finite() || j <= 0.0 {
            return Err(ElementError::Inverted { gauss: q, j });
        }
        let f = [[1.0 + h[0][0], h[0][1]], [h[1][0], 1.0 + h[1][1]]];
        let mut e = green_lagrange(&h);
        e[2] = h_hoop + 0.5 * h_hoop * h_hoop;
        let resp = mat
            .update(&states_n[q], &e)
            .map_err(|source| ElementError::Material { gauss: q, source })?;
        let s = resp.s;
        let d = resp.d;

        // B_NL (4 x 12): δE = B_NL δu. The zz row is the hoop's, zero in plane strain.
        let mut b = [[0.0; N_DOFS]; 4];
        for (a, ga) in g.iter().enumerate() {
            for (i, fi) in f.iter().enumerate() {
                let col = 2 * a + i;
                b[0][col] = fi[0] * ga[0];
                b[1][col] = fi[1] * ga[1];
                b[3][col] = fi[0] * ga[1] + fi[1] * ga[0];
            }
            if analysis.has_hoop() {
                b[2][2 * a] = f_hoop * n[a] / r;
            }
        }

        for k in 0..N_DOFS {
            let mut fk = 0.0;
            for (bi, si) in b.iter().zip(s.iter()) {
                fk += bi[k] * si;
            }
            residual[k] += w * (fk - n[k / 2] * body_force[k % 2]);
        }
        let mut st = resp.state;
        st.stress = push_forward(&f, &s, j);
        st.stress[2] *= f_hoop * f_hoop;
        states[q] = st;
        if !with_tangent {
            continue;
        }

        // Weighted D·B on the in-plane rows and, with a hoop, the zz row (db's rows in the order
        // xx, yy, xy, zz; B's zz row is zero in plane strain), so the material stiffness
        // below is a plain Bᵀ·(wDB) product. Where the material says its tangent is symmetric
        // the element's is too (the geometric part always is): its upper triangle is formed,
        // and mirrored once after the last Gauss point, which halves the work.
        const IN_PLANE: [usize; 3] = [0, 1, 3];
        const WITH_HOOP: [usize; 4] = [0, 1, 3, 2];
        let rows: &[usize] = if analysis.has_hoop() {
            &WITH_HOOP
        } else {
            &IN_PLANE
        };
        debug_assert!(
            full || (0..4).all(|i| (0..i).all(|j| (d[i][j] - d[j][i]).abs()
                <= 1e-9 * d.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs())))),
            "the material tangent is not symmetric: {d:?}"
        );
        let mut db = [[0.0; N_DOFS]; 4];
        for (dbi, &i) in db.iter_mut().zip(rows.iter()) {
            for &jj in rows.iter() {
                let c = w * d[i][jj];
                if c != 0.0 {
                    for (x_, bjk) in dbi.iter_mut().zip(b[jj].iter()) {
                        *x_ += c * bjk;
                    }
                }
            }
        }
        for (k, row) in tangent.iter_mut().enumerate() {
            let bk = [b[0][k], b[1][k], b[3][k], b[2][k]];
            for (l, r) in row.iter_mut().enumerate().skip(if full { 0 } else { k }) {
                *r += bk[0] * db[0][l] + bk[1] * db[1][l] + bk[2] * db[2][l] + bk[3] * db[3][l];
            }
        }

        // Geometric stiffness: (∇N_a · S ∇N_b) on both diagonal displacement components.
        for (a, ga) in g.iter().enumerate() {
            let sa = [s[0] * ga[0] + s[3] * ga[1], s[3] * ga[0] + s[1] * ga[1]];
            for (bn, gb) in g.iter().enumerate().skip(if full { 0 } else { a }) {
                let kg = w * (sa[0] * gb[0] + sa[1] * gb[1]);
                tangent[2 * a][2 * bn] += kg;
                tangent[2 * a + 1][2 * bn + 1] += kg;
            }
        }
        if analysis.has_hoop() {
            // ∂²E_zz/∂u_{a,r}∂u_{b,r} = N_a N_b / r².
            let c = w * s[2] / (r * r);
            for a in 0..N_NODES {
                for bn in (if full { 0 } else { a })..N_NODES {
                    tangent[2 * a][2 * bn] += c * n[a] * n[bn];
                }
            }
        }
    }
    if with_tangent && !full {
        for k in 1..N_DOFS {
            let (upper, lower) = tangent.split_at_mut(k);
            for (l, row) in upper.iter().enumerate() {
                lower[0][l] = row[k];
            }
        }
    }

    Ok(ElementOutput {
        residual,
        tangent,
        states,
    })
}

#[cfg(test)]
// Index loops mirror the component notation of the formulas being checked.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::material::elastic::LinearElastic;
    use std::collections::HashMap;

    type Mat2 = [[f64; 2]; 2];

    fn elastic() -> LinearElastic {
        LinearElastic::new(12e6, 0.2).expect("valid parameters")
    }

    fn rot(theta: f64) -> Mat2 {
        let (s, c) = theta.sin_cos();
        [[c, -s], [s, c]]
    }

    fn mul(a: &Mat2, b: &Mat2) -> Mat2 {
        let mut m = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                m[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
            }
        }
        m
    }

    fn apply(a: &Mat2, v: [f64; 2]) -> [f64; 2] {
        [
            a[0][0] * v[0] + a[0][1] * v[1],
            a[1][0] * v[0] + a[1][1] * v[1],
        ]
    }

    /// Δu_a = (F − I)(x_a − c): homogeneous deformation about c.
    fn homogeneous_du(x: &[[f64; 2]; 6], f: &Mat2, c: [f64; 2]) -> [[f64; 2]; 6] {
        let mut du = [[0.0; 2]; 6];
        for (d, xa) in du.iter_mut().zip(x.iter()) {
            let r = [xa[0] - c[0], xa[1] - c[1]];
            let fr = apply(f, r);
            *d = [fr[0] - r[0], fr[1] - r[1]];
        }
        du
    }

    fn curved_element() -> [[f64; 2]; 6] {
        let mut x = p2::straight_sided(&[[0.3, -0.2], [1.9, 0.1], [0.6, 1.4]]);
        x[4][0] += 0.08;
        x[4][1] += 0.05;
        x[5][0] -= 0.04;
        x
    }

    fn prestress() -> [GaussState; 3] {
        let mk = |s: [f64; 4]| GaussState {
            stress: s,
            ..GaussState::default()
        };
        [
            mk([-1.2e5, -2.5e5, -1.1e5, 3.0e4]),
            mk([-0.9e5, -2.2e5, -1.3e5, -1.5e4]),
            mk([-1.5e5, -2.8e5, -1.7e5, 2.2e4]),
        ]
    }

    fn rel_close(a: &[f64], b: &[f64], tol: f64) -> bool {
        let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b.iter())
            .all(|(x, y)| (x - y).abs() <= tol * scale)
    }

    #[test]
    fn the_residual_alone_is_the_full_elements_bit_for_bit() {
        let x = curved_element();
        let f = mul(&rot(0.6), &[[1.25, 0.1], [0.1, 0.85]]);
        let du = homogeneous_du(&x, &f, [0.5, 0.2]);
        let body = [0.5e3, -2.0e4];
        let full = p2_element(&x, &du, &prestress(), &elastic(), body).expect("valid element");
        let lean = p2_element_with(
            &x,
            &du,
            &prestress(),
            &elastic(),
            body,
            Analysis::PlaneStrain,
            false,
        )
        .expect("valid element");
        assert_eq!(
            full.residual.map(f64::to_bits),
            lean.residual.map(f64::to_bits)
        );
        assert_eq!(format!("{:?}", full.states), format!("{:?}", lean.states));
        assert!(lean.tangent.iter().flatten().all(|&k| k == 0.0));
        assert!(full.tangent.iter().flatten().any(|&k| k != 0.0));
    }

    /// Relative Frobenius error of the tangent against central differences of the residual.
    fn fd_error(
        x: &[[f64; 2]; 6],
        du: &[[f64; 2]; 6],
        states: &[GaussState; 3],
        mat: &dyn Material,
        analysis: Analysis,
    ) -> f64 {
        let body = [0.5e3, -2.0e4];
        let eval = |u: &[[f64; 2]; 6]| {
            p2_element_with(x, u, states, mat, body, analysis, true).expect("valid element")
        };
        let out = eval(du);
        let h = 1e-7;
        let (mut num, mut den) = (0.0, 0.0);
        for l in 0..N_DOFS {
            let (mut p, mut m) = (*du, *du);
            p[l / 2][l % 2] += h;
            m[l / 2][l % 2] -= h;
            let (rp, rm) = (eval(&p), eval(&m));
            for k in 0..N_DOFS {
                let fd = (rp.residual[k] - rm.residual[k]) / (2.0 * h);
                num += (fd - out.tangent[k][l]).powi(2);
                den += out.tangent[k][l].powi(2);
            }
        }
        (num / den).sqrt()
    }

    #[test]
    fn axisymmetric_tangent_matches_central_differences() {
        use crate::material::mohr_coulomb::MohrCoulomb;
        let x = curved_element();
        let f = mul(&rot(0.3), &[[1.05, 0.02], [0.02, 0.97]]);
        let mut du = homogeneous_du(&x, &f, [0.5, 0.2]);
        for (d, xa) in du.iter_mut().zip(x.iter()) {
            d[0] += 0.03 * xa[0] * xa[1];
            d[1] -= 0.02 * xa[0] * xa[0];
        }
        let err = fd_error(&x, &du, &prestress(), &elastic(), Analysis::Axisymmetric);
        assert!(err < 1e-6, "elastic: {err:e}");
        // A non-symmetric plastic tangent (ψ < φ) with the hoop among the principal stresses.
        let mc = MohrCoulomb::new(6.0e6, 0.3, 5.0e3, 30.0, 5.0, None).expect("valid");
        let small = du.map(|d| [0.1 * d[0], 0.1 * d[1]]);
        let zero: [GaussState; 3] = std::array::from_fn(|_| GaussState::default());
        let out = p2_element_with(
            &x,
            &small,
            &zero,
            &mc,
            [0.0; 2],
            Analysis::Axisymmetric,
            true,
        )
        .expect("valid element");
        assert!(out.states.iter().any(|s| s.internal[4] > 0.0), "must yield");
        let err = fd_error(&x, &small, &zero, &mc, Analysis::Axisymmetric);
        assert!(err < 1e-6, "Mohr–Coulomb: {err:e}");
    }

    #[test]
    fn axisymmetric_uniform_radial_stretch_gives_the_hoop_stress() {
        // Δu = ε (x, 0): F = diag(1 + ε, 1, 1 + ε); with zero prestress S = D E and the hoop
        // stress is the in-plane xx one.
        let x = curved_element();
        let eps = 1e-3;
        let du = x.map(|p| [eps * p[0], 0.0]);
        let zero = std::array::from_fn(|_| GaussState::default());
        let out = p2_element_with(
            &x,
            &du,
            &zero,
            &elastic(),
            [0.0; 2],
            Analysis::Axisymmetric,
            true,
        )
        .expect("valid element");
        for st in &out.states {
            let s = st.stress;
            assert!((s[2] - s[0]).abs() <= 1e-12 * s[0].abs(), "{s:?}");
            assert!(s[3].abs() <= 1e-9 * s[0].abs(), "{s:?}");
        }
    }

    #[test]
    fn tangent_matches_central_differences() {
        let x = curved_element();
        let states = prestress();
        let mat = elastic();
        // F = R(0.6) U with a large stretch, plus a quadratic perturbation so F varies in space.
        let u = [[1.25, 0.1], [0.1, 0.85]];
        let f = mul(&rot(0.6), &u);
        let mut du = homogeneous_du(&x, &f, [0.5, 0.2]);
        for (d, xa) in du.iter_mut().zip(x.iter()) {
            d[0] += 0.03 * xa[0] * xa[1];
            d[1] -= 0.02 * xa[0] * xa[0];
        }
        let body = [0.5e3, -2.0e4];
        let out = p2_element(&x, &du, &states, &mat, body).expect("valid element");
        let h = 1e-7;
        let mut fd = [[0.0; N_DOFS]; N_DOFS];
        for l in 0..N_DOFS {
            let mut p = du;
            let mut m = du;
            p[l / 2][l % 2] += h;
            m[l / 2][l % 2] -= h;
            let rp = p2_element(&x, &p, &states, &mat, body).expect("valid element");
            let rm = p2_element(&x, &m, &states, &mat, body).expect("valid element");
            for k in 0..N_DOFS {
                fd[k][l] = (rp.residual[k] - rm.residual[k]) / (2.0 * h);
            }
        }
        let mut num = 0.0;
        let mut den = 0.0;
        for k in 0..N_DOFS {
            for l in 0..N_DOFS {
                num += (fd[k][l] - out.tangent[k][l]).powi(2);
                den += out.tangent[k][l].powi(2);
            }
        }
        let rel = (num / den).sqrt();
        assert!(rel < 1e-6, "relative tangent error {rel:e}");
        // The geometric term must be a visible part of K, or the check above would not cover it.
        let zero_mat = LinearElastic {
            young: 1e-30,
            poisson: 0.0,
        };
        let geo = p2_element(&x, &du, &states, &zero_mat, body).expect("valid element");
        let geo_norm: f64 = geo
            .tangent
            .iter()
            .flatten()
            .map(|v| v * v)
            .sum::<f64>()
            .sqrt();
        assert!(
            geo_norm / den.sqrt() > 1e-3,
            "geometric stiffness unexpectedly negligible"
        );
    }

    #[test]
    fn non_associated_tangent_is_formed_in_full() {
        use crate::material::mohr_coulomb::MohrCoulomb;
        let x = curved_element();
        let states = prestress();
        let body = [0.0; 2];
        let f = [[1.004, 0.003], [0.001, 0.993]];
        let du = homogeneous_du(&x, &f, [0.5, 0.2]);
        for psi in [30.0, 5.0] {
            let mat = MohrCoulomb::new(30e6, 0.3, 5e3, 30.0, psi, None).expect("valid");
            let out = p2_element(&x, &du, &states, &mat, body).expect("valid element");
            assert!(out.states.iter().any(|s| s.internal[4] > 0.0), "must yield");
            let h = 1e-9;
            let (mut num, mut den, mut asym) = (0.0, 0.0, 0.0f64);
            for l in 0..N_DOFS {
                let (mut p, mut m) = (du, du);
                p[l / 2][l % 2] += h;
                m[l / 2][l % 2] -= h;
                let rp = p2_element(&x, &p, &states, &mat, body).expect("valid element");
                let rm = p2_element(&x, &m, &states, &mat, body).expect("valid element");
                for k in 0..N_DOFS {
                    let fd = (rp.residual[k] - rm.residual[k]) / (2.0 * h);
                    num += (fd - out.tangent[k][l]).powi(2);
                    den += out.tangent[k][l].powi(2);
                    asym = asym.max((out.tangent[k][l] - out.tangent[l][k]).abs());
                }
            }
            let rel = (num / den).sqrt();
            assert!(rel < 1e-6, "ψ = {psi}: relative tangent error {rel:e}");
            if psi == 30.0 {
                assert!(asym <= 1e-9 * den.sqrt(), "associated: symmetric");
            } else {
                assert!(asym > 1e-4 * den.sqrt(), "non-associated: {asym:e}");
            }
        }
    }

    #[test]
    fn rigid_rotation_by_90_degrees_rotates_stress_and_forces() {
        let x = curved_element();
        let states = prestress();
        let mat = elastic();
        let r = [[0.0, -1.0], [1.0, 0.0]];
        let du = homogeneous_du(&x, &r, [0.7, 0.4]);
        let zero = [[0.0; 2]; 6];
        let r0 = p2_element(&x, &zero, &states, &mat, [0.0; 2]).expect("valid element");
        let r1 = p2_element(&x, &du, &states, &mat, [0.0; 2]).expect("valid element");
        let mut want = [0.0; N_DOFS];
        for a in 0..6 {
            let v = apply(&r, [r0.residual[2 * a], r0.residual[2 * a + 1]]);
            want[2 * a] = v[0];
            want[2 * a + 1] = v[1];
        }
        assert!(
            rel_close(&r1.residual, &want, 1e-12),
            "{:?} vs {want:?}",
            r1.residual
        );
        // Prestress alone is not in element equilibrium, so this comparison is not vacuous.
        assert!(r0.residual.iter().any(|v| v.abs() > 1e3));
        for q in 0..3 {
            let s = states[q].stress;
            let rotated = [s[1], s[0], s[2], -s[3]]; // R σ Rᵀ for R = rot(90°)
            assert!(
                rel_close(&r1.states[q].stress, &rotated, 1e-12),
                "gauss {q}: {:?} vs {rotated:?}",
                r1.states[q].stress
            );
        }
    }

    #[test]
    fn superposed_rotation_is_objective() {
        let x = curved_element();
        let states = prestress();
        let mat = elastic();
        let u = [[1.1, 0.05], [0.05, 0.92]];
        let r = rot(1.1);
        let c = [0.2, 0.3];
        let a = p2_element(&x, &homogeneous_du(&x, &u, c), &states, &mat, [0.0; 2]).expect("ok");
        let b = p2_element(
            &x,
            &homogeneous_du(&x, &mul(&r, &u), c),
            &states,
            &mat,
            [0.0; 2],
        )
        .expect("ok");
        for q in 0..3 {
            let s = a.states[q].stress;
            let sm = [[s[0], s[3]], [s[3], s[1]]];
            let rs = mul(&mul(&r, &sm), &[[r[0][0], r[1][0]], [r[0][1], r[1][1]]]);
            let want = [rs[0][0], rs[1][1], s[2], rs[0][1]];
            assert!(rel_close(&b.states[q].stress, &want, 1e-12));
        }
        for n in 0..6 {
            let v = apply(&r, [a.residual[2 * n], a.residual[2 * n + 1]]);
            assert!(rel_close(&b.residual[2 * n..2 * n + 2], &v, 1e-9));
        }
    }

    #[test]
    fn inverted_element_is_reported_with_its_jacobian() {
        let x = curved_element();
        let reflect = [[-1.0, 0.0], [0.0, 1.0]];
        let du = homogeneous_du(&x, &reflect, [0.0, 0.0]);
        let err = p2_element(&x, &du, &prestress(), &elastic(), [0.0; 2]).expect_err("inverted");
        match &err {
            ElementError::Inverted { j, .. } => assert!((j + 1.0).abs() < 1e-12),
            other => panic!("wrong error {other:?}"),
        }
        assert!(err.to_string().contains("J = det F = -1"), "{err}");
        let mut nan = [[0.0; 2]; 6];
        nan[2][1] = f64::NAN;
        assert!(matches!(
            p2_element(&x, &nan, &prestress(), &elastic(), [0.0; 2]),
            Err(ElementError::Inverted { .. })
        ));
        let cw = p2::straight_sided(&[[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]);
        assert!(matches!(
            p2_element(&cw, &[[0.0; 2]; 6], &prestress(), &elastic(), [0.0; 2]),
            Err(ElementError::DegenerateGeometry { .. })
        ));
    }

    #[test]
    fn body_force_is_consistent_load() {
        let v = [[0.0, 0.0], [2.0, 0.5], [0.5, 1.5]];
        let x = p2::straight_sided(&v);
        let area = 0.5 * (2.0 * 1.5 - 0.5 * 0.5);
        let b = [3.0, -19620.0];
        let out = p2_element(
            &x,
            &[[0.0; 2]; 6],
            &<[GaussState; 3]>::default(),
            &elastic(),
            b,
        )
        .expect("valid element");
        // P2 consistent load on a straight triangle: nothing at vertices, a third at each midside.
        for a in 0..6 {
            for i in 0..2 {
                let want = if a < 3 { 0.0 } else { -b[i] * area / 3.0 };
                let got = out.residual[2 * a + i];
                assert!(
                    (got - want).abs() < 1e-10 * b[1].abs(),
                    "node {a} comp {i}: {got}"
                );
            }
        }
    }

    #[test]
    fn gauss_points_lie_on_medians() {
        let v = [[1.0, 1.0], [4.0, 1.5], [2.0, 3.0]];
        let gp = p2_gauss_points(&p2::straight_sided(&v));
        for (q, p) in gp.iter().enumerate() {
            for i in 0..2 {
                let want = (v[0][i] + v[1][i] + v[2][i]) / 6.0 + 0.5 * v[q][i];
                assert!((p[i] - want).abs() < 1e-14);
            }
        }
    }

    // ---- patch tests on a small mesh --------------------------------------------------------

    struct Mesh {
        nodes: Vec<[f64; 2]>,
        elems: Vec<[usize; 6]>,
        fixed: Vec<bool>,
    }

    /// 3x3 vertices on [0,2]², centre vertex moved off-centre, 8 triangles, interior edges bowed.
    fn patch_mesh() -> Mesh {
        let mut nodes = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                nodes.push([f64::from(i), f64::from(j)]);
            }
        }
        nodes[4] = [1.15, 0.85];
        let v = |i: usize, j: usize| j * 3 + i;
        let mut tris = Vec::new();
        for j in 0..2 {
            for i in 0..2 {
                let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                if (i + j) % 2 == 0 {
                    tris.push([a, b, c]);
                    tris.push([a, c, d]);
                } else {
                    tris.push([a, b, d]);
                    tris.push([b, c, d]);
                }
            }
        }
        let mut edge_node: HashMap<(usize, usize), usize> = HashMap::new();
        let mut edge_count: HashMap<(usize, usize), usize> = HashMap::new();
        let mut elems = Vec::new();
        for t in &tris {
            let mut e = [t[0], t[1], t[2], 0, 0, 0];
            for (k, [i, j]) in p2::EDGES.iter().enumerate() {
                let key = (t[*i].min(t[*j]), t[*i].max(t[*j]));
                *edge_count.entry(key).or_insert(0) += 1;
                let id = *edge_node.entry(key).or_insert_with(|| {
                    let (p, q) = (nodes[key.0], nodes[key.1]);
                    nodes.push([0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])]);
                    nodes.len() - 1
                });
                e[3 + k] = id;
            }
            elems.push(e);
        }
        let mut fixed = vec![false; nodes.len()];
        for (key, id) in &edge_node {
            if edge_count[key] == 1 {
                fixed[key.0] = true;
                fixed[key.1] = true;
                fixed[*id] = true;
            } else {
                // Curve interior edges: linear fields must still be reproduced exactly.
                let s = 0.04 * (1.0 + (*id % 3) as f64);
                nodes[*id][0] += s;
                nodes[*id][1] -= 0.5 * s;
            }
        }
        Mesh {
            nodes,
            elems,
            fixed,
        }
    }

    /// Global residual, dense tangent and per-element Gauss states.
    type Assembled = (Vec<f64>, Vec<Vec<f64>>, Vec<[GaussState; 3]>);

    fn assemble(
        m: &Mesh,
        u: &[[f64; 2]],
        st: &GaussState,
        mat: &dyn Material,
    ) -> Result<Assembled, ElementError> {
        let n = 2 * m.nodes.len();
        let mut r = vec![0.0; n];
        let mut k = vec![vec![0.0; n]; n];
        let mut states = Vec::new();
        for e in &m.elems {
            let x: [[f64; 2]; 6] = std::array::from_fn(|a| m.nodes[e[a]]);
            let du: [[f64; 2]; 6] = std::array::from_fn(|a| u[e[a]]);
            let out = p2_element(&x, &du, &std::array::from_fn(|_| st.clone()), mat, [0.0; 2])?;
            let dof = |l: usize| 2 * e[l / 2] + l % 2;
            for p in 0..N_DOFS {
                r[dof(p)] += out.residual[p];
                for q in 0..N_DOFS {
                    k[dof(p)][dof(q)] += out.tangent[p][q];
                }
            }
            states.push(out.states);
        }
        Ok((r, k, states))
    }

    /// Dense Gauss elimination with partial pivoting.
    fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
        let n = b.len();
        for c in 0..n {
            let p = (c..n)
                .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
                .unwrap_or(c);
            a.swap(c, p);
            b.swap(c, p);
            assert!(a[c][c].abs() > 1e-300, "singular test system");
            for i in c + 1..n {
                let f = a[i][c] / a[c][c];
                if f != 0.0 {
                    for j in c..n {
                        a[i][j] -= f * a[c][j];
                    }
                    b[i] -= f * b[c];
                }
            }
        }
        let mut x = vec![0.0; n];
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|j| a[i][j] * x[j]).sum();
            x[i] = (b[i] - s) / a[i][i];
        }
        x
    }

    /// Imposes Δu = G x on the boundary, solves for the interior with Newton, and returns the
    /// converged interior error relative to the imposed field and all Gauss stresses.
    /// G = F − I is passed rather than F: forming F x − x would leave rounding noise of 1e-16
    /// absolute in Δu, which is 1e-8 relative for the tiny-displacement patch.
    fn run_patch(g: &Mat2, st: &GaussState) -> (f64, Vec<[GaussState; 3]>) {
        let m = patch_mesh();
        let mat = elastic();
        let exact: Vec<[f64; 2]> = m.nodes.iter().map(|p| apply(g, *p)).collect();
        let mut u: Vec<[f64; 2]> = exact
            .iter()
            .zip(&m.fixed)
            .map(|(e, &fx)| if fx { *e } else { [0.0; 2] })
            .collect();
        let free: Vec<usize> = (0..2 * m.nodes.len()).filter(|d| !m.fixed[d / 2]).collect();
        assert_eq!(
            free.len(),
            18,
            "1 interior vertex + 8 interior midside nodes"
        );
        let mut r_first = None;
        for _ in 0..30 {
            let (r, k, _) = assemble(&m, &u, st, &mat).expect("valid mesh");
            let rf: Vec<f64> = free.iter().map(|&d| -r[d]).collect();
            let kf: Vec<Vec<f64>> = free
                .iter()
                .map(|&i| free.iter().map(|&j| k[i][j]).collect())
                .collect();
            let rnorm = rf.iter().map(|v| v * v).sum::<f64>().sqrt();
            let r0 = *r_first.get_or_insert(rnorm);
            let dx = solve(kf, rf);
            for (d, v) in free.iter().zip(dx) {
                u[d / 2][d % 2] += v;
            }
            if rnorm <= 1e-13 * r0 {
                break;
            }
        }
        let (r, _, states) = assemble(&m, &u, st, &mat).expect("valid mesh");
        let rscale = r.iter().fold(0.0_f64, |a, v| a.max(v.abs())).max(1e-300);
        for &d in &free {
            assert!(r[d].abs() <= 1e-9 * rscale, "interior residual {}", r[d]);
        }
        let uscale = exact.iter().flatten().fold(0.0_f64, |a, v| a.max(v.abs()));
        let err = u
            .iter()
            .zip(&exact)
            .flat_map(|(a, b)| [(a[0] - b[0]).abs(), (a[1] - b[1]).abs()])
            .fold(0.0_f64, f64::max);
        (err / uscale, states)
    }

    /// Closed form σ_{n+1} for a homogeneous F = I + G, computed straight from the definitions
    /// (C − I = G + Gᵀ + GᵀG, kept in terms of G for precision when G is tiny).
    fn closed_form_cauchy(g: &Mat2, sigma_n: &[f64; 4]) -> [f64; 4] {
        let (l, mu) = elastic().lame();
        let gtg = mul(&[[g[0][0], g[1][0]], [g[0][1], g[1][1]]], g);
        let e: Mat2 =
            std::array::from_fn(|i| std::array::from_fn(|k| 0.5 * (g[i][k] + g[k][i] + gtg[i][k])));
        let f = &[[1.0 + g[0][0], g[0][1]], [g[1][0], 1.0 + g[1][1]]];
        let tr = e[0][0] + e[1][1];
        let s = [
            [
                sigma_n[0] + l * tr + 2.0 * mu * e[0][0],
                sigma_n[3] + 2.0 * mu * e[0][1],
            ],
            [
                sigma_n[3] + 2.0 * mu * e[1][0],
                sigma_n[1] + l * tr + 2.0 * mu * e[1][1],
            ],
        ];
        let szz = sigma_n[2] + l * tr;
        let j = 1.0 + g[0][0] + g[1][1] + g[0][0] * g[1][1] - g[0][1] * g[1][0];
        let ft = [[f[0][0], f[1][0]], [f[0][1], f[1][1]]];
        let sig = mul(&mul(f, &s), &ft);
        [sig[0][0] / j, sig[1][1] / j, szz / j, sig[0][1] / j]
    }

    #[test]
    fn patch_test_small_strain() {
        let g = [[1.0e-8, -0.4e-8], [0.7e-8, -0.6e-8]];
        let st = GaussState::default();
        let (err, states) = run_patch(&g, &st);
        assert!(err < 1e-9, "interior displacement error {err:e}");
        // Small-strain closed form σ = D ε.
        let (l, mu) = elastic().lame();
        let (exx, eyy, gxy) = (g[0][0], g[1][1], g[0][1] + g[1][0]);
        let lin = [
            l * (exx + eyy) + 2.0 * mu * exx,
            l * (exx + eyy) + 2.0 * mu * eyy,
            l * (exx + eyy),
            mu * gxy,
        ];
        let exact = closed_form_cauchy(&g, &st.stress);
        for s in states.iter().flatten() {
            assert!(
                rel_close(&s.stress, &exact, 1e-9),
                "{:?} vs {exact:?}",
                s.stress
            );
            assert!(
                rel_close(&s.stress, &lin, 1e-6),
                "{:?} vs {lin:?}",
                s.stress
            );
        }
    }

    #[test]
    fn patch_test_large_uniform_stretch() {
        let g = [[0.2, 0.0], [0.0, -0.1]]; // F = diag(1.2, 0.9)
        let st = GaussState {
            stress: [-1.0e5, -2.0e5, -1.2e5, 4.0e4],
            ..GaussState::default()
        };
        let (err, states) = run_patch(&g, &st);
        assert!(err < 1e-10, "interior displacement error {err:e}");
        let exact = closed_form_cauchy(&g, &st.stress);
        // Spelled out for F = diag(1.2, 0.9): E = diag(0.22, -0.095), J = 1.08.
        let (l, mu) = elastic().lame();
        let sxx = st.stress[0] + l * 0.125 + 2.0 * mu * 0.22;
        let syy = st.stress[1] + l * 0.125 - 2.0 * mu * 0.095;
        let by_hand = [
            1.44 * sxx / 1.08,
            0.81 * syy / 1.08,
            (st.stress[2] + l * 0.125) / 1.08,
            st.stress[3],
        ];
        assert!(
            rel_close(&exact, &by_hand, 1e-13),
            "{exact:?} vs {by_hand:?}"
        );
        for s in states.iter().flatten() {
            assert!(
                rel_close(&s.stress, &exact, 1e-10),
                "{:?} vs {exact:?}",
                s.stress
            );
        }
    }
}
