//! # stirling-macros: the `stirling_model!` macro
//!
//! Compose (bases and `extends`, merged token by token) -> parse ([`ast`](self)) -> check
//! and lower to a topology -> assemble and differentiate with `stirling_dsl` -> emit. The generated code refers to
//! `::stirling_dsl`, so a crate using the macro depends on `stirling-dsl` too.

mod ast;
mod check;
mod compose;
mod effects;
mod expand;
mod expr;
mod links;
mod walls;

use proc_macro::TokenStream;

/// Declare a free-piston engine topology and generate its model.
///
/// See the `stirling-dsl` crate docs and `docs/` for the syntax; in short:
///
/// ```ignore
/// stirling_model! {
///     /// A single gas space with one heat port.
///     pub model Demo {
///         params { /// mass
///                  m: 1.0 "kg", k: 100.0 "N/m", A: 1e-3 "m^2", V0: 1e-4 "m^3",
///                  T: 300.0 "K", h: 100.0 "W/(m^2 K)", Aw: 0.01 "m^2",
///                  R: 287.0 "J/(kg K)", gamma: 1.4 "-", P0: 1e5 "Pa", eps: 1e-5 "kg/s" }
///         gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
///         body piston(y, w) { mass: m, spring: k }
///         space outside { pressure: P0, faces { piston: A } }
///         cv gas { volume: V0, faces { piston: -A }, port wall { h: h, area: Aw, wall: T } }
///     }
/// }
/// ```
///
/// Composition (`compose`, docs/custom-topologies.md section 10): `pub base name { items }`
/// declares no model but a macro `name!` holding its items; `pub model X extends path { .. }`
/// is that base plus changes: added items, `replace <item>`, `remove <kind> <name>;`,
/// `modify <kind> <name> { fields }`, merged before the check.
#[proc_macro]
pub fn stirling_model(input: TokenStream) -> TokenStream {
    compose::parse(input.into())
        .and_then(compose::expand)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

#[cfg(test)]
mod flop_count;
#[cfg(test)]
mod snapshot_tests;
