//! Short text for values on colour bars and in titles.

/// `v` with four significant digits: fixed notation for magnitudes in [1e-3, 1e5), scientific
/// otherwise, without trailing zeros (`0.0125`, `-7021`, `1.5e-5`, `2.35e6`).
pub(crate) fn short(v: f64) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == 0.0 {
        return "0".to_string();
    }
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        // log10 of a value in [1e-3, 1e5) lies in [-3, 5): the cast is exact.
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        trim_zeros(&format!("{v:.decimals$}")).to_string()
    } else {
        let text = format!("{v:.3e}");
        match text.split_once('e') {
            Some((mantissa, exponent)) => format!("{}e{exponent}", trim_zeros(mantissa)),
            None => text,
        }
    }
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn four_significant_digits() {
        assert_eq!(short(0.0), "0");
        assert_eq!(short(0.0125), "0.0125");
        assert_eq!(short(-7021.4), "-7021");
        assert_eq!(short(1.0), "1");
        assert_eq!(short(5.14159), "5.142");
        assert_eq!(short(99999.0), "99999");
        assert_eq!(short(1.5e-5), "1.5e-5");
        assert_eq!(short(-2.345678e6), "-2.346e6");
        assert_eq!(short(1e5), "1e5");
        assert_eq!(short(f64::NAN), "NaN");
    }
}
