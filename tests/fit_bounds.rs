//! Parameter bounds of the fit: declared with the model (`kd: 630.0 "N/m" in 600.0..640.0`)
//! or given in a file (`stirling fit --bounds FILE`, `FitOptions::bounds`, over the declared
//! ones). A fit whose data want a value outside stays inside and says it ended at the bound;
//! a start outside, an unknown name or a bad range is a clear error.

use std::io::Write;

use stirling::dsl::{Closure, Model};
use stirling::models::bounds::load_bounds;
use stirling::models::fit::{self, FitError, FitOptions};
use stirling::models::rig::{self, RigConfig};
use stirling::stirling_model;

stirling_model! {
    /// `nsection` with the displacer's spring declared in 600..640 N/m (its default 630).
    pub model Bounded extends stirling::models::nsection_engine {
        replace params {
            /// displacer spring, bounded
            kd: 630.0 "N/m" in 600.0..640.0,
        }
    }
}

/// A record of `nsection` n = 1 with the displacer spring at 650.74 N/m (the default),
/// outside `Bounded`'s range.
fn record() -> stirling::models::data::Measured {
    let cfg = RigConfig {
        model: "nsection".into(),
        channels: ["p", "x", "y"].map(String::from).to_vec(),
        n: Some(1),
        t_end: 0.6,
        settle: 0.4,
        rate: 2000.0,
        seed: 3,
        ..Default::default()
    };
    rig::run(&cfg).unwrap().data
}

fn free() -> Option<Vec<String>> {
    Some(["kd", "kp", "bd", "bp"].map(String::from).to_vec())
}

fn kd(res: &fit::Identification) -> f64 {
    res.params.iter().find(|(n, _)| n == "kd").unwrap().1
}

#[test]
fn the_declaration_carries_its_bounds() {
    let m = Bounded::new(1, Closure::Full).unwrap();
    let info = &m.params()[m.param_index("kd").unwrap()];
    assert_eq!(info.bounds, Some((600.0, 640.0)));
    assert_eq!(m.params()[m.param_index("kp").unwrap()].bounds, None);
}

/// The data want kd = 650.74; the declared bound keeps the fit at or below 640 and the
/// identification notes it ended there. The same bound given in the options does the same
/// on the unbounded model, and without it the fit goes past 640.
#[test]
fn a_fit_stays_inside_its_bounds_and_says_so() {
    let rec = record();
    let stage1 = |m: &dyn Model, bounds: Vec<(String, f64, f64)>, p0: Vec<f64>| {
        let opts = FitOptions {
            free: free(),
            stage2: false,
            free_run: None,
            bounds,
            ..Default::default()
        };
        fit::identify(m, &p0, &rec, &opts).unwrap()
    };
    let m = Bounded::new(1, Closure::Full).unwrap();
    let res = stage1(&m, Vec::new(), m.default_params());
    let v = kd(&res);
    eprintln!("declared: kd {v}, notes {:?}", res.notes);
    assert!((600.0..=640.0).contains(&v), "kd {v}");
    assert!(v > 635.0, "kd {v} should press against the bound");
    assert!(
        res.notes
            .iter()
            .any(|n| n.contains("`kd`") && n.contains("upper bound")),
        "{:?}",
        res.notes
    );
    let plain = stirling::models::build("nsection", Some(1), Closure::Full).unwrap();
    let mut p0 = plain.default_params();
    p0[plain.param_index("kd").unwrap()] = 630.0;
    let given = stage1(
        plain.as_ref(),
        vec![("kd".into(), 600.0, 640.0)],
        p0.clone(),
    );
    assert!((600.0..=640.0).contains(&kd(&given)), "kd {}", kd(&given));
    let free_fit = stage1(plain.as_ref(), Vec::new(), p0);
    eprintln!("unbounded: kd {}", kd(&free_fit));
    assert!(
        kd(&free_fit) > 645.0,
        "without bounds kd goes to {}",
        kd(&free_fit)
    );
}

#[test]
fn bad_bounds_are_refused_by_name() {
    let rec = record();
    let m = Bounded::new(1, Closure::Full).unwrap();
    let run = |bounds: Vec<(String, f64, f64)>, p0: Vec<f64>| {
        let opts = FitOptions {
            free: free(),
            bounds,
            ..Default::default()
        };
        fit::identify(&m, &p0, &rec, &opts).unwrap_err()
    };
    let mut p0 = m.default_params();
    p0[m.param_index("kd").unwrap()] = 650.0;
    let e = run(Vec::new(), p0);
    assert!(
        matches!(&e, FitError::BadBounds { name, .. } if name == "kd"),
        "{e}"
    );
    assert!(e.to_string().contains("outside [600, 640]"), "{e}");
    let e = run(vec![("kq".into(), 1.0, 2.0)], m.default_params());
    assert!(matches!(e, FitError::UnknownParameter { .. }), "{e}");
    let e = run(vec![("kp".into(), 2.0, 1.0)], m.default_params());
    assert!(e.to_string().contains("lo < hi"), "{e}");
}

#[test]
fn a_bounds_file_is_read_and_checked() {
    let m = Bounded::new(1, Closure::Full).unwrap();
    let dir = std::env::temp_dir().join(format!("stirling_bounds_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, text: &str| {
        let f = dir.join(name);
        std::fs::File::create(&f)
            .unwrap()
            .write_all(text.as_bytes())
            .unwrap();
        f
    };
    let ok = write("b.toml", "kd = [600.0, 700]\nbp = [1.0, 20.0]\n");
    let mut b = load_bounds(&m, &ok).unwrap();
    b.sort_by(|x, y| x.0.cmp(&y.0));
    assert_eq!(
        b,
        [
            ("bp".to_string(), 1.0, 20.0),
            ("kd".to_string(), 600.0, 700.0)
        ]
    );
    let json = write("b.json", r#"{"kd": [600.0, 700.0]}"#);
    assert_eq!(
        load_bounds(&m, &json).unwrap(),
        [("kd".to_string(), 600.0, 700.0)]
    );
    for (file, text, says) in [
        ("u.toml", "kq = [1.0, 2.0]\n", "unknown parameter `kq`"),
        ("r.toml", "kd = [700.0, 600.0]\n", "lo < hi"),
        ("n.toml", "kd = 600.0\n", "expected [lo, hi]"),
        ("s.toml", "kd = [600.0, \"x\"]\n", "expected [lo, hi]"),
        ("bad.json", "{\"kd\": [600.0,", "b"),
    ] {
        let e = load_bounds(&m, &write(file, text)).unwrap_err().to_string();
        assert!(e.contains(says) && e.contains(file), "{file}: {e}");
    }
    let e = load_bounds(&m, &dir.join("missing.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("cannot read"), "{e}");
}
