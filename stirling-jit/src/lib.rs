//! Native code for the register tapes of stirling's compiled models
//! ([`stirling_dsl::compiled::Tape`]), compiled with Cranelift at load time.
//!
//! [`JitTape::compile`] turns a tape into native functions (one per [`CHUNK_OPS`]
//! instructions; they pass the registers they share through a scratch array) writing output
//! `k` to `out[k]`, or, for a tape split between two buffers
//! ([`Tape::split`](stirling_dsl::compiled::Tape::split)), straight into the caller's two
//! slices; [`JitTape::run`] and [`JitTape::run_split`] check the slices and call them. Each
//! output is stored as soon as it is computed; inputs and numbers are loaded at each use.
//! Arithmetic is the same IEEE operation the interpreter performs (so the results agree bit
//! for bit); the functions of [`Func`](stirling_dsl::expr::Func) other than `abs`, `sqrt`,
//! `sign` and the saturated `tanh` (inline) and `powf` call the interpreter's own Rust
//! functions (`shims`); `powi` multiplies as the interpreter's `f64::powi` does (`build`). [`jit`] is a [`Jit`](stirling_dsl::compiled::Jit) to install
//! on a model ([`CompiledModel::with_jit`](stirling_dsl::compiled::CompiledModel::with_jit)).
//!
//! [`cc_jit`] is a second [`Jit`](stirling_dsl::compiled::Jit), for short tapes with the
//! parameters folded in ([`CompiledModel::folded_by`](stirling_dsl::compiled::CompiledModel::folded_by)):
//! the tape as C ([`CcTape`]), compiled by the system's C compiler with IEEE arithmetic kept
//! (the interpreter's bits again) and loaded as a shared library; Cranelift's code where no C
//! compiler works or the tape is longer than [`CC_MAX_OPS`].

mod build;
mod cc;
mod csource;
mod looped;
mod schedule;
mod shims;
mod tape;

pub use cc::{cc_jit, CcTape, CC_MAX_OPS};
pub use tape::{jit, JitError, JitTape, CHUNK_OPS, LOOP_MIN};
