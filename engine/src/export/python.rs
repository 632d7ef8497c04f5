//! The Python emitter: one module, `math` only (no numpy), with `replay` over sequences.

use super::c::constant_names;
use super::code::Func;
use super::description::{literal, LawDescription};
use super::print::{body, Syntax};
use super::ExportError;
use frictionid_models::formula::Func as FormulaFunc;

/// Python's spelling of the export language.
struct Python {
    constants: Vec<String>,
}

impl Syntax for Python {
    fn constants(&self) -> &[String] {
        &self.constants
    }
    fn call(&self, f: Func, args: &[String]) -> String {
        let name = match f {
            Func::Sgn => "_sgn",
            Func::Decay => "_decay",
            Func::Math(FormulaFunc::Min) => "min",
            Func::Math(FormulaFunc::Max) => "max",
            Func::Math(FormulaFunc::Abs) => "abs",
            Func::Pow => "math.pow",
            _ => return format!("math.{}({})", f.c_name(), args.join(", ")),
        };
        format!("{name}({})", args.join(", "))
    }
    fn select(&self, c: &str, then: &str, otherwise: &str) -> String {
        format!("({then} if {c} else {otherwise})")
    }
    fn logic(&self) -> [&'static str; 3] {
        ["and", "or", "not "]
    }
    fn bind(&self, name: &str, value: &str, _mutable: bool) -> String {
        format!("{name} = {value}")
    }
    fn end(&self) -> &'static str {
        ""
    }
    fn comment(&self, text: &str) -> String {
        format!("# {text}")
    }
    fn braces(&self) -> bool {
        false
    }
    fn repeat_head(&self, count: &str) -> String {
        format!("for _ in range(int({count})):")
    }
    fn if_head(&self, c: &str) -> String {
        format!("if {c}:")
    }
}

/// The law as one Python module.
pub(crate) fn emit(desc: &LawDescription) -> Result<String, ExportError> {
    let syntax = Python {
        constants: constant_names(desc, "")?,
    };
    let mut out = String::from("\"\"\"");
    for l in desc.header("Python (math only, no numpy)") {
        out.push_str(&l.replace('\\', "\\\\"));
        out.push('\n');
    }
    out.push_str(
        "\nUse: law = Law(); law.update(v, n, dt); f = law.force(v, n); or\n\
         forces = replay(t, v, n) over whole sequences (n a sequence or one number).\n\
         Python's math raises where C would give NaN or inf (a domain error in a formula).\n\"\"\"\n\nimport math\n\n",
    );
    for (p, name) in desc.params.iter().zip(&syntax.constants) {
        out.push_str(&format!(
            "{name} = {}  # {}\n",
            literal(p.value),
            LawDescription::param_comment(p)
        ));
    }
    let ns = desc.code.n_states;
    out.push_str(&format!(
        "\n# Number of internal states ({}).\nN_STATES = {ns}\n\n\n",
        desc.code.state_doc
    ));
    out.push_str("def _sgn(x):\n    \"\"\"sgn(x), 0 at 0.\"\"\"\n    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)\n\n\n");
    out.push_str("def _decay(x):\n    \"\"\"exp(-x), 0 beyond x = 745.2.\"\"\"\n    return 0.0 if x > 745.2 else math.exp(-x)\n\n\n");
    out.push_str(&format!(
        "class Law:\n    \"\"\"The law `{}` with its internal states `z` ({}).\"\"\"\n\n    def __init__(self):\n        self.z = [0.0] * N_STATES\n\n    def update(self, v, n, dt):\n        \"\"\"Advances the states over dt [s] at constant velocity v and normal force n.\"\"\"\n{}\n    def force(self, v, n):\n        \"\"\"The friction force at velocity v and normal force n.\"\"\"\n{}\n\n",
        desc.model,
        desc.code.state_doc,
        body(&syntax, &desc.code.update, 2),
        body(&syntax, &desc.code.force, 2)
    ));
    out.push_str(
        "def replay(t, v, n=1.0):\n    \"\"\"The force at every sample of a record (t, v, n): the engine's replay convention.\"\"\"\n    count = len(t)\n    if isinstance(n, (int, float)):\n        n = [float(n)] * count\n    law = Law()\n    forces = []\n    for i in range(count):\n        if i > 0:\n            law.update(0.5 * (v[i - 1] + v[i]), 0.5 * (n[i - 1] + n[i]), t[i] - t[i - 1])\n        forces.append(law.force(v[i], n[i]))\n    return forces\n",
    );
    Ok(out)
}
