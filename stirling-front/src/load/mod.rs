//! The run-time loader: a `.stirling` file read, composed with what it `extends`, checked and
//! lowered to its topology, with the macro's messages at `path:line:column`.
//!
//! A file holds one declaration in the language of `stirling_model!` (`pub` optional):
//!
//! ```text
//! /// A gamma engine: ...
//! model Gamma extends default_engine {      // a built-in base, by name
//!     name "gamma";
//!     cv hot { .. }
//!     ..
//! }
//! ```
//!
//! `extends NAME` names a base the caller provides ([`BuiltinBase`]: the family's
//! `default_engine` and `nsection_engine`); `extends "other.stirling"` another file, by a
//! path relative to the declaring file, which declares a `base` or a `model` (its items are
//! extended; a cycle is refused). The merge is the macro's ([`crate::compose::merge`]), so an
//! extended file means what the same `extends` means in Rust.
//!
//! Errors read like rustc's:
//!
//! ```text
//! engine.stirling:11:19: sensor `p`: no state `P_gass`; ...
//!    |
//! 11 |     sensor p: P_gass "Pa";
//!    |               ^^^^^^
//! ```

mod error;
mod resolve;
mod source;

pub use error::{Diagnostic, LoadError};

use std::path::Path;

use stirling_dsl::Topology;

/// A base the loader knows by name (`extends default_engine`): its text, and the path its
/// messages show.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinBase {
    pub name: &'static str,
    pub path: &'static str,
    pub text: &'static str,
}

/// Files larger than this are refused before they are read as tokens.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Load the model declared in the file at `path`.
pub fn load_file(path: &Path, bases: &[BuiltinBase]) -> Result<Topology, LoadError> {
    resolve::Loader::new(bases).top_file(path)
}

/// Load the model declared in `text`, shown in messages as `path` (a file it extends is
/// found relative to `path`'s directory).
///
/// For a text from elsewhere (typed into a page, sent over a network) use [`load_detached`],
/// which reads no file.
pub fn load_str(path: &Path, text: &str, bases: &[BuiltinBase]) -> Result<Topology, LoadError> {
    resolve::Loader::new(bases).top_text(path, text)
}

/// Load the model declared in `text`, shown in messages as `name`, reading no file: it may
/// extend the built-in `bases` only (`extends "file"` is an error at its token). The text of
/// a page's editor is loaded so: whoever typed it cannot make the loader read the files of
/// the machine it runs on.
pub fn load_detached(name: &str, text: &str, bases: &[BuiltinBase]) -> Result<Topology, LoadError> {
    resolve::Loader::new(bases)
        .without_files()
        .top_text(Path::new(name), text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A declaration that extends a file: the file exists and `load_str` reads it;
    /// `load_detached` refuses it at the quoted path, reading nothing.
    #[test]
    fn a_detached_text_reads_no_file() {
        let dir = std::env::temp_dir().join(format!("stirling-front-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let base = dir.join("base.stirling");
        std::fs::write(&base, "base b { params { a: 1.0 \"-\" } }").unwrap();
        let text = "model M extends \"base.stirling\" {\n    name \"m\";\n}\n";
        let read = load_str(&dir.join("m.stirling"), text, &[]);
        let says = |r: Result<Topology, LoadError>| r.err().map(|e| e.to_string());
        assert!(!says(read).unwrap_or_default().contains("not a file"));
        let shown = dir.join("m.stirling").display().to_string();
        let refused = says(load_detached(&shown, text, &[])).expect("refused");
        assert!(
            refused.contains(":1:17: this declaration is not a file"),
            "{refused}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
