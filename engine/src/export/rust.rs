//! The Rust emitter: one module file that builds under `#![no_std]`, its math from the
//! `libm` crate.

use super::c::constant_names;
use super::code::Func;
use super::description::{literal, LawDescription};
use super::print::{bare, body, Syntax};
use super::ExportError;

/// Rust's spelling of the export language.
struct Rust {
    constants: Vec<String>,
}

impl Syntax for Rust {
    fn constants(&self) -> &[String] {
        &self.constants
    }
    fn call(&self, f: Func, args: &[String]) -> String {
        let name = match f {
            Func::Sgn => "sgn".to_string(),
            Func::Decay => "decay".to_string(),
            _ => format!("libm::{}", f.c_name()),
        };
        format!("{name}({})", args.join(", "))
    }
    fn select(&self, c: &str, then: &str, otherwise: &str) -> String {
        format!(
            "(if {} {{ {} }} else {{ {} }})",
            bare(c),
            bare(then),
            bare(otherwise)
        )
    }
    fn bind(&self, name: &str, value: &str, mutable: bool) -> String {
        let m = if mutable { "mut " } else { "" };
        format!("let {m}{name}: f64 = {value};")
    }
    fn comment(&self, text: &str) -> String {
        format!("// {text}")
    }
    fn repeat_head(&self, count: &str) -> String {
        if count.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            format!("for _ in 0..({count} as u64) {{")
        } else {
            format!("for _ in 0..(({count}) as u64) {{")
        }
    }
}

/// The law as one Rust module.
pub(crate) fn emit(desc: &LawDescription) -> Result<String, ExportError> {
    let syntax = Rust {
        constants: constant_names(desc, "")?,
    };
    let mut out = String::new();
    out.push_str(&desc.commented_header(
        "Rust (no_std; exp, tanh, pow, ... from the `libm` crate)",
        "//!",
    ));
    out.push_str(
        "//!\n//! Builds under `#![no_std]`: add `libm = \"0.2\"` to the crate's dependencies and\n\
         //! include this file as a module (`mod law;`).\n\
         //!\n//! Use: `let mut law = Law::new(); law.update(v, n, dt); let f = law.force(v, n);`\n\n",
    );
    out.push_str("#![allow(clippy::all)]\n\n");
    for (p, name) in desc.params.iter().zip(&syntax.constants) {
        out.push_str(&format!(
            "/// {}\npub const {name}: f64 = {};\n",
            LawDescription::param_comment(p),
            literal(p.value)
        ));
    }
    let ns = desc.code.n_states;
    out.push_str(&format!(
        "\n/// Number of internal states ({}).\npub const N_STATES: usize = {ns};\n\n",
        desc.code.state_doc
    ));
    if desc.uses(Func::Sgn) {
        out.push_str(
            "/// sgn(x), 0 at 0.\nfn sgn(x: f64) -> f64 {\n    if x > 0.0 {\n        1.0\n    } else if x < 0.0 {\n        -1.0\n    } else {\n        0.0\n    }\n}\n\n",
        );
    }
    if desc.uses(Func::Decay) {
        out.push_str(
            "/// exp(-x), 0 beyond x = 745.2.\nfn decay(x: f64) -> f64 {\n    if x > 745.2 {\n        0.0\n    } else {\n        libm::exp(-x)\n    }\n}\n\n",
        );
    }
    out.push_str(&format!(
        "/// The law `{}` with its internal states.\n#[derive(Debug, Clone, Copy, PartialEq)]\npub struct Law {{\n    /// The states ({}).\n    pub z: [f64; N_STATES],\n}}\n\n",
        desc.model, desc.code.state_doc
    ));
    out.push_str(
        "impl Default for Law {\n    fn default() -> Self {\n        Self::new()\n    }\n}\n\n",
    );
    out.push_str(&format!(
        "impl Law {{\n    /// The states at rest.\n    pub const fn new() -> Self {{\n        Self {{ z: [0.0; N_STATES] }}\n    }}\n\n    /// Advances the states over `dt` [s] at constant velocity `v` and normal force `n`.\n    #[allow(unused_variables, unused_mut)]\n    pub fn update(&mut self, v: f64, n: f64, dt: f64) {{\n{}    }}\n\n    /// The friction force at velocity `v` and normal force `n`.\n    #[allow(unused_variables)]\n    pub fn force(&self, v: f64, n: f64) -> f64 {{\n{}    }}\n}}\n",
        body(&syntax, &desc.code.update, 2),
        body(&syntax, &desc.code.force, 2)
    ));
    Ok(out)
}
