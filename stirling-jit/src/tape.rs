//! [`JitTape`]: one tape compiled to native code, owning the code's memory.

use std::sync::Arc;

use cranelift_codegen::ir::AbiParam;
use cranelift_codegen::settings::{self, Configurable};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{Linkage, Module, ModuleError};
use stirling_dsl::compiled::{Op, Runner, Tape};

use crate::{build, shims};

/// Why a tape could not be compiled.
#[derive(Debug, thiserror::Error)]
pub enum JitError {
    /// This machine has no Cranelift backend (the interpreter runs the tape then).
    #[error("no native code generator for this machine: {0}")]
    Host(String),
    /// Cranelift refused a setting or the function.
    #[error("compiling the tape failed: {0}")]
    Codegen(String),
}

impl From<ModuleError> for JitError {
    fn from(e: ModuleError) -> Self {
        JitError::Codegen(e.to_string())
    }
}

/// The signature of the compiled code.
type Code = extern "C" fn(*const f64, *const f64, *const f64, *mut f64);

/// A tape compiled to native code: `run` writes output `k` of the tape to `out[k]`.
pub struct JitTape {
    /// Owns the code's memory (never freed while `code` may run: both live and die together).
    _module: JITModule,
    /// The code's address; a [`Code`] (`call`).
    code: *const u8,
    /// The shortest `x`, `p`, `v` and `out` the code may be called with.
    needs: [usize; 4],
}

impl std::fmt::Debug for JitTape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JitTape")
            .field("needs", &self.needs)
            .finish_non_exhaustive()
    }
}

// SAFETY: `JITModule` is neither `Send` nor `Sync` only because it holds raw pointers to the
// code's memory. After `finalize_definitions` nothing mutates it (`JitTape` never hands it
// out, mutably or not); the code is pure (it reads its inputs and writes `out` only), so
// moving the owner to or calling the code from any thread is sound.
#[allow(unsafe_code)]
unsafe impl Send for JitTape {}
// SAFETY: as for `Send`: shared access only ever calls the read-only code.
#[allow(unsafe_code)]
unsafe impl Sync for JitTape {}

impl JitTape {
    /// Compile `tape` for this machine.
    pub fn compile(tape: &Tape) -> Result<JitTape, JitError> {
        let mut module = module()?;
        let ptr = module.target_config().pointer_type();
        let mut ctx = module.make_context();
        for _ in 0..4 {
            ctx.func.signature.params.push(AbiParam::new(ptr));
        }
        build::function(&mut module, &mut ctx.func, tape)?;
        let id = module.declare_function("tape", Linkage::Export, &ctx.func.signature)?;
        module.define_function(id, &mut ctx)?;
        module.clear_context(&mut ctx);
        module.finalize_definitions()?;
        let code = module.get_finalized_function(id);
        Ok(JitTape {
            _module: module,
            code,
            needs: needs(tape),
        })
    }

    /// Run on the state `x`, the parameters `p` and the sensor reads `v`, output `k` to
    /// `out[k]`; `false` (nothing written) when a slice is shorter than the tape reads or
    /// writes.
    pub fn run(&self, x: &[f64], p: &[f64], v: &[f64], out: &mut [f64]) -> bool {
        let [nx, np, nv, no] = self.needs;
        if x.len() < nx || p.len() < np || v.len() < nv || out.len() < no {
            return false;
        }
        self.call(x, p, v, out);
        true
    }

    /// The call of the compiled code.
    #[allow(unsafe_code)]
    fn call(&self, x: &[f64], p: &[f64], v: &[f64], out: &mut [f64]) {
        // SAFETY: `self.code` is the finalized address of the function `compile` declared
        // with exactly `Code`'s signature (four pointers, no result, the platform's C
        // convention), and its module (a field of `self`) keeps the code alive. The code
        // reads `x[i]`, `p[k]`, `v[i]` only at indices the tape names and writes `out[k]`
        // only for its outputs; `run` checked every slice is at least that long (`needs`),
        // and `out` is borrowed mutably, so no one else sees the writes.
        let code = unsafe { std::mem::transmute::<*const u8, Code>(self.code) };
        code(x.as_ptr(), p.as_ptr(), v.as_ptr(), out.as_mut_ptr());
    }
}

/// The JIT module for this machine, the shims known by name.
fn module() -> Result<JITModule, JitError> {
    let mut flags = settings::builder();
    let set = |f: &mut settings::Builder, k: &str, v: &str| {
        f.set(k, v).map_err(|e| JitError::Codegen(e.to_string()))
    };
    set(&mut flags, "use_colocated_libcalls", "false")?;
    set(&mut flags, "is_pic", "false")?;
    set(&mut flags, "opt_level", "speed")?;
    let isa = cranelift_native::builder()
        .map_err(|e| JitError::Host(e.to_string()))?
        .finish(settings::Flags::new(flags))
        .map_err(|e| JitError::Codegen(e.to_string()))?;
    let mut jb = JITBuilder::with_isa(isa, cranelift_module::default_libcall_names());
    for (name, addr) in shims::symbols() {
        jb.symbol(name, addr);
    }
    Ok(JITModule::new(jb))
}

/// The lengths of `x`, `p`, `v` and `out` the tape needs.
fn needs(tape: &Tape) -> [usize; 4] {
    let mut n = [0, 0, 0, tape.outputs.len()];
    for op in &tape.ops {
        match *op {
            Op::X(i) => n[0] = n[0].max(i as usize + 1),
            Op::P(k) => n[1] = n[1].max(k as usize + 1),
            Op::V(i) => n[2] = n[2].max(i as usize + 1),
            _ => {}
        }
    }
    n
}

impl Runner for JitTape {
    fn run(&self, x: &[f64], p: &[f64], v: &[f64], out: &mut [f64]) -> bool {
        JitTape::run(self, x, p, v, out)
    }
}

/// The longest tape compiled: Cranelift's time grows faster than linearly with one
/// straight-line block (the RHS + Jacobian of `nsection` compiled in 85 ms at n = 100, about
/// 25,000 instructions, and in 14 s at n = 1000); a longer tape is left to the interpreter,
/// which starts at once (5-7x slower per call).
pub const MAX_JIT_OPS: usize = 60_000;

/// The [`Jit`](stirling_dsl::compiled::Jit) of this crate: `tape` compiled, or `None` where
/// it cannot be or is longer than `MAX_JIT_OPS` (the interpreter runs it then).
pub fn jit(tape: &Tape) -> Option<Arc<dyn Runner>> {
    if tape.ops.len() > MAX_JIT_OPS {
        return None;
    }
    JitTape::compile(tape)
        .ok()
        .map(|t| Arc::new(t) as Arc<dyn Runner>)
}
