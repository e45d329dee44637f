//! Kinematics in the DSL (docs/physics.md section 12), on the gamma LTD engine declared twice,
//! in `examples/engines/gamma_ltd.stirling` (extending `bases/kinematic.stirling`; loaded, compiled
//! to tapes and run by the JIT) and with the macro (`tests/kinematic/models.rs`, extending the
//! same base as a macro base): the two are one model; their analytic Jacobians match finite
//! differences at states all round the crank; the energy budget `d/dt (gas + J omega^2/2) =
//! heat + boundary - dissipation` closes to round-off at those states and to the integration
//! tolerance along a run; the cranks follow the slider-crank law; the bond graph shows each
//! face on a crank as an MTF.

mod common;
#[path = "kinematic/models.rs"]
mod models;
#[path = "kinematic/run.rs"]
mod run;

use std::path::Path;

use rand::Rng;
use stirling::dsl::bond::Kind;
use stirling::dsl::{Closure, Model};
use stirling::models::files;
use stirling::models::sim::{self, EnergySystem, Hooks, ModelSystem, SimOptions};

fn engines_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/engines")
}

fn from_file() -> Box<dyn Model> {
    files::build(&engines_dir().join("gamma_ltd.stirling"), 1, Closure::Full).unwrap()
}

fn from_macro() -> models::GammaLtd {
    models::GammaLtd::new(1, Closure::Full).unwrap()
}

fn rel(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let s = x.abs().max(y.abs());
            if s == 0.0 {
                0.0
            } else {
                (x - y).abs() / s
            }
        })
        .fold(0.0, f64::max)
}

/// The file and the macro declare the same text (the files are the reference; the macro's
/// copy must not drift from them).
#[test]
fn the_macro_declares_the_files_text() {
    let squash = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let macro_text = squash(include_str!("kinematic/models.rs"));
    for (file, from) in [
        ("bases/kinematic.stirling", "/// A flywheel driving"),
        ("gamma_ltd.stirling", "/// Gamma-type LTD engine"),
    ] {
        let text = std::fs::read_to_string(engines_dir().join(file)).unwrap();
        let body = &text[text.find(from).unwrap()..];
        let body = body.replace(
            "model GammaLtd extends kinematic_engine",
            "pub model GammaLtd extends kinematic_engine",
        );
        assert!(
            macro_text.contains(&squash(&body)),
            "tests/kinematic/models.rs no longer declares {file}'s text"
        );
    }
}

/// The run-time file (its tapes run by the JIT and by the interpreter) and the macro's
/// generated code: the same right-hand side, Jacobians, energy, power terms and volumes at
/// states all round the crank and at perturbed parameters.
#[test]
fn file_and_macro_are_one_model() {
    let m = from_macro();
    let interpreted = files::definition(&engines_dir().join("gamma_ltd.stirling"))
        .unwrap()
        .model(1, Closure::Full)
        .unwrap();
    let runs: [(&str, Box<dyn Model>); 2] =
        [("jit", from_file()), ("interpreter", Box::new(interpreted))];
    for (route, f) in runs {
        let worst = agree(f.as_ref(), &m);
        eprintln!("file ({route}) vs macro: worst relative difference {worst:.2e}");
        assert!(
            worst < 1e-12,
            "file ({route}) and macro differ by {worst:e}"
        );
    }
}

fn agree(f: &dyn Model, m: &models::GammaLtd) -> f64 {
    assert_eq!(f.state_names(), m.state_names());
    assert_eq!(f.default_params(), m.default_params());
    let n = f.n_states();
    let mut rng = common::rng(7);
    let mut worst = 0.0f64;
    for k in 0..8 {
        let mut p = m.default_params();
        if k > 0 {
            p.iter_mut()
                .for_each(|v| *v *= 1.0 + 0.05 * rng.gen_range(-1.0..1.0));
        }
        for x in run::round_the_crank(m, &p, 100 + k, 8) {
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            f.rhs(&p, &x, 0.0, &mut a);
            m.rhs(&p, &x, 0.0, &mut b);
            worst = worst.max(rel(&a, &b));
            worst = worst.max(rel(
                &f.jacobian_dense(&p, &x, 0.0),
                &m.jacobian_dense(&p, &x, 0.0),
            ));
            worst = worst.max(rel(
                &f.param_jacobian_dense(&p, &x, 0.0),
                &m.param_jacobian_dense(&p, &x, 0.0),
            ));
            worst = worst.max(rel(&[f.energy(&p, &x)], &[m.energy(&p, &x)]));
            let (pf, pm) = (f.power(&p, &x), m.power(&p, &x));
            worst = worst.max(rel(
                &[pf.heat, pf.boundary, pf.mechanical],
                &[pm.heat, pm.boundary, pm.mechanical],
            ));
            let nv = f.vessel_names().len();
            let (mut pr, mut va, mut vb) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
            f.pv(&p, &x, &mut pr, &mut va);
            m.pv(&p, &x, &mut pr, &mut vb);
            worst = worst.max(rel(&va, &vb));
        }
    }
    worst
}

const STARTS: [f64; 3] = [1.0, 10.0, 100.0];

/// Both Jacobians (states and parameters) of both declarations against Ridders-extrapolated
/// central differences, to 1e-6 relative, at 24 states all round the crank.
#[test]
fn jacobians_match_finite_differences() {
    let (f, m) = (from_file(), from_macro());
    for model in [f.as_ref(), &m as &dyn Model] {
        let p = model.default_params();
        let mut report = Vec::new();
        let mut worst = (0.0f64, String::new());
        for (k, x) in run::round_the_crank(model, &p, 11, 24)
            .into_iter()
            .enumerate()
        {
            // rows as large as `|P'| ~ 1e8 Pa/s` (the short regenerator link at these spreads)
            // next to entries of ~1e2 near a dead centre: upper steps 10 and 100 times the
            // default resolve them (tests/common/mod.rs, `check_jacobians_from`)
            for b in common::check_jacobians_from(model, &p, &x, &STARTS, common::REL) {
                report.push(format!(
                    "state {k} (theta {:.3}): d {}/d {}: {:e} vs fd {:e}",
                    x[0], b.row, b.col, b.analytic, b.fd
                ));
            }
            let w = common::worst_jacobian_error(model, &p, &x, &STARTS);
            if w.0 > worst.0 {
                worst = w;
            }
        }
        eprintln!(
            "{}: worst FD relative error {:.2e} at {}",
            model.name(),
            worst.0,
            worst.1
        );
        assert!(report.is_empty(), "{}", report.join("\n"));
        assert!(worst.0 < 1e-6);
    }
}

/// `dE/dt` along the right-hand side (a Richardson-extrapolated central difference of `E`
/// along `f`: `E` is no longer quadratic in the states, the volumes follow the cranks) equals
/// `heat + boundary + mechanical` to round-off: the MTF passes `P dV/dt` to the flywheel as
/// `torque x omega` exactly.
#[test]
fn energy_budget_closes_at_states_all_round_the_crank() {
    let m = from_macro();
    let p = m.default_params();
    let n = m.n_states();
    let mut worst = 0.0f64;
    for x in run::round_the_crank(&m, &p, 21, 40) {
        let mut f = vec![0.0; n];
        m.rhs(&p, &x, 0.0, &mut f);
        let e = |s: f64| {
            let xs: Vec<f64> = x.iter().zip(&f).map(|(a, b)| a + s * b).collect();
            m.energy(&p, &xs)
        };
        let d = |h: f64| (e(h) - e(-h)) / (2.0 * h);
        let h = 1e-5;
        let de = (4.0 * d(h / 2.0) - d(h)) / 3.0;
        let w = m.power(&p, &x);
        let budget = w.heat + w.boundary + w.mechanical;
        // the scale: the largest term of the budget and of the flywheel's power, or the
        // difference's round-off `eps E / h`
        let j = p[m.param_index("J").unwrap()];
        let roundoff = m.energy(&p, &x).abs() * f64::EPSILON / h;
        let scale = [w.heat, w.boundary, w.mechanical, j * f[1] * x[1]]
            .iter()
            .fold(0.0f64, |s, v| s.max(v.abs()))
            .max(roundoff);
        let r = (de - budget).abs() / scale;
        worst = worst.max(r);
        assert!(
            r < 1e-8,
            "theta {:.3}: dE/dt {de:e} vs budget {budget:e} (scale {scale:e})",
            x[0]
        );
    }
    eprintln!("pointwise energy budget: worst relative residual {worst:.2e}");
}

/// Along a run from a push at 2 Hz (the flywheel loses and gains energy through the cycle):
/// `E(t) - E(0)` against the integral of `heat + boundary + mechanical` carried as a
/// quadrature state of the same run, at two tolerances.
#[test]
fn energy_budget_closes_along_a_run() {
    let m = from_file();
    let p = m.default_params();
    let n = m.n_states();
    let mut x0 = vec![0.0; n];
    m.equilibrium_guess(&p, &mut x0);
    x0[1] = 4.0 * std::f64::consts::PI;
    let e0 = m.energy(&p, &x0);
    let j = p[m.param_index("J").unwrap()];
    let t_end = 1.5;
    let samples = sim::uniform_samples(t_end, 3000);
    let mut z0 = x0.clone();
    z0.push(0.0);
    let sys = EnergySystem {
        inner: ModelSystem {
            model: m.as_ref(),
            p: &p,
        },
    };
    for rtol in [1e-6, 1e-9] {
        let opts = SimOptions {
            rtol,
            atol: rtol,
            ..Default::default()
        };
        let tr = sim::integrate(&sys, &z0, t_end, &samples, &opts, Hooks::default()).unwrap();
        let (mut worst, mut swing, mut kinetic) = (0.0f64, 0.0f64, 0.0f64);
        for z in &tr.x {
            let de = m.energy(&p, &z[..n]) - e0;
            worst = worst.max((de - z[n]).abs());
            swing = swing.max(de.abs());
            kinetic = kinetic.max((0.5 * j * (z[1] * z[1] - x0[1] * x0[1])).abs());
        }
        eprintln!("rtol {rtol:e}: |dE - integral| <= {worst:.3e} J (E0 = {e0:.4} J, max |dE| = {swing:.3e} J, flywheel swing {kinetic:.3e} J)");
        assert!(swing > 1e-3 && kinetic > 1e-4, "the run exchanges energy");
        assert!(
            worst < 100.0 * rtol * e0,
            "budget gap {worst:e} J at rtol {rtol:e}"
        );
    }
}

/// The volumes follow the slider-crank law: `V_hot = Ad (ch + rd) - Ad s_d(theta)`, with
/// `s = r cos(theta + phi) + sqrt(L^2 - r^2 sin^2(theta + phi)) - L`, and the power piston's
/// displacement reaches `+-rp` at its dead centres.
#[test]
fn cranks_follow_the_slider_crank_law() {
    let m = from_file();
    let p = m.default_params();
    let get = |name: &str| p[m.param_index(name).unwrap()];
    let (ad, ch, rd, ld) = (get("Ad"), get("ch"), get("rd"), get("Ld"));
    let s = |r: f64, l: f64, a: f64| r * a.cos() + (l * l - (r * a.sin()).powi(2)).sqrt() - l;
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x);
    let nv = m.vessel_names().len();
    for k in 0..16 {
        x[0] = k as f64 * std::f64::consts::PI / 8.0 - 3.0;
        let (mut pr, mut v) = (vec![0.0; nv], vec![0.0; nv]);
        m.pv(&p, &x, &mut pr, &mut v);
        let want = ad * (ch + rd) - ad * s(rd, ld, x[0]);
        assert!(
            (v[0] - want).abs() <= 1e-15 * want.abs() + 1e-18,
            "V_hot {} vs {want}",
            v[0]
        );
    }
    assert!(
        (s(rd, ld, 0.0) - rd).abs() < 1e-15 && (s(rd, ld, std::f64::consts::PI) + rd).abs() < 1e-15
    );
}

/// The bond graph: causal, its states one to one with the model's, and each face on a crank
/// a modulated transformer whose modulus is the crank's `ds/dtheta`.
#[test]
fn bond_graph_shows_the_mechanism_as_mtf() {
    for m in [from_file(), Box::new(from_macro()) as Box<dyn Model>] {
        let cg = common::bond::check(m.as_ref());
        let mtf: Vec<&str> = cg
            .graph
            .nodes
            .iter()
            .filter(|n| n.kind == Kind::Mtf)
            .map(|n| n.label.as_str())
            .collect();
        assert_eq!(
            mtf,
            [
                "-Ad * ds_displacer(theta)",
                "Ad * ds_displacer(theta)",
                "-Ap * ds_piston(theta)",
                "Ap * ds_piston(theta)"
            ],
            "{}",
            m.name()
        );
        assert!(!cg.graph.nodes.iter().any(|n| n.kind == Kind::Tf));
    }
}

/// `modify body` changes a crank's fields like a body's: a file extending the gamma engine
/// with a longer displacer rod moves the hot volume as the slider-crank law says at that rod.
#[test]
fn modify_changes_a_cranks_rod() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("kinematic_modify");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("longer_rod.stirling");
    let base = engines_dir().join("gamma_ltd.stirling");
    let text = format!(
        "model Longer extends \"{}\" {{\n    name \"longer\";\n    modify body displacer {{ rod: 3.0 * Ld }}\n}}\n",
        base.display()
    );
    std::fs::write(&file, text).unwrap();
    let m = files::build(&file, 1, Closure::Full).unwrap();
    let p = m.default_params();
    let get = |name: &str| p[m.param_index(name).unwrap()];
    let (ad, ch, rd, ld) = (get("Ad"), get("ch"), get("rd"), 3.0 * get("Ld"));
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x);
    x[0] = 1.0;
    let nv = m.vessel_names().len();
    let (mut pr, mut v) = (vec![0.0; nv], vec![0.0; nv]);
    m.pv(&p, &x, &mut pr, &mut v);
    let s = rd * 1f64.cos() + (ld * ld - (rd * 1f64.sin()).powi(2)).sqrt() - ld;
    let want = ad * (ch + rd) - ad * s;
    assert!(
        (v[0] - want).abs() <= 1e-15 * want,
        "V_hot {} vs {want}",
        v[0]
    );
    // and not the base's rod
    let base_rod = get("Ld");
    let s0 = rd * 1f64.cos() + (base_rod * base_rod - (rd * 1f64.sin()).powi(2)).sqrt() - base_rod;
    assert!((ad * (ch + rd) - ad * s0 - want).abs() > 1e-12);
}
