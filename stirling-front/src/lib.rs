//! # stirling-front: the front end of the engine language
//!
//! One language, two ways in: the `stirling_model!` macro (compile time, in a user's crate)
//! and the file loader ([`load`], run time, `engine.stirling`). Both call this crate, so a
//! declaration means the same and a mistake gets the same message either way.
//!
//! The pipeline is a straight line, one module per step, each reading only the steps
//! before it:
//!
//! 1. [`compose`]: a declaration (`[pub] model Name [extends base] { .. }` or `base name
//!    { .. }`) and the merge of a base's items with a derived body's changes;
//! 2. [`ast`]: the merged items parsed into a spanned syntax tree ([`ast::ModelAst`]);
//! 3. `effects`: the `effect` items applied to the tree, at their null;
//! 4. `check`: names resolved, rules enforced (every error collected, at the user's tokens)
//!    and the tree lowered to a [`Topology`] whose coefficients are expressions in the
//!    symbolic arena of `stirling_dsl`.
//!
//! [`lower`] runs steps 3 and 4. What follows is `stirling_dsl`'s: the energetic assembly
//! and the Jacobians, emitted as Rust by the macro or compiled to a tape by the loader.
//!
//! Outside a proc macro, tokens come from `proc_macro2::TokenStream::from_str` with
//! proc-macro2's `span-locations` feature, so a span knows its line and column: the loader
//! renders an error as `path:line:column: message` with the line and a caret.

pub mod ast;
mod check;
pub mod compose;
mod effects;
mod expr;
pub mod load;

use stirling_dsl::Topology;

/// Apply the `effect` items of `ast` (at their null), then check it and lower it to its
/// topology. Every error is collected, at the user's tokens.
pub fn lower(mut ast: ast::ModelAst) -> syn::Result<Topology> {
    let effects = effects::apply(&mut ast)?;
    let mut topo = check::lower(&ast)?;
    topo.effects = effects;
    Ok(topo)
}
