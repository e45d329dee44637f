//! The rows of one generated function as one program over the value-numbered arena
//! ([`Canon`]): a prologue with the scalar rows and everything the sections share that does
//! not depend on the section (computed once), then the sections peeled by variant, so that
//! no `match` runs per section: `j = 0`, a loop over the interior sections, `j = n - 1`
//! (or the only section when `n = 1`). A value of the interior loop that is the previous
//! section's value of another one (a link's flux is the outflow of section `j - 1` and the
//! inflow of section `j`) is carried from one section to the next instead of recomputed.

use std::collections::HashMap;

use proc_macro2::{Ident, TokenStream};
use quote::quote;

use super::canon::{Canon, Reach, Section};
use super::layout::Layout;
use super::rows::Entry;
use crate::expr::emit::Scope;
use crate::expr::{Arena, Id, Node, Sym};

/// The entries of the scalar rows and, with an array, of each variant (`VARIANTS` order).
pub fn program(
    src: &Arena,
    lay: &Layout,
    (scalar, mid): (&[Entry], TokenStream),
    arrays: Option<&[Vec<Entry>; 4]>,
    private: &TokenStream,
) -> TokenStream {
    let mut c = Canon::default();
    let p = import(&mut c, src, scalar, None);
    let Some(arrays) = arrays else {
        let leaf = |s: Sym| lay.leaf(s);
        let mut sc = Scope::new(&c.arena, &leaf, private, c.names());
        let (lets, outs, _) = block(&mut sc, &p, &[]);
        let stores = stores(scalar, &outs);
        return quote! { #(#lets)* #(#stores)* #mid };
    };
    let [s, f, i, l] = [0, 1, 2, 3].map(|k| import(&mut c, src, &arrays[k], None));
    if s == f && f == i && i == l {
        return uniform(&c, lay, (scalar, &p, mid), (&arrays[2], &i), private);
    }
    let s = s
        .iter()
        .map(|&r| c.at(r, Section::Single))
        .collect::<Vec<_>>();
    let f = f
        .iter()
        .map(|&r| c.at(r, Section::First))
        .collect::<Vec<_>>();
    let l = l
        .iter()
        .map(|&r| c.at(r, Section::Last))
        .collect::<Vec<_>>();
    let carried = carries(&c, &i);
    let a_first: Vec<Id> = carried
        .iter()
        .map(|&(_, a)| c.at(a, Section::First))
        .collect();
    let c_last: Vec<Id> = carried
        .iter()
        .map(|&(k, _)| c.at(k, Section::Last))
        .collect();
    let reach = c.reach();
    let leaf = |s: Sym| lay.leaf(s);
    let mut sc = Scope::new(&c.arena, &leaf, private, c.names());
    let carry: Vec<Ident> = carried.iter().map(|&(k, _)| sc.name(k, "carry")).collect();
    let sources: Vec<Id> = carried.iter().map(|&(_, a)| a).collect();
    // the prologue: what the sections share and does not change with the section
    let base = sc.save();
    name_all(&mut sc, &c_last, &carry);
    let inner = [
        [&f[..], &a_first].concat(),
        [&i[..], &sources].concat(),
        l.clone(),
    ];
    let pro = prologue(&mut sc, &reach, &p, &inner, base);
    let p_stores = stores(scalar, &p.iter().map(|&r| sc.expr(r)).collect::<Vec<_>>());
    let single = scoped(&mut sc, |sc| {
        let (lets, outs, _) = block(sc, &s, &[]);
        let st = stores(&arrays[0], &outs);
        quote! { let j: usize = 0; #(#lets)* #(#st)* }
    });
    let first = scoped(&mut sc, |sc| {
        let (lets, outs, init) = block(sc, &f, &a_first);
        let st = stores(&arrays[1], &outs);
        quote! { let j: usize = 0; #(#lets)* #(#st)* #(#carry = #init;)* }
    });
    let interior = scoped(&mut sc, |sc| {
        let (lets, outs, next) = block(sc, &i, &sources);
        let st = stores(&arrays[2], &outs);
        let upd = updates(&carried, &carry, &next);
        let jf = i
            .iter()
            .any(|r| reach[r.index()].index)
            .then(|| quote!(let jf = j as f64;));
        quote! { #jf #(#lets)* #(#st)* #(#upd)* }
    });
    let last = scoped(&mut sc, |sc| {
        name_all(sc, &c_last, &carry);
        let (lets, outs, _) = block(sc, &l, &[]);
        let st = stores(&arrays[3], &outs);
        quote! { let j: usize = n - 1; #(#lets)* #(#st)* }
    });
    quote! {
        #(#pro)*
        #(#p_stores)*
        #mid
        if n == 1 {
            #single
        } else {
            #(let mut #carry: f64;)*
            { #first }
            for j in 1..n - 1 { #interior }
            { #last }
        }
    }
}

/// All variants alike (no links along the array): one loop over every section.
fn uniform(
    c: &Canon,
    lay: &Layout,
    (scalar, p, mid): (&[Entry], &[Id], TokenStream),
    (entries, i): (&[Entry], &[Id]),
    private: &TokenStream,
) -> TokenStream {
    let reach = c.reach();
    let leaf = |s: Sym| lay.leaf(s);
    let mut sc = Scope::new(&c.arena, &leaf, private, c.names());
    let base = sc.save();
    let pro = prologue(&mut sc, &reach, p, &[i.to_vec()], base);
    let p_stores = stores(scalar, &p.iter().map(|&r| sc.expr(r)).collect::<Vec<_>>());
    let (lets, outs, _) = block(&mut sc, i, &[]);
    let st = stores(entries, &outs);
    let jf = i
        .iter()
        .any(|r| reach[r.index()].index)
        .then(|| quote!(let jf = j as f64;));
    quote! {
        #(#pro)*
        #(#p_stores)*
        #mid
        for j in 0..n { #jf #(#lets)* #(#st)* }
    }
}

fn import(c: &mut Canon, src: &Arena, entries: &[Entry], sec: Option<Section>) -> Vec<Id> {
    let ids = entries
        .iter()
        .map(|e| c.import(src, e.id))
        .collect::<Vec<_>>();
    match sec {
        Some(s) => ids.into_iter().map(|r| c.at(r, s)).collect(),
        None => ids,
    }
}

fn name_all(sc: &mut Scope, ids: &[Id], names: &[Ident]) {
    for (&id, name) in ids.iter().zip(names) {
        if !sc.is_named(id) {
            sc.set(id, name);
        }
    }
}

/// Run `f` in a block of its own: its names are forgotten after it.
fn scoped(sc: &mut Scope, f: impl FnOnce(&mut Scope) -> TokenStream) -> TokenStream {
    let saved = sc.save();
    let out = f(sc);
    sc.restore(saved);
    out
}

/// The prologue's `let`s: of the scalar rows `p` and the sections' blocks `inner`
/// (first, interior, last), every value that does not change with the section and is shared
/// by the scalar rows or the interior loop (or by the first and last section), or read by a
/// value of the loop that does change. `base`: the names to return to before naming them.
fn prologue(
    sc: &mut Scope,
    reach: &[Reach],
    p: &[Id],
    inner: &[Vec<Id>],
    base: (Vec<Option<Ident>>, std::collections::HashSet<String>),
) -> Vec<TokenStream> {
    // one pass over every block: a value's uses are its parents anywhere
    let all: Vec<Id> = inner.iter().flatten().chain(p).copied().collect();
    let total = sc.uses(&all);
    let seen = |roots: &[Id]| -> Vec<bool> { sc.uses(roots).iter().map(|&u| u > 0).collect() };
    let in_p = seen(p);
    let in_blocks: Vec<Vec<bool>> = inner.iter().map(|r| seen(r)).collect();
    // the interior loop's block (the only one with `uniform`)
    let in_loop = &in_blocks[in_blocks.len().min(2) - 1];
    // an output of the loop that does not change with the section is computed once too
    let mut varying_parent = vec![false; total.len()];
    for r in &inner[in_blocks.len().min(2) - 1] {
        varying_parent[r.index()] = true;
    }
    for (k, &on) in in_loop.iter().enumerate() {
        let id = Id(k as u32);
        if on && reach[k].varies() && !sc.is_named(id) {
            for ch in sc.arena().node(id).children() {
                varying_parent[ch.index()] = true;
            }
        }
    }
    let ends = |k: usize| in_blocks.len() == 3 && in_blocks[0][k] && in_blocks[2][k];
    sc.restore(base);
    let pick: Vec<bool> = (0..total.len())
        .map(|k| {
            let id = Id(k as u32);
            let shared = (in_p[k] || in_loop[k] || ends(k)) && sc.worth_a_let(id, total[k]);
            let boundary = varying_parent[k] && sc.worth_a_let(id, 2);
            !reach[k].varies() && total[k] > 0 && (shared || boundary)
        })
        .collect();
    sc.lets(&total, &|id, _| pick[id.index()])
}

/// One block: `let`s for its shared and named values, the expressions of `roots` and of
/// `extra` (values needed after the block, always named).
fn block(
    sc: &mut Scope,
    roots: &[Id],
    extra: &[Id],
) -> (Vec<TokenStream>, Vec<TokenStream>, Vec<TokenStream>) {
    let all = [roots, extra].concat();
    let u = sc.uses(&all);
    let pick: Vec<bool> = (0..u.len())
        .map(|k| {
            let id = Id(k as u32);
            sc.worth_a_let(id, u[k]) || extra.contains(&id)
        })
        .collect();
    let lets = sc.lets(&u, &|id, _| pick[id.index()]);
    let outs = roots.iter().map(|&r| sc.expr(r)).collect();
    let more = extra.iter().map(|&r| sc.expr(r)).collect();
    (lets, outs, more)
}

/// `out[row] = v;` for every value, then one `sink.add_all(&[(row, col, v), ..]);` for the
/// block's Jacobian entries.
fn stores(entries: &[Entry], outs: &[TokenStream]) -> Vec<TokenStream> {
    let mut stores = Vec::new();
    let mut jac = Vec::new();
    for (e, v) in entries.iter().zip(outs) {
        let row = &e.row;
        match &e.col {
            None => stores.push(quote! { out[#row] = #v; }),
            Some(col) => jac.push(quote! { (#row, #col, #v) }),
        }
    }
    if !jac.is_empty() {
        stores.push(quote! { sink.add_all(&[#(#jac),*]); });
    }
    stores
}

/// The carried values for the next section, ordered so that a carried value is read
/// before it is overwritten.
fn updates(carried: &[(Id, Id)], carry: &[Ident], next: &[TokenStream]) -> Vec<TokenStream> {
    let mut pending: Vec<usize> = (0..carried.len()).collect();
    let mut out = Vec::new();
    while !pending.is_empty() {
        let pos = pending
            .iter()
            .position(|&k| {
                !pending
                    .iter()
                    .any(|&m| m != k && carried[m].1 == carried[k].0)
            })
            .expect("internal: carried values form a cycle");
        let k = pending.remove(pos);
        let (name, v) = (&carry[k], &next[k]);
        out.push(quote! { #name = #v; });
    }
    out
}

/// Nodes reachable from `roots`; a node for which `stop` holds is reached, not entered.
fn reachable(arena: &Arena, roots: &[Id], stop: &dyn Fn(Id) -> bool) -> Vec<bool> {
    let mut seen = vec![false; arena.len()];
    let mut stack: Vec<Id> = roots.to_vec();
    while let Some(i) = stack.pop() {
        if std::mem::replace(&mut seen[i.index()], true) || stop(i) {
            continue;
        }
        stack.extend(arena.node(i).children());
    }
    seen
}

/// The values `(c, a)` of the interior loop with `c` = `a` one section back (both read only
/// the sections `j - 1 ..= j + 1`), `c` reached from `roots` when the carried values are not
/// entered, and `a` computed in the loop anyway.
fn carries(c: &Canon, roots: &[Id]) -> Vec<(Id, Id)> {
    let (arena, reach) = (&c.arena, c.reach());
    let all = reachable(arena, roots, &|_| false);
    let mut memo = HashMap::new();
    let mut cand: HashMap<Id, Id> = HashMap::new();
    for k in (0..arena.len()).filter(|&k| all[k]) {
        let id = Id(k as u32);
        let trivial = matches!(arena.node(id), Node::Const(_) | Node::Sym(_) | Node::Neg(_));
        match reach[k].rel {
            Some((lo, hi)) if !trivial && !reach[k].index && lo >= -1 && hi <= 0 => {}
            _ => continue,
        }
        if let Some(a) = c.shifted(id, 1, &mut memo).filter(|a| all[a.index()]) {
            cand.insert(id, a);
        }
    }
    loop {
        let seen = reachable(arena, roots, &|id| cand.contains_key(&id));
        cand.retain(|k, _| seen[k.index()]);
        let before = cand.len();
        cand.retain(|_, a| seen[a.index()]);
        if cand.len() == before {
            let mut out: Vec<(Id, Id)> = cand.into_iter().collect();
            out.sort();
            return out;
        }
    }
}
