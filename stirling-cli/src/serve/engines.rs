//! The engines edited on the page: a declaration sent to `POST /api/compile` is loaded from
//! its text (no file is read or written: `files::definition_of_text`), checked, built once
//! at the page's `n`, and kept under an id (a hash of the text) for the GET endpoints
//! (`model=@ID`).
//!
//! Bounds: the text at most [`MAX_SOURCE_BYTES`]; the compile at most [`COMPILE_TIMEOUT`]
//! (past it the request is refused; the loader finishes in the background); the last
//! [`KEPT`] engines are kept. Each new text leaks its descriptions (a few kilobytes,
//! `stirling_dsl::compiled`); a text compiled again is found by its id and not reloaded.

use std::collections::hash_map::DefaultHasher;
use std::collections::VecDeque;
use std::hash::{Hash, Hasher};
use std::sync::mpsc;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Duration;

use serde_json::{json, Value};
use stirling_dsl::compiled::Definition;
use stirling_dsl::{Closure, Model};
use stirling_models::files::{self, FileError};

/// The largest declaration the page may send (bytes).
pub const MAX_SOURCE_BYTES: usize = 64 * 1024;
/// The longest a compile may take.
pub const COMPILE_TIMEOUT: Duration = Duration::from_secs(20);
/// How many compiled engines the server keeps.
pub const KEPT: usize = 32;
/// The name a declaration from the page has in its messages.
pub const SHOWN_AS: &str = "engine.stirling";

/// The kept engines, newest last.
fn store() -> &'static Mutex<VecDeque<(String, Arc<Definition>)>> {
    static STORE: OnceLock<Mutex<VecDeque<(String, Arc<Definition>)>>> = OnceLock::new();
    STORE.get_or_init(Default::default)
}

/// Why a declaration did not compile: the status and the JSON body of the reply.
pub struct Refused {
    pub status: u16,
    pub body: Value,
}

/// The id of a text.
fn id_of(text: &str) -> String {
    let mut h = DefaultHasher::new();
    text.hash(&mut h);
    format!("{:016x}", h.finish())
}

/// The engine kept under `id`.
pub fn find(id: &str) -> Option<Arc<Definition>> {
    let kept = store().lock().unwrap_or_else(|e| e.into_inner());
    kept.iter()
        .find(|(k, _)| k == id)
        .map(|(_, d)| Arc::clone(d))
}

fn keep(id: &str, def: &Arc<Definition>) {
    let mut kept = store().lock().unwrap_or_else(|e| e.into_inner());
    kept.retain(|(k, _)| k != id);
    kept.push_back((id.to_string(), Arc::clone(def)));
    while kept.len() > KEPT {
        kept.pop_front();
    }
}

/// The model of `def` at `n` sections (the JIT's where this build has it).
pub fn model(def: &Arc<Definition>, n: usize) -> Result<Box<dyn Model>, String> {
    let m = def.model(n, Closure::Full).map_err(|e| e.to_string())?;
    Ok(Box::new(files::jit(m)))
}

/// Compile `text` and check that it builds at `n` (at 1 without an array): its id and the
/// engine, or the refusal (every diagnostic with its line and column).
pub fn compile(text: &str, n: usize) -> Result<(String, Arc<Definition>), Refused> {
    let id = id_of(text);
    let def = match find(&id) {
        Some(def) => def,
        None => load_bounded(text)?,
    };
    let n = if def.has_array() { n } else { 1 };
    if let Err(e) = def.model(n, Closure::Full) {
        return Err(refused(422, &e.to_string(), Vec::new()));
    }
    keep(&id, &def);
    Ok((id, def))
}

/// Load `text` on a thread of its own, waiting at most [`COMPILE_TIMEOUT`].
fn load_bounded(text: &str) -> Result<Arc<Definition>, Refused> {
    let (tx, rx) = mpsc::channel();
    let owned = text.to_string();
    let spawned = std::thread::Builder::new()
        .name("serve-compile".into())
        .spawn(move || {
            let _ = tx.send(files::definition_of_text(SHOWN_AS, &owned));
        });
    if let Err(e) = spawned {
        return Err(refused(
            503,
            &format!("cannot start the compile: {e}"),
            vec![],
        ));
    }
    match rx.recv_timeout(COMPILE_TIMEOUT) {
        Ok(Ok(def)) => Ok(def),
        Ok(Err(e)) => Err(load_error(&e)),
        Err(mpsc::RecvTimeoutError::Timeout) => Err(refused(
            422,
            &format!(
                "the declaration took longer than {} s to compile: make it smaller",
                COMPILE_TIMEOUT.as_secs()
            ),
            vec![],
        )),
        Err(mpsc::RecvTimeoutError::Disconnected) => Err(refused(
            500,
            "the compile stopped on an internal error",
            vec![],
        )),
    }
}

/// A load error as a refusal: the rendered text and each diagnostic at its place.
fn load_error(e: &FileError) -> Refused {
    let diagnostics = match e {
        FileError::Load(l) => l
            .diagnostics()
            .iter()
            .map(|d| {
                json!({
                    "line": d.line,
                    "column": d.column,
                    "message": d.message,
                    "snippet": d.snippet,
                })
            })
            .collect(),
        _ => Vec::new(),
    };
    refused(422, &e.to_string(), diagnostics)
}

fn refused(status: u16, message: &str, diagnostics: Vec<Value>) -> Refused {
    Refused {
        status,
        body: json!({ "error": message, "diagnostics": diagnostics }),
    }
}
