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

mod build;
mod looped;
mod schedule;
mod shims;
mod tape;

pub use tape::{jit, JitError, JitTape, CHUNK_OPS, LOOP_MIN};
