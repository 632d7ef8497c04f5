//! The velocity domain's Jacobian columns from one augmented simulation per record: the
//! sampled displacement's and velocity's forward sensitivities
//! ([`simulate_sensitivities`]) weighted as the residuals are, the velocity offset's column
//! in closed form, and zeros for another record's nuisance values.
//!
//! Where the sensitivities are not available (a law without parameter gradients such as a
//! formula or a plugin, a measured input, the Euler integrator, a contact stiff enough that
//! the explicit augmented run would cost more than differences over the stiff integrator,
//! levels simulated scaled, an acceleration channel) or for a release shift, the column is
//! left to the fit's difference quotients: the choice is automatic.

use super::{ReleaseClock, SimulatedResponse};
use crate::error::EngineError;
use crate::identify::problem::residuals::{Evaluation, JacobianColumns, RecordCase, Residuals};
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::nuisance::NuisanceKind;
use crate::oscillator::OscillatorProperty;
use crate::record::Channel;
use crate::simulate::{
    simulate_sensitivities, RunInputs, SampleGrid, Sensitivities, SensitivityParam,
};

/// Where one free parameter's column comes from, for one record.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Source {
    /// The sensitivity at this index of the augmented run's parameters.
    Simulated(usize),
    /// The record's velocity offset: 1 on every velocity sample.
    VelocityOffset,
    /// Another record's nuisance value: no effect on this record.
    Zero,
    /// Left to difference quotients.
    Differences,
}

/// The source of each of `layout`'s columns for record `index`, and the parameters the
/// augmented run differentiates.
fn sources(layout: &[FreeParam], index: usize) -> (Vec<Source>, Vec<SensitivityParam>) {
    let mut params = Vec::new();
    let mut simulated = |p: SensitivityParam| {
        params.push(p);
        Source::Simulated(params.len() - 1)
    };
    let out = layout
        .iter()
        .map(|f| match f.kind {
            ParamKind::Model(i) => simulated(SensitivityParam::Model(i)),
            ParamKind::Property(OscillatorProperty::NormalForce) => Source::Differences,
            ParamKind::Property(q) => simulated(SensitivityParam::Property(q)),
            ParamKind::Nuisance { record, .. } if record != index => Source::Zero,
            ParamKind::Nuisance { kind, .. } => match kind {
                NuisanceKind::VelocityOffset => Source::VelocityOffset,
                NuisanceKind::StartDisplacement => simulated(SensitivityParam::StartDisplacement),
                NuisanceKind::ReleaseShift => Source::Differences,
                NuisanceKind::ForceOffset => Source::Zero,
            },
        })
        .collect();
    (out, params)
}

impl SimulatedResponse {
    /// The Jacobian columns of record `case` for `layout` ([`Residuals::jacobian_columns`]).
    pub(super) fn sensitivity_columns(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
        layout: &[FreeParam],
    ) -> Result<JacobianColumns, EngineError> {
        let (index, record) = (case.index, case.record);
        let channels = self.channels_of(index);
        let unsupported = channels.contains(&Channel::Acceleration)
            || record.channel(Channel::InputForce).is_some()
            || self.levels.scaled_for_simulation(at.model).is_some();
        if unsupported {
            return Ok(vec![None; layout.len()]);
        }
        let (sources, params) = sources(layout, index);
        let clock = ReleaseClock::new(record, case.nuisance);
        let sens = match clock.times.last() {
            Some(&t_end) if !params.is_empty() => {
                self.sensitivities(at, case, &clock, t_end, &params)?
            }
            _ => None,
        };
        let w = record.weight.sqrt();
        let segments = self.segments(index, record);
        let column = |source: Source| -> Option<Vec<f64>> {
            let mut out = Vec::with_capacity(record.len() * channels.len());
            for (&channel, segment) in channels.iter().zip(&segments) {
                let gain = w * segment.scale;
                let velocity = channel == Channel::Velocity;
                match source {
                    Source::Differences => return None,
                    Source::Zero => out.resize(out.len() + record.len(), 0.0),
                    Source::VelocityOffset => {
                        let value = if velocity { gain } else { 0.0 };
                        out.resize(out.len() + record.len(), value);
                    }
                    Source::Simulated(k) => {
                        let sens = sens.as_ref()?;
                        let p = params[k];
                        let (held, series) = match velocity {
                            true => (0.0, &sens.dv[k]),
                            false if p == SensitivityParam::StartDisplacement => (1.0, &sens.dx[k]),
                            false => (0.0, &sens.dx[k]),
                        };
                        out.resize(out.len() + clock.before, gain * held);
                        out.extend(series.iter().map(|d| gain * d));
                    }
                }
            }
            Some(out)
        };
        Ok(sources.into_iter().map(column).collect())
    }

    /// The augmented run of `case`'s record from its release to `t_end`, sampled at
    /// `clock`'s times, under the same oscillator, law, release state and step limit as its
    /// simulation ([`super::simulated_from_release`]); counted as a simulation.
    fn sensitivities(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
        clock: &ReleaseClock<'_>,
        t_end: f64,
        params: &[SensitivityParam],
    ) -> Result<Option<Sensitivities>, EngineError> {
        let record = case.record;
        at.count_simulation();
        let init = super::initial(record, case.nuisance);
        let opts = super::within_allowance(at, case.index, record, clock.times.len());
        let osc = record.oscillator_for(at.oscillator);
        simulate_sensitivities(
            RunInputs {
                osc: &osc,
                model: at.model,
                init: &init,
                input: None,
                grid: SampleGrid {
                    t_end,
                    sample_times: &clock.times,
                },
                opts: &opts,
            },
            params,
        )
    }
}
