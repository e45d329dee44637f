//! The handlers of `stirling serve`: the page, and the JSON/SVG endpoints it calls.
//!
//! Every request is computed on a worker thread and answered within [`REQUEST_TIMEOUT`]
//! (a 503 past it; the computation, itself bounded, finishes in the background); at most
//! [`MAX_WORKERS`] run at once. A handler that panics is a 500, not the end of the server.

mod api;
mod edit;
mod engines;
mod query;

use std::io::Read;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use serde_json::json;
use tiny_http::{Header, Method, Request, Response};

pub use engines::MAX_SOURCE_BYTES;

/// The page: HTML, its script and style, all embedded (no network needed).
const PAGE: &str = include_str!("page.html");
const SCRIPT: &str = include_str!("page.js");

/// The longest the server computes one request before answering 503.
pub const REQUEST_TIMEOUT: Duration = Duration::from_secs(30);
/// Requests computed at once (those past their deadline included).
pub const MAX_WORKERS: usize = 4;
/// The stack of a worker (the bond graph and the analyses of a large model recurse).
const WORKER_STACK: usize = 64 << 20;

static WORKERS: AtomicUsize = AtomicUsize::new(0);

/// A worker's place among the [`MAX_WORKERS`], given back when it ends (a panic too).
struct Slot;

impl Slot {
    fn take() -> Option<Slot> {
        if WORKERS.fetch_add(1, Ordering::SeqCst) >= MAX_WORKERS {
            WORKERS.fetch_sub(1, Ordering::SeqCst);
            return None;
        }
        Some(Slot)
    }
}

impl Drop for Slot {
    fn drop(&mut self) {
        WORKERS.fetch_sub(1, Ordering::SeqCst);
    }
}

/// A reply: status, content type, body.
pub struct Reply {
    pub status: u16,
    pub content_type: &'static str,
    pub body: String,
}

impl Reply {
    fn ok(content_type: &'static str, body: String) -> Reply {
        Reply {
            status: 200,
            content_type,
            body,
        }
    }

    /// A JSON error `{"error": message}` with `status`.
    pub fn error(status: u16, message: impl std::fmt::Display) -> Reply {
        Reply {
            status,
            content_type: "application/json",
            body: json!({ "error": message.to_string() }).to_string(),
        }
    }
}

/// Answer one request.
pub fn answer(mut request: Request) {
    let url = request.url().to_owned();
    let reply = match request.method() {
        Method::Get => within_deadline(move || route(&url)),
        Method::Post => match read_body(&mut request) {
            Ok(body) => within_deadline(move || post(&url, &body)),
            Err(refusal) => refusal,
        },
        _ => Reply::error(405, "only GET and POST (/api/compile) are served"),
    };
    // a plain Content-Length body (no chunking), the simplest for any client
    let mut response = Response::from_string(reply.body)
        .with_status_code(reply.status)
        .with_chunked_threshold(usize::MAX);
    if let Ok(h) = Header::from_bytes("Content-Type", reply.content_type) {
        response.add_header(h);
    }
    // a client that went away is no error of the server
    let _ = request.respond(response);
}

/// The body of a POST: UTF-8 text of at most [`MAX_SOURCE_BYTES`].
fn read_body(request: &mut Request) -> Result<String, Reply> {
    let too_large = || {
        Reply::error(
            413,
            format!("the body is larger than the {MAX_SOURCE_BYTES} bytes a declaration may have"),
        )
    };
    if request.body_length().is_some_and(|n| n > MAX_SOURCE_BYTES) {
        return Err(too_large());
    }
    let mut raw = Vec::new();
    let limit = MAX_SOURCE_BYTES as u64 + 1;
    if let Err(e) = request.as_reader().take(limit).read_to_end(&mut raw) {
        return Err(Reply::error(400, format!("reading the body: {e}")));
    }
    if raw.len() > MAX_SOURCE_BYTES {
        return Err(too_large());
    }
    String::from_utf8(raw)
        .map_err(|e| Reply::error(400, format!("the body is not UTF-8 text: {e}")))
}

/// `work()` on a worker thread, answered within [`REQUEST_TIMEOUT`].
fn within_deadline<F: FnOnce() -> Reply + Send + 'static>(work: F) -> Reply {
    let Some(slot) = Slot::take() else {
        return Reply::error(503, "the server is busy with earlier requests; try again");
    };
    let (tx, rx) = mpsc::channel();
    let spawned = std::thread::Builder::new()
        .name("serve-worker".into())
        .stack_size(WORKER_STACK)
        .spawn(move || {
            let _slot = slot;
            // on a panic `tx` is dropped unsent: the receiver sees it as a disconnect
            let _ = tx.send(work());
        });
    if let Err(e) = spawned {
        return Reply::error(503, format!("cannot start a worker: {e}"));
    }
    match rx.recv_timeout(REQUEST_TIMEOUT) {
        Ok(reply) => reply,
        Err(mpsc::RecvTimeoutError::Timeout) => Reply::error(
            503,
            format!(
                "the computation took longer than {} s",
                REQUEST_TIMEOUT.as_secs()
            ),
        ),
        Err(mpsc::RecvTimeoutError::Disconnected) => {
            Reply::error(500, "internal error while computing this request")
        }
    }
}

/// The reply to `POST url` with `body`.
fn post(url: &str, body: &str) -> Reply {
    let (path, q) = url.split_once('?').unwrap_or((url, ""));
    match path {
        "/api/compile" => edit::compile(q, body),
        _ => Reply::error(
            405,
            format!("`{path}` is not posted to (only /api/compile)"),
        ),
    }
}

/// The reply to `GET url`.
pub fn route(url: &str) -> Reply {
    let (path, q) = url.split_once('?').unwrap_or((url, ""));
    let handler: fn(&query::Query) -> Reply = match path {
        "/" | "/index.html" => return Reply::ok("text/html; charset=utf-8", PAGE.into()),
        "/page.js" => return Reply::ok("text/javascript; charset=utf-8", SCRIPT.into()),
        "/api/models" => return api::models(),
        "/api/source" => return edit::source(q),
        "/api/graph" => api::graph,
        "/api/linear" => api::linear,
        "/api/cycle" => api::cycle,
        "/api/equations" => edit::equations,
        _ => return Reply::error(404, format!("no page `{path}`")),
    };
    match query::Query::parse(q) {
        Ok(q) => handler(&q),
        Err(e) => Reply::error(400, e),
    }
}
