//! The damping of the p-multigrid's Jacobi smoother, from a bound on the spectrum of
//! diag(K)⁻¹K that the element tangents give without an eigenvalue estimate.
//!
//! For K = Σₑ Kₑ (symmetric element matrices with positive diagonals) and any x,
//! xᵀKx = Σₑ xₑᵀKₑxₑ ≤ Σₑ λₑ xₑᵀdiag(Kₑ)xₑ ≤ (maxₑ λₑ) xᵀdiag(K)x, where λₑ bounds the
//! eigenvalues of diag(Kₑ)⁻¹Kₑ. So the largest λₑ bounds the eigenvalues of diag(K)⁻¹K: no
//! Krylov estimate is needed, and PETSc's estimator (three work vectors of the fine level, ten
//! matrix products per set-up) goes. Gershgorin's theorem on the symmetrically scaled element
//! matrix gives λₑ from its entries alone.

/// The Richardson damping of one Jacobi sweep, ω = 2 / (1.1 `bound`): the single Chebyshev step
/// on [0.1 b, b] (PETSc's Chebyshev smoother targets [0.1, 1.1] times its estimate, which lies
/// below the largest eigenvalue; `bound` lies above it).
pub fn jacobi_damping(bound: f64) -> f64 {
    2.0 / (1.1 * bound)
}

/// An upper bound on the eigenvalues of diag(K)⁻¹K for the row-major `n` × `n` symmetric element
/// matrix `k` restricted to its free dofs (bit i of `fixed` set: dof i prescribed, its row and
/// column zero in the assembled matrix). Gershgorin on D^(−1/2) K D^(−1/2): the largest row sum
/// of |kᵢⱼ| / √(kᵢᵢ kⱼⱼ). A free row with a negative diagonal, or a zero one and a nonzero
/// off-diagonal, and any NaN give infinity: no damping is safe there.
pub fn element_jacobi_bound(k: &[f64], n: usize, fixed: u16) -> f64 {
    debug_assert!(n <= 16 && k.len() >= n * n);
    // 1/√kᵢᵢ on free dofs, 0 on prescribed ones (their rows and columns take no part).
    let mut scale = [0.0; 16];
    for (i, s) in scale.iter_mut().enumerate().take(n) {
        let d = k[i * n + i];
        if fixed & 1 << i != 0 {
            continue;
        }
        if d > 0.0 {
            *s = 1.0 / d.sqrt();
        } else if d < 0.0
            || d.is_nan()
            || (0..n).any(|j| j != i && fixed & 1 << j == 0 && k[i * n + j] != 0.0)
        {
            // The summation argument needs non-negative diagonals.
            return f64::INFINITY;
        }
    }
    // Row sums of the scaled |K| from its upper triangle (K is symmetric); a free row's
    // diagonal term is 1.
    let mut rows = [0.0; 16];
    for i in 0..n {
        let si = scale[i];
        if si > 0.0 {
            rows[i] += 1.0;
        }
        for j in i + 1..n {
            let v = k[i * n + j].abs() * si * scale[j];
            rows[i] += v;
            rows[j] += v;
        }
    }
    if rows[..n].iter().any(|r| r.is_nan()) {
        return f64::INFINITY;
    }
    rows[..n].iter().fold(0.0, |m: f64, &r| m.max(r))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    fn scaled_eigenvalues(k: &DMatrix<f64>) -> Vec<f64> {
        let d = k.diagonal().map(|v| 1.0 / v.sqrt());
        let s = DMatrix::from_fn(k.nrows(), k.ncols(), |i, j| d[i] * k[(i, j)] * d[j]);
        s.symmetric_eigenvalues().iter().copied().collect()
    }

    /// A symmetric positive definite matrix with entries of both signs.
    fn spd(n: usize, seed: u64) -> DMatrix<f64> {
        let mut state = seed;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let a = DMatrix::from_fn(n, n, |_, _| next());
        &a * a.transpose() + DMatrix::identity(n, n) * 0.01
    }

    #[test]
    fn bounds_the_scaled_spectrum_of_random_spd_matrices() {
        for seed in 0..50 {
            let k = spd(12, seed);
            let flat: Vec<f64> = k.transpose().iter().copied().collect();
            let bound = element_jacobi_bound(&flat, 12, 0);
            let largest = scaled_eigenvalues(&k).into_iter().fold(0.0, f64::max);
            assert!(bound >= largest * (1.0 - 1e-12), "{bound} < {largest}");
            // Gershgorin is within a factor n of the largest eigenvalue (it bounds n × the
            // largest scaled entry, which the largest eigenvalue is at least).
            assert!(bound <= 12.0 * largest, "{bound} vs {largest}");
        }
    }

    #[test]
    fn a_prescribed_dof_leaves_the_bound_of_the_free_block() {
        let k = spd(6, 7);
        let flat: Vec<f64> = k.transpose().iter().copied().collect();
        let fixed = 0b000101;
        let free: Vec<usize> = (0..6).filter(|i| fixed & 1 << i == 0).collect();
        let block = DMatrix::from_fn(free.len(), free.len(), |a, b| k[(free[a], free[b])]);
        let block_flat: Vec<f64> = block.transpose().iter().copied().collect();
        assert_eq!(
            element_jacobi_bound(&flat, 6, fixed),
            element_jacobi_bound(&block_flat, free.len(), 0)
        );
        assert!(element_jacobi_bound(&flat, 6, fixed) <= element_jacobi_bound(&flat, 6, 0));
    }

    #[test]
    fn the_assembled_matrix_obeys_the_largest_element_bound() {
        // Two 4 × 4 elements sharing dofs 2 and 3 of a 6-dof system.
        let (a, b) = (spd(4, 3), spd(4, 11));
        let mut k = DMatrix::zeros(6, 6);
        for i in 0..4 {
            for j in 0..4 {
                k[(i, j)] += a[(i, j)];
                k[(i + 2, j + 2)] += b[(i, j)];
            }
        }
        let bound = [a, b]
            .iter()
            .map(|e| element_jacobi_bound(&e.transpose().iter().copied().collect::<Vec<_>>(), 4, 0))
            .fold(0.0, f64::max);
        let largest = scaled_eigenvalues(&k).into_iter().fold(0.0, f64::max);
        assert!(largest <= bound, "{largest} > {bound}");
    }

    #[test]
    fn a_free_row_without_diagonal_has_no_bound() {
        let k = [0.0, 1.0, 1.0, 2.0];
        assert_eq!(element_jacobi_bound(&k, 2, 0), f64::INFINITY);
        assert!((element_jacobi_bound(&k, 2, 0b01) - 1.0).abs() < 1e-15);
        assert_eq!(
            element_jacobi_bound(&[-1.0, 0.0, 0.0, 2.0], 2, 0),
            f64::INFINITY
        );
        assert_eq!(
            element_jacobi_bound(&[1.0, f64::NAN, f64::NAN, 2.0], 2, 0),
            f64::INFINITY
        );
        assert!((jacobi_damping(4.0) - 2.0 / 4.4).abs() < 1e-15);
    }
}
