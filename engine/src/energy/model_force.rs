//! A friction model's force along a measured motion, and its residuals against the
//! energy-based force.
//!
//! # Integrating the internal states
//! A dynamic model's states obey z' = f(v(t), z) with v the measured velocity, taken linear
//! between samples. Bristle models are stiff while sliding: LuGre's and Dahl's states relax
//! at a rate lambda ~ sigma0 |v| / (mu N), about 3e3 1/s for sigma0 = 1e5 N/m at 0.1 m/s with
//! mu N = 3.5 N, so a plain explicit step of dt = 1 ms (lambda dt ~ 3) would diverge. Each
//! sample interval is therefore integrated with the embedded Bogacki-Shampine 3(2) pair under
//! error control (rtol 1e-8, atol 1e-12 per state). The controller shrinks the sub-step to
//! what accuracy needs in the transients after a reversal and to the method's stability limit
//! (~2.5 / lambda) while the state sits on its slow manifold, so the result stays stable and
//! accurate for any stiffness, at a cost of about sigma0 |v| dt / (2.5 mu N) sub-steps per
//! sample (~1-4 for the paper's case). It needs nothing of the model beyond
//! `state_derivative`, so every registered model works unchanged.

use super::EnergyAnalysis;
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use frictionid_models::FrictionModel;
use serde::Serialize;

const RTOL: f64 = 1e-8;
const ATOL: f64 = 1e-12;
/// Total sub-step budget of one call (accepted and rejected).
const MAX_SUBSTEPS: u64 = 20_000_000;

/// The model force along a record against the energy-based force.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForceResiduals {
    /// The model's friction force at every sample \[N\].
    pub model_force: Vec<f64>,
    /// Energy-based force minus model force \[N\]; NaN where the energy-based force is masked.
    pub residual: Vec<f64>,
    /// Root mean square of the residual over the samples used \[N\].
    pub rms: f64,
    /// Number of samples used (not masked).
    pub used: usize,
}

/// The friction force of `model` along the measured motion (`time`, `v`), with the oscillator's
/// normal force. Static models are evaluated sample by sample, `model.force(v, &[], N)`;
/// dynamic models have their states integrated along v (linear between samples) from zero
/// (relaxed bristles at release), see the module docs.
pub fn model_force_along(
    model: &dyn FrictionModel,
    osc: &Oscillator,
    time: &[f64],
    v: &[f64],
) -> Result<Vec<f64>, EngineError> {
    osc.validate()?;
    if time.len() != v.len() {
        return Err(EngineError::InvalidInput(format!(
            "{} time stamps but {} velocities",
            time.len(),
            v.len()
        )));
    }
    if let Some(i) = (0..time.len()).find(|&i| !(time[i].is_finite() && v[i].is_finite())) {
        return Err(EngineError::InvalidInput(format!(
            "sample {i} is not finite (t = {}, v = {})",
            time[i], v[i]
        )));
    }
    if let Err(crate::record::TimeError::NotIncreasing { index, .. }) =
        crate::record::check_time(time)
    {
        return Err(EngineError::InvalidInput(format!(
            "time is not strictly increasing at sample {index}"
        )));
    }
    let normal = osc.normal_force;
    let ns = model.n_states();
    if ns == 0 {
        return Ok(v.iter().map(|&vi| model.force(vi, &[], normal)).collect());
    }
    let mut z = vec![0.0; ns];
    let mut out = Vec::with_capacity(v.len());
    let mut stepper = Stepper::new(ns);
    for i in 0..time.len() {
        if i > 0 {
            let (t0, t1) = (time[i - 1], time[i]);
            let (v0, v1) = (v[i - 1], v[i]);
            stepper.advance(model, normal, &mut z, t0, t1, v0, v1)?;
        }
        out.push(model.force(v[i], &z, normal));
    }
    Ok(out)
}

/// The model's force along the analysed motion against the energy-based force, on the samples
/// where the latter is not masked.
pub fn force_residuals(
    analysis: &EnergyAnalysis,
    model: &dyn FrictionModel,
    osc: &Oscillator,
) -> Result<ForceResiduals, EngineError> {
    let model_force = model_force_along(model, osc, &analysis.time, &analysis.v)?;
    if analysis.friction.len() != model_force.len() {
        return Err(EngineError::InvalidInput(format!(
            "analysis has {} forces for {} samples",
            analysis.friction.len(),
            model_force.len()
        )));
    }
    let residual: Vec<f64> = analysis
        .friction
        .iter()
        .zip(&model_force)
        .map(|(&f, &m)| if f.is_nan() { f64::NAN } else { f - m })
        .collect();
    let (sum, used) = residual
        .iter()
        .filter(|r| !r.is_nan())
        .fold((0.0, 0usize), |(s, n), r| (s + r * r, n + 1));
    if used == 0 {
        return Err(EngineError::InvalidInput(
            "no unmasked samples to compare the model force with".into(),
        ));
    }
    let rms = (sum / used as f64).sqrt();
    if !rms.is_finite() {
        return Err(EngineError::InvalidInput(format!(
            "model `{}` gives a non-finite force along the motion",
            model.name()
        )));
    }
    Ok(ForceResiduals {
        model_force,
        residual,
        rms,
        used,
    })
}

/// Adaptive Bogacki-Shampine 3(2) integrator of z' = f(v(t), z) with v linear in t.
struct Stepper {
    h: f64,
    steps: u64,
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
    next: Vec<f64>,
}

impl Stepper {
    fn new(ns: usize) -> Self {
        Self {
            h: 0.0,
            steps: 0,
            k: [vec![0.0; ns], vec![0.0; ns], vec![0.0; ns], vec![0.0; ns]],
            tmp: vec![0.0; ns],
            next: vec![0.0; ns],
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn advance(
        &mut self,
        model: &dyn FrictionModel,
        normal: f64,
        z: &mut [f64],
        t0: f64,
        t1: f64,
        v0: f64,
        v1: f64,
    ) -> Result<(), EngineError> {
        let span = t1 - t0;
        let vel = |t: f64| v0 + (v1 - v0) * (t - t0) / span;
        let mut t = t0;
        if self.h.is_nan() || self.h <= 0.0 || self.h > span {
            self.h = span;
        }
        let [k1, k2, k3, k4] = &mut self.k;
        model.state_derivative(vel(t), z, normal, k1);
        while t < t1 {
            let last = t + self.h >= t1 - 1e-12 * span;
            let h = if last { t1 - t } else { self.h };
            self.steps += 1;
            if self.steps > MAX_SUBSTEPS {
                return Err(EngineError::Integration {
                    time: t,
                    reason: format!(
                        "model `{}`: more than {MAX_SUBSTEPS} sub-steps integrating its states \
                         along the measured velocity",
                        model.name()
                    ),
                });
            }
            for j in 0..z.len() {
                self.tmp[j] = z[j] + 0.5 * h * k1[j];
            }
            model.state_derivative(vel(t + 0.5 * h), &self.tmp, normal, k2);
            for j in 0..z.len() {
                self.tmp[j] = z[j] + 0.75 * h * k2[j];
            }
            model.state_derivative(vel(t + 0.75 * h), &self.tmp, normal, k3);
            for j in 0..z.len() {
                self.next[j] =
                    z[j] + h * (2.0 / 9.0 * k1[j] + 1.0 / 3.0 * k2[j] + 4.0 / 9.0 * k3[j]);
            }
            model.state_derivative(vel(t + h), &self.next, normal, k4);
            let mut err: f64 = 0.0;
            for j in 0..z.len() {
                let low = z[j]
                    + h * (7.0 / 24.0 * k1[j] + 0.25 * k2[j] + 1.0 / 3.0 * k3[j] + 0.125 * k4[j]);
                let scale = ATOL + RTOL * z[j].abs().max(self.next[j].abs());
                err = err.max((self.next[j] - low).abs() / scale);
            }
            if !err.is_finite() {
                err = f64::INFINITY;
            }
            if err <= 1.0 {
                t = if last { t1 } else { t + h };
                z.copy_from_slice(&self.next);
                k1.copy_from_slice(k4);
                if !z.iter().all(|x| x.is_finite()) {
                    return Err(EngineError::Integration {
                        time: t,
                        reason: format!("model `{}`: a state became non-finite", model.name()),
                    });
                }
            }
            let factor = if err == 0.0 {
                5.0
            } else {
                (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 5.0)
            };
            let proposed = h * factor;
            // Keep the step size learnt in the interval, unless the last (shortened) step
            // was accepted: then carry the regular step into the next interval.
            self.h = if last && err <= 1.0 && h < self.h {
                self.h.max(proposed)
            } else {
                proposed
            };
            if self.h < 1e-14 * span.max(1e-300) {
                return Err(EngineError::Integration {
                    time: t,
                    reason: format!(
                        "model `{}`: step size underflow integrating its states",
                        model.name()
                    ),
                });
            }
        }
        Ok(())
    }
}
