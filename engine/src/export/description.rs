//! The law-description value every emitter prints: read from a report (report.json's value)
//! or a [`FitResult`].

use super::code::{Cond, Expr, Func, LawCode, Stmt};
use super::laws::{law_code, Params, EXPORTABLE};
use super::ExportError;
use crate::identify::FitResult;
use crate::report::fit::fit_json;
use frictionid_models::FrictionModel;
use serde_json::Value;

/// One constant of an exported law: a fitted (or fixed) parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct LawParam {
    /// Name, as in the model's parameter list.
    pub name: String,
    /// Value.
    pub value: f64,
    /// Unit, as the report gives it (a level fitted without a normal force is in N).
    pub unit: String,
    /// Standard error (`None` for fixed or unidentifiable parameters).
    pub std_error: Option<f64>,
    /// Whether it was fitted.
    pub free: bool,
    /// One-line meaning.
    pub description: String,
}

/// A fitted law with what its exported source says about it.
#[derive(Debug)]
pub struct LawDescription {
    /// Registry name (`lugre`).
    pub model: String,
    /// The law's one-line equation.
    pub equation: String,
    /// Where the law comes from in the literature.
    pub reference: String,
    /// Its constants, in the law's parameter order.
    pub params: Vec<LawParam>,
    /// Its code: states, step and force.
    pub code: LawCode,
    /// The records it was fitted to.
    pub records: Vec<String>,
    /// Which report it came from (a path, or `a fit`), and how it was chosen there.
    pub source: String,
    /// The quantity the fit compared (`force`, `velocity`, ...).
    pub compared: String,
    /// A rotary axis (rad, N m) rather than a linear one (m, N).
    pub rotary: bool,
    /// Fitted without a normal force: the levels are forces, call with n = 1.
    pub levels_as_forces: bool,
    /// The largest speed of the records \[m/s\], when the report gives it.
    pub max_speed: Option<f64>,
    /// The oscillator's normal force \[N\], when the report gives one.
    pub normal_force: Option<f64>,
    /// frictionid's version.
    pub version: &'static str,
    /// The law itself (for the compensation table).
    pub law: Box<dyn FrictionModel>,
}

fn missing(key: &str, reason: &str) -> ExportError {
    ExportError::Report {
        key: key.into(),
        reason: reason.into(),
    }
}

/// The fit a report holds: a fit report's own object, or a comparison's recommended law
/// (the verdict's `recommended`, else its `simplest`, else the best-ranked), with how it was chosen.
fn chosen_fit(report: &Value) -> Result<(&Value, String), ExportError> {
    let Some(ranking) = report.get("ranking") else {
        return Ok((report, String::new()));
    };
    let ranking = ranking
        .as_array()
        .filter(|r| !r.is_empty())
        .ok_or_else(|| missing("ranking", "no fitted law (the ranking is empty)"))?;
    let model_of = |f: &Value| f.get("model").and_then(Value::as_str).map(str::to_string);
    let simplest = report
        .pointer("/verdict/recommended")
        .and_then(Value::as_str)
        .or_else(|| report.pointer("/verdict/simplest").and_then(Value::as_str))
        .and_then(|name| {
            ranking
                .iter()
                .find(|f| model_of(f).as_deref() == Some(name))
        });
    Ok(match simplest {
        Some(fit) => (fit, "the comparison's recommended law".into()),
        None => (&ranking[0], "the comparison's best-ranked law".into()),
    })
}

fn as_f64(v: Option<&Value>) -> Option<f64> {
    v.and_then(Value::as_f64).filter(|x| x.is_finite())
}

/// The report's entries of `parameters`, by name: (unit, std error, free).
fn report_param<'a>(fit: &'a Value, name: &str) -> Option<&'a Value> {
    fit.get("parameters")?
        .as_array()?
        .iter()
        .find(|p| p.get("name").and_then(Value::as_str) == Some(name))
}

/// The reference of a built-in law.
fn reference(model: &str) -> &'static str {
    match model {
        "none" => "no friction contact",
        "coulomb" => "C.-A. de Coulomb, Theorie des machines simples (1785)",
        "viscous_coulomb" | "stribeck" => {
            "B. Armstrong-Helouvry, P. Dupont, C. Canudas de Wit, A survey of models, analysis tools and compensation methods for the control of machines with friction, Automatica 30(7), 1994"
        }
        "makkar" => {
            "C. Makkar, W. E. Dixon, W. G. Sawyer, G. Hu, A new continuously differentiable friction model for control systems design, IEEE/ASME AIM 2005, pp. 600-605"
        }
        "dahl" => {
            "P. R. Dahl, A solid friction model, The Aerospace Corporation, TOR-0158(3107-18)-1, 1968"
        }
        "lugre" => {
            "C. Canudas de Wit, H. Olsson, K. J. Astrom, P. Lischinsky, A new model for control of systems with friction, IEEE Trans. Automatic Control 40(3), 419-425, 1995"
        }
        "gms" => {
            "F. Al-Bender, V. Lampaert, J. Swevers, The generalized Maxwell-slip model, IEEE Trans. Automatic Control 50(11), 1883-1887, 2005"
        }
        _ => "a formula given in the configuration",
    }
}

impl LawDescription {
    /// The description of a fitted law.
    pub fn from_fit(fit: &FitResult) -> Result<Self, ExportError> {
        let value = fit_json(fit).map_err(|e| missing("model_parameters", &e.to_string()))?;
        Self::from_report(&value, "a fit")
    }

    /// The description of the law in report.json's value `report` (a fit, or a comparison's
    /// recommended law); `source` names the report.
    pub fn from_report(report: &Value, source: &str) -> Result<Self, ExportError> {
        let (fit, chosen) = chosen_fit(report)?;
        let parameters = fit
            .get("model_parameters")
            .ok_or_else(|| missing("model_parameters", "no fitted law in this report"))?;
        let model = parameters
            .get("type")
            .and_then(Value::as_str)
            .ok_or_else(|| missing("model_parameters.type", "missing"))?;
        if !EXPORTABLE.contains(&model) {
            return Err(ExportError::NotExportable(model.to_string()));
        }
        // Not `build_json`: its checks refuse a fitted value a rounding beyond a bound.
        let law: Box<dyn FrictionModel> = serde_json::from_value(parameters.clone())
            .map_err(|e| missing("model_parameters", &e.to_string()))?;
        let info = law.param_info();
        let values = law.params();
        let names: Vec<String> = info.iter().map(|i| i.name.clone()).collect();
        let formula = parameters.get("force").and_then(Value::as_str);
        let code = law_code(
            &Params {
                model,
                names: &names,
                values: &values,
            },
            formula,
        )?;
        let mut levels_as_forces = false;
        let params = info
            .iter()
            .zip(&values)
            .map(|(i, &value)| {
                let entry = report_param(fit, &i.name);
                let unit = entry
                    .and_then(|e| e.get("unit"))
                    .and_then(Value::as_str)
                    .unwrap_or(&i.unit)
                    .to_string();
                if i.unit == "1" && unit.starts_with('N') {
                    levels_as_forces = true;
                }
                LawParam {
                    name: i.name.clone(),
                    value,
                    unit,
                    std_error: as_f64(entry.and_then(|e| e.get("std_error"))),
                    free: entry
                        .and_then(|e| e.get("free"))
                        .and_then(Value::as_bool)
                        .unwrap_or(false),
                    description: i.description.clone(),
                }
            })
            .collect();
        let records: Vec<&Value> = fit
            .get("records")
            .and_then(Value::as_array)
            .map(|r| r.iter().collect())
            .unwrap_or_default();
        let max_speed = records
            .iter()
            .filter_map(|r| as_f64(r.get("max_speed")))
            .reduce(f64::max);
        let source = if chosen.is_empty() {
            source.to_string()
        } else {
            format!("{chosen} in {source}")
        };
        Ok(Self {
            model: model.to_string(),
            equation: law.equation(),
            reference: reference(model).to_string(),
            params,
            code,
            records: records
                .iter()
                .filter_map(|r| r.get("file").and_then(Value::as_str))
                .map(str::to_string)
                .collect(),
            source,
            compared: fit
                .get("compared")
                .and_then(Value::as_str)
                .unwrap_or("?")
                .to_string(),
            rotary: fit.pointer("/oscillator/axis").and_then(Value::as_str) == Some("rotary"),
            levels_as_forces,
            max_speed,
            normal_force: as_f64(fit.pointer("/oscillator/normal_force")).filter(|n| *n > 0.0),
            version: env!("CARGO_PKG_VERSION"),
            law,
        })
    }

    /// The units of (velocity, force, normal force).
    pub fn units(&self) -> (&'static str, &'static str, &'static str) {
        if self.rotary {
            ("rad/s", "N m", "N")
        } else {
            ("m/s", "N", "N")
        }
    }

    /// The lines every exported file opens with (without comment markers).
    pub fn header(&self, language: &str) -> Vec<String> {
        let (vu, fu, nu) = self.units();
        let mut lines = vec![
            format!(
                "Friction law `{}` exported by frictionid {} as {language}.",
                self.model, self.version
            ),
            String::new(),
            format!("Equation:  {}", self.equation),
            format!("Reference: {}", self.reference),
            format!(
                "Fitted to: {} (compared quantity: {}; from {})",
                if self.records.is_empty() {
                    "-".to_string()
                } else {
                    self.records.join(", ")
                },
                self.compared,
                self.source
            ),
            format!(
                "Axis:      {} (v in {vu}, n in {nu}, dt in s, force in {fu})",
                if self.rotary { "rotary" } else { "linear" }
            ),
        ];
        if self.levels_as_forces {
            lines.push(format!(
                "Normal force: the fit had none, so its levels are forces in {fu}: call \
                 update and force with n = 1 (the engine's convention)."
            ));
        } else {
            lines.push(format!(
                "Normal force: the levels are coefficients of n; pass the normal force in {nu}."
            ));
        }
        lines.extend([
            format!("States:    {}", self.code.state_doc),
            format!("Step:      {}", self.code.step_doc),
            String::new(),
            "Replaying a record (the engine's convention): init; F[0] = force(v[0], n[0]);".into(),
            "for i >= 1: update((v[i-1] + v[i]) / 2, (n[i-1] + n[i]) / 2, t[i] - t[i-1]),".into(),
            "then F[i] = force(v[i], n[i]). The states start at rest (0).".into(),
        ]);
        lines
    }

    /// The [`header`](Self::header) for `language` as comment lines led by `lead`.
    pub fn commented_header(&self, language: &str, lead: &str) -> String {
        let empty = format!("{lead} \n");
        let bare = format!("{lead}\n");
        self.header(language)
            .iter()
            .map(|l| format!("{lead} {l}\n").replace(&empty, &bare))
            .collect()
    }

    /// The comment of parameter `p`: unit, standard error, fitted or fixed, meaning.
    pub fn param_comment(p: &LawParam) -> String {
        let se = p.std_error.map_or("-".to_string(), |s| format!("{s:.3e}"));
        format!(
            "[{}] std error {se}, {}: {}",
            p.unit,
            if p.free { "fitted" } else { "fixed" },
            p.description
        )
    }

    /// Whether the law's code calls `f`.
    pub fn uses(&self, f: Func) -> bool {
        let code = &self.code;
        let calls = |e: &Expr| matches!(e, Expr::Call(g, _) if *g == f);
        code.update
            .iter()
            .chain(&code.force)
            .any(|s| stmt_uses(s, &calls))
    }
}

/// Whether `stmts` read the input or state `leaf` (`Expr::V`, `Expr::N`, `Expr::Dt`, or any
/// state for `Expr::State(_)`).
pub(super) fn reads(stmts: &[Stmt], leaf: &Expr) -> bool {
    let is = |e: &Expr| match (e, leaf) {
        (Expr::State(_), Expr::State(_)) => true,
        _ => e == leaf,
    };
    stmts.iter().any(|s| stmt_uses(s, &is))
}

fn stmt_uses(s: &Stmt, f: &dyn Fn(&Expr) -> bool) -> bool {
    match s {
        Stmt::Let(_, e) | Stmt::Var(_, e) | Stmt::Assign(_, e) | Stmt::SetState(_, e) => {
            expr_uses(e, f)
        }
        Stmt::Return(e) => e.as_ref().is_some_and(|e| expr_uses(e, f)),
        Stmt::If(c, a, b) => cond_uses(c, f) || a.iter().chain(b).any(|s| stmt_uses(s, f)),
        Stmt::Block(b) => b.iter().any(|s| stmt_uses(s, f)),
        Stmt::Repeat(n, b) => expr_uses(n, f) || b.iter().any(|s| stmt_uses(s, f)),
        Stmt::Comment(_) => false,
    }
}

fn cond_uses(c: &Cond, f: &dyn Fn(&Expr) -> bool) -> bool {
    match c {
        Cond::Cmp(_, a, b) => expr_uses(a, f) || expr_uses(b, f),
        Cond::And(a, b) | Cond::Or(a, b) => cond_uses(a, f) || cond_uses(b, f),
        Cond::Not(a) => cond_uses(a, f),
    }
}

fn expr_uses(e: &Expr, f: &dyn Fn(&Expr) -> bool) -> bool {
    if f(e) {
        return true;
    }
    match e {
        Expr::Call(_, args) => args.iter().any(|a| expr_uses(a, f)),
        Expr::Neg(a) => expr_uses(a, f),
        Expr::Bin(_, a, b) => expr_uses(a, f) || expr_uses(b, f),
        Expr::If(c, a, b) => cond_uses(c, f) || expr_uses(a, f) || expr_uses(b, f),
        _ => false,
    }
}

/// A number as a literal every target reads back to the same double (Rust's shortest
/// round-trip form: `0.2`, `100000.0`, `1e-7`).
pub(super) fn literal(x: f64) -> String {
    let text = format!("{x:?}");
    if text.contains(['.', 'e']) {
        text
    } else {
        format!("{text}.0")
    }
}
