//! Printers: readable text and LaTeX, with named intermediates listed as definitions.
//!
//! A [`Style`](crate::expr::print::Style) decides how leaves and operators look; the traversal
//! (precedence, parentheses, definitions before use) is shared by both styles.

use super::arena::Arena;
use super::node::{Func, Id, Node, Sym};

/// Output flavour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    Text,
    Latex,
}

const P_ADD: u8 = 1;
const P_MUL: u8 = 2;
const P_NEG: u8 = 3;
const P_POW: u8 = 4;
const P_ATOM: u8 = 5;

/// Prints expressions of one arena with a symbol namer.
pub struct Printer<'a> {
    arena: &'a Arena,
    style: Style,
    namer: &'a dyn Fn(Sym) -> String,
}

impl<'a> Printer<'a> {
    /// A printer; `namer` gives each symbol's display name (plain text; LaTeX is derived).
    pub fn new(arena: &'a Arena, style: Style, namer: &'a dyn Fn(Sym) -> String) -> Self {
        Self {
            arena,
            style,
            namer,
        }
    }

    /// One expression; named subexpressions appear by name.
    pub fn expr(&self, id: Id) -> String {
        self.go(id).0
    }

    /// Definitions of the named quantities under `roots`, inner ones first, as `(name, body)`.
    pub fn definitions(&self, roots: &[Id]) -> Vec<(String, String)> {
        let mut order = Vec::new();
        let mut seen = std::collections::HashSet::new();
        for &r in roots {
            self.collect_named(r, &mut seen, &mut order);
        }
        order
            .into_iter()
            .map(|id| match *self.arena.node(id) {
                Node::Named(n, body) => (self.ident(self.arena.name(n)), self.go(body).0),
                _ => unreachable!("only named nodes are collected"),
            })
            .collect()
    }

    fn collect_named(&self, id: Id, seen: &mut std::collections::HashSet<Id>, out: &mut Vec<Id>) {
        if !seen.insert(id) {
            return;
        }
        for c in self.arena.node(id).children() {
            self.collect_named(c, seen, out);
        }
        if matches!(self.arena.node(id), Node::Named(..)) {
            out.push(id);
        }
    }

    /// A name in this style (`P_hot` -> `P_{\mathrm{hot}}` in LaTeX).
    pub fn ident(&self, name: &str) -> String {
        match self.style {
            Style::Text => name.to_string(),
            Style::Latex => latex_ident(name),
        }
    }

    /// Returns the printed text and its precedence.
    fn go(&self, id: Id) -> (String, u8) {
        let a = self.arena;
        match *a.node(id) {
            Node::Named(n, _) => (self.ident(a.name(n)), P_ATOM),
            Node::Const(bits) => self.number(f64::from_bits(bits)),
            Node::Sym(s) => (self.ident(&(self.namer)(s)), P_ATOM),
            Node::Add(x, y) => (
                format!("{} + {}", self.wrap(x, P_ADD), self.wrap(y, P_ADD)),
                P_ADD,
            ),
            Node::Sub(x, y) => (
                format!("{} - {}", self.wrap(x, P_ADD), self.wrap(y, P_MUL)),
                P_ADD,
            ),
            Node::Mul(x, y) => (self.product(x, y), P_MUL),
            Node::Div(x, y) => (self.quotient(x, y), self.div_prec()),
            Node::Neg(x) => (format!("-{}", self.wrap(x, P_MUL)), P_NEG),
            Node::Powi(x, k) => (self.power(x, &k.to_string()), P_POW),
            Node::Powf(x, y) => (self.power(x, &self.go(y).0), P_POW),
            Node::Func(f, x) => (self.call(f, x), P_ATOM),
        }
    }

    fn wrap(&self, id: Id, min: u8) -> String {
        let (s, p) = self.go(id);
        if p < min {
            match self.style {
                Style::Text => format!("({s})"),
                Style::Latex => format!("\\left({s}\\right)"),
            }
        } else {
            s
        }
    }

    fn number(&self, v: f64) -> (String, u8) {
        if v == std::f64::consts::PI {
            return (
                if self.style == Style::Latex {
                    "\\pi".into()
                } else {
                    "pi".into()
                },
                P_ATOM,
            );
        }
        let s = format_number(v);
        let p = if v < 0.0 { P_NEG } else { P_ATOM };
        match self.style {
            Style::Latex if s.contains('e') => {
                let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
                (format!("{m} \\cdot 10^{{{e}}}"), P_MUL)
            }
            _ => (s, p),
        }
    }

    fn product(&self, x: Id, y: Id) -> String {
        let op = if self.style == Style::Text {
            " * "
        } else {
            " \\, "
        };
        format!("{}{op}{}", self.wrap(x, P_MUL), self.wrap(y, P_MUL + 1))
    }

    fn quotient(&self, x: Id, y: Id) -> String {
        match self.style {
            Style::Text => format!("{} / {}", self.wrap(x, P_MUL), self.wrap(y, P_MUL + 1)),
            Style::Latex => format!("\\frac{{{}}}{{{}}}", self.go(x).0, self.go(y).0),
        }
    }

    fn div_prec(&self) -> u8 {
        if self.style == Style::Latex {
            P_ATOM
        } else {
            P_MUL
        }
    }

    fn power(&self, x: Id, e: &str) -> String {
        match self.style {
            Style::Text => format!("{}^{}", self.wrap(x, P_ATOM), paren_if_signed(e)),
            Style::Latex => format!("{}^{{{e}}}", self.wrap(x, P_ATOM)),
        }
    }

    fn call(&self, f: Func, x: Id) -> String {
        let arg = self.go(x).0;
        match (self.style, f) {
            (Style::Text, _) => format!("{}({arg})", text_func(f)),
            (Style::Latex, Func::Sqrt) => format!("\\sqrt{{{arg}}}"),
            (Style::Latex, Func::Abs) => format!("\\left|{arg}\\right|"),
            (Style::Latex, Func::Sign) => format!("\\operatorname{{sign}}\\left({arg}\\right)"),
            (Style::Latex, _) => format!("\\{}\\left({arg}\\right)", text_func(f)),
        }
    }
}

fn text_func(f: Func) -> &'static str {
    match f {
        Func::Sign => "sign",
        _ => f.name(),
    }
}

fn paren_if_signed(e: &str) -> String {
    if e.starts_with('-') {
        format!("({e})")
    } else {
        e.to_string()
    }
}

/// Shortest text that reads back as the same `f64`.
pub fn format_number(v: f64) -> String {
    let s = format!("{v:?}");
    let s = s.strip_suffix(".0").map(str::to_string).unwrap_or(s);
    if s.contains('e') || s.len() <= 8 {
        return s;
    }
    let e = format!("{v:e}");
    if e.len() < s.len() {
        e
    } else {
        s
    }
}

const GREEK: &[&str] = &[
    "alpha", "beta", "gamma", "delta", "epsilon", "eta", "theta", "kappa", "lambda", "mu", "nu",
    "rho", "sigma", "tau", "phi", "omega",
];

/// `P_hot` -> `P_{\mathrm{hot}}`, `gamma` -> `\gamma`, `mdot_eps` -> `\dot{m}_{\mathrm{eps}}`.
pub fn latex_ident(name: &str) -> String {
    let (head, tail) = match name.split_once('_') {
        Some((h, t)) => (h, Some(t)),
        None => (name, None),
    };
    let head = latex_head(head);
    match tail {
        None => head,
        Some(t) => format!("{head}_{{\\mathrm{{{}}}}}", t.replace('_', ",")),
    }
}

fn latex_head(head: &str) -> String {
    if GREEK.contains(&head) {
        return format!("\\{head}");
    }
    if let Some(base) = head.strip_suffix("dot") {
        if !base.is_empty() {
            return format!("\\dot{{{base}}}");
        }
    }
    if head.chars().count() > 1 && head.chars().skip(1).all(|c| c.is_ascii_lowercase()) {
        let mut c = head.chars();
        let first = c.next().unwrap_or('?');
        return format!("{first}_{{{}}}", c.as_str());
    }
    head.to_string()
}
