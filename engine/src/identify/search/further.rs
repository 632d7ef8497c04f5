//! Searching further on a free decay that sticks.
//!
//! A velocity fit of a record whose motion stops has one cost minimum per count of
//! half-cycles before the stop: with the oscillator's frequency a few percent off, the
//! simulated and the measured motions drift out of phase over the record, and the levels
//! that end the simulated motion after a neighbouring count of half-cycles fit better than
//! the truth's. Where such a fit fits a property that sets the frequency (the stiffness, the
//! mass or inertia, the gravity moment) and its residual sits far above the noise floor
//! ([`FURTHER_RATIO`]), the search runs more starts before it reports ([`further_points`]):
//! the frequency fitted apart from the levels (a linear spring's damped frequency from the
//! record's turning points, which lie pi / omega_d apart whatever the friction) and starts
//! spread in the frequency's properties around the optimum ([`SPREAD`]). The better optimum
//! is kept; one still far above the noise is suspect ([`suspect_finding`]).

use super::free_params::Layout;
use super::prefit::PREFIT_ORIGIN;
use super::starts::{run_starts, MultiStart};
use super::strategy::{Seeded, StartPlan};
use crate::identify::problem::least_squares::FitProblem;
use crate::identify::problem::residuals::Residuals;
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::outcome::{Check, Finding, StartOutcome, Status};
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::noise::{difference_noise, RESPONSE_ORDER};
use crate::record::{Channel, Record};
use nalgebra::DVector;

/// A residual RMS above this many noise floors (the residuals' own, from their first
/// differences) sends the search further, and still above it after, makes the optimum
/// suspect.
pub(crate) const FURTHER_RATIO: f64 = 2.0;

/// Factors that spread the frequency's properties around the optimum (their frequency
/// changes by half as much: a count of half-cycles over a record of a few dozen).
pub(crate) const SPREAD: [f64; 6] = [0.99, 1.01, 0.98, 1.02, 0.96, 1.04];

/// The origin of the start whose frequency comes from the record's turning points.
pub(crate) const FREQUENCY_ORIGIN: &str = "frequency from the turning points";
/// The origin of a start spread in the frequency's properties.
pub(crate) const SPREAD_ORIGIN: &str = "spread in the oscillator's frequency";

/// Share of a record's samples at its end that must rest for the record to stick.
const REST_SHARE: f64 = 0.05;
/// A sample rests within this many noise levels of zero motion; the turning points are
/// counted once the motion leaves this band.
const REST_BAND: f64 = 5.0;

/// Whether `p` sets the oscillator's frequency.
fn sets_frequency(p: &FreeParam) -> bool {
    matches!(
        p.kind,
        ParamKind::Property(
            OscillatorProperty::Stiffness
                | OscillatorProperty::Mass
                | OscillatorProperty::GravityMoment
        )
    )
}

/// Whether the layout fits a property that sets the frequency.
pub(crate) fn fits_frequency(layout: &Layout) -> bool {
    layout.params.iter().any(sets_frequency)
}

/// The residual RMS over the residuals' noise floor (their robust first-difference
/// level); `None` when there is no floor to divide by.
pub(crate) fn residual_ratio(r: &DVector<f64>) -> Option<f64> {
    if r.is_empty() {
        return None;
    }
    let floor = difference_noise(r.as_slice(), 1);
    let rms = (r.norm_squared() / r.len() as f64).sqrt();
    (floor > 0.0 && rms.is_finite()).then(|| rms / floor)
}

/// The record's motion as a signal whose zero crossings are its turning points (the
/// velocity, else the displacement's first differences), with the band around zero within
/// which it rests: [`REST_BAND`] noise levels (the response's high-order difference level),
/// and at least a thousandth of its peak (a noise-free record).
fn motion(record: &Record) -> Option<(Vec<f64>, f64)> {
    let s: Vec<f64> = match record.channel(Channel::Velocity) {
        Some(v) => v.to_vec(),
        None => {
            let x = record.channel(Channel::Displacement)?;
            x.windows(2).map(|w| w[1] - w[0]).collect()
        }
    };
    let noise = difference_noise(&s, RESPONSE_ORDER);
    let peak = s.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let band = (REST_BAND * noise).max(1e-3 * peak);
    (band.is_finite() && band > 0.0).then_some((s, band))
}

/// Whether the record's motion stops: its last [`REST_SHARE`] of samples (at least 20) all
/// within the rest band while its peak is far beyond it.
pub(crate) fn sticks(record: &Record) -> bool {
    let Some((s, band)) = motion(record) else {
        return false;
    };
    let tail = ((s.len() as f64 * REST_SHARE) as usize).max(20);
    if s.len() < 4 * tail {
        return false;
    }
    let peak = s.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    peak > 10.0 * band && s[s.len() - tail..].iter().all(|v| v.abs() < band)
}

/// The times the signal `s` crosses zero while the motion is clear of the noise band:
/// between two samples beyond the band on either side, at the last sign change (linear
/// interpolation).
fn turning_times(s: &[f64], time: &[f64], band: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut side = 0.0;
    let mut last_clear = 0;
    for (i, &v) in s.iter().enumerate() {
        if v.abs() <= band {
            continue;
        }
        if side != 0.0 && v.signum() != side {
            let change = (last_clear..i)
                .rev()
                .find(|&j| s[j].signum() != s[j + 1].signum() || s[j] == 0.0);
            if let Some(j) = change {
                let (a, b) = (s[j], s[j + 1]);
                let w = if a == b { 0.0 } else { a / (a - b) };
                out.push(time[j] + w * (time[j + 1] - time[j]));
            }
        }
        side = v.signum();
        last_clear = i;
    }
    out
}

/// The half period of the record's motion from its turning points: the slope of their times
/// on their half-cycle counts (each count the nearest multiple of the median spacing), by
/// least squares; `None` with fewer than four turning points.
pub(crate) fn half_period(record: &Record) -> Option<f64> {
    let (s, band) = motion(record)?;
    let time = record.time();
    let time = if s.len() < time.len() {
        &time[1..]
    } else {
        time
    };
    let turns = turning_times(&s, time, band);
    if turns.len() < 4 {
        return None;
    }
    let mut gaps: Vec<f64> = turns.windows(2).map(|w| w[1] - w[0]).collect();
    gaps.sort_by(f64::total_cmp);
    let median = gaps[gaps.len() / 2];
    if median <= 0.0 {
        return None;
    }
    let counts: Vec<f64> = turns
        .iter()
        .map(|t| ((t - turns[0]) / median).round())
        .collect();
    let n = turns.len() as f64;
    let (mc, mt) = (
        counts.iter().sum::<f64>() / n,
        turns.iter().sum::<f64>() / n,
    );
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (c, t) in counts.iter().zip(&turns) {
        sxy += (c - mc) * (t - mt);
        sxx += (c - mc) * (c - mc);
    }
    let slope = sxy / sxx;
    (slope.is_finite() && slope > 0.0).then_some(slope)
}

/// The value of property `which` at `point`, else the oscillator's.
fn property_at(layout: &Layout, point: &[f64], osc: &Oscillator, which: OscillatorProperty) -> f64 {
    layout
        .params
        .iter()
        .zip(point)
        .find(|(f, _)| f.kind == ParamKind::Property(which))
        .map_or_else(|| which.value(osc).unwrap_or(f64::NAN), |(_, &x)| x)
}

/// `point` with a linear spring's damped frequency `pi / half`: the stiffness set from the
/// mass and damping when it is free, else the mass from the stiffness; `None` when neither
/// is free or the values make no oscillator.
fn with_frequency(layout: &Layout, point: &[f64], osc: &Oscillator, half: f64) -> Option<Vec<f64>> {
    let omega_d = std::f64::consts::PI / half;
    let m = property_at(layout, point, osc, OscillatorProperty::Mass);
    let c = property_at(layout, point, osc, OscillatorProperty::Damping);
    let k = property_at(layout, point, osc, OscillatorProperty::Stiffness);
    let slot = |p: OscillatorProperty| {
        layout
            .params
            .iter()
            .position(|f| f.kind == ParamKind::Property(p))
    };
    let mut out = point.to_vec();
    if let Some(s) = slot(OscillatorProperty::Stiffness) {
        let decay = c / (2.0 * m);
        out[s] = layout.params[s].clip(m * (omega_d * omega_d + decay * decay));
    } else if let Some(s) = slot(OscillatorProperty::Mass) {
        out[s] = layout.params[s].clip(k / (omega_d * omega_d));
    } else {
        return None;
    }
    out.iter().all(|x| x.is_finite()).then_some(out)
}

/// The further starts of a fit whose optimum `best` (physical values of the layout) sits far
/// above the noise on records that stick: the frequency from the turning points (a linear
/// spring; the median over the records that give one), once with the optimum's other values
/// and once with the layout's start's, then `best` with each frequency property spread by
/// [`SPREAD`].
pub(crate) fn further_points(
    layout: &Layout,
    best: &[f64],
    osc: &Oscillator,
    records: &[Record],
) -> Vec<Seeded> {
    let mut out = Vec::new();
    if osc.restoring.is_linear_spring() {
        let mut halves: Vec<f64> = records.iter().filter_map(half_period).collect();
        halves.sort_by(f64::total_cmp);
        if let Some(&half) = halves.get(halves.len() / 2) {
            for base in [best, &layout.start] {
                if let Some(point) = with_frequency(layout, base, osc, half) {
                    out.push(Seeded {
                        point,
                        origin: FREQUENCY_ORIGIN.into(),
                    });
                }
            }
        }
    }
    for (s, f) in layout.params.iter().enumerate() {
        if !sets_frequency(f) {
            continue;
        }
        for factor in SPREAD {
            let mut point = best.to_vec();
            point[s] = f.clip(best[s] * factor);
            out.push(Seeded {
                point,
                origin: SPREAD_ORIGIN.into(),
            });
        }
    }
    out.retain(|s| s.point.as_slice() != best);
    out
}

/// Whether a velocity fit over `layout` on `records` whose optimum leaves the residuals
/// `r` should search further: it fits the frequency, a record sticks, and the residual
/// sits above [`FURTHER_RATIO`] noise floors.
pub(crate) fn should_search_further(layout: &Layout, records: &[Record], r: &DVector<f64>) -> bool {
    fits_frequency(layout)
        && records.iter().any(sticks)
        && residual_ratio(r).is_some_and(|q| q > FURTHER_RATIO)
}

/// The finding of a further search: how far above the noise floor the residual sat
/// (`before`) and sits (`after`) after `starts` further starts; a warning when it still
/// sits above [`FURTHER_RATIO`].
pub(crate) fn suspect_finding(before: f64, after: f64, starts: usize) -> Finding {
    if after > FURTHER_RATIO {
        Finding::new(
            Check::SuspectOptimum,
            Status::Warn,
            Some(after),
            format!(
                "the residual RMS is {after:.2} times its noise floor on a record that sticks, after {starts} further starts (the frequency from the turning points, the frequency's properties spread): the optimum is suspect (a neighbouring count of half-cycles before the stop, or a law or fixed property that cannot follow the record); start the stiffness or inertia closer, or fit the record's first half-cycles alone"
            ),
        )
    } else {
        Finding::new(
            Check::SuspectOptimum,
            Status::Pass,
            Some(after),
            format!(
                "the residual RMS sat {before:.2} times its noise floor on a record that sticks; {starts} further starts (the frequency from the turning points, the frequency's properties spread) brought it to {after:.2}"
            ),
        )
    }
}

/// Further starts run: the search's starts so far, their origins, and the finding when it
/// went further.
pub(crate) struct Searched {
    /// Every run, the further ones after the first.
    pub runs: MultiStart,
    /// Where each start came from.
    pub origins: Vec<String>,
    /// What the further search found ([`suspect_finding`]); `None` when it did not run.
    pub finding: Option<Finding>,
}

/// The weighted residuals at the best run's point (its own, else evaluated again).
fn best_residuals<R: Residuals>(
    reference: &FitProblem<R>,
    runs: &MultiStart,
) -> Option<DVector<f64>> {
    match &runs.best.linearisation {
        Some((_, r)) => Some(r.clone()),
        None => reference
            .residuals_at(&reference.physical(&runs.best.u))
            .ok(),
    }
}

/// The fit's runs, extended by the further starts of a velocity fit whose optimum sits far
/// above the noise on records that stick ([`should_search_further`], [`further_points`]):
/// the better optimum is kept, the further starts' outcomes follow the first ones'.
pub(crate) fn search_further<R, F>(
    plan: &StartPlan<'_, R>,
    make_problem: &F,
    reference: &FitProblem<R>,
    runs: MultiStart,
    origins: Vec<String>,
) -> Searched
where
    R: Residuals + 'static,
    F: Fn() -> FitProblem<R> + Sync,
{
    let unchanged = |runs, origins| Searched {
        runs,
        origins,
        finding: None,
    };
    if !plan.residuals.simulates_response() {
        return unchanged(runs, origins);
    }
    let Some(r) = best_residuals(reference, &runs) else {
        return unchanged(runs, origins);
    };
    let (Some(before), true) = (
        residual_ratio(&r),
        should_search_further(plan.layout, plan.records, &r),
    ) else {
        return unchanged(runs, origins);
    };
    let best = reference.physical(&runs.best.u);
    let seeded = further_points(plan.layout, &best, plan.osc, plan.records);
    let points: Vec<Vec<f64>> = seeded
        .iter()
        .map(|s| plan.layout.projected(&s.point))
        .collect();
    let opts = plan.opts;
    let more = run_starts(
        make_problem,
        reference,
        &points,
        &opts.search,
        &opts.hooks,
        FURTHER_PROMOTED,
        None,
    );
    let n = seeded.len();
    let (runs, origins) = match more {
        Ok(more) => {
            let numbering = Numbering::of(&origins, n);
            let mut origins = origins;
            let prefit = numbering.prefit_last.then(|| origins.pop()).flatten();
            origins.extend(seeded.into_iter().map(|s| s.origin));
            origins.extend(prefit);
            (merged(runs, more, numbering), origins)
        }
        Err(_) => (runs, origins),
    };
    let after = best_residuals(reference, &runs)
        .and_then(|r| residual_ratio(&r))
        .unwrap_or(before);
    Searched {
        runs,
        origins,
        finding: Some(suspect_finding(before, after, n)),
    }
}

/// Further starts continued past their screening.
pub(crate) const FURTHER_PROMOTED: usize = 2;

/// How the first starts and the further ones are numbered as one multi-start: the further
/// ones after the first, except that the prefit's start stays the last (its finding looks
/// for it there).
#[derive(Clone, Copy)]
struct Numbering {
    first: usize,
    more: usize,
    prefit_last: bool,
}

impl Numbering {
    fn of(origins: &[String], more: usize) -> Self {
        Self {
            first: origins.len(),
            more,
            prefit_last: origins.last().is_some_and(|o| o == PREFIT_ORIGIN),
        }
    }

    /// The index of the first starts' start `i`.
    fn first_at(self, i: usize) -> usize {
        if self.prefit_last && i + 1 == self.first {
            self.first - 1 + self.more
        } else {
            i
        }
    }

    /// The index of the further starts' start `j`.
    fn more_at(self, j: usize) -> usize {
        j + self.first - usize::from(self.prefit_last)
    }
}

/// The first runs and the further ones as one multi-start ([`Numbering`]), the better best
/// kept.
fn merged(first: MultiStart, more: MultiStart, numbering: Numbering) -> MultiStart {
    let mut outcomes: Vec<StartOutcome> = first
        .outcomes
        .into_iter()
        .map(|o| renumbered(o, |i| numbering.first_at(i)))
        .chain(
            more.outcomes
                .into_iter()
                .map(|o| renumbered(o, |j| numbering.more_at(j))),
        )
        .collect();
    outcomes.sort_by_key(start_of);
    let (iterations, simulations) = (
        first.iterations + more.iterations,
        first.simulations + more.simulations,
    );
    let (best, best_start, starts_at_best) = if more.best.cost < first.best.cost {
        (
            more.best,
            numbering.more_at(more.best_start),
            more.starts_at_best,
        )
    } else {
        (
            first.best,
            numbering.first_at(first.best_start),
            first.starts_at_best,
        )
    };
    MultiStart {
        best,
        best_start,
        iterations,
        simulations,
        starts_at_best,
        outcomes,
    }
}

fn start_of(o: &StartOutcome) -> usize {
    match o {
        StartOutcome::Finished { start, .. }
        | StartOutcome::NonFiniteCost { start }
        | StartOutcome::Failed { start, .. }
        | StartOutcome::ContinuationFailed { start, .. } => *start,
    }
}

/// `o` with its start index `i` renumbered `at(i)`.
fn renumbered(o: StartOutcome, at: impl Fn(usize) -> usize) -> StartOutcome {
    match o {
        StartOutcome::Finished {
            start,
            cost,
            iterations,
            termination,
        } => StartOutcome::Finished {
            start: at(start),
            cost,
            iterations,
            termination,
        },
        StartOutcome::NonFiniteCost { start } => StartOutcome::NonFiniteCost { start: at(start) },
        StartOutcome::Failed { start, error } => StartOutcome::Failed {
            start: at(start),
            error,
        },
        StartOutcome::ContinuationFailed { start, error } => StartOutcome::ContinuationFailed {
            start: at(start),
            error,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decay(rate: f64, omega: f64, stop: f64) -> Record {
        let n = (20.0 * rate) as usize;
        let time: Vec<f64> = (0..n).map(|i| i as f64 / rate).collect();
        let v = time
            .iter()
            .map(|&t| {
                if t < stop {
                    (stop - t) * (omega * t).sin()
                } else {
                    0.0
                }
            })
            .collect();
        Record::new("d", time, v, 0.1)
    }

    #[test]
    fn the_half_period_is_read_from_the_turning_points() {
        let omega = 7.3;
        let r = decay(500.0, omega, 12.0);
        let half = half_period(&r).expect("turning points");
        assert!(
            (half * omega / std::f64::consts::PI - 1.0).abs() < 1e-4,
            "{half}"
        );
        assert!(sticks(&r));
        assert!(!sticks(&decay(500.0, omega, 25.0)));
    }

    #[test]
    fn the_finding_warns_only_while_the_residual_stays_far_above_the_noise() {
        assert_eq!(suspect_finding(4.6, 1.0, 8).status, Status::Pass);
        assert_eq!(suspect_finding(4.6, 3.0, 8).status, Status::Warn);
    }
}
