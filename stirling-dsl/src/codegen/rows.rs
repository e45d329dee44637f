//! The right-hand side, the analytic Jacobian and the parameter Jacobian of one system as Rust: the
//! outputs of every row, emitted as one program by [`crate::codegen::sections::program`].

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::layout::Layout;
use crate::expr::{Arena, At, Id, Sym};
use crate::topology::Row;

/// What a generated function computes for each row expression.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// `out[row] = f`.
    Value,
    /// `sink.add(row, col, df/dx_col)`.
    StateJacobian,
    /// `sink.add(row, k, df/dp_k)`.
    ParamJacobian,
}

/// One output line: the value to emit and where it goes.
pub(super) struct Entry {
    pub(super) id: Id,
    pub(super) row: TokenStream,
    pub(super) col: Option<TokenStream>,
}

/// The body of a generated function (after the prologue) that computes every output of
/// `whats` (the right-hand side and the Jacobian in one pass share their values).
pub fn rows_body(
    arena: &mut Arena,
    lay: &Layout,
    rows: &[Row],
    whats: &[Output],
    private: &TokenStream,
) -> TokenStream {
    let scalar: Vec<(usize, Id)> = rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| match r {
            Row::Scalar(id) => Some((i, *id)),
            Row::Array(_) => None,
        })
        .collect();
    let arrays: Vec<(usize, [Id; 4])> = rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| match r {
            Row::Array(v) => Some((i, *v)),
            Row::Scalar(_) => None,
        })
        .collect();
    let (mut head, mut tail) = (TokenStream::new(), TokenStream::new());
    let mut entries_s = Vec::new();
    let mut entries_a: [Vec<Entry>; 4] = Default::default();
    for &what in whats {
        let grads = (what != Output::Value && !lay.sys.sums.is_empty()).then(|| {
            let ids: Vec<Id> = scalar.iter().map(|&(_, id)| id).collect();
            super::sums::gradients(arena, lay, &ids, what, private)
        });
        entries_s.extend(entries(
            arena,
            lay,
            &scalar,
            what,
            false,
            grads.as_ref().map(|g| &g.grads),
        ));
        if let Some(g) = &grads {
            head.extend(g.code.clone());
            let rows: Vec<(TokenStream, Id)> = scalar
                .iter()
                .map(|&(b, id)| (lay.index(lay.sys.blocks[b].sym, At::Scalar), id))
                .collect();
            tail.extend(super::sums::jacobian(arena, lay, &rows, what, private));
        }
        for (k, list) in entries_a.iter_mut().enumerate() {
            let rows: Vec<(usize, Id)> = arrays.iter().map(|(i, r)| (*i, r[k])).collect();
            list.extend(entries(arena, lay, &rows, what, true, None));
        }
    }
    let arrays = (!arrays.is_empty()).then_some(&entries_a);
    // the sums' chain rule right after the scalar rows, as before the sections
    let body = super::sections::program(arena, lay, (&entries_s, tail), arrays, private);
    quote! { #head { #body } }
}

/// The outputs of `rows` for `what`: values, or nonzero derivatives with their columns.
fn entries(
    arena: &mut Arena,
    lay: &Layout,
    rows: &[(usize, Id)],
    what: Output,
    in_loop: bool,
    sums: Option<&super::sums::SumGrads>,
) -> Vec<Entry> {
    let at = if in_loop { At::Rel(0) } else { At::Scalar };
    outputs(arena, rows, what, sums)
        .into_iter()
        .map(|o| Entry {
            id: o.id,
            row: lay.index(lay.sys.blocks[o.block].sym, at),
            col: o.col.map(|s| match s {
                Sym::State(cb, cat) => lay.index(cb, cat),
                Sym::Param(k) => {
                    let k = Literal::u32_unsuffixed(k);
                    quote!(#k)
                }
                _ => unreachable!("outputs gives state and parameter columns only"),
            }),
        })
        .collect()
}

/// One output of a row: its value (`col` `None`) or a nonzero derivative in column `col`
/// (a state or a parameter symbol).
pub struct RowOutput {
    /// The row's block, by its position in state order.
    pub block: usize,
    pub col: Option<Sym>,
    pub id: Id,
}

/// The outputs of `rows` (block position, expression) for `what`: the values, or the nonzero
/// derivatives in their columns, the sums' chain rule included for the columns that do not
/// change with the section (`sums`: the scalar rows' [`super::sums::SumGrads`]). Shared by
/// the emitted code and the run-time tape (`crate::compiled`), so both hold the same
/// expressions.
pub fn outputs(
    arena: &mut Arena,
    rows: &[(usize, Id)],
    what: Output,
    sums: Option<&super::sums::SumGrads>,
) -> Vec<RowOutput> {
    let mut out = Vec::new();
    for &(block, id) in rows {
        if what == Output::Value {
            out.push(RowOutput {
                block,
                col: None,
                id,
            });
            continue;
        }
        let cols = match sums {
            Some(g) => g.row_columns(arena, id),
            None => arena.symbols(id),
        };
        for s in cols {
            match (what, s) {
                (Output::StateJacobian, Sym::State(..))
                | (Output::ParamJacobian, Sym::Param(_)) => {}
                _ => continue,
            }
            let mut d = arena.diff(id, s);
            if let Some(g) = sums {
                // the sections' part through the sums: `df/dS_k dS_k/ds`
                d = g.total(arena, id, s, d);
            }
            if arena.as_const(d) != Some(0.0) {
                out.push(RowOutput {
                    block,
                    col: Some(s),
                    id: d,
                });
            }
        }
    }
    out
}
