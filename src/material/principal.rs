//! Plane-strain stresses in their principal frame, for models whose return mapping works on
//! principal values (Mohr–Coulomb). In plane strain zz is always a principal direction, so the
//! frame is the in-plane eigenvectors (angle θ) plus z, and the three principal values are
//! `[A, B, Z]` with A ≥ B the in-plane pair. Keeping σzz among them is what lets a criterion that
//! reads all three (σzz may be the major or minor stress) carry over to axisymmetry unchanged.
//!
//! The tangent of an isotropic function σ = f(σ_tr) has two parts: the derivatives of the
//! principal values with respect to the trial's, and a spin part on the in-plane shear of the
//! eigenframe, (σ_A − σ_B)/(σ_tr,A − σ_tr,B), since rotating the trial's eigenvectors rotates the
//! result's with them.

/// A plane-strain stress `[xx, yy, zz, xy]` (tensor shear) in its principal frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spectral {
    /// Principal values `[A, B, Z]`: the larger and smaller in-plane ones, then σzz.
    pub values: [f64; 3],
    /// cos θ and sin θ of the in-plane eigenvector of A.
    pub cos: f64,
    pub sin: f64,
}

impl Spectral {
    pub fn of(s: &[f64; 4]) -> Spectral {
        let m = 0.5 * (s[0] + s[1]);
        let a = 0.5 * (s[0] - s[1]);
        let r = a.hypot(s[3]);
        // atan2(0, 0) = 0: an in-plane isotropic stress takes the x axis as its frame.
        let (sin, cos) = (0.5 * s[3].atan2(a)).sin_cos();
        Spectral {
            values: [m + r, m - r, s[2]],
            cos,
            sin,
        }
    }

    /// The Voigt stress with principal values `values` in this frame.
    pub fn compose(&self, values: &[f64; 3]) -> [f64; 4] {
        let (c, s) = (self.cos, self.sin);
        let [a, b, z] = *values;
        [
            c * c * a + s * s * b,
            s * s * a + c * c * b,
            z,
            c * s * (a - b),
        ]
    }

    /// The engineering-shear Voigt strain with principal values `values` in this frame.
    pub fn compose_strain(&self, values: &[f64; 3]) -> [f64; 4] {
        let mut e = self.compose(values);
        e[3] *= 2.0;
        e
    }

    /// dσ/dσ_tr in global Voigt components (tensor shear on both sides) of the isotropic
    /// function that maps this (trial) frame's principal values to `values` with derivatives
    /// `dv[i][j]` = ∂σ_i/∂σ_tr,j (indices A, B, Z).
    // Index loops mirror the component notation of the products.
    #[allow(clippy::needless_range_loop)]
    pub fn isotropic_tangent(&self, values: &[f64; 3], dv: &[[f64; 3]; 3]) -> [[f64; 4]; 4] {
        let tr = &self.values;
        let gap = tr[0] - tr[1];
        let scale = tr.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // Equal in-plane trial values: the ratio's limit, which the isotropy of f makes the
        // difference of the principal derivatives.
        let spin = if gap > 1e-10 * scale {
            (values[0] - values[1]) / gap
        } else {
            dv[0][0] - dv[0][1]
        };
        let mut local = [[0.0; 4]; 4];
        for i in 0..3 {
            local[i][..3].copy_from_slice(&dv[i]);
        }
        local[3][3] = spin;
        let to = self.frame_map(1.0);
        let from = self.frame_map(-1.0);
        let mut out = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                out[i][j] = (0..4)
                    .map(|k| from[i][k] * (0..4).map(|l| local[k][l] * to[l][j]).sum::<f64>())
                    .sum();
            }
        }
        out
    }

    /// The response of a return in this (trial) frame: principal stresses `values` with
    /// derivatives `dv` by the trial's, the plastic strain `plastic` (principal values) added to
    /// `state`'s plastic strain and `eps_q` (Mohr–Coulomb's layout, which Tresca shares), the tangent the isotropic one times the elastic `trial_d`.
    pub fn returned(
        &self,
        values: &[f64; 3],
        dv: &[[f64; 3]; 3],
        plastic: &[f64; 3],
        trial_d: &[[f64; 4]; 4],
        mut state: super::GaussState,
    ) -> super::MaterialResponse {
        use super::mohr_coulomb::{EPS_Q, PLASTIC_STRAIN};
        let dep = self.compose_strain(plastic);
        for (p, d) in state.internal[PLASTIC_STRAIN..PLASTIC_STRAIN + 4]
            .iter_mut()
            .zip(dep)
        {
            *p += d;
        }
        state.internal[EPS_Q] += super::layout::equivalent_plastic_strain(&dep);
        super::MaterialResponse {
            s: self.compose(values),
            d: product(&self.isotropic_tangent(values, dv), trial_d),
            state,
        }
    }

    /// The map of tensor-shear Voigt stresses into the eigenframe (`sign` 1) or back (−1).
    fn frame_map(&self, sign: f64) -> [[f64; 4]; 4] {
        let (c, s) = (self.cos, sign * self.sin);
        [
            [c * c, s * s, 0.0, 2.0 * c * s],
            [s * s, c * c, 0.0, -2.0 * c * s],
            [0.0, 0.0, 1.0, 0.0],
            [-c * s, c * s, 0.0, c * c - s * s],
        ]
    }
}

/// `a` (4×4) times `b` (4×4).
pub fn product(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..4).map(|k| a[i][k] * b[k][j]).sum()))
}

/// Solves the n×n system `a x = b` (n ≤ 3, row-major in the leading block) by Gaussian
/// elimination with partial pivoting; `None` when a pivot is below 1e-12 of the largest entry.
pub fn solve_small(n: usize, a: &[[f64; 3]; 3], b: &[f64; 3]) -> Option<[f64; 3]> {
    let mut m = *a;
    let mut x = *b;
    let big = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .fold(0.0f64, |acc, (i, j)| acc.max(a[i][j].abs()));
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        if m[piv][col].abs() <= 1e-12 * big {
            return None;
        }
        m.swap(col, piv);
        x.swap(col, piv);
        for row in col + 1..n {
            let f = m[row][col] / m[col][col];
            let pivot_row = m[col];
            for (mk, pk) in m[row][col..n].iter_mut().zip(&pivot_row[col..n]) {
                *mk -= f * pk;
            }
            x[row] -= f * x[col];
        }
    }
    for col in (0..n).rev() {
        let tail: f64 = (col + 1..n).map(|k| m[col][k] * x[k]).sum();
        x[col] = (x[col] - tail) / m[col][col];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decomposition_round_trips() {
        for s in [
            [-3.0, 1.0, -0.5, 2.0],
            [2.0, 2.0, 1.0, 0.0],
            [-1.0, 4.0, 7.0, -3.0],
        ] {
            let sp = Spectral::of(&s);
            assert!(sp.values[0] >= sp.values[1]);
            let back = sp.compose(&sp.values);
            for k in 0..4 {
                assert!((back[k] - s[k]).abs() < 1e-14 * 8.0, "{s:?}: {back:?}");
            }
        }
    }

    #[test]
    fn identity_function_has_the_identity_tangent() {
        let sp = Spectral::of(&[-3.0, 1.0, -0.5, 2.0]);
        let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let t = sp.isotropic_tangent(&sp.values, &eye);
        for (i, row) in t.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-14, "[{i}][{j}] {v}");
            }
        }
    }

    #[test]
    fn small_systems_solve_and_singular_ones_are_refused() {
        let a = [[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]];
        let x = solve_small(3, &a, &[3.0, 5.0, 5.0]).unwrap();
        for (xi, want) in x.iter().zip([1.0, 1.0, 1.0]) {
            assert!((xi - want).abs() < 1e-14);
        }
        let s = [[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 0.0]];
        assert!(solve_small(2, &s, &[1.0, 2.0, 0.0]).is_none());
        assert_eq!(solve_small(1, &a, &[4.0, 0.0, 0.0]).unwrap()[0], 2.0);
    }
}
