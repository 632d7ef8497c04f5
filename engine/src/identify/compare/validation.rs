//! Held-out validation of a comparison's laws: each law is refitted without part of the data
//! (from its full fit's optimum, one local start) and scored on the part it did not see.
//!
//! The folds depend on the records:
//! - several records: leave records out (record i in fold i mod K, K at most
//!   [`MAX_FOLDS`]);
//! - one record fitted along the measured motion (the force domain): K contiguous blocks,
//!   each left out in turn (the rest fitted as its pieces before and after the block); a law
//!   with states is scored on its block replayed on from the record's start, so the block
//!   starts from the state the samples before it left, not from a relaxed one, and is fitted
//!   to the piece after the block replayed on from the block's start (the block's motion
//!   drives the states, its force is compared with nothing);
//! - one record whose response is simulated from the release: the simulation cannot start
//!   inside the record, so each fold fits the record up to a split and scores the response
//!   simulated on from the release with those parameters on the samples after the split.
//!
//! Every law sees the same folds, so fold-wise differences between two laws are paired.

use super::super::assessment::property_refits::refit_options;
use super::super::fit::lean_fit;
use crate::error::EngineError;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::levels::FrictionLevels;
use crate::identify::values::result::FitResult;
use crate::identify::values::search::Search;
use crate::identify::values::target_options::FitDomain;
use crate::oscillator::OscillatorProperty;
use crate::record::Record;
use frictionid_models::{clone_model, FrictionModel};
use serde::Serialize;

/// The most folds a comparison scores (each costs one local refit and one evaluation per law).
pub(crate) const MAX_FOLDS: usize = 3;

/// The iteration limit of a fold's refit: it starts at the full fit's optimum, which a fold's
/// optimum lies near, so a few steps settle it; a flat direction (a parameter the data do
/// not identify) would otherwise take the solver's whole budget for no change in the score.
const REFIT_ITERATIONS: u64 = 30;

/// Fractions of a simulated record fitted before its later part is scored.
const SPLITS: [f64; MAX_FOLDS] = [0.5, 0.65, 0.8];

/// The fewest samples a fitted piece or a scored block keeps.
const MIN_PIECE: usize = 20;

/// How a comparison's folds split its records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ValidationScheme {
    /// Records left out, a group at a time.
    RecordsLeftOut,
    /// Contiguous blocks of the one record, each left out in turn.
    Blocks,
    /// The one record fitted up to a split, its later part scored.
    LaterPart,
}

impl ValidationScheme {
    /// A phrase for people.
    pub fn describe(self) -> &'static str {
        match self {
            Self::RecordsLeftOut => "records left out of the fit",
            Self::Blocks => "contiguous blocks left out of the fit",
            Self::LaterPart => {
                "the later part of the record, simulated on from a fit of the earlier part"
            }
        }
    }
}

/// A law's held-out score.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LawValidation {
    /// The law.
    pub model: String,
    /// RMS of the held-out residuals over all folds (in the fit's residual unit); `None` when
    /// a fold could not be fitted.
    pub validation_rms: Option<f64>,
    /// Standard deviation of the folds' RMS.
    pub validation_rms_spread: Option<f64>,
    /// Each fold's held-out RMS.
    pub folds: Vec<f64>,
    /// Why the law has no score (a fold that failed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// One fold: the records fitted and how the held-out residuals are read.
struct Fold {
    train: Vec<Record>,
    test: Vec<Record>,
    /// Score only samples at or after this time of each test record (the later-part scheme).
    scored_from: Option<f64>,
    /// For a law with states (the blocks scheme): the training records with the piece after
    /// the block run in from the block's start, the test block extended back to the
    /// record's start, and the time of the block's first sample.
    with_history: Option<History>,
}

/// A block fold's records for a law with states.
struct History {
    train: Vec<Record>,
    test: Record,
    block_start: f64,
}

/// The scheme and folds for `records` fitted with `opts` (`None` when the records are too
/// short to split).
fn plan(records: &[Record], opts: &FitOptions) -> Option<(ValidationScheme, Vec<Fold>)> {
    if records.len() >= 2 {
        let k = records.len().min(MAX_FOLDS);
        let folds = (0..k)
            .map(|f| {
                let (test, train): (Vec<_>, Vec<_>) =
                    records.iter().enumerate().partition(|(i, _)| i % k == f);
                Fold {
                    train: train.into_iter().map(|(_, r)| r.clone()).collect(),
                    test: test.into_iter().map(|(_, r)| r.clone()).collect(),
                    scored_from: None,
                    with_history: None,
                }
            })
            .collect();
        return Some((ValidationScheme::RecordsLeftOut, folds));
    }
    let record = records.first()?;
    let n = record.len();
    if n < MAX_FOLDS * 2 * MIN_PIECE {
        return None;
    }
    if opts.target.domain == FitDomain::Force {
        Some((ValidationScheme::Blocks, block_folds(record)))
    } else {
        Some((ValidationScheme::LaterPart, later_part_folds(record)))
    }
}

/// K contiguous blocks of `record`, each left out while the pieces around it are fitted.
fn block_folds(record: &Record) -> Vec<Fold> {
    let n = record.len();
    (0..MAX_FOLDS)
        .map(|f| {
            let (a, b) = (f * n / MAX_FOLDS, (f + 1) * n / MAX_FOLDS);
            let mut train = Vec::new();
            let mut run_in_train = Vec::new();
            if a >= MIN_PIECE {
                train.push(piece(record, 0, a));
                run_in_train.push(piece(record, 0, a));
            }
            if n - b >= MIN_PIECE {
                train.push(piece(record, b, n));
                let mut after = piece(record, a, n);
                after.run_in = b - a;
                run_in_train.push(after);
            }
            Fold {
                train,
                test: vec![piece(record, a, b)],
                scored_from: None,
                with_history: record.time().get(a).map(|&block_start| History {
                    train: run_in_train,
                    test: piece(record, 0, b),
                    block_start,
                }),
            }
        })
        .collect()
}

/// The record fitted up to each split of [`SPLITS`], scored on from the split.
fn later_part_folds(record: &Record) -> Vec<Fold> {
    let n = record.len();
    let time = record.time();
    SPLITS
        .iter()
        .map(|s| {
            let split = ((s * n as f64) as usize).clamp(MIN_PIECE, n - MIN_PIECE);
            Fold {
                train: vec![record.ending_at(split)],
                test: vec![record.clone()],
                scored_from: time.get(split).copied(),
                with_history: None,
            }
        })
        .collect()
}

/// Samples `first..end` of `record`, named after them.
fn piece(record: &Record, first: usize, end: usize) -> Record {
    let mut r = record.starting_at(first).ending_at(end - first);
    r.name = format!("{}[{first}..{end}]", record.name);
    r
}

/// The scheme of a comparison of `records` and each law's held-out score (`None` when the
/// records are too short to split).
pub(crate) fn validate(
    fits: &[FitResult],
    records: &[Record],
    opts: &FitOptions,
    parallel: bool,
) -> Option<(ValidationScheme, Vec<LawValidation>)> {
    let (scheme, folds) = plan(records, opts)?;
    let score = |f: &FitResult| score_law(f, &folds, opts);
    let scores = if parallel {
        use rayon::prelude::*;
        fits.par_iter().map(score).collect()
    } else {
        fits.iter().map(score).collect()
    };
    Some((scheme, scores))
}

/// One law's score over `folds`.
fn score_law(fitted: &FitResult, folds: &[Fold], opts: &FitOptions) -> LawValidation {
    let mut out = LawValidation {
        model: fitted.model.clone(),
        validation_rms: None,
        validation_rms_spread: None,
        folds: Vec::new(),
        error: None,
    };
    let mut sum_sq = 0.0;
    let mut count = 0usize;
    for fold in folds {
        match held_out(fitted, fold, opts) {
            Ok((ss, n)) if n > 0 => {
                sum_sq += ss;
                count += n;
                out.folds.push((ss / n as f64).sqrt());
            }
            Ok(_) => {
                out.error = Some("a fold left no sample to score".into());
                return out;
            }
            Err(e) => {
                out.error = Some(e.to_string());
                return out;
            }
        }
    }
    if count > 0 {
        out.validation_rms = Some((sum_sq / count as f64).sqrt());
        out.validation_rms_spread = Some(spread(&out.folds));
    }
    out
}

/// The sample standard deviation of `values` (0 for fewer than two).
pub(crate) fn spread(values: &[f64]) -> f64 {
    let n = values.len();
    if n < 2 {
        return 0.0;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
}

/// The law refitted to the fold's training records from its full optimum, then evaluated
/// on the test records with every parameter held: the held-out sum of squares and count.
fn held_out(
    fitted: &FitResult,
    fold: &Fold,
    opts: &FitOptions,
) -> Result<(f64, usize), EngineError> {
    let model = fitted.fitted_model.as_ref();
    let mut refit = refit_options(opts, model);
    refit.search.prefit = false;
    refit.search.strategy = Some(fold_strategy(opts));
    refit.search.max_iterations = refit.search.max_iterations.min(REFIT_ITERATIONS);
    let history = fold.with_history.as_ref().filter(|_| model.n_states() > 0);
    let train = history.map_or(&fold.train, |h| &h.train);
    let trained = lean_fit(&fitted.oscillator, model, train, &refit)?;
    let mut eval = evaluation_options(&refit);
    let (mut test, scored_from) = match history {
        Some(h) => (vec![h.test.clone()], Some(h.block_start)),
        None => (fold.test.clone(), fold.scored_from),
    };
    if fold.scored_from.is_some() {
        // The scored samples must not set the release state: it is the training fit's.
        eval.params.x0 = false;
        eval.params.velocity_offset = false;
        eval.params.time_shift = false;
        for (r, n) in test.iter_mut().zip(&trained.world.nuisance) {
            r.x0 = n.x0_of(r);
            if n.shift != 0.0 {
                let t0 = r.time().first().copied().unwrap_or(0.0);
                r.release_time = Some(r.release_time.unwrap_or(t0) + n.shift);
            }
        }
    }
    let world = &trained.world;
    let levels_are_forces = FrictionLevels::read_as_forces(&opts.target.unknown_oscillator, &test);
    let model = within_bounds(world.model.as_ref(), levels_are_forces)?;
    let evaluated = lean_fit(&world.oscillator, model.as_ref(), &test, &eval)?;
    Ok(evaluated
        .records
        .iter()
        .map(|(r, t)| scored(r, t, scored_from))
        .fold((0.0, 0), |(s, n), (a, b)| (s + a, n + b)))
}

/// The search of a fold's refit: the one asked for, else a local run from the full fit's
/// optimum (its only start). A fold's optimum lies near the full fit's, so the staged
/// search's simpler laws and their starts (fitted again on every fold) would only find it
/// again: on the FMM fixture they were three quarters of LuGre's and Dahl's validation.
fn fold_strategy(opts: &FitOptions) -> Search {
    opts.search.strategy.unwrap_or(Search::Local)
}

/// `model` with every parameter clipped into its physical bounds (the solver's mapping can
/// leave a parameter at its bound a rounding error outside it, which a fixed parameter's
/// check refuses).
fn within_bounds(
    model: &(dyn FrictionModel + 'static),
    levels_are_forces: bool,
) -> Result<Box<dyn FrictionModel>, EngineError> {
    let mut m = clone_model(model);
    let values: Vec<f64> = m
        .params()
        .iter()
        .zip(m.param_info())
        .map(|(&v, p)| {
            if p.lower > p.upper {
                v
            } else if levels_are_forces && FrictionLevels::is_level(&p) {
                // A level read as a force is bounded by the data, not by the coefficient's
                // bound of 10: a 20 N Coulomb level stays 20 N.
                v.max(p.lower)
            } else {
                v.clamp(p.lower, p.upper)
            }
        })
        .collect();
    m.set_params(&values)?;
    Ok(m)
}

/// The options that evaluate a fitted law: no model parameter or oscillator property free
/// (the record's own nuisance parameters are still fitted), nothing guessed. The properties
/// the training fit found are the trained oscillator's; a normal force the configuration did
/// not give stays unknown, so the levels are read as the forces the training fit found, not
/// as coefficients bounded by 10.
fn evaluation_options(refit: &FitOptions) -> FitOptions {
    let mut o = refit.clone();
    o.params.free = Some(Vec::new());
    o.params.oscillator = Vec::new();
    o.params.guess = false;
    o.target
        .unknown_oscillator
        .retain(|p| *p == OscillatorProperty::NormalForce);
    o
}

/// The sum of squares and count of a record's residuals at samples at or after `from`.
fn scored(residuals: &[f64], time: &[f64], from: Option<f64>) -> (f64, usize) {
    residuals
        .iter()
        .enumerate()
        .filter(|(i, _)| match (from, time.get(*i)) {
            (Some(t0), Some(t)) => *t >= t0,
            _ => true,
        })
        .map(|(_, e)| e * e)
        .filter(|e| e.is_finite())
        .fold((0.0, 0), |(s, n), e| (s + e, n + 1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::values::search::SearchOptions;

    #[test]
    fn a_fold_refits_locally_unless_a_search_is_asked_for() {
        let mut opts = FitOptions::default();
        assert_eq!(fold_strategy(&opts), Search::Local);
        for asked in [Search::Staged, Search::Global, Search::Local] {
            opts.search = SearchOptions {
                strategy: Some(asked),
                ..SearchOptions::default()
            };
            assert_eq!(fold_strategy(&opts), asked);
        }
    }
}
