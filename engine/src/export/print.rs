//! Printing the export language ([`super::code`]) in a target's syntax: one walk over the
//! tree, each target saying only how it spells a call, a binding, a branch.

use super::code::{Cond, Expr, Func, Stmt};
use super::description::literal;

/// How a target spells the pieces of the export language. The provided methods spell the C
/// family's way (braces, `;`, `&&`, states in `self.z`); a target overrides what it spells
/// otherwise.
pub(super) trait Syntax {
    /// The constants' names, in parameter order.
    fn constants(&self) -> &[String];
    /// A call of `f`.
    fn call(&self, f: Func, args: &[String]) -> String;
    /// `then` if `c` else `otherwise`.
    fn select(&self, c: &str, then: &str, otherwise: &str) -> String;
    /// A new local; `mutable` where it is assigned later.
    fn bind(&self, name: &str, value: &str, mutable: bool) -> String;
    /// A comment line.
    fn comment(&self, text: &str) -> String;
    /// The head of a loop run `count` times.
    fn repeat_head(&self, count: &str) -> String;
    /// Constant `index`.
    fn param(&self, index: usize) -> String {
        self.constants()[index].clone()
    }
    /// State `index` (read or written).
    fn state(&self, index: usize) -> String {
        format!("self.z[{index}]")
    }
    /// The words for and, or, not.
    fn logic(&self) -> [&'static str; 3] {
        ["&&", "||", "!"]
    }
    /// A statement's end (`;` or nothing).
    fn end(&self) -> &'static str {
        ";"
    }
    /// Blocks by braces (C, Rust) rather than by indentation (Python).
    fn braces(&self) -> bool {
        true
    }
    /// The head of an `if`.
    fn if_head(&self, c: &str) -> String {
        format!("if {c} {{")
    }
}

/// An expression, fully parenthesised.
pub(super) fn expr(s: &dyn Syntax, e: &Expr) -> String {
    match e {
        Expr::Num(x) if *x < 0.0 => format!("({})", literal(*x)),
        Expr::Num(x) => literal(*x),
        Expr::Param(i) => s.param(*i),
        Expr::V => "v".into(),
        Expr::N => "n".into(),
        Expr::Dt => "dt".into(),
        Expr::State(i) => s.state(*i),
        Expr::Local(name) => name.clone(),
        Expr::Neg(a) => format!("(-{})", expr(s, a)),
        Expr::Bin(op, a, b) => format!("({} {} {})", expr(s, a), op.symbol(), expr(s, b)),
        Expr::Call(f, args) => {
            let args: Vec<String> = args.iter().map(|a| bare(&expr(s, a)).to_string()).collect();
            s.call(*f, &args)
        }
        Expr::If(c, a, b) => s.select(&cond(s, c), &expr(s, a), &expr(s, b)),
    }
}

/// `text` without the parentheses around all of it, if it has them (the top of an
/// argument, a binding, a return value or a condition needs none; Rust warns about them).
pub(super) fn bare(text: &str) -> &str {
    let Some(inner) = text.strip_prefix('(').and_then(|t| t.strip_suffix(')')) else {
        return text;
    };
    let mut depth = 0i32;
    for c in inner.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ => {}
        }
        if depth < 0 {
            return text;
        }
    }
    inner
}

/// A condition, fully parenthesised.
pub(super) fn cond(s: &dyn Syntax, c: &Cond) -> String {
    let [and, or, not] = s.logic();
    match c {
        Cond::Cmp(op, a, b) => format!("({} {} {})", expr(s, a), op.symbol(), expr(s, b)),
        Cond::And(a, b) => format!("({} {and} {})", cond(s, a), cond(s, b)),
        Cond::Or(a, b) => format!("({} {or} {})", cond(s, a), cond(s, b)),
        Cond::Not(a) => format!("({not}{})", cond(s, a)),
    }
}

/// The names assigned by `Assign` anywhere in `stmts` (their `Var` is mutable).
fn assigned(stmts: &[Stmt], out: &mut Vec<String>) {
    for st in stmts {
        match st {
            Stmt::Assign(name, _) => out.push(name.clone()),
            Stmt::If(_, a, b) => {
                assigned(a, out);
                assigned(b, out);
            }
            Stmt::Block(b) | Stmt::Repeat(_, b) => assigned(b, out),
            _ => {}
        }
    }
}

/// A function body at indentation `depth` (four spaces each).
pub(super) fn body(s: &dyn Syntax, stmts: &[Stmt], depth: usize) -> String {
    let mut out = String::new();
    let mut mutable = Vec::new();
    assigned(stmts, &mut mutable);
    write_stmts(s, stmts, depth, &mutable, &mut out);
    out
}

fn line(out: &mut String, depth: usize, text: &str) {
    out.push_str(&"    ".repeat(depth));
    out.push_str(text);
    out.push('\n');
}

fn write_stmts(s: &dyn Syntax, stmts: &[Stmt], depth: usize, mutable: &[String], out: &mut String) {
    if stmts.is_empty() && !s.braces() {
        line(out, depth, "pass");
    }
    for st in stmts {
        write_stmt(s, st, depth, mutable, out);
    }
}

fn write_stmt(s: &dyn Syntax, st: &Stmt, depth: usize, mutable: &[String], out: &mut String) {
    let end = s.end();
    match st {
        Stmt::Let(name, e) | Stmt::Var(name, e) => {
            let is_mut = matches!(st, Stmt::Var(..)) && mutable.contains(name);
            line(out, depth, &s.bind(name, bare(&expr(s, e)), is_mut));
        }
        Stmt::Assign(name, e) => line(out, depth, &format!("{name} = {}{end}", bare(&expr(s, e)))),
        Stmt::SetState(i, e) => {
            line(
                out,
                depth,
                &format!("{} = {}{end}", s.state(*i), bare(&expr(s, e))),
            );
        }
        Stmt::Return(None) => line(out, depth, &format!("return{end}")),
        Stmt::Return(Some(e)) => line(out, depth, &format!("return {}{end}", bare(&expr(s, e)))),
        Stmt::Comment(text) => line(out, depth, &s.comment(text)),
        Stmt::If(c, then, otherwise) => {
            line(out, depth, &s.if_head(bare(&cond(s, c))));
            write_stmts(s, then, depth + 1, mutable, out);
            if !otherwise.is_empty() {
                line(out, depth, if s.braces() { "} else {" } else { "else:" });
                write_stmts(s, otherwise, depth + 1, mutable, out);
            }
            if s.braces() {
                line(out, depth, "}");
            }
        }
        Stmt::Block(b) if s.braces() => {
            line(out, depth, "{");
            write_stmts(s, b, depth + 1, mutable, out);
            line(out, depth, "}");
        }
        Stmt::Block(b) => write_stmts(s, b, depth, mutable, out),
        Stmt::Repeat(count, b) => {
            line(out, depth, &s.repeat_head(bare(&expr(s, count))));
            write_stmts(s, b, depth + 1, mutable, out);
            if s.braces() {
                line(out, depth, "}");
            }
        }
    }
}
