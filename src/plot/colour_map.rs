//! The contour colour scales. Perceptually uniform, so that equal steps of the field look like
//! equal steps of colour and no false bands appear (the rainbow's yellow and cyan did): viridis
//! for a field of one sign, and a diverging blue–white–red for a field of both signs, with white
//! at zero. Both read in grey and by the colour-blind.

/// Viridis (matplotlib's default) at t = 0, 1/8, ..., 1: dark purple to yellow.
const VIRIDIS: [[u8; 3]; 9] = [
    [0x44, 0x01, 0x54],
    [0x47, 0x2d, 0x7b],
    [0x3b, 0x52, 0x8b],
    [0x2c, 0x72, 0x8e],
    [0x21, 0x90, 0x8c],
    [0x27, 0xad, 0x81],
    [0x5d, 0xc8, 0x63],
    [0xaa, 0xdc, 0x32],
    [0xfd, 0xe7, 0x25],
];

/// ColorBrewer's RdBu, reversed: dark blue at t = 0, white at 1/2, dark red at 1.
const BLUE_WHITE_RED: [[u8; 3]; 11] = [
    [0x05, 0x30, 0x61],
    [0x21, 0x66, 0xac],
    [0x43, 0x93, 0xc3],
    [0x92, 0xc5, 0xde],
    [0xd1, 0xe5, 0xf0],
    [0xf7, 0xf7, 0xf7],
    [0xfd, 0xdb, 0xc7],
    [0xf4, 0xa5, 0x82],
    [0xd6, 0x60, 0x4d],
    [0xb2, 0x18, 0x2b],
    [0x67, 0x00, 0x1f],
];

/// Colour of `t` in [0, 1] (clamped) on viridis: the minimum of a contour at 0, its maximum at
/// 1, linear between the stops. NaN gives mid grey.
pub fn colour_map(t: f64) -> [u8; 3] {
    along(&VIRIDIS, t)
}

/// Colour of `t` in [0, 1] (clamped) on the diverging scale: the most negative value of a
/// contour symmetric about zero at 0, zero at 1/2 (white), the most positive at 1. NaN gives
/// mid grey.
pub fn diverging_colour_map(t: f64) -> [u8; 3] {
    along(&BLUE_WHITE_RED, t)
}

fn along(stops: &[[u8; 3]], t: f64) -> [u8; 3] {
    if t.is_nan() {
        return [128, 128, 128];
    }
    let s = t.clamp(0.0, 1.0) * (stops.len() - 1) as f64;
    // s is in [0, stops - 1], so the cast cannot truncate a meaningful value.
    let i = (s.floor() as usize).min(stops.len() - 2);
    let f = s - i as f64;
    let (a, b) = (stops[i], stops[i + 1]);
    let channel = |k: usize| {
        (f64::from(a[k]) + (f64::from(b[k]) - f64::from(a[k])) * f)
            .round()
            .clamp(0.0, 255.0) as u8
    };
    [channel(0), channel(1), channel(2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative luminance (Rec. 709 weights on the encoded channels): enough to check order.
    fn lightness(c: [u8; 3]) -> f64 {
        0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
    }

    #[test]
    fn viridis_ends_middle_and_clamps() {
        assert_eq!(colour_map(0.0), [0x44, 0x01, 0x54]);
        assert_eq!(colour_map(-3.0), colour_map(0.0));
        assert_eq!(colour_map(0.5), [0x21, 0x90, 0x8c]);
        assert_eq!(colour_map(1.0), [0xfd, 0xe7, 0x25]);
        assert_eq!(colour_map(7.0), colour_map(1.0));
        assert_eq!(colour_map(f64::NAN), [128, 128, 128]);
    }

    #[test]
    fn viridis_grows_lighter_all_the_way() {
        let l: Vec<f64> = (0..=100)
            .map(|k| lightness(colour_map(k as f64 / 100.0)))
            .collect();
        assert!(l.windows(2).all(|w| w[1] > w[0]), "{l:?}");
    }

    #[test]
    fn the_diverging_scale_is_white_at_zero_and_darkens_both_ways() {
        assert_eq!(diverging_colour_map(0.5), [0xf7, 0xf7, 0xf7]);
        let l = |t: f64| lightness(diverging_colour_map(t));
        for k in 0..50 {
            let t = k as f64 / 100.0;
            assert!(l(t) < l(t + 0.01) && l(1.0 - t) < l(0.99 - t), "at {t}");
        }
        let (blue, red) = (diverging_colour_map(0.0), diverging_colour_map(1.0));
        assert!(blue[2] > blue[0] && red[0] > red[2]);
    }
}
