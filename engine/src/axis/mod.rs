//! The axis of the equation of motion J q'' + c q' + R(q) + F_f = u(t): its units (a linear
//! axis in m, N, kg; a rotary axis in rad, N m, kg m^2) and its restoring law R(q).
//!
//! # Restoring laws
//! A law is one file here: a `Copy` struct implementing [`RestoringLaw`] (R(q), dR/dq and the
//! potential V(q) with V(0) = 0) and [`BuildRestoring`] (its name in
//! `restoring = { type = ... }` and its keys), listed once in the `restoring_laws!` call
//! below. The linear spring (the default) reads the oscillator's `stiffness`; the others
//! carry their own parameters.

mod cubic_spring;
mod linear_spring;
mod no_restoring;
mod pendulum;
mod polynomial;
mod units;

pub use cubic_spring::CubicSpring;
pub use linear_spring::LinearSpring;
pub use no_restoring::NoRestoring;
pub use pendulum::Pendulum;
pub use polynomial::Polynomial;
pub use units::Axis;

use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::collections::BTreeMap;

/// A restoring law R(q) of the axis. `k` is the oscillator's `stiffness` (read by the
/// spring-like laws, ignored by the others).
pub trait RestoringLaw {
    /// The restoring force (torque) R(q) [N or N m].
    fn force(&self, q: f64, k: f64) -> f64;
    /// dR/dq [N/m or N m/rad].
    fn stiffness(&self, q: f64, k: f64) -> f64;
    /// The potential V(q) = integral of R from 0 to q [J].
    fn potential(&self, q: f64, k: f64) -> f64;
    /// Whether R(q) is exactly k q (the closed-form propagator and the exact Coulomb
    /// solution apply).
    fn is_linear_spring(&self) -> bool {
        false
    }
    /// Whether the law reads the oscillator's `stiffness`.
    fn reads_stiffness(&self) -> bool {
        false
    }
    /// Why the law's parameters are not admissible, if they are not.
    fn check(&self) -> Result<(), String> {
        Ok(())
    }
}

/// How a law is named and built from its keys in the configuration.
pub trait BuildRestoring: RestoringLaw + Sized {
    /// Its `type` in `restoring = { type = ... }`.
    const NAME: &'static str;
    /// Its parameter keys, in the order of [`BuildRestoring::from_values`].
    const KEYS: &'static [&'static str];
    /// The keys a table may leave out: 0 when absent.
    const OPTIONAL: &'static [&'static str] = &[];
    /// The law from one value per key.
    fn from_values(values: &[f64]) -> Self;
    /// One value per key.
    fn values(&self) -> Vec<f64>;
}

/// An error in `restoring = { ... }`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RestoringError {
    /// The table has no `type`.
    #[error("`restoring` needs a `type` (one of {known})")]
    MissingType {
        /// The registered names.
        known: String,
    },
    /// A `type` that is not registered.
    #[error("unknown restoring law `{name}`{hint}; restoring laws: {known}")]
    UnknownLaw {
        /// As written.
        name: String,
        /// " (did you mean `x`?)" or empty.
        hint: String,
        /// The registered names.
        known: String,
    },
    /// A key the law does not have.
    #[error("unknown key `{key}` of restoring law `{law}`{hint}; its keys: {known}")]
    UnknownKey {
        /// The law.
        law: String,
        /// As written.
        key: String,
        /// " (did you mean `x`?)" or empty.
        hint: String,
        /// The law's keys.
        known: String,
    },
    /// A key the law needs.
    #[error("restoring law `{law}` needs `{key}`")]
    MissingKey {
        /// The law.
        law: String,
        /// The key.
        key: String,
    },
    /// A value that is not a number.
    #[error("`{key}` of restoring law `{law}` must be a number")]
    NotANumber {
        /// The law.
        law: String,
        /// The key.
        key: String,
    },
    /// An inadmissible value.
    #[error("restoring law `{law}`: {reason}")]
    Invalid {
        /// The law.
        law: String,
        /// Why.
        reason: String,
    },
}

/// A value of a `restoring` table as written: the `type` or a number.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
enum RawValue {
    Number(f64),
    Text(String),
}

/// Builds a law from its table's keys (without `type`), naming the nearest key when one is
/// unknown.
fn build_law<L: BuildRestoring>(table: &BTreeMap<String, RawValue>) -> Result<L, RestoringError> {
    let law = L::NAME.to_string();
    if let Some(key) = table.keys().find(|k| !L::KEYS.contains(&k.as_str())) {
        return Err(RestoringError::UnknownKey {
            law,
            key: key.clone(),
            hint: frictionid_models::suggest::did_you_mean(key, L::KEYS.iter().copied()),
            known: if L::KEYS.is_empty() {
                "none".into()
            } else {
                L::KEYS.join(", ")
            },
        });
    }
    let mut values = Vec::with_capacity(L::KEYS.len());
    for key in L::KEYS {
        match table.get(*key) {
            Some(RawValue::Number(v)) => values.push(*v),
            Some(RawValue::Text(_)) => {
                return Err(RestoringError::NotANumber {
                    law,
                    key: key.to_string(),
                })
            }
            None if L::OPTIONAL.contains(key) => values.push(0.0),
            None => {
                return Err(RestoringError::MissingKey {
                    law,
                    key: key.to_string(),
                })
            }
        }
    }
    let built = L::from_values(&values);
    built
        .check()
        .map_err(|reason| RestoringError::Invalid { law, reason })?;
    Ok(built)
}

/// The table of a law: its `type` and its keys.
fn table_of<L: BuildRestoring>(law: &L) -> BTreeMap<String, RawValue> {
    let mut table: BTreeMap<String, RawValue> = L::KEYS
        .iter()
        .zip(law.values())
        .map(|(k, v)| (k.to_string(), RawValue::Number(v)))
        .collect();
    table.insert("type".into(), RawValue::Text(L::NAME.into()));
    table
}

/// Declares the registry: the enum of laws, their names, building, writing and dispatch.
macro_rules! restoring_laws {
    ($($variant:ident($law:ty)),* $(,)?) => {
        /// The axis's restoring law: one of the registered laws.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum Restoring {
            $(
                #[doc = concat!("`", stringify!($law), "`.")]
                $variant($law),
            )*
        }

        impl Restoring {
            /// Every registered name.
            pub const NAMES: &'static [&'static str] = &[$(<$law as BuildRestoring>::NAME),*];

            /// The law named by `table["type"]`, built from the table's other keys.
            fn from_table(mut table: BTreeMap<String, RawValue>) -> Result<Self, RestoringError> {
                let known = Self::NAMES.join(", ");
                let name = match table.remove("type") {
                    Some(RawValue::Text(name)) => name,
                    _ => return Err(RestoringError::MissingType { known }),
                };
                $(
                    if name == <$law as BuildRestoring>::NAME {
                        return build_law::<$law>(&table).map(Self::$variant);
                    }
                )*
                let hint = frictionid_models::suggest::did_you_mean(&name, Self::NAMES.iter().copied());
                Err(RestoringError::UnknownLaw { name, hint, known })
            }

            /// The law's `type`.
            pub fn name(&self) -> &'static str {
                match self {
                    $(Self::$variant(_) => <$law as BuildRestoring>::NAME,)*
                }
            }

            /// The law's keys and values.
            pub fn parameters(&self) -> Vec<(&'static str, f64)> {
                match self {
                    $(Self::$variant(l) => <$law as BuildRestoring>::KEYS
                        .iter()
                        .copied()
                        .zip(l.values())
                        .collect(),)*
                }
            }

            fn table(&self) -> BTreeMap<String, RawValue> {
                match self {
                    $(Self::$variant(l) => table_of(l),)*
                }
            }

            /// The same law with one value per key.
            fn with_values(&self, values: &[f64]) -> Self {
                match self {
                    $(Self::$variant(_) => Self::$variant(<$law as BuildRestoring>::from_values(values)),)*
                }
            }

            /// The law behind the enum.
            #[inline]
            pub fn law(&self) -> &dyn RestoringLaw {
                match self {
                    $(Self::$variant(l) => l,)*
                }
            }
        }
    };
}

restoring_laws! {
    LinearSpring(LinearSpring),
    None(NoRestoring),
    Pendulum(Pendulum),
    CubicSpring(CubicSpring),
    Polynomial(Polynomial),
}

impl Default for Restoring {
    /// The linear spring k q.
    fn default() -> Self {
        Self::LinearSpring(LinearSpring)
    }
}

impl Restoring {
    /// Whether this is the default linear spring.
    pub fn is_linear_spring(&self) -> bool {
        matches!(self, Self::LinearSpring(_))
    }

    /// The value of parameter `key`, if the law has it.
    pub fn parameter(&self, key: &str) -> Option<f64> {
        self.parameters()
            .into_iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| v)
    }

    /// Sets parameter `key` (a fit's trial value, within its own bounds); false when the
    /// law has no such key.
    pub fn set_parameter(&mut self, key: &str, value: f64) -> bool {
        let mut params = self.parameters();
        let Some(slot) = params.iter_mut().find(|(k, _)| *k == key) else {
            return false;
        };
        slot.1 = value;
        let values: Vec<f64> = params.iter().map(|(_, v)| *v).collect();
        *self = self.with_values(&values);
        true
    }

    /// Why the law's parameters are not admissible, if they are not.
    pub fn check(&self) -> Result<(), RestoringError> {
        self.law()
            .check()
            .map_err(|reason| RestoringError::Invalid {
                law: self.name().into(),
                reason,
            })
    }
}

impl Serialize for Restoring {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.table().serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Restoring {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let table = BTreeMap::<String, RawValue>::deserialize(deserializer)?;
        Self::from_table(table).map_err(D::Error::custom)
    }
}

/// `restoring = { ... }` as `[oscillator]` holds it: the law, and the stiffness k that a law
/// reading the oscillator's `stiffness` may carry in its own table (`restoring = { type =
/// "polynomial", stiffness = k1, quadratic_stiffness = k2 }`), which is the oscillator's
/// `stiffness`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WrittenRestoring {
    /// The law.
    pub law: Restoring,
    /// The stiffness written in the law's table.
    pub stiffness: Option<f64>,
}

impl From<Restoring> for WrittenRestoring {
    fn from(law: Restoring) -> Self {
        Self {
            law,
            stiffness: None,
        }
    }
}

impl WrittenRestoring {
    /// From a table: `stiffness` kept aside for a law that reads it, an unknown key of the
    /// others.
    fn from_table(mut table: BTreeMap<String, RawValue>) -> Result<Self, RestoringError> {
        let stiffness = table.remove("stiffness");
        let kept = stiffness.clone();
        let law = Restoring::from_table(table.clone())?;
        let stiffness = match stiffness {
            None => None,
            Some(RawValue::Number(k)) if law.law().reads_stiffness() => Some(k),
            Some(RawValue::Text(_)) if law.law().reads_stiffness() => {
                return Err(RestoringError::NotANumber {
                    law: law.name().into(),
                    key: "stiffness".into(),
                })
            }
            Some(_) => {
                table.extend(kept.map(|v| ("stiffness".to_string(), v)));
                return Restoring::from_table(table).map(Self::from);
            }
        };
        Ok(Self { law, stiffness })
    }
}

impl Serialize for WrittenRestoring {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut table = self.law.table();
        if let Some(k) = self.stiffness {
            table.insert("stiffness".into(), RawValue::Number(k));
        }
        table.serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for WrittenRestoring {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let table = BTreeMap::<String, RawValue>::deserialize(deserializer)?;
        Self::from_table(table).map_err(D::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(json: serde_json::Value) -> Result<Restoring, String> {
        serde_json::from_value(json).map_err(|e| e.to_string())
    }

    #[test]
    fn laws_round_trip_through_their_tables() {
        for json in [
            serde_json::json!({"type": "linear_spring"}),
            serde_json::json!({"type": "none"}),
            serde_json::json!({"type": "pendulum", "gravity_moment": 120.0}),
            serde_json::json!({"type": "cubic_spring", "cubic_stiffness": 5e6}),
            serde_json::json!({"type": "polynomial", "quadratic_stiffness": -2.0, "cubic_stiffness": 5e6}),
        ] {
            let law = parse(json.clone()).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(serde_json::to_value(law).ok(), Some(json));
        }
    }

    #[test]
    fn unknown_names_and_keys_name_the_nearest() {
        let e = parse(serde_json::json!({"type": "pendulm", "gravity_moment": 1.0}));
        assert!(e.is_err_and(|e| e.contains("did you mean `pendulum`")));
        let e = parse(serde_json::json!({"type": "pendulum", "gravity_momnt": 1.0}));
        assert!(e.is_err_and(|e| e.contains("did you mean `gravity_moment`")));
        let e = parse(serde_json::json!({"type": "pendulum"}));
        assert!(e.is_err_and(|e| e.contains("needs `gravity_moment`")));
        let e = parse(serde_json::json!({"type": "pendulum", "gravity_moment": -1.0}));
        assert!(e.is_err_and(|e| e.contains("> 0")));
    }

    #[test]
    fn each_force_is_the_slope_of_its_potential() {
        let laws = [
            Restoring::default(),
            Restoring::None(NoRestoring),
            Restoring::Pendulum(Pendulum {
                gravity_moment: 3.0,
            }),
            Restoring::CubicSpring(CubicSpring {
                cubic_stiffness: 4e5,
            }),
            Restoring::Polynomial(Polynomial {
                quadratic_stiffness: -700.0,
                cubic_stiffness: 4e5,
            }),
        ];
        let k = 1982.0;
        for law in laws {
            let l = law.law();
            for q in [-2.0, -0.3, 0.0, 0.01, 1.1] {
                let h = 1e-6;
                let slope = (l.potential(q + h, k) - l.potential(q - h, k)) / (2.0 * h);
                let tol = 1e-6 * (1.0 + l.force(q, k).abs());
                assert!((slope - l.force(q, k)).abs() < tol, "{} at {q}", law.name());
                let ds = (l.force(q + h, k) - l.force(q - h, k)) / (2.0 * h);
                let tol = 1e-6 * (1.0 + l.stiffness(q, k).abs());
                assert!(
                    (ds - l.stiffness(q, k)).abs() < tol,
                    "{} at {q}",
                    law.name()
                );
            }
            assert_eq!(l.potential(0.0, k), 0.0);
        }
    }

    /// The polynomial spring's absent terms are 0, and with k2 = 0 it is the cubic spring.
    #[test]
    fn the_polynomial_spring_without_k2_is_the_cubic_spring() {
        let p = parse(serde_json::json!({"type": "polynomial", "cubic_stiffness": 3.0}));
        let p = p.unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(p.parameter("quadratic_stiffness"), Some(0.0));
        let cubic = CubicSpring {
            cubic_stiffness: 3.0,
        };
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * (1.0 + b.abs());
        for q in [-0.7, -0.1, 0.0, 0.2, 1.3] {
            assert!(close(p.law().force(q, 2.0), cubic.force(q, 2.0)), "{q}");
            assert!(close(p.law().stiffness(q, 2.0), cubic.stiffness(q, 2.0)));
            assert!(close(p.law().potential(q, 2.0), cubic.potential(q, 2.0)));
        }
        // k1 q + k2 q^2 at q = +-0.5 with k1 = 2, k2 = 4: 1 + 1 and -1 + 1.
        let quadratic = Polynomial {
            quadratic_stiffness: 4.0,
            cubic_stiffness: 0.0,
        };
        assert_eq!(quadratic.force(0.5, 2.0), 2.0);
        assert_eq!(quadratic.force(-0.5, 2.0), 0.0);
        // V = k1 q^2 / 2 + k2 q^3 / 3 = 0.25 + 1/6 at q = 0.5.
        assert!((quadratic.potential(0.5, 2.0) - (0.25 + 1.0 / 6.0)).abs() < 1e-15);
        let e = parse(serde_json::json!({"type": "polynomial", "quadratic_stiffness": f64::NAN}));
        assert!(e.is_err());
    }

    /// A law that reads the oscillator's stiffness may carry it in its table; the others may
    /// not.
    #[test]
    fn the_stiffness_may_be_written_in_a_spring_table() {
        let written: Result<WrittenRestoring, _> = serde_json::from_value(
            serde_json::json!({"type": "polynomial", "stiffness": 0.5, "quadratic_stiffness": 0.2}),
        );
        let written = written.unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(written.stiffness, Some(0.5));
        assert_eq!(written.law.parameter("quadratic_stiffness"), Some(0.2));
        let refused: Result<WrittenRestoring, _> = serde_json::from_value(
            serde_json::json!({"type": "pendulum", "stiffness": 0.5, "gravity_moment": 1.0}),
        );
        assert!(refused.is_err_and(|e| e.to_string().contains("unknown key `stiffness`")));
    }

    #[test]
    fn a_trial_value_replaces_one_parameter() {
        let mut law = Restoring::Pendulum(Pendulum {
            gravity_moment: 3.0,
        });
        assert!(law.set_parameter("gravity_moment", 4.5));
        assert_eq!(law.parameter("gravity_moment"), Some(4.5));
        assert!(!law.set_parameter("stiffness", 1.0));
    }
}
