//! The generalized Maxwell-slip (GMS) model.
//!
//! n elements in parallel, element i with deflection z_i, stiffness k_i, weight w_i and
//! damping sigma_i; every element slides at its share of the Stribeck curve
//!
//! s(v) = N (mu_c + (mu_s - mu_c) exp(-|v / v_s|^delta)),   rho_i = k_i z_i / (w_i s(v)),
//! dz_i/dt = v (1 - max(0, sgn(v) rho_i)^m),
//! F = sum_i (k_i z_i + sigma_i dz_i/dt) + viscous v.
//!
//! Per element i (1 to n):
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `k_i` | N/m | 1e5, 3.3e4, 1.1e4, ... (each a third of the previous) | (0, 1e12] | free | stiffness of element i |
//! | `w_i` | 1 | 1/n | [0, 1] | free | weight of element i (its fraction of the sliding force) |
//! | `sigma_i` | N s/m | 0 | [0, inf) | free | damping of element i |
//!
//! Shared:
//!
//! | parameter | unit | default | bounds | fit | meaning |
//! |---|---|---|---|---|---|
//! | `mu_c` | 1 | 0.2 | [0, 10] | free | Coulomb friction coefficient |
//! | `mu_s` | 1 | 0.3 | [0, 10] | free | static friction coefficient |
//! | `v_s` | m/s | 0.01 | (0, 100] | free | Stribeck velocity |
//! | `delta` | 1 | 2 | (0, 10] | free | Stribeck shape exponent (usually fixed) |
//! | `sharpness` | 1 | 2 | [1, 20] | free | exponent of the element's stick-to-slip transition (usually fixed) |
//! | `viscous` | N s/m | 0.5 | [0, inf) | free | viscous friction coefficient |
//!
//! The parameters are flattened in this order: all stiffnesses, all weights, all dampings,
//! then the six shared ones. The default model has three elements with equal weights; at the
//! FMM stage's Coulomb level (N = 14.5 N, mu_c = 0.2) they break away at w_i s / k_i of about
//! 10, 30 and 90 micrometres.
//!
//! ```toml
//! [model]
//! type = "gms"
//! elements = 3                         # optional: else the length of the lists, else 3
//! stiffness = [4.0e5, 1.0e5, 2.5e4]    # N/m, one per element, or one number for all
//! weights = [0.5, 0.3, 0.2]            # optional, default 1/n each; or one number for all
//! damping = 0.0                        # optional, N s/m, default 0
//! mu_c = 0.2
//! mu_s = 0.3
//! v_s = 0.01
//! ```
//!
//! The weights are free parameters; when they do not sum to 1 the total sliding force is their
//! sum times the Stribeck curve, which `validate` reports as a warning. Weights and the mu's
//! together are redundant in a fit: fix the weights (or one level) when identifying.
//!
//! # Formulation: smooth elements, no per-element events
//!
//! In Al-Bender et al.'s element an element sticks (dz_i/dt = v) until its force k_i z_i
//! reaches w_i s(v), then slips (dz_i/dt = C sgn(v) (1 - k_i z_i / (w_i s(v)))) until the
//! velocity reverses. Whether an element sticks or slips is a memory, not a function of
//! (v, z): an explicit solver would need a stick/slip event per element, which the engine
//! (adaptive Dormand-Prince with zero-velocity events only) does not have, and a hidden
//! switch in the right-hand side would make the step-size control fail around each switch.
//!
//! So each element here follows a smooth rate law in (v, z) alone, an elasto-plastic
//! element with a sharpness exponent m:
//! - unloading (motion against the element's deflection, sgn(v) rho_i <= 0) is exactly stick,
//!   dz_i/dt = v: the element unloads and reloads elastically with its stiffness k_i, as the
//!   paper's element does after a velocity reversal;
//! - loading (sgn(v) rho_i > 0) is nearly stick while rho_i is well below 1 and saturates at
//!   the element's sliding force: dz_i/dt = 0 at k_i z_i = w_i s(v) sgn(v), and beyond it
//!   (when s(v) drops with speed) z_i is pulled back to it, like the paper's slip law.
//!
//! Loaded at constant velocity from rest, the element force follows the virgin curve
//! F_i(x) = w_i s (1 - exp(-k_i x / (w_i s))) for m = 1 and w_i s tanh(k_i x / (w_i s)) for
//! m = 2; m -> infinity recovers the paper's ideal elastic-then-slipping element. The
//! presliding stiffness sum k_i and the sliding level s(v) are the paper's for every m. A plain
//! LuGre element (dz/dt = v - k |v| z / (w s)) would unload with up to twice its stiffness just
//! after a reversal; the max(0, .) keeps unloading elastic. The right-hand side is continuous
//! and Lipschitz in z (with a kink in v at v = 0 only, where the engine stops at its
//! zero-velocity events anyway), so the adaptive solver handles it without per-element
//! events; its stiffness near saturation, m k_i |v| / (w_i s), sets the step size, as sigma0
//! does for LuGre.
//!
//! Exact steps (`Propagator`, in `gms_steps.rs`): at constant velocity each element's law is
//! separable in the distance travelled, with closed forms for sharpness 1 (exponential) and 2
//! (tanh), the stick branch of an unloaded element included; at any other sharpness the
//! element's load solves travel = Phi(y1) - Phi(y0), Phi the integral of 1 / (1 - y^m), by
//! Newton's method (`gms_relaxation.rs`). The sensitivities of every parameter, the sharpness
//! included, come with the step.
//!
//! Energy: the elements store sum_i k_i z_i^2 / 2 and dissipate
//! k_i z_i (v - dz_i/dt) = |v| w_i s max(0, sgn(v) rho_i)^(m+1) >= 0 each, so with
//! sigma_i = 0 the model is passive. An element whose sliding force w_i s(v) is zero (w_i = 0
//! or N = 0) is frozen (dz_i/dt = 0).
//!
//! Reference: F. Al-Bender, V. Lampaert, J. Swevers, "The generalized Maxwell-slip model: a
//! novel model for friction simulation and compensation", IEEE Trans. Automatic Control
//! 50(11), 1883-1887, 2005.

use crate::builtin::stribeck::{mu_s_warning, Stribeck};
use crate::error::ModelError;
use crate::hints::GuessHint;
use crate::model::{
    decay, finite_difference_force_gradient, finite_difference_velocity_derivative, sgn,
    FrictionModel, InternalStates, Jacobians, RigidLimit, Staging,
};
use crate::param_info::{check_len, ParamInfo};
use crate::params::ParamSpec;
use crate::start::{StartContext, StribeckLevels, TYPICAL_PRESLIDING_DISPLACEMENT};
use serde::de::{self, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};
use std::cell::Cell;

const MODEL: &str = "gms";
/// Most elements accepted (each is an internal state of the ODE).
pub const MAX_ELEMENTS: usize = 100;
const DEFAULT_ELEMENTS: usize = 3;
const FIRST_STIFFNESS: f64 = 1e5;

/// The declarations of the per-element parameters, in vector order (each repeated for every
/// element; `{i}` is the element number, the defaults are those of `Gms::with_elements`).
const ELEMENT_PARAMS: [ParamSpec; 3] = [
    ParamSpec::positive(
        "k_{i}",
        "N/m",
        FIRST_STIFFNESS,
        1e12,
        "stiffness of element {i}",
    ),
    ParamSpec::new(
        "w_{i}",
        "1",
        1.0,
        (0.0, 1.0),
        "weight of element {i} (its fraction of the sliding force)",
    ),
    ParamSpec::non_negative("sigma_{i}", "N s/m", 0.0, "damping of element {i}"),
];

/// The declarations of the shared parameters, after the element ones in vector order.
const SHARED_PARAMS: [ParamSpec; 6] = [
    ParamSpec::new(
        "mu_c",
        "1",
        0.2,
        (0.0, 10.0),
        "Coulomb friction coefficient",
    ),
    ParamSpec::new("mu_s", "1", 0.3, (0.0, 10.0), "static friction coefficient"),
    ParamSpec::positive("v_s", "m/s", 0.01, 100.0, "Stribeck velocity"),
    ParamSpec::positive(
        "delta",
        "1",
        2.0,
        10.0,
        "Stribeck shape exponent (usually fixed)",
    ),
    ParamSpec::new(
        "sharpness",
        "1",
        2.0,
        (1.0, 20.0),
        "exponent of the element's stick-to-slip transition (usually fixed)",
    ),
    ParamSpec::non_negative("viscous", "N s/m", 0.5, "viscous friction coefficient"),
];

/// One Maxwell-slip element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmsElement {
    /// Stiffness k_i [N/m].
    pub stiffness: f64,
    /// Weight w_i: the element's fraction of the sliding force.
    pub weight: f64,
    /// Damping sigma_i [N s/m].
    pub damping: f64,
}

/// The generalized Maxwell-slip model with smooth elasto-plastic elements.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "GmsConfig", into = "GmsConfig")]
pub struct Gms {
    /// The elements (at least one).
    pub elements: Vec<GmsElement>,
    /// Coulomb coefficient.
    pub mu_c: f64,
    /// Static coefficient.
    pub mu_s: f64,
    /// Stribeck velocity [m/s].
    pub v_s: f64,
    /// Stribeck shape exponent.
    pub delta: f64,
    /// Viscous coefficient [N s/m].
    pub viscous: f64,
    /// Transition exponent m of the element law.
    pub sharpness: f64,
}

thread_local! {
    /// [`Gms::stribeck_decay`]'s last result: the bits of |v / v_s| and delta it was computed
    /// at, the power and the decay.
    static LAST_DECAY: Cell<Option<(u64, u64, f64, f64)>> = const { Cell::new(None) };
    /// [`Gms::load_power`]'s last results, [`KEPT_POWERS`] slots picked by the load's bits:
    /// the bits of the load and the sharpness each was computed at, and the power.
    static LAST_POWERS: [Cell<(u64, u64, f64)>; KEPT_POWERS] =
        const { [const { Cell::new((u64::MAX, u64::MAX, f64::NAN)) }; KEPT_POWERS] };
}

/// Load powers kept ([`Gms::load_power`]): more than the elements of a usual GMS.
const KEPT_POWERS: usize = 8;

/// Default stiffness of element `i` (0-based): 1e5 N/m, each next one a third of the previous,
/// so the elements break away at well-spread displacements.
fn default_stiffness(i: usize) -> f64 {
    FIRST_STIFFNESS / 3f64.powi(i32::try_from(i).unwrap_or(i32::MAX))
}

crate::start::stribeck_levels_setter!(Gms);

impl Gms {
    /// The default model with `n` elements (default stiffness, equal weights, no damping).
    pub fn with_elements(n: usize) -> Self {
        let w = 1.0 / n.max(1) as f64;
        Self {
            elements: (0..n)
                .map(|i| GmsElement {
                    stiffness: default_stiffness(i),
                    weight: w,
                    damping: 0.0,
                })
                .collect(),
            mu_c: SHARED_PARAMS[0].default,
            mu_s: SHARED_PARAMS[1].default,
            v_s: SHARED_PARAMS[2].default,
            delta: SHARED_PARAMS[3].default,
            sharpness: SHARED_PARAMS[4].default,
            viscous: SHARED_PARAMS[5].default,
        }
    }

    /// The metadata of the six shared parameters (the last six of `param_info`).
    pub fn shared_param_info() -> Vec<ParamInfo> {
        crate::params::infos(&SHARED_PARAMS)
    }

    /// Scales the element stiffnesses, keeping their ratios, to the total `target` [N/m].
    fn scale_stiffness(&mut self, target: f64) {
        let total: f64 = self.elements.iter().map(|e| e.stiffness).sum();
        if total > 0.0 && total.is_finite() {
            for e in &mut self.elements {
                e.stiffness *= target / total;
            }
        }
    }

    /// The Stribeck curve s(v) \[N\] (the total sliding force for weights summing to 1).
    pub fn s(&self, v: f64, normal: f64) -> f64 {
        self.s_and_slope(v, normal).0
    }

    /// The Stribeck power |v / v_s|^delta and its decay exp(-|v / v_s|^delta), to the bit as
    /// computed afresh: the last pair this thread computed is kept, since a replay asks for
    /// them at one velocity from several places (the force, its gradient in v and z, its
    /// gradient in the parameters) and the power is the costliest part of each.
    pub(super) fn stribeck_decay(&self, v: f64) -> (f64, f64) {
        let ratio = (v / self.v_s).abs();
        let key = (ratio.to_bits(), self.delta.to_bits());
        if let Some((r, d, power, e)) = LAST_DECAY.get() {
            if (r, d) == key {
                return (power, e);
            }
        }
        let power = ratio.powf(self.delta);
        let e = decay(power);
        LAST_DECAY.set(Some((key.0, key.1, power, e)));
        (power, e)
    }

    /// An element's load raised to the sharpness, load^m (the load itself at m = 1), to the
    /// bit as computed afresh: the last few powers are kept, in a slot picked by the load's
    /// bits, since a replay asks for each element's power at one sample from three places
    /// (the force, its gradient in z and v, its gradient in the parameters) and the power is
    /// the costliest part of each.
    pub(super) fn load_power(&self, load: f64) -> f64 {
        let m = self.sharpness;
        if m == 1.0 {
            return load;
        }
        let key = (load.to_bits(), m.to_bits());
        let slot = ((key.0 ^ (key.0 >> 32)) % KEPT_POWERS as u64) as usize;
        LAST_POWERS.with(|kept| {
            let (l, k, power) = kept[slot].get();
            if (l, k) == key {
                return power;
            }
            let power = load.powf(m);
            kept[slot].set((key.0, key.1, power));
            power
        })
    }

    /// The Stribeck curve s(v) and its slope ds/dv from one power: with u = |v / v_s|,
    /// d(u^delta)/dv = delta u^delta / v (0 at v = 0).
    fn s_and_slope(&self, v: f64, normal: f64) -> (f64, f64) {
        let (power, e) = self.stribeck_decay(v);
        let s = normal * (self.mu_c + (self.mu_s - self.mu_c) * e);
        let slope = if v == 0.0 {
            0.0
        } else {
            -normal * (self.mu_s - self.mu_c) * e * self.delta * power / v
        };
        (s, slope)
    }

    /// The partial derivatives (d/dz, d/dv) of an element's rate at the Stribeck level `s`
    /// with slope `ds`: while loading, p = load^m, d/dz = -|v| m p k / (load w s) and
    /// d/dv = 1 - p + v m p ds / s (the load falls as s rises); (0, 1) while unloading;
    /// (0, 0) for a frozen element.
    fn element_partials(&self, e: &GmsElement, v: f64, z: f64, s: f64, ds: f64) -> (f64, f64) {
        match Self::element_load(e, v, z, s) {
            None => (0.0, 0.0),
            Some((limit, load)) if load > 0.0 => {
                let m = self.sharpness;
                let p = self.load_power(load);
                let d_dz = -v.abs() * m * (p / load) * e.stiffness / limit;
                (d_dz, 1.0 - p + v * m * p * ds / s)
            }
            Some(_) => (0.0, 1.0),
        }
    }

    /// d(dz/dt)/dz of the element law: -|v| m load^(m-1) k / (w s) while loading
    /// (load > 0), 0 while unloading and for a frozen element (the state Jacobian's form;
    /// `Gms::element_partials` gives the same derivative as m p / load for the gradients).
    fn z_dot_slope(&self, e: &GmsElement, v: f64, z: f64, s: f64) -> f64 {
        match Self::element_load(e, v, z, s) {
            Some((limit, load)) if load > 0.0 => {
                let power = if self.sharpness == 1.0 {
                    1.0
                } else {
                    self.sharpness * load.powf(self.sharpness - 1.0)
                };
                -v.abs() * power * e.stiffness / limit
            }
            _ => 0.0,
        }
    }

    /// The element's sliding force w s and its load sgn(v) k z / (w s): how far the motion
    /// loads the element towards its sliding force in the direction of motion (unloading, v
    /// against the deflection, is purely elastic). `None` for a frozen element (no sliding
    /// force).
    pub(super) fn element_load(e: &GmsElement, v: f64, z: f64, s: f64) -> Option<(f64, f64)> {
        let limit = e.weight * s;
        if limit <= 0.0 {
            return None;
        }
        let rho = e.stiffness * z / limit;
        Some((limit, if v >= 0.0 { rho } else { -rho }))
    }

    /// An element's force k z + sigma dz/dt (k z alone for an undamped element).
    fn element_force(e: &GmsElement, z: f64, z_dot: f64) -> f64 {
        let spring = e.stiffness * z;
        if e.damping == 0.0 {
            spring
        } else {
            spring + e.damping * z_dot
        }
    }

    /// The element law dz/dt = v (1 - max(0, sgn(v) rho)^m).
    pub(super) fn z_dot(&self, e: &GmsElement, v: f64, z: f64, s: f64) -> f64 {
        match Self::element_load(e, v, z, s) {
            None => 0.0,
            Some((_, load)) if load > 0.0 => {
                let p = self.load_power(load);
                v * (1.0 - p)
            }
            Some(_) => v,
        }
    }
}

impl Default for Gms {
    fn default() -> Self {
        Self::with_elements(DEFAULT_ELEMENTS)
    }
}

/// A per-element value in a config: one number for all elements or one per element.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum PerElement {
    /// The same value for every element.
    All(f64),
    /// One value per element.
    Each(Vec<f64>),
}

impl PerElement {
    fn len(&self) -> Option<usize> {
        match self {
            PerElement::All(_) => None,
            PerElement::Each(v) => Some(v.len()),
        }
    }

    fn get(&self, i: usize) -> Option<f64> {
        match self {
            PerElement::All(x) => Some(*x),
            PerElement::Each(v) => v.get(i).copied(),
        }
    }
}

impl<'de> Deserialize<'de> for PerElement {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = PerElement;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number (for all elements) or a list of numbers (one per element)")
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<PerElement, E> {
                Ok(PerElement::All(x))
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<PerElement, E> {
                Ok(PerElement::All(x as f64))
            }
            fn visit_u64<E: de::Error>(self, x: u64) -> Result<PerElement, E> {
                Ok(PerElement::All(x as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<PerElement, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(PerElement::Each(v))
            }
        }
        d.deserialize_any(V)
    }
}

/// The table of the `gms` model as written in a config file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GmsConfig {
    /// Number of elements (else the length of the lists, else 3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elements: Option<usize>,
    /// Element stiffnesses [N/m].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<PerElement>,
    /// Element weights.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weights: Option<PerElement>,
    /// Element dampings [N s/m].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping: Option<PerElement>,
    /// Coulomb coefficient.
    pub mu_c: f64,
    /// Static coefficient.
    pub mu_s: f64,
    /// Stribeck velocity [m/s].
    pub v_s: f64,
    /// Stribeck shape exponent.
    pub delta: f64,
    /// Transition exponent of the element law.
    pub sharpness: f64,
    /// Viscous coefficient [N s/m].
    pub viscous: f64,
}

impl Default for GmsConfig {
    fn default() -> Self {
        let d = Gms::default();
        Self {
            elements: None,
            stiffness: None,
            weights: None,
            damping: None,
            mu_c: d.mu_c,
            mu_s: d.mu_s,
            v_s: d.v_s,
            delta: d.delta,
            sharpness: d.sharpness,
            viscous: d.viscous,
        }
    }
}

fn bad_key(key: &str, message: String) -> ModelError {
    ModelError::BadKey {
        model: MODEL.into(),
        key: key.into(),
        message,
    }
}

impl GmsConfig {
    /// The per-element lists with their keys.
    fn lists(&self) -> [(&'static str, &Option<PerElement>); 3] {
        [
            ("stiffness", &self.stiffness),
            ("weights", &self.weights),
            ("damping", &self.damping),
        ]
    }

    /// The element count and the key it came from (`elements`, else the first list, else
    /// the default).
    fn element_count(&self) -> (usize, &'static str) {
        match self.elements {
            Some(n) => (n, "elements"),
            None => self
                .lists()
                .iter()
                .find_map(|(key, l)| l.as_ref().and_then(PerElement::len).map(|n| (n, *key)))
                .unwrap_or((DEFAULT_ELEMENTS, "the default")),
        }
    }

    /// Checks the element count and that every list has one value per element.
    fn checked_element_count(&self) -> Result<usize, ModelError> {
        let (n, source) = self.element_count();
        if n == 0 || n > MAX_ELEMENTS {
            return Err(bad_key(
                source,
                format!("the model needs 1 to {MAX_ELEMENTS} elements, got {n}"),
            ));
        }
        let source = if source == "the default" {
            source.to_string()
        } else {
            format!("`{source}`")
        };
        for (key, l) in self.lists() {
            if let Some(len) = l.as_ref().and_then(PerElement::len) {
                if len != n {
                    return Err(bad_key(
                        key,
                        format!(
                            "has {len} values but the model has {n} elements (from {source}); give \
                             one value per element or a single number for all"
                        ),
                    ));
                }
            }
        }
        Ok(n)
    }

    /// The `n` elements: the given values, else the defaults of `Gms::with_elements(n)`.
    fn elements(&self, n: usize) -> Vec<GmsElement> {
        let pick = |l: &Option<PerElement>, i: usize, default: f64| {
            l.as_ref().and_then(|l| l.get(i)).unwrap_or(default)
        };
        Gms::with_elements(n)
            .elements
            .iter()
            .enumerate()
            .map(|(i, d)| GmsElement {
                stiffness: pick(&self.stiffness, i, d.stiffness),
                weight: pick(&self.weights, i, d.weight),
                damping: pick(&self.damping, i, d.damping),
            })
            .collect()
    }
}

impl TryFrom<GmsConfig> for Gms {
    type Error = ModelError;

    fn try_from(cfg: GmsConfig) -> Result<Self, ModelError> {
        let n = cfg.checked_element_count()?;
        Ok(Self {
            elements: cfg.elements(n),
            mu_c: cfg.mu_c,
            mu_s: cfg.mu_s,
            v_s: cfg.v_s,
            delta: cfg.delta,
            sharpness: cfg.sharpness,
            viscous: cfg.viscous,
        })
    }
}

impl From<Gms> for GmsConfig {
    fn from(m: Gms) -> Self {
        let list =
            |f: fn(&GmsElement) -> f64| Some(PerElement::Each(m.elements.iter().map(f).collect()));
        Self {
            elements: Some(m.elements.len()),
            stiffness: list(|e| e.stiffness),
            weights: list(|e| e.weight),
            damping: list(|e| e.damping),
            mu_c: m.mu_c,
            mu_s: m.mu_s,
            v_s: m.v_s,
            delta: m.delta,
            sharpness: m.sharpness,
            viscous: m.viscous,
        }
    }
}

#[typetag::serde(name = "gms")]
impl FrictionModel for Gms {
    fn name(&self) -> &'static str {
        MODEL
    }
    fn equation(&self) -> String {
        "dz_i/dt = v (1 - max(0, sgn(v) rho_i)^sharpness), rho_i = k_i z_i / (w_i s(v)), s(v) = N (mu_c + (mu_s - mu_c) exp(-|v/v_s|^delta)), F = sum_i (k_i z_i + sigma_i dz_i/dt) + viscous v".into()
    }
    fn param_info(&self) -> Vec<ParamInfo> {
        let n = self.elements.len();
        let d = Gms::with_elements(n);
        let element_values: [fn(&GmsElement) -> f64; 3] =
            [|e| e.stiffness, |e| e.weight, |e| e.damping];
        let mut info: Vec<ParamInfo> = ELEMENT_PARAMS
            .iter()
            .zip(element_values)
            .flat_map(|(spec, value)| {
                d.elements.iter().enumerate().map(move |(i, e)| {
                    let number = (i + 1).to_string();
                    spec.with_default(value(e)).info_named(
                        &spec.name.replace("{i}", &number),
                        &spec.description.replace("{i}", &number),
                    )
                })
            })
            .collect();
        info.extend(Gms::shared_param_info());
        info
    }
    fn params(&self) -> Vec<f64> {
        let e = &self.elements;
        e.iter()
            .map(|e| e.stiffness)
            .chain(e.iter().map(|e| e.weight))
            .chain(e.iter().map(|e| e.damping))
            .chain([
                self.mu_c,
                self.mu_s,
                self.v_s,
                self.delta,
                self.sharpness,
                self.viscous,
            ])
            .collect()
    }
    fn set_params(&mut self, values: &[f64]) -> Result<(), ModelError> {
        let n = self.elements.len();
        check_len(self.name(), 3 * n + 6, values.len())?;
        let (k, rest) = values.split_at(n);
        let (w, rest) = rest.split_at(n);
        let (sigma, shared) = rest.split_at(n);
        for (((e, &k), &w), &s) in self.elements.iter_mut().zip(k).zip(w).zip(sigma) {
            *e = GmsElement {
                stiffness: k,
                weight: w,
                damping: s,
            };
        }
        if let [mu_c, mu_s, v_s, delta, sharpness, viscous] = *shared {
            self.mu_c = mu_c;
            self.mu_s = mu_s;
            self.v_s = v_s;
            self.delta = delta;
            self.sharpness = sharpness;
            self.viscous = viscous;
        }
        Ok(())
    }
    fn force(&self, v: f64, z: &[f64], normal: f64) -> f64 {
        let s = self.s(v, normal);
        let elements: f64 = self
            .elements
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let zi = z.get(i).copied().unwrap_or(0.0);
                if e.damping == 0.0 {
                    e.stiffness * zi
                } else {
                    Self::element_force(e, zi, self.z_dot(e, v, zi, s))
                }
            })
            .sum();
        elements + self.viscous * v
    }
    fn steady_state(&self, v: f64, normal: f64) -> f64 {
        let total_weight: f64 = self.elements.iter().map(|e| e.weight).sum();
        total_weight * self.s(v, normal) * sgn(v) + self.viscous * v
    }
    crate::law_groups!(states, staging, param_gradients);
    fn validate(&self) -> Result<Vec<String>, ModelError> {
        if self.elements.is_empty() {
            return Err(bad_key(
                "elements",
                "the model needs at least one element".into(),
            ));
        }
        let mut warnings = mu_s_warning(self.name(), self.mu_s, self.mu_c);
        let total: f64 = self.elements.iter().map(|e| e.weight).sum();
        if (total - 1.0).abs() > 1e-9 {
            warnings.push(format!(
                "model `gms`: the weights sum to {total}, so the sliding force is {total} times the Stribeck curve"
            ));
        }
        Ok(warnings)
    }
}

impl InternalStates for Gms {
    fn n_states(&self) -> usize {
        self.elements.len()
    }
    /// The elements' dampings sigma_i and the viscous term.
    fn force_only_params(&self) -> Vec<usize> {
        let n = self.elements.len();
        (2 * n..3 * n).chain([3 * n + 5]).collect()
    }
    fn state_derivative(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) {
        let s = self.s(v, normal);
        for ((e, &zi), d) in self.elements.iter().zip(z).zip(dz.iter_mut()) {
            *d = self.z_dot(e, v, zi, s);
        }
    }
    /// The Stribeck curve once, and each element's rate once for its derivative and force.
    fn state_derivative_and_force(&self, v: f64, z: &[f64], normal: f64, dz: &mut [f64]) -> f64 {
        let s = self.s(v, normal);
        let elements: f64 = self
            .elements
            .iter()
            .zip(dz.iter_mut())
            .enumerate()
            .map(|(i, (e, d))| {
                let zi = z.get(i).copied().unwrap_or(0.0);
                *d = self.z_dot(e, v, zi, s);
                Self::element_force(e, zi, *d)
            })
            .sum();
        elements + self.viscous * v
    }
    /// Every element fully loaded: z_i = sgn(v) w_i s(v) / k_i (rho_i = 1, where its rate is
    /// stiffest); an element without stiffness stays at 0.
    fn sliding_states(&self, v: f64, normal: f64, out: &mut [f64]) -> bool {
        let s = self.s(v, normal);
        for (e, z) in self.elements.iter().zip(out.iter_mut()) {
            *z = if e.stiffness > 0.0 {
                sgn(v) * e.weight * s / e.stiffness
            } else {
                0.0
            };
        }
        true
    }
    fn stored_energy(&self, z: &[f64], _normal: f64) -> f64 {
        self.elements
            .iter()
            .zip(z)
            .map(|(e, zi)| 0.5 * e.stiffness * zi * zi)
            .sum()
    }
    /// Rigid elements: each saturates at once at its share of the Stribeck curve, and the
    /// model slides at s(v) + viscous v, a Stribeck law with GMS's shape exponent (free, as
    /// in GMS) and no dynamics: the elements' weights (only their sum scales the curve), their
    /// damping (it acts only while they deflect) and the sharpness of their saturation vanish.
    fn rigid_limit(&self) -> Option<RigidLimit> {
        // The vector order of `params`: ELEMENT_PARAMS kind by kind (stiffnesses, weights,
        // dampings), one entry per element, then SHARED_PARAMS.
        let n = self.elements.len();
        let kind = |k: usize| k * n..(k + 1) * n;
        let shared = |name: &str| {
            SHARED_PARAMS
                .iter()
                .position(|p| p.name == name)
                .map(|i| ELEMENT_PARAMS.len() * n + i)
        };
        Some(RigidLimit {
            law: Box::new(Stribeck::default()),
            stiffnesses: kind(0).collect(),
            presliding: kind(1).chain(kind(2)).chain(shared("sharpness")).collect(),
            also_free: vec!["delta"],
        })
    }
    crate::law_groups!(jacobians, propagator);
}

impl Jacobians for Gms {
    /// Diagonal: each element's rate depends on its own deflection only (see
    /// `Gms::z_dot_slope`).
    fn state_jacobian(&self, v: f64, z: &[f64], normal: f64, jac: &mut [f64]) {
        let n = self.elements.len();
        jac.iter_mut().for_each(|j| *j = 0.0);
        let s = self.s(v, normal);
        for (i, (e, &zi)) in self.elements.iter().zip(z).enumerate() {
            if let Some(j) = jac.get_mut(i * n + i) {
                *j = self.z_dot_slope(e, v, zi, s);
            }
        }
    }
    /// dF/dv = sum_i sigma_i d(dz_i/dt)/dv + viscous, dF/dz_i = k_i + sigma_i d(dz_i/dt)/dz_i
    /// (no power at all for undamped elements); finite differences where the closed form is
    /// not finite (a Stribeck exponent below 1 at v -> 0).
    fn force_gradient(&self, v: f64, z: &[f64], normal: f64, dfdz: &mut [f64]) -> f64 {
        let (s, ds) = self.s_and_slope(v, normal);
        let mut df_dv = self.viscous;
        for ((e, &zi), d) in self.elements.iter().zip(z).zip(dfdz.iter_mut()) {
            *d = e.stiffness;
            if e.damping != 0.0 {
                let (d_dz, d_dv) = self.element_partials(e, v, zi, s, ds);
                *d += e.damping * d_dz;
                df_dv += e.damping * d_dv;
            }
        }
        if df_dv.is_finite() && dfdz.iter().all(|d| d.is_finite()) {
            df_dv
        } else {
            finite_difference_force_gradient(self, v, z, normal, dfdz)
        }
    }
    /// Each element's d(dz_i/dt)/dv from `Gms::element_partials` (finite differences where
    /// that is not finite).
    fn state_velocity_derivative(&self, v: f64, z: &[f64], normal: f64, out: &mut [f64]) {
        let (s, ds) = self.s_and_slope(v, normal);
        for ((e, &zi), o) in self.elements.iter().zip(z).zip(out.iter_mut()) {
            *o = self.element_partials(e, v, zi, s, ds).1;
        }
        if !out.iter().all(|o| o.is_finite()) {
            finite_difference_velocity_derivative(self, v, z, normal, out);
        }
    }
}

impl Staging for Gms {
    fn apply_guess(&mut self, hint: &GuessHint) {
        let levels = StribeckLevels::guess(hint);
        self.set_levels(&levels);
        // Keep the ratios of the stiffnesses; scale the total presliding stiffness to a
        // breakaway displacement of about 20 micrometres (as the LuGre guess).
        self.scale_stiffness(
            (hint.mu * hint.normal_force / TYPICAL_PRESLIDING_DISPLACEMENT).max(1.0),
        );
    }
    /// The fitted Stribeck curve shared by the elements (weights rescaled to sum to 1, so
    /// that the model slides at exactly that curve), the total stiffness from the presliding
    /// displacement at the Coulomb level, the stiffness ratios kept.
    fn start_from(&mut self, fitted: &dyn FrictionModel, ctx: &StartContext) -> bool {
        let Some(levels) = StribeckLevels::from_model(fitted) else {
            return false;
        };
        self.set_levels(&levels);
        let total_weight: f64 = self.elements.iter().map(|e| e.weight).sum();
        let equal = 1.0 / self.elements.len().max(1) as f64;
        for e in &mut self.elements {
            e.weight = if total_weight > 0.0 {
                e.weight / total_weight
            } else {
                equal
            };
        }
        self.scale_stiffness(ctx.stiffness_for(levels.mu_c * ctx.normal_force));
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kept_stribeck_decay_is_the_one_computed_afresh() {
        // Two laws that share a velocity ratio, or a velocity, but not both their inputs,
        // asked in turn: each gets its own curve, as the formula gives it.
        let a = Gms {
            delta: 1.7,
            ..Gms::default()
        };
        let mut b = a.clone();
        b.v_s = 2.0 * a.v_s;
        let mut c = a.clone();
        c.delta = 2.3;
        for v in [0.004, -0.004, 0.008, 0.0, 0.004] {
            for law in [&a, &b, &c, &a] {
                let power = (v / law.v_s).abs().powf(law.delta);
                let want = 14.5 * (law.mu_c + (law.mu_s - law.mu_c) * (-power).exp());
                assert_eq!(law.s(v, 14.5), want, "v = {v}, v_s = {}", law.v_s);
            }
        }
    }

    #[test]
    fn the_kept_load_powers_are_the_ones_computed_afresh() {
        // More loads than slots, asked in turn by laws of two sharpnesses and again: every
        // answer is the power the formula gives, whichever slot it was kept in.
        let a = Gms {
            sharpness: 2.7,
            ..Gms::default()
        };
        let b = Gms {
            sharpness: 6.0,
            ..Gms::default()
        };
        let loads: Vec<f64> = (1..=3 * KEPT_POWERS).map(|k| 0.037 * k as f64).collect();
        for _ in 0..2 {
            for &load in &loads {
                for law in [&a, &b, &a] {
                    let want = load.powf(law.sharpness);
                    assert_eq!(
                        law.load_power(load),
                        want,
                        "load {load}, m {}",
                        law.sharpness
                    );
                }
            }
        }
        let linear = Gms {
            sharpness: 1.0,
            ..Gms::default()
        };
        assert_eq!(linear.load_power(0.3), 0.3);
    }
}
