//! The presliding travel a record shows: how far the contact moves after a reversal while its
//! friction force turns over, read from a friction force measured along the displacement.
//!
//! After a reversal the force of a contact with presliding (Dahl, LuGre, GMS, ...) runs from
//! its sliding level against the old direction to its level along the new one over a travel
//! set by the contact's stiffness. The travel over which it covers the middle half of that
//! swing (from a quarter to three quarters) is a measure of the presliding displacement
//! (the sliding level over the rest stiffness, `StartContext::presliding_displacement`) that
//! needs neither the level, nor the load cell's offset, nor a law: for Dahl's law with
//! alpha = 1, F = F_c (1 - 2 exp(-s / x_p)) at travel s after the reversal with
//! x_p = F_c / sigma0, so the middle half takes ln 3 x_p = 1.10 x_p. The staged search maps
//! its static stage at this displacement in place of the typical one and a tenth of it
//! (`strategy::STAGED_PRESLIDING`), which hedge for a scale the records can tell.

/// Least share of the record's displacement range the motion must travel back from an
/// extreme for that extreme to count as a reversal (so displacement noise near a turning
/// point makes no reversals).
const REVERSAL_SHARE: f64 = 0.05;

/// Half-strokes a presliding travel needs (the median of their travels is taken).
const MIN_HALF_STROKES: usize = 2;

/// The indices of the reversals of `x`: the extremes the motion then travels back from by
/// more than [`REVERSAL_SHARE`] of its range, in order (the ends of the record are none).
pub(crate) fn reversals(x: &[f64]) -> Vec<usize> {
    let (lo, hi) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let back = REVERSAL_SHARE * (hi - lo);
    let mut out = Vec::new();
    if back.is_nan() || back <= 0.0 {
        return out;
    }
    let (mut extreme, mut rising) = (0, None::<bool>);
    for (k, &v) in x.iter().enumerate() {
        let Some(up) = rising else {
            if (v - x[0]).abs() > back {
                (extreme, rising) = (k, Some(v > x[0]));
            }
            continue;
        };
        if (up && v >= x[extreme]) || (!up && v <= x[extreme]) {
            extreme = k;
        } else if (v - x[extreme]).abs() > back {
            out.push(extreme);
            (extreme, rising) = (k, Some(!up));
        }
    }
    out
}

/// The travel over which the force `f` covers the middle half of its swing along the
/// half-stroke from reversal `from` to reversal `to` of the displacement `x`: `None` when the
/// force does not swing along the motion's direction (friction turns with the velocity).
fn half_stroke_travel(x: &[f64], f: &[f64], from: usize, to: usize) -> Option<f64> {
    let dir = (x[to] - x[from]).signum();
    let swing = dir * (f[to] - f[from]);
    if swing.is_nan() || swing <= 0.0 {
        return None;
    }
    let rise = |k: usize| dir * (f[k] - f[from]);
    let travel = |k: usize| (x[k] - x[from]).abs();
    // The first sample at or past the share of the swing, the travel interpolated linearly
    // from the sample before it (a sample's travel near a reversal can be a tenth of the
    // presliding displacement).
    let crossing = |share: f64| {
        let level = share * swing;
        let k = (from + 1..=to).find(|&k| rise(k) >= level)?;
        let (r0, r1) = (rise(k - 1), rise(k));
        let t = if r1 > r0 {
            (level - r0) / (r1 - r0)
        } else {
            1.0
        };
        Some(travel(k - 1) + t.clamp(0.0, 1.0) * (travel(k) - travel(k - 1)))
    };
    let travel = crossing(0.75)? - crossing(0.25)?;
    (travel >= 0.0).then_some(travel)
}

/// The presliding travel the whole half-strokes of one record show ([`half_stroke_travel`] of
/// each, from one reversal to the next), for the median over every record.
pub(crate) fn record_travels(x: &[f64], f: &[f64]) -> Vec<f64> {
    if x.len() != f.len() {
        return Vec::new();
    }
    reversals(x)
        .windows(2)
        .filter_map(|w| half_stroke_travel(x, f, w[0], w[1]))
        .collect()
}

/// The presliding displacement of the records' half-strokes (`travels`): their median when
/// there are at least [`MIN_HALF_STROKES`] and it is positive (a contact without presliding,
/// whose force jumps at the reversal, shows none).
pub(crate) fn presliding_displacement(mut travels: Vec<f64>) -> Option<f64> {
    travels.retain(|t| t.is_finite());
    if travels.len() < MIN_HALF_STROKES {
        return None;
    }
    travels.sort_by(f64::total_cmp);
    let n = travels.len();
    let median = if n % 2 == 1 {
        travels[n / 2]
    } else {
        0.5 * (travels[n / 2 - 1] + travels[n / 2])
    };
    (median > 0.0).then_some(median)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sinusoidal stroke of amplitude `a` over `cycles` periods, `n` samples.
    fn stroke(a: f64, cycles: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| -a * (2.0 * std::f64::consts::PI * cycles * k as f64 / n as f64).cos())
            .collect()
    }

    /// Dahl's force (alpha = 1) along `x`, exactly: on each monotone piece the force relaxes
    /// towards the level along the direction as exp(-sigma0 |dx| / F_c).
    fn dahl_force(x: &[f64], sigma0: f64, level: f64, offset: f64) -> Vec<f64> {
        let mut f = -level;
        let mut out = vec![f + offset];
        for w in x.windows(2) {
            let dx = w[1] - w[0];
            let target = level * dx.signum();
            if dx != 0.0 {
                f = target + (f - target) * (-sigma0 * dx.abs() / level).exp();
            }
            out.push(f + offset);
        }
        out
    }

    #[test]
    fn reversals_are_the_extremes_of_a_stroke() {
        let x = stroke(1e-3, 3.0, 3000);
        let r = reversals(&x);
        // The five turning points between the ends.
        assert_eq!(r.len(), 5, "{r:?}");
        for (i, &k) in r.iter().enumerate() {
            assert!((k as i64 - 500 * (i as i64 + 1)).abs() <= 1, "{r:?}");
        }
    }

    /// Dahl's middle half of the swing takes ln 3 x_p exactly: the closed form, whatever the
    /// level and the offset.
    #[test]
    fn a_dahl_contact_shows_ln_3_times_its_presliding_displacement() {
        let x = stroke(1e-3, 4.0, 40_000);
        for (sigma0, level, offset) in [(5e5, 60.0, 3.0), (2e6, 10.0, -1.0), (1e5, 2.0, 0.0)] {
            let f = dahl_force(&x, sigma0, level, offset);
            let travels = record_travels(&x, &f);
            assert_eq!(travels.len(), 6);
            let measured = presliding_displacement(travels).unwrap();
            let exact = 3f64.ln() * level / sigma0;
            // Within the travel of one sample near the crossing.
            assert!((measured / exact - 1.0).abs() < 0.02, "{measured} {exact}");
        }
    }

    /// A force that jumps at the reversal (Coulomb's) shows no presliding; one that does not
    /// turn with the motion (noise, or no friction) shows none either.
    #[test]
    fn a_jumping_or_unturned_force_shows_no_presliding() {
        let x = stroke(1e-3, 4.0, 4000);
        let coulomb: Vec<f64> = x
            .windows(2)
            .map(|w| 5.0 * (w[1] - w[0]).signum())
            .chain([5.0])
            .collect();
        let travels = record_travels(&x, &coulomb);
        assert!(presliding_displacement(travels).is_none());
        let flat = vec![1.0; x.len()];
        assert!(record_travels(&x, &flat).is_empty());
        assert!(presliding_displacement(vec![1e-4]).is_none());
    }
}
