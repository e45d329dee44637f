//! Parameter sets: TOML and JSON files by name, `--set name=value` overrides, unknown names
//! rejected with the list of valid ones, and validation of physical ranges.

use std::path::PathBuf;

use stirling::dsl::{Closure, Model};
use stirling::models::build;
use stirling::models::params::{load, ParamError};

fn model() -> Box<dyn Model> {
    build("cv2", None, Closure::Full).unwrap()
}

/// A fresh file under cargo's per-target scratch directory.
fn file(name: &str, text: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("params_files");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn value(m: &dyn Model, p: &[f64], name: &str) -> f64 {
    p[m.param_index(name).unwrap()]
}

fn sets(s: &[&str]) -> Vec<String> {
    s.iter().map(|s| s.to_string()).collect()
}

#[test]
fn defaults_without_file_or_overrides() {
    let m = model();
    assert_eq!(load(m.as_ref(), None, &[]).unwrap(), m.default_params());
}

#[test]
fn toml_file_sets_parameters_by_name() {
    let m = model();
    let path = file(
        "hot.toml",
        "# a hotter engine\nTh = 700.0\nRf = 2e5\nhh = 800\n",
    );
    let p = load(m.as_ref(), Some(&path), &[]).unwrap();
    assert_eq!(value(m.as_ref(), &p, "Th"), 700.0);
    assert_eq!(value(m.as_ref(), &p, "Rf"), 2e5);
    assert_eq!(
        value(m.as_ref(), &p, "hh"),
        800.0,
        "TOML integers are numbers too"
    );
    assert_eq!(
        value(m.as_ref(), &p, "Tk"),
        300.0,
        "unnamed parameters keep their defaults"
    );
}

#[test]
fn json_file_sets_parameters_by_name() {
    let m = model();
    let path = file("set.json", r#"{ "Pmean": 2.0e6, "Pb": 2.0e6, "md": 0.1 }"#);
    let p = load(m.as_ref(), Some(&path), &[]).unwrap();
    assert_eq!(value(m.as_ref(), &p, "Pmean"), 2.0e6);
    assert_eq!(value(m.as_ref(), &p, "Pb"), 2.0e6);
    assert_eq!(value(m.as_ref(), &p, "md"), 0.1);
}

#[test]
fn overrides_apply_after_the_file() {
    let m = model();
    let path = file("base.toml", "Th = 700.0\n");
    let p = load(m.as_ref(), Some(&path), &sets(&["Th=650", " kd = 700.5 "])).unwrap();
    assert_eq!(value(m.as_ref(), &p, "Th"), 650.0);
    assert_eq!(value(m.as_ref(), &p, "kd"), 700.5);
}

#[test]
fn unknown_names_are_rejected_with_the_valid_list() {
    let m = model();
    for err in [
        load(m.as_ref(), Some(&file("typo.toml", "Thot = 700.0\n")), &[]).unwrap_err(),
        load(
            m.as_ref(),
            Some(&file("typo.json", r#"{"Thot": 700.0}"#)),
            &[],
        )
        .unwrap_err(),
        load(m.as_ref(), None, &sets(&["Thot=700"])).unwrap_err(),
    ] {
        let ParamError::Unknown { name, valid, .. } = &err else {
            panic!("expected Unknown, got {err:?}")
        };
        assert_eq!(name, "Thot");
        let text = err.to_string();
        assert!(
            text.contains("Thot") && text.contains("valid parameters"),
            "{text}"
        );
        for p in m.params() {
            assert!(
                valid.split(", ").any(|v| v == p.name),
                "`{}` missing from the list: {valid}",
                p.name
            );
        }
    }
}

#[test]
fn malformed_overrides_and_values_are_errors() {
    let m = model();
    let bad = |s: &str| load(m.as_ref(), None, &sets(&[s])).unwrap_err();
    assert!(matches!(bad("Th"), ParamError::BadOverride(_)));
    assert!(matches!(bad("Th=hot"), ParamError::NotANumber { .. }));
    assert!(matches!(bad("Th="), ParamError::NotANumber { .. }));
    assert!(matches!(bad("=600"), ParamError::Unknown { .. }));
    assert!(bad("Th").to_string().contains("name=value"));
    let text = load(m.as_ref(), Some(&file("str.toml", "Th = \"hot\"\n")), &[]).unwrap_err();
    assert!(matches!(text, ParamError::NotANumber { .. }), "{text:?}");
    let json = load(m.as_ref(), Some(&file("broken.json", "{ \"Th\": ")), &[]).unwrap_err();
    assert!(matches!(json, ParamError::Parse { .. }), "{json:?}");
    let toml = load(m.as_ref(), Some(&file("broken.toml", "Th = = 3")), &[]).unwrap_err();
    assert!(matches!(toml, ParamError::Parse { .. }), "{toml:?}");
    let missing = load(
        m.as_ref(),
        Some(&PathBuf::from("/nonexistent/params.toml")),
        &[],
    )
    .unwrap_err();
    assert!(matches!(missing, ParamError::Read { .. }), "{missing:?}");
}

#[test]
fn scientific_and_signed_numbers_parse() {
    let m = model();
    let p = load(m.as_ref(), None, &sets(&["Rf=1.5e5", "mdot_eps=+2E-6"])).unwrap();
    assert_eq!(value(m.as_ref(), &p, "Rf"), 1.5e5);
    assert_eq!(value(m.as_ref(), &p, "mdot_eps"), 2e-6);
}

/// The name of the offending parameter of an unphysical set.
fn rejected(s: &[&str]) -> String {
    let m = model();
    match load(m.as_ref(), None, &sets(s)) {
        Err(ParamError::Unphysical { name, why, .. }) => {
            assert!(!why.is_empty());
            name
        }
        other => panic!("{s:?}: expected Unphysical, got {other:?}"),
    }
}

#[test]
fn validation_rejects_unphysical_values() {
    assert_eq!(rejected(&["Vh0=-1e-4"]), "Vh0", "negative volume");
    assert_eq!(rejected(&["Vr=0"]), "Vr", "zero volume");
    assert_eq!(rejected(&["Th=300"]), "Th", "Th = Tk");
    assert_eq!(rejected(&["Th=250"]), "Th", "Th < Tk");
    assert_eq!(rejected(&["Tk=-5"]), "Tk", "negative temperature");
    assert_eq!(rejected(&["Ar=0.0028274333882308137"]), "Ar", "Ar = A");
    assert_eq!(rejected(&["Ar=0.01"]), "Ar", "Ar > A");
    assert_eq!(rejected(&["md=0"]), "md", "zero mass");
    assert_eq!(rejected(&["mp=-0.3"]), "mp", "negative mass");
    assert_eq!(rejected(&["gamma=1"]), "gamma", "gamma must exceed 1");
    assert_eq!(rejected(&["Pmean=0"]), "Pmean", "zero pressure");
    assert_eq!(rejected(&["kd=-1"]), "kd", "negative spring");
    assert_eq!(rejected(&["Th=nan"]), "Th", "NaN");
    assert_eq!(rejected(&["Rf=inf"]), "Rf", "infinite");
}

#[test]
fn validation_errors_read_well() {
    let m = model();
    let e = load(m.as_ref(), None, &sets(&["Th=250"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("Th") && e.contains("250") && e.contains("hotter"),
        "{e}"
    );
    let e = load(m.as_ref(), None, &sets(&["Ar=0.01"]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("Ar") && e.contains("thinner"), "{e}");
    let e = load(m.as_ref(), None, &sets(&["md=0"]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("md") && e.contains("positive"), "{e}");
}

#[test]
fn a_valid_file_of_every_parameter_round_trips() {
    let m = model();
    let mut toml = String::new();
    for p in m.params() {
        toml.push_str(&format!("{} = {:e}\n", p.name, p.default));
    }
    let p = load(m.as_ref(), Some(&file("all.toml", &toml)), &[]).unwrap();
    assert_eq!(p, m.default_params());
}

#[test]
fn nonfinite_toml_values_and_wrong_formats_say_what_and_how_read() {
    let model = build("cv2", None, Closure::Full).unwrap();
    let dir = std::env::temp_dir().join(format!("stirling_params_fmt_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let nan = dir.join("nan.toml");
    std::fs::write(&nan, "Th = nan\n").unwrap();
    let e = load(model.as_ref(), Some(&nan), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`Th`") && e.contains("NaN (not a finite number)"),
        "{e}"
    );
    let json_in_toml = dir.join("p.toml");
    std::fs::write(&json_in_toml, "{\"Th\": 650}").unwrap();
    let e = load(model.as_ref(), Some(&json_in_toml), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("read as TOML") && e.contains("looks like JSON"),
        "{e}"
    );
    let toml_in_json = dir.join("p.json");
    std::fs::write(&toml_in_json, "Th = 650\n").unwrap();
    let e = load(model.as_ref(), Some(&toml_in_json), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("read as JSON") && e.contains("rename it to .toml"),
        "{e}"
    );
}
