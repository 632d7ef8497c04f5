//! Each built-in law written once in the export language ([`super::code`]): its `force` and
//! the exact step of its states, with the same operations in the same order as the law's own
//! `force` and `Propagator::propagate` in `frictionid-models`, so that an exported law replays
//! a record as the engine does (`energy::model_force`).

use super::code::*;
use super::ExportError;
use frictionid_models::formula::{self, BinKind, Func as FormulaFunc, Node};

/// The fitted parameters of a law, by name.
pub(crate) struct Params<'a> {
    /// The law's name (for errors).
    pub model: &'a str,
    /// Names, in the law's vector order.
    pub names: &'a [String],
    /// Values, in the same order.
    pub values: &'a [f64],
}

impl Params<'_> {
    /// The index of parameter `name`.
    fn ix(&self, name: &str) -> Result<usize, ExportError> {
        self.names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| ExportError::Report {
                key: "model_parameters".into(),
                reason: format!("model `{}` has no parameter `{name}`", self.model),
            })
    }

    /// The constant `name` as an expression.
    fn p(&self, name: &str) -> Result<Expr, ExportError> {
        self.ix(name).map(p)
    }

    /// The value of `name`.
    fn value(&self, name: &str) -> Result<f64, ExportError> {
        Ok(self.values[self.ix(name)?])
    }
}

/// The code of the law `model` at `params`; `formula` is an expression law's formula.
pub(crate) fn law_code(params: &Params, formula: Option<&str>) -> Result<LawCode, ExportError> {
    match params.model {
        "none" => Ok(static_law(Expr::Num(0.0))),
        "coulomb" => coulomb(params),
        "viscous_coulomb" => viscous_coulomb(params),
        "stribeck" => stribeck(params),
        "makkar" => makkar(params),
        "expression" => expression(params, formula.unwrap_or_default()),
        "dahl" => dahl(params),
        "lugre" => lugre(params),
        "gms" => gms(params),
        other => Err(ExportError::NotExportable(other.to_string())),
    }
}

/// The names of the laws this module writes.
pub(crate) const EXPORTABLE: [&str; 9] = [
    "none",
    "coulomb",
    "viscous_coulomb",
    "stribeck",
    "makkar",
    "expression",
    "dahl",
    "lugre",
    "gms",
];

/// A static law: no states, `update` does nothing, `force` returns `f`.
fn static_law(f: Expr) -> LawCode {
    LawCode {
        n_states: 0,
        state_doc: "none (a static law: the force depends on v and n only)".into(),
        step_doc: "nothing to step".into(),
        update: Vec::new(),
        force: vec![Stmt::Return(Some(f))],
    }
}

fn sgn(e: Expr) -> Expr {
    call(Func::Sgn, e)
}

fn abs(e: Expr) -> Expr {
    call(Func::Math(FormulaFunc::Abs), e)
}

/// mu N sgn(v).
fn coulomb(ps: &Params) -> Result<LawCode, ExportError> {
    Ok(static_law(mul(mul(ps.p("mu")?, Expr::N), sgn(Expr::V))))
}

/// mu N sgn(v) + viscous v.
fn viscous_coulomb(ps: &Params) -> Result<LawCode, ExportError> {
    Ok(static_law(add(
        mul(mul(ps.p("mu")?, Expr::N), sgn(Expr::V)),
        mul(ps.p("viscous")?, Expr::V),
    )))
}

/// a^delta as the Stribeck law computes it: a product for delta = 2, a itself for 1, else pow.
fn stribeck_shape(a: Expr, delta: f64, delta_p: Expr) -> Expr {
    if delta == 2.0 {
        mul(a.clone(), a)
    } else if delta == 1.0 {
        a
    } else {
        call2(Func::Pow, a, delta_p)
    }
}

/// N (mu_c + (mu_s - mu_c) exp(-|v/v_s|^delta)) sgn(v) + viscous v.
fn stribeck(ps: &Params) -> Result<LawCode, ExportError> {
    let a = abs(div(Expr::V, ps.p("v_s")?));
    let shape = stribeck_shape(local("a"), ps.value("delta")?, ps.p("delta")?);
    let coefficient = add(
        ps.p("mu_c")?,
        mul(sub(ps.p("mu_s")?, ps.p("mu_c")?), call(Func::Decay, shape)),
    );
    Ok(LawCode {
        force: vec![
            let_("a", a),
            Stmt::Return(Some(add(
                mul(mul(Expr::N, coefficient), sgn(Expr::V)),
                mul(ps.p("viscous")?, Expr::V),
            ))),
        ],
        ..static_law(Expr::Num(0.0))
    })
}

/// g1 (tanh(g2 v) - tanh(g3 v)) + g4 tanh(g5 v) + g6 v.
fn makkar(ps: &Params) -> Result<LawCode, ExportError> {
    let tanh = |g: &str| -> Result<Expr, ExportError> {
        Ok(call(Func::Math(FormulaFunc::Tanh), mul(ps.p(g)?, Expr::V)))
    };
    Ok(static_law(add(
        add(
            mul(ps.p("g1")?, sub(tanh("g2")?, tanh("g3")?)),
            mul(ps.p("g4")?, tanh("g5")?),
        ),
        mul(ps.p("g6")?, Expr::V),
    )))
}

/// The formula's tree, translated.
fn expression(ps: &Params, text: &str) -> Result<LawCode, ExportError> {
    let parsed = formula::parse(text).map_err(|e| ExportError::Report {
        key: "model_parameters.force".into(),
        reason: e.to_string(),
    })?;
    Ok(static_law(translate(ps, parsed.root())?))
}

/// A formula's node as an export expression: every operator and function of the formula
/// language has a counterpart in C99's math.h, Rust's libm and Python's math.
fn translate(ps: &Params, node: &Node) -> Result<Expr, ExportError> {
    Ok(match node {
        Node::Num(x) => num(*x),
        Node::Var(name) if name == "v" => Expr::V,
        Node::Var(name) if name == "N" => Expr::N,
        Node::Var(name) => ps.p(name)?,
        Node::Neg(a) => neg(translate(ps, a)?),
        Node::Bin(kind, a, b) => {
            let (a, b) = (translate(ps, a)?, translate(ps, b)?);
            match kind {
                BinKind::Add => add(a, b),
                BinKind::Sub => sub(a, b),
                BinKind::Mul => mul(a, b),
                BinKind::Div => div(a, b),
                BinKind::Pow => call2(Func::Pow, a, b),
            }
        }
        Node::Call(f, args) => Expr::Call(
            Func::of_formula(*f),
            args.iter()
                .map(|a| translate(ps, a))
                .collect::<Result<_, _>>()?,
        ),
    })
}

/// `update` returns at once where nothing moves: `no_load` (no sliding force), v = 0 or
/// dt <= 0.
fn return_unless_moving(no_load: Option<Cond>) -> Stmt {
    let still = or(
        cmp(Cmp::Eq, Expr::V, num(0.0)),
        cmp(Cmp::Le, Expr::Dt, num(0.0)),
    );
    Stmt::If(
        match no_load {
            Some(c) => or(c, still),
            None => still,
        },
        vec![Stmt::Return(None)],
        Vec::new(),
    )
}

/// The travel |v| dt of the interval.
fn travel() -> Expr {
    mul(abs(Expr::V), Expr::Dt)
}

/// Dahl: the force is the state; its exact step in r = 1 - F sgn(v) / (mu_c N) over the
/// travel kappa = sigma0 |v| dt / (mu_c N).
fn dahl(ps: &Params) -> Result<LawCode, ExportError> {
    let alpha = ps.value("alpha")?;
    let z = state(0);
    let mut update = vec![
        let_("fc", mul(ps.p("mu_c")?, Expr::N)),
        return_unless_moving(Some(not(cmp(Cmp::Gt, local("fc"), num(0.0))))),
        let_("u", sgn(Expr::V)),
        let_("kappa", div(mul(ps.p("sigma0")?, travel()), local("fc"))),
        let_(
            "r0",
            sub(num(1.0), div(mul(z.clone(), local("u")), local("fc"))),
        ),
    ];
    if alpha == 1.0 {
        update.push(let_(
            "change",
            mul(local("r0"), call(Func::Expm1, neg(local("kappa")))),
        ));
    } else {
        // |r|^(1 - alpha) moves linearly in kappa; r reaches 0 (w >= 1) for alpha < 1.
        let delta = local("delta");
        let w = mul(
            mul(delta.clone(), local("kappa")),
            call(
                Func::Math(FormulaFunc::Exp),
                mul(
                    neg(delta.clone()),
                    call(Func::Math(FormulaFunc::Ln), abs(local("r0"))),
                ),
            ),
        );
        let relaxed = mul(
            local("r0"),
            call(Func::Expm1, div(call(Func::Ln1p, neg(local("w"))), delta)),
        );
        update.extend([
            let_("delta", sub(num(1.0), ps.p("alpha")?)),
            var("change", num(0.0)),
            Stmt::If(
                cmp(Cmp::Ne, local("r0"), num(0.0)),
                vec![
                    let_("w", w),
                    assign(
                        "change",
                        cond(
                            cmp(Cmp::Ge, local("w"), num(1.0)),
                            neg(local("r0")),
                            relaxed,
                        ),
                    ),
                ],
                Vec::new(),
            ),
        ]);
    }
    update.push(Stmt::SetState(
        0,
        sub(
            z.clone(),
            mul(mul(local("u"), local("fc")), local("change")),
        ),
    ));
    Ok(LawCode {
        n_states: 1,
        state_doc: "z[0]: the friction force F [N]".into(),
        step_doc: "exact at constant v and n: r = 1 - F sgn(v) / (mu_c n) relaxes in the travel \
                   kappa = sigma0 |v| dt / (mu_c n) as r0 exp(-kappa) for alpha = 1, else \
                   |r|^(1 - alpha) moves linearly in kappa"
            .into(),
        update,
        force: vec![Stmt::Return(Some(z))],
    })
}

/// LuGre's Stribeck level g(v) = n (mu_c + (mu_s - mu_c) exp(-(v/v_s)^2)), bound to `g`.
fn lugre_g(ps: &Params) -> Result<Vec<Stmt>, ExportError> {
    Ok(vec![
        let_("r", div(Expr::V, ps.p("v_s")?)),
        let_(
            "g",
            mul(
                Expr::N,
                add(
                    ps.p("mu_c")?,
                    mul(
                        sub(ps.p("mu_s")?, ps.p("mu_c")?),
                        call(Func::Decay, mul(local("r"), local("r"))),
                    ),
                ),
            ),
        ),
    ])
}

/// LuGre: the bristle deflection relaxes exponentially in the travel towards g(v) sgn(v) /
/// sigma0; F = sigma0 z + sigma1 dz/dt + sigma2 v.
fn lugre(ps: &Params) -> Result<LawCode, ExportError> {
    let z = state(0);
    let mut update = lugre_g(ps)?;
    update.extend([
        return_unless_moving(Some(not(cmp(Cmp::Gt, local("g"), num(0.0))))),
        let_("x", div(mul(ps.p("sigma0")?, travel()), local("g"))),
        let_("settled", neg(call(Func::Expm1, neg(local("x"))))),
        let_("z_ss", div(mul(sgn(Expr::V), local("g")), ps.p("sigma0")?)),
        Stmt::SetState(
            0,
            add(
                z.clone(),
                mul(sub(local("z_ss"), z.clone()), local("settled")),
            ),
        ),
    ]);
    let mut force = lugre_g(ps)?;
    force.extend([
        let_(
            "z_dot",
            cond(
                cmp(Cmp::Gt, local("g"), num(0.0)),
                sub(
                    Expr::V,
                    div(
                        mul(mul(ps.p("sigma0")?, abs(Expr::V)), z.clone()),
                        local("g"),
                    ),
                ),
                num(0.0),
            ),
        ),
        Stmt::Return(Some(add(
            add(
                mul(ps.p("sigma0")?, z),
                mul(ps.p("sigma1")?, local("z_dot")),
            ),
            mul(ps.p("sigma2")?, Expr::V),
        ))),
    ]);
    Ok(LawCode {
        n_states: 1,
        state_doc: "z[0]: the bristle deflection z [m]".into(),
        step_doc: "exact at constant v and n: z relaxes towards g(v) sgn(v) / sigma0 as \
                   exp(-sigma0 |v| dt / g(v))"
            .into(),
        update,
        force,
    })
}

/// GMS's Stribeck curve s(v) = n (mu_c + (mu_s - mu_c) exp(-|v/v_s|^delta)), bound to `s_v`.
fn gms_s(ps: &Params) -> Result<Vec<Stmt>, ExportError> {
    let power = call2(Func::Pow, abs(div(Expr::V, ps.p("v_s")?)), ps.p("delta")?);
    Ok(vec![let_(
        "s_v",
        mul(
            Expr::N,
            add(
                ps.p("mu_c")?,
                mul(sub(ps.p("mu_s")?, ps.p("mu_c")?), call(Func::Decay, power)),
            ),
        ),
    )])
}

/// tanh(x) for x >= 0 as the GMS step computes it: -expm1(-2x) / (1 + exp(-2x)).
fn gms_tanh(x: Expr) -> Expr {
    div(
        neg(call(Func::Expm1, mul(num(-2.0), x.clone()))),
        add(
            num(1.0),
            call(Func::Math(FormulaFunc::Exp), mul(num(-2.0), x)),
        ),
    )
}

/// An element's load after the travel `rest` from 0.
fn loaded_from_zero(two: bool, rest: Expr) -> Expr {
    if two {
        gms_tanh(rest)
    } else {
        neg(call(Func::Expm1, neg(rest)))
    }
}

/// The change of a loaded element's load y0 > 0 over the travel sigma.
fn loaded_change(two: bool, y0: Expr, sigma: Expr) -> Vec<Stmt> {
    if two {
        vec![
            let_("t", gms_tanh(sigma)),
            let_("den", add(num(1.0), mul(y0.clone(), local("t")))),
            let_(
                "change",
                div(
                    mul(
                        mul(local("t"), sub(num(1.0), y0.clone())),
                        add(num(1.0), y0),
                    ),
                    local("den"),
                ),
            ),
        ]
    } else {
        vec![let_(
            "change",
            mul(neg(sub(num(1.0), y0)), call(Func::Expm1, neg(sigma))),
        )]
    }
}

/// The exact step of element `i` (stiffness `k`, weight `w`), with `s`, `u` and `travel`
/// bound.
fn gms_element_step(i: usize, k: Expr, w: Expr, two: bool) -> Vec<Stmt> {
    let z = state(i);
    let moved = |change: Expr| {
        Stmt::SetState(
            i,
            add(z.clone(), div(mul(local("u"), change), local("rho"))),
        )
    };
    let mut loaded = loaded_change(two, local("y0"), local("sg"));
    loaded.push(moved(local("change")));
    let from_zero = vec![
        let_("y1", loaded_from_zero(two, add(local("y0"), local("sg")))),
        moved(sub(local("y1"), local("y0"))),
    ];
    let stuck = vec![Stmt::SetState(i, add(z.clone(), mul(Expr::V, Expr::Dt)))];
    let unloaded = vec![Stmt::If(
        cmp(Cmp::Le, add(local("y0"), local("sg")), num(0.0)),
        stuck,
        from_zero,
    )];
    let step = Stmt::If(cmp(Cmp::Gt, local("y0"), num(0.0)), loaded, unloaded);
    element_block(i, (k, w), z, step)
}

/// Element `i`'s update: its limit lim = w s_v and, where it is positive, rho = k / lim, the
/// load y0 = u rho z and the travel's sg = rho travel bound, then `step`.
fn element_block(i: usize, (k, w): (Expr, Expr), z: Expr, step: Stmt) -> Vec<Stmt> {
    vec![
        Stmt::Comment(format!("element {}", i + 1)),
        let_("lim", mul(w, local("s_v"))),
        Stmt::If(
            cmp(Cmp::Gt, local("lim"), num(0.0)),
            vec![
                let_("rho", div(k, local("lim"))),
                let_("y0", mul(mul(local("u"), local("rho")), z)),
                let_("sg", mul(local("rho"), local("travel"))),
                step,
            ],
            Vec::new(),
        ),
    ]
}

/// The most RK4 substeps of one element in one update (sharpness other than 1 and 2).
const MAX_SUBSTEPS: f64 = 10000.0;

/// dy/dsigma = 1 - max(0, y)^m at `y`.
fn load_rate(y: Expr, m: Expr) -> Expr {
    sub(
        num(1.0),
        call2(
            Func::Pow,
            call2(Func::Math(FormulaFunc::Max), y, num(0.0)),
            m,
        ),
    )
}

/// The step of element `i` at a sharpness without closed form: stuck while unloaded (exact),
/// then RK4 substeps in the travel (see `gms`'s step documentation).
fn gms_element_substeps(i: usize, k: Expr, w: Expr, m: Expr) -> Vec<Stmt> {
    let z = state(i);
    let h = local("h");
    let at = |half: bool, slope: &str| {
        let step = if half {
            mul(num(0.5), h.clone())
        } else {
            h.clone()
        };
        load_rate(add(local("y"), mul(step, local(slope))), m.clone())
    };
    let stiffness = mul(
        m.clone(),
        call2(
            Func::Pow,
            call2(Func::Math(FormulaFunc::Max), local("y0"), num(1.0)),
            sub(m.clone(), num(1.0)),
        ),
    );
    let substeps = vec![
        let_("k1", load_rate(local("y"), m.clone())),
        let_("k2", at(true, "k1")),
        let_("k3", at(true, "k2")),
        let_("k4", at(false, "k3")),
        assign(
            "y",
            add(
                local("y"),
                mul(
                    div(h.clone(), num(6.0)),
                    add(
                        add(local("k1"), mul(num(2.0), local("k2"))),
                        add(mul(num(2.0), local("k3")), local("k4")),
                    ),
                ),
            ),
        ),
    ];
    let loading = vec![
        var(
            "y",
            call2(Func::Math(FormulaFunc::Max), local("y0"), num(0.0)),
        ),
        let_(
            "rest",
            call2(
                Func::Math(FormulaFunc::Min),
                cond(
                    cmp(Cmp::Gt, local("y0"), num(0.0)),
                    local("sg"),
                    add(local("y0"), local("sg")),
                ),
                add(num(2.0), div(num(60.0), m.clone())),
            ),
        ),
        let_(
            "count",
            call2(
                Func::Math(FormulaFunc::Min),
                call2(
                    Func::Math(FormulaFunc::Max),
                    call(Func::Ceil, div(mul(local("rest"), stiffness), num(0.5))),
                    num(1.0),
                ),
                num(MAX_SUBSTEPS),
            ),
        ),
        let_("h", div(local("rest"), local("count"))),
        Stmt::Repeat(local("count"), substeps),
        Stmt::SetState(
            i,
            add(
                z.clone(),
                div(mul(local("u"), sub(local("y"), local("y0"))), local("rho")),
            ),
        ),
    ];
    let step = Stmt::If(
        and(
            cmp(Cmp::Le, local("y0"), num(0.0)),
            cmp(Cmp::Le, add(local("y0"), local("sg")), num(0.0)),
        ),
        vec![Stmt::SetState(i, add(z.clone(), mul(Expr::V, Expr::Dt)))],
        loading,
    );
    element_block(i, (k, w), z, step)
}

/// A damped element's force k z + sigma dz/dt, its rate v (1 - max(0, sgn(v) rho)^m) bound
/// to `zd_i`.
fn gms_damped_rate(i: usize, k: Expr, w: Expr, sharpness: (f64, Expr)) -> Vec<Stmt> {
    let name = format!("zd_{}", i + 1);
    let (lim, rho, load) = (
        format!("lim_{}", i + 1),
        format!("rho_{}", i + 1),
        format!("load_{}", i + 1),
    );
    let power = if sharpness.0 == 1.0 {
        local(&load)
    } else {
        call2(Func::Pow, local(&load), sharpness.1)
    };
    vec![
        let_(&lim, mul(w, local("s_v"))),
        var(&name, num(0.0)),
        Stmt::If(
            cmp(Cmp::Gt, local(&lim), num(0.0)),
            vec![
                let_(&rho, div(mul(k, state(i)), local(&lim))),
                let_(
                    &load,
                    cond(
                        cmp(Cmp::Ge, Expr::V, num(0.0)),
                        local(&rho),
                        neg(local(&rho)),
                    ),
                ),
                assign(
                    &name,
                    cond(
                        cmp(Cmp::Gt, local(&load), num(0.0)),
                        mul(Expr::V, sub(num(1.0), power)),
                        Expr::V,
                    ),
                ),
            ],
            Vec::new(),
        ),
    ]
}

/// GMS: every element's exact step in its load (sharpness 1: exponential, 2: tanh);
/// F = sum_i (k_i z_i + sigma_i dz_i/dt) + viscous v.
fn gms(ps: &Params) -> Result<LawCode, ExportError> {
    let n = (ps.names.len().saturating_sub(6)) / 3;
    let sharpness = ps.value("sharpness")?;
    let closed = sharpness == 1.0 || sharpness == 2.0;
    let two = sharpness == 2.0;
    let mut update = vec![return_unless_moving(None)];
    update.extend(gms_s(ps)?);
    update.extend([let_("u", sgn(Expr::V)), let_("travel", travel())]);
    let mut force = Vec::new();
    let mut terms = Vec::new();
    let damped: Vec<bool> = (1..=n)
        .map(|i| ps.value(&format!("sigma_{i}")).map(|d| d != 0.0))
        .collect::<Result<_, _>>()?;
    if damped.iter().any(|&d| d) {
        force.extend(gms_s(ps)?);
    }
    for (i, &is_damped) in damped.iter().enumerate() {
        let k = ps.p(&format!("k_{}", i + 1))?;
        let w = ps.p(&format!("w_{}", i + 1))?;
        update.push(Stmt::Block(if closed {
            gms_element_step(i, k.clone(), w.clone(), two)
        } else {
            gms_element_substeps(i, k.clone(), w.clone(), ps.p("sharpness")?)
        }));
        let spring = mul(k.clone(), state(i));
        if is_damped {
            force.extend(gms_damped_rate(i, k, w, (sharpness, ps.p("sharpness")?)));
            let sigma = ps.p(&format!("sigma_{}", i + 1))?;
            terms.push(add(spring, mul(sigma, local(&format!("zd_{}", i + 1)))));
        } else {
            terms.push(spring);
        }
    }
    force.push(Stmt::Return(Some(add(
        sum(terms),
        mul(ps.p("viscous")?, Expr::V),
    ))));
    Ok(LawCode {
        n_states: n,
        state_doc: format!("z[0..{n}]: the deflections z_i of the {n} elements [m]"),
        step_doc: if closed {
            format!(
                "exact at constant v and n: each element's load y = sgn(v) k z / (w s(v)) \
                 sticks while unloaded, then relaxes towards 1 in the travel k |v| dt / \
                 (w s(v)) ({})",
                if two {
                    "tanh, sharpness 2"
                } else {
                    "exponentially, sharpness 1"
                }
            )
        } else {
            format!(
                "sharpness {sharpness} has no closed form (the engine integrates it under \
                 error control): each element's load y = sgn(v) k z / (w s(v)) obeys \
                 dy/dsigma = 1 - max(0, y)^m in the travel sigma = k |v| dt / (w s(v)); it \
                 sticks exactly while unloaded, then classical RK4 substeps of at most 0.5 / \
                 (m max(1, y)^(m-1)) in sigma (stable and accurate to about 1e-6 of the \
                 level; at most {MAX_SUBSTEPS} per update; beyond a travel of 2 + 60 / m the \
                 load has settled at 1 and the rest is not integrated)"
            )
        },
        update,
        force,
    })
}
