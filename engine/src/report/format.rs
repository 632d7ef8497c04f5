//! Number and table formatting shared by every writer.

/// Formats a float compactly for tables: fixed for moderate magnitudes, exponent otherwise.
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if (1e-3..1e5).contains(&a) {
        let s = format!("{x:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    } else {
        let s = format!("{x:.4e}");
        match s.split_once('e') {
            Some((mant, exp)) => {
                let mant = if mant.contains('.') {
                    mant.trim_end_matches('0').trim_end_matches('.')
                } else {
                    mant
                };
                format!("{mant}e{exp}")
            }
            None => s,
        }
    }
}

/// `Some(x)` formatted, or `-` for a missing value.
pub fn fmt_opt(x: Option<f64>) -> String {
    x.map(fmt_num).unwrap_or_else(|| "-".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_compact() {
        assert_eq!(fmt_num(0.24), "0.24");
        assert_eq!(fmt_num(100000.0), "1e5");
        assert_eq!(fmt_num(-1.25e-7), "-1.25e-7");
        assert_eq!(fmt_num(-0.009297), "-0.009297");
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(fmt_opt(None), "-");
    }
}
