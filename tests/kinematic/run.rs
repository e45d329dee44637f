//! A kinematic engine run until it turns steadily: the speed and the indicated work of the
//! last whole revolutions (shared by the kinematic tests).
#![allow(dead_code)]

use rand::Rng;
use stirling::dsl::Model;
use stirling::models::sim::{self, SimOptions};

/// What the last `revs` whole revolutions of a run show.
#[derive(Debug)]
pub struct Running {
    /// Mean speed, revolutions per second (Hz).
    pub hz: f64,
    /// Smallest and largest angular velocity over those revolutions (rad/s).
    pub omega: (f64, f64),
    /// Indicated work per revolution: `sum_i closed-integral P_i dV_i` over the gas CVs (J).
    pub work: f64,
    /// Pressure swing of the sensed (cold) CV over those revolutions (Pa).
    pub swing: f64,
    /// The mean speed over the revolutions before them, for the settling check (Hz).
    pub hz_before: f64,
}

/// The rest state of `m` with the flywheel at `omega0` (the push that starts it).
pub fn started(m: &dyn Model, p: &[f64], omega0: f64) -> Vec<f64> {
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(p, &mut x);
    x[1] = omega0;
    x
}

/// Run `m` from `x0` for `t_end` s and measure the last `revs` whole revolutions (angle in
/// state 0, the CVs first among the vessels).
pub fn run(m: &dyn Model, p: &[f64], x0: &[f64], t_end: f64, revs: usize) -> Running {
    let samples = sim::uniform_samples(t_end, (t_end * 4000.0) as usize);
    let opts = SimOptions {
        rtol: 1e-8,
        atol: 1e-8,
        ..Default::default()
    };
    let tr = sim::simulate(m, p, x0, t_end, &samples, &opts).expect("the run completes");
    let two_pi = 2.0 * std::f64::consts::PI;
    let last = tr.x.last().unwrap()[0];
    let turns = (last / two_pi).floor();
    assert!(
        turns >= 2.0 * revs as f64,
        "only {turns} revolutions in {t_end} s"
    );
    let (a, b) = ((turns - revs as f64) * two_pi, turns * two_pi);
    let (a0, _) = ((turns - 2.0 * revs as f64) * two_pi, a);
    let at = |angle: f64| tr.x.iter().position(|x| x[0] >= angle).unwrap();
    let (k0, ka, kb) = (at(a0), at(a), at(b));
    let ncv = m
        .states()
        .iter()
        .filter(|s| matches!(s.kind, stirling::dsl::StateKind::Pressure(_)))
        .count();
    let nv = m.vessel_names().len();
    let pv = |x: &[f64]| {
        let (mut pr, mut vol) = (vec![0.0; nv], vec![0.0; nv]);
        m.pv(p, x, &mut pr, &mut vol);
        (pr, vol)
    };
    let mut work = 0.0;
    let (mut wmin, mut wmax) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut pmin, mut pmax) = (f64::INFINITY, f64::NEG_INFINITY);
    let cold = m.state_names().iter().position(|s| s == "P_cold").unwrap();
    for k in ka..kb {
        let ((p0, v0), (p1, v1)) = (pv(&tr.x[k]), pv(&tr.x[k + 1]));
        for i in 0..ncv {
            work += 0.5 * (p0[i] + p1[i]) * (v1[i] - v0[i]);
        }
        wmin = wmin.min(tr.x[k][1]);
        wmax = wmax.max(tr.x[k][1]);
        pmin = pmin.min(tr.x[k][cold]);
        pmax = pmax.max(tr.x[k][cold]);
    }
    // the whole revolutions are cut at the first sample past each angle: the loop is closed
    // to within one sample (0.25 ms, a small fraction of a revolution)
    let revs_f = revs as f64;
    Running {
        hz: revs_f / (tr.t[kb] - tr.t[ka]),
        omega: (wmin, wmax),
        work: work / revs_f,
        swing: pmax - pmin,
        hz_before: revs_f / (tr.t[ka] - tr.t[k0]),
    }
}

/// States all round the crank: angle in [0, 2 pi), speed within +-20 rad/s, pressures
/// within +-5 % of the charge and 2 to 200 Pa apart, masses within +-5 % of rest.
pub fn round_the_crank(m: &dyn Model, p: &[f64], seed: u64, count: usize) -> Vec<Vec<f64>> {
    let mut rng: rand::rngs::StdRng = rand::SeedableRng::seed_from_u64(seed);
    let mut x0 = vec![0.0; m.n_states()];
    m.equilibrium_guess(p, &mut x0);
    (0..count)
        .map(|_| {
            let mut x = x0.clone();
            x[0] = rng.gen_range(0.0..2.0 * std::f64::consts::PI);
            x[1] = rng.gen_range(-20.0..20.0);
            let dp = rng.gen_range(2.0..200.0) * if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
            let level = 1.0 + 0.05 * rng.gen_range(-1.0..1.0);
            x[2] *= level;
            x[3] = x[2] + dp;
            x[4] *= 1.0 + 0.05 * rng.gen_range(-1.0..1.0);
            x[5] *= 1.0 + 0.05 * rng.gen_range(-1.0..1.0);
            x
        })
        .collect()
}
