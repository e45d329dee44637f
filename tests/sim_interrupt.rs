//! The process-wide stop request (`sim::interrupt`, set by the Python module on Ctrl-C): a
//! run stops at its first step with `SimError::Interrupted`, a limit cycle and a fit started
//! under the request stop too, and `clear` withdraws it. One test in its own process, as the
//! request reaches every simulation in the process.

use stirling::models::dsl::{Closure, Model};
use stirling::models::family::Schmidt;
use stirling::models::sim::{self, interrupt, SimError, SimOptions};

#[test]
fn a_stop_request_ends_runs_and_clear_withdraws_it() {
    let m = Schmidt::new(1, Closure::Full).expect("schmidt");
    let p = m.default_params();
    let mut x0 = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x0);
    x0[0] += 1e-3;
    let opts = SimOptions::default();
    assert!(!interrupt::requested());
    interrupt::request();
    match sim::simulate(&m, &p, &x0, 0.1, &[0.1], &opts) {
        Err(SimError::Interrupted { t }) => assert!(t > 0.0 && t < 0.1, "stopped at t = {t}"),
        other => panic!("expected Interrupted, got {other:?}"),
    }
    let lc = sim::limit_cycle(&m, &p, &x0, 5.0, &[], &opts, None);
    assert!(
        matches!(lc, Err(SimError::Interrupted { .. })),
        "limit cycle under a stop request: {lc:?}"
    );
    interrupt::clear();
    assert!(!interrupt::requested());
    let tr = sim::simulate(&m, &p, &x0, 0.1, &[0.1], &opts).expect("runs after clear");
    assert_eq!(tr.t_end, 0.1);
}
