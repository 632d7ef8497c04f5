//! The friction-model trait and its parameter metadata.

use crate::error::ModelError;
use serde::Serialize;

/// Metadata of one model parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParamInfo {
    /// Parameter name, as used in config files.
    pub name: String,
    /// SI unit ("1" for dimensionless coefficients).
    pub unit: String,
    /// Default value.
    pub default: f64,
    /// Physical lower bound.
    pub lower: f64,
    /// Physical upper bound.
    pub upper: f64,
    /// When true the lower bound itself is excluded (the value must be strictly greater).
    pub lower_exclusive: bool,
    /// One-line meaning.
    pub description: String,
    /// Whether the identifier keeps this parameter fixed unless the user frees it by name
    /// (e.g. the Stribeck shape exponent).
    pub fixed_by_default: bool,
}

impl ParamInfo {
    /// Metadata with an inclusive lower bound.
    pub fn new(
        name: &str,
        unit: &str,
        default: f64,
        (lower, upper): (f64, f64),
        description: &str,
    ) -> Self {
        Self {
            name: name.to_string(),
            unit: unit.to_string(),
            default,
            lower,
            upper,
            lower_exclusive: false,
            description: description.to_string(),
            fixed_by_default: false,
        }
    }

    /// Metadata for a strictly positive parameter (lower bound 0, excluded).
    pub fn positive(name: &str, unit: &str, default: f64, upper: f64, description: &str) -> Self {
        Self {
            lower_exclusive: true,
            ..Self::new(name, unit, default, (0.0, upper), description)
        }
    }

    /// The same metadata, marked as fixed unless freed by name.
    pub fn fixed(self) -> Self {
        Self {
            fixed_by_default: true,
            ..self
        }
    }

    /// Whether `value` lies inside the physical bounds.
    pub fn admits(&self, value: f64) -> bool {
        let above = if self.lower_exclusive {
            value > self.lower
        } else {
            value >= self.lower
        };
        value.is_finite() && above && value <= self.upper
    }

    /// The bounds as text, e.g. `(0, inf]` or `[0, 10]`.
    pub fn bounds_text(&self) -> String {
        format!(
            "{}{}, {}]",
            if self.lower_exclusive { "(" } else { "[" },
            fmt_bound(self.lower),
            fmt_bound(self.upper)
        )
    }
}

fn fmt_bound(x: f64) -> String {
    if x == f64::INFINITY {
        "inf".into()
    } else if x == f64::NEG_INFINITY {
        "-inf".into()
    } else {
        format!("{x}")
    }
}

/// Data-driven hints for initial parameter values, computed by the identifier from the
/// measured records (see `FrictionModel::apply_guess`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuessHint {
    /// Mean friction force divided by the normal force (from the half-cycle energy estimate).
    pub mu: f64,
    /// A typical sliding speed of the records [m/s] (e.g. the RMS velocity).
    pub typical_velocity: f64,
    /// The normal force \[N\].
    pub normal_force: f64,
    /// The oscillator stiffness [N/m]; bristle and element stiffnesses are guessed relative to it.
    pub stiffness: f64,
    /// The oscillator mass \[kg\] (for damping-like parameters such as LuGre's sigma1).
    pub mass: f64,
}

/// The rigid-contact limit of a model with a presliding stiffness (see
/// [`FrictionModel::rigid_limit`]). On records that do not resolve presliding (Coulomb-like
/// data), the cost falls towards the limit law's as the stiffness grows, so the stiffness has
/// a lower bound but no value; an optimiser that stops at a large finite stiffness, or a cost
/// curvature taken there, would otherwise call it determined.
#[derive(Debug)]
pub struct RigidLimit {
    /// The limit law at its default values (the identifier fits it; its `start_from` maps a
    /// fitted instance of the model onto it).
    pub law: Box<dyn FrictionModel>,
    /// Indices of the stiffness parameters that run to infinity (one per element).
    pub stiffnesses: Vec<usize>,
    /// Indices of the parameters that act only through presliding and vanish from the limit
    /// (Dahl's shape exponent; GMS's element weights, dampings and sharpness): when the
    /// records do not reject the limit, their cost profiles are flat and they are not
    /// identifiable.
    pub presliding: Vec<usize>,
    /// Parameters of the limit law, fixed by default, that the model's limit leaves free
    /// (GMS fits its Stribeck shape exponent: the limit's Stribeck law must fit it too, or
    /// the limit's cost would be too high and the stiffness called determined too readily).
    pub also_free: Vec<&'static str>,
}

/// A friction law: a pure function of sliding velocity, internal states and normal force.
///
/// Implementors derive `Clone`, `Serialize` and `Deserialize` (with `#[serde(default,
/// deny_unknown_fields)]` so that missing parameters take their defaults and unknown keys are
/// rejected) and register with `#[typetag::serde(name = "...")]` on the `impl` block. That is
/// all it takes for the registry, the engine, the identifier and the CLI to know the model.
///
/// Sign convention: the force opposes motion, so a positive velocity gives a positive force in
/// `m x'' + c x' + k x + F = 0`.
#[typetag::serde(tag = "type")]
pub trait FrictionModel: dyn_clone::DynClone + Send + Sync + std::fmt::Debug {
    /// The registry name (must equal the typetag name).
    fn name(&self) -> &'static str;

    /// The friction law in one line, for listings.
    fn equation(&self) -> String;

    /// Parameter metadata, in the order of `params`/`set_params`.
    fn param_info(&self) -> Vec<ParamInfo>;

    /// The current parameter values.
    fn params(&self) -> Vec<f64>;

    /// Sets all parameters at once (same order as `param_info`). The length is checked; the
    /// bounds are not (the identifier enforces them, `validate` reports them).
    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError>;

    /// Number of internal states (0 for static friction laws).
    fn n_states(&self) -> usize {
        0
    }

    /// Time derivative of the internal states at sliding velocity `v`.
    fn state_derivative(&self, _v: f64, _z: &[f64], _normal: f64, _dz: &mut [f64]) {}

    /// How large an error in each internal state is, measured as a displacement: state j
    /// changes by `scales[j]` state units per metre (n_states entries, each finite and > 0).
    /// The integrators resolve state j to `scales[j]` times their absolute tolerance, which
    /// is given in metres; the default, 1 for every state, fits states that are deflections
    /// in metres (LuGre's z, GMS's z_i). A state that is a force in newtons declares the
    /// stiffness that turns a deflection into it (Dahl: sigma0), so that the integrators hold
    /// it no tighter than a displacement state.
    fn state_tolerance_scales(&self) -> Vec<f64> {
        vec![1.0; self.n_states()]
    }

    /// The parameters (indices in [`FrictionModel::params`] order) that enter the force but not
    /// the states' equation ([`FrictionModel::state_derivative`]): a damping on the states'
    /// rate, a viscous drag. Along a given motion the states do not depend on them, so a
    /// force-domain fit keeps the states when only these change. Default: none (always
    /// correct; a declaration is checked by `testing::check_force_only_params`).
    fn force_only_params(&self) -> Vec<usize> {
        Vec::new()
    }

    /// The friction force at velocity `v` with internal states `z`. For static laws `z` is empty
    /// and sgn(0) = 0.
    fn force(&self, v: f64, z: &[f64], normal: f64) -> f64;

    /// [`state_derivative`](Self::state_derivative) into `dz` and [`force`](Self::force), in
    /// one call: what a simulation's right-hand side needs. A law whose force uses its state
    /// derivative (LuGre, GMS) computes the shared terms once; the results must equal the two
    /// calls bit for bit (checked by `testing::check_combined_rhs`).
    fn state_derivative_and_force(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) -> f64 {
        self.state_derivative(v, z, normal, dz);
        self.force(v, z, normal)
    }

    /// For static laws with a set-valued force at zero velocity: the breakaway force limit
    /// used to decide sticking (coulomb: mu N). `None` for smooth laws and dynamic models.
    fn static_limit(&self, _normal: f64) -> Option<f64> {
        None
    }

    /// The force while slipping in `direction` (+1 or -1), for the switched-system treatment
    /// of static laws. `v` may be zero or of the wrong sign by round-off at a mode boundary:
    /// the direction of the set-valued part must come from `direction`, never from sgn(v).
    fn slip_force(&self, v: f64, _direction: f64, normal: f64) -> f64 {
        self.force(v, &[], normal)
    }

    /// The Jacobian of `state_derivative` with respect to the states, d(dz_i)/d(z_j), written
    /// row-major into `jac` (n_states x n_states). The default differentiates numerically
    /// (central differences, step cbrt(eps) max(|z_j|, 1e-6)); models with a closed form should
    /// supply it (stiff integrators call this once per step).
    fn state_jacobian(&self, v: f64, z: &[f64], normal: f64, jac: &mut [f64]) {
        finite_difference_jacobian(self, v, z, normal, jac);
    }

    /// The partial derivatives of [`force`](FrictionModel::force) at (v, z): returns dF/dv and
    /// writes dF/dz_j into `dfdz` (n_states entries). With `state_jacobian` and
    /// `state_velocity_derivative` it completes the Jacobian a stiff integrator needs. The
    /// default differentiates numerically (see [`finite_difference_force_gradient`]).
    fn force_gradient(&self, v: f64, z: &[f64], normal: f64, dfdz: &mut [f64]) -> f64 {
        finite_difference_force_gradient(self, v, z, normal, dfdz)
    }

    /// The derivative of `state_derivative` with respect to the velocity, d(dz_i)/dv, into
    /// `out` (n_states entries). The default differentiates numerically, never across v = 0
    /// (see [`velocity_step`]).
    fn state_velocity_derivative(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        finite_difference_velocity_derivative(self, v, z, normal, out);
    }

    /// The three partial derivatives a stiff step needs at (v, z), in one call:
    /// [`state_jacobian`](FrictionModel::state_jacobian) into `out.dz_dz`,
    /// [`state_velocity_derivative`](FrictionModel::state_velocity_derivative) into
    /// `out.dz_dv`, [`force_gradient`](FrictionModel::force_gradient)'s dF/dz into `out.df_dz`
    /// and its dF/dv returned. A law whose derivatives share terms (LuGre's Stribeck
    /// exponential) computes them once; the results must equal the three calls bit for bit
    /// (checked by `testing::check_combined_linearisation`).
    fn linearisation(&self, v: f64, z: &[f64], normal: f64, out: Linearisation<'_>) -> f64 {
        self.state_jacobian(v, z, normal, out.dz_dz);
        self.state_velocity_derivative(v, z, normal, out.dz_dv);
        self.force_gradient(v, z, normal, out.df_dz)
    }

    /// For static laws that are affine in the velocity within a sliding mode: `(a, b)` such
    /// that `slip_force(v, direction, N) = a + b v` for every v in that mode (e.g. coulomb:
    /// (direction mu N, 0); viscous_coulomb: (direction mu N, c_v)). The engine may then solve
    /// each half-cycle in closed form. `None` (the default) when the law is not of that form.
    fn affine_slip(&self, _direction: f64, _normal: f64) -> Option<(f64, f64)> {
        None
    }

    /// Steady-state friction curve F_ss(v) (the force at constant sliding velocity).
    fn steady_state(&self, v: f64, normal: f64) -> f64;

    /// The internal states of steady sliding at velocity `v` (written into `out`, length
    /// `n_states`), where the law states them; `false` (the default) when it does not. The
    /// engine's `auto` integrator choice looks for stiffness there as well as at the initial
    /// states: a law whose states are soft when relaxed and stiff when loaded (GMS, Dahl with
    /// alpha < 1) would otherwise be given the explicit method. The harness (`testing::check_sliding_states`)
    /// requires dz/dt = 0 and the steady-state force there.
    fn sliding_states(&self, _v: f64, _normal: f64, _out: &mut [f64]) -> bool {
        false
    }

    /// Energy stored in the internal states (bristle deflection), 0 for static laws. Used by
    /// the engine's energy checks: KE + PE + stored never increases for a passive model.
    fn stored_energy(&self, _z: &[f64], _normal: f64) -> f64 {
        0.0
    }

    /// Sets data-driven initial values (levels from the energy estimate). Default: keep.
    fn apply_guess(&mut self, _hint: &GuessHint) {}

    /// Takes the start of a staged fit from a fitted simpler model (see [`crate::start`]);
    /// returns whether it did. Default: `false` (keep the values).
    fn start_from(
        &mut self,
        _fitted: &dyn FrictionModel,
        _ctx: &crate::start::StartContext,
    ) -> bool {
        false
    }

    /// The static law this model tends to as its contact stiffness grows without bound (rigid
    /// bristles), with the index of that stiffness among `params()`: LuGre tends to stribeck
    /// (its bristle damping kept near critical), Dahl to coulomb. The identifier fits the limit
    /// law to the same records and calls the stiffness determined only when the records
    /// exclude the limit (a likelihood-ratio test, [`RigidLimit`]). Default: `None`.
    fn rigid_limit(&self) -> Option<RigidLimit> {
        None
    }

    /// Checks every parameter against its physical bounds; returns warnings for values that
    /// are admissible but unusual (e.g. mu_s < mu_c).
    fn validate(&self) -> Result<Vec<String>, ModelError> {
        check_bounds(self.name(), &self.param_info(), &self.params())?;
        Ok(Vec::new())
    }
}

dyn_clone::clone_trait_object!(FrictionModel);

/// Smallest state magnitude the finite-difference step of [`finite_difference_jacobian`] scales
/// with (bristle deflections are often 1e-7..1e-5 m).
const FD_STATE_FLOOR: f64 = 1e-6;

/// The central-difference Jacobian of `model.state_derivative` with respect to the states
/// (row-major into `jac`); the default of [`FrictionModel::state_jacobian`].
pub fn finite_difference_jacobian<M: FrictionModel + ?Sized>(
    model: &M,
    v: f64,
    z: &[f64],
    normal: f64,
    jac: &mut [f64],
) {
    let n = z.len();
    let mut probe = z.to_vec();
    let mut plus = vec![0.0; n];
    let mut minus = vec![0.0; n];
    for j in 0..n {
        let step = CBRT_EPSILON * z[j].abs().max(FD_STATE_FLOOR);
        probe[j] = z[j] + step;
        model.state_derivative(v, &probe, normal, &mut plus);
        probe[j] = z[j] - step;
        model.state_derivative(v, &probe, normal, &mut minus);
        probe[j] = z[j];
        for i in 0..n {
            if let Some(entry) = jac.get_mut(i * n + j) {
                *entry = (plus[i] - minus[i]) / (2.0 * step);
            }
        }
    }
}

/// cbrt(f64::EPSILON), the relative step of central differences (a constant: `cbrt` is not
/// const-evaluated, and it was 4 % of a GMS fit's time).
pub const CBRT_EPSILON: f64 = 6.055_454_452_393_339_5e-6;

/// Smallest velocity magnitude the finite-difference step in v scales with [m/s].
const FD_VELOCITY_FLOOR: f64 = 1e-6;

/// A finite-difference step in the velocity that never crosses v = 0 (where |v| and sgn(v)
/// kink): `(width, upper, lower)` with width = upper - lower. Central around v where the step
/// fits on v's side of zero, one-sided away from zero otherwise (towards +v at v = 0).
pub fn velocity_step(v: f64) -> (f64, f64, f64) {
    let step = CBRT_EPSILON * v.abs().max(FD_VELOCITY_FLOOR);
    if step < v.abs() {
        (2.0 * step, v + step, v - step)
    } else if v < 0.0 {
        (step, v, v - step)
    } else {
        (step, v + step, v)
    }
}

/// The finite-difference d(dz_i)/dv of `model.state_derivative` (the default of
/// [`FrictionModel::state_velocity_derivative`], step of [`velocity_step`]).
pub fn finite_difference_velocity_derivative<M: FrictionModel + ?Sized>(
    model: &M,
    v: f64,
    z: &[f64],
    normal: f64,
    out: &mut [f64],
) {
    let (step, v_plus, v_minus) = velocity_step(v);
    let mut plus = vec![0.0; out.len()];
    model.state_derivative(v_plus, z, normal, &mut plus);
    model.state_derivative(v_minus, z, normal, out);
    for (o, p) in out.iter_mut().zip(&plus) {
        *o = (p - *o) / step;
    }
}

/// The finite-difference gradient of `model.force` (the default of
/// [`FrictionModel::force_gradient`]): returns dF/dv (step of [`velocity_step`]), writes the
/// central-difference dF/dz_j into `dfdz` (step as in [`finite_difference_jacobian`]).
pub fn finite_difference_force_gradient<M: FrictionModel + ?Sized>(
    model: &M,
    v: f64,
    z: &[f64],
    normal: f64,
    dfdz: &mut [f64],
) -> f64 {
    let mut probe = z.to_vec();
    for (j, d) in dfdz.iter_mut().enumerate().take(z.len()) {
        let step = CBRT_EPSILON * z[j].abs().max(FD_STATE_FLOOR);
        probe[j] = z[j] + step;
        let plus = model.force(v, &probe, normal);
        probe[j] = z[j] - step;
        let minus = model.force(v, &probe, normal);
        probe[j] = z[j];
        *d = (plus - minus) / (2.0 * step);
    }
    let (width, v_plus, v_minus) = velocity_step(v);
    (model.force(v_plus, z, normal) - model.force(v_minus, z, normal)) / width
}

/// Checks `values` against the bounds in `info`; the error names the model and parameter.
pub fn check_bounds(model: &str, info: &[ParamInfo], values: &[f64]) -> Result<(), ModelError> {
    for (p, &v) in info.iter().zip(values) {
        if !p.admits(v) {
            return Err(ModelError::OutOfBounds {
                model: model.to_string(),
                param: p.name.clone(),
                value: v,
                bounds: p.bounds_text(),
            });
        }
    }
    Ok(())
}

/// Checks the length of a parameter vector passed to `set_params`.
pub fn check_len(model: &str, expected: usize, got: usize) -> Result<(), ModelError> {
    if expected == got {
        Ok(())
    } else {
        Err(ModelError::ParamCount {
            model: model.to_string(),
            expected,
            got,
        })
    }
}

/// Where [`FrictionModel::linearisation`] writes (n_states x n_states row-major, then
/// n_states and n_states entries).
pub struct Linearisation<'a> {
    /// d(dz_i)/dz_j, row-major.
    pub dz_dz: &'a mut [f64],
    /// d(dz_i)/dv.
    pub dz_dv: &'a mut [f64],
    /// dF/dz_j.
    pub df_dz: &'a mut [f64],
}

/// exp(-x) for x >= 0, without calling `exp` where the result is 0 anyway (x > 745.2: below
/// half the smallest subnormal). The Stribeck decays exp(-|v/v_s|^delta) underflow there at
/// most sliding speeds, and libm's underflow path costs several times a plain `exp`.
#[inline]
pub fn decay(x: f64) -> f64 {
    if x > 745.2 {
        0.0
    } else {
        (-x).exp()
    }
}

/// Sign with sgn(0) = 0 (and sgn(NaN) = 0).
pub fn sgn(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// A boxed copy of a model behind a reference.
pub fn clone_model(model: &(dyn FrictionModel + 'static)) -> Box<dyn FrictionModel> {
    dyn_clone::clone_box(model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[test]
    fn the_difference_step_constant_is_the_cube_root_of_epsilon() {
        assert_eq!(CBRT_EPSILON, f64::EPSILON.cbrt());
    }

    /// z0' = v - 3 z0^2 + z1, z1' = N z0 z1 (Jacobian [[-6 z0, 1], [N z1, N z0]]).
    #[derive(Debug, Clone, Default, Serialize, Deserialize)]
    struct Quadratic;

    #[typetag::serde(name = "model_rs_quadratic_test_law")]
    impl FrictionModel for Quadratic {
        crate::declared_param_methods!(
            name: "model_rs_quadratic_test_law",
            equation: "",
            no_params
        );
        fn n_states(&self) -> usize {
            2
        }
        fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) {
            dz[0] = v - 3.0 * z[0] * z[0] + z[1];
            dz[1] = normal * z[0] * z[1];
        }
        fn force(&self, _v: f64, z: &[f64], _normal: f64) -> f64 {
            z[0]
        }
        fn steady_state(&self, _v: f64, _normal: f64) -> f64 {
            0.0
        }
    }

    #[test]
    fn default_state_jacobian_matches_the_hand_derivative() {
        let normal = 14.5;
        for z in [[0.3, -1.2], [2e-7, 5e-7], [0.0, 0.0], [-40.0, 3.0]] {
            let mut jac = [0.0; 4];
            Quadratic.state_jacobian(0.1, &z, normal, &mut jac);
            let hand = [-6.0 * z[0], 1.0, normal * z[1], normal * z[0]];
            // Central differences are exact on a quadratic up to round-off, about
            // eps |f| / step <= 2e-16 * 0.1 / 6e-12 ~ 4e-6 at the smallest steps.
            for (got, want) in jac.iter().zip(hand) {
                assert!(
                    (got - want).abs() <= 1e-5 * (1.0 + want.abs()),
                    "z = {z:?}: {jac:?} vs {hand:?}"
                );
            }
        }
    }

    #[test]
    fn laws_are_not_declared_affine_by_default() {
        assert_eq!(Quadratic.affine_slip(1.0, 14.5), None);
        assert_eq!(Quadratic.affine_slip(-1.0, 14.5), None);
    }
}
