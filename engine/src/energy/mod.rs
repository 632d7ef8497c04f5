//! Energy-based friction analysis of a free-vibration record (the paper's Eqs. 2-7).
//!
//! From the measured velocity v(t), the oscillator's m, c, k and the release displacement x0:
//!
//! - displacement x(t) by the trapezoidal rule from x(t0) = x0 ([`cumulative_trapezoid`]),
//!   or the record's measured displacement (an interferometer);
//! - acceleration a(t) by numerical differentiation ([`Differentiator`]), or the record's
//!   measured acceleration (an accelerometer): the paper's proposal of separate sensors,
//!   which removes the differentiation error and the displacement drift from Eq. 7
//!   ([`EnergyAnalysis::sources`] says which series were measured; a displacement-only record has its
//!   velocity by central differences);
//! - PE = k x^2 / 2 (Eq. 2), KE = m v^2 / 2 (Eq. 3), E = KE + PE, dE/dt = v (m a + k x) (Eq. 4);
//! - the friction force from Eq. 7 where |v| > `velocity_threshold`, NaN elsewhere;
//! - the differentiation-free half-cycle estimate (energy lost between turning points, less
//!   the viscous loss, over the distance travelled; see [`HalfCycle`]).
//!
//! # Sign convention
//! The paper writes Eq. 7 as dE/dt / v + c v = F_f with F_f the force the contact exerts on
//! the mass (its Eq. 6 puts F_f on the right of m a + c v + k x). The friction models of this
//! workspace use the opposite sign (F opposes the motion: positive for v > 0, in
//! m a + c v + k x + F = 0), so the force reported here is
//!
//!   F = -(dE/dt) / v - c v = -(m a + k x) - c v,
//!
//! which is directly comparable with `FrictionModel::force` (see [`force_residuals`]). Its
//! magnitude is the paper's |F_f|.
//!
//! # Masking and the oscillating interval
//! Eq. 7 divides by v, so samples with |v| <= `velocity_threshold` are masked (NaN, counted in
//! `masked`). So are samples after the mass has come to rest (the final turning point found
//! by the hysteresis detector described in [`halfcycle`]): the equation of motion with a
//! sliding friction force no longer holds there, and a noisy record would otherwise
//! contribute noise spikes. `mean_abs_force` is the mean of |F| over the unmasked samples,
//! i.e. over the oscillating interval, the quantity the paper compares with mu N (1.9 %,
//! 8.0 % and -4.3 % for its three records).
//!
//! # Displacement drift
//! Integrating a velocity with white noise of standard deviation sigma_v at spacing dt adds a
//! random walk to the displacement: after n samples its standard deviation is about
//! sigma_v dt sqrt(n) (the trapezoidal rule halves the end weights but not the growth). For
//! the paper's vibrometer-like noise of 2e-4 m/s at 1 kHz that is 6 um after 1 s, i.e. a
//! spring-force error k * 6 um = 0.013 N against mu N = 3.5 N. A bias b in the velocity
//! (offset of the vibrometer) drifts linearly, b (t - t0), and is far more harmful; it should
//! be removed before the analysis.
//!
//! # Choice of the default differentiator
//! The Coulomb acceleration jumps by 2 mu N / m at every reversal, and any smoothing window
//! that straddles the jump smears it over the samples on both sides, pulling |F| down on
//! both. With the paper's recipe applied across reversals this bias is about -0.5 to -1.4 %
//! on the records below. The Savitzky-Golay default therefore fits each half-cycle
//! separately (the breaks are the robust turning points) and uses one-sided fits of the same
//! size at the ends of a half-cycle. Measured on the FMM acceptance records (exact Coulomb
//! solution, mu = 0.24, x0 = 10, 14, 22 mm, 2 s at 1 kHz; `tests/energy.rs`), mean |Eq. 7|
//! against mu N:
//!
//! | differentiation | noise-free | 2e-4 m/s noise |
//! |---|---|---|
//! | paper, across reversals | -0.57, -1.00, -1.39 % | -0.57, -0.96, -1.28 % (1 seed) |
//! | SG 21, quadratic | +0.002, +0.011, +0.011 % | 0.13, 0.12, 0.12 % (RMS, 20 seeds) |
//! | SG 31, quartic (default) | +0.0018, +0.0008, +0.0007 % | 0.12, 0.13, 0.14 % (idem) |
//! | SG 51, quartic | +0.0017, +0.0005, +0.0004 % | 0.12, 0.11, 0.10 % (idem) |
//!
//! (SG n = Savitzky-Golay over n samples, fitted per half-cycle.)
//!
//! With noise the error is dominated by the displacement drift, not by the window, so the
//! default takes the middle window: 30 ms is 1/15 of the FMM period, short enough for stages
//! a few times stiffer, and the quartic keeps the fit error at 4e-6 of the acceleration.

pub(crate) mod differentiate;
mod force_derivatives;
pub(crate) mod halfcycle;
mod integrated_sensitivities;
pub(crate) mod model_force;
mod numerical_replay;

pub use crate::simulate::MechanicalEnergy;
pub use differentiate::{
    auto_window, central_difference, centre_weight_norm, derivative_weights, moving_average,
    paper_derivative, savitzky_golay_derivative, savitzky_golay_noise_gains, Differentiator,
    WindowInputs, AUTO_ORDER, PAPER_SPAN,
};
pub use halfcycle::{HalfCycle, MIN_RUN};
pub use model_force::{
    force_derivatives_along, force_derivatives_along_path, force_residuals, forces_at,
    forces_from_states, forces_in, model_force_along, model_force_with_normal, path_interval,
    replay_interval, states_along, states_along_path, ForceDerivatives, ForceResiduals,
    MeasuredMotion, SETTLED_RELAXATIONS, STEPS_PER_INTERVAL,
};

use crate::error::EngineError;
use crate::oscillator::Oscillator;
use crate::record::noise::{difference_noise, quantisation_step, RESPONSE_ORDER};
use crate::record::{Channel, Record};
use halfcycle::{detect_motion, half_cycles, Interp, Motion, Samples, VELOCITY_NOISE_ORDER};
use serde::{Deserialize, Serialize};

/// Options of the energy analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EnergyOptions {
    /// How the acceleration is obtained from the velocity (records only).
    pub differentiator: Differentiator,
    /// Samples with |v| at or below this speed are masked in Eq. 7 [m/s]. Also the lowest
    /// hysteresis level of the turning-point detector.
    pub velocity_threshold: f64,
}

impl Default for EnergyOptions {
    /// The automatic Savitzky-Golay window (31 samples, quartic, on the FMM at 1 kHz) and a
    /// 1 mm/s threshold: 1 % of the paper's smallest peak speed, 5x its vibrometer-like noise
    /// of 2e-4 m/s.
    fn default() -> Self {
        Self {
            differentiator: Differentiator::default(),
            velocity_threshold: 1e-3,
        }
    }
}

impl EnergyOptions {
    /// Checks the threshold and the differentiator's parameters.
    pub fn validate(&self) -> Result<(), EngineError> {
        if !(self.velocity_threshold.is_finite() && self.velocity_threshold >= 0.0) {
            return Err(EngineError::InvalidInput(format!(
                "`velocity_threshold` must be finite and >= 0, got {}",
                self.velocity_threshold
            )));
        }
        self.differentiator.validate()
    }
}

/// The energy analysis of one motion: every series has one value per sample.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EnergyAnalysis {
    /// Time \[s\].
    pub time: Vec<f64>,
    /// Displacement \[m\] (measured or integrated for a record, exact for states).
    pub x: Vec<f64>,
    /// Velocity [m/s].
    pub v: Vec<f64>,
    /// Acceleration [m/s^2] (measured or differentiated for a record, exact for states).
    pub a: Vec<f64>,
    /// Kinetic, potential and mechanical energy (Eqs. 2-3).
    #[serde(flatten)]
    pub mechanical: MechanicalEnergy,
    /// Energy rate v (m a + k x) \[W\] (Eq. 4).
    pub de_dt: Vec<f64>,
    /// Friction force -(dE/dt)/v - c v \[N\] (Eq. 7, model sign convention); NaN where masked.
    pub friction: Vec<f64>,
    /// Number of masked samples (|v| <= threshold, or after the final stop).
    pub masked: usize,
    /// Mean |friction| over the unmasked samples \[N\].
    pub mean_abs_force: f64,
    /// The half-cycle estimates, in time order.
    pub half_cycles: Vec<HalfCycle>,
    /// Mean of the half-cycle forces \[N\] (NaN if no complete half-cycle).
    pub half_cycle_mean: f64,
    /// Sample standard deviation of the half-cycle forces \[N\] (0 for one half-cycle).
    pub half_cycle_std: f64,
    /// Where the displacement, velocity and acceleration series came from.
    pub sources: SeriesSources,
    /// The Savitzky-Golay window the acceleration was differentiated with (`None` when it
    /// was measured, exact, or from the paper's recipe).
    pub window: Option<usize>,
    /// Standard deviation of Eq. 7's force from the measurement noise and quantisation
    /// (m times the derivative's noise, k times the displacement's quantisation) \[N\]; 0
    /// for exact states.
    pub force_noise: f64,
    /// The quantisation step of a measured displacement (an encoder's count) \[m\].
    pub displacement_step: Option<f64>,
}

/// How a series of the energy analysis was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SeriesSource {
    /// Read from the record's own channel (interferometer, accelerometer).
    Measured,
    /// Integrated from the velocity (cumulative trapezoid from x0).
    Integrated,
    /// Differentiated (the acceleration from the velocity by the configured differentiator,
    /// the velocity from the displacement by central differences).
    Differentiated,
    /// Given exactly (states of a simulation).
    Exact,
}

impl SeriesSource {
    /// The lower-case name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            SeriesSource::Measured => "measured",
            SeriesSource::Integrated => "integrated",
            SeriesSource::Differentiated => "differentiated",
            SeriesSource::Exact => "exact",
        }
    }
}

/// The origin of the displacement, velocity and acceleration of an [`EnergyAnalysis`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SeriesSources {
    /// Displacement: measured, or integrated from the velocity.
    pub displacement: SeriesSource,
    /// Velocity: measured, or differentiated from the displacement (an interferometer).
    pub velocity: SeriesSource,
    /// Acceleration: measured, or differentiated from the velocity.
    pub acceleration: SeriesSource,
}

/// The mean |F| of a model force series over the samples where the energy-based force
/// `energy_force` is defined (not masked): the reference the energy estimate is compared
/// with (exactly mu N for Coulomb friction). NaN when no sample is defined.
pub fn mean_abs_where_defined(model_force: &[f64], energy_force: &[f64]) -> f64 {
    let (sum, n) = model_force
        .iter()
        .zip(energy_force)
        .filter(|(m, e)| e.is_finite() && m.is_finite())
        .fold((0.0, 0usize), |(s, n), (m, _)| (s + m.abs(), n + 1));
    if n > 0 {
        sum / n as f64
    } else {
        f64::NAN
    }
}

/// 100 (value - reference) / reference [%].
pub fn percent_difference(value: f64, reference: f64) -> f64 {
    100.0 * (value - reference) / reference
}

/// Cumulative trapezoidal integral of `v` over `time`, starting from `x0` at `time[0]`.
///
/// Exact for a velocity linear between samples; the error for a smooth velocity is
/// -(dt^2 / 12) (a(t) - a(t0)) at most. Noise in `v` makes the result drift as a random walk
/// (see the module docs).
pub fn cumulative_trapezoid(time: &[f64], v: &[f64], x0: f64) -> Vec<f64> {
    let n = time.len().min(v.len());
    let mut x = Vec::with_capacity(n);
    if n == 0 {
        return x;
    }
    let mut acc = x0;
    x.push(acc);
    for i in 1..n {
        acc += 0.5 * (time[i] - time[i - 1]) * (v[i] + v[i - 1]);
        x.push(acc);
    }
    x
}

/// The velocity (measured, or the central difference of the displacement) and the
/// displacement (measured, or the velocity integrated from x0) of a record, with their
/// sources; `None` without either channel. The one place of this rule.
pub fn record_motion(record: &Record) -> Option<RecordMotion> {
    let time = record.time();
    let measured_x = record.channel(Channel::Displacement);
    let (v, velocity) = match record.channel(Channel::Velocity) {
        Some(v) => (v.to_vec(), SeriesSource::Measured),
        None => (
            central_difference(time, measured_x?),
            SeriesSource::Differentiated,
        ),
    };
    let (x, displacement) = match measured_x {
        Some(x) => (x.to_vec(), SeriesSource::Measured),
        None => (
            cumulative_trapezoid(time, &v, record.x0),
            SeriesSource::Integrated,
        ),
    };
    Some(RecordMotion {
        v,
        x,
        velocity,
        displacement,
    })
}

/// The velocity and displacement of a record ([`record_motion`]) and where each came from.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordMotion {
    /// Velocity \[m/s\].
    pub v: Vec<f64>,
    /// Displacement \[m\].
    pub x: Vec<f64>,
    /// Measured, or differentiated from the displacement.
    pub velocity: SeriesSource,
    /// Measured, or integrated from the velocity.
    pub displacement: SeriesSource,
}

impl RecordMotion {
    /// Its displacement and velocity at `time`, without acceleration, linearly interpolated.
    fn samples<'a>(&'a self, time: &'a [f64]) -> Samples<'a> {
        Samples {
            time,
            x: &self.x,
            v: &self.v,
            a: &[],
            interp: Interp::Linear,
        }
    }
}

/// The energy analysis of a measured record, from its measured displacement, velocity and
/// acceleration where it has them (the paper's proposal of separate sensors); `sources` says
/// which were used. A measured displacement must be relative to the spring's equilibrium
/// (the x of Eq. 2).
///
/// Errors: invalid options or oscillator; a record with neither velocity nor displacement,
/// fewer samples than the differentiator's window, non-finite values, non-increasing time
/// (see [`Record::validate_channels`]); a record without motion (|v| never clearly above the
/// threshold and the noise).
pub fn analyze_record(
    record: &Record,
    osc: &Oscillator,
    opts: &EnergyOptions,
) -> Result<EnergyAnalysis, EngineError> {
    record.require_x0("the energy analysis (it integrates the velocity from x0)")?;
    let (measured, motion, velocity_noise) = measured_motion(record, osc, opts)?;
    let time = record.time();
    let displacement_step = match measured.displacement {
        SeriesSource::Measured => record
            .channel(Channel::Displacement)
            .and_then(quantisation_step),
        _ => None,
    };
    let (a, acceleration, derivative) = match record.channel(Channel::Acceleration) {
        Some(channel) => {
            let noise = osc.mass * difference_noise(channel, RESPONSE_ORDER);
            let measured_a = Derivative {
                window: None,
                force_noise: noise,
            };
            (channel.to_vec(), SeriesSource::Measured, measured_a)
        }
        None => {
            let level = half_cycles(&measured.samples(time), &motion, osc).1;
            let context = DerivativeContext {
                osc,
                velocity_noise,
                level,
            };
            let (a, derivative) =
                differentiate_velocity(time, &measured.v, opts, &motion, &context)?;
            (a, SeriesSource::Differentiated, derivative)
        }
    };
    let sources = SeriesSources {
        displacement: measured.displacement,
        velocity: measured.velocity,
        acceleration,
    };
    let series = Series {
        time: time.to_vec(),
        x: measured.x,
        v: measured.v,
        a,
        interp: Interp::Linear,
    };
    let mut analysis = assemble(osc, series, &motion, opts, sources);
    let spring_noise = displacement_step.map_or(0.0, |q| osc.stiffness * q / 12f64.sqrt());
    analysis.window = derivative.window;
    analysis.force_noise = derivative.force_noise.hypot(spring_noise);
    analysis.displacement_step = displacement_step;
    Ok(analysis)
}

/// How the acceleration of an analysis was obtained: the Savitzky-Golay window, and the
/// standard deviation of m a from the velocity's noise \[N\].
struct Derivative {
    window: Option<usize>,
    force_noise: f64,
}

/// What the automatic differentiator chooses its window from.
struct DerivativeContext<'a> {
    osc: &'a Oscillator,
    /// The velocity's noise, quantisation included \[m/s\].
    velocity_noise: f64,
    /// The half-cycle mean friction force \[N\] (NaN without a complete half-cycle).
    level: f64,
}

/// The samples an analysis keeps (owned: the measured motion and the derivative are moved
/// in, not copied) and how to interpolate between them.
struct Series {
    time: Vec<f64>,
    x: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    interp: Interp,
}

impl Series {
    fn samples(&self) -> Samples<'_> {
        Samples {
            time: &self.time,
            x: &self.x,
            v: &self.v,
            a: &self.a,
            interp: self.interp,
        }
    }
}

/// The half-cycle energy estimate of the friction force of a measured record (the mean of
/// [`EnergyAnalysis::half_cycles`]' forces, `None` without a complete half-cycle): the part of
/// [`analyze_record`] that needs no acceleration, at a fraction of its cost. Errors as
/// [`analyze_record`]'s.
pub fn half_cycle_force(
    record: &Record,
    osc: &Oscillator,
    opts: &EnergyOptions,
) -> Result<Option<f64>, EngineError> {
    let (measured, motion, _) = measured_motion(record, osc, opts)?;
    let (_, mean, _) = half_cycles(&measured.samples(record.time()), &motion, osc);
    Ok(mean.is_finite().then_some(mean))
}

/// The checked inputs of an energy analysis: the record's displacement and velocity, its
/// motion (release, turning points, end) and the velocity's noise level (white noise from
/// its second differences, or the quantisation of its values, step / sqrt(12), when larger:
/// a quantised velocity's differences are mostly zero).
fn measured_motion(
    record: &Record,
    osc: &Oscillator,
    opts: &EnergyOptions,
) -> Result<(RecordMotion, Motion, f64), EngineError> {
    opts.validate()?;
    osc.validate()?;
    let window = match opts.differentiator {
        // The automatic window's own size on this record.
        Differentiator::Auto => {
            let time = record.time();
            let span = time.last().zip(time.first()).map(|(b, a)| b - a);
            let dt = span.unwrap_or(f64::NAN) / time.len().saturating_sub(1).max(1) as f64;
            differentiate::auto_base_window(dt, 2.0 * std::f64::consts::PI / osc.omega_n())
        }
        other => other.min_samples(),
    };
    record.validate_channels(window.max(MIN_RUN + 1))?;
    let Some(measured) = record_motion(record) else {
        // The velocity check names what the record has instead.
        record.validate(0)?;
        return Err(EngineError::InvalidInput(format!(
            "record `{}`: no motion",
            record.name
        )));
    };
    let samples = measured.samples(record.time());
    let noise = match measured.velocity {
        SeriesSource::Measured => record.difference_noise(Channel::Velocity, VELOCITY_NOISE_ORDER),
        _ => None,
    }
    .unwrap_or_else(|| difference_noise(&measured.v, VELOCITY_NOISE_ORDER));
    let motion = detect_motion(
        &samples,
        opts.velocity_threshold,
        noise,
        record.v0,
        &record.name,
    )?;
    let quantised = quantisation_step(&measured.v).map_or(0.0, |q| q / 12f64.sqrt());
    Ok((measured, motion, noise.max(quantised)))
}

/// The acceleration from the velocity by the configured differentiator (Savitzky-Golay
/// windows do not straddle the breaks of the motion; the automatic one takes its window from
/// the record, [`auto_window`]), and how it was obtained.
fn differentiate_velocity(
    time: &[f64],
    v: &[f64],
    opts: &EnergyOptions,
    motion: &Motion,
    context: &DerivativeContext<'_>,
) -> Result<(Vec<f64>, Derivative), EngineError> {
    let dt = (time[time.len() - 1] - time[0]) / (time.len() - 1).max(1) as f64;
    let force_noise = |norm: f64| context.osc.mass * context.velocity_noise * norm / dt;
    let (window, order) = match opts.differentiator {
        Differentiator::Paper => {
            let derivative = Derivative {
                window: None,
                force_noise: force_noise(differentiate::PAPER_WEIGHT_NORM),
            };
            return Ok((paper_derivative(time, v), derivative));
        }
        Differentiator::SavitzkyGolay { window, order } => (window, order),
        Differentiator::Auto => {
            let inputs = WindowInputs {
                dt,
                period: 2.0 * std::f64::consts::PI / context.osc.omega_n(),
                velocity_noise: context.velocity_noise,
                mass: context.osc.mass,
                level: context.level,
            };
            (auto_window(&inputs)?.0, AUTO_ORDER)
        }
    };
    let a = savitzky_golay_derivative(time, v, window, order, &motion.break_indices(time))?;
    let derivative = Derivative {
        window: Some(window),
        force_noise: force_noise(centre_weight_norm(window, order)?),
    };
    Ok((a, derivative))
}

/// The energy analysis from exact states (e.g. a simulated trajectory): no integration, no
/// differentiation. The half-cycle integrals use the cubic Hermite velocity built from
/// (v, a), and the turning points a Newton step on the acceleration, so a Coulomb trajectory
/// returns mu N to round-off.
///
/// Errors: unequal lengths, fewer than [`MIN_RUN`] + 1 samples, non-finite values,
/// non-increasing time, no motion.
pub fn analyze_states(
    osc: &Oscillator,
    time: &[f64],
    x: &[f64],
    v: &[f64],
    a: &[f64],
    opts: &EnergyOptions,
) -> Result<EnergyAnalysis, EngineError> {
    opts.validate()?;
    osc.validate()?;
    let err = |reason: String| EngineError::Record {
        record: "states".into(),
        reason,
    };
    let n = time.len();
    if x.len() != n || v.len() != n || a.len() != n {
        return Err(err(format!(
            "lengths differ: time {n}, x {}, v {}, a {}",
            x.len(),
            v.len(),
            a.len()
        )));
    }
    if n < MIN_RUN + 1 {
        return Err(err(format!("{n} samples, at least {} needed", MIN_RUN + 1)));
    }
    if let Some(i) = (0..n).find(|&i| {
        !(time[i].is_finite() && x[i].is_finite() && v[i].is_finite() && a[i].is_finite())
    }) {
        return Err(err(format!(
            "sample {i} is not finite (t = {}, x = {}, v = {}, a = {})",
            time[i], x[i], v[i], a[i]
        )));
    }
    crate::record::check_time(time).map_err(|e| err(e.to_string()))?;
    let samples = Samples {
        time,
        x,
        v,
        a,
        interp: Interp::Hermite,
    };
    let noise = difference_noise(v, VELOCITY_NOISE_ORDER);
    let motion = detect_motion(&samples, opts.velocity_threshold, noise, v[0], "states")?;
    let exact = SeriesSources {
        displacement: SeriesSource::Exact,
        velocity: SeriesSource::Exact,
        acceleration: SeriesSource::Exact,
    };
    let series = Series {
        time: time.to_vec(),
        x: x.to_vec(),
        v: v.to_vec(),
        a: a.to_vec(),
        interp: Interp::Hermite,
    };
    Ok(assemble(osc, series, &motion, opts, exact))
}

/// Energies, Eq. 7 and the half-cycles from complete samples.
fn assemble(
    osc: &Oscillator,
    series: Series,
    motion: &Motion,
    opts: &EnergyOptions,
    sources: SeriesSources,
) -> EnergyAnalysis {
    let s = &series.samples();
    let (m, c) = (osc.mass, osc.damping);
    let n = s.time.len();
    let mechanical = MechanicalEnergy::of(osc, s.x, s.v);
    let de_dt: Vec<f64> = (0..n)
        .map(|i| s.v[i] * (m * s.a[i] + osc.restoring_force(s.x[i])))
        .collect();
    let friction: Vec<f64> = (0..n)
        .map(|i| {
            let v = s.v[i];
            if v.abs() > opts.velocity_threshold && s.time[i] <= motion.end_time {
                -de_dt[i] / v - c * v
            } else {
                f64::NAN
            }
        })
        .collect();
    let (sum, used) = friction
        .iter()
        .filter(|f| !f.is_nan())
        .fold((0.0, 0usize), |(s, u), f| (s + f.abs(), u + 1));
    let mean_abs_force = if used > 0 {
        sum / used as f64
    } else {
        f64::NAN
    };
    let (cycles, half_cycle_mean, half_cycle_std) = half_cycles(s, motion, osc);
    let Series { time, x, v, a, .. } = series;
    // Exact states carry no noise; a record's analysis overwrites these.
    EnergyAnalysis {
        time,
        x,
        v,
        a,
        mechanical,
        de_dt,
        friction,
        masked: n - used,
        mean_abs_force,
        half_cycles: cycles,
        half_cycle_mean,
        half_cycle_std,
        sources,
        window: None,
        force_noise: 0.0,
        displacement_step: None,
    }
}
