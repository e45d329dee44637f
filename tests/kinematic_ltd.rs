//! The gamma-type LTD engine of `examples/engines/gamma_ltd.stirling` (extending
//! `bases/kinematic.stirling`): pushed from rest at 1 Hz it settles on a steady rotation, its
//! limit cycle, at about 2.8 Hz (170 rpm; such engines run at about 150 rpm on a cup of hot
//! water), with positive indicated power (the gas's closed-integral `P dV` per revolution
//! times the speed, about 2.2 mW); with the same push and a brake on the flywheel it turns
//! slower; with no temperature difference it stops.

#[path = "kinematic/run.rs"]
mod run;

use std::path::Path;

use stirling::dsl::{Closure, Model};
use stirling::models::files;

fn gamma() -> Box<dyn Model> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/engines/gamma_ltd.stirling");
    files::build(&path, 1, Closure::Full).expect("the file loads")
}

fn set(m: &dyn Model, p: &mut [f64], name: &str, v: f64) {
    p[m.param_index(name).unwrap()] = v;
}

#[test]
fn gamma_ltd_turns_steadily_with_positive_indicated_power() {
    let m = gamma();
    let p = m.default_params();
    let x0 = run::started(m.as_ref(), &p, 2.0 * std::f64::consts::PI);
    let r = run::run(m.as_ref(), &p, &x0, 30.0, 5);
    let power = r.work * r.hz;
    eprintln!("{r:?}: indicated power {:.3} mW", 1e3 * power);
    // settled: the last five revolutions at the speed of the five before them
    assert!((r.hz - r.hz_before).abs() < 1e-3 * r.hz, "{r:?}");
    // a plausible LTD speed, and the reference number of this geometry
    assert!((1.0..5.0).contains(&r.hz), "{r:?}");
    assert!((r.hz - 2.81).abs() < 0.05, "speed {} Hz", r.hz);
    // a flywheel evens the speed out within 2 % over a revolution
    assert!(r.omega.1 - r.omega.0 < 0.02 * r.omega.1, "{r:?}");
    // indicated work and power: positive, of the order of a hobby LTD's milliwatts
    assert!(r.work > 0.0, "{r:?}");
    assert!(
        (power - 2.24e-3).abs() < 0.1e-3,
        "indicated power {power:e} W"
    );
    // a hobby transducer's pressure swing: about 1 kPa
    assert!((0.8e3..1.4e3).contains(&r.swing), "{r:?}");
}

#[test]
fn a_brake_slows_it_and_no_temperature_difference_stops_it() {
    let m = gamma();
    let mut p = m.default_params();
    let x0 = run::started(m.as_ref(), &p, 2.0 * std::f64::consts::PI);
    set(m.as_ref(), &mut p, "Tl", 5.0e-5);
    let braked = run::run(m.as_ref(), &p, &x0, 30.0, 5);
    eprintln!("braked by 5e-5 N m: {braked:?}");
    assert!(braked.hz < 2.7 && braked.work > 0.0, "{braked:?}");
    // the load takes Tl omega on average: less than the indicated power
    assert!(5.0e-5 * 2.0 * std::f64::consts::PI * braked.hz < braked.work * braked.hz);
    let mut cold = m.default_params();
    let tk = cold[m.param_index("Tk").unwrap()];
    set(m.as_ref(), &mut cold, "Th", tk + 1e-6);
    let samples = [0.0, 20.0];
    let tr = stirling::models::sim::simulate(
        m.as_ref(),
        &cold,
        &x0,
        20.0,
        &samples,
        &Default::default(),
    )
    .unwrap();
    let omega = tr.x.last().unwrap()[1];
    eprintln!("no temperature difference: omega {omega:e} rad/s after 20 s");
    assert!(omega.abs() < 0.05, "it still turns: {omega} rad/s");
}
