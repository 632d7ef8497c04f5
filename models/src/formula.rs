//! Formulas for the `expression` model: parsed once, with error positions, into an [`exmex`]
//! flat expression that evaluates fast.
//!
//! The grammar is ordinary mathematical notation:
//!
//! ```text
//! sum     = product (("+" | "-") product)*
//! product = unary (("*" | "/") unary)*
//! unary   = ("-" | "+") unary | power
//! power   = atom (("^" | "**") unary)?          right-associative: 2^3^2 = 2^9
//! atom    = number | name | name "(" sum ("," sum)* ")" | "(" sum ")"
//! ```
//!
//! so `-v^2 = -(v^2)`, `2^-1 = 0.5` and `a/b/c = (a/b)/c`. Numbers accept decimal exponents
//! (`1.0e-4`). Functions: `sign`/`sgn`/`signum` (with sign(0) = 0), `abs`, `exp`, `ln`/`log`
//! (natural), `log10`, `sqrt`, `sin`, `cos`, `tan`, `asin`, `acos`, `atan`, `sinh`, `cosh`,
//! `tanh`, and the two-argument `min`, `max`, `atan2`; the constant `pi`.
//!
//! exmex does the evaluation, but its own parser uses non-standard precedences (`-2^2 = 4`,
//! `2^3^2 = 64`), has no decimal exponents and reports errors without positions. So this module
//! parses the text itself (reporting the column of any error), checks every name, and hands
//! exmex a fully parenthesised canonical text in which every variable is written `{name}`.

use crate::error::ModelError;
use exmex::prelude::*;
use exmex::{BinOp, MakeOperators, Operator};

/// The operators of the formula language handed to exmex: arithmetic, `min`, `max`, `atan2`,
/// `sign` and the functions of [`UNARY`], in this order.
#[derive(Clone, Debug)]
pub struct FormulaOps;

/// A one-argument function exmex evaluates: name and function.
type Unary = (&'static str, fn(f64) -> f64);

/// The one-argument functions other than `sign`.
const UNARY: [Unary; 14] = [
    ("abs", f64::abs),
    ("exp", f64::exp),
    ("ln", f64::ln),
    ("log10", f64::log10),
    ("sqrt", f64::sqrt),
    ("sin", f64::sin),
    ("cos", f64::cos),
    ("tan", f64::tan),
    ("asin", f64::asin),
    ("acos", f64::acos),
    ("atan", f64::atan),
    ("sinh", f64::sinh),
    ("cosh", f64::cosh),
    ("tanh", f64::tanh),
];

/// A two-argument operator exmex evaluates: name, function, priority (higher binds first)
/// and whether it commutes.
type Binary = (&'static str, fn(f64, f64) -> f64, i64, bool);

/// The arithmetic operators without a one-argument form.
const ARITHMETIC: [Binary; 3] = [
    ("^", f64::powf, 4, false),
    ("*", |a, b| a * b, 2, true),
    ("/", |a, b| a / b, 3, false),
];

/// The two-argument functions.
const BINARY_FUNCTIONS: [Binary; 3] = [
    ("min", f64::min, 0, false),
    ("max", f64::max, 0, false),
    ("atan2", f64::atan2, 0, false),
];

fn bin_op((_, apply, prio, is_commutative): Binary) -> BinOp<f64> {
    BinOp {
        apply,
        prio,
        is_commutative,
    }
}

fn binary<'a>(op: &Binary) -> Operator<'a, f64> {
    Operator::make_bin(op.0, bin_op(*op))
}

impl MakeOperators<f64> for FormulaOps {
    fn make<'a>() -> Vec<Operator<'a, f64>> {
        let mut ops: Vec<Operator<'a, f64>> = ARITHMETIC.iter().map(binary).collect();
        ops.push(Operator::make_bin_unary(
            "+",
            bin_op(("+", |a, b| a + b, 0, true)),
            |a| a,
        ));
        ops.push(Operator::make_bin_unary(
            "-",
            bin_op(("-", |a, b| a - b, 1, false)),
            |a| -a,
        ));
        ops.extend(BINARY_FUNCTIONS.iter().map(binary));
        ops.push(Operator::make_unary("sign", crate::model::sgn));
        ops.extend(UNARY.iter().map(|&(name, f)| Operator::make_unary(name, f)));
        ops
    }
}

/// A function callable in a formula.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    Sign,
    Abs,
    Exp,
    Ln,
    Log10,
    Sqrt,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Min,
    Max,
    Atan2,
}

/// Function names as written in formulas (several spellings for some).
const FUNCTIONS: &[(&str, Func)] = &[
    ("sign", Func::Sign),
    ("sgn", Func::Sign),
    ("signum", Func::Sign),
    ("abs", Func::Abs),
    ("exp", Func::Exp),
    ("ln", Func::Ln),
    ("log", Func::Ln),
    ("log10", Func::Log10),
    ("sqrt", Func::Sqrt),
    ("sin", Func::Sin),
    ("cos", Func::Cos),
    ("tan", Func::Tan),
    ("asin", Func::Asin),
    ("acos", Func::Acos),
    ("atan", Func::Atan),
    ("sinh", Func::Sinh),
    ("cosh", Func::Cosh),
    ("tanh", Func::Tanh),
    ("min", Func::Min),
    ("max", Func::Max),
    ("atan2", Func::Atan2),
];

/// Names of constants.
const CONSTANTS: &[(&str, f64)] = &[("pi", std::f64::consts::PI)];

/// Deepest nesting of parentheses and operators accepted (guards the recursive parser).
const MAX_DEPTH: usize = 256;

/// Longest formula accepted \[characters\]. A chain `a + b + c + ...` is not nested but still
/// builds a tree as deep as it is long, which every later pass (compilation, drop) walks
/// recursively; this bound keeps that depth far from the stack limit.
pub const MAX_FORMULA_CHARS: usize = 2000;

impl Func {
    fn lookup(name: &str) -> Option<Func> {
        FUNCTIONS.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
    }

    fn arity(self) -> usize {
        match self {
            Func::Min | Func::Max | Func::Atan2 => 2,
            _ => 1,
        }
    }

    /// The function's canonical name (the one registered with exmex).
    pub fn exmex_name(self) -> &'static str {
        match self {
            Func::Sign => "sign",
            Func::Abs => "abs",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Log10 => "log10",
            Func::Sqrt => "sqrt",
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Asin => "asin",
            Func::Acos => "acos",
            Func::Atan => "atan",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Tanh => "tanh",
            Func::Min => "min",
            Func::Max => "max",
            Func::Atan2 => "atan2",
        }
    }
}

/// Whether `name` is a function or constant of the formula language (so it cannot name a
/// variable or parameter).
pub fn is_reserved(name: &str) -> bool {
    Func::lookup(name).is_some() || CONSTANTS.iter().any(|(n, _)| *n == name)
}

/// Whether `name` is a valid variable name: a letter or `_`, then letters, digits or `_`.
pub fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// A binary operator of a formula.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinKind {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

impl BinKind {
    fn symbol(self) -> &'static str {
        match self {
            BinKind::Add => "+",
            BinKind::Sub => "-",
            BinKind::Mul => "*",
            BinKind::Div => "/",
            BinKind::Pow => "^",
        }
    }
}

/// The syntax tree of a formula (read by translators of a formula into other languages).
#[derive(Debug, Clone, PartialEq)]
pub enum Node {
    Num(f64),
    /// A variable, by name.
    Var(String),
    Neg(Box<Node>),
    Bin(BinKind, Box<Node>, Box<Node>),
    Call(Func, Vec<Node>),
}

impl Node {
    /// The canonical, fully parenthesised exmex text.
    fn emit(&self, out: &mut String) {
        match self {
            Node::Num(x) => out.push_str(&format!("{x}")),
            Node::Var(name) => {
                out.push('{');
                out.push_str(name);
                out.push('}');
            }
            Node::Neg(a) => {
                out.push_str("(-(");
                a.emit(out);
                out.push_str("))");
            }
            Node::Bin(kind, a, b) => {
                out.push_str("((");
                a.emit(out);
                out.push_str(") ");
                out.push_str(kind.symbol());
                out.push_str(" (");
                b.emit(out);
                out.push_str("))");
            }
            Node::Call(f, args) => match args.as_slice() {
                [a] => {
                    out.push_str(f.exmex_name());
                    out.push_str("((");
                    a.emit(out);
                    out.push_str("))");
                }
                [a, b] => {
                    out.push_str("((");
                    a.emit(out);
                    out.push_str(") ");
                    out.push_str(f.exmex_name());
                    out.push_str(" (");
                    b.emit(out);
                    out.push_str("))");
                }
                // The parser checks every arity; no other shape is ever built.
                _ => out.push_str("(0/0)"),
            },
        }
    }

    fn contains_sign_of(&self, var: &str) -> bool {
        match self {
            Node::Num(_) | Node::Var(_) => false,
            Node::Neg(a) => a.contains_sign_of(var),
            Node::Bin(_, a, b) => a.contains_sign_of(var) || b.contains_sign_of(var),
            Node::Call(f, args) => {
                (*f == Func::Sign && args.as_slice().first().is_some_and(|a| a.is_var(var)))
                    || args.iter().any(|a| a.contains_sign_of(var))
            }
        }
    }

    fn is_var(&self, var: &str) -> bool {
        matches!(self, Node::Var(n) if n == var)
            || matches!(self, Node::Neg(a) if matches!(a.as_ref(), Node::Var(n) if n == var))
    }

    /// Replaces `sign(var)` by `replacement` and `sign(-var)` by `-replacement`.
    fn replace_sign_of(&self, var: &str, replacement: &str) -> Node {
        match self {
            Node::Num(_) | Node::Var(_) => self.clone(),
            Node::Neg(a) => Node::Neg(Box::new(a.replace_sign_of(var, replacement))),
            Node::Bin(k, a, b) => Node::Bin(
                *k,
                Box::new(a.replace_sign_of(var, replacement)),
                Box::new(b.replace_sign_of(var, replacement)),
            ),
            Node::Call(Func::Sign, args) if args.len() == 1 => match args.first() {
                Some(Node::Var(n)) if n == var => Node::Var(replacement.to_string()),
                Some(Node::Neg(a)) if matches!(a.as_ref(), Node::Var(n) if n == var) => {
                    Node::Neg(Box::new(Node::Var(replacement.to_string())))
                }
                _ => Node::Call(
                    Func::Sign,
                    args.iter()
                        .map(|a| a.replace_sign_of(var, replacement))
                        .collect(),
                ),
            },
            Node::Call(f, args) => Node::Call(
                *f,
                args.iter()
                    .map(|a| a.replace_sign_of(var, replacement))
                    .collect(),
            ),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Plus,
    Minus,
    Star,
    Slash,
    Caret,
    LParen,
    RParen,
    Comma,
    End,
}

#[derive(Debug, Clone)]
struct Token {
    tok: Tok,
    /// Column of the first character, counted from 1.
    col: usize,
    /// The text as written.
    text: String,
}

/// An error at a column, before the formula text is attached.
struct Located {
    message: String,
    column: usize,
}

fn err<T>(column: usize, message: impl Into<String>) -> Result<T, Located> {
    Err(Located {
        message: message.into(),
        column,
    })
}

/// The end of the run of characters from `i` on that satisfy `keep`.
fn run_end(chars: &[char], mut i: usize, keep: impl Fn(char) -> bool) -> usize {
    while chars.get(i).is_some_and(|&c| keep(c)) {
        i += 1;
    }
    i
}

/// The end of a number's text starting at `start` (digits, a fraction, an exponent).
fn number_end(chars: &[char], start: usize) -> Result<usize, Located> {
    let digit_at = |j: usize| chars.get(j).is_some_and(char::is_ascii_digit);
    let mut i = run_end(chars, start, |c| c.is_ascii_digit());
    if chars.get(i) == Some(&'.') {
        i = run_end(chars, i + 1, |c| c.is_ascii_digit());
    }
    if matches!(chars.get(i), Some('e' | 'E')) {
        let sign = usize::from(matches!(chars.get(i + 1), Some('+' | '-')));
        if digit_at(i + 1 + sign) {
            i = run_end(chars, i + 1 + sign, |c| c.is_ascii_digit());
        } else if sign == 1 {
            return err(start + 1, "malformed number (exponent without digits)");
        }
    }
    Ok(i)
}

/// The number starting at `start`, and where it ends.
fn lex_number(chars: &[char], start: usize) -> Result<(Token, usize), Located> {
    let col = start + 1;
    let end = number_end(chars, start)?;
    let s: String = chars.get(start..end).unwrap_or_default().iter().collect();
    let value: f64 = match s.parse() {
        Ok(v) => v,
        Err(_) => return err(col, format!("malformed number `{s}`")),
    };
    if !value.is_finite() {
        return err(col, format!("number `{s}` is out of range"));
    }
    let token = Token {
        tok: Tok::Num(value),
        col,
        text: s,
    };
    Ok((token, end))
}

/// The name starting at `start`, and where it ends.
fn lex_name(chars: &[char], start: usize) -> (Token, usize) {
    let end = run_end(chars, start, |c| c.is_ascii_alphanumeric() || c == '_');
    let s: String = chars.get(start..end).unwrap_or_default().iter().collect();
    let token = Token {
        tok: Tok::Name(s.clone()),
        col: start + 1,
        text: s,
    };
    (token, end)
}

/// The operator or bracket at `i`, and where it ends.
fn lex_symbol(chars: &[char], i: usize) -> Result<(Token, usize), Located> {
    let c = chars.get(i).copied().unwrap_or(' ');
    let (tok, len) = match c {
        '+' => (Tok::Plus, 1),
        '-' => (Tok::Minus, 1),
        '*' if chars.get(i + 1) == Some(&'*') => (Tok::Caret, 2),
        '*' => (Tok::Star, 1),
        '/' => (Tok::Slash, 1),
        '^' => (Tok::Caret, 1),
        '(' => (Tok::LParen, 1),
        ')' => (Tok::RParen, 1),
        ',' => (Tok::Comma, 1),
        _ => return err(i + 1, format!("unexpected character `{c}`")),
    };
    let token = Token {
        tok,
        col: i + 1,
        text: chars.get(i..i + len).unwrap_or_default().iter().collect(),
    };
    Ok((token, i + len))
}

fn lex(text: &str) -> Result<Vec<Token>, Located> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut i = 0;
    while let Some(&c) = chars.get(i) {
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        let digit_next = chars.get(i + 1).is_some_and(char::is_ascii_digit);
        let (token, end) = if c.is_ascii_digit() || (c == '.' && digit_next) {
            lex_number(&chars, i)?
        } else if c.is_ascii_alphabetic() || c == '_' {
            lex_name(&chars, i)
        } else {
            lex_symbol(&chars, i)?
        };
        tokens.push(token);
        i = end;
    }
    tokens.push(Token {
        tok: Tok::End,
        col: chars.len() + 1,
        text: String::new(),
    });
    Ok(tokens)
}

struct Parser {
    tokens: Vec<Token>,
    pos: usize,
    depth: usize,
    /// Variables in order of first appearance, with that column.
    names: Vec<(String, usize)>,
}

impl Parser {
    fn peek(&self) -> Token {
        self.tokens
            .get(self.pos)
            .or_else(|| self.tokens.last())
            .cloned()
            .unwrap_or(Token {
                tok: Tok::End,
                col: 1,
                text: String::new(),
            })
    }

    fn bump(&mut self) -> Token {
        let t = self.peek();
        if self.pos < self.tokens.len() {
            self.pos += 1;
        }
        t
    }

    fn unexpected<T>(t: &Token, expected: &str) -> Result<T, Located> {
        if t.tok == Tok::End {
            err(
                t.col,
                format!("unexpected end of formula (expected {expected})"),
            )
        } else {
            err(
                t.col,
                format!("unexpected token `{}` (expected {expected})", t.text),
            )
        }
    }

    fn enter(&mut self, col: usize) -> Result<(), Located> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return err(
                col,
                format!("formula nested deeper than {MAX_DEPTH} levels"),
            );
        }
        Ok(())
    }

    fn sum(&mut self) -> Result<Node, Located> {
        let col = self.peek().col;
        self.enter(col)?;
        let sum = self.left_assoc(Self::product, |tok| match tok {
            Tok::Plus => Some(BinKind::Add),
            Tok::Minus => Some(BinKind::Sub),
            _ => None,
        })?;
        self.depth -= 1;
        Ok(sum)
    }

    fn product(&mut self) -> Result<Node, Located> {
        self.left_assoc(Self::unary, |tok| match tok {
            Tok::Star => Some(BinKind::Mul),
            Tok::Slash => Some(BinKind::Div),
            _ => None,
        })
    }

    /// A left-associative chain `operand (op operand)*`, where `op_of` names the operators
    /// of this precedence level.
    fn left_assoc(
        &mut self,
        operand: fn(&mut Self) -> Result<Node, Located>,
        op_of: fn(&Tok) -> Option<BinKind>,
    ) -> Result<Node, Located> {
        let mut left = operand(self)?;
        while let Some(kind) = op_of(&self.peek().tok) {
            self.bump();
            let right = operand(self)?;
            left = Node::Bin(kind, Box::new(left), Box::new(right));
        }
        Ok(left)
    }

    fn unary(&mut self) -> Result<Node, Located> {
        let t = self.peek();
        match t.tok {
            Tok::Minus | Tok::Plus => {
                self.bump();
                self.enter(t.col)?;
                let inner = self.unary()?;
                self.depth -= 1;
                Ok(if t.tok == Tok::Minus {
                    Node::Neg(Box::new(inner))
                } else {
                    inner
                })
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Node, Located> {
        let base = self.atom()?;
        if self.peek().tok == Tok::Caret {
            let t = self.bump();
            self.enter(t.col)?;
            let exponent = self.unary()?;
            self.depth -= 1;
            return Ok(Node::Bin(BinKind::Pow, Box::new(base), Box::new(exponent)));
        }
        Ok(base)
    }

    fn expect_close(&mut self, open_col: usize) -> Result<(), Located> {
        let t = self.bump();
        match t.tok {
            Tok::RParen => Ok(()),
            Tok::End => err(
                t.col,
                format!("missing `)` to close the `(` at column {open_col}"),
            ),
            _ => Self::unexpected(&t, "an operator or `)`"),
        }
    }

    fn atom(&mut self) -> Result<Node, Located> {
        let t = self.bump();
        match t.tok {
            Tok::Num(x) => Ok(Node::Num(x)),
            Tok::LParen => {
                let inner = self.sum()?;
                self.expect_close(t.col)?;
                Ok(inner)
            }
            Tok::Name(name) => {
                if self.peek().tok == Tok::LParen {
                    let open = self.bump();
                    let Some(f) = Func::lookup(&name) else {
                        return err(t.col, format!("unknown function `{name}`"));
                    };
                    let mut args = vec![self.sum()?];
                    while self.peek().tok == Tok::Comma {
                        self.bump();
                        args.push(self.sum()?);
                    }
                    self.expect_close(open.col)?;
                    if args.len() != f.arity() {
                        return err(
                            t.col,
                            format!(
                                "`{name}` takes {} argument{}, got {}",
                                f.arity(),
                                if f.arity() == 1 { "" } else { "s" },
                                args.len()
                            ),
                        );
                    }
                    return Ok(Node::Call(f, args));
                }
                if let Some((_, value)) = CONSTANTS.iter().find(|(n, _)| *n == name) {
                    return Ok(Node::Num(*value));
                }
                if Func::lookup(&name).is_some() {
                    return err(
                        t.col,
                        format!("function `{name}` needs its argument in parentheses"),
                    );
                }
                if !self.names.iter().any(|(n, _)| *n == name) {
                    self.names.push((name.clone(), t.col));
                }
                Ok(Node::Var(name))
            }
            _ => Self::unexpected(&t, "a number, a variable, a function or `(`"),
        }
    }
}

/// A parsed formula, not yet bound to an ordered list of variables.
#[derive(Debug, Clone, PartialEq)]
pub struct Parsed {
    text: String,
    root: Node,
    names: Vec<(String, usize)>,
}

/// Parses `text`; errors carry the column of the offending token.
pub fn parse(text: &str) -> Result<Parsed, ModelError> {
    let locate = |e: Located| ModelError::Formula {
        message: e.message,
        column: e.column,
        formula: text.to_string(),
    };
    let length = text.chars().count();
    if length > MAX_FORMULA_CHARS {
        let head: String = text.chars().take(40).collect();
        return Err(ModelError::Formula {
            message: format!(
                "the formula has {length} characters; at most {MAX_FORMULA_CHARS} are accepted"
            ),
            column: MAX_FORMULA_CHARS + 1,
            formula: format!("{head}..."),
        });
    }
    let tokens = lex(text).map_err(locate)?;
    let mut p = Parser {
        tokens,
        pos: 0,
        depth: 0,
        names: Vec::new(),
    };
    if p.peek().tok == Tok::End {
        return Err(locate(Located {
            message: "empty formula".into(),
            column: 1,
        }));
    }
    let root = p.sum().map_err(locate)?;
    let t = p.peek();
    if t.tok != Tok::End {
        let expected = if t.tok == Tok::RParen {
            "no `)` without a matching `(`"
        } else {
            "an operator"
        };
        return Err(locate(Located {
            message: format!("unexpected token `{}` ({expected})", t.text),
            column: t.col,
        }));
    }
    Ok(Parsed {
        text: text.to_string(),
        root,
        names: p.names,
    })
}

impl Parsed {
    /// The formula as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The syntax tree.
    pub fn root(&self) -> &Node {
        &self.root
    }

    /// The variables the formula uses, in order of first appearance, with that column.
    pub fn variables(&self) -> &[(String, usize)] {
        &self.names
    }

    /// Whether the formula contains `sign(var)` (or `sign(-var)`, or the spellings `sgn` and
    /// `signum`).
    pub fn has_sign_of(&self, var: &str) -> bool {
        self.root.contains_sign_of(var)
    }

    /// The formula with every `sign(var)` replaced by the variable `replacement` (and
    /// `sign(-var)` by `-replacement`). `replacement` need not be a valid identifier: it is
    /// only ever seen by the compiler, so a name a user cannot write avoids every clash.
    pub fn with_sign_of_replaced(&self, var: &str, replacement: &str) -> Parsed {
        let mut names = self.names.clone();
        if self.has_sign_of(var) {
            names.push((replacement.to_string(), 0));
        }
        Parsed {
            text: self.text.clone(),
            root: self.root.replace_sign_of(var, replacement),
            names,
        }
    }

    /// Compiles the formula for evaluation with values given in the order of `variables`.
    /// Every variable the formula uses must be among `variables` (the error names the first
    /// that is not, at its column); `variables` may hold more.
    pub fn compile(&self, variables: &[&str]) -> Result<Formula, ModelError> {
        for (name, col) in &self.names {
            if !variables.contains(&name.as_str()) {
                let known: Vec<&str> = variables
                    .iter()
                    .copied()
                    .filter(|v| is_identifier(v))
                    .collect();
                return Err(ModelError::Formula {
                    message: format!(
                        "unknown variable `{name}` (known: {})",
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ),
                    column: *col,
                    formula: self.text.clone(),
                });
            }
        }
        let mut canonical = String::new();
        self.root.emit(&mut canonical);
        let expr =
            FlatEx::<f64, FormulaOps>::parse(&canonical).map_err(|e| ModelError::Formula {
                message: format!("the evaluator rejected the formula ({e})"),
                column: 1,
                formula: self.text.clone(),
            })?;
        let slots = expr
            .var_names()
            .iter()
            .map(|n| {
                variables
                    .iter()
                    .position(|v| v == n)
                    .ok_or_else(|| ModelError::Formula {
                        message: format!("the evaluator found an unexpected variable `{n}`"),
                        column: 1,
                        formula: self.text.clone(),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Formula { expr, slots })
    }
}

/// A compiled formula: evaluates with the variable values in the order given to
/// [`Parsed::compile`].
#[derive(Debug, Clone)]
pub struct Formula {
    expr: FlatEx<f64, FormulaOps>,
    /// For each exmex variable (in exmex's alphabetical order), its index in the caller's list.
    slots: Vec<usize>,
}

impl Formula {
    /// The value at `values` (indexed like the `variables` of the compilation). A missing
    /// value reads as NaN, so does any evaluation error; nothing panics.
    pub fn eval(&self, values: &[f64]) -> f64 {
        self.eval_by(|i| values.get(i).copied().unwrap_or(f64::NAN))
    }

    /// The value with variable `i` (index into the `variables` of the compilation) read from
    /// `value(i)`: the caller's values go straight into exmex's order, with no intermediate
    /// buffer (and no allocation for up to 16 variables).
    pub fn eval_by(&self, value: impl Fn(usize) -> f64) -> f64 {
        const STACK: usize = 16;
        let n = self.slots.len();
        let result = if n <= STACK {
            let mut buf = [0.0; STACK];
            for (b, &i) in buf.iter_mut().zip(&self.slots) {
                *b = value(i);
            }
            self.expr.eval(buf.get(..n).unwrap_or_default())
        } else {
            let buf: Vec<f64> = self.slots.iter().map(|&i| value(i)).collect();
            self.expr.eval(&buf)
        };
        result.unwrap_or(f64::NAN)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Direct evaluation of the syntax tree: the meaning the parser gave the text.
    fn reference(n: &Node, x: f64, y: f64) -> f64 {
        match n {
            Node::Num(c) => *c,
            Node::Var(name) => match name.as_str() {
                "x" => x,
                "y" => y,
                _ => f64::NAN,
            },
            Node::Neg(a) => -reference(a, x, y),
            Node::Bin(k, a, b) => {
                let (a, b) = (reference(a, x, y), reference(b, x, y));
                match k {
                    BinKind::Add => a + b,
                    BinKind::Sub => a - b,
                    BinKind::Mul => a * b,
                    BinKind::Div => a / b,
                    BinKind::Pow => a.powf(b),
                }
            }
            Node::Call(f, args) => {
                let a = args.first().map_or(f64::NAN, |a| reference(a, x, y));
                let b = args.get(1).map_or(f64::NAN, |b| reference(b, x, y));
                match f {
                    Func::Sign => crate::model::sgn(a),
                    Func::Abs => a.abs(),
                    Func::Exp => a.exp(),
                    Func::Ln => a.ln(),
                    Func::Log10 => a.log10(),
                    Func::Sqrt => a.sqrt(),
                    Func::Sin => a.sin(),
                    Func::Cos => a.cos(),
                    Func::Tan => a.tan(),
                    Func::Asin => a.asin(),
                    Func::Acos => a.acos(),
                    Func::Atan => a.atan(),
                    Func::Sinh => a.sinh(),
                    Func::Cosh => a.cosh(),
                    Func::Tanh => a.tanh(),
                    Func::Min => a.min(b),
                    Func::Max => a.max(b),
                    Func::Atan2 => a.atan2(b),
                }
            }
        }
    }

    /// Valid formulas of x and y mixing every operator without parentheses, so that the
    /// precedence rules decide.
    fn formula_text() -> impl Strategy<Value = String> {
        let leaf = prop_oneof![
            (0u32..40).prop_map(|i| format!("{}", f64::from(i) / 4.0)),
            Just("x".to_string()),
            Just("y".to_string()),
            Just("pi".to_string()),
            Just("2.5e-1".to_string()),
        ];
        leaf.prop_recursive(5, 40, 2, |inner| {
            prop_oneof![
                (
                    inner.clone(),
                    prop::sample::select(vec!["+", "-", "*", "/", "^", "**"]),
                    inner.clone()
                )
                    .prop_map(|(a, op, b)| format!("{a} {op} {b}")),
                inner.clone().prop_map(|a| format!("-{a}")),
                inner.clone().prop_map(|a| format!("({a})")),
                (
                    prop::sample::select(FUNCTIONS.iter().map(|(n, _)| *n).collect::<Vec<_>>()),
                    inner.clone(),
                    inner
                )
                    .prop_map(|(f, a, b)| match Func::lookup(f).map(Func::arity) {
                        Some(2) => format!("{f}({a}, {b})"),
                        _ => format!("{f}({a})"),
                    }),
            ]
        })
    }

    proptest! {
        /// exmex evaluates the canonical text exactly as the parsed tree reads.
        #[test]
        fn compiled_formula_matches_the_syntax_tree(
            text in formula_text(),
            x in -3.0f64..3.0,
            y in prop_oneof![Just(0.0), -2.0f64..2.0],
        ) {
            let parsed = parse(&text).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let f = parsed.compile(&["x", "y"]).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let got = f.eval(&[x, y]);
            let want = reference(&parsed.root, x, y);
            prop_assert!(
                got == want || (got.is_nan() && want.is_nan()),
                "{} at x = {}, y = {}: exmex {} vs tree {}", text, x, y, got, want
            );
        }
    }

    fn eval(text: &str, vars: &[&str], values: &[f64]) -> f64 {
        parse(text).unwrap().compile(vars).unwrap().eval(values)
    }

    #[test]
    fn precedence_is_the_usual_one() {
        assert_eq!(eval("-2^2", &[], &[]), -4.0);
        assert_eq!(eval("2^3^2", &[], &[]), 512.0);
        assert_eq!(eval("2**-1", &[], &[]), 0.5);
        assert_eq!(eval("8/2/2", &[], &[]), 2.0);
        assert_eq!(eval("1-2-3", &[], &[]), -4.0);
        assert_eq!(eval("1 - 2 + 3", &[], &[]), 2.0);
        assert_eq!(eval("2*3/4*5", &[], &[]), 7.5);
        assert_eq!(eval("-(1 + 2) * 3", &[], &[]), -9.0);
        assert_eq!(eval("1.0e-4 + 1e-4 + 2.5E+3 + .5", &[], &[]), 2500.5002);
        assert_eq!(eval("min(3, 1 + 1) + max(-1, -2)", &[], &[]), 1.0);
        assert_eq!(eval("2 * pi", &[], &[]), std::f64::consts::TAU);
    }

    #[test]
    fn variables_in_order_of_appearance_and_alphabetical_slots() {
        let p = parse("zeta * v + a * N").unwrap();
        let names: Vec<&str> = p.variables().iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["zeta", "v", "a", "N"]);
        let f = p.compile(&["v", "N", "zeta", "a"]).unwrap();
        assert_eq!(f.eval(&[2.0, 3.0, 5.0, 7.0]), 5.0 * 2.0 + 7.0 * 3.0);
    }

    #[test]
    fn sign_replacement() {
        let p = parse("m * sgn(v) + sign(-v) + sign(v - 1)").unwrap();
        assert!(p.has_sign_of("v"));
        let q = p.with_sign_of_replaced("v", "#d");
        let f = q.compile(&["v", "m", "#d"]).unwrap();
        // sign(v) -> d, sign(-v) -> -d, sign(v - 1) evaluated normally
        assert_eq!(f.eval(&[0.0, 3.0, 1.0]), 3.0 - 1.0 - 1.0);
        assert_eq!(f.eval(&[-1e-18, 3.0, 1.0]), 3.0 - 1.0 - 1.0);
        assert!(!parse("tanh(v)").unwrap().has_sign_of("v"));
    }

    #[test]
    fn errors_carry_columns() {
        let col = |t: &str| match parse(t).unwrap_err() {
            ModelError::Formula { column, .. } => column,
            e => panic!("{e}"),
        };
        assert_eq!(col("mu * N * tanh(v /)"), 18);
        assert_eq!(col("mu * N $ v"), 8);
        assert_eq!(col("(v + 1"), 7);
        assert_eq!(col("v + 1)"), 6);
        assert_eq!(col("foo(v)"), 1);
        assert_eq!(col("2 * tanh v"), 5);
        assert_eq!(col("min(v)"), 1);
        assert_eq!(col("1e+ * v"), 1);
        assert_eq!(col(""), 1);
        assert_eq!(col("v v"), 3);
        let deep = format!("{}v{}", "(".repeat(1000), ")".repeat(1000));
        assert!(parse(&deep).is_err());
    }
}
