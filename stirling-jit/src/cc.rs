//! A tape compiled by the system's C compiler (`cc`, or `$STIRLING_CC`) and loaded as a
//! shared library: the path for tapes with the parameters folded in, run many times at one
//! parameter vector (a simulation, a sweep point), where an optimising compiler's code is
//! worth its compile time (some 0.1 s at n = 2). What CasADi does for its generated C; here
//! the tape is the one the Cranelift code runs, compiled without contraction
//! (`-ffp-contract=off`, no `-ffast-math`), so the bits are the interpreter's
//! (`tests/ops.rs`). [`cc_jit`] falls back to Cranelift ([`jit`]) where no C compiler works.

use std::path::Path;
use std::process::Command;
use std::sync::Arc;

use libloading::Library;
use stirling_dsl::compiled::{Runner, Tape};

use crate::csource::{self, ENTRY};
use crate::shims;
use crate::tape::{fits, jit, needs, JitError};

/// The compiled function: `x`, `p`, `v`, the two output buffers, the table of functions.
type Code =
    unsafe extern "C" fn(*const f64, *const f64, *const f64, *mut f64, *mut f64, *const *const u8);

/// The longest tape given to the C compiler; longer ones go to Cranelift. Measured on the
/// folded RHS + Jacobian of `nsection` (docs/performance.md, "The folded tapes by the C
/// compiler"): at n = 2 (342 instructions) GCC's code took 49 ns against Cranelift's 56; at
/// n = 10 (815) the same (122 against 120) for a compile of 0.16 s against 5 ms; at n = 100
/// (6125) 1470-1510 against 940 (Cranelift loops over the sections there, its code stays in
/// the instruction cache; GCC's straight code does not).
pub const CC_MAX_OPS: usize = 600;

/// The flags: optimised for this machine (the code runs where it was compiled), IEEE
/// arithmetic kept (no contraction of `a * b + c`: the tape's fused instructions are
/// explicit `fma`s, so the bits are the interpreter's). Without `-fno-tree-slp-vectorize`
/// GCC pairs scalar operations into vector registers and the code at n = 2 took 64 ns
/// (against 49 without, the same build).
const FLAGS: [&str; 8] = [
    "-O3",
    "-march=native",
    "-fno-tree-slp-vectorize",
    "-ffp-contract=off",
    "-fno-math-errno",
    "-shared",
    "-fPIC",
    "-std=gnu11",
];

/// A tape compiled by the C compiler.
pub struct CcTape {
    /// Keeps the code mapped while `code` may run.
    _lib: Library,
    code: Code,
    needs: [usize; 5],
    /// The functions the code calls (`csource::slot`).
    fns: [*const u8; 9],
}

impl std::fmt::Debug for CcTape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CcTape")
            .field("needs", &self.needs)
            .finish_non_exhaustive()
    }
}

// SAFETY: the library is never unloaded while `self` lives and nothing mutates it; the code
// is pure (it reads its inputs and writes the two output buffers only), and the function
// table holds addresses of plain Rust functions, so moving or sharing across threads is sound.
#[allow(unsafe_code)]
unsafe impl Send for CcTape {}
// SAFETY: as for `Send`.
#[allow(unsafe_code)]
unsafe impl Sync for CcTape {}

impl CcTape {
    /// Compile `tape` with the C compiler (`$STIRLING_CC`, else `cc`) and load it.
    pub fn compile(tape: &Tape) -> Result<CcTape, JitError> {
        let dir =
            tempfile::tempdir().map_err(|e| JitError::Host(format!("no scratch folder: {e}")))?;
        let (src, lib) = (dir.path().join("tape.c"), dir.path().join("tape.so"));
        std::fs::write(&src, csource::source(tape))
            .map_err(|e| JitError::Host(format!("cannot write {}: {e}", src.display())))?;
        compile_c(&src, &lib)?;
        let (lib, code) = load(&lib)?;
        Ok(CcTape {
            _lib: lib,
            code,
            needs: needs(tape),
            fns: shims::table(),
        })
    }
}

/// Run the compiler on `src`, the shared library to `out`.
fn compile_c(src: &Path, out: &Path) -> Result<(), JitError> {
    let cc = std::env::var("STIRLING_CC").unwrap_or_else(|_| "cc".into());
    let done = Command::new(&cc)
        .args(FLAGS)
        .arg("-o")
        .arg(out)
        .arg(src)
        .output()
        .map_err(|e| JitError::Host(format!("cannot run the C compiler `{cc}`: {e}")))?;
    if done.status.success() {
        Ok(())
    } else {
        let err = String::from_utf8_lossy(&done.stderr);
        Err(JitError::Codegen(format!(
            "`{cc}` failed: {}",
            err.lines().next().unwrap_or("")
        )))
    }
}

/// Load the library at `path` and find the tape's function.
#[allow(unsafe_code)]
fn load(path: &Path) -> Result<(Library, Code), JitError> {
    // SAFETY: the library is the one `compile_c` just built from `csource::source`: it has
    // no initialisers and exports `ENTRY` with exactly `Code`'s signature.
    let lib = unsafe { Library::new(path) }.map_err(|e| JitError::Host(e.to_string()))?;
    // SAFETY: as above; the pointer is copied out, and `lib` is kept beside it.
    let code = unsafe { lib.get::<Code>(ENTRY.as_bytes()) }
        .map(|s| *s)
        .map_err(|e| JitError::Host(e.to_string()))?;
    Ok((lib, code))
}

impl Runner for CcTape {
    #[allow(unsafe_code)]
    fn run(&self, x: &[f64], p: &[f64], v: &[f64], head: &mut [f64], tail: &mut [f64]) -> bool {
        if !fits(
            self.needs,
            [x.len(), p.len(), v.len(), head.len(), tail.len()],
        ) {
            return false;
        }
        // SAFETY: the code reads `x[i]`, `p[k]`, `v[i]` only at indices the tape names and
        // writes `head` and `tail` only at its outputs' indices, all within the lengths just
        // checked (`needs`); the table holds the nine functions `csource::slot` indexes.
        unsafe {
            (self.code)(
                x.as_ptr(),
                p.as_ptr(),
                v.as_ptr(),
                head.as_mut_ptr(),
                tail.as_mut_ptr(),
                self.fns.as_ptr(),
            )
        };
        true
    }
}

/// A [`Jit`](stirling_dsl::compiled::Jit) for folded tapes: the C compiler's code where it
/// works and the tape is at most [`CC_MAX_OPS`] long, else Cranelift's ([`jit`]).
pub fn cc_jit(tape: &Tape) -> Option<Arc<dyn Runner>> {
    if tape.ops.len() <= CC_MAX_OPS {
        if let Ok(t) = CcTape::compile(tape) {
            return Some(Arc::new(t));
        }
    }
    jit(tape)
}
