//! The C99 emitter: one file, `math.h` only, no allocation; every identifier carries a
//! prefix (`fid_` by default) so that several laws live in one program.

use super::code::Func;
use super::code::{Expr, Stmt};
use super::description::{literal, reads, LawDescription};
use super::print::{body, Syntax};
use super::ExportError;

/// C's spelling of the export language.
struct C {
    prefix: String,
    constants: Vec<String>,
}

impl Syntax for C {
    fn state(&self, index: usize) -> String {
        format!("s->z[{index}]")
    }
    fn constants(&self) -> &[String] {
        &self.constants
    }
    fn call(&self, f: Func, args: &[String]) -> String {
        let name = match f {
            Func::Sgn | Func::Decay => format!("{}{}", self.prefix, f.c_name()),
            _ => f.c_name().to_string(),
        };
        format!("{name}({})", args.join(", "))
    }
    fn select(&self, c: &str, then: &str, otherwise: &str) -> String {
        format!("({c} ? {then} : {otherwise})")
    }
    fn bind(&self, name: &str, value: &str, mutable: bool) -> String {
        let qualifier = if mutable { "" } else { "const " };
        format!("{qualifier}double {name} = {value};")
    }
    fn comment(&self, text: &str) -> String {
        format!("/* {text} */")
    }
    fn repeat_head(&self, count: &str) -> String {
        format!("for (long k = 0; k < (long)({count}); ++k) {{")
    }
    fn if_head(&self, c: &str) -> String {
        format!("if ({c}) {{")
    }
}

/// Whether `prefix` can start a C identifier.
fn valid_prefix(prefix: &str) -> bool {
    let mut chars = prefix.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The constants' macro names: the prefix and the parameter's name in upper case. Errors:
/// two names the same in upper case, a value not finite.
pub(crate) fn constant_names(
    desc: &LawDescription,
    upper_prefix: &str,
) -> Result<Vec<String>, ExportError> {
    let names: Vec<String> = desc
        .params
        .iter()
        .map(|p| format!("{upper_prefix}{}", p.name.to_ascii_uppercase()))
        .collect();
    for (i, a) in names.iter().enumerate() {
        if let Some(j) = names[..i].iter().position(|b| b == a) {
            return Err(ExportError::NameClash(
                desc.params[j].name.clone(),
                desc.params[i].name.clone(),
                "upper case",
            ));
        }
    }
    if let Some(p) = desc.params.iter().find(|p| !p.value.is_finite()) {
        return Err(ExportError::Report {
            key: format!("model_parameters.{}", p.name),
            reason: format!("not finite ({})", p.value),
        });
    }
    Ok(names)
}

/// `(void)x;` for each argument `body` does not read (no warning under -Wextra).
fn unused(body: &[Stmt], args: &[(&str, Expr)]) -> String {
    args.iter()
        .filter(|(_, leaf)| !reads(body, leaf))
        .map(|(name, _)| format!("    (void){name};\n"))
        .collect()
}

/// The law as one C99 file.
pub(crate) fn emit(desc: &LawDescription, prefix: &str) -> Result<String, ExportError> {
    if !valid_prefix(prefix) {
        return Err(ExportError::Options(format!(
            "--prefix `{prefix}` does not start a C identifier (letters, digits, `_`)"
        )));
    }
    let upper = prefix.to_ascii_uppercase();
    let syntax = C {
        prefix: prefix.to_string(),
        constants: constant_names(desc, &upper)?,
    };
    let mut out = String::from("/*\n");
    out.push_str(&desc.commented_header("C99 (math.h only, no allocation; link with -lm)", " *"));
    out.push_str(&format!(
        " *\n * Use:\n *   {p}state s; {p}init(&s);\n *   {p}update(&s, v, n, dt);  (each step)\n *   double f = {p}force(&s, v, n);\n */\n",
        p = prefix
    ));
    let guard = format!("{upper}{}_LAW_C", desc.model.to_ascii_uppercase());
    out.push_str(&format!(
        "#ifndef {guard}\n#define {guard}\n\n#include <math.h>\n\n"
    ));
    out.push_str("/* The fitted parameters: value, [unit], standard error. */\n");
    for (p, name) in desc.params.iter().zip(&syntax.constants) {
        let value = literal(p.value);
        let value = if p.value < 0.0 {
            format!("({value})")
        } else {
            value
        };
        out.push_str(&format!(
            "#define {name} {value} /* {} */\n",
            LawDescription::param_comment(p)
        ));
    }
    let ns = desc.code.n_states;
    out.push_str(&format!(
        "\n/* Number of internal states ({}). */\n#define {upper}N_STATES {ns}\n\n",
        desc.code.state_doc
    ));
    out.push_str(&format!(
        "/* The law's internal states{}. */\ntypedef struct {{\n    double z[{}];\n}} {prefix}state;\n\n",
        if ns == 0 {
            " (none: one unused slot keeps the struct valid C)"
        } else {
            ""
        },
        ns.max(1)
    ));
    if desc.uses(Func::Sgn) {
        out.push_str(&format!(
            "/* sgn(x), 0 at 0. */\nstatic inline double {prefix}sgn(double x) {{\n    return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);\n}}\n\n"
        ));
    }
    if desc.uses(Func::Decay) {
        out.push_str(&format!(
            "/* exp(-x), 0 beyond x = 745.2. */\nstatic inline double {prefix}decay(double x) {{\n    return x > 745.2 ? 0.0 : exp(-x);\n}}\n\n"
        ));
    }
    out.push_str(&format!(
        "/* The states at rest. */\nvoid {prefix}init({prefix}state *s) {{\n    int i;\n    for (i = 0; i < {}; ++i) {{\n        s->z[i] = 0.0;\n    }}\n}}\n\n",
        ns.max(1)
    ));
    out.push_str(&format!(
        "/* Advances the states over dt [s] at constant velocity v and normal force n. */\nvoid {prefix}update({prefix}state *s, double v, double n, double dt) {{\n{}{}}}\n\n",
        unused(&desc.code.update, &[("s", Expr::State(0)), ("v", Expr::V), ("n", Expr::N), ("dt", Expr::Dt)]),
        body(&syntax, &desc.code.update, 1)
    ));
    out.push_str(&format!(
        "/* The friction force at velocity v and normal force n. */\ndouble {prefix}force(const {prefix}state *s, double v, double n) {{\n{}{}}}\n\n#endif /* {guard} */\n",
        unused(&desc.code.force, &[("s", Expr::State(0)), ("v", Expr::V), ("n", Expr::N)]),
        body(&syntax, &desc.code.force, 1)
    ));
    Ok(out)
}
