//! Checking and lowering: names resolved, rules enforced, errors collected with
//! the user's spans, and the [`Topology`] built.

use std::collections::HashMap;

use proc_macro2::Span;
use stirling_dsl::expr::{Id, Sym};
use stirling_dsl::topology::{Topology, Vessel};
use syn::spanned::Spanned;
use syn::Ident;

use crate::ast::{Item, ModelAst};
use crate::expr::{convert, Scope};

mod declare;
mod fields;
mod flow;
mod kinematics;
mod links;
mod mechanics;
mod sensors;
mod vessels;
mod walls;

/// Collects errors so that all are reported at once.
#[derive(Default)]
pub(crate) struct Ctxt {
    errors: Vec<syn::Error>,
}

impl Ctxt {
    pub(crate) fn error(&mut self, span: Span, msg: impl std::fmt::Display) {
        self.errors.push(syn::Error::new(span, msg));
    }

    fn finish(self) -> syn::Result<()> {
        let mut it = self.errors.into_iter();
        match it.next() {
            None => Ok(()),
            Some(mut first) => {
                it.for_each(|e| first.combine(e));
                Err(first)
            }
        }
    }
}

/// Check `ast` and build its topology.
pub fn lower(ast: &ModelAst) -> syn::Result<Topology> {
    let mut l = Lower::default();
    l.topo.name = model_name(ast);
    l.topo.doc = ast.doc.clone();
    l.run(ast);
    l.cx.finish()?;
    Ok(l.topo)
}

/// Names the generated functions use for their own locals: a declared name equal to one
/// would shadow it (or be shadowed) in the emitted code.
fn generated_local(name: &str) -> bool {
    let temp = name
        .strip_prefix('t')
        .is_some_and(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()));
    matches!(
        name,
        "p" | "x" | "t" | "u" | "out" | "sink" | "f" | "nf" | "jf"
    ) || temp
        || name.starts_with("o_")
        || name.starts_with("__")
}

fn model_name(ast: &ModelAst) -> String {
    for it in &ast.items {
        if let Item::Name(s) = it {
            return s.value();
        }
    }
    ast.ident.to_string().to_lowercase()
}

#[derive(Default)]
pub(crate) struct Lower {
    pub(crate) cx: Ctxt,
    pub(crate) topo: Topology,
    declared: HashMap<String, Span>,
    params: HashMap<String, u32>,
    lets: HashMap<String, Id>,
    pub(crate) states: HashMap<String, Sym>,
    bodies: HashMap<String, usize>,
    /// Declared cranks and linkages: their index in `Topology::mechanisms`.
    mechanisms: HashMap<String, usize>,
    /// Mechanisms refused at their declaration: faces on them report nothing more.
    refused_mechanisms: std::collections::HashSet<String>,
    pub(crate) vessels: HashMap<String, Vessel>,
    cv_arrays: Vec<bool>,
    /// Declared walls: index and whether an array.
    pub(crate) walls: HashMap<String, (usize, bool)>,
}

impl Lower {
    pub(crate) fn declare(&mut self, id: &Ident) -> bool {
        let name = id.to_string();
        if self.declared.contains_key(&name) {
            self.cx.error(id.span(), format!("duplicate name `{name}`: every parameter, let, state, body, space and CV needs its own name"));
            return false;
        }
        if matches!(name.as_str(), "n" | "pi" | "j") {
            self.cx.error(
                id.span(),
                format!("`{name}` is reserved (`n` sections, `j` section index, `pi`)"),
            );
            return false;
        }
        self.declared.insert(name, id.span());
        true
    }

    /// As [`Lower::declare`], for a name that becomes a local of the generated code
    /// (parameters, lets).
    fn declare_local(&mut self, id: &Ident) -> bool {
        let name = id.to_string();
        if generated_local(&name) {
            self.cx.error(
                id.span(),
                format!("`{name}` is reserved for the generated code (`p`, `x`, `t`, `u`, `out`, `sink`, `f`, `nf`, `jf`, `t0`, `t1`, .., `o_*`, `__*`): choose another name for this parameter or `let`"),
            );
            return false;
        }
        self.declare(id)
    }

    fn run(&mut self, ast: &ModelAst) {
        for it in &ast.items {
            if let Item::Params(ps) = it {
                ps.iter().for_each(|p| self.param(p));
            }
        }
        for it in &ast.items {
            if let Item::Body(b) = it {
                self.declare_body(b);
            }
        }
        for it in &ast.items {
            if let Item::Mechanism(m) = it {
                self.declare_mechanism(m);
            }
        }
        for it in &ast.items {
            if let Item::Space(v) | Item::Cv(v) = it {
                self.declare_vessel(v, matches!(it, Item::Cv(_)));
            }
        }
        for it in &ast.items {
            if let Item::Wall(v) = it {
                self.declare_wall(v);
            }
        }
        // a mechanism's position is bound before any item reads it (parameters only inside)
        for it in &ast.items {
            if let Item::Mechanism(m) = it {
                self.mechanism(m);
            }
        }
        for it in &ast.items {
            match it {
                Item::Let(name, e) => self.let_(name, e),
                Item::Gas(span, f) => self.gas(*span, f),
                Item::Body(b) => self.body(b),
                Item::Coupling(c) => self.coupling(c),
                Item::Space(v) => self.space(v),
                Item::Cv(v) => self.cv(v),
                Item::Wall(v) => self.wall(v),
                Item::Link(l) => self.link(l),
                Item::Name(_)
                | Item::Params(_)
                | Item::Sensor(_)
                | Item::Effect(_)
                | Item::Mechanism(_) => {}
                Item::Free(_, names) => self.free(names),
            }
        }
        for it in &ast.items {
            if let Item::Sensor(s) = it {
                self.sensor(s);
            }
        }
        self.check_space_links(ast);
        if !self.topo.cvs.is_empty() && self.topo.gas.is_none() {
            self.cx.error(ast.ident.span(), "a model with control volumes needs a `gas { R: .., gamma: .., charge: .., mdot_eps: .. }` item");
        }
    }

    /// A link into a space carries its enthalpy, so the space needs a temperature.
    fn check_space_links(&mut self, ast: &ModelAst) {
        let mut bad = Vec::new();
        for l in &self.topo.links {
            for v in [l.from.vessel, l.to.vessel] {
                if let Vessel::Space(s) = v {
                    if self.topo.spaces[s].temperature.is_none() {
                        bad.push(self.topo.spaces[s].name.clone());
                    }
                }
            }
        }
        for name in bad {
            self.cx.error(ast.ident.span(), format!("space `{name}` takes part in a mass-flow link, so it needs `temperature: <expression>`"));
        }
    }

    /// Convert an expression, recording an error (and returning 0) on failure.
    pub(crate) fn expr(&mut self, e: &syn::Expr, index: Option<&str>) -> Id {
        let scope = Scope {
            params: &self.params,
            lets: &self.lets,
            states: &self.states,
            index: index.map(str::to_string),
        };
        match convert(&mut self.topo.arena, &scope, e) {
            Ok(id) => id,
            Err(err) => {
                self.cx.errors.push(err);
                self.topo.arena.num(0.0)
            }
        }
    }

    /// As [`Lower::expr`], and the value must not depend on the motion.
    pub(crate) fn static_expr(&mut self, e: &syn::Expr, index: Option<&str>, what: &str) -> Id {
        let id = self.expr(e, index);
        if self
            .topo
            .arena
            .symbols(id)
            .iter()
            .any(|s| matches!(s, Sym::State(..)))
        {
            self.cx.error(
                e.span(),
                format!("{what} must not depend on the states (positions, velocities)"),
            );
        }
        id
    }

    pub(crate) fn bodies_len(&self) -> usize {
        self.bodies.len()
    }

    pub(crate) fn cvs_len(&self) -> usize {
        self.cv_arrays.len()
    }

    pub(crate) fn is_param(&self, name: &str) -> bool {
        self.params.contains_key(name)
    }

    pub(crate) fn is_param_or_let(&self, name: &str) -> bool {
        self.params.contains_key(name) || self.lets.contains_key(name)
    }

    /// Whether CV number `i` (declaration order) is an array.
    fn is_array_cv(&self, i: usize) -> bool {
        self.cv_arrays.get(i).copied().unwrap_or(false)
    }
}
