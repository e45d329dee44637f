//! [`JitTape`]: one tape compiled to native code, owning the code's memory.

use std::cell::RefCell;
use std::sync::Arc;

use cranelift_codegen::ir::AbiParam;
use cranelift_codegen::settings::{self, Configurable};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{Linkage, Module, ModuleError};
use stirling_dsl::compiled::{Op, Repeat, Runner, Tape};

use crate::{build, looped, shims};

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

/// The signature of the compiled code: `x`, `p`, `v`, the two output buffers, the scratch
/// array, the tape's numbers.
type Code =
    extern "C" fn(*const f64, *const f64, *const f64, *mut f64, *mut f64, *mut f64, *const f64);

/// The number of arguments of [`Code`]; the last is the numbers' table.
pub(crate) const ARGS: usize = 7;

/// A tape compiled to native code: `run` writes output `k` of the tape to `out[k]`.
pub struct JitTape {
    /// Owns the code's memory (never freed while `code` may run: both live and die together).
    _module: JITModule,
    /// The functions' addresses, each a [`Code`] (`call`), run in order.
    code: Vec<*const u8>,
    /// The shortest `x`, `p`, `v`, first and second output buffer the code may be called
    /// with.
    needs: [usize; 5],
    /// The length of the scratch array the functions pass registers through.
    scratch: usize,
    /// The tape's numbers, whose address the code takes as its last argument.
    consts: Box<[f64]>,
    /// Whether the code loops over the tape's repeating sections ([`Repeat`]).
    looped: bool,
    /// The machine code's size in bytes, every function together.
    bytes: usize,
}

impl std::fmt::Debug for JitTape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JitTape")
            .field("needs", &self.needs)
            .field("functions", &self.code.len())
            .field("looped", &self.looped)
            .field("bytes", &self.bytes)
            .finish_non_exhaustive()
    }
}

// SAFETY: `JITModule` is neither `Send` nor `Sync` only because it holds raw pointers to the
// code's memory. After `finalize_definitions` nothing mutates it (`JitTape` never hands it
// out, mutably or not); the code is pure (it reads its inputs and writes the output buffers
// and the calling thread's scratch array only), so moving the owner to or calling the code
// from any thread is sound.
#[allow(unsafe_code)]
unsafe impl Send for JitTape {}
// SAFETY: as for `Send`: shared access only ever calls the read-only code.
#[allow(unsafe_code)]
unsafe impl Sync for JitTape {}

thread_local! {
    /// The scratch array of the tapes compiled as several functions or with a loop (one per
    /// thread, reused).
    static SCRATCH: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// The instructions per function: Cranelift compiles a few thousand in one block in tens of
/// milliseconds, but its time grows faster than linearly beyond (one block of 80,000: 14 s).
pub const CHUNK_OPS: usize = 4_000;

impl JitTape {
    /// Compile `tape` for this machine: with a loop over its repeating sections where it
    /// has some ([`Tape::repeat`], [`JitTape::compile_looped`]), else unrolled as functions
    /// of at most [`CHUNK_OPS`] instructions.
    pub fn compile(tape: &Tape) -> Result<JitTape, JitError> {
        match tape.repeat().filter(|r| worth_looping(tape, r)) {
            Some(rep) => JitTape::compile_looped(tape, &rep),
            None => JitTape::compile_chunked(tape, CHUNK_OPS),
        }
    }

    /// Compile `tape` as one function with a loop over the sections `rep` (found on it by
    /// [`Tape::repeat`]).
    pub fn compile_looped(tape: &Tape, rep: &Repeat) -> Result<JitTape, JitError> {
        let mut module = module()?;
        let ptr = module.target_config().pointer_type();
        let numbers = looped::Numbers::new(tape, rep);
        if uses_tanh(tape) {
            build::define_tanh_keep(&mut module)?;
        }
        let mut ctx = module.make_context();
        for _ in 0..ARGS {
            ctx.func.signature.params.push(AbiParam::new(ptr));
        }
        looped::function(&mut module, &mut ctx.func, tape, rep, &numbers)?;
        let id = module.declare_function("tape_loop", Linkage::Export, &ctx.func.signature)?;
        ctx.set_disasm(disasm());
        module.define_function(id, &mut ctx)?;
        if let Some(d) = ctx.compiled_code().and_then(|c| c.vcode.clone()) {
            eprintln!("{d}");
        }
        let bytes = code_bytes(&ctx);
        module.clear_context(&mut ctx);
        module.finalize_definitions()?;
        let code = vec![module.get_finalized_function(id)];
        Ok(JitTape {
            _module: module,
            code,
            needs: needs(tape),
            scratch: looped::scratch_len(tape, rep),
            consts: numbers.values,
            looped: true,
            bytes,
        })
    }

    /// Compile `tape` as functions of at most `chunk` instructions each.
    pub fn compile_chunked(tape: &Tape, chunk: usize) -> Result<JitTape, JitError> {
        let mut module = module()?;
        let ptr = module.target_config().pointer_type();
        let mut layout = build::Layout::new(tape, chunk);
        let mut ids = Vec::with_capacity(layout.chunks.len());
        let mut ctx = module.make_context();
        let mut bytes = 0;
        for c in 0..layout.chunks.len() {
            for _ in 0..ARGS {
                ctx.func.signature.params.push(AbiParam::new(ptr));
            }
            build::function(&mut module, &mut ctx.func, tape, &layout, c)?;
            let name = format!("tape{c}");
            let id = module.declare_function(&name, Linkage::Export, &ctx.func.signature)?;
            ctx.set_disasm(disasm());
            module.define_function(id, &mut ctx)?;
            if let Some(d) = ctx.compiled_code().and_then(|c| c.vcode.clone()) {
                eprintln!("{d}");
            }
            bytes += code_bytes(&ctx);
            module.clear_context(&mut ctx);
            ids.push(id);
        }
        module.finalize_definitions()?;
        let code = ids
            .into_iter()
            .map(|id| module.get_finalized_function(id))
            .collect();
        Ok(JitTape {
            _module: module,
            code,
            needs: needs(tape),
            scratch: layout.slots,
            consts: std::mem::take(&mut layout.consts),
            looped: false,
            bytes,
        })
    }

    /// Whether the code loops over the tape's repeating sections.
    pub fn looped(&self) -> bool {
        self.looped
    }

    /// The size of the machine code in bytes.
    pub fn code_bytes(&self) -> usize {
        self.bytes
    }

    /// The number of functions the tape was compiled as.
    pub fn functions(&self) -> usize {
        self.code.len()
    }

    /// Run on the state `x`, the parameters `p` and the sensor reads `v`, output `k` to
    /// `out[k]`; `false` (nothing written) when a slice is shorter than the tape reads or
    /// writes.
    pub fn run(&self, x: &[f64], p: &[f64], v: &[f64], out: &mut [f64]) -> bool {
        if out.len() < self.needs[3] + self.needs[4] {
            return false;
        }
        let (head, tail) = out.split_at_mut(self.needs[3]);
        self.run_split(x, p, v, head, tail)
    }

    /// Run as [`JitTape::run`], the outputs from the tape's split on
    /// ([`Tape::split`](stirling_dsl::compiled::Tape::split)) to `tail`.
    pub fn run_split(
        &self,
        x: &[f64],
        p: &[f64],
        v: &[f64],
        head: &mut [f64],
        tail: &mut [f64],
    ) -> bool {
        if !fits(
            self.needs,
            [x.len(), p.len(), v.len(), head.len(), tail.len()],
        ) {
            return false;
        }
        if self.scratch == 0 {
            self.call(x, p, v, head, tail, &mut []);
            return true;
        }
        SCRATCH.with(|s| {
            let mut s = s.borrow_mut();
            if s.len() < self.scratch {
                s.resize(self.scratch, 0.0);
            }
            self.call(x, p, v, head, tail, &mut s);
        });
        true
    }

    /// The calls of the compiled functions.
    #[allow(unsafe_code)]
    fn call(&self, x: &[f64], p: &[f64], v: &[f64], h: &mut [f64], t: &mut [f64], s: &mut [f64]) {
        debug_assert!(s.len() >= self.scratch);
        for &f in &self.code {
            // SAFETY: `f` is the finalized address of a function `compile_chunked` declared
            // with exactly `Code`'s signature (seven pointers, no result, the platform's C
            // convention), and its module (a field of `self`) keeps the code alive. The code
            // reads `x[i]`, `p[k]`, `v[i]` only at indices the tape names and writes the
            // output buffers only at its outputs' indices; `run_split` checked every slice is
            // at least that long (`needs`); it reads the numbers of `self.consts` at the
            // slots the tape gave them (`Layout`, `looped::Numbers`), all within it (an empty
            // table is never read). The scratch array is read and written only at slots below
            // `self.scratch` (`Layout`, `looped::before`), its length whenever that is not 0
            // (with 0, the code never touches it). Every buffer is borrowed mutably, so no one
            // else sees the writes.
            let code = unsafe { std::mem::transmute::<*const u8, Code>(f) };
            code(
                x.as_ptr(),
                p.as_ptr(),
                v.as_ptr(),
                h.as_mut_ptr(),
                t.as_mut_ptr(),
                s.as_mut_ptr(),
                self.consts.as_ptr(),
            );
        }
    }
}

/// The size of the machine code `ctx` holds after `define_function`.
fn code_bytes(ctx: &cranelift_codegen::Context) -> usize {
    ctx.compiled_code()
        .map_or(0, |c| c.code_info().total_size as usize)
}

/// The fewest iterations a loop is compiled for: below, the unrolled code fits the
/// level-1 instruction cache and is faster (`nsection` at n = 10, 6 iterations: the loop
/// 1.6x the macro's code, unrolled 0.85-1.15x).
pub const LOOP_MIN: usize = 16;

/// The longest straight part (before or after the loop) or body compiled as one function.
const LOOP_PART_OPS: usize = 2 * CHUNK_OPS;

/// Whether `rep` is worth a loop (enough iterations) and compiles as one function (no
/// part too long for one block).
fn worth_looping(tape: &Tape, rep: &Repeat) -> bool {
    rep.count >= LOOP_MIN
        && rep.start <= LOOP_PART_OPS
        && rep.len <= LOOP_PART_OPS
        && tape.ops.len() - rep.end() <= LOOP_PART_OPS
}

/// Whether `tape` calls `tanh` (its code then calls the trampoline `build::TANH_KEEP`).
fn uses_tanh(tape: &Tape) -> bool {
    tape.ops
        .iter()
        .any(|op| matches!(op, Op::Func(stirling_dsl::expr::Func::Tanh, _)))
}

/// Whether to print the machine code of every compiled function to stderr (the environment
/// variable `STIRLING_JIT_DISASM` set: a profiling aid, e.g. to count a loop body's spills).
fn disasm() -> bool {
    std::env::var_os("STIRLING_JIT_DISASM").is_some()
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
    // the IR is checked by construction (and by the tests); the verifier cost ~5% of the
    // compile time
    set(&mut flags, "enable_verifier", "false")?;
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

/// Whether slices of the lengths `have` (`x`, `p`, `v`, both output buffers) are long enough
/// for a tape that `needs` them.
pub(crate) fn fits(needs: [usize; 5], have: [usize; 5]) -> bool {
    needs.iter().zip(have).all(|(&n, h)| h >= n)
}

/// The lengths of `x`, `p`, `v` and both output buffers the tape needs.
pub(crate) fn needs(tape: &Tape) -> [usize; 5] {
    let head = tape.head();
    let mut n = [0, 0, 0, head, tape.outputs.len() - head];
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
    fn run(&self, x: &[f64], p: &[f64], v: &[f64], head: &mut [f64], tail: &mut [f64]) -> bool {
        JitTape::run_split(self, x, p, v, head, tail)
    }

    fn looped(&self) -> bool {
        self.looped
    }

    fn code_bytes(&self) -> Option<usize> {
        Some(self.bytes)
    }
}

/// The longest tape compiled: its functions of [`CHUNK_OPS`] instructions compile in about
/// 20-30 ms each (the RHS + Jacobian of `nsection` at n = 1000, about 80,000 instructions,
/// in 0.3-0.6 s), so this cap is some 2-4 s of compile time; a longer tape is left to the
/// interpreter, which starts at once (5-7x slower per call).
pub const MAX_JIT_OPS: usize = 400_000;

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
