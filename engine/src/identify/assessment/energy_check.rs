//! The energy-balance check (the paper's cross-check): the friction force from the energy
//! balance, Eq. 7, held against the force of a fitted model or a given reference force.
//!
//! One function, [`energy_force_check`], serves the identifier (after every fit) and the
//! `energy` command (against `[model]`, `reference_force` or a Coulomb fit).

use crate::energy::{mean_abs_where_defined, percent_difference, EnergyAnalysis};
use crate::error::EngineError;
use crate::identify::values::EnergyForce;

/// What the energy-based force is compared with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ForceReference<'a> {
    /// A model's friction force along the analysed motion, one value per sample of the
    /// analysis (e.g. from [`crate::energy::model_force_along`] on `analysis.time`,
    /// `analysis.v`). The reference level is its mean |F| over the samples where the
    /// energy-based force is defined (exactly mu N for Coulomb friction).
    ModelForce(&'a [f64]),
    /// A constant force level [N] (e.g. a measured mu N).
    Level(f64),
}

/// Holds the energy-based force of `analysis` against `reference`.
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
    let (level, distance_level, residual_rms, samples) = match reference {
        ForceReference::ModelForce(model) => {
            if model.len() != energy.len() {
                return Err(EngineError::InvalidInput(format!(
                    "analysis has {} forces for {} samples",
                    energy.len(),
                    model.len()
                )));
            }
            let (rms, used) = residual_rms(energy, model)?;
            let distance = distance_mean(model, energy, &analysis.v);
            (mean_abs_where_defined(model, energy), distance, rms, used)
        }
        ForceReference::Level(level) => (
            level,
            level,
            f64::NAN,
            energy.iter().filter(|f| f.is_finite()).count(),
        ),
    };
    Ok(EnergyForce {
        mean_abs: analysis.mean_abs_force,
        reference: level,
        percent_difference: percent_difference(analysis.mean_abs_force, level),
        residual_rms,
        samples,
        half_cycle_mean: analysis.half_cycle_mean,
        half_cycle_reference: distance_level,
        half_cycle_percent_difference: percent_difference(analysis.half_cycle_mean, distance_level),
    })
}

/// The distance mean sum |F| |v| / sum |v| of a model force over the samples where the
/// energy-based force is defined (NaN when none is).
fn distance_mean(model: &[f64], energy: &[f64], v: &[f64]) -> f64 {
    let (work, distance) = model
        .iter()
        .zip(energy)
        .zip(v)
        .filter(|((m, e), _)| e.is_finite() && m.is_finite())
        .fold((0.0, 0.0), |(w, d), ((m, _), v)| {
            (w + m.abs() * v.abs(), d + v.abs())
        });
    if distance > 0.0 {
        work / distance
    } else {
        f64::NAN
    }
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
        // Coulomb friction is the same at every speed: its distance mean is mu N too, and
        // the half-cycle estimate (energy per distance) finds it.
        assert!((ef.half_cycle_reference - mu_n).abs() < 1e-12);
        assert!(ef.half_cycle_percent_difference.abs() < 0.5);
        assert!(
            ef.percent_difference.abs() < 1e-6,
            "{}",
            ef.percent_difference
        );
        // The independent residual computation of the energy module agrees.
        assert!((ef.residual_rms - fr.rms).abs() < 1e-15);
        assert_eq!(ef.samples, fr.used);
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
