//! `stirling serve`: the endpoints answer with the numbers the command line prints, follow a
//! parameter change as `stirling linearize --set` does, compile an engine declaration sent
//! from the page to the model `stirling linearize` makes of the same text in a file, and
//! refuse bad requests and bad declarations with a message (a declaration's at its line and
//! column), never a crash (plain HTTP/1.1 over a TcpStream; the server on a free port).

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
    request(s, "GET", path, b"")
}

/// `POST path` with `body`: status and body.
fn post(s: &Server, path: &str, body: &[u8]) -> (u16, String) {
    request(s, "POST", path, body)
}

fn request(s: &Server, method: &str, path: &str, body: &[u8]) -> (u16, String) {
    let mut c = TcpStream::connect(&s.addr).expect("connect");
    write!(
        c,
        "{method} {path} HTTP/1.1\r\nHost: {}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
        s.addr,
        body.len()
    )
    .unwrap();
    // a server that refuses a body before reading it may close early: read its answer anyway
    let _ = c.write_all(body);
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

/// cv2's declaration (the page's starting text for `cv2`) with `text` inserted before its
/// last `}`, as a user types it into the editor.
fn edited_cv2(text: &str) -> String {
    let src = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/engines/cv2.stirling"
    ))
    .expect("cv2.stirling");
    let end = src.rfind('}').expect("a closing brace");
    format!("{}{text}\n{}", &src[..end], &src[end..])
}

/// `POST /api/compile`: the engine's id.
fn compile(s: &Server, text: &str) -> String {
    let (status, body) = post(s, "/api/compile", text.as_bytes());
    assert_eq!(status, 200, "{body}");
    let v: Value = serde_json::from_str(&body).expect("json");
    v["id"].as_str().expect("id").to_owned()
}

/// A default replaced and a load damper added on the piston.
const EDIT: &str = r#"    replace params { Th: 650.0 "K" }
    params { /// a load on the piston
        c_load: 2.0 "N s/m" }
    modify body piston { force: -c_load * w }"#;

#[test]
fn an_edited_declaration_shows_the_poles_of_the_same_file() {
    let s = start();
    let text = edited_cv2(EDIT);
    let file = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("serve_edited.stirling");
    std::fs::write(&file, &text).unwrap();
    let id = compile(&s, &text);
    let edited = page_poles(&s, &format!("model=@{id}"));
    assert_same(&edited, &cli_poles(&[file.to_str().unwrap()]));
    assert_ne!(
        format!("{edited:.3?}"),
        format!("{:.3?}", page_poles(&s, "model=cv2")),
        "the edit moves the poles"
    );
    // a slider on the edited engine is `--set` on the file
    let kp = page_poles(&s, &format!("model=@{id}&kp=200&c_load=5"));
    assert_same(
        &kp,
        &cli_poles(&[
            file.to_str().unwrap(),
            "--set",
            "kp=200",
            "--set",
            "c_load=5",
        ]),
    );
    let (status, body) = get(&s, &format!("/api/equations?model=@{id}"));
    assert_eq!(status, 200, "{body}");
    let v: Value = serde_json::from_str(&body).unwrap();
    assert!(v["equations"].as_str().unwrap().contains("c_load"));
    let th = v["params"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "Th");
    assert_eq!(th.unwrap()["default"].as_f64(), Some(650.0));
    let (status, svg) = get(&s, &format!("/api/graph?model=@{id}"));
    assert!(status == 200 && svg.starts_with("<svg"), "{svg}");
    let (status, body) = get(&s, &format!("/api/cycle?model=@{id}"));
    assert_eq!(status, 200, "{body}");
    // the same text again is the same engine
    assert_eq!(compile(&s, &text), id);
}

#[test]
fn an_edited_array_engine_follows_n() {
    let s = start();
    let text = "model Mine extends nsection_engine {\n    name \"mine\";\n    replace params { kd: 800.0 \"N/m\" }\n}\n";
    let (status, body) = post(&s, "/api/compile?n=3", text.as_bytes());
    assert_eq!(status, 200, "{body}");
    let v: Value = serde_json::from_str(&body).unwrap();
    assert_eq!(v["has_array"], true);
    let id = v["id"].as_str().unwrap();
    assert_same(
        &page_poles(&s, &format!("model=@{id}&n=3")),
        &cli_poles(&["nsection", "--n", "3", "--set", "kd=800"]),
    );
}

/// A refused declaration: the status, the message, and the first diagnostic's line.
fn refused(s: &Server, body: &[u8]) -> (u16, String, Option<u64>) {
    let (status, text) = post(s, "/api/compile", body);
    let v: Value = serde_json::from_str(&text).unwrap_or_else(|_| panic!("JSON: {text}"));
    let msg = v["error"].as_str().expect("error text").to_owned();
    let line = v["diagnostics"][0]["line"].as_u64();
    (status, msg, line)
}

#[test]
fn bad_declarations_are_refused_at_their_place() {
    let s = start();
    let typo = edited_cv2("    sensor q: P_colt \"Pa\";");
    let typo_line = typo.lines().position(|l| l.contains("P_colt")).unwrap() as u64 + 1;
    let cases: Vec<(String, &str, Option<u64>)> = vec![
        (typo, "no state `P_colt`", Some(typo_line)),
        (
            "model X extends \"/etc/passwd.stirling\" { name \"x\"; }".into(),
            "not a file",
            Some(1),
        ),
        (
            "model X extends \"../examples/engines/cv2.stirling\" { name \"x\"; }".into(),
            "not a file",
            Some(1),
        ),
        ("".into(), "empty", None),
        ("model X extends default_engine {".into(), "", Some(1)),
        (
            "model X extends nowhere { name \"x\"; }".into(),
            "unknown base",
            Some(1),
        ),
        (
            format!(
                "model X extends default_engine {{ let a = {}1{}; }}",
                "(".repeat(5000),
                ")".repeat(5000)
            ),
            "nested deeper",
            Some(1),
        ),
        ("base b { }".into(), "declares no model", Some(1)),
        ("\u{0}\u{1}\"".into(), "", None),
        (
            "model X extends default_engine { name \"x\"; cv a { volume: 1.0 / 0.0 } }".into(),
            "",
            None,
        ),
    ];
    for (text, says, line) in cases {
        let (status, msg, at) = refused(&s, text.as_bytes());
        let short: String = text.chars().take(60).collect();
        assert_eq!(status, 422, "{short}: {msg}");
        assert!(msg.contains(says), "{short}: {msg}");
        if line.is_some() {
            assert_eq!(at, line, "{short}: {msg}");
        }
    }
    let (status, msg, _) = refused(&s, &[0xff, 0xfe, b'm']);
    assert_eq!(status, 400, "{msg}");
    assert!(msg.contains("UTF-8"), "{msg}");
    let big = "/".repeat(70 * 1024);
    let (status, msg, _) = refused(&s, big.as_bytes());
    assert_eq!(status, 413, "{msg}");
    let (status, msg, _) = refused(&s, b"");
    assert_eq!(status, 422, "{msg}");
    for (path, code) in [
        ("/api/compile?n=0", 400),
        ("/api/compile?n=99", 400),
        ("/api/linear", 405),
    ] {
        assert_eq!(post(&s, path, b"x").0, code, "{path}");
    }
    // the GET endpoints read no file and know only the engines compiled
    for (q, says) in [
        ("model=@0123456789abcdef", "no engine compiled"),
        ("model=examples/engines/cv2.stirling", "reads no file"),
    ] {
        let (status, body) = get(&s, &format!("/api/linear?{q}"));
        assert_eq!(status, 400, "{body}");
        assert!(body.contains(says), "{body}");
    }
    // the server is still up, and still compiles
    compile(&s, &edited_cv2(""));
}

/// Every prefix of an edited declaration (as typed, one cut every 7 characters) and every
/// declaration with one character replaced is answered, never with a 500 or a crash.
#[test]
fn no_declaration_crashes_the_server() {
    let s = start();
    let text = edited_cv2(EDIT);
    let chars: Vec<char> = text.chars().collect();
    let mut texts: Vec<String> = (0..chars.len())
        .step_by(7)
        .map(|k| chars[..k].iter().collect())
        .collect();
    for (k, c) in (0..chars.len())
        .step_by(11)
        .zip("{}()[];:,.-*/\"#@!0e".chars().cycle())
    {
        let mut t = chars.clone();
        t[k] = c;
        texts.push(t.into_iter().collect());
    }
    for t in &texts {
        let (status, body) = post(&s, "/api/compile", t.as_bytes());
        assert!(status == 200 || status == 422, "{status}: {body}\n{t}");
        if status == 200 {
            let id = serde_json::from_str::<Value>(&body).unwrap()["id"]
                .as_str()
                .unwrap()
                .to_owned();
            let (status, body) = get(&s, &format!("/api/linear?model=@{id}"));
            assert!(
                status == 200 || status == 400 || status == 422,
                "{status}: {body}\n{t}"
            );
        }
    }
    assert_eq!(get(&s, "/api/linear?model=cv1").0, 200);
}
