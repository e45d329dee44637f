//! Engines declared in a `.stirling` file, loaded at run time: the file is read, composed with
//! what it `extends` (the family's bases by name, other files by path), checked and lowered by
//! the macro's own front end (`stirling_front::load`), then assembled and compiled to tapes
//! (`stirling_dsl::compiled`). The model is a [`Model`](stirling_dsl::Model) like the family's: every analysis and
//! command runs on it.
//!
//! A definition is loaded once per process and file (cached by its canonical path and
//! modification time) and then built at any `n` and closure; its descriptions are leaked once
//! per load (`stirling_dsl::compiled`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::SystemTime;

use stirling_dsl::compiled::{CompileError, CompiledModel, Definition};
use stirling_dsl::{Closure, Model};
use stirling_front::load::{load_detached, load_file, BuiltinBase, LoadError};

/// The extension of an engine file.
pub const EXTENSION: &str = "stirling";

/// The bases a file extends by name: the family's engine and its `nsection` gas (the same
/// declarations as the family's `stirling_model!` bases), and the kinematic engines' common
/// base (a flywheel and two cranks: `examples/engines/bases/kinematic.stirling`, docs/physics.md
/// section 12), so that a user's file starts from any of them wherever it lies.
pub const BASES: &[BuiltinBase] = &[
    BuiltinBase {
        name: "default_engine",
        path: "<stirling>/default_engine.stirling",
        text: include_str!("family/default_engine.stirling"),
    },
    BuiltinBase {
        name: "nsection_engine",
        path: "<stirling>/nsection_engine.stirling",
        text: include_str!("family/nsection_engine.stirling"),
    },
    BuiltinBase {
        name: "kinematic_engine",
        path: "<stirling>/kinematic_engine.stirling",
        text: include_str!("../../../examples/engines/bases/kinematic.stirling"),
    },
];

/// An engine file that comes with stirling: its path in the source tree and its text (for
/// `stirling models`, which lists them with the first sentence of their doc comment).
pub struct Shipped {
    pub path: &'static str,
    pub text: &'static str,
}

/// The engine files of `examples/engines/` beyond the family's own: the kinematic engines
/// (docs/physics.md section 12) and the gamma engine with a hot plate of finite heat capacity.
pub const SHIPPED: &[Shipped] = &[
    Shipped {
        path: "examples/engines/gamma_ltd.stirling",
        text: include_str!("../../../examples/engines/gamma_ltd.stirling"),
    },
    Shipped {
        path: "examples/engines/gamma_ltd_plate.stirling",
        text: include_str!("../../../examples/engines/gamma_ltd_plate.stirling"),
    },
    Shipped {
        path: "examples/engines/beta.stirling",
        text: include_str!("../../../examples/engines/beta.stirling"),
    },
    Shipped {
        path: "examples/engines/alpha.stirling",
        text: include_str!("../../../examples/engines/alpha.stirling"),
    },
];

/// Why a file's model cannot be had.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// Unreadable, or a mistake in the declaration (every message at its place).
    #[error(transparent)]
    Load(#[from] LoadError),
    /// The declaration is fine but the model cannot be built at this `n`.
    #[error(transparent)]
    Compile(#[from] CompileError),
    /// The loader's thread could not be started or stopped unexpectedly.
    #[error("{path}: the loader failed: {why}")]
    Loader { path: PathBuf, why: String },
}

/// Whether `name` names an engine file (ends in `.stirling`).
pub fn is_file(name: &str) -> bool {
    Path::new(name).extension().is_some_and(|e| e == EXTENSION)
}

/// The stack of the loader's thread: the parser and the checks recurse once per level of an
/// expression, and a file's expressions may be long.
const LOADER_STACK: usize = 256 << 20;

fn cache() -> &'static Mutex<HashMap<PathBuf, (Option<SystemTime>, Arc<Definition>)>> {
    static CACHE: OnceLock<Mutex<HashMap<PathBuf, (Option<SystemTime>, Arc<Definition>)>>> =
        OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// The definition declared in the file at `path` (loaded once per process while the file is
/// unchanged).
pub fn definition(path: &Path) -> Result<Arc<Definition>, FileError> {
    let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    let stamp = std::fs::metadata(path).and_then(|m| m.modified()).ok();
    let table = cache().lock().unwrap_or_else(|e| e.into_inner());
    if let Some((s, def)) = table.get(&key) {
        if *s == stamp {
            return Ok(Arc::clone(def));
        }
    }
    drop(table);
    let def = load(path)?;
    let mut table = cache().lock().unwrap_or_else(|e| e.into_inner());
    table.insert(key, (stamp, Arc::clone(&def)));
    Ok(def)
}

/// Load and assemble on a thread of its own, with a stack deep enough for long expressions.
fn load(path: &Path) -> Result<Arc<Definition>, FileError> {
    let owned = path.to_path_buf();
    on_loader_thread(path, move || load_file(&owned, BASES))
}

/// The definition declared in `text` (shown in messages as `name`), reading no file: it
/// extends the family's bases by name only (`stirling_front::load::load_detached`). Not
/// cached: each call loads (and leaks its descriptions) anew.
pub fn definition_of_text(name: &str, text: &str) -> Result<Arc<Definition>, FileError> {
    let (name_owned, text) = (name.to_string(), text.to_string());
    on_loader_thread(Path::new(name), move || {
        load_detached(&name_owned, &text, BASES)
    })
}

/// Run `load` and assemble its topology on a thread whose stack is [`LOADER_STACK`].
fn on_loader_thread<F>(path: &Path, load: F) -> Result<Arc<Definition>, FileError>
where
    F: FnOnce() -> Result<stirling_dsl::Topology, LoadError> + Send + 'static,
{
    let fail = |why: String| FileError::Loader {
        path: path.to_path_buf(),
        why,
    };
    let handle = std::thread::Builder::new()
        .name("stirling-loader".into())
        .stack_size(LOADER_STACK)
        .spawn(move || load().map(Definition::new))
        .map_err(|e| fail(e.to_string()))?;
    let joined = handle
        .join()
        .map_err(|_| fail("it stopped on an internal error".into()))?;
    Ok(joined?)
}

/// The model of the file at `path` at `n` sections (1 without an array) and `closure`, run
/// as native code where this build has the JIT ([`jit`]).
pub fn build(path: &Path, n: usize, closure: Closure) -> Result<Box<dyn Model>, FileError> {
    let def = definition(path)?;
    Ok(Box::new(jit(def.model(n, closure)?)))
}

/// `model` with its tapes compiled to native code (the `jit` feature, on by default:
/// `stirling-jit`); unchanged, run by the interpreter, without it.
pub fn jit(model: CompiledModel) -> CompiledModel {
    #[cfg(feature = "jit")]
    let model = model.with_jit(stirling_jit::jit);
    model
}

/// `model` with the parameters `p` folded in ([`CompiledModel::folded`]), the folded tapes
/// compiled by the system's C compiler where it works (`stirling_jit::cc_jit`: some 0.1 s at
/// n = 2, the code some 12 % faster than Cranelift's there, docs/performance.md), else by the
/// JIT; run by the interpreter without the `jit` feature.
pub fn folded_native(model: &CompiledModel, p: &[f64]) -> CompiledModel {
    #[cfg(feature = "jit")]
    return model.folded_by(p, Some(stirling_jit::cc_jit));
    #[cfg(not(feature = "jit"))]
    model.folded(p)
}
