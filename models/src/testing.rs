//! The test harness every friction model runs: the invariants that hold for any model,
//! checked on a model instance (diffsol runs one harness over every solver; this is the same
//! idea over every model). The built-in models' tests and the plugin example's tests call it;
//! a new model's tests should too:
//!
//! ```
//! use frictionid_models::{testing, Coulomb};
//! testing::assert_model(&Coulomb::default());
//! ```
//!
//! [`check_model`] runs every check of [`Check`] and returns the first [`Violation`];
//! [`assert_model`] panics with it (for tests). The checks probe the model at velocities from
//! 0 and 1e-300 to 7.5 m/s, at internal states from 0 to large deflections and at normal
//! forces 0, 1 and 14.5 N; they are oracles in their own right (symmetry, finiteness, round
//! trips), not snapshots of the model's output. Hand-computed forces and model-specific
//! physics stay in the model's own tests.
//!
//! The invariants that need a simulation (energy never increases, mirror symmetry of a
//! release, convergence of two integrators) are in [`motion`], over a [`motion::Simulator`]
//! that the caller implements with the engine: this crate knows no solver.

pub mod motion;
pub mod reference;
mod steps;

pub use steps::{check_exact_steps, check_param_gradients, check_step};

use crate::error::ModelError;
use crate::linearisation::Linearisation;
use crate::model::{Derivatives, FrictionModel, SwitchedLaw};
use crate::registry::{build_json, build_toml, default_model, names};
use crate::ParamInfo;
use thiserror::Error;

/// Velocities [m/s] at which the laws are probed (both signs are used).
pub const VELOCITIES: [f64; 17] = [
    0.0, 1e-300, 1e-18, 1e-15, 1e-12, 1e-9, 1e-6, 1e-4, 0.001, 0.003, 0.01, 0.05, 0.2, 0.4, 1.0,
    3.0, 7.5,
];
/// Normal forces \[N\] at which the laws are probed (the FMM stage's is 14.5 N).
pub const NORMAL_FORCES: [f64; 3] = [0.0, 1.0, 14.5];
/// Internal-state scales (deflections in m, or forces in N for Dahl) at which dynamic laws
/// are probed.
pub const STATE_SCALES: [f64; 6] = [0.0, 1e-6, -3e-5, 1e-4, -1e-3, 2.0];

/// The invariants of [`check_model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Check {
    /// The model's name is registered, and its default instance builds by name.
    Registered,
    /// `param_info` and `params` agree in length, names are unique, the default instance's
    /// values are its declared defaults and lie inside the bounds; the state tolerance scales
    /// are one per state, finite and > 0.
    Declarations,
    /// `set_params` then `params` gives the values back; a wrong length is a `ParamCount` error.
    ParamVector,
    /// `check` (the declared bounds, then the law's `validate`) accepts the model and rejects
    /// each value outside its bounds by name.
    Bounds,
    /// JSON and TOML round trips (also through `build_toml`) keep every parameter; an unknown
    /// key is rejected by name.
    Serde,
    /// Forces, steady states, slip forces, state derivatives and stored energies are finite.
    Finite,
    /// F(-v, -z) = -F(v, z), dz(-v, -z) = -dz(v, z), F_ss(-v) = -F_ss(v) and
    /// slip(-v, -d) = -slip(v, d), exactly.
    OddSymmetry,
    /// A static law opposes the motion: F(v) v >= 0.
    Dissipative,
    /// A set-valued law slips at the breakaway force in the slip direction, whatever the sign
    /// of a round-off velocity.
    SlipDirection,
    /// Stored energy is >= 0 and 0 in the undeflected state.
    StoredEnergy,
    /// A parameter declared force-only leaves the state derivative unchanged, exactly.
    ForceOnlyParams,
    /// `state_derivative_and_force` equals `state_derivative` and `force`, bit for bit.
    CombinedRhs,
    /// `linearisation` equals `state_jacobian`, `state_velocity_derivative` and
    /// `force_gradient`, bit for bit.
    CombinedLinearisation,
    /// Stated sliding states are a fixed point of the states with the steady-state force.
    SlidingStates,
    /// An exact step ([`crate::Propagator`]) equals a tight reference integration of
    /// `state_derivative` at constant velocity, and its sensitivities central differences.
    ExactSteps,
    /// The force's parameter gradient ([`crate::ParamGradients`]) equals central differences.
    ParamGradients,
    /// (motion) The simulator completes every release.
    Simulates,
    /// (motion) KE + PE + stored never increases.
    EnergyNeverIncreases,
    /// (motion) A set-valued law comes to rest with |k x| within its breakaway limit.
    RestWithinStaticLimit,
    /// (motion) The release from -x0 mirrors the release from x0.
    MirrorSymmetry,
    /// (motion) Fixed-step Euler converges to the adaptive solution at first order.
    IntegratorsAgree,
}

/// A failed invariant: which one and where.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("model `{model}` fails {check:?}: {message}")]
pub struct Violation {
    /// The model's registry name.
    pub model: String,
    /// The invariant.
    pub check: Check,
    /// What was found, with the inputs.
    pub message: String,
}

type Outcome = Result<(), Violation>;

/// A model under test (owned data: any built or boxed model).
pub type Model = dyn FrictionModel + 'static;

fn fail(model: &Model, check: Check, message: String) -> Outcome {
    Err(Violation {
        model: model.name().to_string(),
        check,
        message,
    })
}

fn ensure(model: &Model, check: Check, ok: bool, message: impl FnOnce() -> String) -> Outcome {
    if ok {
        Ok(())
    } else {
        fail(model, check, message())
    }
}

/// Runs every check on `model` (an admissible instance: `check` must accept it).
pub fn check_model(model: &Model) -> Outcome {
    check_registered(model)?;
    check_declarations(model)?;
    check_param_vector(model)?;
    check_bounds(model)?;
    check_serde(model)?;
    check_finite(model)?;
    check_odd_symmetry(model)?;
    check_dissipative(model)?;
    check_slip_direction(model)?;
    check_stored_energy(model)?;
    check_force_only_params(model)?;
    check_combined_rhs(model)?;
    check_combined_linearisation(model)?;
    check_sliding_states(model)?;
    check_param_gradients(model)?;
    check_exact_steps(model)
}

/// [`check_model`] for tests: panics with the violation.
pub fn assert_model(model: &Model) {
    if let Err(v) = check_model(model) {
        panic!("{v}");
    }
}

/// [`Check::Registered`].
pub fn check_registered(model: &Model) -> Outcome {
    let name = model.name();
    ensure(
        model,
        Check::Registered,
        names().iter().any(|n| n == name),
        || format!("`{name}` is not among the registered names {:?}", names()),
    )?;
    match default_model(name) {
        Ok(d) => ensure(model, Check::Registered, d.name() == name, || {
            format!("the default instance is named `{}`", d.name())
        }),
        Err(e) => fail(
            model,
            Check::Registered,
            format!("the default instance: {e}"),
        ),
    }
}

/// [`Check::Declarations`], on the model and on its registered default instance.
pub fn check_declarations(model: &Model) -> Outcome {
    let info = model.param_info();
    let values = model.params();
    ensure(
        model,
        Check::Declarations,
        info.len() == values.len(),
        || format!("{} declarations but {} values", info.len(), values.len()),
    )?;
    for (i, p) in info.iter().enumerate() {
        ensure(
            model,
            Check::Declarations,
            info[..i].iter().all(|q| q.name != p.name),
            || format!("the name `{}` is declared twice", p.name),
        )?;
    }
    check_state_tolerance_scales(model)?;
    let Ok(default) = default_model(model.name()) else {
        return fail(model, Check::Declarations, "no default instance".into());
    };
    for (p, v) in default.param_info().iter().zip(default.params()) {
        ensure(
            model,
            Check::Declarations,
            p.default == v && p.admits(v),
            || {
                format!(
                    "`{}`: the default instance has {v}, the declared default is {} in {}",
                    p.name,
                    p.default,
                    p.bounds_text()
                )
            },
        )?;
    }
    Ok(())
}

/// Part of [`Check::Declarations`]: one tolerance scale per state, each finite and > 0.
fn check_state_tolerance_scales(model: &Model) -> Outcome {
    let scales = model
        .states()
        .map_or_else(Vec::new, |s| s.state_tolerance_scales());
    ensure(
        model,
        Check::Declarations,
        scales.len() == model.n_states() && scales.iter().all(|s| s.is_finite() && *s > 0.0),
        || {
            format!(
                "state tolerance scales {scales:?} for {} states (each must be finite and > 0)",
                model.n_states()
            )
        },
    )
}

/// A value near `x` other than `x`, inside the bounds of `p` where possible.
fn perturbed(p: &ParamInfo, x: f64) -> f64 {
    [x * 1.1 + 0.001, x * 0.9, 0.5 * (x + p.lower)]
        .into_iter()
        .find(|&y| y != x && p.admits(y))
        .unwrap_or(x)
}

fn perturbed_params(model: &Model) -> Vec<f64> {
    model
        .param_info()
        .iter()
        .zip(model.params())
        .map(|(p, x)| perturbed(p, x))
        .collect()
}

/// [`Check::ParamVector`].
pub fn check_param_vector(model: &Model) -> Outcome {
    let mut m = crate::clone_model(model);
    let values = perturbed_params(model);
    if let Err(e) = m.set_params(&values) {
        return fail(
            model,
            Check::ParamVector,
            format!("set_params({values:?}): {e}"),
        );
    }
    let back = m.params();
    ensure(model, Check::ParamVector, back == values, || {
        format!("set_params({values:?}) then params() gives {back:?}")
    })?;
    let long = vec![1.0; values.len() + 1];
    let expected = ModelError::ParamCount {
        model: model.name().to_string(),
        expected: values.len(),
        got: long.len(),
    };
    let got = m.set_params(&long);
    ensure(
        model,
        Check::ParamVector,
        got.as_ref().err() == Some(&expected),
        || format!("set_params with {} values gives {got:?}", long.len()),
    )?;
    ensure(model, Check::ParamVector, m.params() == values, || {
        "a rejected set_params changed the values".into()
    })
}

/// Values just outside the bounds of `p` (none for an unbounded side), and NaN.
fn outside(p: &ParamInfo) -> Vec<f64> {
    let mut out = vec![f64::NAN];
    if p.lower.is_finite() {
        out.push(if p.lower_exclusive {
            p.lower
        } else {
            p.lower - 1.0 - p.lower.abs()
        });
    }
    if p.upper.is_finite() {
        out.push(p.upper + 1.0 + p.upper.abs());
    }
    out
}

/// [`Check::Bounds`].
pub fn check_bounds(model: &Model) -> Outcome {
    if let Err(e) = model.check() {
        return fail(
            model,
            Check::Bounds,
            format!("the model under test is rejected: {e}"),
        );
    }
    let values = model.params();
    for (i, p) in model.param_info().iter().enumerate() {
        for bad in outside(p) {
            let mut m = crate::clone_model(model);
            let mut v = values.clone();
            v[i] = bad;
            if m.set_params(&v).is_err() {
                return fail(model, Check::Bounds, format!("set_params rejects {v:?}"));
            }
            let r = m.check();
            let named =
                matches!(&r, Err(ModelError::OutOfBounds { param, .. }) if *param == p.name);
            ensure(model, Check::Bounds, named, || {
                format!(
                    "`{}` = {bad} outside {}: check gives {r:?}",
                    p.name,
                    p.bounds_text()
                )
            })?;
        }
    }
    Ok(())
}

fn same_model(model: &Model, back: &Model, how: &str) -> Outcome {
    let same = back.name() == model.name()
        && back.params() == model.params()
        && back.param_info() == model.param_info()
        && back.equation() == model.equation()
        && back.n_states() == model.n_states();
    ensure(model, Check::Serde, same, || {
        format!(
            "{how}: got `{}` with {:?}, expected {:?}",
            back.name(),
            back.params(),
            model.params()
        )
    })
}

/// [`Check::Serde`], with perturbed parameters so that defaults cannot hide a lost field.
pub fn check_serde(model: &Model) -> Outcome {
    let mut m = crate::clone_model(model);
    if let Err(e) = m.set_params(&perturbed_params(model)) {
        return fail(model, Check::Serde, e.to_string());
    }
    let (json, back) = match json_round_trip(m.as_ref()) {
        Ok(pair) => pair,
        Err(e) => return fail(model, Check::Serde, e),
    };
    same_model(m.as_ref(), back.as_ref(), &format!("JSON {json}"))?;
    let (text, back) = match toml_round_trip(m.as_ref()) {
        Ok(pair) => pair,
        Err(e) => return fail(model, Check::Serde, e),
    };
    same_model(m.as_ref(), back.as_ref(), &format!("TOML {text}"))?;
    check_unknown_key(model)
}

type RoundTrip = Result<(String, Box<dyn FrictionModel>), String>;

fn json_round_trip(model: &Model) -> RoundTrip {
    let json = serde_json::to_string(model).map_err(|e| format!("to JSON: {e}"))?;
    let back = serde_json::from_str::<Box<dyn FrictionModel>>(&json)
        .map_err(|e| format!("from JSON {json}: {e}"))?;
    Ok((json, back))
}

/// Through TOML text and the registry's `build_toml` (which also validates).
fn toml_round_trip(model: &Model) -> RoundTrip {
    let text = toml::to_string(model).map_err(|e| format!("to TOML: {e}"))?;
    let table = toml::from_str::<toml::Value>(&text).map_err(|e| format!("TOML {text}: {e}"))?;
    let built = build_toml(&table).map_err(|e| format!("build_toml of {text}: {e}"))?;
    let direct = toml::from_str::<Box<dyn FrictionModel>>(&text)
        .map_err(|e| format!("from TOML {text}: {e}"))?;
    if direct.params() != built.model.params() {
        return Err(format!(
            "from TOML {text}: {:?}, through build_toml: {:?}",
            direct.params(),
            built.model.params()
        ));
    }
    Ok((text, built.model))
}

fn check_unknown_key(model: &Model) -> Outcome {
    const KEY: &str = "no_such_parameter_";
    let r = build_json(&serde_json::json!({ "type": model.name(), KEY: 1.0 }));
    let named = matches!(&r, Err(ModelError::UnknownParameter { key, .. }) if key == KEY);
    ensure(model, Check::Serde, named, || {
        format!("an unknown key gives {:?}", r.map(|b| b.model.params()))
    })
}

/// The state vectors at which a model with `n` states is probed: every scale for all states
/// alike, and a pattern of mixed signs and sizes.
fn states(n: usize) -> Vec<Vec<f64>> {
    if n == 0 {
        return vec![Vec::new()];
    }
    let pattern = [1.0, -0.5, 2.0, 0.1, -3.0];
    STATE_SCALES
        .iter()
        .flat_map(|&s| {
            let mixed = (0..n).map(|i| s * pattern[i % pattern.len()]).collect();
            [vec![s; n], mixed]
        })
        .collect()
}

/// Calls `probe(v, z, normal)` at every probe point (both signs of v) until one fails.
fn for_each_probe(model: &Model, mut probe: impl FnMut(f64, &[f64], f64) -> Outcome) -> Outcome {
    for normal in NORMAL_FORCES {
        for z in states(model.n_states()) {
            for v in VELOCITIES {
                probe(v, &z, normal)?;
                probe(-v, &z, normal)?;
            }
        }
    }
    Ok(())
}

fn derivative(model: &Model, v: f64, z: &[f64], normal: f64) -> Vec<f64> {
    let mut dz = vec![0.0; model.n_states()];
    if let Some(states) = model.states() {
        states.state_derivative(v, z, normal, &mut dz);
    }
    dz
}

/// The stored energy at `z` (0 for a law without states).
fn stored_energy(model: &Model, z: &[f64], normal: f64) -> f64 {
    model.states().map_or(0.0, |s| s.stored_energy(z, normal))
}

/// The switched-law facts with the breakaway force at `normal`, for a set-valued law.
fn set_valued(model: &Model, normal: f64) -> Option<(&dyn SwitchedLaw, f64)> {
    let law = model.switching()?;
    Some((law, law.static_limit(normal)?))
}

/// [`Check::ForceOnlyParams`]: each declared index exists, and moving that parameter alone
/// (to a nearby admissible value) changes no state derivative at any probe point.
pub fn check_force_only_params(model: &Model) -> Outcome {
    let declared = model
        .states()
        .map_or_else(Vec::new, |s| s.force_only_params());
    check_state_free(model, &declared)
}

/// Whether moving each parameter of `indices` alone leaves the state derivative unchanged.
fn check_state_free(model: &Model, indices: &[usize]) -> Outcome {
    let info = model.param_info();
    let values = model.params();
    for &j in indices {
        let Some(p) = info.get(j) else {
            return fail(
                model,
                Check::ForceOnlyParams,
                format!(
                    "index {j} declared force-only, but the model has {} parameters",
                    info.len()
                ),
            );
        };
        let mut moved = crate::clone_model(model);
        let mut changed = values.clone();
        changed[j] = perturbed(p, values[j]);
        if let Err(e) = moved.set_params(&changed) {
            return fail(model, Check::ForceOnlyParams, e.to_string());
        }
        for_each_probe(model, |v, z, normal| {
            let (before, after) = (
                derivative(model, v, z, normal),
                derivative(moved.as_ref(), v, z, normal),
            );
            let same = before
                .iter()
                .zip(&after)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            ensure(model, Check::ForceOnlyParams, same, || {
                format!(
                    "`{}` is declared force-only but moves dz at v = {v}, z = {z:?}, N = {normal}: {before:?} -> {after:?}",
                    p.name
                )
            })
        })?;
    }
    Ok(())
}

/// [`Check::CombinedRhs`]: at every probe point the one-call state derivative and force are
/// those of the two separate calls, to the bit.
pub fn check_combined_rhs(model: &Model) -> Outcome {
    for_each_probe(model, |v, z, normal| {
        let separate = (derivative(model, v, z, normal), model.force(v, z, normal));
        let mut dz = vec![0.0; model.n_states()];
        let force = match model.states() {
            Some(states) => states.state_derivative_and_force(v, z, normal, &mut dz),
            None => model.force(v, z, normal),
        };
        let bits = |x: &f64| x.to_bits();
        let same = force.to_bits() == separate.1.to_bits()
            && dz.iter().map(bits).eq(separate.0.iter().map(bits));
        ensure(model, Check::CombinedRhs, same, || {
            format!(
                "at v = {v}, z = {z:?}, N = {normal}: one call gives dz {dz:?}, F {force}; separate {:?}, {}",
                separate.0, separate.1
            )
        })
    })
}

/// [`Check::CombinedLinearisation`]: at every probe point the one-call derivatives equal the
/// three separate calls, bit for bit (a stiff step's Jacobian, and so every trajectory, must
/// not depend on which the engine calls).
pub fn check_combined_linearisation(model: &Model) -> Outcome {
    let Some(states) = model.states() else {
        return Ok(());
    };
    let n = states.n_states();
    let derivatives = Derivatives::of(states);
    for_each_probe(model, |v, z, normal| {
        let (mut dz_dz, mut dz_dv, mut df_dz) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
        derivatives.state_jacobian(v, z, normal, &mut dz_dz);
        derivatives.state_velocity_derivative(v, z, normal, &mut dz_dv);
        let df_dv = derivatives.force_gradient(v, z, normal, &mut df_dz);
        let separate = [dz_dz, dz_dv, df_dz, vec![df_dv]];
        let (mut dz_dz, mut dz_dv, mut df_dz) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
        let out = Linearisation {
            dz_dz: &mut dz_dz,
            dz_dv: &mut dz_dv,
            df_dz: &mut df_dz,
        };
        let df_dv = derivatives.linearisation(v, z, normal, out);
        let combined = [dz_dz, dz_dv, df_dz, vec![df_dv]];
        let bits = |parts: &[Vec<f64>; 4]| -> Vec<u64> {
            parts.iter().flatten().map(|x| x.to_bits()).collect()
        };
        ensure(
            model,
            Check::CombinedLinearisation,
            bits(&combined) == bits(&separate),
            || {
                format!(
                "at v = {v}, z = {z:?}, N = {normal}: one call gives [dz/dz, dz/dv, dF/dz, dF/dv] {combined:?}; separate {separate:?}"
            )
            },
        )
    })
}

/// [`Check::SlidingStates`]: where the law states its steady sliding states, at sliding
/// speeds of both signs dz/dt vanishes (to 1e-9 of |v| per state) and the force is the
/// steady-state force (to 1e-9 relative).
pub fn check_sliding_states(model: &Model) -> Outcome {
    let Some(states) = model.states() else {
        return Ok(());
    };
    let normal = 10.0;
    for v in [1e-3, 0.05, 0.3, 2.0].into_iter().flat_map(|v| [v, -v]) {
        let mut z = vec![0.0; states.n_states()];
        if !states.sliding_states(v, normal, &mut z) {
            return Ok(());
        }
        let dz = derivative(model, v, &z, normal);
        let (force, steady) = (model.force(v, &z, normal), model.steady_state(v, normal));
        let settled = dz.iter().all(|d| d.abs() <= 1e-9 * v.abs());
        let on_curve = (force - steady).abs() <= 1e-9 * steady.abs().max(1e-12);
        ensure(model, Check::SlidingStates, settled && on_curve, || {
            format!(
                "at v = {v}, N = {normal}, sliding states {z:?}: dz/dt {dz:?}, force {force} against the steady-state {steady}"
            )
        })?;
    }
    Ok(())
}

/// [`Check::Finite`].
pub fn check_finite(model: &Model) -> Outcome {
    for_each_probe(model, |v, z, normal| {
        let at = || format!("v = {v:e}, z = {z:?}, N = {normal}");
        let f = model.force(v, z, normal);
        ensure(model, Check::Finite, f.is_finite(), || {
            format!("force {f} at {}", at())
        })?;
        let s = model.steady_state(v, normal);
        ensure(model, Check::Finite, s.is_finite(), || {
            format!("steady state {s} at {}", at())
        })?;
        let dz = derivative(model, v, z, normal);
        ensure(
            model,
            Check::Finite,
            dz.iter().all(|d| d.is_finite()),
            || format!("dz/dt {dz:?} at {}", at()),
        )?;
        let e = stored_energy(model, z, normal);
        ensure(model, Check::Finite, e.is_finite(), || {
            format!("stored energy {e} at {}", at())
        })?;
        if let Some((law, limit)) = set_valued(model, normal) {
            ensure(
                model,
                Check::Finite,
                limit.is_finite() && limit >= 0.0,
                || format!("static limit {limit} at N = {normal}"),
            )?;
            for d in [1.0, -1.0] {
                let f = law.slip_force(v, d, normal);
                ensure(model, Check::Finite, f.is_finite(), || {
                    format!("slip force {f} in direction {d} at {}", at())
                })?;
            }
        }
        Ok(())
    })
}

/// [`Check::OddSymmetry`].
pub fn check_odd_symmetry(model: &Model) -> Outcome {
    for_each_probe(model, |v, z, normal| {
        let zn: Vec<f64> = z.iter().map(|x| -x).collect();
        let at = || format!("v = {v:e}, z = {z:?}, N = {normal}");
        let (f, fn_) = (model.force(v, z, normal), model.force(-v, &zn, normal));
        ensure(model, Check::OddSymmetry, fn_ == -f, || {
            format!("F = {f} but F(-v, -z) = {fn_} at {}", at())
        })?;
        let (d, dn) = (
            derivative(model, v, z, normal),
            derivative(model, -v, &zn, normal),
        );
        let odd = d.iter().zip(&dn).all(|(a, b)| *b == -a);
        ensure(model, Check::OddSymmetry, odd, || {
            format!("dz/dt = {d:?} but at (-v, -z) {dn:?} at {}", at())
        })?;
        let (s, sn) = (
            model.steady_state(v, normal),
            model.steady_state(-v, normal),
        );
        ensure(model, Check::OddSymmetry, sn == -s, || {
            format!("F_ss = {s} but F_ss(-v) = {sn} at {}", at())
        })?;
        if let Some((law, _)) = set_valued(model, normal) {
            let (p, pn) = (
                law.slip_force(v, 1.0, normal),
                law.slip_force(-v, -1.0, normal),
            );
            ensure(model, Check::OddSymmetry, pn == -p, || {
                format!("slip(v, +1) = {p} but slip(-v, -1) = {pn} at {}", at())
            })?;
        }
        Ok(())
    })
}

/// [`Check::Dissipative`] (static laws only).
pub fn check_dissipative(model: &Model) -> Outcome {
    if model.n_states() > 0 {
        return Ok(());
    }
    for_each_probe(model, |v, _, normal| {
        let f = model.force(v, &[], normal);
        ensure(model, Check::Dissipative, f * v >= 0.0, || {
            format!("F = {f} at v = {v:e}, N = {normal}")
        })
    })
}

/// [`Check::SlipDirection`] (set-valued laws only).
pub fn check_slip_direction(model: &Model) -> Outcome {
    for normal in NORMAL_FORCES {
        let Some((law, limit)) = set_valued(model, normal) else {
            continue;
        };
        for d in [1.0, -1.0] {
            let f0 = law.slip_force(0.0, d, normal);
            let offset = law.static_offset(normal);
            ensure(
                model,
                Check::SlipDirection,
                (f0 - offset - d * limit).abs() <= 1e-12 * (1.0 + limit + offset.abs()),
                || {
                    format!("slip force {f0} at v = 0 in direction {d}, breakaway {limit}, N = {normal}")
                },
            )?;
            let wrong = law.slip_force(-d * 1e-15, d, normal);
            ensure(
                model,
                Check::SlipDirection,
                limit == 0.0 || wrong * d > 0.0,
                || {
                    format!(
                        "slip force {wrong} in direction {d} at v = {:e}",
                        -d * 1e-15
                    )
                },
            )?;
        }
    }
    Ok(())
}

/// [`Check::StoredEnergy`].
pub fn check_stored_energy(model: &Model) -> Outcome {
    let rest = vec![0.0; model.n_states()];
    for normal in NORMAL_FORCES {
        let e0 = stored_energy(model, &rest, normal);
        ensure(model, Check::StoredEnergy, e0 == 0.0, || {
            format!("{e0} in the undeflected state at N = {normal}")
        })?;
        for z in states(model.n_states()) {
            let e = stored_energy(model, &z, normal);
            ensure(model, Check::StoredEnergy, e >= 0.0, || {
                format!("{e} at z = {z:?}, N = {normal}")
            })?;
        }
    }
    Ok(())
}

/// Whether the parameter table in a model's documentation (`//! ` lines of its source) is
/// the one rendered from its declarations by [`crate::params::markdown_table`]; `Some` gives
/// the expected table when it is not.
pub fn doc_table_mismatch(source: &str, info: &[ParamInfo]) -> Option<String> {
    let doc: String = source
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("//!"))
        .map(|l| format!("{}\n", l.strip_prefix(' ').unwrap_or(l)))
        .collect();
    let table = crate::params::markdown_table(info);
    (!doc.contains(&table)).then_some(table)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::LuGre;
    use crate::model::{InternalStates, Jacobians};
    use serde::{Deserialize, Serialize};

    /// LuGre with a one-call right-hand side that forgets the bristle damping.
    #[derive(Debug, Clone, Default, Serialize, Deserialize)]
    struct ForgetfulLuGre(LuGre);

    #[typetag::serde(name = "testing_rs_forgetful_lugre")]
    impl FrictionModel for ForgetfulLuGre {
        crate::declared_param_methods!(
            name: "testing_rs_forgetful_lugre",
            equation: "",
            no_params
        );
        fn force(&self, v: f64, z: &[f64], normal: f64) -> f64 {
            self.0.force(v, z, normal)
        }
        fn steady_state(&self, v: f64, normal: f64) -> f64 {
            self.0.steady_state(v, normal)
        }
        crate::law_groups!(states);
    }

    impl InternalStates for ForgetfulLuGre {
        fn n_states(&self) -> usize {
            self.0.n_states()
        }
        fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) {
            self.0.state_derivative(v, z, normal, dz);
        }
        fn state_derivative_and_force(
            &self,
            v: f64,
            z: &[f64],
            normal: f64,
            dz: &mut [f64],
        ) -> f64 {
            self.0.state_derivative(v, z, normal, dz);
            self.0.sigma0 * z[0] + self.0.sigma2 * v
        }
        crate::law_groups!(jacobians);
    }

    /// The three derivatives by finite differences, the one call LuGre's without sigma1.
    impl Jacobians for ForgetfulLuGre {
        fn linearisation(&self, v: f64, z: &[f64], normal: f64, out: Linearisation<'_>) -> f64 {
            self.0.linearisation(v, z, normal, out);
            self.0.sigma2
        }
    }

    #[test]
    fn a_one_call_rhs_that_differs_from_the_two_calls_is_caught() {
        assert_eq!(check_combined_rhs(&LuGre::default()), Ok(()));
        let e = check_combined_rhs(&ForgetfulLuGre::default()).unwrap_err();
        assert_eq!(e.check, Check::CombinedRhs);
        assert!(e.message.contains("one call gives"), "{e}");
    }

    /// LuGre's one-call derivatives share the Stribeck exponential and give the three calls'
    /// bits; a one-call dF/dv that forgets the bristle damping is caught.
    #[test]
    fn one_call_derivatives_that_differ_from_the_three_calls_are_caught() {
        for sigma0 in [1e5, 1e7, 1e9] {
            let lugre = LuGre {
                sigma0,
                ..LuGre::default()
            };
            assert_eq!(check_combined_linearisation(&lugre), Ok(()));
        }
        let e = check_combined_linearisation(&ForgetfulLuGre::default()).unwrap_err();
        assert_eq!(e.check, Check::CombinedLinearisation);
        assert!(e.message.contains("one call gives"), "{e}");
    }

    /// LuGre's rate dz/dt = v - sigma0 |v| z / g(v) holds sigma0 and not sigma1: the check
    /// passes the true declaration and names sigma0 when it is declared force-only.
    #[test]
    fn a_state_parameter_declared_force_only_is_named() {
        let lugre = LuGre::default();
        assert_eq!(check_state_free(&lugre, &[1, 2]), Ok(()));
        let e = check_state_free(&lugre, &[0]).unwrap_err();
        assert_eq!(e.check, Check::ForceOnlyParams);
        assert!(e.message.contains("`sigma0` is declared force-only"), "{e}");
        let e = check_state_free(&lugre, &[6]).unwrap_err();
        assert!(e.message.contains("index 6"), "{e}");
    }
}
