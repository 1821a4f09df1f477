//! The linear (P1) triangle: the gradient of a linear field from its vertex values, its shape
//! gradients and area. Pure numerics.

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
