//! The last increment's nodal solution by global node key, the next step's predictor.

/// Values by node key (`[gid, gid]` for a vertex, the sorted end ids for a midside node), kept
/// as sorted arrays: a hash map of the same entries took about twice the memory (its buckets
/// rounded up to a power of two), and it lives beside every solve. A vertex's displacement
/// increment is its particle's (`Particles::increment`, the same numbers), so vertices are kept
/// only where their pressure is a solution value (mixed elements); a midside node carries no
/// pressure. For P2 that is 3 entries of 32 bytes a particle instead of 4 of 40.
/// Where a vertex has one pressure per material (a scene of several materials), `vertices`
/// holds its lowest material's and `by_material` every one; one-material scenes keep no second
/// copy.
#[derive(Debug, Default)]
pub struct NodeValues {
    vertices: Vec<(u64, [f64; 3])>,
    edges: Vec<([u64; 2], [f64; 2])>,
    by_material: Vec<((u64, u32), f64)>,
}

impl NodeValues {
    /// From entries in any order; of repeated keys the first is kept. Vertices are kept only
    /// with `pressures`.
    pub fn new(entries: impl IntoIterator<Item = ([u64; 2], [f64; 3])>, pressures: bool) -> Self {
        let mut vertices = Vec::new();
        let mut edges = Vec::new();
        for (key, v) in entries {
            if key[0] != key[1] {
                edges.push((key, [v[0], v[1]]));
            } else if pressures {
                vertices.push((key[0], v));
            }
        }
        vertices.sort_by_key(|e| e.0);
        vertices.dedup_by_key(|e| e.0);
        vertices.shrink_to_fit();
        edges.sort_by_key(|e| e.0);
        edges.dedup_by_key(|e| e.0);
        edges.shrink_to_fit();
        NodeValues {
            vertices,
            edges,
            by_material: Vec::new(),
        }
    }

    /// With the pressures per (vertex gid, material), in any order; of repeated keys the first
    /// is kept.
    pub fn with_material_pressures(
        mut self,
        entries: impl IntoIterator<Item = ((u64, u32), f64)>,
    ) -> Self {
        let mut by_material: Vec<((u64, u32), f64)> = entries.into_iter().collect();
        by_material.sort_by_key(|e| e.0);
        by_material.dedup_by_key(|e| e.0);
        by_material.shrink_to_fit();
        self.by_material = by_material;
        self
    }

    /// The pressure of vertex `gid` in `material`, where pressures were per material.
    pub fn pressure(&self, gid: u64, material: u32) -> Option<f64> {
        let i = self
            .by_material
            .binary_search_by_key(&(gid, material), |e| e.0)
            .ok()?;
        Some(self.by_material[i].1)
    }

    /// The node's displacement increment and pressure (zero at a midside node).
    pub fn get(&self, key: &[u64; 2]) -> Option<[f64; 3]> {
        if key[0] == key[1] {
            let i = self.vertices.binary_search_by_key(&key[0], |e| e.0).ok()?;
            Some(self.vertices[i].1)
        } else {
            let i = self.edges.binary_search_by_key(key, |e| e.0).ok()?;
            let [x, y] = self.edges[i].1;
            Some([x, y, 0.0])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_every_key_and_keeps_the_first_of_repeats() {
        let entries = vec![
            ([5, 9], [1.0, 2.0, 3.0]),
            ([1, 1], [4.0, 5.0, 6.0]),
            ([5, 9], [7.0, 8.0, 9.0]),
            ([2, 7], [0.5, 0.25, f64::NAN]),
        ];
        let v = NodeValues::new(entries.clone(), true);
        assert_eq!((v.vertices.len(), v.edges.len()), (1, 2));
        assert_eq!(v.get(&[5, 9]), Some([1.0, 2.0, 0.0]));
        assert_eq!(v.get(&[1, 1]), Some([4.0, 5.0, 6.0]));
        assert_eq!(v.get(&[2, 7]).map(|x| x[1]), Some(0.25));
        assert_eq!(v.get(&[9, 5]), None);
        assert!(NodeValues::default().get(&[1, 1]).is_none());
        // Without pressures a vertex is left to its particle.
        let v = NodeValues::new(entries, false);
        assert_eq!(v.get(&[1, 1]), None);
        assert_eq!(v.get(&[5, 9]), Some([1.0, 2.0, 0.0]));
    }

    #[test]
    fn pressures_per_material_are_found_by_vertex_and_material() {
        let v = NodeValues::new([([4, 4], [0.0, 0.0, 1.0])], true).with_material_pressures([
            ((4, 2), 3.0),
            ((4, 0), 1.0),
            ((4, 2), 9.0),
        ]);
        assert_eq!(v.pressure(4, 2), Some(3.0));
        assert_eq!(v.pressure(4, 0), Some(1.0));
        assert_eq!(v.pressure(4, 1), None);
        assert_eq!(v.pressure(5, 0), None);
        assert_eq!(NodeValues::default().pressure(4, 0), None);
    }
}
