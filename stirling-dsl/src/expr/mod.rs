//! The symbolic core: a hash-consed expression arena with folding constructors,
//! differentiation, substitution, evaluation, printers and Rust emission.

mod arena;
mod diff;
/// Rust code emission with common-subexpression elimination.
pub mod emit;
mod eval;
mod node;
/// Printers.
pub mod print;
mod subst;
mod tanh;

pub use arena::Arena;
pub use node::{sign, At, Func, Id, Node, Sym};
pub use print::{Printer, Style};
pub use tanh::tanh;

#[cfg(test)]
mod tests;
