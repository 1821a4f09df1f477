//! SplitMix64: a fixed, portable stream of pseudo-random bits from an integer. Used where a
//! result must be reproducible everywhere (the jitter of a scene's lattice) and by tests.

/// The stream's increment (the golden ratio in 64 bits).
pub const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// The SplitMix64 output for state `x` (the state then advances by [`GOLDEN`]).
pub fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(GOLDEN);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The next value of a SplitMix64 stream whose state is `state`.
pub fn next(state: &mut u64) -> u64 {
    let r = splitmix64(*state);
    *state = state.wrapping_add(GOLDEN);
    r
}
