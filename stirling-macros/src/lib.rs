//! # stirling-macros: the `stirling_model!` macro
//!
//! A thin wrapper: the front end (`stirling_front`: compose, parse, check, lower to a
//! topology) is shared with the run-time file loader; this crate turns a base into a
//! `macro_rules!`, routes `extends` through it, and emits the lowered topology as Rust
//! (`stirling_dsl::codegen`). The generated code refers to `::stirling_dsl`, so a crate
//! using the macro depends on `stirling-dsl` too.

mod expand;

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
    stirling_front::compose::parse(input.into())
        .and_then(expand::declaration)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

#[cfg(test)]
mod flop_count;
#[cfg(test)]
mod snapshot_tests;
