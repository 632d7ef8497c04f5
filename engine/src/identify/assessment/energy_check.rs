//! The energy-balance check (the paper's cross-check): the friction force from the energy
//! balance, Eq. 7, held against the force of a fitted model or a given reference force, and
//! the energy the friction dissipates over each half-cycle, measured, against the model's
//! along the measured motion.
//!
//! One function, [`energy_force_check`], serves the identifier (after every fit) and the
//! `energy` command (against `[model]`, `reference_force` or a Coulomb fit).
//!
//! # Like with like
//! Eq. 7's force is compared sample by sample and by its time mean with the model's force
//! over the same samples, each mean taken of the force against the motion, F sgn(v): the
//! mean |F| where the force opposes the motion (a sliding contact's), and unbiased by noise
//! where |F| is not (stiff bristles replayed along a noisy velocity give a model force whose
//! noise alone would add to a mean |F|; presliding just after a reversal pushes with the
//! motion on both sides alike). The half-cycle energy balance needs no derivative: between two
//! turning points the drop of the mechanical energy less the viscous work is the energy the
//! friction dissipated, and the model's is int F v dt over the same interval of the measured
//! motion. Both are energies, summed over the complete half-cycles; a force that depends on
//! the speed or on presliding changes neither side's weighting.
//!
//! # When it cannot judge
//! A part is skipped, with its reason ([`EnergySkip`]), where its figure would measure the
//! record rather than the model: fewer than [`MIN_HALF_CYCLE_SAMPLES`] samples in the median
//! half-cycle (both parts), a displacement quantised so coarsely that the energies at the
//! turning points are uncertain by more than [`MAX_QUANTISATION_SHARE`] of the energy
//! dissipated (the energies), an Eq. 7 force whose noise exceeds [`MAX_NOISE_SHARE`] of the
//! friction level (Eq. 7).

use crate::energy::{percent_difference, EnergyAnalysis, HalfCycle};
use crate::error::EngineError;
use crate::identify::values::{EnergyForce, EnergySkip};
use crate::record::noise::{difference_noise, rms_difference_noise};

/// The fewest samples in the median half-cycle for either part of the check: a 31-sample
/// derivative window needs a few windows per half-cycle, and the trapezoidal work of a
/// half-sine over 20 samples is within 0.5 %.
pub(crate) const MIN_HALF_CYCLE_SAMPLES: usize = 20;
/// The largest uncertainty of the dissipated energy from the displacement's quantisation,
/// as a share of it, that the energies are judged with: half the warning threshold.
pub(crate) const MAX_QUANTISATION_SHARE: f64 = 0.025;
/// The largest noise of the Eq. 7 force, as a share of the friction level, that its mean is
/// judged with: E|F + e| exceeds F by under 0.1 % while sd(e) <= F / 3.
pub(crate) const MAX_NOISE_SHARE: f64 = 1.0 / 3.0;

/// The largest share of the friction's part (the Eq. 7 mean, the dissipated energy) that the
/// standard error of a fitted damping alone may move for the part to be judged: half the
/// warning threshold, as for the quantisation.
pub(crate) const MAX_CONDITION_SHARE: f64 = 0.025;

/// A fitted damping: its value and standard error \[N s/m\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FittedDamping {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub std_error: f64,
}

/// Skips each part of `ef` (made from `analysis`) that rests on an ill-conditioned remainder:
/// the friction's part is what the energy balance leaves after the viscous part c v of a
/// fitted `damping`, and the damping's standard error alone moves the Eq. 7 mean by
/// sigma_c mean|v| and the dissipated energy by sigma_c int v^2 dt; above
/// [`MAX_CONDITION_SHARE`] of the part, the part cannot judge the law (a damping fitted as
/// an oscillator property that trades with the friction).
pub(crate) fn skip_ill_conditioned(
    ef: &mut EnergyForce,
    analysis: &EnergyAnalysis,
    damping: FittedDamping,
) {
    let se = damping.std_error;
    if !(se.is_finite() && se > 0.0) {
        return;
    }
    let skip = |share: f64| {
        (share > MAX_CONDITION_SHARE || share.is_nan()).then(|| EnergySkip::IllConditioned {
            property: "damping".into(),
            share,
        })
    };
    if ef.eq7_skipped.is_none() {
        let speed = mean_against_motion(&analysis.v, &analysis.friction, &analysis.v);
        ef.eq7_skipped = skip(se * speed / ef.reference.abs());
    }
    if ef.dissipation_skipped.is_none() && !analysis.half_cycles.is_empty() {
        let squares: f64 = analysis
            .half_cycles
            .iter()
            .map(|c| work_over(analysis, &analysis.v, c))
            .sum();
        ef.dissipation_skipped = skip(se * squares / ef.dissipated.abs());
    }
}

/// What the energy-based force is compared with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ForceReference<'a> {
    /// A model's friction force along the analysed motion, one value per sample of the
    /// analysis (e.g. from [`crate::energy::model_force_along`] on `analysis.time`,
    /// `analysis.v`). The reference level is its mean |F| over the samples where the
    /// energy-based force is defined (exactly mu N for Coulomb friction); its dissipated
    /// energy is int F v dt over each half-cycle.
    ModelForce(&'a [f64]),
    /// A constant force level [N] (e.g. a measured mu N): its dissipated energy is the level
    /// times the distance travelled.
    Level(f64),
}

/// Holds the energy-based force of `analysis` against `reference`, and the energy dissipated
/// over its half-cycles against the reference's.
///
/// With a model force, the residual is the energy-based minus the model force on the samples
/// where both are defined; an error when there are none, or when the model force is not
/// finite there, or when the series lengths differ. With a level, `residual_rms` is NaN and
/// `samples` counts the samples where the energy-based force is defined.
pub fn energy_force_check(
    analysis: &EnergyAnalysis,
    reference: ForceReference<'_>,
) -> Result<EnergyForce, EngineError> {
    let energy = &analysis.friction;
    let eq7_mean = mean_against_motion(energy, energy, &analysis.v);
    let (level, residual_rms, samples) = match reference {
        ForceReference::ModelForce(model) => {
            if model.len() != energy.len() {
                return Err(EngineError::InvalidInput(format!(
                    "analysis has {} forces for {} samples",
                    energy.len(),
                    model.len()
                )));
            }
            let (rms, used) = residual_rms(energy, model)?;
            (mean_against_motion(model, energy, &analysis.v), rms, used)
        }
        ForceReference::Level(level) => (
            level,
            f64::NAN,
            energy.iter().filter(|f| f.is_finite()).count(),
        ),
    };
    let cycles = &analysis.half_cycles;
    let dissipated: f64 = cycles.iter().map(|c| c.energy_lost - c.viscous_loss).sum();
    let model_dissipated: f64 = cycles
        .iter()
        .map(|c| match reference {
            ForceReference::ModelForce(model) => work_over(analysis, model, c),
            ForceReference::Level(level) => level * c.distance,
        })
        .sum();
    let (eq7_skipped, dissipation_skipped) = skips(analysis, dissipated);
    let eq7_skipped = eq7_skipped.or_else(|| match reference {
        ForceReference::ModelForce(model) => noisy_replay(model, energy, level),
        ForceReference::Level(_) => None,
    });
    Ok(EnergyForce {
        mean_abs: eq7_mean,
        reference: level,
        percent_difference: percent_difference(eq7_mean, level),
        residual_rms,
        samples,
        force_noise: analysis.force_noise,
        half_cycle_mean: analysis.half_cycle_mean,
        half_cycles: cycles.len(),
        dissipated,
        model_dissipated,
        dissipation_percent_difference: if cycles.is_empty() {
            f64::NAN
        } else {
            percent_difference(dissipated, model_dissipated)
        },
        eq7_skipped,
        dissipation_skipped,
    })
}

/// The mean of `force` sgn(v) over the samples where the energy-based force `energy` is
/// defined (NaN when none is): the mean force against the motion.
fn mean_against_motion(force: &[f64], energy: &[f64], v: &[f64]) -> f64 {
    let (sum, n) = force
        .iter()
        .zip(energy)
        .zip(v)
        .filter(|((f, e), _)| e.is_finite() && f.is_finite())
        .fold((0.0, 0usize), |(s, n), ((f, _), v)| {
            (s + f * v.signum(), n + 1)
        });
    if n > 0 {
        sum / n as f64
    } else {
        f64::NAN
    }
}

/// Why each part (Eq. 7, the dissipated energies) cannot judge the analysis, if it cannot.
fn skips(analysis: &EnergyAnalysis, dissipated: f64) -> (Option<EnergySkip>, Option<EnergySkip>) {
    let cycles = &analysis.half_cycles;
    let per_half_cycle = median_samples(analysis);
    let few = per_half_cycle
        .filter(|&n| n < MIN_HALF_CYCLE_SAMPLES)
        .map(|n| EnergySkip::FewSamples {
            per_half_cycle: n,
            needed: MIN_HALF_CYCLE_SAMPLES,
        });
    let level = if analysis.half_cycle_mean.is_finite() {
        analysis.half_cycle_mean
    } else {
        analysis.mean_abs_force
    };
    let noisy = (analysis.force_noise > MAX_NOISE_SHARE * level.abs()).then_some(
        EnergySkip::NoisyDerivative {
            force_noise: analysis.force_noise,
            level,
        },
    );
    let quantised = analysis.displacement_step.and_then(|step| {
        let share = turning_point_uncertainty(analysis, step) / dissipated.abs();
        (share > MAX_QUANTISATION_SHARE || !share.is_finite())
            .then_some(EnergySkip::Quantised { step, share })
    });
    let energies = if cycles.is_empty() {
        Some(EnergySkip::NoHalfCycle)
    } else {
        few.clone().or(quantised)
    };
    (few.or(noisy), energies)
}

/// The skip for a model force whose own noise (white-noise level of its second differences,
/// the larger of the median-based and the RMS level, so that a force chattering on a few
/// stretches of the motion counts) exceeds [`MAX_NOISE_SHARE`] of `level`: its mean then
/// measures the replayed noise. The noise is that of the samples the mean is taken over,
/// where the energy-based force `energy` is defined, each stretch of them apart: a static
/// law replayed along a noisy velocity chatters only at the reversals, which the
/// energy-based force's mask leaves out, so the paper's own kind of record is judged.
fn noisy_replay(model: &[f64], energy: &[f64], level: f64) -> Option<EnergySkip> {
    let force_noise = defined_stretches(energy)
        .map(|run| {
            let part = &model[run];
            (
                difference_noise(part, 2),
                rms_difference_noise(part, 2),
                part.len(),
            )
        })
        .fold(
            (Vec::new(), 0.0, 0usize),
            |(mut median_based, sq, n), (m, r, len)| {
                median_based.push(m);
                (median_based, sq + r * r * len as f64, n + len)
            },
        );
    let (median_based, sum_sq, n) = force_noise;
    if n == 0 {
        return None;
    }
    // The stretches' levels, each weighted alike: the median-based level is the largest
    // stretch's, the RMS level pooled over all.
    let median_level = median_based.iter().copied().fold(0.0, f64::max);
    let force_noise = median_level.max((sum_sq / n as f64).sqrt());
    (force_noise > MAX_NOISE_SHARE * level.abs())
        .then_some(EnergySkip::NoisyReplay { force_noise, level })
}

/// The index ranges of the stretches of at least three consecutive samples where `energy`
/// is defined (finite).
fn defined_stretches(energy: &[f64]) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    let mut start = None;
    (0..=energy.len()).filter_map(move |i| {
        let defined = energy.get(i).is_some_and(|e| e.is_finite());
        match (defined, start) {
            (true, None) => {
                start = Some(i);
                None
            }
            (false, Some(s)) => {
                start = None;
                (i - s >= 3).then_some(s..i)
            }
            _ => None,
        }
    })
}

/// Samples in the median complete half-cycle (`None` without one).
fn median_samples(analysis: &EnergyAnalysis) -> Option<usize> {
    let dt = mean_spacing(&analysis.time)?;
    let mut counts: Vec<usize> = analysis
        .half_cycles
        .iter()
        .map(|c| ((c.t_end - c.t_start) / dt).round() as usize)
        .collect();
    counts.sort_unstable();
    counts.get(counts.len() / 2).copied()
}

fn mean_spacing(time: &[f64]) -> Option<f64> {
    let n = time.len();
    (n >= 2).then(|| (time[n - 1] - time[0]) / (n - 1) as f64)
}

/// The uncertainty of the dissipated energy from a displacement quantised to `step`: k |x|
/// step / 2 at both turning points of every half-cycle.
fn turning_point_uncertainty(analysis: &EnergyAnalysis, step: f64) -> f64 {
    let k = stiffness_of(analysis);
    analysis
        .half_cycles
        .iter()
        .map(|c| {
            let x = |t| interpolate(&analysis.time, &analysis.x, t).abs();
            k * (x(c.t_start) + x(c.t_end)) * step / 2.0
        })
        .sum()
}

/// The spring stiffness of the analysis, from its potential energy k x^2 / 2 at the sample
/// farthest from equilibrium (the analysis keeps energies, not the oscillator).
fn stiffness_of(analysis: &EnergyAnalysis) -> f64 {
    let pe = &analysis.mechanical.potential;
    let far =
        (0..analysis.x.len()).max_by(|&a, &b| analysis.x[a].abs().total_cmp(&analysis.x[b].abs()));
    far.map_or(f64::NAN, |i| 2.0 * pe[i] / (analysis.x[i] * analysis.x[i]))
}

/// `values` at `t`, linear between samples (the end values outside).
fn interpolate(time: &[f64], values: &[f64], t: f64) -> f64 {
    let i = time.partition_point(|&s| s <= t);
    match (i.checked_sub(1), values.get(i)) {
        (Some(lo), Some(&hi)) => {
            let share = (t - time[lo]) / (time[i] - time[lo]);
            values[lo] + (hi - values[lo]) * share
        }
        (Some(lo), None) => values[lo],
        (None, _) => values.first().copied().unwrap_or(f64::NAN),
    }
}

/// int F v dt of the model force `force` over the half-cycle `c` of the analysed motion, with
/// the power F v linear between samples (the pieces at both ends cut at the turning points).
fn work_over(analysis: &EnergyAnalysis, force: &[f64], c: &HalfCycle) -> f64 {
    let (time, v) = (&analysis.time, &analysis.v);
    let power = |i: usize| force[i] * v[i];
    let power_at = |t: f64| {
        let i = time.partition_point(|&s| s <= t).clamp(1, time.len() - 1);
        let share = (t - time[i - 1]) / (time[i] - time[i - 1]);
        power(i - 1) + (power(i) - power(i - 1)) * share
    };
    let first = time.partition_point(|&s| s <= c.t_start);
    let last = time.partition_point(|&s| s < c.t_end);
    if first >= last {
        return 0.5 * (power_at(c.t_start) + power_at(c.t_end)) * (c.t_end - c.t_start);
    }
    let mut work = 0.5 * (power_at(c.t_start) + power(first)) * (time[first] - c.t_start);
    for i in first + 1..last {
        work += 0.5 * (power(i - 1) + power(i)) * (time[i] - time[i - 1]);
    }
    work + 0.5 * (power(last - 1) + power_at(c.t_end)) * (c.t_end - time[last - 1])
}

/// RMS of energy minus model force over the samples where both are defined, and their count.
fn residual_rms(energy: &[f64], model: &[f64]) -> Result<(f64, usize), EngineError> {
    let residual: Vec<f64> = energy
        .iter()
        .zip(model)
        .map(|(e, m)| e - m)
        .filter(|r| !r.is_nan())
        .collect();
    let rms = (residual.iter().map(|r| r * r).sum::<f64>() / residual.len() as f64).sqrt();
    match (residual.len(), rms.is_finite()) {
        (0, _) => Err(EngineError::InvalidInput(
            "no unmasked samples to compare the model force with".into(),
        )),
        (_, false) => Err(EngineError::InvalidInput(
            "the model gives a non-finite force along the motion".into(),
        )),
        (used, true) => Ok((rms, used)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::energy::{analyze_states, force_residuals, EnergyOptions};
    use crate::exact::coulomb_free_vibration;
    use crate::oscillator::Oscillator;
    use frictionid_models::Coulomb;

    fn exact_analysis(osc: &Oscillator, mu: f64) -> EnergyAnalysis {
        let time: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
        let e = coulomb_free_vibration(osc, mu * osc.normal_force, 0.014, &time).unwrap();
        analyze_states(osc, &e.time, &e.x, &e.v, &e.a, &EnergyOptions::default()).unwrap()
    }

    /// On the exact Coulomb motion the energy-based force is mu N wherever it is defined:
    /// the Coulomb model's force gives a zero difference and a zero residual.
    #[test]
    fn the_exact_coulomb_motion_passes_against_its_own_model() {
        let osc = Oscillator::fmm();
        let a = exact_analysis(&osc, 0.24);
        let model = Coulomb { mu: 0.24 };
        let fr = force_residuals(&a, &model, &osc).unwrap();
        let ef = energy_force_check(&a, ForceReference::ModelForce(&fr.model_force)).unwrap();
        let mu_n = 0.24 * osc.normal_force;
        assert!((ef.reference - mu_n).abs() < 1e-12);
        // The energy the model dissipates along the exact motion is the energy it loses.
        assert!(
            ef.dissipation_percent_difference.abs() < 0.05,
            "{}",
            ef.dissipation_percent_difference
        );
        assert!(ef.eq7_skipped.is_none() && ef.dissipation_skipped.is_none());
        assert!(
            ef.percent_difference.abs() < 1e-6,
            "{}",
            ef.percent_difference
        );
        // The independent residual computation of the energy module agrees.
        assert!((ef.residual_rms - fr.rms).abs() < 1e-15);
        assert_eq!(ef.samples, fr.used);
    }

    /// The energy check of a fit reads the analysis its residuals kept since the guess, which
    /// holds only some series: on a velocity record and on a quantised displacement's (whose
    /// turning points read the displacement and potential energy), the check is the same as
    /// on the whole analysis.
    #[test]
    fn the_check_of_a_kept_analysis_is_the_check_of_the_whole() {
        use crate::identify::problem::analysis_cache::{AnalysisCache, AnalysisRequest};
        use crate::record::{Channel, Record, TimeBase};
        let osc = Oscillator::fmm();
        let time: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
        let e = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.014, &time).unwrap();
        let velocity = Record::new("v", time.clone(), e.v.clone(), 0.014);
        let step = 5e-6;
        let counts: Vec<f64> = e.x.iter().map(|x| (x / step).round() * step).collect();
        let encoder = Record::from_time_base("x", TimeBase::new(time).unwrap())
            .with_channel(Channel::Displacement, counts);
        let options = EnergyOptions::default();
        for (index, record) in [velocity, encoder].iter().enumerate() {
            let whole = crate::energy::analyze_record(record, &osc, &options).unwrap();
            let cache = AnalysisCache::default();
            let kept = cache
                .analysis(AnalysisRequest {
                    index,
                    record,
                    osc: &osc,
                    options: &options,
                })
                .unwrap();
            assert_eq!(kept.displacement_step.is_some(), index == 1);
            let model: Vec<f64> = whole
                .v
                .iter()
                .map(|v| 0.24 * osc.normal_force * v.signum())
                .collect();
            for reference in [
                ForceReference::ModelForce(&model),
                ForceReference::Level(3.5),
            ] {
                let of = |a: &EnergyAnalysis| {
                    serde_json::to_string(&energy_force_check(a, reference).unwrap()).unwrap()
                };
                assert_eq!(of(&kept), of(&whole), "record {}", record.name);
            }
        }
    }

    /// Coulomb's force replayed along a noisy velocity chatters at the reversals only, where
    /// the energy-based force is masked: over the samples where it is defined the replay is
    /// quiet, so the Eq. 7 mean is judged; a force noisy everywhere (stiff bristles on a
    /// noisy velocity) is still skipped.
    #[test]
    fn a_replay_noisy_only_at_the_reversals_is_judged() {
        use rand::rngs::StdRng;
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let n = 3000;
        let mut rng = StdRng::seed_from_u64(1);
        let noise = Normal::new(0.0, 0.3).unwrap();
        let v: Vec<f64> = (0..n)
            .map(|i| (i as f64 * 0.05).sin() + noise.sample(&mut rng))
            .collect();
        let energy: Vec<f64> = v
            .iter()
            .map(|v| if v.abs() > 0.9 { 3.5 } else { f64::NAN })
            .collect();
        let coulomb: Vec<f64> = v.iter().map(|v| 3.5 * v.signum()).collect();
        // Over the whole record the chatter at the reversals reads as noise.
        assert!(rms_difference_noise(&coulomb, 2) > MAX_NOISE_SHARE * 3.5);
        assert_eq!(noisy_replay(&coulomb, &energy, 3.5), None);
        let noisy: Vec<f64> = (0..n)
            .map(|i| 3.5 + if i % 2 == 0 { 2.0 } else { -2.0 })
            .collect();
        assert!(matches!(
            noisy_replay(&noisy, &energy, 3.5),
            Some(EnergySkip::NoisyReplay { .. })
        ));
        let runs: Vec<_> = defined_stretches(&[
            1.0,
            1.0,
            1.0,
            f64::NAN,
            1.0,
            1.0,
            f64::NAN,
            1.0,
            1.0,
            1.0,
            1.0,
        ])
        .collect();
        assert_eq!(runs, [0..3, 7..11]);
    }

    /// A damping known to 1 % of a small value leaves the check judging; one whose standard
    /// error moves the friction's part by more than 2.5 % skips both parts with the reason.
    #[test]
    fn a_remainder_an_uncertain_damping_dominates_is_skipped() {
        let osc = Oscillator::fmm();
        let a = exact_analysis(&osc, 0.24);
        let model: Vec<f64> =
            a.v.iter()
                .map(|v| 0.24 * osc.normal_force * v.signum())
                .collect();
        let check = || energy_force_check(&a, ForceReference::ModelForce(&model)).unwrap();
        let mut known = check();
        let small = FittedDamping {
            value: 0.275,
            std_error: 0.003,
        };
        skip_ill_conditioned(&mut known, &a, small);
        assert!(known.eq7_skipped.is_none() && known.dissipation_skipped.is_none());
        let mut traded = check();
        let large = FittedDamping {
            value: 0.275,
            std_error: 20.0,
        };
        skip_ill_conditioned(&mut traded, &a, large);
        for part in [&traded.eq7_skipped, &traded.dissipation_skipped] {
            let Some(EnergySkip::IllConditioned { share, .. }) = part else {
                panic!("{part:?}");
            };
            assert!(*share > MAX_CONDITION_SHARE, "{share}");
        }
        // By hand: sigma_c mean|v| over the samples where Eq. 7 is defined, over mu N.
        let (sum, n) =
            a.v.iter()
                .zip(&a.friction)
                .filter(|(_, f)| f.is_finite())
                .fold((0.0, 0), |(s, n), (v, _)| (s + v.abs(), n + 1));
        let want = 20.0 * sum / n as f64 / (0.24 * osc.normal_force);
        let Some(EnergySkip::IllConditioned { share, .. }) = traded.eq7_skipped else {
            unreachable!()
        };
        assert!((share / want - 1.0).abs() < 1e-9, "{share} vs {want}");
        let finding = crate::identify::assessment::diagnostics::energy_balance(
            "r",
            &traded,
            crate::axis::Axis::Linear,
        );
        assert_eq!(finding.status, crate::identify::values::Status::Skipped);
        assert!(
            finding.message.contains("ill-conditioned"),
            "{}",
            finding.message
        );
    }

    #[test]
    fn a_level_reference_gives_the_percentage_by_definition() {
        let osc = Oscillator::fmm();
        let a = exact_analysis(&osc, 0.24);
        let level = 0.2 * osc.normal_force;
        let ef = energy_force_check(&a, ForceReference::Level(level)).unwrap();
        assert!((ef.percent_difference - 20.0).abs() < 1e-6);
        assert!(ef.residual_rms.is_nan());
        assert_eq!(
            ef.samples,
            a.friction.iter().filter(|f| f.is_finite()).count()
        );
        let short = energy_force_check(&a, ForceReference::ModelForce(&[1.0]));
        assert!(short.is_err());
    }
}
