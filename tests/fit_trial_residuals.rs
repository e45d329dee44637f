//! The residuals of a Levenberg-Marquardt trial point (`Stage::trial_residuals`, no
//! sensitivities) against the residuals of the full evaluation with its Jacobian
//! (`Stage::residuals`), on the stages of a `p, x, y` calibration: the same rows (outputs,
//! then the priors) to the integration tolerance, and the same refusal of a positive
//! parameter stepping below its floor.

use stirling::dsl::Closure;
use stirling::models::fit::{self, FitError, FitOptions};
use stirling::models::rig::{self, RigConfig};

#[test]
fn trial_residuals_match_the_full_evaluation() {
    let cfg = RigConfig {
        model: "nsection".into(),
        n: Some(2),
        t_end: 1.0,
        seed: 3,
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    let model = stirling::models::build("nsection", Some(2), Closure::Full).unwrap();
    let mut p0 = model.default_params();
    p0[model.param_index("kd").unwrap()] *= 1.05;
    let opts = FitOptions {
        free: Some(["kd", "kp", "bd", "hh", "Rf"].map(String::from).to_vec()),
        prior: Some(0.5),
        ..Default::default()
    };
    let (_, stages) = fit::identify_stages(model.as_ref(), &p0, &out.data, &opts).unwrap();
    assert!(stages.len() >= 2, "both stages fitted");
    for st in &stages {
        // a point off the optimum, as a trial is
        let u: Vec<f64> = st.u.iter().map(|v| v + 0.01).collect();
        let (r, j) = st.stage.residuals(&u, st.first, st.last, &st.keep).unwrap();
        let t = st
            .stage
            .trial_residuals(&u, st.first, st.last, &st.keep)
            .unwrap();
        assert_eq!(r.len(), t.len(), "{}: rows", st.stage.name);
        assert_eq!(j.nrows(), t.len());
        let rms = (r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64).sqrt();
        let worst = r
            .iter()
            .zip(&t)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{}: rms {rms:.3e}, worst difference {worst:.3e}",
            st.stage.name
        );
        // residuals are in noise units: the runs differ by the integration error of two step
        // sequences (the sensitivities join the error test of the full one), far below 1
        assert!(worst < 0.05, "{}: {worst}", st.stage.name);
        // the cost agrees to the integration tolerance (1.7e-3 on the gas stage here); the
        // trials are compared with the trial cost of the current point (lm::Point::ct), so
        // this difference never decides a step
        let cost = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>();
        let rel = (cost(&r) - cost(&t)).abs() / cost(&r);
        eprintln!("{}: relative cost difference {rel:.2e}", st.stage.name);
        assert!(rel < 1e-2, "{}: {rel}", st.stage.name);
        // a positive parameter far below its start is refused as in the full evaluation
        if let Some(k) = st.stage.vars.iter().position(|v| v.name == "Rf") {
            let v = &st.stage.vars[k];
            let mut low = st.u.clone();
            low[k] = (0.01 * v.initial - v.initial) / v.scale;
            let full = st.stage.residuals(&low, st.first, st.last, &st.keep);
            let trial = st.stage.trial_residuals(&low, st.first, st.last, &st.keep);
            assert!(matches!(full, Err(FitError::ParamRange { .. })));
            assert!(matches!(trial, Err(FitError::ParamRange { .. })));
        }
    }
}
