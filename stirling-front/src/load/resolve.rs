//! `extends` resolved: a built-in base by name, another file by path, each loaded once per
//! chain and a cycle refused; then the merge, the parse and the lowering.

use std::path::{Path, PathBuf};

use proc_macro2::{Span, TokenStream};
use quote::ToTokens;
use stirling_dsl::Topology;
use syn::Ident;

use super::error::{Diagnostic, LoadError};
use super::source::Sources;
use super::{BuiltinBase, MAX_FILE_BYTES};
use crate::compose::{self, Decl, Extends, Items};

/// What a declaration was read from (the chain of `extends` being loaded, for cycles).
#[derive(Clone, PartialEq, Eq)]
enum Origin {
    File(PathBuf),
    Builtin(&'static str),
}

/// A load in progress: the texts read and the chain of `extends` being followed.
pub(super) struct Loader<'b> {
    bases: &'b [BuiltinBase],
    sources: Sources,
    chain: Vec<Origin>,
    /// The path shown for messages without a place.
    top: String,
    /// Whether `extends "file"` may read a file (not for a text that came from elsewhere).
    files: bool,
}

/// Why a step failed: diagnostics already placed, or a `syn::Error` to place.
enum Fail {
    Load(LoadError),
    Syn(syn::Error),
}

impl From<syn::Error> for Fail {
    fn from(e: syn::Error) -> Self {
        Fail::Syn(e)
    }
}

impl<'b> Loader<'b> {
    pub(super) fn new(bases: &'b [BuiltinBase]) -> Self {
        Loader {
            bases,
            sources: Sources::default(),
            chain: Vec::new(),
            top: String::new(),
            files: true,
        }
    }

    /// A loader that reads no file: `extends "file"` is refused at its token.
    pub(super) fn without_files(mut self) -> Self {
        self.files = false;
        self
    }

    pub(super) fn top_file(self, path: &Path) -> Result<Topology, LoadError> {
        let text = read(path)?;
        self.top_text(path, &text)
    }

    /// The model of the top-level declaration `text`, read from `path`.
    pub(super) fn top_text(mut self, path: &Path, text: &str) -> Result<Topology, LoadError> {
        self.top = path.display().to_string();
        let shown = self.top.clone();
        let result = self
            .declaration(Origin::File(canonical(path)), &shown, text)
            .and_then(|(decl, items)| {
                if decl.is_base() {
                    return Err(Fail::Syn(not_a_model(&decl, path)));
                }
                Ok(crate::lower(compose::model(&decl, &items)?)?)
            });
        result.map_err(|f| self.placed(f))
    }

    fn placed(&self, f: Fail) -> LoadError {
        match f {
            Fail::Load(e) => e,
            Fail::Syn(e) => LoadError::Invalid(self.sources.render(e, &self.top)),
        }
    }

    /// Read a declaration and resolve what it extends: the declaration and its merged items.
    fn declaration(
        &mut self,
        origin: Origin,
        path: &str,
        text: &str,
    ) -> Result<(Decl, Items), Fail> {
        let tokens = self.sources.tokens(path, text).map_err(invalid)?;
        if tokens.is_empty() {
            let msg = "the file is empty: it declares `model Name { .. }` (or `base name { .. }`)";
            return Err(invalid(Diagnostic {
                path: path.to_string(),
                line: 0,
                column: 0,
                message: msg.to_string(),
                snippet: String::new(),
            }));
        }
        let decl = compose::parse(tokens)?;
        if let Some((name, _)) = &decl.base {
            let msg = "`@base` is put in front by a base's macro in Rust; a file writes `extends`";
            return Err(Fail::Syn(syn::Error::new(name.span(), msg)));
        }
        self.chain.push(origin);
        let items = self.items(&decl);
        self.chain.pop();
        Ok((decl, items?))
    }

    /// The declaration's items, merged with its base's.
    fn items(&mut self, decl: &Decl) -> Result<Items, Fail> {
        let Some(ext) = &decl.extends else {
            return Ok(compose::items(decl.body.clone())?);
        };
        let (origin, path, text, span) = match ext {
            Extends::Path(p) => self.builtin(p)?,
            Extends::File(lit) => self.file(lit)?,
        };
        if self.chain.contains(&origin) {
            let mut names: Vec<String> = self.chain.iter().map(origin_name).collect();
            names.push(origin_name(&origin));
            let msg = format!("`extends` cycle: {}", names.join(" extends "));
            return Err(Fail::Syn(syn::Error::new(span, msg)));
        }
        let (base, items) = self.declaration(origin, &path, &text)?;
        let tokens: TokenStream = items.to_token_stream();
        Ok(compose::merge(
            &base_ident(&base),
            tokens,
            decl.body.clone(),
        )?)
    }

    /// A built-in base by name.
    fn builtin(&self, p: &syn::Path) -> Result<(Origin, String, String, Span), Fail> {
        let span = compose::path_span(p);
        let name = p
            .segments
            .last()
            .map(|s| s.ident.to_string())
            .unwrap_or_default();
        let found = (p.segments.len() == 1)
            .then(|| self.bases.iter().find(|b| b.name == name))
            .flatten();
        let Some(b) = found else {
            let known: Vec<&str> = self.bases.iter().map(|b| b.name).collect();
            let msg = format!(
                "unknown base `{}`: a file extends a built-in base by name ({}) or another file by its path in quotes (`extends \"base.stirling\"`)",
                p.to_token_stream().to_string().replace(' ', ""),
                if known.is_empty() { "none is given".to_string() } else { known.join(", ") }
            );
            return Err(Fail::Syn(syn::Error::new(span, msg)));
        };
        Ok((
            Origin::Builtin(b.name),
            b.path.to_string(),
            b.text.to_string(),
            span,
        ))
    }

    /// Another file, relative to the file that names it.
    fn file(&self, lit: &syn::LitStr) -> Result<(Origin, String, String, Span), Fail> {
        if !self.files {
            let known: Vec<&str> = self.bases.iter().map(|b| b.name).collect();
            let msg = format!(
                "this declaration is not a file: it extends a built-in base by name ({}), not another file",
                known.join(", ")
            );
            return Err(Fail::Syn(syn::Error::new(lit.span(), msg)));
        }
        let dir = match self.chain.last() {
            Some(Origin::File(p)) => p.parent().map(Path::to_path_buf).unwrap_or_default(),
            _ => {
                let msg = "a built-in base cannot extend a file";
                return Err(Fail::Syn(syn::Error::new(lit.span(), msg)));
            }
        };
        let path = dir.join(lit.value());
        let text = read(&path).map_err(|e| {
            Fail::Syn(syn::Error::new(
                lit.span(),
                format!("cannot read `{}`: {}", path.display(), io_reason(&e)),
            ))
        })?;
        Ok((
            Origin::File(canonical(&path)),
            path.display().to_string(),
            text,
            lit.span(),
        ))
    }
}

fn not_a_model(decl: &Decl, path: &Path) -> syn::Error {
    let file = path.file_name().map(|f| f.to_string_lossy().to_string());
    let msg = format!(
        "`base {}` declares no model: a file run by itself declares `model Name {{ .. }}` (a base is extended: `model Mine extends \"{}\" {{ .. }}`)",
        decl.ident,
        file.unwrap_or_default()
    );
    syn::Error::new(decl.kind.span(), msg)
}

fn invalid(d: Diagnostic) -> Fail {
    Fail::Load(LoadError::Invalid(vec![d]))
}

fn io_reason(e: &LoadError) -> String {
    match e {
        LoadError::Read { source, .. } => source.to_string(),
        other => other.to_string(),
    }
}

/// The name the merge reports the base by.
fn base_ident(decl: &Decl) -> Ident {
    decl.ident.clone()
}

fn origin_name(o: &Origin) -> String {
    match o {
        Origin::File(p) => format!(
            "\"{}\"",
            p.file_name()
                .map(|f| f.to_string_lossy().to_string())
                .unwrap_or_default()
        ),
        Origin::Builtin(n) => n.to_string(),
    }
}

fn canonical(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

fn read(path: &Path) -> Result<String, LoadError> {
    let fail = |source| LoadError::Read {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(fail)?;
    if meta.len() > MAX_FILE_BYTES {
        let msg = format!(
            "{} bytes: larger than the {MAX_FILE_BYTES} a declaration may have",
            meta.len()
        );
        return Err(fail(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            msg,
        )));
    }
    std::fs::read_to_string(path).map_err(fail)
}
