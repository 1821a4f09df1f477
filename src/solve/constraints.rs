//! Dirichlet conditions of one step, recovered from geometry after every remesh: a selector picks
//! particles by their reference (initial) position, so supports and platens stay attached to the
//! same material whatever the remesh did.

use super::dofs::DofMap;

/// A prescribed step displacement per node and component. Prescribed nodes are a boundary's
/// few: one byte a node says which components are, and only those carry values (a value per
/// node and component was 32 bytes a node, 20 MB of 840 at the memory peak of the cantilever at
/// h = 1/128 on 1 rank).
#[derive(Debug, Clone)]
pub struct Constraints {
    /// Per node, bit c set where component c is prescribed.
    mask: Vec<u8>,
    /// The prescribed nodes, increasing, with their values (0 for a free component).
    values: Vec<(usize, [f64; 2])>,
}

impl Constraints {
    /// `point_bc(p)` gives the prescribed step displacement of local point p per component. An edge
    /// node is constrained in a component when both endpoints are, with their mean value: a
    /// straight constrained side stays straight.
    pub fn build(dofs: &DofMap, point_bc: impl Fn(usize) -> [Option<f64>; 2]) -> Constraints {
        let n_vertex = dofs.n_nodes() - dofs.edges.len();
        let mut c = Constraints::none(dofs.n_nodes());
        for n in 0..n_vertex {
            c.set(n, point_bc(dofs.node_point[n] as usize));
        }
        for (e, [a, b]) in dofs.edges.iter().enumerate() {
            let (ga, gb) = (point_bc(*a as usize), point_bc(*b as usize));
            let mean = |k: usize| ga[k].zip(gb[k]).map(|(x, y)| 0.5 * (x + y));
            c.set(n_vertex + e, [mean(0), mean(1)]);
        }
        c
    }

    /// `n_nodes` nodes, none prescribed.
    fn none(n_nodes: usize) -> Constraints {
        Constraints {
            mask: vec![0; n_nodes],
            values: Vec::new(),
        }
    }

    /// Nodes must come in increasing order.
    fn set(&mut self, n: usize, g: [Option<f64>; 2]) {
        debug_assert!(self.values.last().is_none_or(|&(m, _)| m < n));
        let bits = u8::from(g[0].is_some()) | (u8::from(g[1].is_some()) << 1);
        if bits != 0 {
            self.mask[n] = bits;
            self.values
                .push((n, [g[0].unwrap_or(0.0), g[1].unwrap_or(0.0)]));
        }
    }

    /// Whether component `c` of node `n` is prescribed (a pressure, `c` = 2, never is).
    pub fn is_fixed(&self, n: usize, c: usize) -> bool {
        c < 2 && self.mask[n] & (1 << c) != 0
    }

    /// The prescribed step displacement of component `c` of node `n`, if it is prescribed.
    pub fn value(&self, n: usize, c: usize) -> Option<f64> {
        if !self.is_fixed(n, c) {
            return None;
        }
        let i = self
            .values
            .binary_search_by_key(&n, |&(m, _)| m)
            .expect("a masked node has a value");
        Some(self.values[i].1[c])
    }

    /// Every prescribed (node, component, value), nodes increasing.
    pub fn prescribed(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        self.values.iter().flat_map(move |&(n, v)| {
            (0..2)
                .filter(move |&c| self.is_fixed(n, c))
                .map(move |c| (n, c, v[c]))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_prescribed_components_have_values() {
        let mut c = Constraints::none(5);
        c.set(0, [None, None]);
        c.set(1, [Some(0.5), None]);
        c.set(3, [Some(-2.0), Some(-1.0)]);
        c.set(4, [None, Some(0.25)]);
        let fixed: Vec<(usize, usize)> = (0..5)
            .flat_map(|n| (0..3).map(move |k| (n, k)))
            .filter(|&(n, k)| c.is_fixed(n, k))
            .collect();
        assert_eq!(fixed, [(1, 0), (3, 0), (3, 1), (4, 1)]);
        assert_eq!(c.value(1, 0), Some(0.5));
        assert_eq!(c.value(1, 1), None);
        assert_eq!(c.value(3, 1), Some(-1.0));
        assert_eq!(c.value(4, 1), Some(0.25));
        assert_eq!(c.value(2, 0), None);
        assert_eq!(c.value(3, 2), None, "a pressure is never prescribed");
        let all: Vec<_> = c.prescribed().collect();
        assert_eq!(all, [(1, 0, 0.5), (3, 0, -2.0), (3, 1, -1.0), (4, 1, 0.25)]);
        assert_eq!(c.values.len(), 3, "free nodes carry no value");
    }
}
