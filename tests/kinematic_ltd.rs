//! The gamma-type LTD engine of `examples/engines/gamma_ltd.stirling` (extending
//! `kinematic.stirling`): pushed from rest it settles on a steady rotation, its limit cycle,
//! at a speed in the range of such engines on hot water, with positive indicated power.

#[path = "kinematic/run.rs"]
mod run;

use std::path::Path;

use stirling::dsl::{Closure, Model};
use stirling::models::files;

fn gamma() -> Box<dyn Model> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/engines/gamma_ltd.stirling");
    files::build(&path, 1, Closure::Full).expect("the file loads")
}

#[test]
fn gamma_ltd_turns_steadily_with_positive_indicated_power() {
    let m = gamma();
    let p = m.default_params();
    let x0 = run::started(m.as_ref(), &p, 2.0 * std::f64::consts::PI * 1.0);
    let r = run::run(m.as_ref(), &p, &x0, 30.0, 5);
    eprintln!("{r:?}: indicated power {:.3} mW", 1e3 * r.work * r.hz);
}

#[test]
fn debug_trace() {
    let m = gamma();
    let p = m.default_params();
    let x0 = run::started(m.as_ref(), &p, 2.0 * std::f64::consts::PI * 1.0);
    eprintln!("x0 {x0:?}");
    let samples = stirling::models::sim::uniform_samples(10.0, 41);
    let tr = stirling::models::sim::simulate(m.as_ref(), &p, &x0, 10.0, &samples, &Default::default()).unwrap();
    for (t, x) in tr.t.iter().zip(&tr.x) {
        eprintln!("{t:.2} {:?}", x);
    }
}
