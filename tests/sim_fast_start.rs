//! A start whose neighbouring regenerator pressures differ: at n = 1000 they equalize on a time
//! scale of about 1e-14 s, and the BDF's first steps must resolve that before the step grows.
//! With the old minimum step (1e-13 s) such a run stopped at its first step ("step size
//! collapsed"), and so did the block route's shooting at n = 10,000 (a Newton update moves the
//! section pressures apart by that much).

use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::sim::{self, SimError, SimOptions};

/// The rest state with one mid-regenerator pressure raised by `factor`, and that state's index.
fn pressure_kick(model: &dyn Model, p: &[f64], factor: f64) -> (Vec<f64>, usize) {
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    let n = model
        .states()
        .iter()
        .filter(|s| s.name.starts_with("P_regen["))
        .count();
    let name = format!("P_regen[{}]", n / 2);
    let k = model.states().iter().position(|s| s.name == name).unwrap();
    x[k] *= factor;
    (x, k)
}

#[test]
fn an_unequal_section_pressure_at_n_1000_runs_and_equalizes() {
    let model = NSection::new(1000, Closure::Full).unwrap();
    let p = model.default_params();
    let (x0, k) = pressure_kick(&model, &p, 1.1);
    let t_end = 1e-5;
    let run = sim::simulate(&model, &p, &x0, t_end, &[t_end], &SimOptions::default())
        .expect("the kicked start runs");
    let x = run.x.last().unwrap();
    // equalized with its neighbours to well below the kick (10 % of 1 bar)
    let spread = (x[k] - x[k - 1]).abs().max((x[k] - x[k + 1]).abs());
    assert!(
        spread < 1e-4 * x0[k],
        "the kicked pressure still differs from its neighbours by {spread:e} Pa"
    );
    // the gas's mass is conserved through the fast transient
    let (m0, m1) = (model.gas_mass(&p, &x0), model.gas_mass(&p, x));
    assert!(((m1 - m0) / m0).abs() < 1e-9, "mass {m0:e} -> {m1:e}");
}

#[test]
fn the_old_minimum_step_cannot_start_there() {
    let model = NSection::new(1000, Closure::Full).unwrap();
    let p = model.default_params();
    let (x0, _) = pressure_kick(&model, &p, 1.1);
    let opts = SimOptions {
        min_step: 1e-13,
        ..SimOptions::default()
    };
    let err = sim::simulate(&model, &p, &x0, 1e-5, &[1e-5], &opts).unwrap_err();
    assert!(
        matches!(err, SimError::StepSizeCollapse { t } if t < 1e-12),
        "{err}"
    );
}
