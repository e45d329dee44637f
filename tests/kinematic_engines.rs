//! The beta and alpha kinematic engines of `examples/engines/` (each extending
//! `bases/kinematic.stirling`, as the gamma LTD does): pushed from rest at 5 Hz they settle on a
//! steady rotation with positive indicated power (beta 6.03 Hz, 8.6 mJ per revolution, 52 mW;
//! alpha 6.41 Hz, 15.1 mJ, 97 mW, with their estimated geometry and friction); their
//! Jacobians match finite differences all round the crank; their bond graphs are causal with
//! an MTF per face on a crank.

mod common;
#[path = "kinematic/run.rs"]
mod run;

use std::path::Path;

use stirling::dsl::bond::Kind;
use stirling::dsl::{Closure, Model};
use stirling::models::files;

fn engine(name: &str) -> Box<dyn Model> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/engines")
        .join(format!("{name}.stirling"));
    files::build(&path, 1, Closure::Full).expect("the file loads")
}

/// `(name, speed Hz, indicated power W)` of the reference runs.
const REFERENCE: [(&str, f64, f64); 2] = [("beta", 6.03, 52.1e-3), ("alpha", 6.41, 96.7e-3)];

#[test]
fn beta_and_alpha_turn_steadily_with_positive_indicated_power() {
    for (name, hz, power) in REFERENCE {
        let m = engine(name);
        let p = m.default_params();
        let x0 = run::started(m.as_ref(), &p, 2.0 * std::f64::consts::PI * 5.0);
        let r = run::run(m.as_ref(), &p, &x0, 20.0, 10);
        let w = r.work * r.hz;
        eprintln!("{name}: {r:?}: indicated power {:.3} mW", 1e3 * w);
        assert!(
            (r.hz - r.hz_before).abs() < 1e-3 * r.hz,
            "{name} settled: {r:?}"
        );
        assert!((r.hz - hz).abs() < 0.02 * hz, "{name}: {} Hz", r.hz);
        assert!(
            r.work > 0.0 && (w - power).abs() < 0.05 * power,
            "{name}: {w} W"
        );
    }
}

#[test]
fn jacobians_match_finite_differences() {
    for (name, _, _) in REFERENCE {
        let m = engine(name);
        let p = m.default_params();
        let mut report = Vec::new();
        let mut worst = 0.0f64;
        for x in run::round_the_crank(m.as_ref(), &p, 5, 12) {
            for b in
                common::check_jacobians_from(m.as_ref(), &p, &x, &[1.0, 10.0, 100.0], common::REL)
            {
                report.push(format!(
                    "{name} theta {:.3}: d {}/d {}: {:e} vs {:e}",
                    x[0], b.row, b.col, b.analytic, b.fd
                ));
            }
            worst =
                worst.max(common::worst_jacobian_error(m.as_ref(), &p, &x, &[1.0, 10.0, 100.0]).0);
        }
        eprintln!("{name}: worst FD relative error {worst:.2e}");
        assert!(report.is_empty(), "{}", report.join("\n"));
    }
}

#[test]
fn bond_graphs_are_causal_with_an_mtf_per_crank_face() {
    for (name, faces) in [("beta", 4), ("alpha", 4)] {
        let m = engine(name);
        let cg = common::bond::check(m.as_ref());
        let mtf = cg
            .graph
            .nodes
            .iter()
            .filter(|n| n.kind == Kind::Mtf)
            .count();
        assert_eq!(mtf, faces, "{name}");
    }
}
