//! Along trajectories (`full` closure) the gas inventory is conserved to round-off
//! and the energy budget of docs/physics.md section 10 closes to the solver tolerance:
//! `E(t) - E(0) = integral (heat + boundary + mechanical) dt`, the integral carried
//! as a quadrature state of the same BDF run.

#[path = "dsl_walls/models.rs"]
mod wall_models;

use stirling::dsl::{Closure, Model};
use stirling::models::family::{Cv2, NSection};
use stirling::models::sim::{self, EnergySystem, Hooks, ModelSystem, SimOptions};

fn perturbed(model: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    x[0] = 5e-3;
    x[3] = -0.2;
    x
}

#[test]
fn mass_is_conserved_to_round_off() {
    for model in [
        Box::new(NSection::new(3, Closure::Full).unwrap()) as Box<dyn Model>,
        Box::new(Cv2::new(1, Closure::Full).unwrap()),
    ] {
        let p = model.default_params();
        let x0 = perturbed(model.as_ref(), &p);
        let m0 = model.gas_mass(&p, &x0);
        let tr = sim::simulate(
            model.as_ref(),
            &p,
            &x0,
            0.3,
            &sim::uniform_samples(0.3, 300),
            &SimOptions::default(),
        )
        .unwrap();
        let drift =
            tr.x.iter()
                .map(|x| (model.gas_mass(&p, x) - m0).abs() / m0)
                .fold(0.0, f64::max);
        eprintln!(
            "{}: max relative mass drift {drift:.2e} over {} steps",
            model.name(),
            tr.stats.steps
        );
        assert!(drift < 1e-12, "{}: mass drift {drift:e}", model.name());
    }
}

/// Also with walls that have a temperature state (the heater head and the regenerator matrix
/// of `tests/dsl_walls/models.rs`): their `C Tw` is stored energy, the head's input and the
/// conduction to the cold end are heat from outside.
#[test]
fn energy_budget_closes_along_a_trajectory() {
    let models: [Box<dyn Model>; 2] = [
        Box::new(NSection::new(2, Closure::Full).unwrap()),
        Box::new(wall_models::HeadMatrix::new(2, Closure::Full).unwrap()),
    ];
    for model in &models {
        budget_along_a_trajectory(model.as_ref());
    }
}

fn budget_along_a_trajectory(model: &dyn Model) {
    let p = model.default_params();
    let x0 = perturbed(model, &p);
    let n = model.n_states();
    let sys = EnergySystem {
        inner: ModelSystem { model, p: &p },
    };
    let mut z0 = x0.clone();
    z0.push(0.0);
    for rtol in [1e-6, 1e-9] {
        let opts = SimOptions {
            rtol,
            atol: rtol,
            ..Default::default()
        };
        let tr = sim::integrate(
            &sys,
            &z0,
            0.2,
            &sim::uniform_samples(0.2, 200),
            &opts,
            Hooks::default(),
        )
        .unwrap();
        let e0 = model.energy(&p, &x0);
        let (mut worst, mut swing) = (0.0f64, 0.0f64);
        for z in &tr.x {
            let de = model.energy(&p, &z[..n]) - e0;
            worst = worst.max((de - z[n]).abs());
            swing = swing.max(de.abs());
        }
        eprintln!("{}: rtol {rtol:e}: |dE - integral| <= {worst:.3e} J (E0 = {e0:.4} J, max |dE| = {swing:.3e} J)", model.name());
        assert!(
            worst < 100.0 * rtol * e0,
            "budget gap {worst:e} J at rtol {rtol:e}"
        );
        // walls store far more than moves (the head's C Tw): hold the gap to what moves too
        assert!(swing > 1.0, "the trajectory exchanges energy: {swing:e} J");
        assert!(
            worst < 100.0 * rtol * swing,
            "budget gap {worst:e} J against a swing of {swing:e} J at rtol {rtol:e}"
        );
    }
}

/// With every CV's mass a state (`full` closure) each gas temperature is `P V / (m R)`
/// (docs/physics.md), so it is positive once the pressure, volume and mass are: the
/// nonphysical-state check (`sim::PhysicalCheck`) relies on it and checks the temperatures
/// only when some CV's mass is not a state.
#[test]
fn full_closure_temperatures_are_the_gas_law_of_the_checked_states() {
    let model = NSection::new(3, Closure::Full).unwrap();
    let p = model.default_params();
    let r = p[model.params().iter().position(|q| q.name == "R").unwrap()];
    let states = model.states();
    let x = perturbed(&model, &p);
    let tr = sim::simulate(
        &model,
        &p,
        &x,
        0.05,
        &sim::uniform_samples(0.05, 20),
        &SimOptions::default(),
    )
    .unwrap();
    let nv = model.vessel_names().len();
    for x in &tr.x {
        let (mut pr, mut vol) = (vec![0.0; nv], vec![0.0; nv]);
        model.pv(&p, x, &mut pr, &mut vol);
        let mut temp = vec![0.0; nv];
        model.temperatures(&p, x, &mut temp);
        for (k, s) in states.iter().enumerate() {
            if let stirling::dsl::StateKind::Mass(cv) = s.kind {
                let law = pr[cv] * vol[cv] / (x[k] * r);
                assert!(
                    ((temp[cv] - law) / law).abs() < 1e-12,
                    "{}: T {} against P V / (m R) {law}",
                    s.name,
                    temp[cv]
                );
            }
        }
    }
}
