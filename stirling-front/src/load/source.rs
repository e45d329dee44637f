//! The texts a load has read, so that a span (which knows only the text it came from, by
//! proc-macro2's label `<parsed string K>`) is shown as `path:line:column` with its line.

use std::collections::HashMap;
use std::str::FromStr;

use proc_macro2::{Span, TokenStream, TokenTree};

use super::error::Diagnostic;

/// One text read: the path shown in messages and the text.
struct Text {
    path: String,
    text: String,
}

/// The texts read so far, by proc-macro2's label of their spans.
#[derive(Default)]
pub(super) struct Sources {
    texts: Vec<Text>,
    by_label: HashMap<String, usize>,
}

/// Nesting of brackets deeper than this is refused before the text is parsed (the parser and
/// the checks recurse once per level).
const MAX_DEPTH: usize = 64;
/// Tokens in one file beyond this are refused (an expression's depth grows with its terms).
const MAX_TOKENS: usize = 200_000;

impl Sources {
    /// Tokenize `text` (shown as `path`), remembering it for the messages.
    pub(super) fn tokens(&mut self, path: &str, text: &str) -> Result<TokenStream, Diagnostic> {
        if let Some((line, column)) = too_deep(text) {
            let msg = format!("brackets nested deeper than {MAX_DEPTH} levels");
            return Err(self.at_line(path, text, line, column, &msg));
        }
        let tokens = TokenStream::from_str(text).map_err(|e| {
            let s = e.span();
            let (a, b) = (s.start(), s.end());
            let span = (a.line, a.column, b.line, b.column);
            diagnostic(path, text, Some(span), &lex_message(&e.to_string()))
        })?;
        if let Some(first) = first_span(&tokens) {
            self.by_label.insert(first.file(), self.texts.len());
        }
        self.texts.push(Text {
            path: path.to_string(),
            text: text.to_string(),
        });
        if count(&tokens) > MAX_TOKENS {
            let msg = format!("more than {MAX_TOKENS} tokens: split the declaration");
            return Err(diagnostic(path, text, None, &msg));
        }
        Ok(tokens)
    }

    /// `err`'s messages at their places; a message without a place (a token the front end
    /// made) is shown at `fallback`'s path.
    pub(super) fn render(&self, err: syn::Error, fallback: &str) -> Vec<Diagnostic> {
        err.into_iter()
            .map(|e| self.one(e.span(), &e.to_string(), fallback))
            .collect()
    }

    fn one(&self, span: Span, message: &str, fallback: &str) -> Diagnostic {
        let Some(t) = self.by_label.get(&span.file()).map(|&k| &self.texts[k]) else {
            return Diagnostic {
                path: fallback.to_string(),
                line: 0,
                column: 0,
                message: message.to_string(),
                snippet: String::new(),
            };
        };
        let (a, b) = (span.start(), span.end());
        diagnostic(
            &t.path,
            &t.text,
            Some((a.line, a.column, b.line, b.column)),
            message,
        )
    }

    fn at_line(&self, path: &str, text: &str, line: usize, col: usize, msg: &str) -> Diagnostic {
        diagnostic(path, text, Some((line, col, line, col + 1)), msg)
    }
}

/// The first span of a token stream (descending into groups).
fn first_span(ts: &TokenStream) -> Option<Span> {
    ts.clone().into_iter().next().map(|t| match t {
        TokenTree::Group(g) => first_span(&g.stream()).unwrap_or(g.span_open()),
        other => other.span(),
    })
}

fn count(ts: &TokenStream) -> usize {
    ts.clone()
        .into_iter()
        .map(|t| match t {
            TokenTree::Group(g) => 1 + count(&g.stream()),
            _ => 1,
        })
        .sum()
}

/// proc-macro2's lexer says `cannot parse string into token stream` with its position in
/// Debug only: say what is usually wrong.
fn lex_message(raw: &str) -> String {
    let _ = raw;
    "cannot read this as tokens: an unclosed or unmatched bracket, an unterminated string or comment, or a character the language does not use".to_string()
}

/// The line and column (1-based line, 0-based column) of the first bracket nested deeper than
/// [`MAX_DEPTH`], outside strings and comments.
fn too_deep(text: &str) -> Option<(usize, usize)> {
    let (mut depth, mut line, mut col) = (0usize, 1usize, 0usize);
    let mut chars = text.chars().peekable();
    let (mut in_str, mut line_comment, mut block) = (false, false, 0usize);
    while let Some(c) = chars.next() {
        let next = chars.peek().copied();
        match c {
            '\n' => {
                line += 1;
                col = 0;
                line_comment = false;
                continue;
            }
            _ if line_comment => {}
            '*' if block > 0 && next == Some('/') => {
                chars.next();
                block -= 1;
                col += 1;
            }
            '/' if !in_str && next == Some('*') => {
                chars.next();
                block += 1;
                col += 1;
            }
            _ if block > 0 => {}
            '\\' if in_str => {
                chars.next();
                col += 1;
            }
            '"' => in_str = !in_str,
            _ if in_str => {}
            '/' if next == Some('/') => line_comment = true,
            '(' | '[' | '{' => {
                depth += 1;
                if depth > MAX_DEPTH {
                    return Some((line, col));
                }
            }
            ')' | ']' | '}' => depth = depth.saturating_sub(1),
            _ => {}
        }
        col += 1;
    }
    None
}

/// `path:line:col: message`, then the line and a caret under the span (`(line, col, end line,
/// end col)`, lines 1-based, columns 0-based in characters).
fn diagnostic(
    path: &str,
    text: &str,
    span: Option<(usize, usize, usize, usize)>,
    message: &str,
) -> Diagnostic {
    let Some((line, col, end_line, end_col)) = span.filter(|s| s.0 >= 1) else {
        return Diagnostic {
            path: path.to_string(),
            line: 0,
            column: 0,
            message: message.to_string(),
            snippet: String::new(),
        };
    };
    let src = text.lines().nth(line - 1).unwrap_or("");
    let len = src.chars().count();
    let start = col.min(len);
    let end = if end_line == line {
        end_col.min(len)
    } else {
        len
    };
    let width = end.saturating_sub(start).max(1);
    // keep tabs so that the caret lines up under the text
    let pad: String = src
        .chars()
        .take(start)
        .map(|c| if c == '\t' { '\t' } else { ' ' })
        .collect();
    let num = line.to_string();
    let gutter = " ".repeat(num.len());
    let snippet = format!(
        "{gutter} |\n{num} | {src}\n{gutter} | {pad}{}",
        "^".repeat(width)
    );
    Diagnostic {
        path: path.to_string(),
        line,
        column: col + 1,
        message: message.to_string(),
        snippet,
    }
}
