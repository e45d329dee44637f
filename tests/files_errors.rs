//! Mistakes in an engine file: each refused with `path:line:column: message`, the line and a
//! caret under the user's tokens (the macro's messages), never a panic. One snapshot per
//! mistake (`tests/snapshots/files_errors__*.snap`); every test also asserts the place.

use std::path::{Path, PathBuf};

use stirling::models::files::BASES;
use stirling_front::load::{load_file, load_str, Diagnostic, LoadError};

/// A small valid engine: the family's nsection engine renamed. Each case changes one line.
const GOOD: &str = r#"/// A user's engine.
model Mine extends nsection_engine {
    name "mine";
    params {
        /// bounce-space volume
        Vb0: 2.0e-3 "m^3",
    }
    sensor p_regen: P_regen[0] "Pa";
}
"#;

/// `GOOD` with `from` replaced by `to` (which must occur).
fn edit(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "`{from}` not in the engine");
    GOOD.replacen(from, to, 1)
}

/// The load error of `text`, read as `bad/NAME.stirling`.
fn refused(name: &str, text: &str) -> LoadError {
    let path = PathBuf::from(format!("bad/{name}.stirling"));
    match load_str(&path, text, BASES) {
        Ok(_) => panic!("{name}: loaded"),
        Err(e) => e,
    }
}

/// A diagnostic is at `line:column` and says `says` (the first one, or one the same mistake
/// brings with it); the snapshot holds the whole rendering.
fn check(name: &str, text: &str, line: usize, column: usize, says: &str) -> Diagnostic {
    let e = refused(name, text);
    let rendered = e.to_string();
    let path = format!("bad/{name}.stirling");
    let d = e
        .diagnostics()
        .iter()
        .find(|d| (d.line, d.column) == (line, column))
        .cloned()
        .unwrap_or_else(|| panic!("{name}: nothing at {line}:{column} in {rendered}"));
    assert_eq!(d.path, path, "{rendered}");
    assert!(d.message.contains(says), "{name}: {rendered}");
    assert!(
        rendered.contains(&format!("{path}:{line}:{column}: ")),
        "{rendered}"
    );
    assert!(rendered.contains('^'), "no caret: {rendered}");
    insta::assert_snapshot!(name, rendered);
    d
}

#[test]
fn unknown_name_in_an_expression() {
    let text = edit("Vb0: 2.0e-3", "Vb0: 2.0e-3 * Vr0");
    check("unknown_name", &text, 6, 23, "unknown name `Vr0`");
}

#[test]
fn missing_unit() {
    let text = edit(
        "    sensor p_regen",
        "    sensor emf: 2.0 * w;\n    sensor p_regen",
    );
    check("missing_unit", &text, 8, 12, "needs its unit");
}

#[test]
fn wrong_array_length() {
    let text = edit(
        "    sensor p_regen",
        "    wall mat[m] { capacity: 1.0, rest: Tk }\n    sensor p_regen",
    );
    check(
        "wrong_array_length",
        &text,
        8,
        14,
        "write `[n]`, found `[m]`",
    );
}

#[test]
fn an_index_that_is_not_a_number() {
    let text = edit("P_regen[0]", "P_regen[n]");
    check("array_index", &text, 8, 21, "unsupported expression");
}

#[test]
fn sensor_on_an_unknown_state() {
    let text = edit("P_regen[0]", "P_regn[0]");
    check("sensor_unknown_state", &text, 8, 21, "no state `P_regn`");
}

#[test]
fn unknown_base() {
    let text = edit("extends nsection_engine", "extends nsection_engin");
    check("unknown_base", &text, 2, 20, "nsection_engin");
}

#[test]
fn duplicate_body() {
    let text = edit(
        "    sensor p_regen",
        "    body piston(z, u) { mass: 1.0, spring: 1.0, damper: 1.0 }\n    sensor p_regen",
    );
    check("duplicate_body", &text, 8, 10, "piston");
}

#[test]
fn duplicate_parameter() {
    let text = edit(
        "        Vb0: 2.0e-3",
        "        Vr: 1.0 \"m^3\",\n        Vb0: 2.0e-3",
    );
    check("duplicate_parameter", &text, 6, 9, "Vr");
}

#[test]
fn syntax_error() {
    let text = edit("    name \"mine\";", "    name \"mine\"");
    check("syntax_error", &text, 4, 5, "");
}

#[test]
fn unbalanced_brace() {
    let text = edit(
        "    sensor p_regen: P_regen[0] \"Pa\";\n}",
        "    sensor p_regen: P_regen[0] \"Pa\";",
    );
    let e = refused("unbalanced", &text);
    let d = &e.diagnostics()[0];
    assert!(d.line >= 1 && d.column >= 1, "{e}");
    assert!(e.to_string().contains('^'), "{e}");
    insta::assert_snapshot!("unbalanced", e.to_string());
}

#[test]
fn unknown_item() {
    let text = edit(
        "    sensor p_regen",
        "    cylinder c { area: 1.0 }\n    sensor p_regen",
    );
    check("unknown_item", &text, 8, 5, "cylinder");
}

#[test]
fn unknown_effect() {
    let text = edit(
        "    sensor p_regen",
        "    effect stiction on piston;\n    sensor p_regen",
    );
    check("unknown_effect", &text, 8, 12, "stiction");
}

#[test]
fn cv_without_a_heat_port() {
    let text = edit(
        "    sensor p_regen",
        "    cv extra { volume: Vb0, faces { piston: 1.0e-4 } }\n    sensor p_regen",
    );
    check("cv_without_port", &text, 8, 8, "port");
}

#[test]
fn a_base_is_not_a_model() {
    let text = GOOD.replacen("model Mine", "base mine", 1);
    check("base_not_model", &text, 2, 1, "base");
}

#[test]
fn an_empty_file() {
    let e = refused("empty", "// nothing\n");
    assert!(e.to_string().starts_with("bad/empty.stirling: "), "{e}");
    assert!(e.to_string().contains("empty"), "{e}");
}

/// A directory of this test's files (the paths shown are relative to it in the snapshots).
fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("files_errors")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn shown(e: &LoadError, dir: &Path) -> String {
    e.to_string()
        .replace(&format!("{}/", dir.display()), "")
        .replace(&dir.display().to_string(), "")
}

#[test]
fn a_cycle_of_extends() {
    let d = dir("cycle");
    let a = "base a extends \"b.stirling\" { params { Xa: 1.0 \"m\" } }\n";
    let b = "base b extends \"c.stirling\" { params { Xb: 1.0 \"m\" } }\n";
    let c = "base c extends \"a.stirling\" { params { Xc: 1.0 \"m\" } }\n";
    let top = "model Top extends \"a.stirling\" { name \"top\"; }\n";
    for (f, t) in [("a", a), ("b", b), ("c", c), ("top", top)] {
        std::fs::write(d.join(format!("{f}.stirling")), t).unwrap();
    }
    let e = load_file(&d.join("top.stirling"), BASES).unwrap_err();
    let s = shown(&e, &d);
    assert!(s.contains("cycle"), "{s}");
    assert!(s.starts_with("c.stirling:1:16: "), "{s}");
    insta::assert_snapshot!("extends_cycle", s);
}

#[test]
fn an_extended_file_that_is_not_there() {
    let d = dir("missing");
    let top = "model Top extends \"gone.stirling\" { name \"top\"; }\n";
    std::fs::write(d.join("top.stirling"), top).unwrap();
    let e = load_file(&d.join("top.stirling"), BASES).unwrap_err();
    let s = shown(&e, &d);
    assert!(s.contains("gone.stirling"), "{s}");
    insta::assert_snapshot!("extends_missing", s);
}
