//! The loader never panics: random bytes, and the family's files mutated (bytes changed,
//! spans cut or doubled, lines swapped, the language's own tokens inserted), are either
//! refused with a message or loaded; what loads is compiled at n = 2 and evaluated.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use stirling::dsl::compiled::Definition;
use stirling::dsl::{Closure, Model};
use stirling::models::files::BASES;
use stirling_front::load::load_str;

/// Tokens of the language, inserted to reach deeper than random bytes do.
const TOKENS: &[&str] = &[
    "{",
    "}",
    "[",
    "]",
    "(",
    ")",
    ";",
    ",",
    ":",
    "->",
    "..",
    "-",
    "/",
    "*",
    "0.0",
    "1e308",
    "n",
    "j",
    "[n]",
    "[j + 1]",
    "for j in 0..n",
    "extends",
    "base",
    "model",
    "cv",
    "link",
    "wall",
    "sensor",
    "effect",
    "free",
    "remove",
    "replace",
    "modify",
    "\"m\"",
    "pi",
    "sqrt(",
    "x",
    "y",
    "P_hot",
    "regen",
    "let",
    "port",
    "faces",
    "in 0.0..1.0",
    "powi(x, 1000)",
    "\u{00e9}",
];

fn examples() -> Vec<(PathBuf, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/engines");
    let mut v: Vec<(PathBuf, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "stirling"))
        .map(|p| {
            let t = std::fs::read_to_string(&p).unwrap();
            (p, t)
        })
        .collect();
    v.sort();
    assert!(v.len() >= 6, "the family's files: {}", v.len());
    v
}

/// One random change of `text`.
fn mutate(text: &str, r: &mut StdRng) -> String {
    let mut b = text.as_bytes().to_vec();
    let at = |r: &mut StdRng, len: usize| r.gen_range(0..=len);
    match r.gen_range(0..6) {
        0 => {
            for _ in 0..r.gen_range(1..4) {
                let k = r.gen_range(0..b.len().max(1));
                if k < b.len() {
                    b[k] = r.gen();
                }
            }
        }
        1 => {
            let i = at(r, b.len());
            let j = (i + r.gen_range(1..40)).min(b.len());
            b.drain(i..j);
        }
        2 => {
            let i = at(r, b.len());
            let j = (i + r.gen_range(1..80)).min(b.len());
            let span = b[i..j].to_vec();
            let k = at(r, b.len());
            b.splice(k..k, span);
        }
        3 => {
            let mut lines: Vec<&str> = text.lines().collect();
            let (i, j) = (r.gen_range(0..lines.len()), r.gen_range(0..lines.len()));
            lines.swap(i, j);
            return lines.join("\n");
        }
        _ => {
            let t = TOKENS[r.gen_range(0..TOKENS.len())];
            let k = at(r, b.len());
            b.splice(k..k, format!(" {t} ").into_bytes());
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

/// Load `text`; if it loads, compile it at n = 2 (or 1) and evaluate every function once.
fn exercise(path: &Path, text: &str) -> bool {
    let Ok(topo) = load_str(path, text, BASES) else {
        return false;
    };
    let def = Definition::new(topo);
    let n = if def.has_array() { 2 } else { 1 };
    if let Ok(m) = def.model(n, Closure::Full) {
        let p = m.default_params();
        let mut x = vec![0.0; m.n_states()];
        m.equilibrium_guess(&p, &mut x);
        let mut f = vec![0.0; m.n_states()];
        m.rhs(&p, &x, 0.0, &mut f);
        let _ = m.jacobian_dense(&p, &x, 0.0);
        let _ = m.param_jacobian_dense(&p, &x, 0.0);
        let _ = (m.energy(&p, &x), m.power(&p, &x));
    }
    true
}

fn never_panics(path: &Path, text: &str) -> bool {
    catch_unwind(AssertUnwindSafe(|| exercise(path, text)))
        .unwrap_or_else(|_| panic!("the loader panicked on:\n{text}"))
}

#[test]
fn random_bytes_are_refused_without_panic() {
    let mut r = StdRng::seed_from_u64(35);
    let path = Path::new("fuzz/random.stirling");
    for _ in 0..200 {
        let len = r.gen_range(0..400);
        let bytes: Vec<u8> = (0..len).map(|_| r.gen()).collect();
        let text = String::from_utf8_lossy(&bytes);
        assert!(!never_panics(path, &text), "random bytes loaded: {text}");
    }
    // random tokens of the language
    for _ in 0..200 {
        let len = r.gen_range(0..60);
        let text: Vec<&str> = (0..len)
            .map(|_| TOKENS[r.gen_range(0..TOKENS.len())])
            .collect();
        never_panics(path, &text.join(" "));
    }
}

#[test]
fn mutated_files_never_panic() {
    let mut r = StdRng::seed_from_u64(7);
    let mut loaded = 0;
    let mut cases = 0;
    for (path, text) in examples() {
        assert!(never_panics(&path, &text), "{} loads", path.display());
        for _ in 0..60 {
            let mut t = text.clone();
            for _ in 0..r.gen_range(1..3) {
                t = mutate(&t, &mut r);
            }
            cases += 1;
            loaded += usize::from(never_panics(&path, &t));
        }
    }
    println!("{cases} mutated files, {loaded} loaded (the rest refused)");
    assert!(cases >= 300);
}
