//! Reductions over the sections (per-section links and ports seen from their scalar end): the
//! values `S_k = sum_j s_k(j)` computed once per call in one O(n) loop, and the Jacobian of a
//! scalar row `f(.., S_k)` by the chain rule (an arrow-shaped Jacobian: the scalar row depends
//! on every section).
//!
//! In every loop the `let`s that do not depend on the section (the scalar ends' volumes,
//! temperatures, ...) are computed once, before it. The chain rule is split by column: a
//! column of a scalar state or of a parameter gets `df/dS_k * dS_k/dx`, where `dS_k/dx =
//! sum_j ds_k(j)/dx` is itself a sum, accumulated in one loop before the rows and added to
//! the row's own entry of that column (one triplet per entry); a column of section `j`
//! gets `df/dS_k * ds_k(j)/dx_j` in a loop over the sections (one triplet per section).

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::canon::reciprocal_form;
use super::layout::Layout;
use super::rows::Output;
use crate::expr::emit::emit_split;
use crate::expr::{Arena, At, Id, Sym};

fn sum_ident(k: usize) -> Ident {
    format_ident!("__sum{}", k)
}

/// Whether a symbol changes with the section `j` of a loop.
fn varies(s: Sym) -> bool {
    matches!(s, Sym::Index | Sym::State(_, At::Rel(_)))
}

/// Whether `s` is a column of `what` that does not change with the section.
fn fixed_column(what: Output, s: Sym) -> bool {
    match (what, s) {
        (Output::StateJacobian, Sym::State(_, at)) => !matches!(at, At::Rel(_)),
        (Output::ParamJacobian, Sym::Param(_)) => true,
        _ => false,
    }
}

/// `let mut __sum0 = 0.0; ..; for j in 0..n { __sum0 += s_0(j); .. }` (empty without sums).
pub fn prologue(arena: &Arena, lay: &Layout, private: &TokenStream) -> TokenStream {
    if lay.sys.sums.is_empty() {
        return TokenStream::new();
    }
    sum_loop(arena, lay, &lay.sys.sums, 0, private)
}

/// `__sum{first + i} = sum_j templates[i](j)`, the section-independent `let`s before the loop.
fn sum_loop(
    arena: &Arena,
    lay: &Layout,
    templates: &[Id],
    first: usize,
    private: &TokenStream,
) -> TokenStream {
    let leaf = |s: Sym| lay.leaf(s);
    let (arena, templates) = reciprocal_form(arena, templates);
    let b = emit_split(&arena, &templates, &leaf, private, &varies);
    let (outer, inner, outs) = (b.outer, b.inner, b.outputs);
    let ids: Vec<Ident> = (first..first + outs.len()).map(sum_ident).collect();
    quote! {
        #(let mut #ids: f64 = 0.0;)*
        {
            #(#outer)*
            for j in 0..n {
                let jf = j as f64;
                let _ = jf;
                #(#inner)*
                #(#ids += #outs;)*
            }
        }
    }
}

/// The derivatives of the sums along the columns that do not change with the section, and
/// the loop that accumulates them.
pub struct SumGradients {
    /// The loop that accumulates them (`__sum{K}` after the sums themselves).
    pub code: TokenStream,
    pub grads: SumGrads,
}

/// The derivatives of the sums along the columns that do not change with the section: each a
/// sum of its own, `Sym::Sum(K)` over a template of [`SumGrads::templates`].
pub struct SumGrads {
    /// `(k, column, dS_k/dcolumn as the symbol Sum(K))`.
    grads: Vec<(u32, Sym, Id)>,
    /// The templates of the new sums, `Sym::Sum(first + i)` for `templates[i]`.
    pub templates: Vec<Id>,
}

impl SumGrads {
    /// `dS_k/ds` (the symbol of its accumulator), if nonzero.
    fn get(&self, k: u32, s: Sym) -> Option<Id> {
        let found = self.grads.iter().find(|g| g.0 == k && g.1 == s);
        found.map(|g| g.2)
    }

    /// The columns of `what` that the sums in `row` add to it, in order.
    fn columns(&self, arena: &Arena, row: Id) -> Vec<Sym> {
        let sums = sums_of(arena, row);
        let mut out: Vec<Sym> = Vec::new();
        for g in self.grads.iter().filter(|g| sums.contains(&g.0)) {
            if !out.contains(&g.1) {
                out.push(g.1);
            }
        }
        out
    }

    /// `df/ds` with the sums' part: `df/ds + sum_k df/dS_k dS_k/ds`.
    pub fn total(&self, arena: &mut Arena, row: Id, s: Sym, partial: Id) -> Id {
        let mut d = partial;
        for k in sums_of(arena, row) {
            if let Some(g) = self.get(k, s) {
                let dk = arena.diff(row, Sym::Sum(k));
                let term = arena.mul(dk, g);
                d = arena.add(d, term);
            }
        }
        d
    }

    /// The columns of `row`: its own, then those only its sums depend on.
    pub fn row_columns(&self, arena: &Arena, row: Id) -> Vec<Sym> {
        let mut cols = arena.symbols(row);
        for s in self.columns(arena, row) {
            if !cols.contains(&s) {
                cols.push(s);
            }
        }
        cols
    }
}

fn sums_of(arena: &Arena, row: Id) -> Vec<u32> {
    let syms = arena.symbols(row);
    syms.into_iter()
        .filter_map(|s| if let Sym::Sum(k) = s { Some(k) } else { None })
        .collect()
}

/// The sums' derivatives along the fixed columns of `what`, for the sums that `rows` use.
pub fn gradients(
    arena: &mut Arena,
    lay: &Layout,
    rows: &[Id],
    what: Output,
    private: &TokenStream,
) -> SumGradients {
    let first = lay.sys.sums.len();
    let grads = gradient_sums(arena, &lay.sys.sums, rows, what, first);
    let code = if grads.templates.is_empty() {
        TokenStream::new()
    } else {
        sum_loop(arena, lay, &grads.templates, first, private)
    };
    SumGradients { code, grads }
}

/// The sums' derivatives along the fixed columns of `what` for the sums (templates `sums`)
/// that `rows` use, numbered as sums from `first` on.
pub fn gradient_sums(
    arena: &mut Arena,
    sums: &[Id],
    rows: &[Id],
    what: Output,
    first: usize,
) -> SumGrads {
    let mut used: Vec<u32> = Vec::new();
    for &r in rows {
        for k in sums_of(arena, r) {
            if !used.contains(&k) {
                used.push(k);
            }
        }
    }
    used.sort_unstable();
    let (mut templates, mut grads) = (Vec::new(), Vec::new());
    for k in used {
        let template = sums[k as usize];
        for s in arena.symbols(template) {
            if !fixed_column(what, s) {
                continue;
            }
            let g = arena.diff(template, s);
            if arena.as_const(g) == Some(0.0) {
                continue;
            }
            let sym = arena.sym(Sym::Sum((first + templates.len()) as u32));
            templates.push(g);
            grads.push((k, s, sym));
        }
    }
    SumGrads { grads, templates }
}

/// The chain-rule entries of the scalar rows `(row index, expression)` in the columns of the
/// sections: one loop per row and sum (the fixed columns are in the rows' own entries).
pub fn jacobian(
    arena: &mut Arena,
    lay: &Layout,
    rows: &[(TokenStream, Id)],
    what: Output,
    private: &TokenStream,
) -> TokenStream {
    let mut code = TokenStream::new();
    if what != Output::StateJacobian {
        return code;
    }
    for (row, id) in rows {
        for c in chains(arena, &lay.sys.sums, *id) {
            code.extend(one_sum(arena, lay, row, &c, private));
        }
    }
    code
}

/// A scalar row's dependence on the sections through sum `S_k`: the entries `d * ds(j)` in
/// the columns `cols` at every section `j`.
pub struct Chain {
    /// `df/dS_k`, in the row's frame.
    pub d: Id,
    /// The columns of the sections (`Sym::State(block, At::Rel(r))`) with `ds_k(j)/dcol`, in
    /// the array's frame.
    pub cols: Vec<(Sym, Id)>,
}

/// The chains of the scalar row `id` through the sums (templates `sums`), in sum order.
pub fn chains(arena: &mut Arena, sums: &[Id], id: Id) -> Vec<Chain> {
    let mut out = Vec::new();
    for k in sums_of(arena, id) {
        let d = arena.diff(id, Sym::Sum(k));
        if arena.as_const(d) == Some(0.0) {
            continue;
        }
        let template = sums[k as usize];
        let mut cols = Vec::new();
        for s in arena.symbols(template) {
            if !matches!(s, Sym::State(_, At::Rel(_))) {
                continue;
            }
            let ds = arena.diff(template, s);
            if arena.as_const(ds) != Some(0.0) {
                cols.push((s, ds));
            }
        }
        if !cols.is_empty() {
            out.push(Chain { d, cols });
        }
    }
    out
}

/// `{ let __d = df/dS; for j in 0..n { sink.add(row, col(j), __d * ds(j)/dcol); .. } }`.
fn one_sum(
    arena: &mut Arena,
    lay: &Layout,
    row: &TokenStream,
    c: &Chain,
    private: &TokenStream,
) -> TokenStream {
    let mut cols = Vec::new();
    let mut roots = vec![c.d];
    for &(s, ds) in &c.cols {
        if let Sym::State(b, at) = s {
            cols.push(lay.index(b, at));
            roots.push(ds);
        }
    }
    let leaf = |s: Sym| lay.leaf(s);
    let (arena, roots) = reciprocal_form(arena, &roots);
    let b = emit_split(&arena, &roots, &leaf, private, &varies);
    let (outer, inner) = (b.outer, b.inner);
    let (dout, outs) = (&b.outputs[0], &b.outputs[1..]);
    quote! {
        {
            #(#outer)*
            let __d: f64 = #dout;
            for j in 0..n {
                let jf = j as f64;
                let _ = jf;
                #(#inner)*
                #(sink.add(#row, #cols, __d * (#outs));)*
            }
        }
    }
}
