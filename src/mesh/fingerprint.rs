//! A hash of the global mesh that does not depend on how it is distributed.

/// FNV-1a over the sorted list of global-id triangles (each smallest-gid first, CCW): equal
/// fingerprints mean equal meshes, whatever the rank count that built them.
pub fn fingerprint(sorted_tris: &[[u64; 3]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for t in sorted_tris {
        for g in t {
            for b in g.to_le_bytes() {
                h ^= b as u64;
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_and_content_matter() {
        let a = [[0, 1, 2], [1, 3, 2]];
        let b = [[1, 3, 2], [0, 1, 2]];
        let c = [[0, 1, 2], [1, 2, 3]];
        assert_ne!(fingerprint(&a), fingerprint(&b));
        assert_ne!(fingerprint(&a), fingerprint(&c));
        assert_eq!(fingerprint(&a), fingerprint(&a.clone()));
    }
}
