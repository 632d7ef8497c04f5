//! Parameters that share a column: an unprofiled parameter (an offset, an oscillator
//! property) whose Jacobian column is, apart from the other determined parameters, the same
//! as that of a parameter the records do not determine takes the same verdict. On a one-way
//! stroke the Coulomb level's column sgn(v) is the offset's column 1: the records fix their
//! sum, neither one, so neither is reported as determined.
//!
//! A parameter the records determine or bound on one side whose column is a combination of
//! the columns of the others they determine or bound (nothing of it is left apart from them)
//! is redundant with them: the records fix only a combination, whatever each one's profile
//! says (a profile re-optimises the others, and moving along the combination they all follow
//! is where its refits stop short and report a rise, or where a box bound such as a weight's
//! 1 ends it). GMS's element weights and its levels scale the sliding force together: with
//! both free, every one of them is redundant.

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

/// The part of a determined column left apart from the other determined ones, relative to
/// its norm, at or below which it is their combination. Exact sensitivities of an exactly
/// redundant parameterisation leave about 1e-8 (the integration's error); two parameters
/// that merely trade closely (correlation 0.999 999) leave 1.4e-3.
pub const REDUNDANT_REMAINDER: f64 = 1e-6;

/// Each slot that `standings` calls determined or bounded on one side (a slot it does not
/// cover counts: every one with none) whose column in `jac` is a combination of the other
/// such slots' columns: less than [`REDUNDANT_REMAINDER`] of it is left apart from them.
pub fn redundant_columns(jac: &DMatrix<f64>, standings: &[Standing]) -> Vec<usize> {
    let p = jac.ncols();
    let bounded = |j: usize| {
        standings
            .get(j)
            .is_none_or(|s| s.class != Identifiability::NotIdentifiable)
    };
    let counted: Vec<usize> = (0..p).filter(|&j| bounded(j)).collect();
    // R of the counted columns' QR factors has their lengths and angles in a square of their
    // number: the same remainders for a fraction of the work on a long record.
    let r = jac.select_columns(&counted).qr().r();
    (0..counted.len())
        .filter(|&k| {
            let others: Vec<usize> = (0..counted.len()).filter(|&j| j != k).collect();
            let basis = orthonormal_basis(&r.select_columns(&others));
            let own = r.column(k).into_owned();
            let scale = own.norm();
            scale > 0.0
                && scale.is_finite()
                && apart_from(&basis, own).norm() <= REDUNDANT_REMAINDER * scale
        })
        .map(|k| counted[k])
        .collect()
}

/// One warning naming the redundant slots `redundant` (`names`: each slot's name); none when
/// there are none.
pub fn redundant_findings(names: &[String], redundant: &[usize]) -> Option<Finding> {
    if redundant.is_empty() {
        return None;
    }
    let listed: Vec<String> = redundant
        .iter()
        .map(|&slot| format!("`{}`", names.get(slot).map_or("?", String::as_str)))
        .collect();
    Some(Finding::warn(
        Check::Identifiability,
        None,
        format!(
            "{} are not identifiable one by one: each one's column is a combination of the \
             others' on these records, so the records fix only a combination of them (GMS's \
             weights and levels scale the sliding force together: fix the weights or a level); \
             no standard errors",
            listed.join(", ")
        ),
    ))
}

/// `standings` with every slot in `slots` not identifiable.
pub fn not_identifiable(standings: &[Standing], slots: &[usize]) -> Vec<Standing> {
    let mut out = standings.to_vec();
    for &slot in slots {
        if let Some(st) = out.get_mut(slot) {
            *st = Standing {
                class: Identifiability::NotIdentifiable,
                bound: None,
            };
        }
    }
    out
}

/// `standings` with every shared slot not identifiable.
pub fn with_shared(standings: &[Standing], shared: &[SharedColumn]) -> Vec<Standing> {
    let slots: Vec<usize> = shared.iter().map(|s| s.slot).collect();
    not_identifiable(standings, &slots)
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

    /// GMS's weights and level as a Jacobian: the force w1 s f1(t) + w2 s f2(t) + v g(t) in
    /// (w1, w2, s, v). Scaling w1 and w2 up and s down by one factor leaves it unchanged, so
    /// the columns obey w1 J_w1 + w2 J_w2 - s J_s = 0: each of the three is a combination of
    /// the others and is redundant, w1 too when its profile bounded it on one side; v's
    /// column is its own. A column the others nearly, but not exactly, repeat (a correlation
    /// of 0.999 999) is not redundant.
    #[test]
    fn columns_that_are_a_combination_of_the_others_are_redundant_and_no_others() {
        let n = 200;
        let (w1, w2, s) = (0.6, 0.4, 20.0);
        let f1 = |t: f64| (t * 0.05).tanh();
        let f2 = |t: f64| (t * 0.01).tanh();
        let g = |t: f64| (t * 0.07).sin();
        let jac = DMatrix::from_fn(n, 4, |i, c| {
            let t = i as f64;
            match c {
                0 => s * f1(t),
                1 => s * f2(t),
                2 => w1 * f1(t) + w2 * f2(t),
                _ => g(t),
            }
        });
        let redundant = redundant_columns(&jac, &[DETERMINED; 4]);
        assert_eq!(redundant, vec![0, 1, 2]);
        let one_sided = Standing {
            class: Identifiability::LowerBound,
            bound: Some(0.5),
        };
        let with_bound = [one_sided, DETERMINED, DETERMINED, DETERMINED];
        assert_eq!(redundant_columns(&jac, &with_bound), vec![0, 1, 2]);
        let after = not_identifiable(&[DETERMINED; 4], &redundant);
        assert!(after[..3].iter().all(|s| !s.determined()) && after[3].determined());
        let names = ["w_1", "w_2", "mu_c", "viscous"].map(String::from);
        let finding = redundant_findings(&names, &redundant).unwrap();
        assert!(finding
            .message
            .starts_with("`w_1`, `w_2`, `mu_c` are not identifiable"));
        // A parameter the records leave unbounded is not among the others: with w2 so, w1 and
        // s are each their own again.
        assert!(redundant_columns(&jac, &[DETERMINED, FLAT, DETERMINED, DETERMINED]).is_empty());
        // Nearly repeated: the second column leaves about 1e-3 of itself apart from the first.
        let near = DMatrix::from_fn(n, 2, |i, c| {
            let t = i as f64;
            match c {
                0 => f1(t),
                _ => f1(t) + 1.4e-3 * g(t) * f1(t).abs().max(0.1),
            }
        });
        assert!(redundant_columns(&near, &[DETERMINED; 2]).is_empty());
        assert!(redundant_findings(&names, &[]).is_none());
    }
}
