//! The one number formatter of every writer (terminal, Markdown, HTML; plot legends): the
//! same quantity is written the same way everywhere.
//!
//! - a measured or derived figure: 4 significant digits, fixed notation from 0.001 to
//!   99 999, else `1.978e-4` ([`fmt_num`]);
//! - a fitted value with a standard error: to the decimal its standard error supports, the
//!   error in parentheses in units of the last digit, `0.239978(9)` ([`fmt_estimate`]); the
//!   error itself to 1 or 2 significant digits ([`fmt_std_error`]);
//! - information criteria (AIC, BIC and their differences): one decimal ([`fmt_criterion`]);
//! - percentages: two decimals ([`fmt_percent`]);
//! - an undefined value (NaN, infinite, absent): `-`.
//!
//! A unit a report writes itself (a column header, a table's unit cell) is written for a
//! linear axis and shown on the report's axis by [`on_axis`] and [`column`]; the units a fit
//! carries (its parameters, residuals and channels) are on its axis already.

use crate::axis::Axis;

/// Significant digits of a figure.
pub(crate) const SIGNIFICANT: i32 = 4;

/// The text of an undefined value.
pub(crate) const UNDEFINED: &str = "-";

/// Decimal exponent of `a > 0`.
fn exponent(a: f64) -> i32 {
    a.log10().floor() as i32
}

/// `s` without trailing zeros after a decimal point (and without a bare point).
fn trim_zeros(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

/// Scientific notation with `digits` digits after the point, trailing zeros trimmed:
/// `1.978e-4`, `-1.2e5`.
fn scientific(x: f64, digits: usize) -> String {
    let s = format!("{x:.digits$e}");
    match s.split_once('e') {
        Some((mantissa, exp)) => format!("{}e{exp}", trim_zeros(mantissa)),
        None => s,
    }
}

/// Whether a number with decimal exponent `e` is written in fixed notation.
fn fixed_range(e: i32) -> bool {
    (-3..5).contains(&e)
}

/// Scientific notation with exactly `digits` digits after the point: `1.50e5`.
fn scientific_exact(x: f64, digits: usize) -> String {
    format!("{x:.digits$e}")
}

/// A figure to [`SIGNIFICANT`] digits; `-` when not finite.
pub fn fmt_num(x: f64) -> String {
    if !x.is_finite() {
        return UNDEFINED.into();
    }
    if x == 0.0 {
        return "0".into();
    }
    // Round first: 99 996 becomes 1.000e5, not 99 996 in fixed notation.
    let rounded: f64 = scientific(x, (SIGNIFICANT - 1) as usize)
        .parse()
        .unwrap_or(x);
    let e = exponent(rounded.abs());
    let full = if fixed_range(e) {
        let decimals = (SIGNIFICANT - 1 - e).max(0) as usize;
        format!("{rounded:.decimals$}")
    } else {
        scientific_exact(rounded, (SIGNIFICANT - 1) as usize)
    };
    // Trailing zeros stay when they are significant digits of a rounded value (3.480), and
    // go when the value is exactly what is left (0.01, 1e5).
    let short = match full.split_once('e') {
        Some((mantissa, exp)) => format!("{}e{exp}", trim_zeros(mantissa)),
        None => trim_zeros(&full),
    };
    if short.parse::<f64>().ok() == Some(x) {
        short
    } else {
        full
    }
}

/// `Some(x)` as [`fmt_num`], `None` as `-`.
pub(crate) fn fmt_opt(x: Option<f64>) -> String {
    x.map(fmt_num).unwrap_or_else(|| UNDEFINED.into())
}

/// A percentage to two decimals; `-` when not finite.
pub(crate) fn fmt_percent(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2}")
    } else {
        UNDEFINED.into()
    }
}

/// An information criterion (AIC, BIC or a difference of them) to one decimal; `-` when
/// not finite.
pub(crate) fn fmt_criterion(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.1}")
    } else {
        UNDEFINED.into()
    }
}

/// Significant digits of a standard error: 2 when its leading digit is 1 or 2, else 1.
fn error_digits(se: f64) -> i32 {
    let lead = se / 10f64.powi(exponent(se));
    if lead < 3.0 {
        2
    } else {
        1
    }
}

/// The decimal exponent of the last digit a standard error supports.
fn last_digit(se: f64) -> i32 {
    exponent(se) - error_digits(se) + 1
}

/// A standard error to 1 or 2 significant digits; `-` when absent or not positive.
pub(crate) fn fmt_std_error(se: Option<f64>) -> String {
    match se.filter(|s| s.is_finite() && *s > 0.0) {
        Some(s) => {
            let digits = error_digits(s) as usize;
            let rounded: f64 = scientific(s, digits - 1).parse().unwrap_or(s);
            let e = exponent(rounded);
            if fixed_range(e) {
                let decimals = (-last_digit(s)).max(0) as usize;
                trim_zeros(&format!("{rounded:.decimals$}"))
            } else {
                scientific(rounded, digits - 1)
            }
        }
        None => UNDEFINED.into(),
    }
}

/// `x` rounded to the last digit `se` supports (for interval ends); [`fmt_num`] without a
/// usable error.
pub(crate) fn fmt_to_error(x: f64, se: Option<f64>) -> String {
    match se.filter(|s| s.is_finite() && *s > 0.0) {
        Some(s) if x.is_finite() => {
            let last = last_digit(s);
            let e = if x == 0.0 { last } else { exponent(x.abs()) };
            if fixed_range(e) && (-12..=0).contains(&last) {
                format!("{x:.prec$}", prec = (-last) as usize)
            } else {
                scientific_exact(x, (e - last).max(0) as usize)
            }
        }
        _ => fmt_num(x),
    }
}

/// A fitted value with its standard error in parentheses, in units of the value's last
/// digit: `0.239978(9)`, `1.51(12)e5`; [`fmt_num`] without a usable error.
pub(crate) fn fmt_estimate(x: f64, se: Option<f64>) -> String {
    let Some(s) = se.filter(|s| s.is_finite() && *s > 0.0 && x.is_finite()) else {
        return fmt_num(x);
    };
    let last = last_digit(s);
    let digits = (s / 10f64.powi(last)).round() as u64;
    let value = fmt_to_error(x, Some(s));
    match value.split_once('e') {
        Some((mantissa, exp)) => format!("{mantissa}({digits})e{exp}"),
        None => format!("{value}({digits})"),
    }
}

/// `unit`, written for a linear axis, on `axis` (rad, N m, kg m^2 on a rotary one).
pub(crate) fn on_axis(axis: Axis, unit: &str) -> String {
    axis.unit(unit)
}

/// A column header `quantity [unit]`, the unit written for a linear axis and shown on `axis`.
pub(crate) fn column(axis: Axis, quantity: &str, unit: &str) -> String {
    format!("{quantity} [{}]", on_axis(axis, unit))
}

/// The name a unit-like enum value has in report.json (its serde name, e.g. `pass`,
/// `energy_balance`), so every writer spells it the same way.
pub fn serialized_name<T: serde::Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(s)) => s,
        _ => "-".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_have_four_significant_digits() {
        assert_eq!(fmt_num(0.24), "0.24");
        assert_eq!(fmt_num(3.479675), "3.480");
        assert_eq!(fmt_num(0.01), "0.01");
        assert_eq!(fmt_num(1981.993897), "1982");
        assert_eq!(fmt_num(5.547401), "5.547");
        assert_eq!(fmt_num(1.9773e-4), "1.977e-4");
        assert_eq!(fmt_num(2.0001e-4), "2.000e-4");
        assert_eq!(fmt_num(0.001295), "0.001295");
        assert_eq!(fmt_num(100000.0), "1e5");
        assert_eq!(fmt_num(99996.0), "1.000e5");
        assert_eq!(fmt_num(-102389.7), "-1.024e5");
        assert_eq!(fmt_num(-1.25e-7), "-1.25e-7");
        assert_eq!(fmt_num(-0.009297), "-0.009297");
        assert_eq!(fmt_num(0.0), "0");
    }

    #[test]
    fn columns_show_the_axis_units() {
        assert_eq!(column(Axis::Linear, "x0", "m"), "x0 [m]");
        assert_eq!(column(Axis::Rotary, "x0", "m"), "x0 [rad]");
        assert_eq!(column(Axis::Rotary, "mean |F|", "N"), "mean |F| [N m]");
    }

    #[test]
    fn undefined_values_are_a_dash() {
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(fmt_num(x), "-");
            assert_eq!(fmt_percent(x), "-");
            assert_eq!(fmt_criterion(x), "-");
        }
        assert_eq!(fmt_opt(None), "-");
        assert_eq!(fmt_std_error(None), "-");
    }

    #[test]
    fn estimates_follow_their_standard_error() {
        assert_eq!(fmt_estimate(0.2399781, Some(9.1765e-6)), "0.239978(9)");
        assert_eq!(fmt_std_error(Some(9.1765e-6)), "9e-6");
        assert_eq!(fmt_estimate(0.2399781, Some(1.4e-5)), "0.239978(14)");
        assert_eq!(fmt_std_error(Some(1.4e-5)), "1.4e-5");
        assert_eq!(fmt_estimate(1981.99, Some(0.52)), "1982.0(5)");
        assert_eq!(fmt_estimate(151234.0, Some(12000.0)), "1.51(12)e5");
        assert_eq!(fmt_to_error(0.23996, Some(9.1765e-6)), "0.239960");
        assert_eq!(fmt_estimate(150000.0, Some(12000.0)), "1.50(12)e5");
        assert_eq!(fmt_estimate(0.24, None), "0.24");
        assert_eq!(fmt_criterion(-102389.73), "-102389.7");
        assert_eq!(fmt_percent(0.2345), "0.23");
    }
}
