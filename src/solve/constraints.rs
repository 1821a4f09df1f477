//! Dirichlet conditions of one step, recovered from geometry after every remesh: a selector picks
//! particles by their reference (initial) position, so supports and platens stay attached to the
//! same material whatever the remesh did.

use super::dofs::DofMap;

/// A prescribed step displacement per node and component (`None` = free).
#[derive(Debug, Clone)]
pub struct Constraints {
    pub fixed: Vec<[Option<f64>; 2]>,
}

impl Constraints {
    /// `point_bc(p)` gives the prescribed step displacement of local point p per component. An edge
    /// node is constrained in a component when both endpoints are, with their mean value: a
    /// straight constrained side stays straight.
    pub fn build(dofs: &DofMap, point_bc: impl Fn(usize) -> [Option<f64>; 2]) -> Constraints {
        let n_vertex = dofs.n_nodes() - dofs.edges.len();
        let mut fixed = vec![[None, None]; dofs.n_nodes()];
        for (n, f) in fixed.iter_mut().enumerate().take(n_vertex) {
            *f = point_bc(dofs.node_point[n] as usize);
        }
        for (e, [a, b]) in dofs.edges.iter().enumerate() {
            let (ga, gb) = (point_bc(*a as usize), point_bc(*b as usize));
            for c in 0..2 {
                if let (Some(x), Some(y)) = (ga[c], gb[c]) {
                    fixed[n_vertex + e][c] = Some(0.5 * (x + y));
                }
            }
        }
        Constraints { fixed }
    }
}
