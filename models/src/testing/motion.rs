//! The invariants of a model in motion: a free vibration of an oscillator with the model as
//! its friction contact. This crate has no solver, so the caller supplies one through
//! [`Simulator`] (a few lines over the engine's `simulate`; see
//! `examples/plugin-model/tests/invariants.rs`), and these checks judge what it returns:
//!
//! - [`check_energy_never_increases`]: KE + PE + stored never rises for a passive model, and a
//!   set-valued law comes to rest within its breakaway limit, |k x| <= limit;
//! - [`check_mirror_symmetry`]: the release from -x0 gives -x(t), -v(t) and -F(t);
//! - [`check_integrators_agree`]: the paper's fixed-step Euler converges to the adaptive
//!   solution at first order (ten times the steps, about a tenth of the error).

use super::{ensure, fail, Check, Model, Outcome};

/// Which integrator a release uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integration {
    /// The engine's default adaptive solver.
    Adaptive,
    /// Fixed-step explicit Euler with this many steps per undamped natural period.
    Euler {
        /// Steps per natural period.
        steps_per_period: f64,
    },
}

/// A release of the mass from rest: from where, for how long, with which integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Release {
    /// The initial displacement \[m\].
    pub x0: f64,
    /// The end of the simulation \[s\].
    pub t_end: f64,
    /// The integrator.
    pub integration: Integration,
}

impl Release {
    /// A release from `x0` until `t_end` with the engine's adaptive solver.
    pub fn adaptive(x0: f64, t_end: f64) -> Self {
        Self {
            x0,
            t_end,
            integration: Integration::Adaptive,
        }
    }
}

/// A simulated release, sampled at common times (every release of one check uses the same
/// sampling).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Motion {
    /// Sample times \[s\].
    pub time: Vec<f64>,
    /// Displacement \[m\].
    pub x: Vec<f64>,
    /// Velocity [m/s].
    pub v: Vec<f64>,
    /// Number of events (turning points, sticks, ...).
    pub events: usize,
    /// Where the mass came to rest for good, if it did.
    pub rest_displacement: Option<f64>,
    /// Friction force \[N\].
    pub friction: Vec<f64>,
    /// Kinetic + potential + stored energy \[J\].
    pub total_energy: Vec<f64>,
}

/// An oscillator and a solver: releases a mass from rest with a given friction model.
pub trait Simulator {
    /// The spring stiffness [N/m].
    fn stiffness(&self) -> f64;
    /// The normal force of the contact \[N\].
    fn normal_force(&self) -> f64;
    /// Releases the mass from rest at `x0` and simulates until `t_end`, sampled at fixed
    /// times (the same for every call with the same `t_end`).
    fn release(&self, model: &Model, release: Release) -> Result<Motion, String>;
}

/// `sim`'s release of `model`, its failure a [`Check::Simulates`] violation.
fn released(
    sim: &dyn Simulator,
    model: &Model,
    release: Release,
) -> Result<Motion, super::Violation> {
    let Release {
        x0, integration, ..
    } = release;
    sim.release(model, release).map_err(|e| super::Violation {
        model: model.name().to_string(),
        check: Check::Simulates,
        message: format!("release from {x0} m with {integration:?}: {e}"),
    })
}

/// The first rise of a total-energy series by more than `tolerance` \[J\] from one sample to
/// the next, as (index of the later sample, rise \[J\]); a NaN rise counts. A passive law
/// has none beyond integration error.
pub fn first_energy_rise(total: &[f64], tolerance: f64) -> Option<(usize, f64)> {
    total
        .windows(2)
        .map(|w| w[1] - w[0])
        .enumerate()
        .find(|&(_, rise)| rise > tolerance || rise.is_nan())
        .map(|(i, rise)| (i + 1, rise))
}

/// Energy never increases (to 1e-9 of the initial energy per sample) over a release from
/// each of `releases` until `t_end`; a set-valued law comes to rest within its breakaway
/// limit.
pub fn check_energy_never_increases(
    sim: &dyn Simulator,
    model: &Model,
    releases: &[f64],
    t_end: f64,
) -> Outcome {
    for &x0 in releases {
        let m = released(sim, model, Release::adaptive(x0, t_end))?;
        let scale = m.total_energy.first().copied().unwrap_or(0.0);
        if let Some((i, rise)) = first_energy_rise(&m.total_energy, 1e-9 * scale) {
            let t = m.time.get(i).copied().unwrap_or(f64::NAN);
            return fail(
                model,
                Check::EnergyNeverIncreases,
                format!("from {x0} m: energy rises by {rise:e} J at t = {t}"),
            );
        }
        check_rest_within_limit(sim, model, x0, &m)?;
    }
    Ok(())
}

fn check_rest_within_limit(sim: &dyn Simulator, model: &Model, x0: f64, m: &Motion) -> Outcome {
    let Some(limit) = model
        .switching()
        .and_then(|law| law.static_limit(sim.normal_force()))
    else {
        return Ok(());
    };
    let Some(rest) = m.rest_displacement else {
        return fail(
            model,
            Check::RestWithinStaticLimit,
            format!("a set-valued law released from {x0} m does not come to rest"),
        );
    };
    let spring = sim.stiffness() * rest.abs();
    ensure(
        model,
        Check::RestWithinStaticLimit,
        spring <= limit + 1e-9,
        || {
            format!(
                "from {x0} m: rest at {rest} m, spring force {spring} N above the limit {limit} N"
            )
        },
    )
}

/// Whether `gap` is not below `tolerance` (NaN is not).
fn not_within(gap: f64, tolerance: f64) -> bool {
    gap >= tolerance || gap.is_nan()
}

/// The first sample at which `a` and `b` differ by `tolerance` or more (or NaN), if any.
pub fn first_mismatch(a: &[f64], b: &[f64], tolerance: f64) -> Option<usize> {
    a.iter()
        .zip(b)
        .position(|(a, b)| not_within((a - b).abs(), tolerance))
}

/// The first sample at which `b` is not the mirror image of `a` (|a + b| not below
/// `tolerance`, or NaN), if any; a mirrored pair of releases has none in x, v, F and states.
pub fn first_unmirrored(a: &[f64], b: &[f64], tolerance: f64) -> Option<usize> {
    a.iter()
        .zip(b)
        .position(|(a, b)| not_within((a + b).abs(), tolerance))
}

/// The release from -x0 mirrors the release from x0: x and v to 1e-12, the friction force to
/// 1e-9, the same number of events and the same rest (or none).
pub fn check_mirror_symmetry(sim: &dyn Simulator, model: &Model, x0: f64, t_end: f64) -> Outcome {
    let a = released(sim, model, Release::adaptive(x0, t_end))?;
    let b = released(sim, model, Release::adaptive(-x0, t_end))?;
    let unmirrored = [
        first_unmirrored(&a.x, &b.x, 1e-12),
        first_unmirrored(&a.v, &b.v, 1e-12),
        first_unmirrored(&a.friction, &b.friction, 1e-9),
    ];
    if let Some(i) = unmirrored.into_iter().flatten().min() {
        return fail(
            model,
            Check::MirrorSymmetry,
            format!(
                "at t = {}: x = {}, v = {}, F = {} but mirrored {}, {}, {}",
                a.time[i], a.x[i], a.v[i], a.friction[i], b.x[i], b.v[i], b.friction[i]
            ),
        );
    }
    let same = a.x.len() == b.x.len()
        && a.events == b.events
        && a.rest_displacement.is_some() == b.rest_displacement.is_some();
    ensure(model, Check::MirrorSymmetry, same, || {
        format!(
            "{} vs {} samples, {} vs {} events, rest {:?} vs {:?}",
            a.x.len(),
            b.x.len(),
            a.events,
            b.events,
            a.rest_displacement,
            b.rest_displacement
        )
    })
}

/// Fixed-step Euler with 1e4 and 1e5 steps per period converges to the adaptive solution at
/// first order: the larger error is below 2e-5 m and below a fifth of the smaller one's.
pub fn check_integrators_agree(sim: &dyn Simulator, model: &Model, x0: f64, t_end: f64) -> Outcome {
    let reference = released(sim, model, Release::adaptive(x0, t_end))?;
    let error = |steps_per_period: f64| -> Result<f64, super::Violation> {
        let euler = Release {
            integration: Integration::Euler { steps_per_period },
            ..Release::adaptive(x0, t_end)
        };
        let euler = released(sim, model, euler)?;
        Ok(euler
            .x
            .iter()
            .zip(&reference.x)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max))
    };
    let (e4, e5) = (error(1e4)?, error(1e5)?);
    ensure(
        model,
        Check::IntegratorsAgree,
        e5 < 2e-5 && e5 < 0.2 * e4,
        || {
            format!("max |x_euler - x_adaptive|: {e4:e} m at 1e4 steps, {e5:e} m at 1e5 steps per period")
        },
    )
}

/// The registered laws a simulation can run: those that read nothing besides the speed, the
/// normal force and their states (a law that reads the position, the acceleration or a
/// channel is fitted along measured motion, and the simulator refuses it).
pub fn simulable_names() -> Vec<String> {
    crate::names()
        .into_iter()
        .filter(|name| crate::default_model(name).is_ok_and(|m| m.conditions().is_empty()))
        .collect()
}
