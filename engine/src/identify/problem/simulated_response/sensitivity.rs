//! The velocity domain's Jacobian columns from one augmented simulation per record: the
//! sampled displacement's and velocity's forward sensitivities
//! ([`simulate_sensitivities`]) weighted as the residuals are, the velocity offset's column
//! in closed form, and zeros for another record's nuisance values.
//!
//! A record driven by a measured input has its sensitivities under that input, across the
//! sticks and breakaways it forces. Where they are not available (a law without parameter
//! gradients such as a formula or a plugin, a law that reads channels, the Euler
//! integrator, levels simulated scaled, an acceleration channel) or for a release shift, the column is
//! left to the fit's difference quotients: the choice is automatic.

use super::{ReleaseClock, SimulatedResponse};
use crate::error::EngineError;
use crate::identify::problem::residuals::{Evaluation, JacobianColumns, RecordCase, Residuals};
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::nuisance::NuisanceKind;
use crate::oscillator::OscillatorProperty;
use crate::record::Channel;
use crate::simulate::{
    simulate_sensitivities, RunInputs, SampleGrid, SampledSeries, Sensitivities, SensitivityParam,
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
    /// `clock`'s times, under the same oscillator, law, release state, measured input and
    /// step limit as its simulation ([`super::simulated_from_release`]); counted as a
    /// simulation. A law that reads channels has none (`simulate_sensitivities` refuses it).
    fn sensitivities(
        &self,
        at: &Evaluation<'_>,
        case: RecordCase<'_>,
        clock: &ReleaseClock<'_>,
        t_end: f64,
        params: &[SensitivityParam],
    ) -> Result<Option<Sensitivities>, EngineError> {
        let record = case.record;
        let kept = if self
            .channels_of(case.index)
            .contains(&Channel::Displacement)
        {
            SampledSeries::All
        } else {
            SampledSeries::VelocitySensitivities
        };
        at.count_simulation();
        let init = super::initial(record, case.nuisance);
        let opts = super::within_allowance(at, case.index, record, clock.times.len());
        let osc = record.oscillator_for(at.oscillator);
        let input = clock.input(record)?;
        simulate_sensitivities(
            RunInputs {
                osc: &osc,
                model: at.model,
                init: &init,
                input: input.as_ref(),
                channels: None,
                grid: SampleGrid {
                    t_end,
                    sample_times: &clock.times,
                },
                opts: &opts,
            },
            params,
            kept,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::problem::least_squares::{FitProblem, ProblemParts};
    use crate::oscillator::Oscillator;
    use crate::record::Record;
    use crate::simulate::{simulate, Initial, SimOptions};
    use frictionid_models::LuGre;
    use nalgebra::DVector;
    use std::sync::Arc;

    /// Two LuGre records (0.6 s at 1 kHz from 14 and 22 mm), their velocities as simulated.
    fn records(osc: &Oscillator, model: &LuGre, opts: &SimOptions) -> Vec<Record> {
        let time: Vec<f64> = (0..600).map(|i| i as f64 * 1e-3).collect();
        [0.014, 0.022]
            .iter()
            .map(|&x0| {
                let init = Initial {
                    x0,
                    v0: 0.0,
                    z0: None,
                };
                let v = simulate(osc, model, &init, 0.599, &time, opts).unwrap().v;
                Record::new(format!("{x0}"), time.clone(), v, x0)
            })
            .collect()
    }

    fn param(name: &str, kind: ParamKind, value: f64, log: bool) -> FreeParam {
        FreeParam {
            log,
            ..FreeParam::linear(name.into(), "", kind, (-1e12, 1e12), value, 1.0)
        }
    }

    /// A velocity fit's problem of `model` on `osc` over `records` with `layout` at the
    /// tight options; `(offset, shift, x0)` say which nuisance values the residuals carry.
    fn velocity_problem(
        osc: Oscillator,
        model: Box<dyn frictionid_models::FrictionModel>,
        records: Arc<[Record]>,
        layout: Vec<FreeParam>,
        (offset, shift, x0): (bool, bool, bool),
    ) -> FitProblem<SimulatedResponse> {
        let residuals = SimulatedResponse::for_records(&records, offset, shift, x0).unwrap();
        FitProblem::new(
            Arc::new(residuals),
            ProblemParts {
                oscillator: osc,
                model,
                records,
                layout,
                sim: SimOptions::tight_dopri5(),
                parallel: false,
            },
        )
    }

    /// The first `columns` columns of `jac` (at internal point `u`) against central
    /// differences of the residuals at relative step `rel`, each within 1e-3 of its scale.
    fn assert_columns_match_differences<R: Residuals + 'static>(
        problem: &FitProblem<R>,
        u: &DVector<f64>,
        jac: &nalgebra::DMatrix<f64>,
        columns: usize,
        rel: f64,
    ) {
        for j in 0..columns {
            let h = rel * u[j].abs().max(1e-3);
            let mut moved = u.clone();
            moved[j] += h;
            let plus = problem.residuals_at(&problem.physical(&moved)).unwrap();
            moved[j] -= 2.0 * h;
            let minus = problem.residuals_at(&problem.physical(&moved)).unwrap();
            let expected: DVector<f64> = (plus - minus) / (2.0 * h);
            let scale = expected.amax().max(1e-12);
            let off = (jac.column(j) - &expected).amax() / scale;
            assert!(off < 1e-3, "column {j}: off by {off:e} of {scale:e}");
        }
    }

    /// The fit's Jacobian with the sensitivity columns (law, property, x0, offset, another
    /// record's nuisance) against central differences of the residuals in internal
    /// coordinates, column by column; the release shift's column is the fit's forward
    /// difference either way (at a release on a sample it is one-sided: not compared).
    #[test]
    fn sensitivity_columns_match_central_differences_of_the_residuals() {
        let osc = Oscillator::fmm();
        let model = LuGre::default();
        let records: Arc<[Record]> = records(&osc, &model, &SimOptions::tight_dopri5()).into();
        let nuisance = |kind, record| ParamKind::Nuisance { kind, record };
        let layout = vec![
            param("sigma0", ParamKind::Model(0), 1e5, true),
            param("mu_c", ParamKind::Model(3), 0.2, false),
            param(
                "c",
                ParamKind::Property(OscillatorProperty::Damping),
                0.275,
                false,
            ),
            param("off", nuisance(NuisanceKind::VelocityOffset, 0), 0.0, false),
            param(
                "x0",
                nuisance(NuisanceKind::StartDisplacement, 1),
                0.022,
                false,
            ),
            param("shift", nuisance(NuisanceKind::ReleaseShift, 0), 0.0, false),
        ];
        let nuisance = (true, true, true);
        let problem = velocity_problem(osc, Box::new(model), records, layout, nuisance);
        let p = [1e5, 0.2, 0.275, 0.0, 0.022, 0.0];
        let u = problem.internal(&p);
        let r0 = problem.residuals_at(&p).unwrap();
        let jac = problem.jacobian_internal(&u, &r0);
        assert_columns_match_differences(&problem, &u, &jac, p.len() - 1, 1e-5);
        // The offset's column is 1 on record 0's samples and 0 on record 1's.
        assert!(jac
            .column(3)
            .iter()
            .take(600)
            .all(|&d| (d - 1.0).abs() < 1e-12));
        assert!(jac.column(3).iter().skip(600).all(|&d| d == 0.0));
    }

    /// A record driven by a slow 8 N force (0.5 Hz) that sticks Stribeck's law at its start
    /// and at each turn until the force breaks it away: the Jacobian (every law parameter,
    /// the mass and the stiffness) from one augmented run under the record's input, against
    /// central differences of the residuals.
    #[test]
    fn a_driven_record_takes_its_columns_from_one_run_under_its_input() {
        let osc = Oscillator::fmm();
        let model = frictionid_models::Stribeck::default();
        let time: Vec<f64> = (0..3000).map(|i| i as f64 * 1e-3).collect();
        let u: Vec<f64> = time
            .iter()
            .map(|t| 8.0 * (std::f64::consts::PI * t).sin())
            .collect();
        let record = Record::new("driven", time.clone(), vec![0.0; time.len()], 0.0)
            .with_channel(Channel::InputForce, u);
        let records: Arc<[Record]> = vec![record].into();
        let layout = vec![
            param("mu_c", ParamKind::Model(0), 0.2, false),
            param("mu_s", ParamKind::Model(1), 0.3, false),
            param("v_s", ParamKind::Model(2), 0.01, true),
            param("viscous", ParamKind::Model(4), 0.5, false),
            param(
                "m",
                ParamKind::Property(OscillatorProperty::Mass),
                osc.mass,
                false,
            ),
            param(
                "k",
                ParamKind::Property(OscillatorProperty::Stiffness),
                osc.stiffness,
                false,
            ),
        ];
        let nuisance = (true, false, false);
        let problem = velocity_problem(osc, Box::new(model), records, layout, nuisance);
        let p = [0.2, 0.3, 0.01, 0.5, osc.mass, osc.stiffness];
        let u = problem.internal(&p);
        let r0 = problem.residuals_at(&p).unwrap();
        let before = problem.simulations();
        let jac = problem.jacobian_internal(&u, &r0);
        assert_eq!(problem.simulations() - before, 1, "one augmented run");
        assert_columns_match_differences(&problem, &u, &jac, p.len(), 1e-6);
    }
}
