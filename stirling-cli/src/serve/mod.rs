//! The handlers of `stirling serve`: the page, and the JSON/SVG endpoints it calls.

mod api;
mod query;

use std::panic::{catch_unwind, AssertUnwindSafe};

use serde_json::json;
use tiny_http::{Header, Method, Request, Response};

/// The page: HTML, its script and style, all embedded (no network needed).
const PAGE: &str = include_str!("page.html");
const SCRIPT: &str = include_str!("page.js");

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

/// Answer one request; a handler that panics is a 500, not the end of the server.
pub fn answer(request: Request) {
    let reply = if *request.method() == Method::Get {
        let url = request.url().to_owned();
        catch_unwind(AssertUnwindSafe(|| route(&url)))
            .unwrap_or_else(|_| Reply::error(500, "internal error while computing this request"))
    } else {
        Reply::error(405, "only GET is served")
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

/// The reply to `GET url`.
pub fn route(url: &str) -> Reply {
    let (path, q) = url.split_once('?').unwrap_or((url, ""));
    let handler: fn(&query::Query) -> Reply = match path {
        "/" | "/index.html" => return Reply::ok("text/html; charset=utf-8", PAGE.into()),
        "/page.js" => return Reply::ok("text/javascript; charset=utf-8", SCRIPT.into()),
        "/api/models" => return api::models(),
        "/api/graph" => api::graph,
        "/api/linear" => api::linear,
        "/api/cycle" => api::cycle,
        _ => return Reply::error(404, format!("no page `{path}`")),
    };
    match query::Query::parse(q) {
        Ok(q) => handler(&q),
        Err(e) => Reply::error(400, e),
    }
}
