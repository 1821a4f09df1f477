//! The linear (P1) triangle: the gradient of a linear field from its vertex values, and the
//! plane-strain stiffness (the coarse level of the p-multigrid, `solve::pmg`). Pure numerics.

/// Gradient of the linear field with vertex values `f` over the triangle `x`; `None` for a
/// degenerate triangle. The arithmetic is fixed by the vertex order, so a caller that orders
/// the vertices canonically gets the same bits on every rank (`mesh::adapt`).
pub fn gradient(x: [[f64; 2]; 3], f: [f64; 3]) -> Option<[f64; 2]> {
    let d1 = [x[1][0] - x[0][0], x[1][1] - x[0][1]];
    let d2 = [x[2][0] - x[0][0], x[2][1] - x[0][1]];
    let det = d1[0] * d2[1] - d1[1] * d2[0];
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let (a, b) = (f[1] - f[0], f[2] - f[0]);
    Some([(a * d2[1] - b * d1[1]) / det, (b * d1[0] - a * d2[0]) / det])
}

/// The area of the triangle `x` (either orientation).
pub fn area(x: &[[f64; 2]; 3]) -> f64 {
    (0.5 * ((x[1][0] - x[0][0]) * (x[2][1] - x[0][1]) - (x[1][1] - x[0][1]) * (x[2][0] - x[0][0])))
        .abs()
}

/// The gradients of the three shape functions (vertex a: 1 there, 0 at the others).
pub fn shape_gradients(x: &[[f64; 2]; 3]) -> Option<[[f64; 2]; 3]> {
    let unit = |a: usize| std::array::from_fn(|b| if a == b { 1.0 } else { 0.0 });
    Some([
        gradient(*x, unit(0))?,
        gradient(*x, unit(1))?,
        gradient(*x, unit(2))?,
    ])
}

/// The plane-strain stiffness of a linear triangle with vertices `x` and tangent `d` (Voigt
/// xx, yy, engineering xy), dofs (node0 ux, node0 uy, node1 ux, ...).
pub fn stiffness(x: &[[f64; 2]; 3], d: &[[f64; 3]; 3]) -> [[f64; 6]; 6] {
    let Some(grad) = shape_gradients(x) else {
        return [[0.0; 6]; 6];
    };
    let area = area(x);
    let mut strain = [[0.0; 6]; 3];
    for (a, g) in grad.iter().enumerate() {
        strain[0][2 * a] = g[0];
        strain[1][2 * a + 1] = g[1];
        strain[2][2 * a] = g[1];
        strain[2][2 * a + 1] = g[0];
    }
    let mut k = [[0.0; 6]; 6];
    for (i, ki) in k.iter_mut().enumerate() {
        for (j, kij) in ki.iter_mut().enumerate() {
            let mut s = 0.0;
            for p in 0..3 {
                for q in 0..3 {
                    s += strain[p][i] * d[p][q] * strain[q][j];
                }
            }
            *kij = area * s;
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    fn d(e: f64, nu: f64) -> [[f64; 3]; 3] {
        let l = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let m = e / (2.0 * (1.0 + nu));
        [[l + 2.0 * m, l, 0.0], [l, l + 2.0 * m, 0.0], [0.0, 0.0, m]]
    }

    fn apply(k: &[[f64; 6]; 6], u: &[f64; 6]) -> [f64; 6] {
        std::array::from_fn(|i| (0..6).map(|j| k[i][j] * u[j]).sum())
    }

    #[test]
    fn rigid_body_modes_cost_nothing_and_a_stretch_gives_its_force() {
        let x = [[0.1, 0.2], [1.3, 0.1], [0.4, 0.9]];
        let (e, nu) = (10.0e6, 0.3);
        let k = stiffness(&x, &d(e, nu));
        let scale = e;
        for mode in [
            [1.0, 0.0, 1.0, 0.0, 1.0, 0.0],
            [0.0, 1.0, 0.0, 1.0, 0.0, 1.0],
            std::array::from_fn(|i| {
                if i % 2 == 0 {
                    -x[i / 2][1]
                } else {
                    x[i / 2][0]
                }
            }),
        ] {
            let f = apply(&k, &mode);
            assert!(f.iter().all(|v| v.abs() < 1e-9 * scale), "{f:?}");
        }
        // A uniform stretch εxx = 1e-3: strain energy ½ (λ + 2μ) ε² × area.
        let u: [f64; 6] =
            std::array::from_fn(|i| if i % 2 == 0 { 1e-3 * x[i / 2][0] } else { 0.0 });
        let energy = 0.5 * u.iter().zip(apply(&k, &u)).map(|(a, b)| a * b).sum::<f64>();
        let area = 0.5 * ((1.3 - 0.1) * (0.9 - 0.2) - (0.4 - 0.1) * (0.1 - 0.2));
        let want = 0.5 * d(e, nu)[0][0] * 1e-6 * area;
        assert!((energy - want).abs() < 1e-12 * want, "{energy} vs {want}");
    }
}
