//! Rust code emission with common-subexpression elimination.
//!
//! The arena already shares structurally equal nodes; the emitter names every
//! node that has more than one parent among the requested outputs (and every
//! named quantity) with a `let`, in arena (topological) order, and prints each
//! output as an expression over those temporaries.

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

use super::arena::Arena;
use super::node::{Func, Id, Node, Sym};

const P_ADD: u8 = 1;
const P_MUL: u8 = 2;
const P_UNARY: u8 = 3;
const P_ATOM: u8 = 4;

/// The statements and output expressions of one straight-line block.
pub struct Block {
    /// `let` statements, in dependency order.
    pub lets: Vec<TokenStream>,
    /// One expression per requested output.
    pub outputs: Vec<TokenStream>,
}

/// Emit `roots` as one block; `leaf` prints each symbol. `private` is the path of the
/// runtime helpers (`::stirling_dsl::__private`).
pub fn emit_block(
    arena: &Arena,
    roots: &[Id],
    leaf: &dyn Fn(Sym) -> TokenStream,
    private: &TokenStream,
) -> Block {
    let (_, lets, outputs) = emit(arena, roots, leaf, private, None);
    Block { lets, outputs }
}

/// A block for the body of a loop over the sections, split in two: the `let`s that do not
/// depend on a symbol for which `varies` holds (hoisted before the loop), the `let`s that
/// do (inside it), and the outputs.
pub struct SplitBlock {
    pub outer: Vec<TokenStream>,
    pub inner: Vec<TokenStream>,
    pub outputs: Vec<TokenStream>,
}

/// Emit `roots` as one block whose loop-invariant `let`s (no symbol for which `varies`
/// holds among their leaves) are hoisted out of the loop.
pub fn emit_split(
    arena: &Arena,
    roots: &[Id],
    leaf: &dyn Fn(Sym) -> TokenStream,
    private: &TokenStream,
    varies: &dyn Fn(Sym) -> bool,
) -> SplitBlock {
    let (outer, inner, outputs) = emit(arena, roots, leaf, private, Some(varies));
    SplitBlock {
        outer,
        inner,
        outputs,
    }
}

/// Per node: whether it depends on a symbol for which `varies` holds (children come before
/// their parents in the arena).
fn varying(arena: &Arena, varies: &dyn Fn(Sym) -> bool) -> Vec<bool> {
    let mut out = vec![false; arena.len()];
    for i in 0..arena.len() {
        out[i] = match *arena.node(Id(i as u32)) {
            Node::Const(_) => false,
            Node::Sym(s) => varies(s),
            ref n => n.children().iter().any(|c| out[c.index()]),
        };
    }
    out
}

type Lets = Vec<TokenStream>;

fn emit(
    arena: &Arena,
    roots: &[Id],
    leaf: &dyn Fn(Sym) -> TokenStream,
    private: &TokenStream,
    varies: Option<&dyn Fn(Sym) -> bool>,
) -> (Lets, Lets, Vec<TokenStream>) {
    // without `varies` every `let` is an inner one, in arena order
    let vary = match varies {
        Some(v) => varying(arena, v),
        None => vec![true; arena.len()],
    };
    let mut outer = Vec::new();
    let uses = count_uses(arena, roots);
    let mut names: Vec<Option<Ident>> = vec![None; arena.len()];
    let mut taken = std::collections::HashSet::new();
    let mut lets = Vec::new();
    let em = Emitter {
        arena,
        leaf,
        private,
    };
    let preferred = preferred_names(arena, &uses);
    for i in 0..arena.len() {
        let id = Id(i as u32);
        if uses[i] == 0 || !needs_let(arena, id, uses[i]) {
            continue;
        }
        // a named quantity whose value already has a `let` is that `let`
        if let Node::Named(_, inner) = *arena.node(id) {
            if let Some(n) = names[inner.index()].clone() {
                names[i] = Some(n);
                continue;
            }
        }
        let base = preferred[i]
            .clone()
            .unwrap_or_else(|| temp_name(arena, id, lets.len() + outer.len()));
        let name = fresh(base, &mut taken);
        let value = em.go(inner(arena, id), &names).0;
        let stmt = quote! { let #name = #value; };
        if vary[i] {
            lets.push(stmt);
        } else {
            outer.push(stmt);
        }
        names[i] = Some(name);
    }
    let outputs = roots.iter().map(|&r| em.go(r, &names).0).collect();
    (outer, lets, outputs)
}

/// The name of the quantity a shared node is the value of, so that its `let` reads
/// `let T_hot = ...` rather than `let t2 = ...; let T_hot = t2;`.
fn preferred_names(arena: &Arena, uses: &[u32]) -> Vec<Option<String>> {
    let mut out = vec![None; arena.len()];
    for i in 0..arena.len() {
        if let Node::Named(n, inner) = *arena.node(Id(i as u32)) {
            if uses[i] > 0 && out[inner.index()].is_none() {
                out[inner.index()] = Some(sanitize(arena.name(n)));
            }
        }
    }
    out
}

fn inner(arena: &Arena, id: Id) -> Id {
    match *arena.node(id) {
        Node::Named(_, a) => a,
        _ => id,
    }
}

/// Number of parents of each node among the nodes reachable from `roots`
/// (roots count once more, so a root that is also shared gets a name).
fn count_uses(arena: &Arena, roots: &[Id]) -> Vec<u32> {
    let mask = arena.reachable(roots);
    let mut uses = vec![0u32; arena.len()];
    for (i, &m) in mask.iter().enumerate() {
        if m {
            for c in arena.node(Id(i as u32)).children() {
                uses[c.index()] += 1;
            }
        }
    }
    for r in roots {
        uses[r.index()] += 1;
    }
    uses
}

fn needs_let(arena: &Arena, id: Id, uses: u32) -> bool {
    match arena.node(id) {
        Node::Const(_) | Node::Sym(_) => false,
        Node::Named(..) => true,
        Node::Neg(a) => uses > 1 && !matches!(arena.node(*a), Node::Const(_) | Node::Sym(_)),
        _ => uses > 1,
    }
}

fn temp_name(arena: &Arena, id: Id, k: usize) -> String {
    match *arena.node(id) {
        Node::Named(n, _) => sanitize(arena.name(n)),
        _ => format!("t{k}"),
    }
}

fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

fn fresh(base: String, taken: &mut std::collections::HashSet<String>) -> Ident {
    let mut name = base.clone();
    let mut k = 2;
    while !taken.insert(name.clone()) {
        name = format!("{base}_{k}");
        k += 1;
    }
    Ident::new(&name, Span::call_site())
}

struct Emitter<'a> {
    arena: &'a Arena,
    leaf: &'a dyn Fn(Sym) -> TokenStream,
    private: &'a TokenStream,
}

impl Emitter<'_> {
    fn go(&self, id: Id, names: &[Option<Ident>]) -> (TokenStream, u8) {
        if let Some(n) = &names[id.index()] {
            return (quote!(#n), P_ATOM);
        }
        let w = |c: Id, min: u8| self.wrap(c, min, names);
        match *self.arena.node(id) {
            Node::Const(bits) => number(f64::from_bits(bits)),
            Node::Sym(s) => ((self.leaf)(s), P_ATOM),
            Node::Named(_, a) => self.go(a, names),
            Node::Add(a, b) => binary(w(a, P_ADD), quote!(+), w(b, P_ADD), P_ADD),
            Node::Sub(a, b) => binary(w(a, P_ADD), quote!(-), w(b, P_MUL), P_ADD),
            Node::Mul(a, b) => binary(w(a, P_MUL), quote!(*), w(b, P_UNARY), P_MUL),
            Node::Div(a, b) => binary(w(a, P_MUL), quote!(/), w(b, P_UNARY), P_MUL),
            Node::Neg(a) => {
                let a = w(a, P_UNARY);
                (quote!(-#a), P_UNARY)
            }
            Node::Powi(a, k) => {
                let a = w(a, P_ATOM);
                let k = Literal::i32_unsuffixed(k);
                (quote!(#a.powi(#k)), P_ATOM)
            }
            Node::Powf(a, b) => {
                let (a, b) = (w(a, P_ATOM), self.go(b, names).0);
                (quote!(#a.powf(#b)), P_ATOM)
            }
            Node::Func(f, a) => self.call(f, a, names),
        }
    }

    fn call(&self, f: Func, a: Id, names: &[Option<Ident>]) -> (TokenStream, u8) {
        // our own `sign` (`sign(0) = 0`) and `tanh` (inlined, no libm call: expr/tanh.rs)
        if matches!(f, Func::Sign | Func::Tanh) {
            let (arg, private) = (self.go(a, names).0, self.private);
            let m = format_ident!("{}", if f == Func::Sign { "sign" } else { "tanh" });
            return (quote!(#private::#m(#arg)), P_ATOM);
        }
        let arg = self.wrap(a, P_ATOM, names);
        let m = format_ident!("{}", f.name());
        (quote!(#arg.#m()), P_ATOM)
    }

    fn wrap(&self, id: Id, min: u8, names: &[Option<Ident>]) -> TokenStream {
        let (t, p) = self.go(id, names);
        if p < min {
            quote!((#t))
        } else {
            t
        }
    }
}

fn binary(a: TokenStream, op: TokenStream, b: TokenStream, p: u8) -> (TokenStream, u8) {
    (quote!(#a #op #b), p)
}

fn number(v: f64) -> (TokenStream, u8) {
    if v.is_nan() {
        return (quote!(f64::NAN), P_ATOM);
    }
    if v.is_infinite() {
        return if v > 0.0 {
            (quote!(f64::INFINITY), P_ATOM)
        } else {
            (quote!(f64::NEG_INFINITY), P_ATOM)
        };
    }
    let lit = Literal::f64_unsuffixed(v.abs());
    if v < 0.0 {
        (quote!(-#lit), P_UNARY)
    } else {
        (quote!(#lit), P_ATOM)
    }
}

/// Emission of nested blocks that read each other's names: a prologue, then blocks that
/// see its `let`s (and values carried in from outside) and name only what is left.
pub struct Scope<'a> {
    em: Emitter<'a>,
    /// The name of every node computed in an enclosing block.
    names: Vec<Option<Ident>>,
    taken: std::collections::HashSet<String>,
    preferred: Vec<Option<String>>,
    temps: usize,
}

/// What a [`Scope`] has named, to return to after a block.
pub type Saved = (Vec<Option<Ident>>, std::collections::HashSet<String>);

impl<'a> Scope<'a> {
    /// A scope over `arena` with the preferred name of every node.
    pub fn new(
        arena: &'a Arena,
        leaf: &'a dyn Fn(Sym) -> TokenStream,
        private: &'a TokenStream,
        mut preferred: Vec<Option<String>>,
    ) -> Self {
        preferred.resize(arena.len(), None);
        Self {
            em: Emitter {
                arena,
                leaf,
                private,
            },
            names: vec![None; arena.len()],
            taken: Default::default(),
            preferred,
            temps: 0,
        }
    }

    /// The names, to [`Scope::restore`] after a block.
    pub fn save(&self) -> Saved {
        (self.names.clone(), self.taken.clone())
    }

    /// Forget what the block since [`Scope::save`] named.
    pub fn restore(&mut self, s: Saved) {
        (self.names, self.taken) = s;
    }

    /// Reserve a fresh identifier for `id` (its preferred name, else `base`).
    pub fn name(&mut self, id: Id, base: &str) -> Ident {
        let base = self.preferred[id.index()]
            .as_deref()
            .map(sanitize)
            .unwrap_or_else(|| base.to_string());
        let ident = fresh(base, &mut self.taken);
        self.names[id.index()] = Some(ident.clone());
        ident
    }

    /// The arena the scope emits from.
    pub fn arena(&self) -> &'a Arena {
        self.em.arena
    }

    /// Read `id` as `name` in this scope.
    pub fn set(&mut self, id: Id, name: &Ident) {
        self.names[id.index()] = Some(name.clone());
    }

    /// Whether `id` has a name in this scope.
    pub fn is_named(&self, id: Id) -> bool {
        self.names[id.index()].is_some()
    }

    /// Whether `id` has a preferred name.
    pub fn has_preferred(&self, id: Id) -> bool {
        self.preferred[id.index()].is_some()
    }

    /// Parents of every node reachable from `roots` without entering named nodes (a root
    /// counts once more).
    pub fn uses(&self, roots: &[Id]) -> Vec<u32> {
        let arena = self.em.arena;
        let mut uses = vec![0u32; arena.len()];
        let mut seen = vec![false; arena.len()];
        let mut stack: Vec<Id> = Vec::new();
        for &r in roots {
            uses[r.index()] += 1;
            stack.push(r);
        }
        while let Some(i) = stack.pop() {
            if std::mem::replace(&mut seen[i.index()], true) || self.is_named(i) {
                continue;
            }
            for c in arena.node(i).children() {
                uses[c.index()] += 1;
                stack.push(c);
            }
        }
        uses
    }

    /// Whether a node used `uses` times is worth a `let` of its own (not a constant or a
    /// symbol).
    pub fn worth_a_let(&self, id: Id, uses: u32) -> bool {
        needs_let(self.em.arena, id, uses) || (uses > 0 && self.has_preferred(id))
    }

    /// `let`s, in arena order, for the unnamed nodes with uses that `want` picks.
    pub fn lets(&mut self, uses: &[u32], want: &dyn Fn(Id, u32) -> bool) -> Vec<TokenStream> {
        let mut lets = Vec::new();
        for i in 0..self.em.arena.len() {
            let id = Id(i as u32);
            let trivial = matches!(self.em.arena.node(id), Node::Const(_) | Node::Sym(_));
            if uses[i] == 0 || trivial || self.is_named(id) || !want(id, uses[i]) {
                continue;
            }
            let value = self.em.go(id, &self.names).0;
            let name = self.name(id, &format!("t{}", self.temps));
            self.temps += 1;
            lets.push(quote! { let #name = #value; });
        }
        lets
    }

    /// `id` as an expression over the names in scope.
    pub fn expr(&self, id: Id) -> TokenStream {
        self.em.go(id, &self.names).0
    }
}
