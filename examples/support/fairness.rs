//! The fairness setup shared by the benchmarks (`examples/bench_native.rs`,
//! `examples/files_speed.rs`, `benches/rhs_jacobian.rs`): the state every kernel is timed at,
//! and the timer (batches of calls, the median batch).
#![allow(dead_code)] // each benchmark uses a part of it

use std::time::Instant;

use stirling::dsl::Model;

/// The fairness state: the rest state moved off equilibrium in every kind of state (the
/// bodies displaced and moving, each pressure a little off its neighbours'), so every term of
/// the right-hand side is active and every branch of the upwind switches taken somewhere.
pub fn fairness_state(m: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(p, &mut x);
    x[0] = 3e-3;
    x[1] = 0.2;
    x[2] = -2e-3;
    x[3] = -0.1;
    for (i, s) in m.states().iter().enumerate() {
        if s.unit == "Pa" {
            x[i] *= 1.0 + 1e-3 * ((i % 7) as f64);
        }
    }
    x
}

/// Median seconds per call of `f` and the number of calls timed: batches of `k` calls sized
/// to about `batch_s`, `reps` batches (but at most about `budget_s` in all).
pub fn time_per_call(
    mut f: impl FnMut(),
    batch_s: f64,
    reps: usize,
    budget_s: f64,
) -> (f64, usize) {
    // warm up for 0.2 s: on this VM the first tens of milliseconds of a busy core run up to
    // 1.5x slower, from one process to the next (bench/casadi_timer.c does the same)
    let w = Instant::now();
    while w.elapsed().as_secs_f64() < 0.2 {
        f();
    }
    // calibrate
    let t0 = Instant::now();
    f();
    let one = t0.elapsed().as_secs_f64().max(1e-9);
    let k = ((batch_s / one).ceil() as usize).max(1);
    let reps = reps
        .min(((budget_s / (one * k as f64)).floor() as usize).max(1))
        .max(1);
    let mut v = Vec::with_capacity(reps);
    for _ in 0..reps {
        let t = Instant::now();
        for _ in 0..k {
            f();
        }
        v.push(t.elapsed().as_secs_f64() / k as f64);
    }
    (median(&mut v), reps * k)
}

/// The median of `v` (sorted in place).
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}
