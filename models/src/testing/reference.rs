//! The harness's reference integration of a law's states at constant velocity and normal
//! force: the oracle that exact steps ([`crate::Propagator`]) are checked against. It uses
//! nothing of a law but [`InternalStates::state_derivative`]: the fifth-order Dormand-Prince
//! formula (Hairer, Norsett & Wanner, Sec. II.5) with its step controlled by step doubling,
//! held to a tolerance far below what a replay needs. The interval is autonomous (v and N
//! constant), so the method needs no time; it steps until the interval's end, never past it.

use crate::interval::Interval;
use crate::model::InternalStates;

/// The Dormand-Prince 5(4) tableau (Hairer, Norsett & Wanner, Table II.5.2): row i holds
/// stage i + 1's coefficients a_ij as whole numerators over the row's least common
/// denominator, the last row the fifth-order weights b. The oracle states the tableau in this
/// form of its own so that it shares no transcription with the engine's solver it checks;
/// each quotient is the correctly rounded a_ij.
const ROWS: [(f64, &[f64]); 6] = [
    (5.0, &[1.0]),
    (40.0, &[3.0, 9.0]),
    (45.0, &[44.0, -168.0, 160.0]),
    (6561.0, &[19372.0, -76080.0, 64448.0, -1908.0]),
    (
        167904.0,
        &[477901.0, -1806240.0, 1495424.0, 46746.0, -45927.0],
    ),
    (
        142464.0,
        &[12985.0, 0.0, 64000.0, 92750.0, -45927.0, 18656.0],
    ),
];

/// Most steps of one interval before the integration gives up.
const MAX_STEPS: usize = 10_000_000;

/// Why a reference integration did not reach the end of its interval.
#[derive(Debug, Clone, PartialEq)]
pub enum ReferenceFailure {
    /// More than [`MAX_STEPS`] steps.
    TooManySteps,
    /// The step size fell below the round-off of the interval.
    StepTooSmall {
        /// How far into the interval \[s\].
        at: f64,
    },
}

/// The tolerance of a reference integration: component j is held to atol\[j\] + rtol |z_j|
/// per step.
#[derive(Debug, Clone, PartialEq)]
pub struct Tolerance {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance of each state.
    pub atol: Vec<f64>,
}

impl Tolerance {
    /// rtol 1e-13 and atol 1e-14 of each state's scale `scales[j]` (its size along the step:
    /// a bristle's deflection of micrometres needs an absolute tolerance of its own size).
    pub fn relative(scales: &[f64]) -> Self {
        Self {
            rtol: 1e-13,
            atol: scales.iter().map(|s| 1e-14 * s).collect(),
        }
    }

    fn norm(&self, z: &[f64], next: &[f64], err: &[f64]) -> f64 {
        let sum: f64 = (0..z.len())
            .map(|j| {
                let scale = self.atol[j] + self.rtol * z[j].abs().max(next[j].abs());
                (err[j] / scale).powi(2)
            })
            .sum();
        (sum / z.len().max(1) as f64).sqrt()
    }
}

/// One step of the fifth-order Dormand-Prince formula from `z` with step `h` into `out`
/// (`stages`: seven scratch vectors of the states' length).
fn dp5_step(
    rhs: &dyn Fn(&[f64], &mut [f64]),
    z: &[f64],
    h: f64,
    stages: &mut [Vec<f64>],
    out: &mut [f64],
) {
    rhs(z, &mut stages[0]);
    for s in 1..7 {
        let (done, todo) = stages.split_at_mut(s);
        let (denominator, numerators) = ROWS[s - 1];
        for (j, o) in out.iter_mut().enumerate() {
            let slope: f64 = numerators
                .iter()
                .zip(done.iter())
                .map(|(a, k)| a / denominator * k[j])
                .sum();
            *o = z[j] + h * slope;
        }
        if s < 6 {
            rhs(out, &mut todo[0]);
        }
    }
}

/// Integrates the states `z` of `law` over `interval` (v and N held) to `tol`.
///
/// The local error is estimated by step doubling (one step of h against two of h/2, whose
/// difference is 31 times the error of the pair), not by an embedded formula: a law with a
/// kink in its rate (an element that starts loading, a force that reaches its level) makes an
/// embedded pair's two solutions wrong by the same amount, so that their difference misses the
/// error, while halving the step shows it.
pub fn integrate(
    law: &dyn InternalStates,
    interval: Interval,
    z: &mut [f64],
    tol: &Tolerance,
) -> Result<(), ReferenceFailure> {
    let n = z.len();
    if n == 0 || interval.dt <= 0.0 {
        return Ok(());
    }
    let rhs =
        |y: &[f64], out: &mut [f64]| law.state_derivative(interval.v, y, interval.normal, out);
    let mut stages = vec![vec![0.0; n]; 7];
    let (mut full, mut half, mut pair, mut err) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut t, mut h) = (0.0, interval.dt * 1e-6);
    for _ in 0..MAX_STEPS {
        if t >= interval.dt {
            return Ok(());
        }
        let last = t + h >= interval.dt;
        let h_try = if last { interval.dt - t } else { h };
        dp5_step(&rhs, z, h_try, &mut stages, &mut full);
        dp5_step(&rhs, z, 0.5 * h_try, &mut stages, &mut half);
        dp5_step(&rhs, &half, 0.5 * h_try, &mut stages, &mut pair);
        for j in 0..n {
            err[j] = (pair[j] - full[j]) / 31.0;
        }
        let e = tol.norm(z, &pair, &err);
        if e <= 1.0 {
            t = if last { interval.dt } else { t + h_try };
            z.copy_from_slice(&pair);
        }
        let factor = if e == 0.0 {
            4.0
        } else {
            (0.9 * e.powf(-1.0 / 6.0)).clamp(0.2, 4.0)
        };
        h = h_try * factor;
        if h.is_nan() || h < f64::MIN_POSITIVE || t + h == t {
            return Err(ReferenceFailure::StepTooSmall { at: t });
        }
    }
    Err(ReferenceFailure::TooManySteps)
}
