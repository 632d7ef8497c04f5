//! The small language an exported law is written in once, and each emitter prints in its own
//! syntax: expressions over the law's constants, the inputs v, n, dt and the states, `let`
//! bindings, state assignments, conditionals and an early return. Every binary operation is
//! kept as the engine evaluates it (operands in the same order, parenthesised by the tree), so
//! the emitted code rounds as the engine does up to the math library.

use frictionid_models::formula::Func as FormulaFunc;

/// A function an expression calls; the emitters name it in their language.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    /// sgn(x) with sgn(0) = sgn(NaN) = 0 (a helper in every emitted file).
    Sgn,
    /// exp(-x), 0 for x > 745.2 (the engine's `decay`; a helper in every emitted file).
    Decay,
    Expm1,
    Ln1p,
    /// The least whole number >= x.
    Ceil,
    /// x^y.
    Pow,
    /// A function of the formula language (abs, exp, ln, the trigonometric and hyperbolic
    /// functions, min, max, atan2), built by [`Func::of_formula`]: its `sign` is [`Func::Sgn`].
    Math(FormulaFunc),
}

impl Func {
    /// The function a formula's call of `f` prints as.
    pub fn of_formula(f: FormulaFunc) -> Func {
        match f {
            FormulaFunc::Sign => Func::Sgn,
            f => Func::Math(f),
        }
    }

    /// The C99 `math.h` name (`Sgn` and `Decay` are the file's helpers): a formula function's
    /// own name but for abs, ln, min and max.
    pub fn c_name(self) -> &'static str {
        match self {
            Func::Sgn | Func::Math(FormulaFunc::Sign) => "sgn",
            Func::Decay => "decay",
            Func::Expm1 => "expm1",
            Func::Ln1p => "log1p",
            Func::Ceil => "ceil",
            Func::Pow => "pow",
            Func::Math(FormulaFunc::Abs) => "fabs",
            Func::Math(FormulaFunc::Ln) => "log",
            Func::Math(FormulaFunc::Min) => "fmin",
            Func::Math(FormulaFunc::Max) => "fmax",
            Func::Math(f) => f.exmex_name(),
        }
    }
}

/// A binary arithmetic operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    Add,
    Sub,
    Mul,
    Div,
}

impl Op {
    /// The operator's symbol (the same in C, Rust and Python).
    pub fn symbol(self) -> &'static str {
        match self {
            Op::Add => "+",
            Op::Sub => "-",
            Op::Mul => "*",
            Op::Div => "/",
        }
    }
}

/// A comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cmp {
    Gt,
    Ge,
    Le,
    Eq,
    Ne,
}

impl Cmp {
    /// The comparison's symbol (the same in C, Rust and Python).
    pub fn symbol(self) -> &'static str {
        match self {
            Cmp::Gt => ">",
            Cmp::Ge => ">=",
            Cmp::Le => "<=",
            Cmp::Eq => "==",
            Cmp::Ne => "!=",
        }
    }
}

/// An expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A number.
    Num(f64),
    /// The law's constant `index` (a fitted parameter, in `LawDescription::params` order).
    Param(usize),
    /// The velocity argument.
    V,
    /// The normal-force argument.
    N,
    /// The interval's duration (in `update` only).
    Dt,
    /// State `index`.
    State(usize),
    /// A local bound by [`Stmt::Let`].
    Local(String),
    Neg(Box<Expr>),
    Bin(Op, Box<Expr>, Box<Expr>),
    Call(Func, Vec<Expr>),
    /// `then` where the condition holds, else `otherwise`.
    If(Box<Cond>, Box<Expr>, Box<Expr>),
}

/// A condition.
#[derive(Debug, Clone, PartialEq)]
pub enum Cond {
    Cmp(Cmp, Expr, Expr),
    And(Box<Cond>, Box<Cond>),
    Or(Box<Cond>, Box<Cond>),
    Not(Box<Cond>),
}

/// A statement.
#[derive(Debug, Clone, PartialEq)]
pub enum Stmt {
    /// Binds a new local (once per name within a function).
    Let(String, Expr),
    /// Sets state `index`.
    SetState(usize, Expr),
    /// Runs `then` where the condition holds, else `otherwise`.
    If(Cond, Vec<Stmt>, Vec<Stmt>),
    /// Leaves the function, with a value in `force` (none in `update`).
    Return(Option<Expr>),
    /// Declares a mutable local with its first value (read where no later `Assign` runs).
    Var(String, Expr),
    /// Sets a local declared by `Var`.
    Assign(String, Expr),
    /// A comment line.
    Comment(String),
    /// Statements whose locals end with them (one GMS element's step).
    Block(Vec<Stmt>),
    /// Runs the statements `count` times (`count` a whole number >= 0).
    Repeat(Expr, Vec<Stmt>),
}

/// The code of one law: its states, the body of `update` (v, n, dt in; states set) and of
/// `force` (v, n in; ends with a `Return`).
#[derive(Debug, Clone, PartialEq)]
pub struct LawCode {
    /// Number of internal states.
    pub n_states: usize,
    /// What each state is (for the generated comments).
    pub state_doc: String,
    /// How `update` steps the states (for the generated comments).
    pub step_doc: String,
    /// The body of `update`.
    pub update: Vec<Stmt>,
    /// The body of `force`.
    pub force: Vec<Stmt>,
}

// Builders, so that the laws read close to their equations.

/// A number.
pub(crate) fn num(x: f64) -> Expr {
    Expr::Num(x)
}

/// Constant `i`.
pub(crate) fn p(i: usize) -> Expr {
    Expr::Param(i)
}

/// A local.
pub(crate) fn local(name: &str) -> Expr {
    Expr::Local(name.to_string())
}

/// State `i`.
pub(crate) fn state(i: usize) -> Expr {
    Expr::State(i)
}

fn bin(op: Op, a: Expr, b: Expr) -> Expr {
    Expr::Bin(op, Box::new(a), Box::new(b))
}

/// a + b.
pub(crate) fn add(a: Expr, b: Expr) -> Expr {
    bin(Op::Add, a, b)
}

/// a - b.
pub(crate) fn sub(a: Expr, b: Expr) -> Expr {
    bin(Op::Sub, a, b)
}

/// a * b.
pub(crate) fn mul(a: Expr, b: Expr) -> Expr {
    bin(Op::Mul, a, b)
}

/// a / b.
pub(crate) fn div(a: Expr, b: Expr) -> Expr {
    bin(Op::Div, a, b)
}

/// -a.
pub(crate) fn neg(a: Expr) -> Expr {
    Expr::Neg(Box::new(a))
}

/// f(a).
pub(crate) fn call(f: Func, a: Expr) -> Expr {
    Expr::Call(f, vec![a])
}

/// f(a, b).
pub(crate) fn call2(f: Func, a: Expr, b: Expr) -> Expr {
    Expr::Call(f, vec![a, b])
}

/// a `cmp` b.
pub(crate) fn cmp(c: Cmp, a: Expr, b: Expr) -> Cond {
    Cond::Cmp(c, a, b)
}

/// a and b.
pub(crate) fn and(a: Cond, b: Cond) -> Cond {
    Cond::And(Box::new(a), Box::new(b))
}

/// a or b.
pub(crate) fn or(a: Cond, b: Cond) -> Cond {
    Cond::Or(Box::new(a), Box::new(b))
}

/// not a.
pub(crate) fn not(a: Cond) -> Cond {
    Cond::Not(Box::new(a))
}

/// `then` where `c` holds, else `otherwise`.
pub(crate) fn cond(c: Cond, then: Expr, otherwise: Expr) -> Expr {
    Expr::If(Box::new(c), Box::new(then), Box::new(otherwise))
}

/// let `name` = `e`.
pub(crate) fn let_(name: &str, e: Expr) -> Stmt {
    Stmt::Let(name.to_string(), e)
}

/// A mutable local `name` starting at `e`.
pub(crate) fn var(name: &str, e: Expr) -> Stmt {
    Stmt::Var(name.to_string(), e)
}

/// `name` = `e` (a local declared by [`var`]).
pub(crate) fn assign(name: &str, e: Expr) -> Stmt {
    Stmt::Assign(name.to_string(), e)
}

/// Sum of the terms, left to right (0 when empty).
pub(crate) fn sum(terms: Vec<Expr>) -> Expr {
    terms.into_iter().reduce(add).unwrap_or(num(0.0))
}
