//! Parameters that share a column: an unprofiled parameter (an offset, an oscillator
//! property) whose Jacobian column is, apart from the other determined parameters, the same
//! as that of a parameter the records do not determine takes the same verdict. On a one-way
//! stroke the Coulomb level's column sgn(v) is the offset's column 1: the records fix their
//! sum, neither one, so neither is reported as determined.

use super::Standing;
use crate::identify::values::outcome::{Check, Finding};
use crate::identify::values::result::Identifiability;
use nalgebra::{DMatrix, DVector};

/// The partial correlation of two columns (apart from the other determined ones) at or
/// above which they count as one column: the estimates trade one for one.
pub const SHARED_CORRELATION: f64 = 0.99;

/// A determined parameter that shares its column with an undetermined one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SharedColumn {
    /// The slot the verdict passes to.
    pub slot: usize,
    /// The undetermined slot it shares with.
    pub with: usize,
    /// Their columns' partial correlation.
    pub correlation: f64,
}

/// Each slot in `candidates` that the records call determined but whose column in `jac`
/// correlates with an undetermined slot's at [`SHARED_CORRELATION`] or more, apart from the
/// other determined columns.
pub fn shared_columns(
    jac: &DMatrix<f64>,
    standings: &[Standing],
    candidates: &[bool],
) -> Vec<SharedColumn> {
    let p = jac.ncols();
    let determined = |j: usize| standings.get(j).is_none_or(Standing::determined);
    let mut out = Vec::new();
    for slot in (0..p).filter(|&k| determined(k) && candidates.get(k) == Some(&true)) {
        let others: Vec<usize> = (0..p).filter(|&j| j != slot && determined(j)).collect();
        let basis = orthonormal_basis(&jac.select_columns(&others));
        let own = apart_from(&basis, jac.column(slot).into_owned());
        for with in (0..p).filter(|&j| !determined(j)) {
            let theirs = apart_from(&basis, jac.column(with).into_owned());
            let correlation = cosine(&own, &theirs);
            if correlation.abs() >= SHARED_CORRELATION {
                out.push(SharedColumn {
                    slot,
                    with,
                    correlation,
                });
                break;
            }
        }
    }
    out
}

/// `standings` with every shared slot not identifiable.
pub fn with_shared(standings: &[Standing], shared: &[SharedColumn]) -> Vec<Standing> {
    let mut out = standings.to_vec();
    for s in shared {
        if let Some(st) = out.get_mut(s.slot) {
            *st = Standing {
                class: Identifiability::NotIdentifiable,
                bound: None,
            };
        }
    }
    out
}

/// A warning per shared slot, naming the parameter it shares its column with (`names`:
/// each slot's name).
pub fn shared_findings(names: &[String], shared: &[SharedColumn]) -> Vec<Finding> {
    let name = |slot: usize| names.get(slot).map_or("?", String::as_str);
    shared
        .iter()
        .map(|s| {
            Finding::warn(
                Check::Identifiability,
                Some(s.correlation),
                format!(
                    "`{}` is not identifiable apart from `{}`: their columns are the same on these records (correlation {:.4}), so the records fix only a combination of the two (e.g. a Coulomb level and a force offset on a one-way stroke); no standard error",
                    name(s.slot),
                    name(s.with),
                    s.correlation
                ),
            )
        })
        .collect()
}

/// An orthonormal basis of the columns of `m` (their independent directions).
fn orthonormal_basis(m: &DMatrix<f64>) -> Vec<DVector<f64>> {
    let mut basis: Vec<DVector<f64>> = Vec::new();
    for c in m.column_iter() {
        let scale = c.norm();
        let mut v = c.into_owned();
        // Two passes of Gram-Schmidt keep the basis orthogonal to round-off.
        for _ in 0..2 {
            for b in &basis {
                let d = b.dot(&v);
                v -= b * d;
            }
        }
        let norm = v.norm();
        if norm > 1e-10 * scale && norm.is_finite() {
            basis.push(v / norm);
        }
    }
    basis
}

/// `v` less its projection on the orthonormal `basis`.
fn apart_from(basis: &[DVector<f64>], mut v: DVector<f64>) -> DVector<f64> {
    for b in basis {
        let d = b.dot(&v);
        v -= b * d;
    }
    v
}

/// The cosine of the angle between `a` and `b`, 0 when either vanishes.
fn cosine(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    let den = a.norm() * b.norm();
    if den > 0.0 && den.is_finite() {
        a.dot(b) / den
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DETERMINED: Standing = Standing {
        class: Identifiability::Determined,
        bound: None,
    };
    const FLAT: Standing = Standing {
        class: Identifiability::NotIdentifiable,
        bound: None,
    };

    /// Columns: a slope, a level the records leave flat, an offset equal to the level's
    /// column but for a slope share (the same column apart from the slope), and a sine.
    #[test]
    fn an_offset_that_repeats_a_flat_level_apart_from_the_rest_shares_its_verdict() {
        let n = 50;
        let jac = DMatrix::from_fn(n, 4, |t, c| match c {
            0 => t as f64,
            1 => 1.0,
            2 => 2.0 + 0.3 * t as f64,
            _ => (t as f64 * 0.4).sin(),
        });
        let standings = [DETERMINED, FLAT, DETERMINED, DETERMINED];
        let candidates = [false, false, true, true];
        let shared = shared_columns(&jac, &standings, &candidates);
        assert_eq!(shared.len(), 1, "{shared:?}");
        assert_eq!((shared[0].slot, shared[0].with), (2, 1));
        assert!((shared[0].correlation - 1.0).abs() < 1e-9);
        let after = with_shared(&standings, &shared);
        assert!(!after[2].determined() && after[3].determined());
        let names = ["a", "mu", "force_offset", "b"].map(String::from);
        let findings = shared_findings(&names, &shared);
        assert!(findings[0]
            .message
            .contains("`force_offset` is not identifiable apart from `mu`"));
        // Nothing shares when every parameter is determined, or with a distinct column.
        assert!(shared_columns(&jac, &[DETERMINED; 4], &[true; 4]).is_empty());
        let distinct = [DETERMINED, DETERMINED, DETERMINED, FLAT];
        assert!(shared_columns(&jac, &distinct, &[true; 4]).is_empty());
    }
}
