//! The regular part R of a loading GMS element's travel integral (`gms_relaxation.rs`),
//! tabulated once per sharpness m, with its derivative in m, so that an element's step costs
//! a few polynomial evaluations instead of a quadrature per Newton iteration.
//!
//! R(y) = Phi(y) - u / m, the integral of h_m(r) = 1 / (1 - r^m) - 1 / (m (1 - r)) from 0 to
//! y, is tabulated over the loads a near step meets, 0 <= y^m <= 2 (a little more, for the
//! rounding of the far step's hand-over), in two parts:
//!
//! - below y^m = 1/4, in x = y^m: R(y) = y S(x) + ln(1 - y) / m with S(x) = sum_k x^k /
//!   (m k + 1), and dR/dm = y (ln y T(x) - U(x)) - ln(1 - y) / m^2 with T(x) = sum_k k x^k /
//!   (m k + 1) and U(x) = sum_k k x^k / (m k + 1)^2. S, T and U are power series of radius 1
//!   in x, so one Chebyshev expansion of 16 terms on [0, 1/4] holds each to rounding (the
//!   nearest singularity, x = 1, lies at 7 half-widths from the centre: a Bernstein ellipse of
//!   parameter 13.9);
//! - from there on, in w = ln y: R(e^w) and dR/dm(e^w) are analytic in the strip
//!   |Im w| < 2 pi / max(m, 1) (the integrand's, `gms_relaxation.rs`), so pieces of length
//!   1 / max(m, 1) in w (half-widths 2 pi / 0.5 = 12.6 times shorter than that distance)
//!   with 16 Chebyshev terms each hold them to rounding; three pieces for m >= 1.
//!
//! The values at the Chebyshev nodes come from the exact series and Gauss-Legendre panels of
//! `gms_relaxation.rs`; a table is a few hundred evaluations of the integrand, built once per
//! sharpness and thread (`with_table`) and used by every step of a replay.

use super::gms_quadrature::{panels, series, SERIES_LIMIT, SERIES_TERMS};
use std::cell::RefCell;
use std::rc::Rc;

/// Loads with y^m above this level step by `gms_relaxation`'s far step, in ln y; the table
/// holds the loads below it.
pub(super) const FAR_LEVEL: f64 = 2.0;
/// Terms of each Chebyshev expansion.
const TERMS: usize = 16;
/// Longest piece in w, times max(m, 1).
const PIECE_REACH: f64 = 1.0;
/// The tabulated loads reach y^m = FAR_LEVEL times this margin (the far step hands over at
/// FAR_LEVEL, to the rounding of ln and exp).
const FAR_MARGIN: f64 = 1.01;
/// Sharpnesses below this are stepped without a table (the loads' span in w, ln 8 / m,
/// would take too many pieces).
const LEAST_SHARPNESS: f64 = 0.5;
/// Tables kept per thread (the most recently used first).
const CACHED_TABLES: usize = 4;

/// The Chebyshev expansions of `K` functions on [lo, hi], evaluated together (their
/// recurrences interleaved: one costs the time of all).
#[derive(Debug, Clone, PartialEq)]
struct Chebyshev<const K: usize> {
    lo: f64,
    hi: f64,
    /// Term by term, the `K` functions' coefficients.
    coeffs: [[f64; K]; TERMS],
}

impl<const K: usize> Chebyshev<K> {
    /// The expansions interpolating the `K` functions `f` gives at once on [lo, hi], at the
    /// Chebyshev points of the first kind.
    fn interpolate(lo: f64, hi: f64, mut f: impl FnMut(f64) -> [f64; K]) -> Self {
        let n = TERMS as f64;
        // cos(k theta_j), theta_j = pi (j + 1/2) / n, from the angle reduced in integers (a
        // rounded theta_j times k would cost the high coefficients k roundings).
        let cos_of = |k: usize, j: usize| {
            let quarter_turns = (k * (2 * j + 1)) % (4 * TERMS);
            (std::f64::consts::PI * quarter_turns as f64 / (2.0 * n)).cos()
        };
        let values: Vec<[f64; K]> = (0..TERMS)
            .map(|j| f(0.5 * (lo + hi) + 0.5 * (hi - lo) * cos_of(1, j)))
            .collect();
        let coeffs = std::array::from_fn(|k| {
            let scale = if k == 0 { 1.0 / n } else { 2.0 / n };
            std::array::from_fn(|i| {
                let sum: f64 = values
                    .iter()
                    .enumerate()
                    .map(|(j, v)| v[i] * cos_of(k, j))
                    .sum();
                scale * sum
            })
        });
        Self { lo, hi, coeffs }
    }

    /// The expansions at `x` (Clenshaw's recurrence).
    fn eval(&self, x: f64) -> [f64; K] {
        let t = (2.0 * x - self.lo - self.hi) / (self.hi - self.lo);
        let (mut b1, mut b2) = ([0.0; K], [0.0; K]);
        for c in self.coeffs[1..].iter().rev() {
            for i in 0..K {
                let b0 = 2.0 * t * b1[i] + c[i] - b2[i];
                b2[i] = b1[i];
                b1[i] = b0;
            }
        }
        std::array::from_fn(|i| t * b1[i] + self.coeffs[0][i] - b2[i])
    }
}

/// S, T and U of the module docs at x = y^m, by their series.
fn series_parts(m: f64, x: f64) -> [f64; 3] {
    let (mut s, mut t, mut u, mut power) = (0.0, 0.0, 0.0, 1.0);
    for k in 0..SERIES_TERMS {
        let k = k as f64;
        let den = m * k + 1.0;
        s += power / den;
        t += k * power / den;
        u += k * power / (den * den);
        power *= x;
    }
    [s, t, u]
}

/// R and dR/dm at one sharpness over the loads 0 <= y^m <= 2 (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct RegularTable {
    m: f64,
    /// ln y at the series' limit, y^m = 1/4.
    wq: f64,
    /// ln y at the table's upper end.
    w_top: f64,
    /// S, T and U in x = y^m on [0, 1/4].
    series: Chebyshev<3>,
    /// R and dR/dm in pieces in w, from `wq` to `w_top`, of equal length.
    pieces: Vec<Chebyshev<2>>,
    /// The pieces per unit of w.
    per_width: f64,
}

impl RegularTable {
    /// The table at sharpness `m`; `None` for a sharpness below [`LEAST_SHARPNESS`] (or not
    /// finite).
    pub(super) fn new(m: f64) -> Option<Self> {
        if !m.is_finite() || m < LEAST_SHARPNESS {
            return None;
        }
        let wq = SERIES_LIMIT.ln() / m;
        let w_top = (FAR_LEVEL * FAR_MARGIN).ln() / m;
        let (at_limit, d_at_limit) = series(m, wq.exp(), true);
        let parts = Chebyshev::interpolate(0.0, SERIES_LIMIT, |x| series_parts(m, x));
        let count = ((w_top - wq) * m.max(1.0) / PIECE_REACH).ceil().max(1.0) as usize;
        let width = (w_top - wq) / count as f64;
        let pieces = (0..count)
            .map(|i| {
                let lo = wq + width * i as f64;
                let hi = if i + 1 == count { w_top } else { lo + width };
                Chebyshev::interpolate(lo, hi, |w| {
                    let (r, dr) = panels(m, wq, w - wq, true);
                    [at_limit + r, d_at_limit + dr]
                })
            })
            .collect();
        Some(Self {
            m,
            wq,
            w_top,
            series: parts,
            pieces,
            per_width: 1.0 / width,
        })
    }

    /// The sharpness the table holds.
    pub(super) fn sharpness(&self) -> f64 {
        self.m
    }

    /// Whether the load of logarithm `w` lies in the table.
    pub(super) fn holds(&self, w: f64) -> bool {
        w <= self.w_top
    }

    /// The piece holding `w` (wq <= w <= w_top).
    fn piece(&self, w: f64) -> Option<&Chebyshev<2>> {
        // The cast saturates: below `wq` (by a rounding) the first piece.
        let i = ((w - self.wq) * self.per_width) as usize;
        self.pieces.get(i.min(self.pieces.len().saturating_sub(1)))
    }

    /// R(y) at the load `y` of logarithm `w` (y^m <= 2), and dR/dm when `with_m`.
    pub(super) fn regular(&self, y: f64, w: f64, with_m: bool) -> (f64, f64) {
        if y <= 0.0 {
            return (0.0, 0.0);
        }
        let m = self.m;
        if w <= self.wq {
            let x = (m * w).exp();
            let log_rest = (-y).ln_1p();
            let [s, t, u] = self.series.eval(x);
            let value = y * s + log_rest / m;
            let slope = if with_m {
                y * (w * t - u) - log_rest / (m * m)
            } else {
                0.0
            };
            return (value, slope);
        }
        match self.piece(w) {
            Some(p) => {
                let [value, slope] = p.eval(w);
                (value, if with_m { slope } else { 0.0 })
            }
            None => (f64::NAN, f64::NAN),
        }
    }
}

thread_local! {
    /// The tables this thread built, the most recently used first.
    static TABLES: RefCell<Vec<Rc<RegularTable>>> = const { RefCell::new(Vec::new()) };
}

/// The table at sharpness `m` (built once per thread and kept among the last
/// [`CACHED_TABLES`]); `None` where [`RegularTable::new`] has none.
pub(super) fn table_for(m: f64) -> Option<Rc<RegularTable>> {
    TABLES.with(|cell| {
        let mut tables = cell.borrow_mut();
        if let Some(i) = tables.iter().position(|t| t.m.to_bits() == m.to_bits()) {
            if i > 0 {
                let table = tables.remove(i);
                tables.insert(0, table);
            }
            return tables.first().cloned();
        }
        let table = Rc::new(RegularTable::new(m)?);
        tables.insert(0, table.clone());
        tables.truncate(CACHED_TABLES);
        Some(table)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// R(y) and dR/dm by the exact series and panels (an independent route: the panels run
    /// from the series' limit straight to the load).
    fn exact(m: f64, y: f64) -> (f64, f64) {
        let wq = SERIES_LIMIT.ln() / m;
        let w = y.ln();
        if w <= wq {
            series(m, y, true)
        } else {
            let (a, da) = series(m, wq.exp(), true);
            let (r, dr) = panels(m, wq, w - wq, true);
            (a + r, da + dr)
        }
    }

    #[test]
    fn chebyshev_expansions_reproduce_smooth_functions() {
        let both = Chebyshev::interpolate(-0.3, 1.2, |x: f64| [x.cos(), x.exp()]);
        for i in 0..=50 {
            let x = -0.3 + 1.5 * i as f64 / 50.0;
            let [c, s] = both.eval(x);
            assert!((c - x.cos()).abs() < 1e-15, "cos at {x}");
            let e = x.exp();
            assert!((s - e).abs() < 2e-15 * e, "exp at {x}");
        }
    }

    #[test]
    fn the_table_holds_the_regular_part_and_its_slope_to_rounding() {
        // To the rounding of the reference (its integrand loses a few digits where its two
        // terms cancel, |ln r| just above 0.2).
        for m in [0.7, 1.0, 1.3, 2.0, 2.7, 6.0, 20.0] {
            let table = RegularTable::new(m).expect("a table");
            let top = FAR_LEVEL.powf(1.0 / m);
            for i in 0..=400 {
                let y = top * i as f64 / 400.0;
                if y == 1.0 {
                    continue;
                }
                let (value, slope) = table.regular(y, y.ln(), true);
                let (want, want_slope) = exact(m, y);
                assert!(
                    (value - want).abs() <= 1e-14 * want.abs().max(1.0),
                    "m = {m}, y = {y}: R {value} against {want}"
                );
                assert!(
                    (slope - want_slope).abs() <= 1e-13 * want_slope.abs().max(1.0),
                    "m = {m}, y = {y}: dR/dm {slope} against {want_slope}"
                );
            }
        }
    }

    #[test]
    fn at_sharpness_one_the_regular_part_vanishes() {
        // h_1 = 1 / (1 - r) - 1 / (1 - r) = 0: R = 0 at every load.
        let table = RegularTable::new(1.0).expect("a table");
        for y in [0.01, 0.2, 0.7, 0.99, 1.3, 1.9] {
            assert!(table.regular(y, y.ln(), false).0.abs() < 1e-14, "y = {y}");
        }
    }

    #[test]
    fn tables_are_built_once_per_sharpness_and_thread() {
        let a = table_for(2.5).expect("a table");
        let b = table_for(2.5).expect("a table");
        assert!(Rc::ptr_eq(&a, &b));
        assert_eq!(a.sharpness(), 2.5);
        assert!(table_for(0.1).is_none());
        for m in [3.0, 4.0, 5.0, 6.0, 7.0] {
            table_for(m);
        }
        // Evicted by the last four: built anew, to the same values.
        let c = table_for(2.5).expect("a table");
        assert!(!Rc::ptr_eq(&a, &c));
        assert_eq!(*a, *c);
    }
}
