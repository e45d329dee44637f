//! From a perturbed equilibrium the default engine's unstable pair grows and the
//! motion settles on a limit cycle; shooting converges and the Floquet
//! multipliers contain the trivial 1 (twice with the `full` closure).

use stirling::dsl::{Closure, Model, StateKind};
use stirling::models::family::NSection;
use stirling::models::sim::{self, SimOptions};

fn start(model: &dyn Model, p: &[f64], x_disp: f64) -> Vec<f64> {
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    let ix = model
        .states()
        .iter()
        .position(|s| s.kind == StateKind::Position(0))
        .unwrap();
    x[ix] = x_disp;
    x
}

#[test]
fn nsection2_full_grows_and_settles_on_a_limit_cycle() {
    let model = NSection::new(2, Closure::Full).unwrap();
    let p = model.default_params();
    let t0 = std::time::Instant::now();
    // growth: from 1 mm the displacer amplitude grows over the first 0.6 s
    let small = start(&model, &p, 1e-3);
    let samples = sim::uniform_samples(0.6, 6000);
    let early = sim::simulate(&model, &p, &small, 0.6, &samples, &SimOptions::default()).unwrap();
    let x_amp = |rows: &[Vec<f64>]| rows.iter().map(|r| r[0].abs()).fold(0.0, f64::max);
    let first = x_amp(&early.x[..900]);
    let last = x_amp(&early.x[5100..]);
    // settling: start at 5 mm, closer to the cycle
    let x0 = start(&model, &p, 5e-3);
    eprintln!("amplitude first 0.03 s {first:.4e}, last 0.03 s {last:.4e}");
    let lc = sim::limit_cycle(&model, &p, &x0, 20.0, &[], &SimOptions::default(), None).unwrap();
    let f = &lc.figures;
    eprintln!(
        "settled at t = {:.3} s; f = {:.4} Hz, x_amp = {:.4e}, y_amp = {:.4e}, p_amp = {:?}, phase = {:.2} deg",
        lc.settled.t, f.frequency_hz, f.x_amp, f.y_amp, f.p_amp, f.phase_deg
    );
    eprintln!(
        "work {:?} total {:.5e} J, power {:.5e} W",
        lc.work.per_vessel,
        lc.work.total,
        lc.work.total * f.frequency_hz
    );
    eprintln!(
        "floquet {:?}; iterations {}, residual {:.2e}",
        lc.cycle.floquet, lc.cycle.iterations, lc.cycle.residual
    );
    eprintln!("stats {:?}; wall {:?}", lc.stats, t0.elapsed());
    assert!(
        last > 1.3 * first,
        "the unstable pair grows: {first:e} -> {last:e}"
    );
    assert!(f.x_amp > 5e-3, "the amplitude grew from 5 mm to the cycle");
    let ones = lc
        .cycle
        .floquet
        .iter()
        .filter(|&&(re, im)| ((re - 1.0).powi(2) + im * im).sqrt() < 1e-5)
        .count();
    assert!(
        ones >= 2,
        "trivial and inventory multipliers: {:?}",
        lc.cycle.floquet
    );
    assert!(
        lc.cycle
            .floquet
            .iter()
            .skip(2)
            .all(|&(re, im)| re.hypot(im) < 1.0),
        "orbitally stable"
    );
    assert!((f.frequency_hz - 85.0 / (2.0 * std::f64::consts::PI)).abs() < 3.0);
    assert!(f.x_amp > 1e-3 && f.x_amp < 5e-2);
    assert!(lc.work.total > 0.0, "the engine does work");
}
