//! # stirling-dsl: the symbolic core of `stirling`
//!
//! A free-piston Stirling engine is declared as a topology of bodies, gas control
//! volumes (CVs), faces, heat ports and mass-flow links. This crate turns such a
//! declaration into equations by the energetic rules of PHYSICS.md, differentiates
//! them symbolically and emits Rust: the right-hand side, the analytic Jacobian and
//! the parameter Jacobian, for any number `n` of array sections chosen at run time.
//!
//! - [`expr`]: the hash-consed expression arena (folding constructors, differentiation,
//!   substitution, evaluation, text/LaTeX printers, Rust emission with CSE).
//! - [`topology`]: the declaration ([`Topology`]) and its assembly ([`assemble`]).
//! - [`codegen`]: emission of a whole model ([`codegen::generate`]), used by the
//!   `stirling_model!` macro at compile time.
//! - The run-time interface every generated model implements: [`Model`], with
//!   [`ParamInfo`], [`StateInfo`], [`JacSink`], [`PowerTerms`], [`TopologyInfo`] and
//!   the bond-graph view [`to_dot`].
//!
//! Users declare models with `stirling_macros::stirling_model!`; the generated code
//! refers to this crate as `::stirling_dsl`, so depend on both.

mod closure;
pub mod codegen;
pub mod expr;
pub mod runtime;
pub mod topology;

pub use closure::Closure;
pub use expr::{Arena, Id, Style, Sym};
pub use runtime::{
    to_dot, BodyInfo, FaceInfo, JacSink, LinkInfo, Model, ModelError, ParamInfo, PortInfo, PowerTerms, StateInfo,
    StateKind, TopologyInfo, VesselInfo,
};
pub use topology::{assemble, Topology};

/// Helpers for generated code only.
#[doc(hidden)]
pub mod __private {
    pub use crate::expr::sign;
    pub use crate::topology::Variant;
    pub use serde;

    impl Variant {
        /// The variant of section `j` of `n`.
        #[inline(always)]
        pub fn of(j: usize, n: usize) -> Variant {
            if n == 1 {
                Variant::Single
            } else if j == 0 {
                Variant::First
            } else if j + 1 == n {
                Variant::Last
            } else {
                Variant::Interior
            }
        }
    }
}
