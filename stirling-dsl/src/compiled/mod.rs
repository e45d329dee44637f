//! Models compiled at run time: a topology lowered from a file (`stirling_front::load`) is
//! assembled and differentiated here exactly as `stirling_model!`'s expansion does it, and
//! each function of the [`crate::Model`] trait becomes a register tape at the `n` and closure
//! asked for.
//!
//! - [`Definition`](crate::compiled::Definition): the topology assembled for both closures,
//!   its outputs chosen and differentiated by the emitted code's own functions (`plan`);
//! - [`CompiledModel`](crate::compiled::CompiledModel): a definition at `n` and a closure;
//!   every expression instantiated at its place with the emitted code's value numbering
//!   (`instance`), laid out as a [`Tape`](crate::compiled::Tape) (`functions`) and run by a
//!   tight interpreter loop, or by native code a [`Jit`](crate::compiled::Jit) compiled
//!   from it; on request with one parameter vector folded in (`fold`);
//! - [`Repeat`](crate::compiled::Repeat): the interior sections of a tape that repeat, found
//!   on the tape, as one loop body for native code (`repeat`);
//! - the descriptions the trait hands out as `&'static` are leaked once per definition
//!   (`statics`).

mod definition;
mod fold;
mod functions;
mod instance;
mod kernel;
mod model;
mod peephole;
mod plan;
mod repeat;
mod runner;
mod statics;
mod tape;

pub use definition::Definition;
pub use functions::Function;
pub use instance::InstanceError;
pub use kernel::{Kernel, KernelError};
pub use model::{CompileError, CompiledModel};
pub use repeat::{Arg, LoopLeaf, Repeat, Step};
pub use runner::{Jit, Runner};
pub use tape::{fused_value, operands, Op, Tape};
