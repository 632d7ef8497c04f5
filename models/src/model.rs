//! The friction-model trait: the law itself ([`FrictionModel`]) and the optional groups a
//! law may add, each a small trait with defaults behind an accessor of the core:
//!
//! | group | accessor | what it buys |
//! |---|---|---|
//! | [`InternalStates`] | [`FrictionModel::states`] | states integrated with the motion (bristles, elements) and their facts |
//! | [`Jacobians`] | [`InternalStates::jacobians`] | closed-form derivatives for the stiff integrator (finite differences otherwise) |
//! | [`SwitchedLaw`] | [`FrictionModel::switching`] | a set-valued force at v = 0 (stick-slip), closed-form half-cycles |
//! | [`Staging`] | [`FrictionModel::staging`] | data-driven first guesses and starts from fitted simpler models |
//! | [`Propagator`] | [`InternalStates::propagator`] | the states' exact step over an interval of constant velocity, with their parameter sensitivities (a measured motion replayed without an integrator) |
//! | [`ParamGradients`] | [`FrictionModel::param_gradients`] | the force's derivatives with respect to the parameters at fixed states (analytic Jacobians of force-domain fits) |
//!
//! A law implements the group's trait for itself and names the group in
//! [`law_groups!`](crate::law_groups), which writes the accessor (`Some(self)`).

use crate::conditions::Condition;
use crate::error::ModelError;
use crate::hints::{GuessHint, StartContext};
use crate::interval::Interval;
use crate::linearisation::{state_step, velocity_step, Linearisation};
use crate::param_info::{check_bounds, ParamInfo};

/// A friction law: a pure function of sliding velocity, internal states and normal force.
///
/// Implementors derive `Clone`, `Serialize` and `Deserialize` (with `#[serde(default,
/// deny_unknown_fields)]` so that missing parameters take their defaults and unknown keys are
/// rejected) and register with `#[typetag::serde(name = "...")]` on the `impl` block. That is
/// all it takes for the registry, the engine, the identifier and the CLI to know the model.
/// `declare_params!` and `declared_param_methods!` write the name, equation and parameter
/// methods; a static law then writes [`force`](Self::force) (its
/// [`steady_state`](Self::steady_state) follows from it).
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
    /// bounds are not (the identifier enforces them, `check` reports them).
    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError>;

    /// The friction force at velocity `v` with internal states `z` (empty for a law without
    /// [`states`](Self::states)); sgn(0) = 0 for static laws.
    fn force(&self, v: f64, z: &[f64], normal: f64) -> f64;

    /// Steady-state friction curve F_ss(v) (the force at constant sliding velocity). The
    /// default, `force(v, &[], normal)`, is the curve of a law without
    /// [`states`](Self::states); a law with states writes its own (the force at the states
    /// steady sliding reaches).
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        self.force(v, &[], normal)
    }

    /// What the law reads at each instant besides v, N and its states (the displacement, the
    /// acceleration, the input force, named record channels), in the order
    /// [`force_in`](Self::force_in) receives their values. Default: nothing.
    fn conditions(&self) -> Vec<Condition> {
        Vec::new()
    }

    /// The friction force with the values `at` of the law's [`conditions`](Self::conditions)
    /// (one per condition, in that order). The default, [`force`](Self::force), is right for
    /// a law that reads none; a law that reads some writes this, and its `force` is this at
    /// every condition 0 (a load law's force without load).
    fn force_in(&self, v: f64, z: &[f64], normal: f64, _at: &[f64]) -> f64 {
        self.force(v, z, normal)
    }

    /// The internal states and their law, for a dynamic model (`Some(self)`); `None` (the
    /// default) for a static law.
    fn states(&self) -> Option<&dyn InternalStates> {
        None
    }

    /// The switched-system facts of a static law with a set-valued force at v = 0 or a force
    /// affine in v (`Some(self)`); `None` (the default) for a smooth law.
    fn switching(&self) -> Option<&dyn SwitchedLaw> {
        None
    }

    /// The staging of a fit: data-driven first guesses and starts from fitted simpler models
    /// (`Some(self)`); `None` (the default) keeps the declared defaults.
    fn staging(&mut self) -> Option<&mut dyn Staging> {
        None
    }

    /// The force's derivatives with respect to the parameters at fixed states
    /// (`Some(self)`); `None` (the default) leaves them to finite differences of whole fits.
    fn param_gradients(&self) -> Option<&dyn ParamGradients> {
        None
    }

    /// The law's own rules beyond its declared bounds: an error for an inadmissible
    /// combination, warnings for values that are admissible but unusual (e.g. mu_s < mu_c).
    /// The default has none. The bounds themselves are not checked here: callers use
    /// `check` (a method of `dyn FrictionModel`), which checks them first and then calls this.
    fn validate(&self) -> Result<Vec<String>, ModelError> {
        Ok(Vec::new())
    }
}

dyn_clone::clone_trait_object!(FrictionModel);

impl<'a> dyn FrictionModel + 'a {
    /// The number of internal states: 0 for a law without [`FrictionModel::states`].
    pub fn n_states(&self) -> usize {
        self.states().map_or(0, |s| s.n_states())
    }

    /// Checks the parameters: every value against its declared bounds ([`check_bounds`]),
    /// then the law's own rules ([`FrictionModel::validate`]); the warnings of the latter.
    /// Every caller that admits a model goes through here, so no law repeats the bounds.
    pub fn check(&self) -> Result<Vec<String>, ModelError> {
        check_bounds(self.name(), &self.param_info(), &self.params())?;
        self.validate()
    }
}

/// A law with internal states z integrated alongside the motion: dz/dt = h(v, z, N). The
/// state count and derivative are required; the rest are facts with defaults.
pub trait InternalStates: FrictionModel {
    /// Number of internal states (> 0).
    fn n_states(&self) -> usize;

    /// Time derivative of the internal states at sliding velocity `v`, into `dz`.
    fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]);

    /// [`state_derivative`](Self::state_derivative) into `dz` and
    /// [`force`](FrictionModel::force), in one call: what a simulation's right-hand side
    /// needs. A law whose force uses its state derivative (LuGre, GMS) computes the shared
    /// terms once; the results must equal the two calls bit for bit (checked by
    /// `testing::check_combined_rhs`).
    fn state_derivative_and_force(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) -> f64 {
        self.state_derivative(v, z, normal, dz);
        self.force(v, z, normal)
    }

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

    /// The internal states of steady sliding at velocity `v` (written into `out`, length
    /// `n_states`), where the law states them; `false` (the default) when it does not. The
    /// engine's `auto` integrator choice looks for stiffness there as well as at the initial
    /// states: a law whose states are soft when relaxed and stiff when loaded (GMS, Dahl with
    /// alpha < 1) would otherwise be given the explicit method. The harness
    /// (`testing::check_sliding_states`) requires dz/dt = 0 and the steady-state force there.
    fn sliding_states(&self, _v: f64, _normal: f64, _out: &mut [f64]) -> bool {
        false
    }

    /// Energy stored in the internal states (bristle deflection). Used by the engine's energy
    /// checks: KE + PE + stored never increases for a passive model. Default: 0.
    fn stored_energy(&self, _z: &[f64], _normal: f64) -> f64 {
        0.0
    }

    /// The parameters (indices in [`FrictionModel::params`] order) that enter the force but
    /// not the states' equation: a damping on the states' rate, a viscous drag. Along a given
    /// motion the states do not depend on them, so a force-domain fit keeps the states when
    /// only these change. Default: none (always correct; a declaration is checked by
    /// `testing::check_force_only_params`).
    fn force_only_params(&self) -> Vec<usize> {
        Vec::new()
    }

    /// The static law this model tends to as its contact stiffness grows without bound (rigid
    /// bristles), with the index of that stiffness among `params()`: LuGre tends to stribeck
    /// (its bristle damping kept near critical), Dahl to coulomb. The identifier fits the limit
    /// law to the same records and calls the stiffness determined only when the records
    /// exclude the limit (a likelihood-ratio test, [`RigidLimit`]). Default: `None`.
    fn rigid_limit(&self) -> Option<RigidLimit> {
        None
    }

    /// The law's closed-form derivatives (`Some(self)`); `None` (the default) lets the engine
    /// differentiate numerically (see [`Derivatives`]).
    fn jacobians(&self) -> Option<&dyn Jacobians> {
        None
    }

    /// The states' exact step over an interval of constant velocity and normal force
    /// (`Some(self)`); `None` (the default) lets the engine integrate
    /// [`state_derivative`](Self::state_derivative) over each interval.
    fn propagator(&self) -> Option<&dyn Propagator> {
        None
    }
}

/// The partial derivatives a stiff integrator needs, each with a finite-difference default.
/// A law with closed forms overrides those it has; the engine reaches them through
/// [`Derivatives`].
pub trait Jacobians: InternalStates {
    /// The Jacobian of `state_derivative` with respect to the states, d(dz_i)/d(z_j), written
    /// row-major into `jac` (n_states x n_states). Default: [`finite_difference_jacobian`].
    fn state_jacobian(&self, v: f64, z: &[f64], normal: f64, jac: &mut [f64]) {
        finite_difference_jacobian(self, v, z, normal, jac);
    }

    /// The partial derivatives of [`force`](FrictionModel::force) at (v, z): returns dF/dv and
    /// writes dF/dz_j into `dfdz` (n_states entries). Default:
    /// [`finite_difference_force_gradient`].
    fn force_gradient(&self, v: f64, z: &[f64], normal: f64, dfdz: &mut [f64]) -> f64 {
        finite_difference_force_gradient(self, v, z, normal, dfdz)
    }

    /// The derivative of `state_derivative` with respect to the velocity, d(dz_i)/dv, into
    /// `out` (n_states entries). Default: [`finite_difference_velocity_derivative`], never
    /// across v = 0.
    fn state_velocity_derivative(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        finite_difference_velocity_derivative(self, v, z, normal, out);
    }

    /// The three derivatives above in one call: `state_jacobian` into `out.dz_dz`,
    /// `state_velocity_derivative` into `out.dz_dv`, `force_gradient`'s dF/dz into
    /// `out.df_dz` and its dF/dv returned. A law whose derivatives share terms (LuGre's
    /// Stribeck exponential) computes them once; the results must equal the three calls bit
    /// for bit (checked by `testing::check_combined_linearisation`).
    fn linearisation(&self, v: f64, z: &[f64], normal: f64, out: Linearisation<'_>) -> f64 {
        self.state_jacobian(v, z, normal, out.dz_dz);
        self.state_velocity_derivative(v, z, normal, out.dz_dv);
        self.force_gradient(v, z, normal, out.df_dz)
    }
}

/// The facts of a static law the engine treats as a switched system (slip+, slip-, stick).
pub trait SwitchedLaw: FrictionModel {
    /// The breakaway force limit used to decide sticking (coulomb: mu N), for a law with a
    /// set-valued force at zero velocity; `None` (the default) for a law without one.
    fn static_limit(&self, _normal: f64) -> Option<f64> {
        None
    }

    /// The centre of the stick band for a law whose breakaway forces differ by direction:
    /// the mass sticks while the force it must hold, less this offset, lies within
    /// +-`static_limit` (levels F+ and F-: offset (F+ - F-)/2, limit (F+ + F-)/2). Default 0:
    /// the band is symmetric.
    fn static_offset(&self, _normal: f64) -> f64 {
        0.0
    }

    /// The force while slipping in `direction` (+1 or -1). `v` may be zero or of the wrong
    /// sign by round-off at a mode boundary: the direction of the set-valued part must come
    /// from `direction`, never from sgn(v). Default: the force at `v`.
    fn slip_force(&self, v: f64, _direction: f64, normal: f64) -> f64 {
        self.force(v, &[], normal)
    }

    /// `(a, b)` such that `slip_force(v, direction, N) = a + b v` for every v in that sliding
    /// mode (coulomb: (direction mu N, 0); viscous_coulomb: (direction mu N, c_v)): the engine
    /// then solves each half-cycle in closed form. `None` (the default) when the law is not
    /// of that form.
    fn affine_slip(&self, _direction: f64, _normal: f64) -> Option<(f64, f64)> {
        None
    }

    /// [`static_limit`](Self::static_limit) at the values `at` of the law's
    /// [`conditions`](FrictionModel::conditions) (a simulation's displacement, input force
    /// and interpolated channels). Default: the limit without them (right for a law that
    /// reads none).
    fn static_limit_in(&self, normal: f64, _at: &[f64]) -> Option<f64> {
        self.static_limit(normal)
    }

    /// [`static_offset`](Self::static_offset) at the values `at` of the law's conditions.
    /// Default: the offset without them.
    fn static_offset_in(&self, normal: f64, _at: &[f64]) -> f64 {
        self.static_offset(normal)
    }

    /// [`slip_force`](Self::slip_force) at the values `at` of the law's conditions. Default:
    /// the slip force without them.
    fn slip_force_in(&self, v: f64, direction: f64, normal: f64, _at: &[f64]) -> f64 {
        self.slip_force(v, direction, normal)
    }
}

/// The exact step of a law's states over an [`Interval`] of constant velocity v and normal
/// force N, and of their sensitivities to the parameters. The engine replays a measured motion
/// interval by interval at the mean velocity of each (see the engine's `energy::model_force`):
/// with a propagator that replay is one call per sample instead of an integration, exact
/// whatever the stiffness, and the sensitivities give a force-domain fit its Jacobian from the
/// same pass.
///
/// The step must be the exact solution of [`InternalStates::state_derivative`] at constant v
/// and N, every branch of the law included (the harness compares it with a tight numerical
/// integration, `testing::check_exact_steps`).
pub trait Propagator: InternalStates {
    /// Whether [`propagate`](Self::propagate) is exact at the current parameter values (GMS:
    /// only for sharpness 1 and 2); where it is not, the engine integrates the states
    /// numerically. Default: `true`.
    fn propagates_exactly(&self) -> bool {
        true
    }

    /// Advances the states `z` over `interval`: z(dt) of dz/dt = h(v, z, N) from z(0) = `z`.
    fn propagate(&self, interval: Interval, z: &mut [f64]);

    /// [`propagate`](Self::propagate), carrying the sensitivities `sens` = dz/dp with the
    /// states (n_states x n_params, row-major, parameters in [`FrictionModel::params`] order):
    /// sens <- (dz(dt)/dz(0)) sens + dz(dt)/dp. The states must be those of `propagate`, bit for
    /// bit.
    fn propagate_with_sensitivities(&self, interval: Interval, z: &mut [f64], sens: &mut [f64]);

    /// For each parameter, whether [`propagate_with_sensitivities`](Self::propagate_with_sensitivities)
    /// gives its sensitivities (the entries of the others are unspecified: the engine
    /// differentiates the residuals numerically along them). Default: every parameter.
    fn exact_sensitivities(&self) -> Vec<bool> {
        vec![true; self.params().len()]
    }
}

/// The force's partial derivatives with respect to the parameters, states held: with a
/// [`Propagator`]'s sensitivities S, the total derivative of the force along a replayed
/// motion is dF/dp + dF/dz S; for a static law dF/dp alone.
pub trait ParamGradients: FrictionModel {
    /// dF/dp_j at velocity `v`, states `z` and normal force `normal`, into `out` (one entry
    /// per parameter, in [`FrictionModel::params`] order).
    fn force_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]);

    /// [`force_param_gradient`](Self::force_param_gradient) with the values `at` of the law's
    /// [`conditions`](FrictionModel::conditions). Default: the gradient without them (right
    /// for a law that reads none).
    fn force_param_gradient_in(
        &self,
        v: f64,
        z: &[f64],
        normal: f64,
        _at: &[f64],
        out: &mut [f64],
    ) {
        self.force_param_gradient(v, z, normal, out);
    }

    /// The states' rate's partial derivatives with respect to the parameters, states held:
    /// d(dz_i/dt)/dp_j into `out` (n_states x n_params, row-major, parameters in
    /// [`FrictionModel::params`] order), for the forward sensitivities of a simulation.
    /// Returns whether it wrote them; the default does not (`false`), and the engine then
    /// differentiates a simulated response by difference quotients. A law without states
    /// has nothing to write and returns `true`.
    fn state_param_gradient(&self, _v: f64, _z: &[f64], _normal: f64, _out: &mut [f64]) -> bool {
        false
    }
}

/// How a model starts a fit: from the data, or from a fitted simpler model.
pub trait Staging {
    /// Sets data-driven initial values (levels from the energy estimate). Default: keep.
    fn apply_guess(&mut self, _hint: &GuessHint) {}

    /// Takes the start of a staged fit from a fitted simpler model (see [`crate::start`]);
    /// returns whether it did. Default: `false` (keep the values).
    fn start_from(&mut self, _fitted: &dyn FrictionModel, _ctx: &StartContext) -> bool {
        false
    }
}

/// Writes the accessors of the optional groups a law implements, each `Some(self)`: inside
/// its `impl FrictionModel` block `states`, `switching`, `staging` and `param_gradients`,
/// inside its `impl InternalStates` block `jacobians` and `propagator`.
///
/// ```ignore
/// frictionid_models::law_groups!(switching, staging);
/// ```
#[macro_export]
macro_rules! law_groups {
    ($($group:ident),+ $(,)?) => {
        $( $crate::law_groups!(@accessor $group); )+
    };
    (@accessor states) => {
        fn states(&self) -> ::core::option::Option<&dyn $crate::InternalStates> {
            ::core::option::Option::Some(self)
        }
    };
    (@accessor switching) => {
        fn switching(&self) -> ::core::option::Option<&dyn $crate::SwitchedLaw> {
            ::core::option::Option::Some(self)
        }
    };
    (@accessor staging) => {
        fn staging(&mut self) -> ::core::option::Option<&mut dyn $crate::Staging> {
            ::core::option::Option::Some(self)
        }
    };
    (@accessor jacobians) => {
        fn jacobians(&self) -> ::core::option::Option<&dyn $crate::Jacobians> {
            ::core::option::Option::Some(self)
        }
    };
    (@accessor propagator) => {
        fn propagator(&self) -> ::core::option::Option<&dyn $crate::Propagator> {
            ::core::option::Option::Some(self)
        }
    };
    (@accessor param_gradients) => {
        fn param_gradients(&self) -> ::core::option::Option<&dyn $crate::ParamGradients> {
            ::core::option::Option::Some(self)
        }
    };
}

/// Writes, for a law that reads conditions, the methods without them as their `_in` twins at
/// no condition values (`&[]`: every condition at 0): `switching` gives `static_limit` and
/// `slip_force` inside its `impl SwitchedLaw` block, `param_gradients` gives
/// `force_param_gradient` inside its `impl ParamGradients` block.
///
/// ```ignore
/// frictionid_models::at_no_conditions!(switching);
/// ```
#[macro_export]
macro_rules! at_no_conditions {
    (switching) => {
        fn static_limit(&self, normal: f64) -> ::core::option::Option<f64> {
            self.static_limit_in(normal, &[])
        }
        fn slip_force(&self, v: f64, direction: f64, normal: f64) -> f64 {
            self.slip_force_in(v, direction, normal, &[])
        }
    };
    (param_gradients) => {
        fn force_param_gradient(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
            self.force_param_gradient_in(v, z, normal, &[], out);
        }
    };
}

/// The rigid-contact limit of a model with a presliding stiffness (see
/// [`InternalStates::rigid_limit`]). On records that do not resolve presliding (Coulomb-like
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

/// The derivatives of a law with states as the engine calls them: the law's [`Jacobians`]
/// where it has them, finite differences otherwise. Fetched once per run ([`Derivatives::of`]);
/// each call is then one dispatch to the law, as a trait default would be.
#[derive(Debug, Clone, Copy)]
pub struct Derivatives<'a> {
    law: &'a dyn InternalStates,
    closed: Option<&'a dyn Jacobians>,
}

impl<'a> Derivatives<'a> {
    /// The derivatives of `law`.
    pub fn of(law: &'a dyn InternalStates) -> Self {
        Self {
            law,
            closed: law.jacobians(),
        }
    }

    /// [`Jacobians::state_jacobian`].
    pub fn state_jacobian(&self, v: f64, z: &[f64], normal: f64, jac: &mut [f64]) {
        match self.closed {
            Some(j) => j.state_jacobian(v, z, normal, jac),
            None => finite_difference_jacobian(self.law, v, z, normal, jac),
        }
    }

    /// [`Jacobians::force_gradient`].
    pub fn force_gradient(&self, v: f64, z: &[f64], normal: f64, dfdz: &mut [f64]) -> f64 {
        match self.closed {
            Some(j) => j.force_gradient(v, z, normal, dfdz),
            None => finite_difference_force_gradient(self.law, v, z, normal, dfdz),
        }
    }

    /// [`Jacobians::state_velocity_derivative`].
    pub fn state_velocity_derivative(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        match self.closed {
            Some(j) => j.state_velocity_derivative(v, z, normal, out),
            None => finite_difference_velocity_derivative(self.law, v, z, normal, out),
        }
    }

    /// [`Jacobians::linearisation`] (without closed forms: the three finite differences).
    pub fn linearisation(&self, v: f64, z: &[f64], normal: f64, out: Linearisation<'_>) -> f64 {
        match self.closed {
            Some(j) => j.linearisation(v, z, normal, out),
            None => {
                self.state_jacobian(v, z, normal, out.dz_dz);
                self.state_velocity_derivative(v, z, normal, out.dz_dv);
                self.force_gradient(v, z, normal, out.df_dz)
            }
        }
    }
}

/// The central-difference Jacobian of `model.state_derivative` with respect to the states
/// (row-major into `jac`, step [`state_step`]); the default of [`Jacobians::state_jacobian`].
pub fn finite_difference_jacobian<M: InternalStates + ?Sized>(
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
        let step = state_step(z[j]);
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

/// The finite-difference d(dz_i)/dv of `model.state_derivative` (the default of
/// [`Jacobians::state_velocity_derivative`], step of [`velocity_step`]).
pub fn finite_difference_velocity_derivative<M: InternalStates + ?Sized>(
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
/// [`Jacobians::force_gradient`]): returns dF/dv (step of [`velocity_step`]), writes the
/// central-difference dF/dz_j into `dfdz` (step [`state_step`]).
pub fn finite_difference_force_gradient<M: FrictionModel + ?Sized>(
    model: &M,
    v: f64,
    z: &[f64],
    normal: f64,
    dfdz: &mut [f64],
) -> f64 {
    let mut probe = z.to_vec();
    for (j, d) in dfdz.iter_mut().enumerate().take(z.len()) {
        let step = state_step(z[j]);
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
pub fn clone_model<'a>(model: &(dyn FrictionModel + 'a)) -> Box<dyn FrictionModel + 'a> {
    dyn_clone::clone_box(model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::{Deserialize, Serialize};

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
        fn force(&self, _v: f64, z: &[f64], _normal: f64) -> f64 {
            z[0]
        }
        fn steady_state(&self, _v: f64, _normal: f64) -> f64 {
            0.0
        }
        crate::law_groups!(states);
    }

    impl InternalStates for Quadratic {
        fn n_states(&self) -> usize {
            2
        }
        fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) {
            dz[0] = v - 3.0 * z[0] * z[0] + z[1];
            dz[1] = normal * z[0] * z[1];
        }
    }

    #[test]
    fn default_state_jacobian_matches_the_hand_derivative() {
        let normal = 14.5;
        for z in [[0.3, -1.2], [2e-7, 5e-7], [0.0, 0.0], [-40.0, 3.0]] {
            let mut jac = [0.0; 4];
            Derivatives::of(&Quadratic).state_jacobian(0.1, &z, normal, &mut jac);
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

    /// The switched-law facts' defaults, on a law that claims the group and writes nothing.
    impl SwitchedLaw for Quadratic {}

    #[test]
    fn laws_are_not_declared_affine_by_default() {
        assert_eq!(Quadratic.affine_slip(1.0, 14.5), None);
        assert_eq!(Quadratic.affine_slip(-1.0, 14.5), None);
    }

    #[test]
    fn check_rejects_a_value_outside_the_bounds_that_the_law_leaves_to_it() {
        let law = crate::builtin::Coulomb { mu: -0.1 };
        assert_eq!(law.validate().unwrap(), Vec::<String>::new());
        let model: &dyn FrictionModel = &law;
        let e = model.check().unwrap_err();
        assert!(
            matches!(&e, ModelError::OutOfBounds { model, param, .. } if model == "coulomb" && param == "mu"),
            "{e}"
        );
        let admissible: &dyn FrictionModel = &crate::builtin::Coulomb { mu: 0.2 };
        assert_eq!(admissible.check().unwrap(), Vec::<String>::new());
    }

    #[test]
    fn a_stateless_law_s_steady_state_is_its_force_by_default() {
        let law = crate::builtin::Coulomb { mu: 0.2 };
        for v in [-1.0, -1e-9, 0.0, 1e-9, 0.5] {
            assert_eq!(law.steady_state(v, 14.5), law.force(v, &[], 14.5));
        }
    }

    #[test]
    fn laws_are_smooth_and_unstaged_by_default() {
        let mut law = Quadratic;
        let model: &dyn FrictionModel = &law;
        assert!(model.switching().is_none());
        assert_eq!(model.n_states(), 2);
        assert!(law.staging().is_none());
    }
}
