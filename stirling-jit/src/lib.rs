//! Native code for the register tapes of stirling's compiled models
//! ([`stirling_dsl::compiled::Tape`]), compiled with Cranelift at load time.
//!
//! [`JitTape::compile`] turns a tape into one native function
//! `fn(x: *const f64, p: *const f64, v: *const f64, out: *mut f64)` writing output `k` to
//! `out[k]`; [`JitTape::run`] checks the slices and calls it. Arithmetic is the same IEEE
//! operation the interpreter performs (so the results agree bit for bit); the functions of
//! [`Func`](stirling_dsl::expr::Func) other than `abs`, `sqrt` and `sign` and `powf` call the
//! interpreter's own Rust functions (`shims`); `powi` multiplies as the interpreter's
//! `f64::powi` does (`build`). [`jit`] is a [`Jit`](stirling_dsl::compiled::Jit) to install
//! on a model ([`CompiledModel::with_jit`](stirling_dsl::compiled::CompiledModel::with_jit)).

mod build;
mod shims;
mod tape;

pub use tape::{jit, JitError, JitTape, CHUNK_OPS};
