//! One declaration per model parameter.
//!
//! A model states each parameter once, as a [`ParamSpec`] (name, unit, default, bounds,
//! meaning, whether a fit keeps it fixed). For a model whose parameters are plain `f64`
//! fields, the [`declare_params!`](crate::declare_params) macro turns one line per parameter
//! into the struct fields, the `Default` impl, the vector order of `params`/`set_params` and
//! `param_info`; [`markdown_table`] renders the same declarations as the parameter table of the
//! model's documentation, and a test ([`crate::testing::doc_table_mismatch`]) checks that the
//! written table is the rendered one. Models with a variable number of parameters (`gms`)
//! build their `ParamInfo`s from `ParamSpec`s too.

use crate::param_info::ParamInfo;

/// The declaration of one model parameter; `const`-constructible, so a model keeps its
/// declarations in a `const` table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// Parameter name, as used in config files (the struct field name).
    pub name: &'static str,
    /// SI unit ("1" for dimensionless coefficients).
    pub unit: &'static str,
    /// Default value.
    pub default: f64,
    /// Physical lower bound.
    pub lower: f64,
    /// Physical upper bound.
    pub upper: f64,
    /// When true the lower bound itself is excluded.
    pub lower_exclusive: bool,
    /// One-line meaning.
    pub description: &'static str,
    /// Whether a fit keeps the parameter fixed unless the user frees it by name.
    pub fixed_by_default: bool,
}

impl ParamSpec {
    /// A parameter with inclusive bounds `[lower, upper]`.
    pub const fn new(
        name: &'static str,
        unit: &'static str,
        default: f64,
        (lower, upper): (f64, f64),
        description: &'static str,
    ) -> Self {
        Self {
            name,
            unit,
            default,
            lower,
            upper,
            lower_exclusive: false,
            description,
            fixed_by_default: false,
        }
    }

    /// A strictly positive parameter, bounds `(0, upper]` (fitted in log coordinates).
    pub const fn positive(
        name: &'static str,
        unit: &'static str,
        default: f64,
        upper: f64,
        description: &'static str,
    ) -> Self {
        let mut spec = Self::new(name, unit, default, (0.0, upper), description);
        spec.lower_exclusive = true;
        spec
    }

    /// A parameter with no upper bound, `[0, inf]`.
    pub const fn non_negative(
        name: &'static str,
        unit: &'static str,
        default: f64,
        description: &'static str,
    ) -> Self {
        Self::new(name, unit, default, (0.0, f64::INFINITY), description)
    }

    /// The same declaration, held fixed in a fit unless freed by name.
    pub const fn fixed(mut self) -> Self {
        self.fixed_by_default = true;
        self
    }

    /// The same declaration with another default (per-instance defaults, e.g. gms elements).
    pub const fn with_default(mut self, default: f64) -> Self {
        self.default = default;
        self
    }

    /// The metadata reported by `FrictionModel::param_info`.
    pub fn info(&self) -> ParamInfo {
        self.info_named(self.name, self.description)
    }

    /// The metadata under another name and meaning (numbered copies such as `k_1`, `k_2`).
    pub fn info_named(&self, name: &str, description: &str) -> ParamInfo {
        ParamInfo {
            name: name.to_string(),
            unit: self.unit.to_string(),
            default: self.default,
            lower: self.lower,
            upper: self.upper,
            lower_exclusive: self.lower_exclusive,
            description: description.to_string(),
            fixed_by_default: self.fixed_by_default,
        }
    }
}

/// The metadata of every declared parameter, in declaration order.
pub fn infos(specs: &[ParamSpec]) -> Vec<ParamInfo> {
    specs.iter().map(ParamSpec::info).collect()
}

/// The documentation table of a model's parameters (Markdown, one row a parameter, ending
/// with a newline): `| parameter | unit | default | bounds | fit | meaning |`.
pub fn markdown_table(info: &[ParamInfo]) -> String {
    let mut out = String::from(
        "| parameter | unit | default | bounds | fit | meaning |\n|---|---|---|---|---|---|\n",
    );
    for p in info {
        out.push_str(&format!(
            "| `{}` | {} | {} | {} | {} | {} |\n",
            p.name,
            p.unit,
            fmt_value(p.default),
            bounds_text(p),
            if p.fixed_by_default { "fixed" } else { "free" },
            p.description
        ));
    }
    out
}

/// Bounds as written in the documentation: `(0, 1e12]`, `[0, inf)`.
fn bounds_text(p: &ParamInfo) -> String {
    let open = if p.lower_exclusive || p.lower.is_infinite() {
        "("
    } else {
        "["
    };
    let close = if p.upper.is_infinite() { ")" } else { "]" };
    format!(
        "{open}{}, {}{close}",
        fmt_value(p.lower),
        fmt_value(p.upper)
    )
}

/// A number as written in the documentation: `0.2`, `300`, `1e5`, `1e-4`.
pub fn fmt_value(x: f64) -> String {
    let a = x.abs();
    if a.is_infinite() {
        (if x > 0.0 { "inf" } else { "-inf" }).to_string()
    } else if a != 0.0 && !(1e-3..1e4).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Declares a model whose parameters are plain `f64` fields, one line per parameter:
///
/// ```
/// use frictionid_models::declare_params;
///
/// declare_params! {
///     /// Coulomb friction with a viscous term.
///     pub struct MyLaw {
///         mu: new("1", 0.2, (0.0, 10.0), "Coulomb friction coefficient"),
///         viscous: non_negative("N s/m", 0.5, "viscous friction coefficient"),
///         v_ref: positive("m/s", 0.1, 100.0, "reference speed").fixed(),
///     }
/// }
/// assert_eq!(MyLaw::default().viscous, 0.5);
/// assert_eq!(MyLaw::PARAMS[2].name, "v_ref");
/// ```
///
/// Each line names the field and a [`ParamSpec`] constructor without its first argument (the
/// name is the field's): `new(unit, default, (lower, upper), meaning)`,
/// `positive(unit, default, upper, meaning)`, `non_negative(unit, default, meaning)`, then
/// optionally `.fixed()`. The macro writes the struct with one `pub f64` field per line
/// (the attributes above the struct are kept; it derives `Debug`, `Clone`, `PartialEq` and
/// serde's `Serialize` and `Deserialize` with `#[serde(default, deny_unknown_fields)]`, so
/// the crate needs `serde` as a dependency), `Default` from the
/// defaults, the table `PARAMS` and the [`DeclaredParams`] impl. Inside the model's
/// `impl FrictionModel` block, [`declared_param_methods!`](crate::declared_param_methods)
/// writes `param_info`, `params` and `set_params` from it.
#[macro_export]
macro_rules! declare_params {
    (
        $(#[$meta:meta])*
        $vis:vis struct $model:ident {
            $( $field:ident : $kind:ident ( $($arg:expr),* $(,)? ) $(. $modifier:ident ())* ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, ::serde::Serialize, ::serde::Deserialize)]
        #[serde(default, deny_unknown_fields)]
        $vis struct $model {
            $(
                #[doc = concat!("Parameter `", stringify!($field), "`: see its declaration in `PARAMS`.")]
                pub $field: f64,
            )*
        }

        impl $model {
            /// The parameter declarations, in the order of `params`/`set_params`.
            pub const PARAMS: &'static [$crate::ParamSpec] = &[
                $( $crate::declare_params!(@spec $field $kind ($($arg),*) $($modifier)*) ),*
            ];
        }

        impl ::core::default::Default for $model {
            fn default() -> Self {
                Self {
                    $( $field: $crate::declare_params!(@spec $field $kind ($($arg),*) $($modifier)*).default, )*
                }
            }
        }

        impl $crate::DeclaredParams for $model {
            fn specs(&self) -> &'static [$crate::ParamSpec] {
                Self::PARAMS
            }
            fn values(&self) -> ::std::vec::Vec<f64> {
                ::std::vec![ $( self.$field ),* ]
            }
            fn assign(&mut self, values: &[f64]) {
                if let [ $( $field ),* ] = *values {
                    $( self.$field = $field; )*
                }
            }
        }
    };
    (@spec $field:ident $kind:ident ($($arg:expr),*) $($modifier:ident)*) => {
        $crate::ParamSpec::$kind(stringify!($field), $($arg),*) $(.$modifier())*
    };
}

/// A model whose parameters are declared by [`declare_params!`](crate::declare_params).
pub trait DeclaredParams {
    /// The declarations, in vector order.
    fn specs(&self) -> &'static [ParamSpec];
    /// The current values, in vector order.
    fn values(&self) -> Vec<f64>;
    /// Sets every value; `values` has exactly one entry per declaration (checked by the
    /// caller), otherwise nothing changes.
    fn assign(&mut self, values: &[f64]);
}

/// Writes `param_info`, `params` and `set_params` of a [`DeclaredParams`] model inside its
/// `impl FrictionModel` block; with `name: "..."` and `equation: "..."` also `name` (which
/// must equal the typetag name) and `equation`. A law without parameters (a test law, a
/// fixed reference law) writes `name: "...", equation: "...", no_params` instead and needs
/// no declaration.
#[macro_export]
macro_rules! declared_param_methods {
    (name: $name:expr, equation: $equation:expr, no_params $(,)?) => {
        fn name(&self) -> &'static str {
            $name
        }
        fn equation(&self) -> ::std::string::String {
            ::std::string::String::from($equation)
        }
        fn param_info(&self) -> ::std::vec::Vec<$crate::ParamInfo> {
            ::std::vec::Vec::new()
        }
        fn params(&self) -> ::std::vec::Vec<f64> {
            ::std::vec::Vec::new()
        }
        fn set_params(&mut self, values: &[f64]) -> ::core::result::Result<(), $crate::ModelError> {
            $crate::check_len($name, 0, values.len())
        }
    };
    (name: $name:expr, equation: $equation:expr $(,)?) => {
        fn name(&self) -> &'static str {
            $name
        }
        fn equation(&self) -> ::std::string::String {
            ::std::string::String::from($equation)
        }
        $crate::declared_param_methods!();
    };
    () => {
        fn param_info(&self) -> ::std::vec::Vec<$crate::ParamInfo> {
            $crate::params::infos($crate::DeclaredParams::specs(self))
        }
        fn params(&self) -> ::std::vec::Vec<f64> {
            $crate::DeclaredParams::values(self)
        }
        fn set_params(&mut self, values: &[f64]) -> ::core::result::Result<(), $crate::ModelError> {
            $crate::check_len(
                $crate::FrictionModel::name(self),
                $crate::DeclaredParams::specs(self).len(),
                values.len(),
            )?;
            $crate::DeclaredParams::assign(self, values);
            ::core::result::Result::Ok(())
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_as_in_the_docs() {
        let cases = [
            (0.2, "0.2"),
            (300.0, "300"),
            (1e5, "1e5"),
            (1e12, "1e12"),
            (1e-4, "1e-4"),
            (0.0, "0"),
            (0.01, "0.01"),
        ];
        for (x, text) in cases {
            assert_eq!(fmt_value(x), text);
        }
    }

    #[test]
    fn specs_give_the_metadata_of_param_info() {
        let spec = ParamSpec::positive("v_s", "m/s", 0.01, 100.0, "Stribeck velocity").fixed();
        let info = ParamInfo::positive("v_s", "m/s", 0.01, 100.0, "Stribeck velocity").fixed();
        assert_eq!(spec.info(), info);
        let spec = ParamSpec::non_negative("b", "N s/m", 0.5, "viscous");
        assert_eq!(
            spec.info(),
            ParamInfo::new("b", "N s/m", 0.5, (0.0, f64::INFINITY), "viscous")
        );
    }

    #[test]
    fn the_table_has_one_row_per_parameter() {
        let info = [
            ParamSpec::new("mu", "1", 0.2, (0.0, 10.0), "Coulomb friction coefficient").info(),
            ParamSpec::positive("delta", "1", 2.0, 10.0, "shape")
                .fixed()
                .info(),
        ];
        assert_eq!(
            markdown_table(&info),
            "| parameter | unit | default | bounds | fit | meaning |\n\
             |---|---|---|---|---|---|\n\
             | `mu` | 1 | 0.2 | [0, 10] | free | Coulomb friction coefficient |\n\
             | `delta` | 1 | 2 | (0, 10] | fixed | shape |\n"
        );
    }
}
