//! `stirling serve`: the endpoints answer with the numbers the command line prints, follow a
//! parameter change as `stirling linearize --set` does, and refuse bad requests with a 400
//! and a message (plain HTTP/1.1 over a TcpStream; the server on a free port).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};

use serde_json::Value;

/// The server, stopped when the test ends.
struct Server {
    child: Child,
    addr: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn start() -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_stirling"))
        .args(["serve", "--port", "0"])
        .stderr(Stdio::piped())
        .spawn()
        .expect("start stirling serve");
    let mut line = String::new();
    let stderr = child.stderr.take().expect("stderr");
    BufReader::new(stderr)
        .read_line(&mut line)
        .expect("address line");
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|s| s.split('/').next())
        .unwrap_or_else(|| panic!("no address in `{line}`"))
        .to_owned();
    assert!(addr.starts_with("127.0.0.1:"), "binds localhost: {addr}");
    Server { child, addr }
}

/// `GET path`: status and body.
fn get(s: &Server, path: &str) -> (u16, String) {
    let mut c = TcpStream::connect(&s.addr).expect("connect");
    write!(
        c,
        "GET {path} HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n\r\n",
        s.addr
    )
    .unwrap();
    let mut raw = String::new();
    c.read_to_string(&mut raw).expect("read");
    let (head, body) = raw.split_once("\r\n\r\n").expect("a header");
    let status = head
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("status");
    (status, body.to_owned())
}

/// Closed-loop poles from `stirling linearize MODEL --json` with `args`.
fn cli_poles(args: &[&str]) -> Vec<(f64, f64)> {
    let out = Command::new(env!("CARGO_BIN_EXE_stirling"))
        .arg("linearize")
        .args(args)
        .arg("--json")
        .output()
        .expect("run linearize");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    poles(&serde_json::from_slice(&out.stdout).expect("json"))
}

fn poles(report: &Value) -> Vec<(f64, f64)> {
    report["poles"]
        .as_array()
        .expect("poles")
        .iter()
        .map(|p| (p["re"].as_f64().unwrap(), p["im"].as_f64().unwrap()))
        .collect()
}

fn page_poles(s: &Server, query: &str) -> Vec<(f64, f64)> {
    let (status, body) = get(s, &format!("/api/linear?{query}"));
    assert_eq!(status, 200, "{body}");
    let v: Value = serde_json::from_str(&body).expect("json");
    assert!(v["bode"]["w"].as_array().is_some_and(|w| w.len() > 10));
    poles(&v["report"])
}

/// Equal to the 6 decimals `stirling linearize` prints.
fn assert_same(a: &[(f64, f64)], b: &[(f64, f64)]) {
    assert_eq!(a.len(), b.len());
    for (p, q) in a.iter().zip(b) {
        assert_eq!(
            format!("{:.6} {:.6}", p.0, p.1),
            format!("{:.6} {:.6}", q.0, q.1)
        );
    }
}

#[test]
fn poles_equal_the_command_line_and_follow_a_parameter() {
    let s = start();
    let base = page_poles(&s, "model=cv2");
    assert_same(&base, &cli_poles(&["cv2"]));
    let hot = page_poles(&s, "model=cv2&Th=700");
    assert_same(&hot, &cli_poles(&["cv2", "--set", "Th=700"]));
    assert!(
        base.iter().zip(&hot).any(|(a, b)| (a.0 - b.0).abs() > 1e-3),
        "Th moves the poles"
    );
    let n3 = page_poles(&s, "model=nsection&n=3&kd=800");
    assert_same(
        &n3,
        &cli_poles(&["nsection", "--n", "3", "--set", "kd=800"]),
    );
}

#[test]
fn page_graph_and_cycle_are_served() {
    let s = start();
    let (status, page) = get(&s, "/");
    assert_eq!(status, 200);
    assert!(page.contains("/page.js") && !page.contains("http://") && !page.contains("https://"));
    let (status, svg) = get(&s, "/api/graph?model=cv1");
    assert_eq!(status, 200);
    assert!(svg.starts_with("<svg") && svg.contains("I: md"));
    let (status, body) = get(&s, "/api/cycle?model=cv2");
    assert_eq!(status, 200, "{body}");
    let c: Value = serde_json::from_str(&body).unwrap();
    let f = c["frequency_hz"].as_f64().unwrap();
    assert!(f > 1.0 && f < 100.0, "{f}");
    assert!(
        c["power_w"].as_f64().unwrap() > 0.0,
        "the engine delivers power"
    );
    assert_eq!(
        c["x"].as_array().unwrap().len(),
        c["pv"][0].as_array().unwrap().len()
    );
}

#[test]
fn bad_requests_are_400_with_a_message() {
    let s = start();
    for (q, says) in [
        ("model=foo", "unknown model"),
        ("model=cv2&Th=NaN", "not a finite number"),
        ("model=cv2&Th=inf", "not a finite number"),
        ("model=cv2&Th=-5", "not physical"),
        ("model=nsection&n=51", "1 to 50"),
        ("model=nsection&n=zero", "1 to 50"),
        ("model=cv2&nope=1", "nope"),
        ("Th=600", "no `model=`"),
        ("model=cv2&Th", "NAME=VALUE"),
    ] {
        for ep in ["linear", "graph", "cycle"] {
            let (status, body) = get(&s, &format!("/api/{ep}?{q}"));
            assert_eq!(status, 400, "{ep}?{q}: {body}");
            let v: Value = serde_json::from_str(&body).expect("a JSON error");
            let msg = v["error"].as_str().expect("error text");
            assert!(msg.contains(says), "{ep}?{q}: {msg}");
        }
    }
    assert_eq!(get(&s, "/nowhere").0, 404);
    // the server is still up after all that
    assert_eq!(get(&s, "/api/linear?model=cv1").0, 200);
}
