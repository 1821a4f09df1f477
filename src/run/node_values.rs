//! The last increment's nodal solution by global node key, the next step's predictor.

/// Values by node key (`[gid, gid]` for a vertex, the sorted end ids for a midside node), kept
/// as one sorted array: a hash map of the same entries took about twice the memory (its
/// buckets rounded up to a power of two), and it lives beside every solve.
#[derive(Debug, Default)]
pub struct NodeValues {
    entries: Vec<([u64; 2], [f64; 3])>,
}

impl NodeValues {
    /// From entries in any order; of repeated keys the first is kept.
    pub fn new(mut entries: Vec<([u64; 2], [f64; 3])>) -> Self {
        entries.sort_by_key(|e| e.0);
        entries.dedup_by_key(|e| e.0);
        entries.shrink_to_fit();
        NodeValues { entries }
    }

    pub fn get(&self, key: &[u64; 2]) -> Option<&[f64; 3]> {
        self.entries
            .binary_search_by_key(key, |e| e.0)
            .ok()
            .map(|i| &self.entries[i].1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_every_key_and_keeps_the_first_of_repeats() {
        let v = NodeValues::new(vec![
            ([5, 9], [1.0, 2.0, 3.0]),
            ([1, 1], [4.0, 5.0, 6.0]),
            ([5, 9], [7.0, 8.0, 9.0]),
            ([2, 7], [0.5, 0.25, f64::NAN]),
        ]);
        assert_eq!(v.entries.len(), 3);
        assert_eq!(v.get(&[5, 9]), Some(&[1.0, 2.0, 3.0]));
        assert_eq!(v.get(&[1, 1]), Some(&[4.0, 5.0, 6.0]));
        assert_eq!(v.get(&[2, 7]).map(|x| x[1]), Some(0.25));
        assert_eq!(v.get(&[9, 5]), None);
        assert!(NodeValues::default().get(&[1, 1]).is_none());
    }
}
