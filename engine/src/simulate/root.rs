//! Root location of an event function on a bracket (Illinois variant of regula falsi).

/// Finds t in (a, b] with g(t) = 0, given g(a) > 0 >= g(b), to a bracket width of `tol`.
/// Returns the right end of the final bracket (the first time found with g <= 0), or `None` if
/// g is not finite.
pub(crate) fn illinois(
    mut g: impl FnMut(f64) -> Option<f64>,
    mut a: f64,
    mut ga: f64,
    mut b: f64,
    mut gb: f64,
    tol: f64,
) -> Option<f64> {
    if gb == 0.0 {
        return Some(b);
    }
    // -1: the last update moved a, +1: it moved b.
    let mut side = 0i8;
    for _ in 0..200 {
        if b - a <= tol {
            break;
        }
        let mut c = (a * gb - b * ga) / (gb - ga);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
            if !(c > a && c < b) {
                break;
            }
        }
        let gc = g(c)?;
        if !gc.is_finite() {
            return None;
        }
        if gc == 0.0 {
            return Some(c);
        }
        if gc > 0.0 {
            a = c;
            ga = gc;
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        } else {
            b = c;
            gb = gc;
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        }
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_root_of_a_cosine_to_the_tolerance() {
        let root = std::f64::consts::FRAC_PI_2;
        let g = |t: f64| Some(t.cos());
        let r = illinois(g, 0.3, 0.3f64.cos(), 2.5, 2.5f64.cos(), 1e-13).unwrap();
        assert!((r - root).abs() < 1e-12, "{r}");
    }

    #[test]
    fn steep_one_sided_function_converges() {
        let g = |t: f64| Some(1.0 - (20.0 * t).exp());
        let (a, b) = (-1.0, 0.5);
        let r = illinois(g, a, 1.0 - (-20.0f64).exp(), b, 1.0 - 10.0f64.exp(), 1e-13).unwrap();
        assert!(r.abs() < 1e-12, "{r}");
    }
}
