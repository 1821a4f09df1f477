//! The contour colour scale: blue, cyan, green, yellow, red, the rainbow of the seed paper's
//! (Abaqus) contour pictures.

/// Stops of the scale at t = 0, 1/4, 1/2, 3/4 and 1.
const STOPS: [[f64; 3]; 5] = [
    [0.0, 0.0, 255.0],
    [0.0, 255.0, 255.0],
    [0.0, 255.0, 0.0],
    [255.0, 255.0, 0.0],
    [255.0, 0.0, 0.0],
];

/// Colour of `t` in [0, 1] (clamped): blue at 0 (the minimum of a contour), red at 1 (its
/// maximum), linear in between. NaN gives mid grey.
pub fn colour_map(t: f64) -> [u8; 3] {
    if t.is_nan() {
        return [128, 128, 128];
    }
    let s = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    // s is in [0, 4], so the cast cannot truncate a meaningful value.
    let i = (s.floor() as usize).min(STOPS.len() - 2);
    let f = s - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let channel = |k: usize| (a[k] + (b[k] - a[k]) * f).round().clamp(0.0, 255.0) as u8;
    [channel(0), channel(1), channel(2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_middle() {
        assert_eq!(colour_map(0.0), [0, 0, 255]);
        assert_eq!(colour_map(-3.0), [0, 0, 255]);
        assert_eq!(colour_map(0.5), [0, 255, 0]);
        assert_eq!(colour_map(0.125), [0, 128, 255]);
        assert_eq!(colour_map(1.0), [255, 0, 0]);
        assert_eq!(colour_map(7.0), [255, 0, 0]);
        assert_eq!(colour_map(f64::NAN), [128, 128, 128]);
    }
}
